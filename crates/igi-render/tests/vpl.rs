//! Physics of the VPL random walks (paper 2.1, instant radiosity): every test compares the
//! VPLs of many independent sets (each set is its own RQMC estimate) with a closed-form or
//! numerically integrated answer, within a few standard errors of the mean.

mod common;

use common::*;
use glam::{Vec2, Vec3};
use igi_render::PreparedScene;
use igi_render::frame::limits::MAX_BOUNCES;
use igi_render::frame::{FrameSettings, FrameState};
use igi_render::igi::view_importance::{UNSEEN_ACCEPTANCE, ViewImportance};
use igi_render::igi::vpl::{Vpl, VplSets};
use igi_render::prepared::lights::eye_light;
use igi_scene::{Light, Material, MaterialKind, Mesh};
use std::f64::consts::PI;

/// The frame of `seed` with `vpls` VPLs per set and 4 × 4 sets (one level: the coarse level
/// only multiplies the sets, and 16 times the paths of 144 sets would not fit one sequence).
fn frame(seed: u32, vpls: u32) -> FrameState {
    let settings = FrameSettings {
        vpls_per_pixel: vpls,
        interleave: [4, 4],
        coarse_interleave: 1,
        seed,
        ..FrameSettings::default()
    };
    FrameState::new(camera(Vec3::new(0.0, 1.0, 3.5), Vec3::new(0.0, 1.0, 0.0), 39.3), settings)
}

/// `f` of every set of the frames with seeds `0..seeds`.
fn per_set<T>(scene: &PreparedScene, vpls: u32, seeds: u32, f: impl Fn(&[Vpl]) -> T) -> Vec<T> {
    let mut out = Vec::new();
    for seed in 0..seeds {
        let sets = VplSets::generate(scene, &frame(seed, vpls));
        out.extend((0..sets.set_count()).map(|s| f(sets.set(s))));
    }
    out
}

/// Mean and standard error of the mean.
fn mean_and_error(samples: &[f64]) -> (f64, f64) {
    let n = samples.len() as f64;
    let mean = samples.iter().sum::<f64>() / n;
    let var = samples.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, (var / n).sqrt())
}

/// Asserts that the mean of `samples` (one per independent set) is `want` within four
/// standard errors plus `slack` (relative, for the known bias of a test's geometry).
fn assert_mean(samples: &[f64], want: f64, slack: f64, what: &str) {
    let (mean, err) = mean_and_error(samples);
    assert!(
        (mean - want).abs() <= 4.0 * err + (slack + 1e-5) * want.abs(),
        "{what}: mean {mean} ± {err} over {} sets, want {want}",
        samples.len()
    );
}

/// Per channel: asserts [`assert_mean`] on `samples`.
fn assert_mean3(samples: &[Vec3], want: Vec3, slack: f64, what: &str) {
    for c in 0..3 {
        let channel: Vec<f64> = samples.iter().map(|v| f64::from(v[c])).collect();
        assert_mean(&channel, f64::from(want[c]), slack, &format!("{what}, channel {c}"));
    }
}

fn total_power(vpls: &[Vpl]) -> Vec3 {
    vpls.iter().map(|v| v.power).sum()
}

/// A square of half size `half` in the plane y = `y`, facing up or down.
fn plane(y: f32, half: f32, up: bool, material: u32) -> Mesh {
    horizontal_square("plane", Vec3::new(0.0, y, 0.0), Vec2::splat(half), up, material)
}

fn material(kind: MaterialKind, reflectance: f32) -> Material {
    Material {
        name: "specular".into(),
        diffuse: Vec3::ZERO,
        glossy: Vec3::splat(reflectance),
        kind,
        ..Material::default()
    }
}

/// Solid angle of the square of half size `a` seen from distance `d` above its centre.
fn square_solid_angle(a: f64, d: f64) -> f64 {
    4.0 * (a * a / (a * a + d * d)).asin()
}

