//! What an image will take in memory, said before the render starts (issue 35): a 16384x16384
//! render grew past 8 GB with no word beforehand. The estimate is the frame's bound
//! ([`FRAME_BYTES_PER_PIXEL`], [`FRAME_BYTES_PER_THREAD`], held by a test) without the scene,
//! which is not loaded yet; a render that cannot fit the machine's memory is refused, one that
//! fits only in more than what is free now gets a warning.

use anyhow::{Result, bail};
use igi_render::schedule::frame_renderer::{FRAME_BYTES_PER_PIXEL, FRAME_BYTES_PER_THREAD};

/// A byte count in GiB for messages.
fn gib(bytes: u64) -> String {
    format!("{:.1} GiB", bytes as f64 / f64::from(1u32 << 30))
}

/// The machine's memory and what is available now, in bytes (Linux: `/proc/meminfo`);
/// `None` where it cannot be told.
fn machine_memory() -> Option<(u64, u64)> {
    let info = std::fs::read_to_string("/proc/meminfo").ok()?;
    let field = |name: &str| -> Option<u64> {
        let line = info.lines().find(|l| l.starts_with(name))?;
        let kib: u64 = line[name.len()..].trim().trim_end_matches("kB").trim().parse().ok()?;
        Some(kib * 1024)
    };
    Some((field("MemTotal:")?, field("MemAvailable:")?))
}

/// Refuses a `width` × `height` render on `threads` threads that cannot fit this machine's
/// memory, and warns about one that needs more than is free now.
pub fn check(width: u32, height: u32, threads: usize) -> Result<()> {
    let threads =
        if threads == 0 { std::thread::available_parallelism().map_or(1, usize::from) } else { threads };
    let needed = u64::from(width) * u64::from(height) * FRAME_BYTES_PER_PIXEL
        + threads as u64 * FRAME_BYTES_PER_THREAD;
    let Some((total, available)) = machine_memory() else { return Ok(()) };
    let what = format!(
        "a {width}x{height} image needs about {} to render ({FRAME_BYTES_PER_PIXEL} bytes a pixel, \
         besides the scene)",
        gib(needed)
    );
    if needed > total {
        bail!("{what}, more than this machine's {}: render it smaller", gib(total));
    }
    if needed > available {
        tracing::warn!("{what}, more than the {} free now: the machine may swap", gib(available));
    }
    Ok(())
}
