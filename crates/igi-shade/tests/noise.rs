//! Facts about `igi_shade::noise`: lattice zeros, range, Lipschitz continuity, determinism,
//! SIMD = scalar bit for bit, and analytic gradients = central differences.

use glam::Vec3;
use igi_shade::noise::*;
use igi_simd::Vec3x8;

/// A small deterministic generator (xorshift64*), so the tests need no dependency.
struct Rng(u64);

impl Rng {
    fn next_f32(&mut self) -> f32 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 40) as f32 / (1u64 << 24) as f32
    }
    fn point(&mut self, extent: f32) -> Vec3 {
        Vec3::new(self.next_f32(), self.next_f32(), self.next_f32()) * (2.0 * extent) - Vec3::splat(extent)
    }
}

#[test]
fn zero_at_lattice_points() {
    for x in -5..5 {
        for y in -5..5 {
            for z in -5..5 {
                let p = Vec3::new(x as f32, y as f32, z as f32) * 7.0;
                assert_eq!(noise3(p.to_array()), 0.0, "{p}");
                assert_eq!(fbm3(p.to_array(), 5), 0.0, "{p}");
            }
        }
    }
}

#[test]
fn range_within_unit_interval() {
    let mut rng = Rng(1);
    let (mut lo, mut hi, mut best) = (0.0f32, 0.0f32, Vec3::ZERO);
    for _ in 0..1_000_000 {
        let p = rng.point(300.0);
        let n = noise3(p.to_array());
        if n.abs() > hi.max(-lo) {
            best = p;
        }
        lo = lo.min(n);
        hi = hi.max(n);
    }
    assert!(hi > 0.85 && lo < -0.85, "noise should use most of its range: {lo} {hi}");
    // Climb from the most extreme sample along the analytic gradient.
    let sign = noise3(best.to_array()).signum();
    let mut p = best;
    for _ in 0..2000 {
        let (_, g) = noise3_grad(p.to_array());
        p += Vec3::from(g) * (sign * 1e-3);
    }
    let peak = noise3(p.to_array()).abs();
    assert!(peak <= 1.0, "local extreme {peak} at {p}");
    assert!(hi.max(-lo) <= 1.0);
    // The fractal sums stay inside their documented bounds.
    for _ in 0..100_000 {
        let p = rng.point(50.0);
        assert!(fbm3(p.to_array(), 6).abs() <= 1.0364 * (2.0 - 2f32.powi(-5)));
        let t = turbulence3(p.to_array(), 6);
        assert!((0.0..=1.0364 * (2.0 - 2f32.powi(-5))).contains(&t));
    }
}

#[test]
fn lipschitz_continuous() {
    // |∇n| ≤ 8.5 √3 (module documentation).
    let lipschitz = 8.5 * 3f32.sqrt();
    let mut rng = Rng(2);
    let mut worst = 0.0f32;
    for _ in 0..200_000 {
        let p = rng.point(20.0);
        let eps = 1e-3 * (1.0 + rng.next_f32());
        let d = rng.point(1.0).normalize_or(Vec3::X) * eps;
        let slope = (noise3((p + d).to_array()) - noise3(p.to_array())).abs() / d.length();
        worst = worst.max(slope);
        // Allow for the f32 rounding of the two values.
        assert!(slope <= lipschitz + 2e-6 / eps, "slope {slope} at {p}");
    }
    assert!(worst > 1.0, "the test should probe real slopes, saw {worst}");
}

#[test]
fn deterministic_and_not_trivial() {
    let p = Vec3::new(3.75, -1.25, 0.375);
    assert_eq!(noise3(p.to_array()).to_bits(), noise3(p.to_array()).to_bits());
    let t = std::thread::spawn(move || noise3(p.to_array())).join().unwrap();
    assert_eq!(noise3(p.to_array()).to_bits(), t.to_bits());
    assert_ne!(noise3(p.to_array()), noise3((p + Vec3::new(0.31, 0.0, 0.0)).to_array()));
    // Period 256 along each axis: the hash wraps.
    assert_eq!(noise3(p.to_array()), noise3((p + Vec3::new(256.0, 0.0, -256.0)).to_array()));
}

