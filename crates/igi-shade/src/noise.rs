//! Ken Perlin's improved gradient noise (Perlin 2002, "Improving Noise", SIGGRAPH), its
//! analytic gradient, and the fractal sums built from it (fBm and turbulence), in a scalar and
//! an eight-lane form. Procedural surface shaders (paper 3.2) evaluate these per hit.
//!
//! Improved noise, as in the paper: the lattice point (i, j, k) gets one of 12 gradients
//! (the edge midpoints of a cube, (±1, ±1, 0) and permutations) picked by hashing i, j, k
//! through Perlin's reference permutation table; each of the 8 corners of the cell around p
//! contributes `g · (p − corner)`, and the 8 values are blended trilinearly with the quintic
//! fade 6t⁵ − 15t⁴ + 10t³, whose first and second derivatives vanish at the lattice, so the
//! noise is C² and its gradient is continuous (bump mapping shows no lattice creases).
//!
//! **Gradient.** The derivative is analytic and shares the corner hashes and dot products
//! with the value: with fade weights u, v, w of the fractional position and corner values
//! d_c = g_c · (f − c),
//!
//! ```text
//! n      = trilerp(u, v, w; d_c)
//! ∂n/∂x  = trilerp(u, v, w; g_c.x) + u′ · lerp(w, lerp(v, d100 − d000, d110 − d010),
//!                                                  lerp(v, d101 − d001, d111 − d011))
//! ```
//!
//! and likewise for y and z, so the gradient costs about as much again as the value instead of
//! the three extra evaluations of finite differences.
//!
//! **Range.** Noise is 0 at every lattice point (every corner term vanishes there).
//! `|noise3(p)| ≤ 1.0364` for *any* assignment of the 12 gradients to the corners: the bound
//! is the maximum over the cell of Σ_c w_c(f) · max_g g · (f − c), found numerically (it is
//! attained near f = (0.355, 0.481, 0.5)). With Perlin's table the measured extreme over
//! 10⁶ random points and a local ascent from the largest of them stays inside [−1, 1]
//! (see the tests), so in practice the noise lies in [−1, 1]; patterns clamp what they derive
//! from it. fBm and turbulence of `o` octaves (gain ½) are bounded by the noise bound times
//! 2 − 2^(1−o) < 2.
//!
//! **Lipschitz bound.** In a cell, ∂n/∂x = Σ_c w_c g_c.x + u′ · D with weights w_c ≥ 0 summing
//! to 1 and |g_c.x| ≤ 1; D is a blend of differences d_c − d_c′ of corner values, and each
//! |d_c| = |g_c · (f − c)| ≤ 2 (two unit entries times offsets in [−1, 1]), so |D| ≤ 4; the fade
//! slope is u′ ≤ 30/16 = 1.875. Hence |∂n/∂x| ≤ 1 + 1.875 · 4 = 8.5 per axis,
//! |∇n| ≤ 8.5 √3 < 14.73, and |n(p) − n(q)| ≤ 14.73 |p − q| (the gradient is continuous across
//! cells, so the bound holds globally).
//!
//! **Lanes.** Every function is generic over [`Lanes`]: a point is `[f32; 3]` or, for eight
//! points, `[F32x8; 3]` (`Vec3x8::into`). Both run the same adds, multiplies and fused
//! multiply-adds in the same order, and the same table lookups, so they are bit-identical, lane
//! for lane.
//!
//! [`F32x8`]: igi_simd::F32x8

use igi_simd::Lanes;

/// Perlin's reference permutation of 0..256 (Perlin 2002). The reference code doubles it to
/// 512 entries so that `p[p[x] + y]` never leaves the table; masking every index with 255 is
/// the same thing.
const PERM: [i32; 256] = [
    151, 160, 137, 91, 90, 15, 131, 13, 201, 95, 96, 53, 194, 233, 7, 225, 140, 36, 103, 30, 69, 142, 8, 99,
    37, 240, 21, 10, 23, 190, 6, 148, 247, 120, 234, 75, 0, 26, 197, 62, 94, 252, 219, 203, 117, 35, 11, 32,
    57, 177, 33, 88, 237, 149, 56, 87, 174, 20, 125, 136, 171, 168, 68, 175, 74, 165, 71, 134, 139, 48, 27,
    166, 77, 146, 158, 231, 83, 111, 229, 122, 60, 211, 133, 230, 220, 105, 92, 41, 55, 46, 245, 40, 244,
    102, 143, 54, 65, 25, 63, 161, 1, 216, 80, 73, 209, 76, 132, 187, 208, 89, 18, 169, 200, 196, 135, 130,
    116, 188, 159, 86, 164, 100, 109, 198, 173, 186, 3, 64, 52, 217, 226, 250, 124, 123, 5, 202, 38, 147,
    118, 126, 255, 82, 85, 212, 207, 206, 59, 227, 47, 16, 58, 17, 182, 189, 28, 42, 223, 183, 170, 213, 119,
    248, 152, 2, 44, 154, 163, 70, 221, 153, 101, 155, 167, 43, 172, 9, 129, 22, 39, 253, 19, 98, 108, 110,
    79, 113, 224, 232, 178, 185, 112, 104, 218, 246, 97, 228, 251, 34, 242, 193, 238, 210, 144, 12, 191, 179,
    162, 241, 81, 51, 145, 235, 249, 14, 239, 107, 49, 192, 214, 31, 181, 199, 106, 157, 184, 84, 204, 176,
    115, 121, 50, 45, 127, 4, 150, 254, 138, 236, 205, 93, 222, 114, 67, 29, 24, 72, 243, 141, 128, 195, 78,
    66, 215, 61, 156, 180,
];

