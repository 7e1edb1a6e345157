//! [`LateProgress`]: the progress of long renders (`igi render`, the reference of `igi bench
//! quality`); [`StageSpinner`]: what a viewer does before its first frame.

use igi_render::{FrameDone, StoppingRule};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// The progress of a render, shown only once it has taken more than a second, so quick renders
/// print nothing but their summary: a bar on a terminal, else (a log, a pipe) a line on
/// stderr every [`LateProgress::LINE_EVERY`]. A render of a fixed amount of work counts tiles;
/// a converging mean shows its time against the budget and the estimated error.
pub struct LateProgress {
    bar: ProgressBar,
    start: Instant,
    shown: AtomicBool,
    terminal: bool,
    /// The stopping rule of a converging mean.
    rule: Option<StoppingRule>,
    /// When the last line was printed (not on a terminal), and what the frames say.
    last_line: Mutex<(Instant, String)>,
}

impl LateProgress {
    const DELAY: Duration = Duration::from_secs(1);
    /// Time between progress lines when stderr is not a terminal.
    pub const LINE_EVERY: Duration = Duration::from_secs(5);

    /// A hidden bar for work counted in tiles; it shows once a second has passed.
    pub fn new() -> Self {
        Self::with_rule(None)
    }

    /// A hidden bar for a mean that converges by `rule` (`None`: work counted in tiles).
    pub fn with_rule(rule: Option<StoppingRule>) -> Self {
        let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::hidden());
        let template = match rule {
            None => "{bar:40} {pos}/{len} tiles, {elapsed} (eta {eta})",
            Some(_) => "{bar:40} {elapsed} of the time budget: {msg}",
        };
        if let Ok(style) = ProgressStyle::with_template(template) {
            bar.set_style(style);
        }
        let start = Instant::now();
        Self {
            bar,
            start,
            shown: AtomicBool::new(false),
            terminal: std::io::stderr().is_terminal(),
            rule,
            last_line: Mutex::new((start, String::new())),
        }
    }

    /// `done` of `total` tiles are finished.
    pub fn tile_done(&self, done: u32, total: u32) {
        let (position, length) = match self.rule {
            None => (u64::from(done), u64::from(total)),
            Some(rule) => (self.start.elapsed().as_millis() as u64, rule.time_budget.as_millis() as u64),
        };
        if self.due() && self.terminal {
            self.bar.set_length(length);
            self.bar.set_draw_target(ProgressDrawTarget::stderr());
        }
        self.bar.set_position(position);
        if !self.terminal {
            let what = match self.rule {
                None => format!("{done}/{total} tiles"),
                Some(_) => self.last_line.lock().map(|l| l.1.clone()).unwrap_or_default(),
            };
            self.line(&what);
        }
    }

    /// A frame of a converging mean is finished.
    pub fn frame_done(&self, frame: &FrameDone) {
        let Some(rule) = self.rule else { return };
        let what = match frame.estimated_blotch {
            Some(b) => {
                format!("{} frame(s), estimated blotch10 {b:.3} (done at {:.3})", frame.frames, rule.target)
            }
            None => format!("{} frame(s)", frame.frames),
        };
        self.bar.set_message(what.clone());
        if let Ok(mut last) = self.last_line.lock() {
            last.1 = what.clone();
        }
        self.tile_done(0, 0);
    }

    /// True once the delay has passed (the first time: the bar or lines start now).
    fn due(&self) -> bool {
        !self.shown.load(Ordering::Relaxed)
            && self.start.elapsed() > Self::DELAY
            && !self.shown.swap(true, Ordering::Relaxed)
    }

    /// Prints `what` on stderr if the last line is [`Self::LINE_EVERY`] old.
    fn line(&self, what: &str) {
        if self.start.elapsed() <= Self::DELAY || what.is_empty() {
            return;
        }
        let Ok(mut last) = self.last_line.lock() else { return };
        if last.0 != self.start && last.0.elapsed() < Self::LINE_EVERY {
            return;
        }
        last.0 = Instant::now();
        eprintln!("igi: rendering, {:.1} s: {what}", self.start.elapsed().as_secs_f64());
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
