//! SIGINT and SIGTERM end the viewers in the middle of a frame of minutes: `igi serve`, and
//! `igi view` in a real window under Xvfb (skipped, with a message, where `Xvfb` is missing).
//! Each exits cleanly (status 0) within a few seconds, where the frame alone would take a
//! minute or more: the render loop cancels the frame between tiles. (Before, `igi serve`
//! waited for the frame to finish, and `igi view` was killed by the signal's default action,
//! so a cluster session could not stop its nodes.)

use std::io::{BufRead, BufReader, Read};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

const IGI: &str = env!("CARGO_BIN_EXE_igi");

/// A frame of a minute or more on one thread: 1280x960 pixels, each with 64 primary rays and
/// 4096 VPLs (3 · 10⁹ rays, 57 Mrays/s on an idle core; a tile takes about a quarter of a
/// second).
const LONG_FRAME: [&str; 12] = [
    "cornell-box",
    "--width",
    "1280",
    "--height",
    "960",
    "--vpls",
    "4096",
    "--aa",
    "64",
    "--threads",
    "1",
    "--paused",
];

/// How long the process may take to end after the signal.
const BOUND: Duration = Duration::from_secs(5);

/// Sends `signal` (a `kill` name) to `child` and waits for it to end; returns how long it
/// took, and its status and stderr.
fn stop(mut child: Child, signal: &str) -> (Duration, std::process::ExitStatus, String) {
    let start = Instant::now();
    let sent = Command::new("kill").args([&format!("-{signal}"), &child.id().to_string()]).status().unwrap();
    assert!(sent.success(), "kill -{signal} failed");
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            let mut stderr = String::new();
            if let Some(mut pipe) = child.stderr.take() {
                pipe.read_to_string(&mut stderr).unwrap();
            }
            return (start.elapsed(), status, stderr);
        }
        if start.elapsed() > 4 * BOUND {
            child.kill().unwrap();
            child.wait().unwrap();
            panic!("still running {:?} after SIG{signal}", start.elapsed());
        }
        std::thread::sleep(Duration::from_millis(10));
    }
}

#[test]
fn serve_ends_within_seconds_of_sigint_or_sigterm_mid_frame() {
    for signal in ["INT", "TERM"] {
        let mut serve = Command::new(IGI)
            .args(["serve", "--listen", "127.0.0.1:0", "--max-frame-mrays", "100000"])
            .args(LONG_FRAME)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        // "igi serve: open http://127.0.0.1:PORT/ ...": the render loop starts right after.
        // (The pipe stays open until the process has ended.)
        let mut stdout = BufReader::new(serve.stdout.take().unwrap());
        let mut line = String::new();
        stdout.read_line(&mut line).unwrap();
        assert!(line.contains("open http://"), "{line}");
        std::thread::sleep(Duration::from_secs(1));
        let (took, status, stderr) = stop(serve, signal);
        drop(stdout);
        eprintln!("igi serve ended {took:?} after SIG{signal}");
        assert!(status.success(), "igi serve after SIG{signal}: {status}: {stderr}");
        assert!(took < BOUND, "igi serve took {took:?} to end after SIG{signal}");
    }
}

#[test]
fn serve_refuses_starting_settings_over_its_frame_budget() {
    let out = Command::new(IGI)
        .arg("serve")
        .args(LONG_FRAME)
        .args(["--max-frame-mrays", "100", "--listen", "127.0.0.1:0"])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(stderr.contains("--max-frame-mrays") && stderr.contains("5112 million rays"), "{stderr}");
}

#[test]
fn view_ends_within_seconds_of_sigint_or_sigterm_mid_frame() {
    // Xvfb says which display it took on the descriptor -displayfd names.
    let Ok(xvfb) = Command::new("Xvfb")
        .args(["-displayfd", "1", "-screen", "0", "1600x1200x24", "-nolisten", "tcp"])
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
    else {
        eprintln!("skipped: the window test needs Xvfb (apt-get install -y xvfb libgl1-mesa-dri)");
        return;
    };
    let mut xvfb = Killed(xvfb);
    let mut display = String::new();
    BufReader::new(xvfb.0.stdout.take().unwrap()).read_line(&mut display).unwrap();
    let display = format!(":{}", display.trim());
    for signal in ["INT", "TERM"] {
        let view = Command::new(IGI)
            .arg("view")
            .args(LONG_FRAME)
            .env("DISPLAY", &display)
            .env_remove("WAYLAND_DISPLAY")
            .env("LIBGL_ALWAYS_SOFTWARE", "1")
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        // The window opens and the first frame starts well within this.
        std::thread::sleep(Duration::from_secs(3));
        let (took, status, stderr) = stop(view, signal);
        eprintln!("igi view ended {took:?} after SIG{signal}");
        assert!(status.success(), "igi view after SIG{signal}: {status}: {stderr}");
        assert!(took < BOUND, "igi view took {took:?} to end after SIG{signal}");
    }
}

/// A process killed when the test ends, however it ends.
struct Killed(Child);

impl Drop for Killed {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

#[test]
fn a_render_interrupted_while_writing_leaves_no_temporary_file() {
    // SIGINT while the image is being written: the default action left the hidden temporary
    // file behind (5 of 13 4K EXR runs). The signal is sent as soon as it appears.
    let folder = tempfile::tempdir().unwrap();
    let child = Command::new(IGI)
        .current_dir(folder.path())
        .args([
            "render",
            "cornell-box",
            "--frames",
            "1",
            "--width",
            "2560",
            "--height",
            "1440",
            "-o",
            "x.exr",
        ])
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // A temporary file with bytes in it: the image's, not the empty one that tries the folder
    // before rendering.
    let temporary = || {
        std::fs::read_dir(folder.path()).unwrap().filter_map(Result::ok).any(|e| {
            e.file_name().to_string_lossy().ends_with(".tmp") && e.metadata().is_ok_and(|m| m.len() > 0)
        })
    };
    let start = Instant::now();
    while !temporary() {
        assert!(start.elapsed() < Duration::from_secs(120), "no temporary file appeared");
        std::thread::sleep(Duration::from_micros(200));
    }
    let (took, status, stderr) = stop(child, "INT");
    assert!(took < BOUND, "{took:?}");
    let left: Vec<String> = std::fs::read_dir(folder.path())
        .unwrap()
        .filter_map(Result::ok)
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    // Either the write was interrupted (status 130, nothing there) or it had just finished.
    assert!(left.iter().all(|name| name == "x.exr"), "left behind: {left:?} ({status}: {stderr})");
    assert!(status.code() == Some(130) || left == ["x.exr"], "{status}: {stderr}");
}
