//! [`MpiTransport`]: the cluster's messages over MPI (the `mpi` crate on the system's Open
//! MPI or MPICH), initialised for "serialized" threading: any one thread at a time may call
//! MPI, which the transport's `&mut self` methods guarantee (a viewer's render loop runs on
//! its own thread).
//!
//! Receiving polls `MPI_Improbe` with a short sleep between tries instead of blocking in
//! `MPI_Recv`: Open MPI's blocking calls spin, and a spinning rank 0 or an idle node's
//! transport thread would take a core from the render threads on the same machine.

use crate::transport::{MAX_MESSAGE, Transport, TransportError};
use mpi::environment::Universe;
use mpi::topology::SimpleCommunicator;
use mpi::traits::*;
use std::time::{Duration, Instant};

/// The tag of every igi message.
const TAG: i32 = 17;

/// The longest sleep between two probes for a message.
const MAX_NAP: Duration = Duration::from_micros(200);

/// This process's rank in `MPI_COMM_WORLD`. MPI is finalised when it is dropped.
pub struct MpiTransport {
    world: SimpleCommunicator,
    // Dropped last: finalises MPI.
    _universe: Universe,
}

impl std::fmt::Debug for MpiTransport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("MpiTransport")
            .field("rank", &self.world.rank())
            .field("size", &self.world.size())
            .finish()
    }
}

impl MpiTransport {
    /// Initialises MPI. Fails if it was initialised before or the library cannot serve
    /// calls from more than one thread (one at a time).
    pub fn init() -> Result<Self, String> {
        let (universe, threading) = mpi::initialize_with_threading(mpi::Threading::Serialized)
            .ok_or("MPI is already initialised in this process")?;
        if threading < mpi::Threading::Serialized {
            return Err(format!("the MPI library offers {threading:?} threading; igi needs Serialized"));
        }
        let world = universe.world();
        Ok(Self { world, _universe: universe })
    }
}

/// Ends every rank of the job at once (`MPI_Abort` on the world): what a failed job does, so
/// no rank is left waiting for a message that will not come. MPI must be initialised.
pub fn abort_job(code: i32) -> ! {
    SimpleCommunicator::world().abort(code)
}

// SAFETY: MPI runs with MPI_THREAD_SERIALIZED (checked in `init`), so the communicator may be
// used from any thread as long as calls do not overlap; every call goes through `&self` or
// `&mut self` of this one value, which moves between threads only as a whole.
unsafe impl Send for MpiTransport {}

impl Transport for MpiTransport {
    fn rank(&self) -> usize {
        self.world.rank() as usize
    }

    fn size(&self) -> usize {
        self.world.size() as usize
    }

    fn send(&mut self, to: usize, bytes: &[u8]) -> Result<(), TransportError> {
        let rank = i32::try_from(to).map_err(|_| TransportError::Closed(to))?;
        if rank >= self.world.size() {
            return Err(TransportError::Closed(to));
        }
        self.world.process_at_rank(rank).send_with_tag(bytes, TAG);
        Ok(())
    }

    fn recv(&mut self, timeout: Duration) -> Result<Option<(usize, Vec<u8>)>, TransportError> {
        let start = Instant::now();
        let mut nap = Duration::from_micros(5);
        loop {
            if let Some((message, status)) = self.world.any_process().immediate_matched_probe_with_tag(TAG) {
                let rank = status.source_rank() as usize;
                let len = usize::try_from(status.count(u8::equivalent_datatype())).unwrap_or(usize::MAX);
                if len > MAX_MESSAGE {
                    return Err(TransportError::TooLarge { rank, len });
                }
                let mut bytes = vec![0u8; len];
                message.matched_receive_into(&mut bytes[..]);
                return Ok(Some((rank, bytes)));
            }
            let left = timeout.saturating_sub(start.elapsed());
            if left.is_zero() {
                return Ok(None);
            }
            std::thread::sleep(nap.min(left));
            nap = (nap * 2).min(MAX_NAP);
        }
    }
}
