//! Output files are replaced at once: `igi render` stopped by Ctrl-C while it writes its image,
//! or running out of disk space, leaves the earlier file as it was (issue 12, fault 3), and an
//! output folder that does not exist fails the command before anything is rendered.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const IGI: &str = env!("CARGO_BIN_EXE_igi");

fn folder(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("igi-output-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// `igi render cornell-box` at `side` x `side` with the cheapest frame options, so that a good
/// part of its time goes into writing the image (an EXR of 3072 x 3072 takes most of a second,
/// a PNG a tenth: both go through the same writer).
fn render(output: &Path, side: u32) -> Command {
    let side = side.to_string();
    let mut command = Command::new(IGI);
    command
        .args(["render", "cornell-box", "--width", &side, "--height", &side])
        .args([
            "--aa",
            "1",
            "--vpls",
            "1",
            "--interleave",
            "1x1",
            "--bounces",
            "0",
            "--no-filter",
            "--frames",
            "1",
            "-o",
        ])
        .arg(output);
    command
}

/// True while a write to `path` is under way: its temporary file has bytes in it (the atomic
/// writer; the empty one of the start-up check does not count), or `path` itself no longer
/// holds `earlier` (a writer that truncates it in place).
fn writing(path: &Path, earlier: &[u8]) -> bool {
    let dir = path.parent().unwrap();
    let temporary = std::fs::read_dir(dir).unwrap().flatten().any(|e| {
        e.file_name().to_string_lossy().ends_with(".tmp") && e.metadata().is_ok_and(|m| m.len() > 0)
    });
    temporary || std::fs::metadata(path).is_ok_and(|m| m.len() != earlier.len() as u64)
}

#[test]
fn ctrl_c_during_the_image_write_keeps_the_earlier_file() {
    let dir = folder("sigint");
    let keep = dir.join("keep.exr");
    assert!(render(&keep, 64).output().unwrap().status.success());
    let earlier = std::fs::read(&keep).unwrap();

    // The write lasts most of a second; a poll every millisecond catches it. Should the
    // process end before the signal lands, the attempt proves nothing and is repeated.
    let mut caught = 0;
    for attempt in 0..4 {
        let mut child = render(&keep, 3072).stdout(Stdio::null()).stderr(Stdio::null()).spawn().unwrap();
        let deadline = Instant::now() + Duration::from_secs(600);
        while !writing(&keep, &earlier) && child.try_wait().unwrap().is_none() && Instant::now() < deadline {
            std::thread::sleep(Duration::from_millis(1));
        }
        let sent = Command::new("kill").args(["-INT", &child.id().to_string()]).status().unwrap().success();
        let status = child.wait().unwrap();
        let bytes = std::fs::read(&keep).unwrap();
        if bytes == earlier {
            // Interrupted with the earlier file intact: what this test is for.
            caught += usize::from(sent && !status.success());
        } else {
            // The new file, if the rename came before the signal: then it must be whole.
            let image = image::load_from_memory(&bytes)
                .unwrap_or_else(|e| panic!("attempt {attempt}: {} holds a torn image ({e})", keep.display()));
            assert_eq!((image.width(), image.height()), (3072, 3072));
            std::fs::write(&keep, &earlier).unwrap();
        }
        if caught > 0 {
            break;
        }
    }
    assert!(caught > 0, "no attempt was interrupted during its write");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_missing_output_folder_fails_before_rendering() {
    let start = Instant::now();
    // This frame would take half a minute on two cores; the error comes first.
    let out = render(Path::new("/nonexistent-igi-folder/x.png"), 8192).output().unwrap();
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("cannot create files in the folder /nonexistent-igi-folder"), "{stderr}");
    assert!(start.elapsed() < Duration::from_secs(10), "took {:?}", start.elapsed());
}

/// A 64 KiB tmpfs, unmounted when dropped.
struct TinyDisk(PathBuf);

impl TinyDisk {
    /// `None` where this user may not mount (mounting needs root; CI runs as root).
    fn mount() -> Option<Self> {
        let dir = folder("full-disk");
        let mounted = Command::new("mount")
            .args(["-t", "tmpfs", "-o", "size=64k", "tmpfs"])
            .arg(&dir)
            .stderr(Stdio::null())
            .status()
            .is_ok_and(|s| s.success());
        if mounted {
            return Some(Self(dir));
        }
        let _ = std::fs::remove_dir(&dir);
        None
    }
}

impl Drop for TinyDisk {
    fn drop(&mut self) {
        let _ = Command::new("umount").arg(&self.0).status();
        let _ = std::fs::remove_dir(&self.0);
    }
}

#[test]
fn a_full_disk_keeps_the_earlier_file() {
    let Some(disk) = TinyDisk::mount() else {
        eprintln!("skipped: cannot mount a tmpfs here (needs root)");
        return;
    };
    let keep = disk.0.join("keep.png");
    assert!(render(&keep, 32).output().unwrap().status.success());
    let earlier = std::fs::read(&keep).unwrap();
    // About 400 KB of PNG for 64 KiB of disk.
    let out = render(&keep, 1024).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && stderr.contains("No space left"), "{stderr}");
    let after = std::fs::read(&keep).unwrap();
    assert!(after == earlier, "the earlier file changed: {} bytes, were {}", after.len(), earlier.len());
    let names: Vec<_> = std::fs::read_dir(&disk.0).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert_eq!(names, ["keep.png"], "temporary files were left");
}