#[test]
fn direct_vpls_carry_the_area_light_power_uniformly_by_area() {
    // Two emitters facing down at y = 1 (1 × 1 and 2 × 1) over a black floor: with albedo 0
    // everywhere, every VPL is a light-surface sample.
    let le = Vec3::new(2.0, 1.0, 0.5);
    let meshes = vec![
        plane(0.0, 5.0, true, 0),
        horizontal_square("a", Vec3::new(-1.5, 1.0, 0.0), Vec2::new(0.5, 0.5), false, 1),
        horizontal_square("b", Vec3::new(2.0, 1.0, 0.0), Vec2::new(1.0, 0.5), false, 1),
    ];
    let scene = PreparedScene::new(scene(meshes, vec![diffuse("black", 0.0), emitter("light", le)], vec![]));
    let want = std::f32::consts::PI * 3.0 * le;

    let (mut on_a, mut on_b) = (Vec::new(), Vec::new());
    for seed in 0..40 {
        let sets = VplSets::generate(&scene, &frame(seed, 16));
        assert!(sets.lights().is_empty(), "area lights are not punctual lights");
        assert_eq!(sets.paths(), 16 * sets.set_count(), "one VPL per path, no punctual light: P = V per set");
        for s in 0..sets.set_count() {
            let set = sets.set(s);
            assert_eq!(set.len(), 16);
            for v in set {
                assert!((v.position.y - 1.0).abs() < 1e-6 && v.normal == -Vec3::Y, "{v:?}");
            }
            // One emission colour: each particle carries exactly Φ / P, so a set sums to Φ.
            assert!(rel_err(total_power(set), want) < 1e-5, "set power {} want {want}", total_power(set));
            on_a.extend(set.iter().filter(|v| v.position.x < 0.0).map(|v| v.position));
            on_b.extend(set.iter().filter(|v| v.position.x > 0.0).map(|v| v.position));
        }
    }
    // Uniform by area: a third of the points on A; on each, mean at the centre and the
    // variance of a uniform interval, w² / 12.
    let fraction_a = on_a.len() as f64 / (on_a.len() + on_b.len()) as f64;
    assert!((fraction_a - 1.0 / 3.0).abs() < 0.01, "fraction on the 1 × 1 emitter {fraction_a}");
    for (points, centre, width) in
        [(&on_a, Vec2::new(-1.5, 0.0), Vec2::ONE), (&on_b, Vec2::new(2.0, 0.0), Vec2::new(2.0, 1.0))]
    {
        let n = points.len() as f32;
        let mean = points.iter().map(|p| Vec2::new(p.x, p.z)).sum::<Vec2>() / n;
        let var = points.iter().map(|p| (Vec2::new(p.x, p.z) - centre).powf(2.0)).sum::<Vec2>() / n;
        assert!(
            (mean - centre).abs().max_element() < 0.01 * width.max_element(),
            "mean {mean} want {centre}"
        );
        assert!(
            ((var / (width * width / 12.0)) - 1.0).abs().max_element() < 0.03,
            "variance {var} for {width}"
        );
    }
}

#[test]
fn closed_box_bounce_power_is_a_geometric_series_per_channel() {
    // A closed cube [-1, 1]³, every face facing inward with reflectance ρ; the ceiling also
    // emits. Every particle hits a wall, so a set's VPLs sum, in expectation, to
    // Φ (light) + Φ ρ (1 − ρ^32) / (1 − ρ) per channel (Russian roulette on max ρ, 32 bounces).
    let rho = Vec3::new(0.6, 0.45, 0.3);
    let le = Vec3::new(1.0, 2.0, 3.0);
    let c = |x: f32, y: f32, z: f32| Vec3::new(x, y, z);
    let faces = [
        [c(-1., -1., -1.), c(1., -1., -1.), c(1., -1., 1.), c(-1., -1., 1.)],
        [c(-1., -1., -1.), c(-1., 1., -1.), c(-1., 1., 1.), c(-1., -1., 1.)],
        [c(1., -1., -1.), c(1., 1., -1.), c(1., 1., 1.), c(1., -1., 1.)],
        [c(-1., -1., -1.), c(1., -1., -1.), c(1., 1., -1.), c(-1., 1., -1.)],
        [c(-1., -1., 1.), c(1., -1., 1.), c(1., 1., 1.), c(-1., 1., 1.)],
    ];
    let mut meshes: Vec<Mesh> = faces.iter().map(|f| quad_facing("wall", *f, Vec3::ZERO, 0)).collect();
    meshes.push(plane(1.0, 1.0, false, 1));
    let wall = Material { name: "wall".into(), diffuse: rho, ..Material::default() };
    let light = Material { name: "light".into(), diffuse: rho, emission: le, ..Material::default() };
    let scene = PreparedScene::new(scene(meshes, vec![wall, light], vec![]));

    let phi = std::f32::consts::PI * 4.0 * le;
    let series = rho * (Vec3::ONE - rho.powf(MAX_BOUNCES as f32)) / (Vec3::ONE - rho);
    let samples = per_set(&scene, 64, 25, total_power);
    assert_mean3(&samples, phi * (Vec3::ONE + series), 0.0, "closed box");
}

