//! Ctrl-C (SIGINT) and SIGTERM during a command that writes files (`render`, `bench`): the
//! process ends at once, as the signals' default action ends it, but first removes the
//! temporary files of the writes under way, which the default action left behind as hidden
//! `.NAME.XXXXXX.tmp` files beside the outputs. The outputs themselves stay as they were, or
//! are already whole (ARCHITECTURE.md, "Output files are replaced, never rewritten in place").

use igi_render::image::output::end_writes;
use signal_hook::consts::{SIGINT, SIGTERM};
use signal_hook::iterator::Signals;

/// From now on, SIGINT or SIGTERM removes the temporary files of the writes under way and
/// ends the process with status 128 + the signal's number (130 for Ctrl-C), as a shell
/// reports a process the signal ended.
pub fn end_writes_on_signal() -> std::io::Result<()> {
    let mut signals = Signals::new([SIGINT, SIGTERM])?;
    std::thread::Builder::new().name("igi-signals".into()).spawn(move || {
        if let Some(signal) = signals.forever().next() {
            // Held until the process is gone, so no write starts meanwhile.
            let _writes = end_writes();
            eprintln!("igi: interrupted");
            std::process::exit(128 + signal);
        }
    })?;
    Ok(())
}
