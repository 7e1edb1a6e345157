//! Every example of the README runs as a newcomer would type it (issue 34): the files it asks
//! to save are written to a fresh folder, and every command of its `sh` blocks runs there with
//! the `igi` this build made, exits 0, warns about nothing and writes the files it names.
//!
//! What the test changes, and why: images are rendered at 160x120 with a time budget of 2 s
//! (the commands' flags, scenes and files are what is checked, not the picture's quality,
//! which the first-sight and quality tests judge); `igi serve` listens on a free port and is
//! stopped once it has served its page; `igi view` runs under Xvfb for a few frames (skipped,
//! with a message, without `xvfb-run`). The `cargo` commands of the README are the build and
//! this test suite themselves, so they are recognised and not run again. Blocks marked `text`
//! (the cluster's `mpirun` lines, command summaries) are syntax, not examples; the cluster's
//! launches are run by `cluster_mpi.rs`.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const IGI: &str = env!("CARGO_BIN_EXE_igi");

/// A fenced block of the README: its language, its lines, and the `<!-- readme-test: ... -->`
/// note just above it, if any.
struct Block {
    language: String,
    text: String,
    note: Option<String>,
    line: usize,
}

fn blocks(readme: &str) -> Vec<Block> {
    let mut blocks = Vec::new();
    let mut note = None;
    let mut lines = readme.lines().enumerate();
    while let Some((number, line)) = lines.next() {
        if let Some(rest) = line.strip_prefix("<!-- readme-test:") {
            note = Some(rest.trim_end_matches("-->").trim().to_string());
            continue;
        }
        let Some(language) = line.strip_prefix("```") else {
            if !line.trim().is_empty() {
                note = None;
            }
            continue;
        };
        let mut text = String::new();
        for (_, line) in lines.by_ref() {
            if line.starts_with("```") {
                break;
            }
            text.push_str(line);
            text.push('\n');
        }
        blocks.push(Block {
            language: language.trim().to_string(),
            text,
            note: note.take(),
            line: number + 1,
        });
    }
    blocks
}

/// The value after `flag` in `args`, replaced by `value` (or both appended).
fn set_flag(args: &mut Vec<String>, flag: &str, value: &str) {
    match args.iter().position(|a| a == flag) {
        Some(i) if i + 1 < args.len() => args[i + 1] = value.to_string(),
        _ => args.extend([flag.to_string(), value.to_string()]),
    }
}

fn has_xvfb() -> bool {
    Command::new("sh").args(["-c", "command -v xvfb-run"]).output().is_ok_and(|o| o.status.success())
}

/// Runs `igi serve` with `args` on a free port until its page answers, then stops it.
fn serve(args: &[String], folder: &Path, what: &str) {
    let mut args = args.to_vec();
    set_flag(&mut args, "--listen", "127.0.0.1:0");
    let mut child = Command::new(IGI)
        .args(&args)
        .current_dir(folder)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // "igi serve: open http://ADDRESS/ in a browser (Ctrl-C stops)"
    let mut stdout = BufReader::new(child.stdout.take().unwrap());
    let mut line = String::new();
    stdout.read_line(&mut line).unwrap();
    let address = line
        .split_once("http://")
        .and_then(|(_, rest)| rest.split_once('/'))
        .map(|(address, _)| address.to_string())
        .unwrap_or_else(|| panic!("{what}: igi serve says where it listens: {line:?}"));
    let deadline = Instant::now() + Duration::from_secs(60);
    let page = loop {
        let mut stream = TcpStream::connect(&address).unwrap();
        stream.set_read_timeout(Some(Duration::from_secs(60))).unwrap();
        write!(stream, "GET / HTTP/1.1\r\nHost: {address}\r\nConnection: close\r\n\r\n").unwrap();
        let mut response = String::new();
        let _ = stream.read_to_string(&mut response);
        if response.starts_with("HTTP/1.1 200") || Instant::now() > deadline {
            break response;
        }
        std::thread::sleep(Duration::from_millis(200));
    };
    child.kill().unwrap();
    let output = child.wait_with_output().unwrap();
    assert!(
        page.starts_with("HTTP/1.1 200") && page.contains("<html"),
        "{what}: the page: {}\n{}",
        page.lines().next().unwrap_or(""),
        String::from_utf8_lossy(&output.stderr)
    );
}