#[test]
fn same_frame_gives_the_same_vpls_at_any_thread_count() {
    let scene = PreparedScene::new(igi_scene::builtin("cornell-box").expect("built-in scene"));
    let f = frame(7, 12);
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("thread pool");
        let sets = pool.install(|| VplSets::generate(&scene, &f));
        (0..sets.set_count()).map(|s| sets.set(s).to_vec()).collect::<Vec<_>>()
    };
    let one = run(1);
    assert!(one.iter().all(|set| !set.is_empty()));
    assert_eq!(one, run(2));
    assert_eq!(one, run(2));

    let vpls = |f: &FrameState| {
        let sets = VplSets::generate(&scene, f);
        (sets.paths(), (0..sets.set_count()).map(|s| sets.set(s).to_vec()).collect::<Vec<_>>())
    };
    // A still scene keeps its VPLs from frame to frame unless asked to reseed.
    let (paths, base) = vpls(&f);
    assert_eq!(vpls(&FrameState { number: 5, ..f.clone() }).1, base);
    let mut reseeded = f.clone();
    reseeded.reseed_per_frame = true;
    let (paths0, frame0) = vpls(&reseeded);
    let (paths1, frame1) = vpls(&FrameState { number: 1, ..reseeded.clone() });
    assert_ne!(frame0, frame1);
    assert_ne!(vpls(&FrameState { settings: FrameSettings { seed: 8, ..f.settings }, ..f.clone() }).1, base);
    // The number of paths comes from a fixed-seed pilot: it stays put.
    assert_eq!((paths0, paths1), (paths, paths));
    // The sets of one frame are independent estimates, not copies.
    assert_ne!(base[0], base[1]);
}

#[test]
fn directional_light_deposits_e_cos_area_albedo_on_either_side_of_a_plane() {
    // A 4 × 4 plane of reflectance ρ, nothing else: particles of the sun reach it over its
    // projected area A cosθ and bounce away, so each set's VPLs sum to E cosθ A ρ.
    let rho = 0.5;
    let irradiance = Vec3::new(2.0, 1.5, 1.0);
    for (direction, normal) in
        [(Vec3::new(0.3, -1.0, 0.2).normalize(), Vec3::Y), (Vec3::new(-0.5, 1.0, 0.1).normalize(), -Vec3::Y)]
    {
        let light = Light::Directional { direction, irradiance };
        let scene = PreparedScene::new(scene(
            vec![plane(0.0, 2.0, true, 0)],
            vec![diffuse("grey", rho)],
            vec![light],
        ));
        let samples = per_set(&scene, 32, 20, |set| {
            for v in set {
                assert!(v.position.y.abs() < 1e-6 && v.normal == normal, "{v:?}");
            }
            total_power(set)
        });
        let want = irradiance * direction.y.abs() * 16.0 * rho;
        assert_mean3(&samples, want, 0.0, &format!("sun along {direction}"));
    }
}

