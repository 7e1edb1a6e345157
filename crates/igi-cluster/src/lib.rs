//! igi on a cluster (paper sections 2.1, 3.4 and 4): rank 0 owns the display, the animation
//! clock, the input and the tile queue; ranks 1..N render. Each frame rank 0 sends the nodes a
//! small [`FrameJob`]; they derive the VPLs themselves, take tiles on demand, filter and
//! tone-map them and send back only 8-bit pixels and luminance statistics.
//!
//! - [`protocol`]: the messages and their encoding.
//! - [`transport`]: [`Transport`], and the in-process transport the tests run on.
//! - `mpi_transport` (feature `mpi`): the same over MPI, as `mpirun` or `srun` start it.
//! - [`tile_queue`]: which tile goes where, tiles of silent nodes, deadlines and copies of late
//!   tiles.
//! - [`failure_detector`]: which nodes are silent, and which are lost.
//! - [`master`]: rank 0's side ([`Master`]).
//! - [`worker`]: a render node's side ([`run_worker`]).
//! - [`cluster_source`]: a viewer session rendered by the cluster ([`ClusterSource`]).

pub mod cluster_source;
pub mod error;
pub mod failure_detector;
pub mod master;
#[cfg(feature = "mpi")]
pub mod mpi_transport;
pub mod protocol;
pub mod tile_queue;
pub mod transport;
pub mod worker;

pub use cluster_source::ClusterSource;
pub use error::ClusterError;
pub use master::{ClusterFrame, Master, MasterConfig};
#[cfg(feature = "mpi")]
pub use mpi_transport::{MpiTransport, abort_job};
pub use protocol::{FrameJob, Setup};
pub use transport::{InProcess, Transport, in_process};
pub use worker::{WorkerSummary, run_worker};
