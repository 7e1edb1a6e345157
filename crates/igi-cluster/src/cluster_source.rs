//! [`ClusterSource`]: frames rendered by a cluster, for `igi render` or a viewer session on
//! rank 0 (input, clock, display); each frame becomes a [`FrameJob`] for the nodes, which run
//! the frame's estimator. Moving frames come back as 8-bit pixels, accumulating still frames
//! as linear radiance.

use crate::error::ClusterError;
use crate::master::Master;
use crate::protocol::FrameJob;
use crate::transport::Transport;
use igi_render::{CancelToken, Cancelled, FrameError, FrameOutput, FrameSource, FrameState, PreparedScene};

/// What to do when the cluster fails mid-session: end the job (an MPI abort, so no rank is
/// left waiting) after the message is shown.
pub type OnFailure = Box<dyn Fn(&ClusterError) + Send>;

/// A [`FrameSource`] backed by a cluster's render nodes.
pub struct ClusterSource<T: Transport> {
    master: Master<T>,
    on_failure: OnFailure,
}

impl<T: Transport> std::fmt::Debug for ClusterSource<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ClusterSource").field("nodes", &self.master.nodes()).finish_non_exhaustive()
    }
}

impl<T: Transport> ClusterSource<T> {
    /// Frames from `master`'s nodes; `on_failure` runs before an error is returned.
    pub fn new(master: Master<T>, on_failure: OnFailure) -> Self {
        Self { master, on_failure }
    }
}

impl<T: Transport> FrameSource for ClusterSource<T> {
    fn render_frame(
        &mut self,
        scene: &mut PreparedScene,
        frame: &FrameState,
        cancel: &CancelToken,
        _progress: &(dyn Fn(u32, u32) + Sync),
    ) -> Result<FrameOutput, FrameError> {
        let fail = |e: ClusterError| {
            (self.on_failure)(&e);
            FrameError::Failed(e.to_string())
        };
        self.master.begin(FrameJob { id: 0, frame: frame.clone() }).map_err(fail)?;
        // Rank 0's copy of the scene answers the session's picks: it stands where the nodes'
        // copies do.
        scene.pose(&frame.pose);
        // A cancelled frame is abandoned on rank 0; the nodes drop its tiles with the next job.
        let out =
            self.master.finish_cancellable(cancel).map_err(fail)?.ok_or(FrameError::Cancelled(Cancelled))?;
        Ok(out.output)
    }

    fn threads(&self) -> usize {
        self.master.threads()
    }

    fn prefers_srgb8(&self) -> bool {
        true
    }
}
