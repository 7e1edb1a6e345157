//! Tests of [`super`].

use super::*;
use igi_bvh::TriangleMesh;

/// Points along a floor lit by one VPL above its start: far points get a small share of the
/// clamp's ceiling, so the roulette traces fewer shadow rays than points, and over many
/// VPL placements the light it estimates is the exact light (unbiased).
#[test]
fn shadow_roulette_traces_fewer_rays_and_keeps_the_mean() {
    let (accel, _) = Accel::build(vec![TriangleMesh::default()], &[]);
    let points: Vec<Vec3> = (0..64).map(|i| Vec3::new(0.25 + i as f32 * 0.5, 0.0, 0.0)).collect();
    let (mut estimated, mut exact, mut rays, mut lanes) = (0.0f64, 0.0f64, 0u64, 0u64);
    let mut receivers = Receivers::default();
    for trial in 0..400 {
        let vpl = Vpl::diffuse(Vec3::new(trial as f32 * 1e-3, 1.0, 0.0), Vec3::NEG_Y, Vec3::splat(PI * PI));
        receivers.clear();
        for (k, &p) in points.iter().enumerate() {
            receivers.push((p, k as u32 + 1000 * trial), Vec3::Y, Vec3::Y, None);
        }
        let mut counts = RayCounts::default();
        let roulette = ShadowRoulette { below: 0.005, d_min2: 1.0 };
        receivers.add_vpls(&accel, std::iter::once(&vpl), 1.0, 1.0, roulette, &mut counts);
        rays += counts.shadow;
        lanes += points.len() as u64;
        for (k, &p) in points.iter().enumerate() {
            let d = offset_ray_origin(vpl.position, vpl.normal) - p;
            let (cos_x, cos_y) = (d.normalize().y, d.normalize().y);
            exact += f64::from(cos_x * cos_y / d.length_squared().max(1.0));
            estimated += f64::from(receivers.radiance(k).0.x);
        }
    }
    assert!(rays * 2 < lanes, "{rays} shadow rays for {lanes} point-VPL pairs");
    assert!((estimated / exact - 1.0).abs() < 0.03, "estimated {estimated}, exact {exact}");
}

/// Shadow rays gathered into full packets answer for the right points: floor points half
/// behind a wall, lit by VPLs on both sides, get exactly the light of their VPLs that a
/// single ray from each point sees.
#[test]
fn gathered_shadow_rays_answer_for_their_own_points() {
    // A wall x = 0 from y = 0.1 to 2, z from -10 to 10.
    let wall = TriangleMesh {
        positions: vec![
            Vec3::new(0.0, 0.1, -10.0),
            Vec3::new(0.0, 2.0, -10.0),
            Vec3::new(0.0, 2.0, 10.0),
            Vec3::new(0.0, 0.1, 10.0),
        ],
        indices: vec![[0, 1, 2], [0, 2, 3]],
    };
    let (accel, _) = Accel::build(vec![wall], &[(0, glam::Affine3A::IDENTITY)]);
    let points: Vec<Vec3> =
        (0..45).map(|i| Vec3::new(-2.05 + (i % 9) as f32 * 0.5, 0.0, (i / 9) as f32 * 0.7 - 1.4)).collect();
    let vpls: Vec<Vpl> = [-1.5f32, -0.5, 0.7, 1.9]
        .iter()
        .map(|&x| Vpl::diffuse(Vec3::new(x, 1.0, 0.3 * x), Vec3::NEG_Y, Vec3::splat(1.0)))
        .collect();
    let mut receivers = Receivers::default();
    for (k, &p) in points.iter().enumerate() {
        receivers.push((p + Vec3::Y * 1e-3, k as u32), Vec3::Y, Vec3::Y, None);
    }
    let mut counts = RayCounts::default();
    receivers.add_vpls(&accel, vpls.iter(), 1.0, 0.0, ShadowRoulette::OFF, &mut counts);
    let (mut lit, mut blocked) = (0, 0);
    for (k, &p) in points.iter().enumerate() {
        let origin = p + Vec3::Y * 1e-3;
        let mut expected = 0.0;
        for vpl in &vpls {
            let d = offset_ray_origin(vpl.position, vpl.normal) - origin;
            let ray = Ray { origin, dir: d.normalize(), tnear: 0.0, tfar: d.length() * SHADOW_SHORTEN };
            if accel.occluded(&ray) {
                blocked += 1;
                continue;
            }
            lit += 1;
            let cos = d.normalize().y;
            expected += vpl.power.x * FRAC_1_PI * FRAC_1_PI * cos * cos / d.length_squared();
        }
        let d = receivers.radiance(k).0.x;
        assert!((d - expected).abs() <= 1e-5 * expected.max(1e-3), "point {k}: {d}, expected {expected}");
    }
    assert!(lit > 20 && blocked > 20, "{lit} lit and {blocked} blocked point-VPL pairs");
}

/// Twelve VPLs of equal light around a point, each 1/12 of its light, below the roulette's
/// share: each would be traced with probability (1/12)/share; systematic sampling traces
/// exactly that expected number of them at every point (independent draws would trace
/// anywhere from 0 to 12), and since they are equal, every estimate is exact.
#[test]
fn shadow_roulette_share_traces_the_expected_number_of_rays_per_point() {
    let (accel, _) = Accel::build(vec![TriangleMesh::default()], &[]);
    let vpls: Vec<Vpl> = (0..12)
        .map(|k| {
            let angle = k as f32 * std::f32::consts::TAU / 12.0;
            let y = Vec3::new(angle.cos(), 1.0, angle.sin());
            Vpl::diffuse(y, -y.normalize(), Vec3::splat(1.0))
        })
        .collect();
    let share = 1.0 / 12.0 / SHADOW_ROULETTE_SHARE;
    let expected = (12.0 * share).round() as u64;
    assert!((12.0 * share - expected as f32).abs() < 1e-4, "the test wants a whole expected count");
    let roulette = ShadowRoulette { below: 1e-9, d_min2: 0.0 };
    let mut receivers = Receivers::default();
    let mut exact = Receivers::default();
    for trial in 0..100u32 {
        receivers.clear();
        exact.clear();
        for lane in 0..8 {
            receivers.push((Vec3::ZERO, trial * 8 + lane), Vec3::Y, Vec3::Y, None);
            exact.push((Vec3::ZERO, 0), Vec3::Y, Vec3::Y, None);
        }
        let mut counts = RayCounts::default();
        receivers.add_vpls(&accel, vpls.iter(), 1.0, 0.0, roulette, &mut counts);
        assert_eq!(counts.shadow, 8 * expected, "trial {trial}");
        exact.add_vpls(&accel, vpls.iter(), 1.0, 0.0, ShadowRoulette::OFF, &mut RayCounts::default());
        for lane in 0..8 {
            let (d, e) = (receivers.radiance(lane).0.x, exact.radiance(lane).0.x);
            assert!((d / e - 1.0).abs() < 1e-4, "trial {trial}: {d} for {e}");
        }
    }
}
