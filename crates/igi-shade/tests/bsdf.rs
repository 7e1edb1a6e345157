//! The BRDF shaders against the physics they promise: reciprocity, energy conservation (a
//! white furnace per lobe: the directional albedo never exceeds the lobe's reflectance), the
//! sampling routine drawing directions with exactly the density `pdf` reports (a chi-square
//! test), sample weights equal to f·cos/pdf, and Fresnel glass.

use glam::{Vec2, Vec3};
use igi_shade::BrdfParams;
use igi_shade::brdf::dielectric::{Interface, fresnel_dielectric, refract};
use igi_shade::brdf::{Bsdf, Lobe};
use std::f32::consts::PI;

/// A small deterministic generator (xorshift) for test directions.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }

    /// A unit direction in the hemisphere around +Z.
    fn hemisphere(&mut self) -> Vec3 {
        let (z, phi) = (self.next(), 2.0 * PI * self.next());
        let r = (1.0 - z * z).max(0.0).sqrt();
        Vec3::new(r * phi.cos(), r * phi.sin(), z.max(1e-3)).normalize()
    }
}

fn params(diffuse: f32, specular: f32, exponent: f32) -> BrdfParams {
    BrdfParams {
        diffuse: Vec3::splat(diffuse),
        specular: Vec3::splat(specular),
        exponent,
        ..BrdfParams::black(Vec3::Z)
    }
}

/// The directional albedo ∫ f(wo, wi) cos θ_i dω_i by stratified quadrature in (cos θ, φ):
/// fine near the pole for sharp lobes (cos θ = 1 − s² puts more points there).
fn albedo(bsdf: &Bsdf, wo: Vec3) -> f32 {
    let (n, m) = (400, 200);
    let mut sum = 0.0f64;
    for i in 0..n {
        for j in 0..m {
            // cos θ = 1 − s², dcos = 2 s ds.
            let s = (i as f32 + 0.5) / n as f32;
            let cos = 1.0 - s * s;
            let phi = 2.0 * PI * (j as f32 + 0.5) / m as f32;
            let sin = (1.0 - cos * cos).max(0.0).sqrt();
            let wi = Vec3::new(sin * phi.cos(), sin * phi.sin(), cos);
            let weight = 2.0 * s / n as f32 * 2.0 * PI / m as f32;
            sum += f64::from(bsdf.f(wo, wi).x * cos * weight);
        }
    }
    sum as f32
}

#[test]
fn non_delta_lobes_are_reciprocal() {
    let mut rng = Rng(7);
    for &(d, s, e) in &[(0.5, 0.5, 1.0), (0.2, 0.7, 10.0), (0.0, 0.9, 100.0), (0.3, 0.6, 1000.0)] {
        for bent in [Vec3::Z, Vec3::new(0.2, -0.1, 1.0).normalize()] {
            let bsdf = Bsdf::new(BrdfParams { shading_normal: bent, ..params(d, s, e) }, Vec3::Z);
            for _ in 0..2000 {
                let (a, b) = (rng.hemisphere(), rng.hemisphere());
                let (fab, fba) = (bsdf.f(a, b), bsdf.f(b, a));
                // cosⁿα amplifies the rounding of α's cosine n-fold.
                let tolerance = (1e-5 + 1e-7 * e) * fab.max_element().max(1.0);
                assert!((fab - fba).abs().max_element() <= tolerance, "{fab} {fba}");
            }
        }
    }
}

#[test]
fn white_furnace_per_lobe_albedo_never_exceeds_the_reflectance() {
    // Lambert: exactly ρ at every angle. Modified Phong: ρ_s at normal incidence, less at
    // grazing angles (part of the lobe falls below the horizon). Their sum ρ_d + ρ_s = 1
    // never exceeds 1.
    for &theta in &[0.0f32, 0.5, 1.0, 1.4] {
        let wo = Vec3::new(theta.sin(), 0.0, theta.cos());
        let lambert = albedo(&Bsdf::new(params(0.8, 0.0, 1.0), Vec3::Z), wo);
        assert!((lambert - 0.8).abs() < 2e-3, "Lambert at {theta}: {lambert}");
        for &e in &[1.0, 10.0, 100.0] {
            let phong = albedo(&Bsdf::new(params(0.0, 1.0, e), Vec3::Z), wo);
            assert!(phong <= 1.0 + 2e-3, "Phong n = {e} at {theta}: {phong}");
            if theta == 0.0 {
                assert!((phong - 1.0).abs() < 5e-3, "Phong n = {e} at normal incidence: {phong}");
            }
            let sum = albedo(&Bsdf::new(params(0.5, 0.5, e), Vec3::Z), wo);
            assert!(sum <= 1.0 + 2e-3, "mixture n = {e} at {theta}: {sum}");
        }
    }
}