// The gradient of hash h (its low 4 bits), as Perlin's `grad` picks it: u = h < 8 ? x : y,
// v = h < 4 ? y : (h == 12 || h == 14 ? x : z), signs from bits 0 and 1. The 16 entries are
// the 12 cube-edge directions with (1,1,0), (−1,1,0), (0,−1,1), (0,−1,−1) repeated, which
// makes the choice a cheap mask instead of a modulo 12 (Perlin 2002, section 3).
const GRAD_X: [f32; 16] = [1., -1., 1., -1., 1., -1., 1., -1., 0., 0., 0., 0., 1., 0., -1., 0.];
const GRAD_Y: [f32; 16] = [1., 1., -1., -1., 0., 0., 0., 0., 1., -1., 1., -1., 1., -1., 1., -1.];
const GRAD_Z: [f32; 16] = [0., 0., 0., 0., 1., 1., -1., -1., 1., 1., -1., -1., 0., 1., 0., -1.];

/// `a + t (b − a)`.
#[inline(always)]
fn lerp<T: Lanes>(t: T, a: T, b: T) -> T {
    t.mul_add(b - a, a)
}

/// Trilinear blend of eight corner values, indexed `[x + 2y + 4z]`.
#[inline(always)]
fn trilerp<T: Lanes>(u: T, v: T, w: T, c: [T; 8]) -> T {
    let y0 = lerp(v, lerp(u, c[0], c[1]), lerp(u, c[2], c[3]));
    let y1 = lerp(v, lerp(u, c[4], c[5]), lerp(u, c[6], c[7]));
    lerp(w, y0, y1)
}

/// Perlin's fade 6t⁵ − 15t⁴ + 10t³ and its derivative 30 t² (t − 1)².
#[inline(always)]
fn fade<T: Lanes>(t: T) -> (T, T) {
    let poly = t.mul_add(T::splat(6.0), T::splat(-15.0)).mul_add(t, T::splat(10.0));
    let t2 = t * t;
    let s = t2 - t;
    (poly * t2 * t, T::splat(30.0) * s * s)
}

