//! [`ClusterSource`]: a viewer session's frames rendered by a cluster. Rank 0 runs the
//! session (input, clock, display); each frame becomes a [`FrameJob`] for the nodes. Moving
//! frames come back as 8-bit pixels, accumulating still frames as linear radiance.

use crate::error::ClusterError;
use crate::master::Master;
use crate::protocol::{FrameJob, PixelFormat};
use crate::transport::Transport;
use igi_render::output::to_srgb8;
use igi_render::{CancelToken, Cancelled, FrameState, PreparedScene};
use igi_session::{FrameSource, ScenePose, SourceError, SourceFrame};

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
    fn render_cancellable(
        &mut self,
        _scene: &PreparedScene,
        pose: &ScenePose,
        frame: &FrameState,
        linear: bool,
        cancel: &CancelToken,
    ) -> Result<SourceFrame, SourceError> {
        let job = FrameJob {
            id: 0,
            state: *frame,
            time: pose.time,
            moved: pose.moved.clone(),
            pixels: if linear { PixelFormat::Linear } else { PixelFormat::Srgb8 },
        };
        let fail = |e: ClusterError| {
            (self.on_failure)(&e);
            SourceError::Failed(e.to_string())
        };
        self.master.begin(job).map_err(fail)?;
        // A cancelled frame is abandoned on rank 0; the nodes drop its tiles with the next job.
        let out =
            self.master.finish_cancellable(cancel).map_err(fail)?.ok_or(SourceError::Cancelled(Cancelled))?;
        let srgb8 = match (out.srgb8, &out.film) {
            (Some(bytes), _) => bytes,
            (None, Some(film)) => to_srgb8(film, &frame.tone_map),
            (None, None) => unreachable!("a frame has one of the two images"),
        };
        Ok(SourceFrame {
            film: out.film,
            srgb8,
            stats: out.stats,
            rays: out.rays,
            times: out.times,
            vpls: out.vpls,
        })
    }

    fn threads(&self) -> usize {
        self.master.threads()
    }
}