#[test]
fn vpls_the_view_cannot_see_are_kept_one_in_sixteen_with_sixteen_times_the_power() {
    // The sun on a 4 × 4 floor before a wall, seen from the front and from under the floor:
    // from under it no VPL can light what the camera sees, so a frame keeps one in sixteen,
    // each with 16 times the power, and starts 16 times the paths to keep V VPLs per set.
    let rho = 0.5;
    let (direction, irradiance) = (Vec3::new(0.3, -1.0, 0.0).normalize(), Vec3::new(2.0, 1.5, 1.0));
    let wall = square_z(-2.0, 2.0, Vec3::Z, 0);
    let scene = PreparedScene::new(scene(
        vec![plane(0.0, 2.0, true, 0), wall],
        vec![diffuse("grey", rho)],
        vec![Light::Directional { direction, irradiance }],
    ));
    let vpls = 32;
    let from = |position: Vec3, seed: u32| FrameState {
        camera: camera(position, Vec3::new(0.0, 0.5, -2.0), 60.0),
        ..frame(seed, vpls)
    };
    let (front, under) = (Vec3::new(0.0, 1.5, 3.0), Vec3::new(0.0, -3.0, 3.0));
    let (seen, unseen) =
        (VplSets::generate(&scene, &from(front, 0)), VplSets::generate(&scene, &from(under, 0)));
    let ratio = unseen.paths() as f32 / seen.paths() as f32;
    assert!(
        (ratio - 16.0).abs() < 0.1,
        "{} paths from under the floor, {} from the front",
        unseen.paths(),
        seen.paths()
    );
    // Every VPL carries about Φ ρ / P (the walk's weight over its survival probability is 1
    // for grey Lambertian surfaces, up to the shading normals): kept with probability 1/16, 16
    // times that of one path of the frame.
    let brightest = |sets: &VplSets| sets.set(0).iter().map(|v| v.power).fold(Vec3::ZERO, Vec3::max);
    let (kept, seen) = (brightest(&unseen), brightest(&seen));
    assert!(rel_err(kept, 16.0 / ratio * seen) < 0.01, "{kept} against {seen}");
    for position in [front, under] {
        let (mut counts, mut floor_power) = (Vec::new(), Vec::new());
        for seed in 0..20 {
            let sets = VplSets::generate(&scene, &from(position, seed));
            for s in 0..sets.set_count() {
                counts.push(sets.set(s).len() as f64);
                floor_power.push(sets.set(s).iter().filter(|v| v.normal == Vec3::Y).map(|v| v.power).sum());
            }
        }
        let (mean, _) = mean_and_error(&counts);
        assert!((mean / f64::from(vpls - 1) - 1.0).abs() < 0.1, "camera at {position}: {mean} VPLs per set");
        // The sun deposits E cosθ A ρ on the floor, whichever VPLs are kept.
        assert_mean3(
            &floor_power,
            irradiance * direction.y.abs() * 16.0 * rho,
            0.0,
            &format!("camera at {position}"),
        );
    }
}

#[test]
fn vpls_seen_in_a_mirror_are_kept() {
    // The camera at the origin looks at a wall (z = 5); behind it stands another (z = -4),
    // and a VPL at z = -3 faces that one. The wall in front cannot see the VPL; with a mirror
    // over the left half of it, the camera's rays see the wall behind, which the VPL lights.
    let vpl = (Vec3::new(0.0, 0.0, -3.0), -Vec3::Z);
    let walls = vec![square_z(5.0, 10.0, Vec3::ZERO, 0), square_z(-4.0, 10.0, Vec3::ZERO, 0)];
    let mirror = quad_facing(
        "mirror",
        [
            Vec3::new(-10.0, -10.0, 4.9),
            Vec3::new(0.0, -10.0, 4.9),
            Vec3::new(0.0, 10.0, 4.9),
            Vec3::new(-10.0, 10.0, 4.9),
        ],
        Vec3::ZERO,
        1,
    );
    let frame = FrameState { camera: camera(Vec3::ZERO, Vec3::new(0.0, 0.0, 5.0), 60.0), ..frame(0, 12) };
    let materials = vec![diffuse("grey", 0.5), material(MaterialKind::Mirror, 1.0)];
    for (meshes, want) in [(walls.clone(), UNSEEN_ACCEPTANCE), ([walls, vec![mirror]].concat(), 1.0)] {
        let scene = PreparedScene::new(scene(meshes, materials.clone(), Vec::new()));
        let view = ViewImportance::new(&scene, &frame);
        assert_eq!(view.surface_acceptance(scene.accel(), vpl.0, vpl.1), want);
    }
}

#[test]
fn point_light_paths_start_at_the_light_and_fill_its_solid_angle() {
    // An isotropic light 1 below the centre of a 6 × 6 plane: the VPLs face down (the side
    // the light arrived from), none sits at the light, and they sum to I Ω ρ.
    let rho = 0.5;
    let intensity = Vec3::new(3.0, 2.0, 1.0);
    let light = Light::Point { position: Vec3::new(0.0, -1.0, 0.0), intensity };
    let scene = PreparedScene::new(scene(
        vec![plane(0.0, 3.0, true, 0)],
        vec![diffuse("grey", rho)],
        vec![light.clone()],
    ));
    let sets = VplSets::generate(&scene, &frame(0, 16));
    assert_eq!(sets.lights(), &[light]);
    let samples = per_set(&scene, 16, 20, |set| {
        for v in set {
            assert!(v.position.y.abs() < 1e-6 && v.normal == -Vec3::Y, "{v:?}");
        }
        total_power(set)
    });
    let want = intensity * (square_solid_angle(3.0, 1.0) * f64::from(rho)) as f32;
    assert_mean3(&samples, want, 0.0, "point light");
}

