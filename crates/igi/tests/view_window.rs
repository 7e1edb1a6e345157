//! `igi view` in a real window under Xvfb: `--screenshot` writes the window's framebuffer, and
//! its image region equals the PNG `igi render` writes for the same frame (same scene, time,
//! settings and fixed exposure). Skipped, with a message, where `xvfb-run` is missing (CI
//! installs it: see `.ci/run`). Also: without a display, `igi view` fails with a clear
//! message instead of a panic.

use std::path::{Path, PathBuf};
use std::process::Command;

const IGI: &str = env!("CARGO_BIN_EXE_igi");

fn temp(name: &str) -> PathBuf {
    std::env::temp_dir().join(format!("igi-view-{}-{name}", std::process::id()))
}

fn has_xvfb() -> bool {
    Command::new("sh").args(["-c", "command -v xvfb-run"]).output().is_ok_and(|o| o.status.success())
}

/// The frame options shared by both commands: a paused animated room at 1.3 s.
const FRAME: [&str; 11] =
    ["animated-room", "--width", "320", "--height", "240", "--aa", "1", "--exposure", "0", "--time", "1.3"];

fn load(path: &Path) -> image::RgbImage {
    image::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display())).to_rgb8()
}

#[test]
fn the_window_shows_the_rendered_frame_pixel_for_pixel() {
    if !has_xvfb() {
        eprintln!("skipped: the window test needs xvfb-run (apt-get install -y xvfb xauth libgl1-mesa-dri)");
        return;
    }
    let (shot, reference) = (temp("shot.png"), temp("render.png"));
    let view = Command::new("xvfb-run")
        .args(["-a", "-s", "-screen 0 1280x1024x24", IGI, "view"])
        .args(FRAME)
        .args(["--paused", "--no-accumulate", "--exit-after-frames", "3", "--screenshot"])
        .arg(&shot)
        .env("LIBGL_ALWAYS_SOFTWARE", "1")
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&view.stdout);
    assert!(view.status.success(), "igi view failed: {stdout}{}", String::from_utf8_lossy(&view.stderr));
    // "image at X,Y size WxH in window screenshot W'xH' -> FILE"
    let at: Vec<u32> = stdout
        .split_once("image at ")
        .and_then(|(_, rest)| rest.split_once(" in window"))
        .map(|(place, _)| place.split([',', ' ', 'x']).filter_map(|t| t.parse().ok()).collect())
        .unwrap_or_default();
    assert_eq!(at.len(), 4, "igi view says where the image is: {stdout}");
    assert_eq!(at[2..], [320, 240]);

    let render = Command::new(IGI).arg("render").args(FRAME).arg("-o").arg(&reference).output().unwrap();
    assert!(render.status.success(), "{}", String::from_utf8_lossy(&render.stderr));

    let window = load(&shot);
    let expected = load(&reference);
    let crop = image::imageops::crop_imm(&window, at[0], at[1], 320, 240).to_image();
    let worst = crop
        .pixels()
        .zip(expected.pixels())
        .map(|(a, b)| a.0.iter().zip(b.0).map(|(x, y)| x.abs_diff(y)).max().unwrap_or(0))
        .max()
        .unwrap_or(0);
    // Both are the same 8-bit encoding of the same frame; allow one level of rounding.
    assert!(worst <= 1, "the window's image differs from igi render by up to {worst} levels");
    let _ = std::fs::remove_file(shot);
    let _ = std::fs::remove_file(reference);
}

#[test]
fn without_a_display_view_says_so() {
    let out = Command::new(IGI)
        .args(["view", "cornell-box"])
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .output()
        .unwrap();
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("needs a display") && !stderr.contains("panicked"), "{stderr}");
}
