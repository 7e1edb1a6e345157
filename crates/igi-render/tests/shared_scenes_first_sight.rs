//! Every public scene of `../shared/scenes`, opened as a new user opens it (no camera, no
//! light options), shows a picture: a small default frame is neither black nor flat, a fair
//! share of it is geometry, and the interiors are seen from inside, with geometry in every
//! direction around the eye (issue 14: Sponza used to open as its outer wall, Lost Empire
//! black, DamagedHelmet a green blob). The frames are written to
//! `$CARGO_TARGET_TMPDIR/first-sight/` to be looked at.

use glam::Vec3;
use igi_bvh::Ray;
use igi_render::{
    FrameRenderer, FrameSettings, FrameState, PinholeCamera, PreparedScene, ToneMap, ToneMapper,
    add_default_light, start_camera, write_png,
};
use std::path::{Path, PathBuf};

/// The scenes, and whether each is an interior.
const SCENES: &[(&str, bool)] = &[
    ("sponza-dabrovic/sponza.obj", true),
    ("sibenik/sibenik.obj", true),
    ("conference/conference.obj", true),
    ("lost-empire/lost_empire.obj", false),
    ("cornell-box/CornellBox-Original.obj", false),
    ("stanford-armadillo/Armadillo.ply", false),
    ("stanford-bunny/bun_zipper.ply", false),
    ("gltf-samples/DamagedHelmet/glTF/DamagedHelmet.gltf", false),
    ("gltf-samples/BoxTextured/glTF/BoxTextured.gltf", false),
    ("gltf-samples/AnimatedMorphCube/glTF/AnimatedMorphCube.gltf", false),
    ("gltf-samples/Duck/glTF/Duck.gltf", false),
    ("gltf-samples/CesiumMilkTruck/glTF/CesiumMilkTruck.gltf", false),
    ("gltf-samples/Fox/glTF/Fox.gltf", false),
];

fn shared() -> Option<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/scenes");
    dir.is_dir().then_some(dir)
}

/// What a user sees in the default frame of one scene.
struct Sight {
    /// Share of the pixels whose primary ray hits geometry.
    geometry: f32,
    /// Mean and standard deviation of the display luminance (0..1) over the geometry.
    mean: f32,
    spread: f32,
}

fn first_sight(path: &Path, interior: bool, out: &Path) -> Sight {
    let scene = igi_scene::load_named(path.to_str().unwrap()).unwrap();
    let mut prepared = PreparedScene::new(scene);
    add_default_light(&mut prepared, true);
    let camera = start_camera(&prepared);
    let bounds = prepared.bounds();
    if interior {
        assert!(
            camera.position.cmpgt(bounds.min).all() && camera.position.cmplt(bounds.max).all(),
            "{}: the camera {camera:?} stands outside the interior",
            path.display()
        );
        // Geometry all around the eye and below it (above, a courtyard may be open).
        for k in 0..16 {
            let phi = std::f32::consts::TAU * k as f32 / 16.0;
            for dir in [Vec3::new(phi.cos(), 0.0, phi.sin()), Vec3::new(phi.cos(), -1.0, phi.sin())] {
                let hit = prepared.accel().intersect(&Ray::new(camera.position, dir));
                assert!(hit.is_hit(), "{}: nothing toward {dir} from the eye", path.display());
            }
        }
    }
    let (width, height) = (160, 120);
    let settings = FrameSettings {
        width,
        height,
        clamp: FrameSettings::clamp_for(bounds.diagonal()),
        ..FrameSettings::default()
    };
    let frame = FrameState::new(camera, settings);
    let output = FrameRenderer::new(2).render(&mut prepared, &frame, &|_, _| {}).unwrap();
    let film = output.image.film().unwrap();
    let mapper = ToneMapper::for_film(ToneMap::default(), film);
    write_png(film, out, &mapper).unwrap();

    let pinhole = PinholeCamera::new(&camera, width, height);
    let mut luma = Vec::new();
    for y in 0..height {
        for x in 0..width {
            if prepared.accel().intersect(&pinhole.ray(x, y)).is_hit() {
                let rgb = mapper.map(film.get(x, y));
                luma.push(0.2126 * rgb.x + 0.7152 * rgb.y + 0.0722 * rgb.z);
            }
        }
    }
    let n = luma.len().max(1) as f32;
    let mean = luma.iter().sum::<f32>() / n;
    let spread = (luma.iter().map(|l| (l - mean) * (l - mean)).sum::<f32>() / n).sqrt();
    Sight { geometry: luma.len() as f32 / (width * height) as f32, mean, spread }
}

#[test]
fn every_shared_scene_shows_a_picture_with_the_defaults() {
    let Some(dir) = shared() else {
        eprintln!("skipped: ../shared/scenes is absent");
        return;
    };
    let out = Path::new(env!("CARGO_TARGET_TMPDIR")).join("first-sight");
    std::fs::create_dir_all(&out).unwrap();
    let mut failures = Vec::new();
    for &(file, interior) in SCENES {
        let path = dir.join(file);
        if !path.is_file() {
            eprintln!("skipped {file}: absent");
            continue;
        }
        let name = Path::new(file).file_stem().unwrap().to_string_lossy().into_owned();
        let sight = first_sight(&path, interior, &out.join(format!("{name}.png")));
        eprintln!(
            "{file}: geometry {:.0} %, display luminance {:.2} ± {:.2}",
            100.0 * sight.geometry,
            sight.mean,
            sight.spread
        );
        // The Duck brings its own camera, from which it fills 6 % of the frame.
        let least = if file.contains("Duck") { 0.05 } else { 0.15 };
        if sight.geometry < least {
            failures.push(format!("{file}: geometry fills {:.0} % of the frame", 100.0 * sight.geometry));
        }
        if sight.mean < 0.08 {
            failures.push(format!("{file}: dark (mean display luminance {:.3})", sight.mean));
        }
        if sight.spread < 0.04 {
            failures.push(format!("{file}: flat (luminance spread {:.3})", sight.spread));
        }
    }
    eprintln!("the frames are in {}", out.display());
    assert!(failures.is_empty(), "{failures:#?}");
}