#[test]
fn spot_light_vpls_stay_inside_its_cone() {
    // Full angle 60° from height 1: the cone meets the 6 × 6 plane in a disc of radius
    // tan 30°, and the whole cone's power 2π (1 − cos 30°) I reaches the plane.
    let rho = 0.5;
    let intensity = Vec3::splat(5.0);
    let position = Vec3::new(0.2, 1.0, -0.1);
    let axis = Vec3::new(0.2, -1.0, 0.1).normalize();
    let light = Light::Spot { position, direction: axis, angle_deg: 60.0, intensity };
    let scene =
        PreparedScene::new(scene(vec![plane(0.0, 3.0, true, 0)], vec![diffuse("grey", rho)], vec![light]));
    let cos_half = 30f32.to_radians().cos();
    let samples = per_set(&scene, 16, 20, |set| {
        for v in set {
            let cos = (v.position - position).normalize().dot(axis);
            assert!(cos >= cos_half - 1e-5 && v.normal == Vec3::Y, "{v:?} at cos {cos}");
        }
        total_power(set)
    });
    let want = intensity * (2.0 * PI * (1.0 - 30f64.to_radians().cos()) * f64::from(rho)) as f32;
    assert_mean3(&samples, want, 0.0, "spot light");
}

#[test]
fn many_point_lights_are_sampled_per_set_with_their_whole_power() {
    // 40 point lights of different intensities under a plane, more than the 8 of 16 VPLs per
    // pixel that may light every set exactly: no exact light, and each set's sampled lights
    // (chosen in proportion to their power, each scaled by 1 / (p_l P)) sum to the scene's
    // whole intensity, since every path starts at one of them.
    let lights: Vec<Light> = (0..40)
        .map(|i| Light::Point {
            position: Vec3::new(0.1 * i as f32 - 2.0, -1.0, 0.05 * i as f32),
            intensity: Vec3::new(1.0 + i as f32, 2.0, 0.5 + 0.1 * i as f32),
        })
        .collect();
    let total: Vec3 = lights
        .iter()
        .map(|l| match l {
            Light::Point { intensity, .. } => *intensity,
            _ => unreachable!(),
        })
        .sum();
    let many =
        PreparedScene::new(scene(vec![plane(0.0, 3.0, true, 0)], vec![diffuse("grey", 0.5)], lights.clone()));
    let sets = VplSets::generate(&many, &frame(0, 16));
    assert!(sets.lights().is_empty(), "40 lights are more than 16 VPLs per pixel may light exactly");
    for s in 0..sets.set_count() {
        let sampled = sets.sky(s);
        assert!(!sampled.is_empty() && sampled.len() < lights.len(), "set {s}: {} lights", sampled.len());
        let intensity: Vec3 = sampled
            .iter()
            .map(|l| match l {
                Light::Point { intensity, .. } => *intensity,
                other => panic!("a sampled point light: {other:?}"),
            })
            .sum();
        // The luminance is exact; the channels follow the chosen lights' colours.
        let luminance = |c: Vec3| c.dot(Vec3::new(0.2126, 0.7152, 0.0722));
        let relative = (luminance(intensity) - luminance(total)).abs() / luminance(total);
        assert!(relative < 1e-4, "set {s}: {intensity} against {total}");
    }
    // Up to the limit, the lights stay exact in every set.
    let few = PreparedScene::new(scene(
        vec![plane(0.0, 3.0, true, 0)],
        vec![diffuse("grey", 0.5)],
        lights[..8].to_vec(),
    ));
    let sets = VplSets::generate(&few, &frame(0, 16));
    assert_eq!(sets.lights(), &lights[..8]);
    assert!((0..sets.set_count()).all(|s| sets.sky(s).is_empty()));
}

#[test]
fn scene_without_lights_walks_from_the_headlight() {
    let scene = PreparedScene::new(scene(vec![plane(0.0, 3.0, true, 0)], vec![diffuse("grey", 0.5)], vec![]));
    let f = frame(0, 16);
    let sets = VplSets::generate(&scene, &f);
    assert_eq!(sets.lights(), &[eye_light(&scene.bounds(), &f.camera)]);
    assert!(sets.total_vpls() > 0, "the headlight's particles should light the plane");
    for s in 0..sets.set_count() {
        assert!(sets.set(s).iter().all(|v| v.position.y.abs() < 1e-6 && v.normal == Vec3::Y));
    }
}

