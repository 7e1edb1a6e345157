//! [`Transport`]: messages between ranks, whatever carries them. MPI carries them on a
//! cluster ([`crate::mpi_transport`], feature `mpi`); [`in_process`] channels carry them
//! between threads, so the whole protocol and scheduling run in plain `cargo test`.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, RecvTimeoutError, Sender, channel};
use std::time::Duration;

/// The largest message a rank accepts (a 1024² tile of linear pixels is 12 MiB; anything
/// beyond this is refused before its buffer is allocated).
pub const MAX_MESSAGE: usize = 64 << 20;

/// Why a message could not be sent or received.
#[derive(Debug, thiserror::Error)]
pub enum TransportError {
    /// The other side is gone.
    #[error("rank {0} is gone")]
    Closed(usize),
    /// A message beyond [`MAX_MESSAGE`].
    #[error("rank {rank} sent a message of {len} bytes, more than the limit of {MAX_MESSAGE}")]
    TooLarge {
        /// The sender.
        rank: usize,
        /// Its length.
        len: usize,
    },
    /// A rank ended the job ([`Transport::abort`]).
    #[error("the job was aborted")]
    Aborted,
}

/// Point-to-point messages between the ranks of a job. Messages from one rank to another
/// arrive in the order they were sent (as MPI guarantees).
pub trait Transport: Send {
    /// This rank's number (0 is the display and scheduler).
    fn rank(&self) -> usize;
    /// Number of ranks in the job.
    fn size(&self) -> usize;
    /// Sends `bytes` to rank `to`.
    fn send(&mut self, to: usize, bytes: &[u8]) -> Result<(), TransportError>;
    /// The next message from any rank, waiting at most `timeout`; `None` if nothing came.
    fn recv(&mut self, timeout: Duration) -> Result<Option<(usize, Vec<u8>)>, TransportError>;
    /// Ends the whole job at once, every rank, with status `code`: the only end of a job that
    /// has lost a rank, since a normal end waits for every rank (`MPI_Finalize` is collective).
    /// Over MPI it does not return; in process, every rank's sends and receives fail from then
    /// on.
    fn abort(&mut self, code: i32);
}

impl<T: Transport + ?Sized> Transport for Box<T> {
    fn rank(&self) -> usize {
        (**self).rank()
    }
    fn size(&self) -> usize {
        (**self).size()
    }
    fn send(&mut self, to: usize, bytes: &[u8]) -> Result<(), TransportError> {
        (**self).send(to, bytes)
    }
    fn recv(&mut self, timeout: Duration) -> Result<Option<(usize, Vec<u8>)>, TransportError> {
        (**self).recv(timeout)
    }
    fn abort(&mut self, code: i32) {
        (**self).abort(code);
    }
}

/// One rank of an in-process job.
#[derive(Debug)]
pub struct InProcess {
    rank: usize,
    inbox: Receiver<(usize, Vec<u8>)>,
    peers: Vec<Sender<(usize, Vec<u8>)>>,
    /// Set by any rank's [`Transport::abort`].
    aborted: Arc<AtomicBool>,
}

/// The ranks of an in-process job of `size` ranks, to be moved onto their threads.
pub fn in_process(size: usize) -> Vec<InProcess> {
    let (senders, inboxes): (Vec<_>, Vec<_>) = (0..size).map(|_| channel()).unzip();
    let aborted = Arc::new(AtomicBool::new(false));
    inboxes
        .into_iter()
        .enumerate()
        .map(|(rank, inbox)| InProcess { rank, inbox, peers: senders.clone(), aborted: aborted.clone() })
        .collect()
}

impl Transport for InProcess {
    fn rank(&self) -> usize {
        self.rank
    }

    fn size(&self) -> usize {
        self.peers.len()
    }

    fn send(&mut self, to: usize, bytes: &[u8]) -> Result<(), TransportError> {
        if self.aborted.load(Ordering::Relaxed) {
            return Err(TransportError::Aborted);
        }
        let peer = self.peers.get(to).ok_or(TransportError::Closed(to))?;
        peer.send((self.rank, bytes.to_vec())).map_err(|_| TransportError::Closed(to))
    }

    fn recv(&mut self, timeout: Duration) -> Result<Option<(usize, Vec<u8>)>, TransportError> {
        if self.aborted.load(Ordering::Relaxed) {
            return Err(TransportError::Aborted);
        }
        match self.inbox.recv_timeout(timeout) {
            Ok((rank, bytes)) if bytes.len() > MAX_MESSAGE => {
                Err(TransportError::TooLarge { rank, len: bytes.len() })
            }
            Ok(message) => Ok(Some(message)),
            Err(RecvTimeoutError::Timeout) => Ok(None),
            // Every rank holds a sender to every inbox, its own included: never disconnected.
            Err(RecvTimeoutError::Disconnected) => Err(TransportError::Closed(self.rank)),
        }
    }

    fn abort(&mut self, _code: i32) {
        self.aborted.store(true, Ordering::Relaxed);
    }
}
