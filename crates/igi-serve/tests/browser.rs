//! The browser viewer end to end in real headless Chromium: `e2e/viewer.test.mjs` (driven by
//! playwright-core) loads the page from a server started here, waits for a frame, drags,
//! changes a setting, and measures the input-to-photon latency and the frames drawn per
//! second. Skipped, with a message, where Chromium, Node or the npm packages are missing
//! (CI installs them: `apt-get install -y chromium`, `npm ci --prefix crates/igi-serve/e2e`).

mod common;

use std::path::Path;
use std::process::Command;

#[test]
fn the_page_shows_frames_and_follows_input_in_chromium() {
    let e2e = Path::new(env!("CARGO_MANIFEST_DIR")).join("e2e");
    let missing = [
        (Path::new("/usr/bin/chromium").exists(), "/usr/bin/chromium (apt-get install -y chromium)"),
        (Command::new("node").arg("--version").output().is_ok(), "node"),
        (
            e2e.join("node_modules/playwright-core").exists(),
            "playwright-core (npm ci --prefix crates/igi-serve/e2e)",
        ),
    ];
    if let Some((_, what)) = missing.iter().find(|(present, _)| !present) {
        eprintln!("skipped: the browser test needs {what}");
        return;
    }
    let server = common::start(320, 240);
    let url = format!("http://{}/", server.address);
    let output = Command::new("node").arg("viewer.test.mjs").arg(&url).current_dir(&e2e).output().unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout);
    eprintln!("{stdout}{}", String::from_utf8_lossy(&output.stderr));
    assert!(output.status.success() && stdout.trim_end().ends_with("ok"), "the browser test failed");
}