#[test]
fn mirror_passes_power_on_without_vpls() {
    // A point light halfway between a mirror floor (reflectance m) and a diffuse ceiling
    // (reflectance ρ), 2000 wide: half the flux reaches the ceiling directly, half by the
    // mirror, and each further ceiling → mirror → ceiling round trip keeps ρ m of it:
    // Φ ρ (1 + m) / 2 / (1 − ρ m), with Φ = 4π I (a few 0.1 % escape at the far edges).
    let (rho, m) = (0.5f32, 0.5f32);
    let intensity = Vec3::splat(1.0);
    let light = Light::Point { position: Vec3::new(0.0, 1.0, 0.0), intensity };
    let meshes = vec![plane(0.0, 1000.0, true, 0), plane(2.0, 1000.0, false, 1)];
    let materials = vec![material(MaterialKind::Mirror, m), diffuse("ceiling", rho)];
    let scene = PreparedScene::new(scene(meshes, materials, vec![light]));
    let samples = per_set(&scene, 32, 20, |set| {
        for v in set {
            assert!((v.position.y - 2.0).abs() < 1e-4 && v.normal == -Vec3::Y, "VPL off the ceiling: {v:?}");
        }
        f64::from(total_power(set).x)
    });
    let want = 4.0 * PI * f64::from(rho * (1.0 + m) / 2.0 / (1.0 - rho * m));
    assert_mean(&samples, want, 0.01, "mirror");
}

#[test]
fn glass_conserves_power_between_diffuse_planes() {
    // A glass interface at y = 0 between a diffuse floor (y = −1, inside the glass) and a
    // diffuse ceiling (y = 2), both of reflectance ρ, with a point light at y = 1: glass
    // absorbs nothing, so the particles deposit Φ (ρ + ρ² + …) = Φ ρ / (1 − ρ) on the planes
    // and no VPL on the glass.
    let rho = 0.5f32;
    let light = Light::Point { position: Vec3::new(0.0, 1.0, 0.0), intensity: Vec3::ONE };
    let meshes =
        vec![plane(-1.0, 1000.0, true, 0), plane(0.0, 1000.0, true, 1), plane(2.0, 1000.0, false, 0)];
    let glass = Material { ior: 1.5, ..material(MaterialKind::Glass, 0.0) };
    let scene = PreparedScene::new(scene(meshes, vec![diffuse("grey", rho), glass], vec![light]));
    let samples = per_set(&scene, 32, 20, |set| {
        for v in set {
            let on_floor = (v.position.y + 1.0).abs() < 1e-4 && v.normal == Vec3::Y;
            let on_ceiling = (v.position.y - 2.0).abs() < 1e-4 && v.normal == -Vec3::Y;
            assert!(on_floor || on_ceiling, "VPL off the diffuse planes: {v:?}");
        }
        f64::from(total_power(set).x)
    });
    let want = 4.0 * PI * f64::from(rho / (1.0 - rho));
    assert_mean(&samples, want, 0.01, "glass");
}

/// The VPL estimate of the irradiance at `x` (unit normal `n`), without visibility:
/// Σ Φ_i cosθ_i cosθ_x / (π d²).
fn vpl_irradiance(set: &[Vpl], x: Vec3, n: Vec3) -> f64 {
    set.iter()
        .map(|v| {
            let d = x - v.position;
            let d2 = f64::from(d.length_squared());
            let w = d.normalize();
            let g = f64::from(v.normal.dot(w).max(0.0)) * f64::from(n.dot(-w).max(0.0)) / (PI * d2);
            f64::from(v.power.x) * g
        })
        .sum()
}

#[test]
fn light_surface_vpls_estimate_the_irradiance_of_a_square_emitter() {
    // A 1 × 1 emitter of radiance L_e, 1 above the receiver point: E = π L_e F with F the
    // point-to-rectangle form factor (four corner rectangles of 0.5 × 0.5).
    let le = 2.0f32;
    let meshes =
        vec![plane(0.0, 3.0, true, 0), horizontal_square("light", Vec3::Y, Vec2::splat(0.5), false, 1)];
    let scene = PreparedScene::new(scene(
        meshes,
        vec![diffuse("black", 0.0), emitter("light", Vec3::splat(le))],
        vec![],
    ));
    let samples = per_set(&scene, 64, 10, |set| vpl_irradiance(set, Vec3::ZERO, Vec3::Y));
    let want = PI * f64::from(le) * 4.0 * corner_form_factor(0.5, 0.5, 1.0);
    assert_mean(&samples, want, 0.0, "area-light irradiance");
}