#[test]
fn simd_equals_scalar_bit_for_bit() {
    let mut rng = Rng(3);
    for round in 0..20_000 {
        let extent = if round % 2 == 0 { 4.0 } else { 1000.0 };
        let pts: [Vec3; 8] = std::array::from_fn(|_| rng.point(extent));
        let p8 = Vec3x8::from_lanes(pts.map(|p| p.to_array()));
        let octaves = round % 7;
        let n8 = noise3(p8.into());
        let (ng8, g8) = noise3_grad(p8.into());
        let f8 = fbm3(p8.into(), octaves);
        let (fg8, fgrad8) = fbm3_grad(p8.into(), octaves);
        let t8 = turbulence3(p8.into(), octaves);
        let (tg8, tgrad8) = turbulence3_grad(p8.into(), octaves);
        let (g8, fgrad8, tgrad8) = (Vec3x8::from(g8), Vec3x8::from(fgrad8), Vec3x8::from(tgrad8));
        for (i, &p) in pts.iter().enumerate() {
            let bits = |v: [f32; 3]| v.map(f32::to_bits);
            let (n, g) = noise3_grad(p.to_array());
            assert_eq!(n8.lane(i).to_bits(), noise3(p.to_array()).to_bits());
            assert_eq!(n.to_bits(), noise3(p.to_array()).to_bits(), "value with and without gradient");
            assert_eq!(ng8.lane(i).to_bits(), n.to_bits());
            assert_eq!(bits(g8.lane(i)), bits(g));
            let (f, fg) = fbm3_grad(p.to_array(), octaves);
            assert_eq!(f8.lane(i).to_bits(), fbm3(p.to_array(), octaves).to_bits());
            assert_eq!(fg8.lane(i).to_bits(), f.to_bits());
            assert_eq!(bits(fgrad8.lane(i)), bits(fg));
            let (t, tg) = turbulence3_grad(p.to_array(), octaves);
            assert_eq!(t8.lane(i).to_bits(), turbulence3(p.to_array(), octaves).to_bits());
            assert_eq!(tg8.lane(i).to_bits(), t.to_bits());
            assert_eq!(bits(tgrad8.lane(i)), bits(tg));
        }
    }
}

/// Central differences of `f` at `p` with step `h` (in f64 arithmetic on the f32 values).
fn central(f: impl Fn(Vec3) -> f32, p: Vec3, h: f32) -> Vec3 {
    let d = |axis: Vec3| (f(p + axis * h) as f64 - f(p - axis * h) as f64) / (2.0 * h as f64);
    Vec3::new(d(Vec3::X) as f32, d(Vec3::Y) as f32, d(Vec3::Z) as f32)
}

#[test]
fn analytic_gradient_equals_central_differences() {
    let mut rng = Rng(4);
    let h = 1e-3;
    for _ in 0..20_000 {
        let p = rng.point(50.0) + Vec3::splat(0.5);
        let g = Vec3::from(noise3_grad(p.to_array()).1);
        let fd = central(|q| noise3(q.to_array()), p, h);
        // Truncation error h²/6 · |n‴| (n‴ is bounded by a few hundred) plus rounding.
        assert!((g - fd).abs().max_element() < 2e-3, "{p}: {g} vs {fd}");
    }
    for _ in 0..2000 {
        let p = rng.point(5.0);
        let g = Vec3::from(fbm3_grad(p.to_array(), 4).1);
        let fd = central(|q| fbm3(q.to_array(), 4), p, 1e-4);
        assert!((g - fd).abs().max_element() < 2e-2, "fbm {p}: {g} vs {fd}");
        // Away from the creases turbulence is smooth too.
        let creased = (0..4).any(|o| noise3((p * 2f32.powi(o)).to_array()).abs() < 1e-2);
        if !creased {
            let g = Vec3::from(turbulence3_grad(p.to_array(), 4).1);
            let fd = central(|q| turbulence3(q.to_array(), 4), p, 1e-4);
            assert!((g - fd).abs().max_element() < 2e-2, "turbulence {p}: {g} vs {fd}");
        }
    }
}
