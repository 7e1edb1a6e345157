//! Progress in a log (issue 34): with stderr a file, as under a job scheduler or `2> log`, a long
//! render says how far it is every few seconds, from loading the scene to its frames, and a
//! short stage says nothing; no terminal bar or escape code reaches the file.

use std::process::{Command, Stdio};
use std::time::Instant;

const IGI: &str = env!("CARGO_BIN_EXE_igi");

#[test]
fn a_long_render_into_a_log_file_reports_its_stages_and_frames() {
    let dir = tempfile::tempdir().unwrap();
    let log_path = dir.path().join("igi.log");
    let start = Instant::now();
    // A plant of 4 million triangles: a second or more to load and prepare, a few to render.
    let out = Command::new(IGI)
        .args(["render", "power-plant:triangles=1M", "--width", "640", "--height", "480"])
        .args(["--time-budget", "3", "-o"])
        .arg(dir.path().join("plant.png"))
        .stderr(Stdio::from(std::fs::File::create(&log_path).unwrap()))
        .output()
        .unwrap();
    let seconds = start.elapsed().as_secs_f64();
    let log = std::fs::read_to_string(&log_path).unwrap();
    assert!(out.status.success(), "{log}");
    let summary = String::from_utf8(out.stdout).unwrap();
    // The summary's "load X s, prepare Y s": a stage line is due once they took over a second.
    let figure = |name: &str| -> f64 {
        let at = summary.find(&format!("{name} ")).unwrap_or_else(|| panic!("{name} in {summary}"));
        summary[at + name.len() + 1..].split(' ').next().unwrap().parse().unwrap()
    };
    if figure("load") + figure("prepare") > 1.2 {
        assert!(
            log.contains("igi: loading power-plant") || log.contains("igi: preparing power-plant"),
            "no stage line after {} s:\n{log}",
            figure("load") + figure("prepare")
        );
    }
    // The time budget keeps frames coming for 3 s: the first line after a second.
    assert!(log.contains("igi: rendering, 1."), "no progress line:\n{log}");
    assert!(!log.contains('\r') && !log.contains('\u{1b}'), "a terminal's bar in a file: {log:?}");
    // Not flooded: a line per stage and then one every 5 s at most.
    let lines = log.lines().filter(|l| l.starts_with("igi: ")).count();
    assert!(lines as f64 <= 3.0 + seconds / 5.0, "{lines} lines in {seconds:.1} s:\n{log}");
}
