//! `--tone-map` (issue 34): both curves expose the image's log-average luminance at middle
//! grey; the filmic one, the default, shows the Cornell box's white back wall brighter than
//! Reinhard's operator does (it showed mid-grey), keeps its colour, and is the same at any
//! thread count. A fixed `--exposure` replaces the tone map, so the two are refused together.

use std::path::Path;
use std::process::Command;

const IGI: &str = env!("CARGO_BIN_EXE_igi");

/// `igi render cornell-box` at 80x80, one frame, with `options`, as 8-bit RGB.
fn render(folder: &Path, name: &str, options: &[&str]) -> image::RgbImage {
    let png = folder.join(format!("{name}.png"));
    let out = Command::new(IGI)
        .args(["render", "cornell-box", "--width", "80", "--height", "80", "--frames", "1", "-o"])
        .arg(&png)
        .args(options)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    image::open(&png).unwrap().to_rgb8()
}

/// The mean 8-bit values of the back wall between the blocks, above the short one.
fn back_wall(image: &image::RgbImage) -> [f64; 3] {
    let mut sum = [0.0; 3];
    let mut n = 0.0;
    for y in WALL_ROWS {
        for x in WALL_COLUMNS {
            let p = image.get_pixel(x, y);
            (0..3).for_each(|c| sum[c] += f64::from(p[c]));
            n += 1.0;
        }
    }
    sum.map(|s| s / n)
}

/// The back wall's pixels in an 80x80 render from the box's own camera.
const WALL_COLUMNS: std::ops::Range<u32> = 44..54;
const WALL_ROWS: std::ops::Range<u32> = 16..28;

#[test]
fn filmic_shows_the_white_wall_near_white_and_is_the_default() {
    let folder = tempfile::tempdir().unwrap();
    let filmic = render(folder.path(), "filmic", &["--tone-map", "filmic"]);
    let reinhard = render(folder.path(), "reinhard", &["--tone-map", "reinhard"]);
    let (f, r) = (back_wall(&filmic), back_wall(&reinhard));
    // Reinhard shows the wall at about 145 of 255 in green (mid-grey in sRGB), filmic at 190.
    assert!(f[1] > r[1] + 25.0 && f[1] > 175.0, "filmic {f:?}, Reinhard {r:?}");
    // The same colour: the light's warm tint in the same proportions (within 5 %).
    let tint = |c: [f64; 3]| [c[0] / c[1], c[2] / c[1]];
    let (tf, tr) = (tint(f), tint(r));
    assert!((tf[0] / tr[0] - 1.0).abs() < 0.05 && (tf[1] / tr[1] - 1.0).abs() < 0.05, "{tf:?} vs {tr:?}");
    // The default is filmic, the same at any thread count.
    let default = render(folder.path(), "default", &["--threads", "1"]);
    assert!(default == filmic, "the default tone map is not filmic, or the threads changed it");
    let out = Command::new(IGI)
        .args(["render", "cornell-box", "-o", "x.png", "--tone-map", "reinhard", "--exposure", "0"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2), "{}", String::from_utf8_lossy(&out.stderr));
}

#[test]
fn a_fixed_exposure_is_held_to_the_range_the_viewers_take() {
    // `serve` refused stops outside [-64, 64] while `render` took 1e30 (issue 35).
    for (stops, ok) in [("1e30", false), ("-65", false), ("64", true)] {
        let folder = tempfile::tempdir().unwrap();
        let out = Command::new(IGI)
            .current_dir(folder.path())
            .args([
                "render",
                "cornell-box",
                "-o",
                "x.png",
                "--frames",
                "1",
                "--width",
                "16",
                "--height",
                "12",
            ])
            .arg(format!("--exposure={stops}"))
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.success(), ok, "--exposure {stops}: {stderr}");
        if !ok {
            assert!(stderr.contains("--exposure") && stderr.contains("[-64, 64]"), "{stderr}");
        }
    }
}
