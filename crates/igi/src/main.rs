//! `igi`: the command line of the interactive global-illumination renderer.
//!
//! `main` only checks the CPU and hands over: this build may use AVX2/FMA instructions anywhere
//! in its own code, so nothing of it runs before [`cpu_check::require_cpu_features`].

/// `println!` that ends the process quietly (status 0) when stdout is a closed pipe, as in
/// `igi info scene.obj | head`, instead of panicking.
macro_rules! outln {
    ($($arg:tt)*) => {
        $crate::stdout::write_stdout_line(format_args!($($arg)*))
    };
}

mod bench;
mod camera_args;
mod cli;
mod cluster;
mod cmd_info;
mod cmd_render;
mod cmd_serve;
mod cmd_view;
mod cmd_worker;
mod cpu_check;
mod frame_args;
mod interrupt;
mod progress;
mod render_memory;
mod scene_load;
mod stdout;
mod viewer_args;

use std::process::ExitCode;

fn main() -> ExitCode {
    cpu_check::require_cpu_features();
    run()
}

/// Everything after the CPU check: arguments, logging, the subcommand, error reporting.
#[inline(never)]
fn run() -> ExitCode {
    let cli = <cli::Cli as clap::Parser>::parse();
    cli::init_logging();
    match cli::dispatch(cli.command) {
        Ok(()) => ExitCode::SUCCESS,
        Err(err) => {
            print_error(one_line(&err));
            ExitCode::FAILURE
        }
    }
}

/// Prints an error on stderr the one way igi prints them: `error: MESSAGE`, the form clap gives
/// a mistyped flag, so a user (and a script reading the log) sees one form whatever failed.
pub(crate) fn print_error(message: impl std::fmt::Display) {
    eprintln!("error: {message}");
}

/// The error and its causes on one line, `a: b: c`, without a backtrace. A cause whose text
/// the message already ends with (errors that print their source themselves) is not repeated.
fn one_line(err: &anyhow::Error) -> String {
    let mut line = String::new();
    for cause in err.chain() {
        let text = cause.to_string();
        if line.is_empty() {
            line = text;
        } else if !line.ends_with(&text) {
            line.push_str(": ");
            line.push_str(&text);
        }
    }
    line.replace('\n', " ")
}
