//! Image files: EXR keeps the linear values exactly, PNG holds the tone-mapped sRGB bytes.

use glam::Vec3;
use igi_render::image::output::{ImageFormat, to_srgb8, write_png_rgb8};
use igi_render::image::tonemap::{LuminanceStats, ToneMapper, linear_to_srgb, srgb_to_linear};
use igi_render::{Film, ToneMap, write_exr, write_image, write_png};
use std::path::PathBuf;

fn test_film() -> Film {
    let (w, h) = (13u32, 7u32);
    let pixels = (0..w * h)
        .map(|i| {
            let f = i as f32;
            Vec3::new(f * 0.037, (f * 0.61).sin().abs() * 3.0, 1.0 / (1.0 + f))
                * if i % 5 == 0 { 40.0 } else { 1.0 }
        })
        .collect();
    Film::from_pixels(w, h, pixels)
}

fn tmp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("igi-render-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

#[test]
fn exr_round_trip_is_exact() {
    let film = test_film();
    let path = tmp("round.exr");
    write_exr(&film, &path).unwrap();

    // Read back with the exr crate.
    let image = exr::prelude::read_first_rgba_layer_from_file(
        &path,
        |res, _| (res.width(), vec![Vec3::ZERO; res.width() * res.height()]),
        |(w, px), pos, (r, g, b, _a): (f32, f32, f32, f32)| px[pos.y() * *w + pos.x()] = Vec3::new(r, g, b),
    )
    .unwrap();
    let (_, pixels) = image.layer_data.channel_data.pixels;
    assert_eq!(pixels, film.pixels());

    // And with the image crate.
    let img = image::open(&path).unwrap().into_rgb32f();
    assert_eq!((img.width(), img.height()), (film.width(), film.height()));
    for (x, y, p) in img.enumerate_pixels() {
        assert_eq!(Vec3::from_array(p.0), film.get(x, y));
    }
}

#[test]
fn png_round_trip_holds_the_tone_mapped_bytes() {
    let film = test_film();
    for tone_map in [ToneMap::default(), ToneMap::Exposure { stops: -1.5 }] {
        let path = tmp("round.png");
        write_png(&film, &path, &ToneMapper::for_film(tone_map, &film)).unwrap();
        let img = image::open(&path).unwrap().into_rgb8();
        assert_eq!((img.width(), img.height()), (film.width(), film.height()));
        assert_eq!(img.into_raw(), to_srgb8(&film, &ToneMapper::for_film(tone_map, &film)));
    }
}

#[test]
fn write_image_picks_the_format_from_the_extension() {
    let film = test_film();
    assert_eq!(ImageFormat::from_path("a.PNG".as_ref()).unwrap(), ImageFormat::Png);
    assert_eq!(ImageFormat::from_path("a.exr".as_ref()).unwrap(), ImageFormat::Exr);
    let err =
        write_image(&film, &tmp("bad.jpg"), &ToneMapper::for_film(ToneMap::default(), &film)).unwrap_err();
    assert!(err.to_string().contains("bad.jpg"), "{err}");
    let path = tmp("pick.exr");
    write_image(&film, &path, &ToneMapper::for_film(ToneMap::default(), &film)).unwrap();
    assert!(image::open(&path).unwrap().into_rgb32f().width() == film.width());
}

#[test]
fn reinhard_maps_the_log_average_to_the_key() {
    // Half the pixels at 1, half at 100: log-average 10 maps to the key 0.18 before the
    // compression, the maximum 100 to L_white = 1.8 (eq. 4), which comes out white.
    let mut px = vec![Vec3::ONE; 16];
    px[8..].fill(Vec3::splat(100.0));
    let film = Film::from_pixels(4, 4, px);
    let m = ToneMapper::for_film(ToneMap::Reinhard { key: 0.18 }, &film);
    assert!((m.scale - 0.018).abs() < 1e-6 && (m.white - 1.8).abs() < 1e-4, "{m:?}");
    let v = m.map(Vec3::splat(10.0));
    let want = 0.18 * (1.0 + 0.18 / (1.8 * 1.8)) / 1.18;
    assert!((v.x - want).abs() < 1e-5, "{v} vs {want}");
    assert!((m.map(Vec3::splat(100.0)).x - 1.0).abs() < 1e-5);
    // A uniform image is its own maximum: it shows as white.
    let uniform = Film::from_pixels(2, 2, vec![Vec3::splat(3.7); 4]);
    let u = ToneMapper::for_film(ToneMap::Reinhard { key: 0.18 }, &uniform).map(Vec3::splat(3.7));
    assert!((u.x - 1.0).abs() < 1e-5, "{u}");
    // Black pixels do not drag the average down.
    let mut px = vec![Vec3::splat(3.7); 16];
    px[..8].fill(Vec3::ZERO);
    let stats = LuminanceStats::of_pixels(&px);
    assert_eq!(stats.count, 8);
    assert!((stats.log_average().unwrap() - 3.7).abs() < 1e-4);
}

#[test]
fn exposure_is_a_plain_scale_and_srgb_round_trips() {
    let m = ToneMapper::new(ToneMap::Exposure { stops: 1.0 }, &LuminanceStats::default());
    assert_eq!(m.map(Vec3::splat(0.25)), Vec3::splat(0.5));
    assert_eq!(m.map(Vec3::splat(4.0)), Vec3::ONE);
    assert_eq!(m.map(Vec3::new(-1.0, f32::NAN, f32::INFINITY)), Vec3::ZERO);
    for c in [0.0, 0.001, 0.2, 0.5, 1.0] {
        assert!((srgb_to_linear(linear_to_srgb(c)) - c).abs() < 1e-6);
    }
    assert_eq!(m.to_srgb8(Vec3::splat(0.5)), [255, 255, 255]);
    assert_eq!(m.to_srgb8(Vec3::ZERO), [0, 0, 0]);
}

#[test]
fn srgb8_encoding_rounds_the_transfer_function() {
    use igi_render::image::tonemap::encode_srgb8;
    for i in 0..=100_000 {
        let c = i as f32 / 100_000.0;
        let exact = linear_to_srgb(c) * 255.0;
        let code = f32::from(encode_srgb8(c));
        // Equal to the rounded value, except within float noise of a rounding boundary.
        assert!((code - exact).abs() <= 0.5 + 1e-3, "{c}: {code} vs {exact}");
    }
    assert_eq!(encode_srgb8(-1.0), 0);
    assert_eq!(encode_srgb8(f32::NAN), 0);
    assert_eq!(encode_srgb8(2.0), 255);
}

#[test]
fn files_are_byte_for_byte_reproducible() {
    let film = test_film();
    for name in ["a.exr", "a.png"] {
        let (p1, p2) = (tmp(&format!("1{name}")), tmp(&format!("2{name}")));
        write_image(&film, &p1, &ToneMapper::for_film(ToneMap::default(), &film)).unwrap();
        write_image(&film, &p2, &ToneMapper::for_film(ToneMap::default(), &film)).unwrap();
        assert!(std::fs::read(&p1).unwrap() == std::fs::read(&p2).unwrap(), "{name} differs between writes");
    }
}

/// The files in `path`'s folder other than `path` itself (temporaries a write left behind).
fn others_in_folder(path: &std::path::Path) -> Vec<PathBuf> {
    let mut others: Vec<PathBuf> = std::fs::read_dir(path.parent().unwrap())
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p != path)
        .collect();
    others.sort();
    others
}