#[test]
fn sample_weights_are_f_cos_over_pdf_and_average_to_the_albedo() {
    let wo = Vec3::new(0.5, 0.0, 0.75f32.sqrt());
    for &(d, s, e) in &[(0.8, 0.0, 1.0), (0.0, 0.9, 20.0), (0.4, 0.5, 60.0)] {
        let bsdf = Bsdf::new(params(d, s, e), Vec3::Z);
        let k = 256;
        let mut mean = 0.0f64;
        for i in 0..k {
            for j in 0..k {
                let u = Vec2::new((i as f32 + 0.5) / k as f32, (j as f32 + 0.5) / k as f32);
                let lobe = ((i * 7 + j * 13) % 64) as f32 / 64.0 + 1.0 / 128.0;
                if let Some(smp) = bsdf.sample(wo, lobe, u) {
                    let want = bsdf.f(wo, smp.wi) * smp.wi.z / bsdf.pdf(wo, smp.wi);
                    assert!((smp.weight - want).abs().max_element() < 1e-4 * want.max_element().max(1.0));
                    assert_eq!(smp.pdf, bsdf.pdf(wo, smp.wi));
                    mean += f64::from(smp.weight.x);
                }
            }
        }
        let mean = mean as f32 / (k * k) as f32;
        let quadrature = albedo(&bsdf, wo);
        assert!((mean - quadrature).abs() < 0.01, "({d}, {s}, {e}): sampled {mean}, quadrature {quadrature}");
    }
}

/// The 0.999 quantile of χ² with `k` degrees of freedom (Wilson–Hilferty).
fn chi2_quantile_999(k: f64) -> f64 {
    let z = 3.090_232;
    let a = 2.0 / (9.0 * k);
    k * (1.0 - a + z * a.sqrt()).powi(3)
}

#[test]
fn sampled_directions_follow_the_reported_density() {
    // Bins in (cos θ, φ) over the hemisphere; the expected count of a bin is N times the
    // integral of `pdf` over it (fine quadrature); bins expecting fewer than 5 are merged.
    let wo = Vec3::new(0.3, 0.2, 0.9).normalize();
    for &(d, s, e) in
        &[(1.0, 0.0, 1.0), (0.0, 1.0, 1.0), (0.0, 1.0, 20.0), (0.0, 1.0, 200.0), (0.5, 0.5, 30.0)]
    {
        let bsdf = Bsdf::new(params(d, s, e), Vec3::Z);
        let (nt, np) = (16usize, 32usize);
        let bin = |w: Vec3| {
            let t = ((1.0 - w.z.clamp(0.0, 1.0)) * nt as f32).min(nt as f32 - 1.0) as usize;
            let p = ((w.y.atan2(w.x) / (2.0 * PI) + 1.0).fract() * np as f32).min(np as f32 - 1.0) as usize;
            t * np + p
        };
        let mut observed = vec![0f64; nt * np];
        let mut rng = Rng(99);
        let n = 200_000;
        for _ in 0..n {
            if let Some(smp) = bsdf.sample(wo, rng.next(), Vec2::new(rng.next(), rng.next())) {
                observed[bin(smp.wi)] += 1.0;
            }
        }
        let mut expected = vec![0f64; nt * np];
        let sub = 24;
        for t in 0..nt {
            for p in 0..np {
                let mut sum = 0.0f64;
                for a in 0..sub {
                    for b in 0..sub {
                        let cos = 1.0 - (t as f32 + (a as f32 + 0.5) / sub as f32) / nt as f32;
                        let phi = 2.0 * PI * (p as f32 + (b as f32 + 0.5) / sub as f32) / np as f32;
                        let sin = (1.0 - cos * cos).max(0.0).sqrt();
                        let w = Vec3::new(sin * phi.cos(), sin * phi.sin(), cos);
                        sum += f64::from(bsdf.pdf(wo, w));
                    }
                }
                let area = (1.0 / nt as f64) * (2.0 * std::f64::consts::PI / np as f64);
                expected[t * np + p] = sum / (sub * sub) as f64 * area * n as f64;
            }
        }
        let (mut chi2, mut dof, mut pool_o, mut pool_e) = (0.0f64, 0usize, 0.0f64, 0.0f64);
        for (o, x) in observed.iter().zip(&expected) {
            if *x < 5.0 {
                pool_o += o;
                pool_e += x;
            } else {
                chi2 += (o - x) * (o - x) / x;
                dof += 1;
            }
        }
        if pool_e >= 5.0 {
            chi2 += (pool_o - pool_e) * (pool_o - pool_e) / pool_e;
            dof += 1;
        }
        let limit = chi2_quantile_999((dof - 1) as f64);
        assert!(chi2 < limit, "({d}, {s}, {e}): χ² = {chi2:.1} over {dof} bins, limit {limit:.1}");
    }
}

