//! [`LateProgress`]: the progress of long renders (`igi render`, the reference of `igi bench
//! quality`); [`Stages`]: what a command does before its first frame (loading the scene,
//! preparing it).
//!
//! Both show a bar or a spinner on a terminal and, when stderr is not one (a log, a pipe, CI),
//! a plain line every [`LINE_EVERY`] once a second has passed, `igi: rendering, 6.0 s: ...`, so
//! a long run says how far it is without flooding the log and a short one prints nothing.

use igi_render::{FrameDone, StoppingRule};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, RecvTimeoutError};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// How long a stage or a render runs before its progress shows.
const DELAY: Duration = Duration::from_secs(1);
/// Time between progress lines when stderr is not a terminal.
pub const LINE_EVERY: Duration = Duration::from_secs(5);

/// The progress of a render, shown only once it has taken more than a second, so quick renders
/// print nothing but their summary: a bar on a terminal, else (a log, a pipe) a line on
/// stderr every [`LINE_EVERY`]. A render of a fixed amount of work counts tiles (and the
/// frames done); a converging mean shows its time against the budget and the estimated error.
pub struct LateProgress {
    bar: ProgressBar,
    start: Instant,
    shown: AtomicBool,
    terminal: bool,
    /// The stopping rule of a converging mean.
    rule: Option<StoppingRule>,
    /// What the lines say beyond the tiles (not on a terminal).
    lines: Mutex<Lines>,
}

/// The state of [`LateProgress`]'s lines.
struct Lines {
    /// When the last line was printed, `None` before the first.
    last: Option<Instant>,
    /// Frames of the current image finished.
    frames: u32,
    /// What the last finished frame of a converging mean says.
    mean: String,
    /// `image K of N, ` while a sequence of N images renders, else empty.
    image: String,
}

impl LateProgress {
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
        let lines = Lines { last: None, frames: 0, mean: String::new(), image: String::new() };
        Self {
            bar,
            start: Instant::now(),
            shown: AtomicBool::new(false),
            terminal: std::io::stderr().is_terminal(),
            rule,
            lines: Mutex::new(lines),
        }
    }

    /// Image `k` (from 0) of a sequence of `of` starts: its frames count from 0, and the lines
    /// say which image it is.
    pub fn image(&self, k: u32, of: u32) {
        if let Ok(mut lines) = self.lines.lock() {
            lines.frames = 0;
            lines.mean.clear();
            lines.image = if of > 1 { format!("image {} of {of}, ", k + 1) } else { String::new() };
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
            self.line(done, total);
        }
    }

    /// A frame of the current image is finished.
    pub fn frame_done(&self, frame: &FrameDone) {
        let mean = self.rule.map(|rule| match frame.estimated_blotch {
            Some(b) => {
                format!("{} frame(s), estimated blotch10 {b:.3} (done at {:.3})", frame.frames, rule.target)
            }
            None => format!("{} frame(s)", frame.frames),
        });
        if let Some(mean) = &mean {
            self.bar.set_message(mean.clone());
        }
        if let Ok(mut lines) = self.lines.lock() {
            lines.frames = frame.frames;
            lines.mean = mean.unwrap_or_default();
        }
        if self.rule.is_some() {
            self.tile_done(0, 0);
        }
    }

    /// True once the delay has passed (the first time: the bar or lines start now).
    fn due(&self) -> bool {
        !self.shown.load(Ordering::Relaxed)
            && self.start.elapsed() > DELAY
            && !self.shown.swap(true, Ordering::Relaxed)
    }

    /// Prints where the render is on stderr if the last line is [`LINE_EVERY`] old (the first
    /// after [`DELAY`]): the tiles of a fixed amount of work and the frames done, or the last
    /// frame of a converging mean (the tiles of its first frame until it has one).
    fn line(&self, done: u32, total: u32) {
        if self.start.elapsed() <= DELAY {
            return;
        }
        let Ok(mut lines) = self.lines.lock() else { return };
        if lines.last.is_some_and(|last| last.elapsed() < LINE_EVERY) {
            return;
        }
        let what = match (self.rule, lines.frames) {
            (None, 0) => format!("{done}/{total} tiles"),
            (None, frames) => format!("{done}/{total} tiles, {frames} frame(s) done"),
            (Some(_), 0) if total > 0 => format!("first frame, {done}/{total} tiles"),
            (Some(_), 0) => return,
            (Some(_), _) => lines.mean.clone(),
        };
        lines.last = Some(Instant::now());
        eprintln!("igi: rendering, {:.1} s: {}{what}", self.start.elapsed().as_secs_f64(), lines.image);
    }

    /// Clears the bar.
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