#[test]
fn bounce_vpls_estimate_the_irradiance_reflected_by_a_lit_plane() {
    // A point light over a 4 × 4 plane of reflectance ρ. The plane reflects radiance
    // ρ/π · I cosθ_l / r² toward a receiver x facing down; its irradiance there,
    // ∫ L cosθ_p cosθ_x / d² dA, is integrated by the midpoint rule and must match the
    // VPL estimate.
    let (rho, half) = (0.5f64, 2.0f64);
    let light_pos = Vec3::new(0.5, 1.0, 0.0);
    let light = Light::Point { position: light_pos, intensity: Vec3::ONE };
    let scene = PreparedScene::new(scene(
        vec![plane(0.0, half as f32, true, 0)],
        vec![diffuse("grey", rho as f32)],
        vec![light],
    ));
    let (x, n) = (Vec3::new(-0.3, 0.8, 0.2), -Vec3::Y);
    let samples = per_set(&scene, 64, 30, |set| vpl_irradiance(set, x, n));

    let cells = 800;
    let h = 2.0 * half / f64::from(cells);
    let mut want = 0.0;
    for i in 0..cells {
        for j in 0..cells {
            let p = [-half + (f64::from(i) + 0.5) * h, 0.0, -half + (f64::from(j) + 0.5) * h];
            let to_light =
                [f64::from(light_pos.x) - p[0], f64::from(light_pos.y), f64::from(light_pos.z) - p[2]];
            let r2 = to_light.iter().map(|c| c * c).sum::<f64>();
            let radiance = rho / PI * to_light[1] / r2.sqrt() / r2;
            let to_x = [f64::from(x.x) - p[0], f64::from(x.y), f64::from(x.z) - p[2]];
            let d2 = to_x.iter().map(|c| c * c).sum::<f64>();
            // cosθ_p = to_x.y / d, cosθ_x = to_x.y / d (x faces straight down).
            want += radiance * to_x[1] * to_x[1] / (d2 * d2) * h * h;
        }
    }
    assert_mean(&samples, want, 0.0, "bounce irradiance");
}

#[test]
fn cornell_box_sets_hold_about_v_vpls() {
    let scene = PreparedScene::new(igi_scene::builtin("cornell-box").expect("built-in scene"));
    for v in [12, 108] {
        let counts = per_set(&scene, v, 30, |set| set.len() as f64);
        let (mean, _) = mean_and_error(&counts);
        let sets = VplSets::generate(&scene, &frame(0, v));
        assert!(sets.lights().is_empty());
        // round(S·V / e) paths shared out: rounding moves the mean by at most e / (2S) VPLs.
        let rounding = 0.5 * f64::from(sets.expected_vpls_per_path()) / f64::from(v) / 9.0;
        assert!(
            (mean / f64::from(v) - 1.0).abs() < 0.1 + rounding,
            "V = {v}: mean {mean} VPLs per set from {} paths in all (e = {})",
            sets.paths(),
            sets.expected_vpls_per_path()
        );
    }
}

#[test]
fn the_bounce_limit_truncates_light_paths() {
    let scene = PreparedScene::new(igi_scene::builtin("cornell-box").unwrap());
    let vpls_per_path = |bounces: u32| {
        let mut f = frame(0, 12);
        f.settings.bounces = bounces;
        let sets = VplSets::generate(&scene, &f);
        let total: usize = (0..sets.set_count()).map(|s| sets.set(s).len()).sum();
        let power: Vec3 = (0..sets.set_count()).map(|s| total_power(sets.set(s))).sum();
        (total as f64 / f64::from(sets.paths()), power)
    };
    // Without bounces a path leaves exactly its VPL on the light: direct light only.
    let (direct, direct_power) = vpls_per_path(0);
    assert_eq!(direct, 1.0);
    let (one, one_power) = vpls_per_path(1);
    assert!(one > 1.5 && one <= 2.0, "{one}");
    let (all, all_power) = vpls_per_path(MAX_BOUNCES);
    assert!(all > one, "{all} vs {one}");
    // Each bounce adds the power of the light it reflects.
    assert!(direct_power.x < one_power.x && one_power.x < all_power.x);
}
