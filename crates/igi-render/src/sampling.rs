//! Deterministic sample generation: integer hashes that turn (pixel, seed) into a sequence
//! seed, Owen-scrambled Sobol points (`sobol_burley`) for stratified light samples, uniform
//! triangle sampling, a discrete distribution (CDF) for choosing among lights, and the
//! warps from the unit square to spheres, cones and discs that start light paths.
//!
//! Nothing here keeps state between calls, so a pixel's samples depend only on the pixel, the
//! sample index and the seed: the image is the same whichever thread or node renders the pixel
//! (paper 3.4: tiles go to any node).

use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// A 32-bit integer hash with good avalanche ("lowbias32" from Chris Wellons' hash
/// prospector). Used to decorrelate seeds; not a cryptographic hash.
#[inline]
pub fn hash32(mut x: u32) -> u32 {
    x ^= x >> 16;
    x = x.wrapping_mul(0x7feb_352d);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846c_a68b);
    x ^= x >> 16;
    x
}

/// Hashes `value` into the running hash `seed` (order matters).
#[inline]
pub fn hash_combine(seed: u32, value: u32) -> u32 {
    hash32(seed ^ hash32(value.wrapping_add(0x9e37_79b9)))
}

/// The sequence seed of pixel `(x, y)` under the frame seed `seed`.
#[inline]
pub fn pixel_seed(x: u32, y: u32, seed: u32) -> u32 {
    hash_combine(hash_combine(hash32(seed), x), y)
}

/// Dimensions 4·`set` .. 4·`set`+3 of sample `index` of the Owen-scrambled Sobol sequence
/// with scramble seed `seed`, each in [0, 1). The first 2^k samples of a seed are stratified in
/// every 2D projection of a set. `index` must stay below [`MAX_SAMPLES`].
///
/// This is `sobol_burley::sample_4d` without its seed-dependent shuffle of the sample index:
/// with one short sequence per pixel, the per-seed Owen scramble alone decorrelates the
/// pixels, and an unshuffled small index needs only a few steps of the Sobol recurrence
/// (several times faster than `sample_4d` here).
#[inline]
pub fn sobol4(index: u32, set: u32, seed: u32) -> [f32; 4] {
    use sobol_burley::parts::{Int4, hash_int4, owen_scramble_int4_rev, sobol_int4_rev};
    debug_assert!(index < MAX_SAMPLES);
    let sobol = sobol_int4_rev(index.reverse_bits(), set);
    let scramble: Int4 = scramble_seeds(seed, set).into();
    owen_scramble_int4_rev(sobol, hash_int4(scramble)).reverse_bits().to_f32_norm()
}

/// The scramble seeds of the four dimensions of `set` under `seed`, before their hash: the same
/// per-dimension seeds as `sobol_burley::sample_4d`.
#[inline]
fn scramble_seeds(seed: u32, set: u32) -> [u32; 4] {
    let s = seed.wrapping_mul(0x9c8f_2d3b) ^ set;
    [s ^ 0x912f_69ba, s ^ 0x174f_18ab, s ^ 0x691e_72ca, s ^ 0xb40c_c1b8]
}

/// Dimensions 0 and 1 of [`sobol4`]'s set 0 under one seed, for many sample indices: the
/// seed's two Owen scrambles are hashed once, and the unscrambled Sobol point of an index,
/// the same for every seed, comes from [`Sobol2::unscrambled`] once for many seeds. A pixel's
/// anti-aliasing samples come so, eight pixels of a packet sharing each index; the bits are
/// [`sobol4`]'s.
#[derive(Clone, Copy, Debug)]
pub struct Sobol2 {
    scramble: [u32; 2],
}

impl Sobol2 {
    /// The scrambles of `seed` (the lanes 0 and 1 of [`sobol4`]'s).
    #[inline]
    pub fn new(seed: u32) -> Self {
        let [u, v, ..] = scramble_seeds(seed, 0);
        Self { scramble: [u, v].map(sobol_burley::parts::hash) }
    }

    /// The unscrambled point `index` (bit-reversed), for [`Sobol2::point`].
    #[inline]
    pub fn unscrambled(index: u32) -> [u32; 2] {
        debug_assert!(index < MAX_SAMPLES);
        let reversed = index.reverse_bits();
        [sobol_burley::parts::sobol_rev(reversed, 0), sobol_burley::parts::sobol_rev(reversed, 1)]
    }

    /// The point whose unscrambled form is `unscrambled`, scrambled by this seed, in [0, 1)².
    #[inline]
    pub fn point(&self, unscrambled: [u32; 2]) -> [f32; 2] {
        use sobol_burley::parts::{owen_scramble_rev, u32_to_f32_norm};
        std::array::from_fn(|d| {
            u32_to_f32_norm(owen_scramble_rev(unscrambled[d], self.scramble[d]).reverse_bits())
        })
    }
}

/// The largest f32 below 1: where numbers meant to lie in [0, 1) are clamped.
pub const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;

/// The largest number of samples per sequence [`sobol4`] supports.
pub const MAX_SAMPLES: u32 = 1 << 16;

/// Uniformly distributed barycentric weights `(b1, b2)` of the second and third vertex from a
/// point of the unit square (the square-root parametrisation, Shirley 1992). The point is
/// `(1 - b1 - b2) p0 + b1 p1 + b2 p2`.
#[inline]
pub fn uniform_triangle(u: Vec2) -> Vec2 {
    let su = u.x.sqrt();
    Vec2::new(su * (1.0 - u.y), su * u.y)
}

