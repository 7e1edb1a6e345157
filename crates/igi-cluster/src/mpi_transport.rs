//! [`MpiTransport`]: the cluster's messages over MPI (the `mpi` crate on the system's Open
//! MPI or MPICH), initialised for "serialized" threading: any one thread at a time may call
//! MPI, which the transport's `&mut self` methods guarantee (a viewer's render loop runs on
//! its own thread).
//!
//! Nothing blocks inside MPI: Open MPI's blocking calls spin (yielding, when oversubscribed,
//! thousands of times a second), and a spinning rank 0 or a node's transport thread takes
//! CPU from the render threads. Receiving polls `MPI_Improbe` with a short sleep between
//! tries; sending posts `MPI_Isend` and the buffer is freed once a later call finds the send
//! complete (measured: a node's transport thread spent 13 % of a core in `sched_yield` inside
//! `MPI_Send`).

use crate::transport::{MAX_MESSAGE, Transport, TransportError};
use mpi::environment::Universe;
use mpi::request::{Request, StaticScope};
use mpi::topology::SimpleCommunicator;
use mpi::traits::*;
use std::time::{Duration, Instant};

/// The tag of every igi message.
const TAG: i32 = 17;

/// The first sleep after a probe found nothing.
const MIN_NAP: Duration = Duration::from_micros(50);

/// Open MPI's shared-memory transport sends messages up to this size eagerly (the default is
/// 4 KiB): a tile of 64² 8-bit pixels (12 KiB) then leaves a node without waiting for rank 0
/// to match it, which on an oversubscribed machine took 13 % of a node's CPU. A value the user
/// set in the environment stays.
const VADER_EAGER_LIMIT: (&str, &str) = ("OMPI_MCA_btl_vader_eager_limit", "32768");

/// The longest sleep between two probes for a message.
const MAX_NAP: Duration = Duration::from_micros(200);

/// A send in flight: MPI reads `buffer` (leaked from a `Box<[u8]>`) until `request`
/// completes, then the box is taken back.
struct Outgoing {
    request: Request<'static, [u8], StaticScope>,
    buffer: *mut [u8],
}

/// This process's rank in `MPI_COMM_WORLD`. MPI is finalised when it is dropped, after every
/// send has completed.
pub struct MpiTransport {
    world: SimpleCommunicator,
    outgoing: Vec<Outgoing>,
    // Dropped last: finalises MPI.
    _universe: Universe,
}

impl MpiTransport {
    /// Frees the buffers of the sends that have completed.
    fn reap(&mut self) {
        for o in std::mem::take(&mut self.outgoing) {
            match o.request.test() {
                // SAFETY: the send is complete, so MPI no longer reads the buffer, and the
                // pointer came from `Box::leak` in `send`.
                Ok(_) => drop(unsafe { Box::from_raw(o.buffer) }),
                Err(request) => self.outgoing.push(Outgoing { request, buffer: o.buffer }),
            }
        }
    }
}

impl Drop for MpiTransport {
    fn drop(&mut self) {
        for o in self.outgoing.drain(..) {
            o.request.wait();
            // SAFETY: as in `reap`: the send is complete and the buffer was leaked by `send`.
            drop(unsafe { Box::from_raw(o.buffer) });
        }
    }
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
        if std::env::var_os(VADER_EAGER_LIMIT.0).is_none() {
            // SAFETY: called before MPI starts its threads and before igi starts any that read
            // the environment (the command line calls this first).
            unsafe { std::env::set_var(VADER_EAGER_LIMIT.0, VADER_EAGER_LIMIT.1) };
        }
        let (universe, threading) = mpi::initialize_with_threading(mpi::Threading::Serialized)
            .ok_or("MPI is already initialised in this process")?;
        if threading < mpi::Threading::Serialized {
            return Err(format!("the MPI library offers {threading:?} threading; igi needs Serialized"));
        }
        let world = universe.world();
        Ok(Self { world, outgoing: Vec::new(), _universe: universe })
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
        self.reap();
        let buffer: &'static [u8] = Box::leak(bytes.to_vec().into_boxed_slice());
        let request = self.world.process_at_rank(rank).immediate_send_with_tag(StaticScope, buffer, TAG);
        self.outgoing.push(Outgoing { request, buffer: std::ptr::from_ref(buffer).cast_mut() });
        Ok(())
    }

    fn recv(&mut self, timeout: Duration) -> Result<Option<(usize, Vec<u8>)>, TransportError> {
        self.reap();
        let start = Instant::now();
        let mut nap = MIN_NAP;
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

    fn abort(&mut self, code: i32) {
        self.world.abort(code)
    }
}
