//! [`LateProgress`]: the progress bar of long renders (`igi render`, the reference of `igi
//! bench quality`); [`StageSpinner`]: what a viewer does before its first frame.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// A progress bar that appears only once a render has taken more than a second (and only on
/// a terminal), so quick renders print nothing but their summary.
pub struct LateProgress {
    bar: ProgressBar,
    start: Instant,
    shown: AtomicBool,
}

impl LateProgress {
    const DELAY: Duration = Duration::from_secs(1);

    /// A hidden bar; it shows once a second has passed.
    pub fn new() -> Self {
        let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::hidden());
        if let Ok(style) = ProgressStyle::with_template("{bar:40} {pos}/{len} tiles, {elapsed} (eta {eta})") {
            bar.set_style(style);
        }
        Self { bar, start: Instant::now(), shown: AtomicBool::new(false) }
    }

    /// `done` of `total` tiles are finished.
    pub fn tile_done(&self, done: u32, total: u32) {
        if !self.shown.load(Ordering::Relaxed)
            && self.start.elapsed() > Self::DELAY
            && !self.shown.swap(true, Ordering::Relaxed)
        {
            self.bar.set_length(u64::from(total));
            self.bar.set_draw_target(ProgressDrawTarget::stderr());
        }
        self.bar.set_position(u64::from(done));
    }

    /// Clears the bar.
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

/// A spinner on the terminal naming the stage a viewer is in before its window or page can show
/// anything (loading the scene, building the BVH), with the time it has taken: the power plant
/// takes tens of seconds. Nothing is drawn when stderr is not a terminal.
pub struct StageSpinner {
    bar: ProgressBar,
}

impl StageSpinner {
    /// A spinner showing `stage`.
    pub fn new(stage: String) -> Self {
        let bar = ProgressBar::new_spinner();
        if let Ok(style) = ProgressStyle::with_template("{spinner} {msg} ({elapsed})") {
            bar.set_style(style);
        }
        bar.set_message(stage);
        bar.enable_steady_tick(Duration::from_millis(120));
        Self { bar }
    }

    /// Moves on to `stage`.
    pub fn stage(&self, stage: String) {
        self.bar.set_message(stage);
    }
}

impl Drop for StageSpinner {
    fn drop(&mut self) {
        self.bar.finish_and_clear();
    }
}