/// A discrete distribution over `n` items with given non-negative weights, sampled by
/// inverting its cumulative distribution (binary search).
#[derive(Clone, Debug, Default)]
pub struct Cdf {
    /// Cumulative weights normalised to end at 1: `cdf[i]` = P(item ≤ i).
    cdf: Vec<f32>,
    /// Probability of each item.
    pmf: Vec<f32>,
    /// Sum of the weights.
    total: f64,
}

impl Cdf {
    /// The distribution proportional to `weights` (negative or NaN weights count as 0). If all
    /// weights are 0 the distribution is empty.
    pub fn new(weights: impl IntoIterator<Item = f32>) -> Self {
        let weights: Vec<f64> =
            weights.into_iter().map(|w| if w > 0.0 { f64::from(w) } else { 0.0 }).collect();
        let total: f64 = weights.iter().sum();
        if total <= 0.0 {
            return Self::default();
        }
        let mut running = 0.0;
        let mut cdf = Vec::with_capacity(weights.len());
        for w in &weights {
            running += w;
            cdf.push((running / total) as f32);
        }
        // Make the last entry exactly 1 so every u in [0, 1) finds an item.
        if let Some(last) = cdf.last_mut() {
            *last = 1.0;
        }
        let pmf = weights.iter().map(|w| (w / total) as f32).collect();
        Self { cdf, pmf, total }
    }

    /// Number of items (0 if the distribution is empty).
    pub fn len(&self) -> usize {
        self.cdf.len()
    }

    /// True if there is nothing to sample.
    pub fn is_empty(&self) -> bool {
        self.cdf.is_empty()
    }

    /// Sum of the weights given to [`Cdf::new`].
    pub fn total(&self) -> f64 {
        self.total
    }

    /// Probability of item `i`.
    pub fn pmf(&self, i: usize) -> f32 {
        self.pmf[i]
    }

    /// The item for `u` in [0, 1) and its probability. Items of zero weight are never chosen.
    /// Panics if the distribution is empty.
    pub fn sample(&self, u: f32) -> (usize, f32) {
        // First index whose cumulative value exceeds u; zero-weight items repeat the previous
        // value and are skipped by the strict comparison.
        let i = self.cdf.partition_point(|&c| c <= u).min(self.cdf.len() - 1);
        (i, self.pmf[i])
    }

    /// Like [`Cdf::sample`], and also where `u` lies within the chosen item's interval of the
    /// cumulative distribution, rescaled to [0, 1): a fresh uniform number for choosing a
    /// point inside the item, so that one number can pick both.
    pub fn sample_remapped(&self, u: f32) -> (usize, f32, f32) {
        let (i, pmf) = self.sample(u);
        let low = if i == 0 { 0.0 } else { self.cdf[i - 1] };
        let high = self.cdf[i];
        // The interval is empty only for u ≥ 1, where `sample` clamped the item.
        let within = if high > low { ((u - low) / (high - low)).clamp(0.0, ONE_MINUS_EPSILON) } else { 0.0 };
        (i, pmf, within)
    }
}

/// A unit vector uniformly distributed on the sphere (density 1 / 4π).
pub fn uniform_sphere(u: Vec2) -> Vec3 {
    let z = 1.0 - 2.0 * u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Direction `i` of `n` spread evenly over the unit sphere, +Y the pole (a Fibonacci lattice:
/// equal-area bands in y, successive points a golden angle apart): the fixed probe directions
/// of the default camera and light.
pub fn fibonacci_sphere(i: u32, n: u32) -> Vec3 {
    let golden = PI * (3.0 - 5f32.sqrt());
    let y = 1.0 - 2.0 * (i as f32 + 0.5) / n as f32;
    let r = (1.0 - y * y).max(0.0).sqrt();
    let phi = golden * i as f32;
    Vec3::new(r * phi.cos(), y, r * phi.sin())
}

/// A unit vector uniformly distributed in the cone of directions within angle acos(`cos_max`)
/// of the unit axis `axis` (density 1 / (2π (1 − cos_max))).
pub fn uniform_cone(axis: Vec3, cos_max: f32, u: Vec2) -> Vec3 {
    let z = 1.0 - u.x * (1.0 - cos_max);
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    let (t, b) = axis.any_orthonormal_pair();
    (t * (r * phi.cos()) + b * (r * phi.sin()) + axis * z).normalize()
}

/// A point uniformly distributed on the unit disc (concentric mapping, Shirley & Chiu 1997).
pub fn concentric_disc(u: Vec2) -> Vec2 {
    let o = 2.0 * u - Vec2::ONE;
    if o == Vec2::ZERO {
        return Vec2::ZERO;
    }
    let (r, theta) = if o.x.abs() > o.y.abs() {
        (o.x, PI / 4.0 * (o.y / o.x))
    } else {
        (o.y, PI / 2.0 - PI / 4.0 * (o.x / o.y))
    };
    r * Vec2::new(theta.cos(), theta.sin())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sphere_cone_and_disc_samples_stay_in_their_domains() {
        let axis = Vec3::new(0.0, -1.0, 1.0).normalize();
        for i in 0..32 {
            for j in 0..32 {
                let u = Vec2::new(i as f32 / 32.0, j as f32 / 32.0);
                assert!((uniform_sphere(u).length() - 1.0).abs() < 1e-5);
                assert!(uniform_cone(axis, 0.9, u).dot(axis) >= 0.9 - 1e-5);
                assert!(concentric_disc(u).length() <= 1.0 + 1e-6);
            }
        }
    }
}
