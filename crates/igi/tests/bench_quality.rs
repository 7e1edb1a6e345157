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
    // What igi render writes by default: at least the 4 frames of its stopping rule, and fewer
    // blotches than one frame (against a reference of 64 paths a pixel, itself blotchy at 64²).
    let default = &first["default"];
    assert!(default["frames"].as_u64().unwrap() >= 4, "{default}");
    assert!(
        default["blotch10"].as_f64().unwrap() < 0.75 * one["blotch10"].as_f64().unwrap(),
        "{default} {one}"
    );
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

/// A change of the light shows in the frame it happens (a cut: no history lags it), and an
/// orbit keeps most of its history with temporal reuse and none without.
#[test]
fn a_light_change_lags_no_frame_and_an_orbit_keeps_its_history() {
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("lag.json");
    let small = ["--width", "64", "--height", "48", "--view-reference-frames", "8", "--json"];
    let run = |scene: &str, mode: &[&str]| -> serde_json::Value {
        let mut args = vec!["bench", "quality", scene];
        args.extend(mode);
        args.extend(small);
        args.push(json.to_str().unwrap());
        let out = igi(&args);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap()
    };
    let lag = run("animated-room", &["--lag", "0.5"]);
    assert_eq!(lag["lag_frames"], 1, "{lag}");
    assert!(lag["shares"][0].as_f64().unwrap() > 0.9, "{lag}");
    let orbit = run("cornell-box", &["--orbit", "6", "--orbit-from", "3", "--orbit-degrees", "2"]);
    let (kept, least) = (&orbit["temporal"]["history_kept"], &orbit["temporal"]["history_kept_least"]);
    assert!(least.as_f64().unwrap() > 0.5 && least.as_f64() <= kept.as_f64(), "{orbit}");
    assert_eq!(orbit["single"]["history_kept"].as_f64(), Some(0.0), "{orbit}");
    for way in ["temporal", "single"] {
        let f = &orbit[way];
        assert!(f["flip"].as_f64().unwrap() > 0.0 && f["blotch10"].as_f64().unwrap() < 1.0, "{f}");
    }
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

#[test]
fn a_reference_that_is_not_radiance_is_refused() {
    // An all-NaN, an infinite or a negative EXR used to be measured (FLIP 0.887).
    let dir = tempfile::tempdir().unwrap();
    for (name, value) in [("nan", f32::NAN), ("inf", f32::INFINITY), ("negative", -1.0)] {
        let path = dir.path().join(format!("{name}.exr"));
        image::Rgb32FImage::from_pixel(16, 16, image::Rgb([0.5, value, 0.5])).save(&path).unwrap();
        let out = igi(&[
            "bench",
            "quality",
            "cornell-box",
            "--width",
            "16",
            "--height",
            "16",
            "--reference",
            path.to_str().unwrap(),
        ]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{name}: {err}");
        assert!(err.contains("is not radiance: pixel (0, 0)"), "{name}: {err}");
    }
}

/// What `igi render` writes by default is clean against a converged image, also where the
/// frames' own estimate of the remaining error errs low: the white Cornell box (a featureless
/// box, whose patches the eye sees at a few per cent) stopped after 6-8 frames with a darker
/// patch on its back wall while its rule stopped at an estimated 1 % (measured 0.0095,
/// 0.0078, 0.0105 for seeds 1-3 at 320x240; ARCHITECTURE.md, "Convergence by the blotch
/// figure"). Deterministic: each seed's frames are the same on any machine.
#[test]
fn the_default_still_image_of_a_white_box_is_clean_against_a_converged_one() {
    let file = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/scenes/cornell-variants/CornellBox-Empty-White.obj");
    if !file.is_file() {
        eprintln!("skipped: ../shared/scenes/cornell-variants is absent");
        return;
    }
    let dir = std::env::temp_dir().join(format!("igi-bench-quality-white-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let (reference, json) = (dir.join("reference.exr"), dir.join("quality.json"));
    let blotch: Vec<f64> = (1..=3)
        .map(|seed| {
            let out = igi(&[
                "bench",
                "quality",
                file.to_str().unwrap(),
                "--width",
                "320",
                "--height",
                "240",
                "--reference-frames",
                "200",
                "--reference",
                reference.to_str().unwrap(),
                "--accumulate",
                "2",
                // The rule, not the clock, stops it: the same frames on a slow machine.
                "--time-budget",
                "300",
                "--seed",
                &seed.to_string(),
                "--json",
                json.to_str().unwrap(),
            ]);
            assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
            let r: serde_json::Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
            r["default"]["blotch10"].as_f64().unwrap()
        })
        .collect();
    let mean = blotch.iter().sum::<f64>() / 3.0;
    assert!(blotch.iter().all(|&b| b <= 0.01) && mean <= 0.0075, "blotch10 of seeds 1-3: {blotch:?}");
    let _ = std::fs::remove_dir_all(&dir);
}
