//! Facts about `ProceduralShader`: known colours of checker and brick, SIMD = a scalar
//! per-lane evaluation for the noise patterns, and bump mapping that keeps normals unit, in the
//! geometric hemisphere, and unchanged on flat parts of the height field.

use glam::Vec3;
use igi_scene::{Pattern, ShaderDesc};
use igi_shade::noise::{noise3_grad, turbulence3_grad};
use igi_shade::{BrdfParams8, ProceduralShader, ShadingHit8, SurfaceShader};
use igi_simd::{F32x8, I32x8, M32x8, Vec3x8};

const C0: Vec3 = Vec3::new(0.8, 0.2, 0.1);
const C1: Vec3 = Vec3::new(0.1, 0.3, 0.9);

fn desc(pattern: Pattern, scale: f32, bump: f32) -> ShaderDesc {
    ShaderDesc { pattern, scale, colors: [C0, C1], glossy: Vec3::splat(0.2), exponent: 40.0, bump }
}

/// Eight hits at `points` (object = world space) with shading and geometric normal `n[i]`.
fn hits(points: [Vec3; 8], n: [Vec3; 8]) -> ShadingHit8 {
    let v = |a: [Vec3; 8]| Vec3x8::from_lanes(a.map(|p| p.to_array()));
    ShadingHit8 {
        position: v(points),
        object_position: v(points),
        geometric_normal: v(n),
        shading_normal: v(n),
        u: F32x8::ZERO,
        v: F32x8::ZERO,
        dpdu: Vec3x8::splat([1.0, 0.0, 0.0]),
        dpdv: Vec3x8::splat([0.0, 1.0, 0.0]),
        footprint: F32x8::splat(1e-3),
        object: I32x8::splat(0),
        active: M32x8::ALL,
        material: 0,
        time: 0.0,
    }
}

fn shade(d: &ShaderDesc, points: [Vec3; 8], n: [Vec3; 8]) -> BrdfParams8 {
    let h = hits(points, n);
    let mut out = BrdfParams8::black(h.shading_normal);
    ProceduralShader::new(d).shade(&h, &mut out);
    out
}

fn diffuse(out: &BrdfParams8, i: usize) -> Vec3 {
    Vec3::from(out.diffuse.lane(i))
}

fn normal(out: &BrdfParams8, i: usize) -> Vec3 {
    Vec3::from(out.shading_normal.lane(i))
}

#[test]
fn checker_colours_at_known_points() {
    let p = [
        Vec3::new(0.5, 0.5, 0.5),
        Vec3::new(1.5, 0.5, 0.5),
        Vec3::new(-0.5, 0.5, 0.5),
        Vec3::new(-0.5, -0.5, 0.5),
        Vec3::new(1.5, 1.5, 1.5),
        Vec3::new(-2.5, 7.5, 0.25),
        Vec3::new(0.25, 0.75, 0.0),
        Vec3::new(0.1, 0.1, -0.1),
    ];
    let want = [C0, C1, C1, C0, C1, C0, C0, C1];
    // Scale 2: cubes of half a unit, so evaluate at half the points.
    let out = shade(&desc(Pattern::Checker, 2.0, 0.5), p.map(|q| q * 0.5), [Vec3::Z; 8]);
    for i in 0..8 {
        assert_eq!(diffuse(&out, i), want[i], "lane {i} at {}", p[i]);
        assert_eq!(normal(&out, i), Vec3::Z, "a checker has no bump");
        assert_eq!(Vec3::from(out.glossy.lane(i)), Vec3::splat(0.2));
        assert_eq!(out.exponent.lane(i), 40.0);
    }
}

fn brick() -> Pattern {
    Pattern::Brick { size: Vec3::new(2.0, 1.0, 1.0), mortar: 0.1 }
}

#[test]
fn brick_centre_is_brick_and_joints_are_mortar() {
    let p = [
        Vec3::new(1.0, 0.5, 0.5),   // centre of a brick in row 0
        Vec3::new(0.0, 0.5, 0.5),   // head joint, row 0
        Vec3::new(1.0, 1.0, 0.5),   // bed joint between rows 0 and 1
        Vec3::new(1.0, 1.5, 0.5),   // row 1 is shifted by half a brick: head joint here
        Vec3::new(0.0, 1.5, 0.0),   // ... and its brick centre here
        Vec3::new(-4.0, -0.5, 0.0), // centre of a brick in row −1 (odd: shifted in x and z)
        Vec3::new(1.02, 0.5, 0.5),  // still flat brick face
        Vec3::new(1.0, 0.5, 0.0),   // a joint in depth (z) too
    ];
    let want = [C0, C1, C1, C1, C0, C0, C0, C1];
    let n = [Vec3::Z; 8];
    let out = shade(&desc(brick(), 1.0, 0.02), p, n);
    for (i, want) in want.iter().enumerate() {
        assert!((diffuse(&out, i) - *want).abs().max_element() < 1e-6, "lane {i}: {}", diffuse(&out, i));
        // Brick faces and mortar are flat: the normal is exactly unchanged.
        assert_eq!(normal(&out, i), Vec3::Z, "lane {i}");
    }
}

