//! [`MpiTransport`]: the cluster's messages over MPI (the `mpi` crate on the system's Open
//! MPI or MPICH), initialised for "serialized" threading: any one thread at a time may call
//! MPI, which the transport's `&mut self` methods guarantee (a viewer's render loop runs on
//! its own thread).
//!
//! Nothing blocks inside MPI: Open MPI's blocking calls spin (yielding, when oversubscribed,
//! thousands of times a second), and a spinning rank 0 or a node's transport thread takes
//! CPU from the render threads. Sending posts `MPI_Isend` and the buffer is freed once a later
//! call finds the send complete (measured: a node's transport thread spent 13 % of a core in
//! `sched_yield` inside `MPI_Send`). Receiving polls `MPI_Improbe` with a short sleep between
//! tries and starts `MPI_Imrecv` for each message it matches; a message is handed on once a
//! later call finds it complete. A blocking receive would wait for the sender: a message
//! beyond the eager limit (a tile of linear pixels) travels only while its sender runs, and
//! rank 0 spun in `MPI_Mrecv` for as long as a node stopped halfway through sending one.

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

/// A send or receive in flight: MPI reads or writes `buffer` (from `Box::into_raw`) until
/// `request` completes, then the box is taken back.
struct InFlight {
    request: Request<'static, [u8], StaticScope>,
    buffer: *mut [u8],
    /// The rank at the other end.
    peer: usize,
}

impl InFlight {
    /// The buffer, if the transfer is complete; else the transfer.
    fn test(self) -> Result<Box<[u8]>, Self> {
        match self.request.test() {
            // SAFETY: the transfer is complete, so MPI no longer touches the buffer, and the
            // pointer came from `Box::into_raw`.
            Ok(_) => Ok(unsafe { Box::from_raw(self.buffer) }),
            Err(request) => Err(Self { request, ..self }),
        }
    }

    /// The buffer, once the transfer is complete.
    fn wait(self) -> Box<[u8]> {
        self.request.wait();
        // SAFETY: as in `test`.
        unsafe { Box::from_raw(self.buffer) }
    }
}

/// This process's rank in `MPI_COMM_WORLD`. MPI is finalised when it is dropped, after every
/// send and receive in flight has completed.
pub struct MpiTransport {
    world: SimpleCommunicator,
    outgoing: Vec<InFlight>,
    /// Receives in flight, in the order their messages were matched.
    incoming: Vec<InFlight>,
    // Dropped last: finalises MPI.
    _universe: Universe,
}

impl MpiTransport {
    /// Frees the buffers of the sends that have completed.
    fn reap(&mut self) {
        for o in std::mem::take(&mut self.outgoing) {
            if let Err(o) = o.test() {
                self.outgoing.push(o);
            }
        }
    }

    /// The first message received in full whose sender has no earlier message still arriving:
    /// each rank's messages are handed on in the order it sent them, as MPI matches them.
    fn arrived(&mut self) -> Option<(usize, Vec<u8>)> {
        let mut arriving = Vec::new();
        let mut i = 0;
        while i < self.incoming.len() {
            let peer = self.incoming[i].peer;
            if !arriving.contains(&peer) {
                match self.incoming.remove(i).test() {
                    Ok(bytes) => return Some((peer, bytes.into_vec())),
                    Err(transfer) => self.incoming.insert(i, transfer),
                }
                arriving.push(peer);
            }
            i += 1;
        }
        None
    }
}

impl Drop for MpiTransport {
    fn drop(&mut self) {
        for transfer in self.outgoing.drain(..).chain(self.incoming.drain(..)) {
            drop(transfer.wait());
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
        Ok(Self { world, outgoing: Vec::new(), incoming: Vec::new(), _universe: universe })
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
        let buffer = Box::into_raw(bytes.to_vec().into_boxed_slice());
        // SAFETY: the box is only taken back (`InFlight`) once the send is complete.
        let data: &'static [u8] = unsafe { &*buffer };
        let request = self.world.process_at_rank(rank).immediate_send_with_tag(StaticScope, data, TAG);
        self.outgoing.push(InFlight { request, buffer, peer: to });
        Ok(())
    }

    fn recv(&mut self, timeout: Duration) -> Result<Option<(usize, Vec<u8>)>, TransportError> {
        self.reap();
        let start = Instant::now();
        let mut nap = MIN_NAP;
        loop {
            while let Some((message, status)) = self.world.any_process().immediate_matched_probe_with_tag(TAG)
            {
                let peer = status.source_rank() as usize;
                let len = usize::try_from(status.count(u8::equivalent_datatype())).unwrap_or(usize::MAX);
                if len > MAX_MESSAGE {
                    return Err(TransportError::TooLarge { rank: peer, len });
                }
                let buffer = Box::into_raw(vec![0u8; len].into_boxed_slice());
                // SAFETY: the box is only taken back (`InFlight`) once the receive is complete.
                let data: &'static mut [u8] = unsafe { &mut *buffer };
                let request = message.immediate_matched_receive_into(StaticScope, data);
                self.incoming.push(InFlight { request, buffer, peer });
            }
            if let Some(message) = self.arrived() {
                return Ok(Some(message));
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
        abort_job(code)
    }
}