#[test]
fn glass_follows_fresnel_and_snell_and_a_slab_transmits_one_minus_f_over_one_plus_f() {
    let r0 = ((1.5f32 - 1.0) / (1.5 + 1.0)).powi(2);
    assert!((fresnel_dielectric(1.0, 1.0 / 1.5) - r0).abs() < 1e-6);
    // Brewster's angle: the p-polarised reflectance vanishes, F = r_s² / 2.
    let brewster = 1.5f32.atan();
    let (ci, ct) = (brewster.cos(), (brewster.sin() / 1.5).asin().cos());
    let rs = (ci - 1.5 * ct) / (ci + 1.5 * ct);
    assert!((fresnel_dielectric(ci, 1.0 / 1.5) - 0.5 * rs * rs).abs() < 1e-5);
    // Beyond the critical angle inside glass: total internal reflection.
    assert_eq!(fresnel_dielectric((1.0f32 - 0.8 * 0.8).sqrt(), 1.5), 1.0);
    // Snell and reversibility.
    let d = Vec3::new(0.6, 0.0, -0.8);
    let t = refract(d, Vec3::Z, 1.0 / 1.5).expect("no total reflection entering glass");
    assert!((d.x - 1.5 * t.x).abs() < 1e-6);
    let back = refract(-t, -Vec3::Z, 1.5).expect("the reverse path exists");
    assert!((back + d).length() < 1e-5, "{back}");
    // A slab at normal incidence: transmission through both faces with all internal
    // reflections, Σ (1 − F)² F^(2k) = (1 − F)/(1 + F), from the interfaces' own Fresnel terms.
    let enter = Interface::new(-Vec3::Z, Vec3::Z, 1.5).reflectance;
    let leave = Interface::new(-Vec3::Z, -Vec3::Z, 1.5).reflectance;
    let (mut transmitted, mut inside) = (0.0f64, f64::from(1.0 - enter));
    for _ in 0..100 {
        transmitted += inside * f64::from(1.0 - leave);
        inside *= f64::from(leave * leave);
    }
    let f = f64::from(r0);
    assert!((transmitted - (1.0 - f) / (1.0 + f)).abs() < 1e-6, "{transmitted}");
    // The glass lobe of a `Bsdf` splits by the same F: the mean weight of reflections plus
    // refractions is the glass weight, and reflections come with probability F.
    let glass = Bsdf::new(BrdfParams { glass: 1.0, ior: 1.5, ..BrdfParams::black(Vec3::Z) }, Vec3::Z);
    let (mut reflected, mut total, k) = (0, 0.0f32, 10_000);
    for i in 0..k {
        let smp =
            glass.sample(Vec3::Z, (i as f32 + 0.5) / k as f32, Vec2::splat(0.5)).expect("glass samples");
        total += smp.weight.x;
        reflected += usize::from(smp.lobe == Lobe::GlassReflection);
    }
    assert!((total / k as f32 - 1.0).abs() < 1e-5);
    assert!((reflected as f32 / k as f32 - r0).abs() < 1e-3, "{reflected}");
}

#[test]
fn conserving_clamps_and_scales_any_input() {
    let p = BrdfParams {
        diffuse: Vec3::new(0.9, f32::NAN, 2.0),
        specular: Vec3::splat(0.5),
        mirror: Vec3::new(0.3, 0.0, -1.0),
        glass: 0.4,
        exponent: f32::INFINITY,
        ior: -1.0,
        ..BrdfParams::black(Vec3::Z)
    }
    .conserving();
    let sum = p.diffuse + p.specular + p.mirror + Vec3::splat(p.glass);
    assert!(sum.max_element() <= 1.0 + 1e-6, "{sum}");
    assert!(p.diffuse.is_finite() && p.exponent.is_finite() && p.ior > 0.0);
    assert!(p.diffuse.cmpge(Vec3::ZERO).all() && p.mirror.cmpge(Vec3::ZERO).all());
}