#[test]
fn brick_bevel_tilts_toward_the_joint() {
    // x = 0.075: in the bevel next to the head joint at x = 0 (mortar half-width 0.05, bevel
    // 0.05), where the height rises with x.
    let p = [Vec3::new(0.075, 0.5, 0.5); 8];
    let out = shade(&desc(brick(), 1.0, 0.02), p, [Vec3::Z; 8]);
    let n = normal(&out, 0);
    assert!(n.x < -0.1 && n.y.abs() < 1e-6 && n.z > 0.0, "{n}");
    assert!((n.length() - 1.0).abs() < 1e-6);
    let t = diffuse(&out, 0);
    assert!(t.x < C0.x && t.x > C1.x, "the bevel blends brick into mortar: {t}");
}

fn band(s: f32) -> f32 {
    let tri = (2.0 * (s - s.floor()) - 1.0).abs();
    tri * tri * (-2.0f32).mul_add(tri, 3.0)
}

fn bumped(n: Vec3, g: Vec3) -> Vec3 {
    (n - (g - g.dot(n) * n)).normalize()
}

/// Scalar per-lane evaluation of a noise pattern: (blend factor, height gradient in q).
fn scalar(pattern: Pattern, q: Vec3) -> (f32, Vec3) {
    match pattern {
        Pattern::Marble { octaves, turbulence } => {
            let (t, g) = turbulence3_grad(q.to_array(), octaves);
            (band(t.mul_add(turbulence, q.x)), Vec3::from(g))
        }
        Pattern::Wood { rings, turbulence } => {
            let (n, g) = noise3_grad(q.to_array());
            let r = q.x.mul_add(q.x, q.z * q.z).sqrt();
            (band(n.mul_add(turbulence, r * rings)), Vec3::from(g))
        }
        Pattern::Turbulence { octaves } => {
            let (t, g) = turbulence3_grad(q.to_array(), octaves);
            (t.clamp(0.0, 1.0), Vec3::from(g))
        }
        _ => unreachable!("only the noise patterns"),
    }
}

fn some_points(seed: u32) -> [Vec3; 8] {
    std::array::from_fn(|i| {
        let k = (seed * 8 + i as u32) as f32;
        Vec3::new(
            (k * 0.7548).fract() * 6.0 - 3.0,
            (k * 0.5698).fract() * 3.0,
            (k * 0.3141).fract() * 6.0 - 3.0,
        )
    })
}

#[test]
fn noise_patterns_equal_scalar_evaluation() {
    let patterns = [
        Pattern::Marble { octaves: 4, turbulence: 5.0 },
        Pattern::Wood { rings: 8.0, turbulence: 0.7 },
        Pattern::Turbulence { octaves: 5 },
    ];
    let n = Vec3::new(0.3, 0.9, -0.2).normalize();
    for pattern in patterns {
        for (scale, bump) in [(1.0, 0.0), (3.0, 0.01), (0.5, -0.2)] {
            for seed in 0..50 {
                let p = some_points(seed);
                let out = shade(&desc(pattern, scale, bump), p, [n; 8]);
                for (i, &pi) in p.iter().enumerate() {
                    let (t, g) = scalar(pattern, pi * scale);
                    let want = (1.0 - t) * C0 + t * C1;
                    assert!((diffuse(&out, i) - want).abs().max_element() < 1e-6, "{pattern:?} {pi}");
                    let want_n = if bump == 0.0 { n } else { bumped(n, g * (bump * scale)) };
                    assert!((normal(&out, i) - want_n).abs().max_element() < 1e-5, "{pattern:?} {pi}");
                }
            }
        }
    }
}

#[test]
fn bump_keeps_normals_unit_and_in_the_geometric_hemisphere() {
    let patterns = [
        Pattern::Marble { octaves: 4, turbulence: 5.0 },
        Pattern::Wood { rings: 8.0, turbulence: 0.7 },
        Pattern::Turbulence { octaves: 5 },
        brick(),
    ];
    let mut bent = 0;
    for pattern in patterns {
        for seed in 0..200 {
            let p = some_points(seed);
            // Normals all over the sphere, and a strong bump that would tip some over.
            let n: [Vec3; 8] = std::array::from_fn(|i| {
                let a = (seed * 8 + i as u32) as f32 * 2.399;
                let z = ((seed * 8 + i as u32) as f32 * 0.618).fract() * 2.0 - 1.0;
                let r = (1.0 - z * z).sqrt();
                Vec3::new(r * a.cos(), r * a.sin(), z).normalize()
            });
            let out = shade(&desc(pattern, 4.0, 0.5), p, n);
            for (i, &ni) in n.iter().enumerate() {
                let b = normal(&out, i);
                assert!((b.length() - 1.0).abs() < 1e-5, "{pattern:?}: |n| = {}", b.length());
                assert!(b.dot(ni) > 0.0, "{pattern:?}: {b} leaves the hemisphere of {ni}");
                if b.dot(ni) < 0.999 {
                    bent += 1;
                }
            }
        }
    }
    assert!(bent > 1000, "the bump should bend normals, bent {bent}");
}