/// The stage a command is in before it can render (loading the scene, preparing it: the BVH,
/// the shading tables, the default light), with the time it has taken: the power plant takes
/// tens of seconds. On a terminal a spinner if asked for (the viewers, whose window or page
/// shows nothing meanwhile; `igi render` keeps the terminal for its bar); elsewhere a line
/// every [`LINE_EVERY`] from a second on, `igi: loading power-plant, 6.0 s`. Dropping it ends
/// the spinner or the lines.
pub struct Stages {
    spinner: Option<ProgressBar>,
    /// The current stage and when it began.
    current: Arc<Mutex<(String, Instant)>>,
    /// Ends the line thread when dropped, and the thread.
    lines: Option<(mpsc::Sender<()>, JoinHandle<()>)>,
}

impl Stages {
    /// Starts at `stage`: a spinner on a terminal, lines elsewhere.
    pub fn spinner(stage: String) -> Self {
        Self::start(stage, true)
    }

    /// Starts at `stage`: nothing on a terminal, lines elsewhere.
    pub fn lines_only(stage: String) -> Self {
        Self::start(stage, false)
    }

    fn start(stage: String, spinner: bool) -> Self {
        let current = Arc::new(Mutex::new((stage.clone(), Instant::now())));
        if std::io::stderr().is_terminal() {
            let spinner = spinner.then(|| {
                let bar = ProgressBar::new_spinner();
                if let Ok(style) = ProgressStyle::with_template("{spinner} {msg} ({elapsed})") {
                    bar.set_style(style);
                }
                bar.set_message(stage);
                bar.enable_steady_tick(Duration::from_millis(120));
                bar
            });
            return Self { spinner, current, lines: None };
        }
        let (stop, stopped) = mpsc::channel::<()>();
        let shared = Arc::clone(&current);
        let thread = std::thread::spawn(move || {
            let mut next = Instant::now() + DELAY;
            // Woken by the time of the next line; the sender's drop ends the loop.
            while let Err(RecvTimeoutError::Timeout) =
                stopped.recv_timeout(next.saturating_duration_since(Instant::now()))
            {
                if let Ok(current) = shared.lock() {
                    eprintln!("igi: {}, {:.1} s", current.0, current.1.elapsed().as_secs_f64());
                }
                next += LINE_EVERY;
            }
        });
        Self { spinner: None, current, lines: Some((stop, thread)) }
    }

    /// Moves `stages` (the loading's, if it had any) on to preparing `scene`, or starts there
    /// through `start` ([`Stages::spinner`] or [`Stages::lines_only`]) where there were none.
    pub fn preparing(stages: Option<Self>, scene: &str, start: fn(String) -> Self) -> Self {
        let preparing = format!("preparing {scene} (BVH, shading tables, lights)");
        match stages {
            Some(stages) => {
                stages.stage(preparing);
                stages
            }
            None => start(preparing),
        }
    }

    /// Moves on to `stage`.
    pub fn stage(&self, stage: String) {
        if let Some(spinner) = &self.spinner {
            spinner.set_message(stage.clone());
        }
        if let Ok(mut current) = self.current.lock() {
            *current = (stage, Instant::now());
        }
    }
}

impl Drop for Stages {
    fn drop(&mut self) {
        if let Some(spinner) = &self.spinner {
            spinner.finish_and_clear();
        }
        if let Some((stop, thread)) = self.lines.take() {
            drop(stop);
            let _ = thread.join();
        }
    }
}