/// Improved noise at (x, y, z) and, when `GRAD`, its gradient (else zeros, and the compiler
/// drops that work).
#[inline(always)]
fn noise_core<T: Lanes, const GRAD: bool>(p: [T; 3]) -> (T, [T; 3]) {
    let cell = p.map(T::floor);
    let [x0, y0, z0] = [p[0] - cell[0], p[1] - cell[1], p[2] - cell[2]];
    let one = T::splat(1.0);
    let [x1, y1, z1] = [x0 - one, y0 - one, z0 - one];
    let [i, j, k] = cell.map(T::to_i32);
    // Perlin's hash chain: A = p[X] + Y, AA = p[A] + Z, ... (each lookup wraps at 256).
    let perm = |i: T::Int| T::gather(&PERM, i);
    let one_i = T::splat_i32(1);
    let a = perm(i) + j;
    let b = perm(i + one_i) + j;
    let rows = [perm(a) + k, perm(b) + k, perm(a + one_i) + k, perm(b + one_i) + k];
    // Corner c = x + 2y + 4z: rows are (y, x) pairs at z = 0; +1 on the row hash steps to z = 1.
    let hashes = [
        perm(rows[0]),
        perm(rows[1]),
        perm(rows[2]),
        perm(rows[3]),
        perm(rows[0] + one_i),
        perm(rows[1] + one_i),
        perm(rows[2] + one_i),
        perm(rows[3] + one_i),
    ];
    // The gradient of each corner's hash.
    let grads = hashes.map(|h| [T::lookup16(&GRAD_X, h), T::lookup16(&GRAD_Y, h), T::lookup16(&GRAD_Z, h)]);
    let offsets = |c: usize| {
        [if c & 1 == 0 { x0 } else { x1 }, if c & 2 == 0 { y0 } else { y1 }, if c & 4 == 0 { z0 } else { z1 }]
    };
    // g · (f − c): the products are exact (g is −1, 0 or 1), so the order of the sum only
    // matters for the sign of zero.
    let d: [T; 8] = std::array::from_fn(|c| {
        let [ox, oy, oz] = offsets(c);
        let g = grads[c];
        g[2].mul_add(oz, g[1].mul_add(oy, g[0] * ox))
    });
    let ((u, du), (v, dv), (w, dw)) = (fade(x0), fade(y0), fade(z0));
    let value = trilerp(u, v, w, d);
    if !GRAD {
        return (value, [T::splat(0.0); 3]);
    }
    let blended = |axis: usize| trilerp(u, v, w, grads.map(|g| g[axis]));
    let l = |a: usize, b: usize| lerp(u, d[a], d[b]);
    let ddu = lerp(w, lerp(v, d[1] - d[0], d[3] - d[2]), lerp(v, d[5] - d[4], d[7] - d[6]));
    let ddv = lerp(w, l(2, 3) - l(0, 1), l(6, 7) - l(4, 5));
    let ddw = lerp(v, l(4, 5), l(6, 7)) - lerp(v, l(0, 1), l(2, 3));
    (value, [du.mul_add(ddu, blended(0)), dv.mul_add(ddv, blended(1)), dw.mul_add(ddw, blended(2))])
}

/// Sum over `octaves` of gain^i · f(2^i p) (`TURB`: of |f|), with the gradient when `GRAD`.
/// Scaling by 2^i is exact, and the chain rule factor 2^i cancels the gain ½^i in the
/// gradient, so the gradient is the plain sum of the octave gradients (sign-flipped with the
/// noise for turbulence).
#[inline(always)]
fn fractal<T: Lanes, const GRAD: bool, const TURB: bool>(p: [T; 3], octaves: u32) -> (T, [T; 3]) {
    let zero = T::splat(0.0);
    let (mut sum, mut grad) = (zero, [zero; 3]);
    let mut freq = 1.0f32;
    for _ in 0..octaves {
        let f = T::splat(freq);
        let (n, g) = noise_core::<T, GRAD>(p.map(|c| c * f));
        // |n| as n with its own sign flipped away.
        let (n, g) = if TURB { (n.xor_sign(n), g.map(|c| c.xor_sign(n))) } else { (n, g) };
        sum = n.mul_add(T::splat(1.0 / freq), sum);
        if GRAD {
            grad = [grad[0] + g[0], grad[1] + g[1], grad[2] + g[2]];
        }
        freq *= 2.0;
    }
    (sum, grad)
}

/// Improved noise at `p` (Perlin 2002), for one point (`f32`) or eight (`F32x8`): 0 at integer
/// points, in [−1, 1] in practice (module documentation).
pub fn noise3<L: Lanes>(p: [L; 3]) -> L {
    noise_core::<L, false>(p).0
}

/// Improved noise at `p` and its analytic gradient; the value equals [`noise3`]'s.
pub fn noise3_grad<L: Lanes>(p: [L; 3]) -> (L, [L; 3]) {
    noise_core::<L, true>(p)
}

/// Fractional Brownian motion: Σ_{i < octaves} ½^i · noise(2^i p), in ±1.0364 · (2 − 2^(1−octaves)).
pub fn fbm3<L: Lanes>(p: [L; 3], octaves: u32) -> L {
    fractal::<L, false, false>(p, octaves).0
}

/// [`fbm3`] and its gradient.
pub fn fbm3_grad<L: Lanes>(p: [L; 3], octaves: u32) -> (L, [L; 3]) {
    fractal::<L, true, false>(p, octaves)
}

/// Perlin's turbulence: Σ_{i < octaves} ½^i · |noise(2^i p)|, in [0, 1.0364 · (2 − 2^(1−octaves))].
/// Continuous, with creases where an octave crosses zero (that is the look).
pub fn turbulence3<L: Lanes>(p: [L; 3], octaves: u32) -> L {
    fractal::<L, false, true>(p, octaves).0
}

/// [`turbulence3`] and its gradient (one-sided at the creases: the sign of the octave's noise,
/// +0 counting as positive).
pub fn turbulence3_grad<L: Lanes>(p: [L; 3], octaves: u32) -> (L, [L; 3]) {
    fractal::<L, true, true>(p, octaves)
}