/// Runs one README command in `folder`; `what` names it in failures.
fn run(words: &[String], folder: &Path, what: &str) {
    let mut args: Vec<String> = match words {
        [cargo, run, release, dashes, rest @ ..] if cargo == "cargo" && run == "run" && dashes == "--" => {
            assert_eq!(release, "--release", "{what}: the README runs release builds");
            rest.to_vec()
        }
        [cargo, ..] if cargo == "cargo" => {
            // `cargo install --path crates/igi`, `cargo test --workspace`: the build and the
            // tests that run this one.
            return;
        }
        [igi, rest @ ..] if igi == "igi" => rest.to_vec(),
        _ => panic!("{what}: a README command this test does not know how to run: {words:?}"),
    };
    let mut outputs = Vec::new();
    match args.first().map(String::as_str) {
        Some("render") => {
            set_flag(&mut args, "--width", "160");
            set_flag(&mut args, "--height", "120");
            if !args.iter().any(|a| a == "--frames") {
                set_flag(&mut args, "--time-budget", "2");
            }
            let o =
                args.iter().position(|a| a == "-o" || a == "--output").expect("a render names its output");
            outputs.push(folder.join(&args[o + 1]));
        }
        Some("bench") => {
            set_flag(&mut args, "--width", "160");
            set_flag(&mut args, "--height", "120");
        }
        Some("serve") => return serve(&args, folder, what),
        Some("view") => {
            if !has_xvfb() {
                eprintln!("skipped {what}: the window needs xvfb-run");
                return;
            }
            let shot = folder.join("readme-view.png");
            let mut command = Command::new("xvfb-run");
            command.args(["-a", "-s", "-screen 0 1600x1200x24", IGI]).args(&args);
            command.arg("--exit-after-frames").arg("2").arg("--screenshot").arg(&shot);
            // The X server of Xvfb makes winit complain (no XSETTINGS, a display of 0 mm): the
            // environment's, not the README's.
            command.env("LIBGL_ALWAYS_SOFTWARE", "1").env("RUST_LOG", "warn,winit=error");
            outputs.push(shot);
            return check(command.current_dir(folder), &outputs, what);
        }
        _ => {}
    }
    let mut command = Command::new(IGI);
    command.args(&args);
    check(command.current_dir(folder), &outputs, what);
}

/// Runs `command`: it succeeds, warns about nothing, and writes `outputs`.
fn check(command: &mut Command, outputs: &[PathBuf], what: &str) {
    let output = command.output().unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "{what} failed:\n{stderr}");
    assert!(!stderr.contains("WARN"), "{what} warns:\n{stderr}");
    for file in outputs {
        let size = std::fs::metadata(file).map(|m| m.len()).unwrap_or(0);
        assert!(size > 0, "{what} wrote {}", file.display());
    }
}

#[test]
fn every_readme_example_runs() {
    let readme_path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../README.md");
    let readme = std::fs::read_to_string(&readme_path).unwrap();
    let folder = tempfile::tempdir().unwrap();
    let mut commands = 0;
    for block in blocks(&readme) {
        match block.note.as_deref() {
            Some(note) if note.starts_with("file ") => {
                let name = note.trim_start_matches("file ").trim();
                std::fs::write(folder.path().join(name), &block.text).unwrap();
                continue;
            }
            Some(note) => assert_eq!(note, "in the folder of the files above", "README line {}", block.line),
            None => {}
        }
        if block.language != "sh" {
            continue;
        }
        for (offset, line) in block.text.lines().enumerate() {
            let command = line.split(" #").next().unwrap_or("").trim();
            if command.is_empty() || command.starts_with('#') {
                continue;
            }
            let words =
                shlex::split(command).unwrap_or_else(|| panic!("README line {}: {command}", block.line));
            let what = format!("README line {} `{command}`", block.line + 1 + offset);
            run(&words, folder.path(), &what);
            commands += 1;
        }
    }
    assert!(commands >= 8, "the README's examples were found: {commands} commands");
}
