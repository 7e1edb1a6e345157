//! [`ClusterError`]: everything that ends a cluster job, each naming the rank at fault.

use crate::protocol::DecodeError;
use crate::transport::TransportError;
use std::time::Duration;

/// Why a cluster job cannot go on.
#[derive(Debug, thiserror::Error)]
pub enum ClusterError {
    /// Sending or receiving failed.
    #[error(transparent)]
    Transport(#[from] TransportError),
    /// A rank sent bytes that are not a message.
    #[error("rank {rank}: {error}")]
    Decode {
        /// The sender.
        rank: usize,
        /// What is wrong.
        error: DecodeError,
    },
    /// A rank sent a message out of turn or with impossible contents.
    #[error("rank {rank} broke the protocol: {message}")]
    Protocol {
        /// The sender.
        rank: usize,
        /// What it did.
        message: String,
    },
    /// A node loaded a different scene than rank 0.
    #[error(
        "rank {rank} loaded a different scene (digest {theirs:016x}, rank 0 has {ours:016x}): give every rank the same files, or use --broadcast-scene"
    )]
    SceneMismatch {
        /// The node.
        rank: usize,
        /// Rank 0's digest.
        ours: u64,
        /// The node's digest.
        theirs: u64,
    },
    /// A node gave up and said why.
    #[error("rank {rank} failed: {message}")]
    NodeFailed {
        /// The node.
        rank: usize,
        /// Its reason.
        message: String,
    },
    /// A node has not been heard from for too long: it died or hangs.
    #[error("rank {rank} has not answered for {:.1} s: it died or hangs", silent.as_secs_f64())]
    NodeLost {
        /// The node.
        rank: usize,
        /// How long it has been silent.
        silent: Duration,
    },
    /// The job has no render nodes.
    #[error("the cluster job has only rank 0: start at least 2 ranks (mpirun -n 2 or more)")]
    NoWorkers,
    /// The frame's settings are invalid.
    #[error(transparent)]
    Settings(#[from] igi_render::frame::SettingsError),
}
