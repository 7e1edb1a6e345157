//! Result lines on stdout (the `outln!` macro of the crate root): a closed pipe ends the
//! process quietly.

/// Writes one line to stdout; a closed pipe ends the process with status 0 (the reader has
/// what it wanted), any other write error with status 1.
pub fn write_stdout_line(args: std::fmt::Arguments) {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    if let Err(e) = out.write_fmt(args).and_then(|()| out.write_all(b"\n")) {
        if e.kind() == std::io::ErrorKind::BrokenPipe {
            std::process::exit(0);
        }
        crate::print_error(format_args!("cannot write to stdout: {e}"));
        std::process::exit(1);
    }
}
