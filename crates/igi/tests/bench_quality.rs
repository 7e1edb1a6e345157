//! `igi bench quality` (issue 16): the figures it reports behave as image errors must, the
//! reference is written once and read by later runs (which do not claim to know how it was
//! made), and bad flags are refused by name.

use std::process::Command;

const IGI: &str = env!("CARGO_BIN_EXE_igi");

fn igi(args: &[&str]) -> std::process::Output {
    Command::new(IGI).args(args).env("NO_COLOR", "1").output().unwrap()
}

#[test]
fn accumulated_frames_are_closer_to_the_reference_than_one_frame_and_the_reference_is_kept() {
    let dir = std::env::temp_dir().join(format!("igi-bench-quality-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let (reference, json) = (dir.join("reference.exr"), dir.join("quality.json"));
    let args = [
        "bench",
        "quality",
        "cornell-box",
        "--width",
        "64",
        "--height",
        "64",
        "--reference-spp",
        "64",
        "--accumulate",
        "16",
        "--reference",
        reference.to_str().unwrap(),
        "--json",
        json.to_str().unwrap(),
    ];
    let report = |out: std::process::Output| -> serde_json::Value {
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap()
    };
    let first = report(igi(&args));
    assert!(reference.exists(), "the reference is written");
    let (one, mean) = (&first["one_frame"], &first["accumulated"]);
    for f in [one, mean] {
        let (flip, rmse) = (f["flip"].as_f64().unwrap(), f["rmse"].as_f64().unwrap());
        assert!(flip > 0.0 && flip < 1.0 && rmse > 0.0 && rmse < 1.0, "{f}");
    }
    assert!(mean["flip"].as_f64() < one["flip"].as_f64(), "16 frames {mean} against one {one}");
    assert!(first["reference_seconds"].as_f64().unwrap() > 0.0);
    // The second run reads the reference and measures the same images.
    let second = report(igi(&args));
    assert_eq!(second["reference_seconds"].as_f64(), Some(0.0));
    // Read from a file it was given, it does not claim to know how the file was made.
    assert_eq!(first["reference_method"], "path tracer, 64 spp");
    assert!(second["reference_method"].as_str().unwrap().contains("not recorded"), "{second}");
    assert_eq!(second["one_frame"]["flip"], first["one_frame"]["flip"]);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_flags_are_refused_by_name() {
    for (flag, value) in
        [("--flicker", "1"), ("--accumulate", "0"), ("--reference-spp", "0"), ("--reference-frames", "1")]
    {
        let out = igi(&["bench", "quality", "cornell-box", flag, value]);
        assert!(!out.status.success());
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(stderr.contains(flag), "{flag} {value}: {stderr}");
    }
}

#[test]
fn an_accumulated_reference_is_closer_to_many_frames_than_to_one() {
    let dir = std::env::temp_dir().join(format!("igi-bench-quality-igi-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let json = dir.join("quality.json");
    let out = igi(&[
        "bench",
        "quality",
        "two-rooms",
        "--width",
        "48",
        "--height",
        "36",
        "--reference-frames",
        "64",
        "--accumulate",
        "16",
        "--reference",
        dir.join("reference.exr").to_str().unwrap(),
        "--json",
        json.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let r: serde_json::Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    assert_eq!(r["reference_method"], "IGI, the mean of 64 frames");
    assert!(r["accumulated"]["flip"].as_f64() < r["one_frame"]["flip"].as_f64(), "{r}");
    let _ = std::fs::remove_dir_all(&dir);
}