/// A folder of its own for one test, so the files in it are the test's alone.
fn own_folder(name: &str) -> PathBuf {
    let dir = tmp(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn a_failed_png_write_keeps_the_earlier_file() {
    let path = own_folder("failed-png").join("keep.png");
    let film = test_film();
    write_png(&film, &path, &ToneMapper::for_film(ToneMap::default(), &film)).unwrap();
    let before = std::fs::read(&path).unwrap();
    // The PNG encoder refuses an image of 0 x 0 pixels, after the file was opened.
    let err = write_png_rgb8(&[], 0, 0, &path).unwrap_err();
    assert!(err.to_string().contains("keep.png"), "{err}");
    let after = std::fs::read(&path).unwrap();
    assert!(after == before, "the earlier file changed: {} bytes, were {}", after.len(), before.len());
    assert_eq!(others_in_folder(&path), Vec::<PathBuf>::new(), "temporary files were left");
}

#[test]
fn a_failed_exr_write_keeps_the_earlier_file() {
    let path = own_folder("failed-exr").join("keep.exr");
    write_exr(&test_film(), &path).unwrap();
    let before = std::fs::read(&path).unwrap();
    // The EXR writer refuses an image without pixels, after the file was opened.
    let err = write_exr(&Film::from_pixels(0, 0, Vec::new()), &path).unwrap_err();
    assert!(err.to_string().contains("keep.exr"), "{err}");
    let after = std::fs::read(&path).unwrap();
    assert!(after == before, "the earlier file changed: {} bytes, were {}", after.len(), before.len());
    assert_eq!(others_in_folder(&path), Vec::<PathBuf>::new(), "temporary files were left");
}
