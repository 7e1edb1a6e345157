//! The watertight ray-triangle test of Woop, Benthin and Wald, "Watertight Ray/Triangle
//! Intersection" (JCGT 2(1), 2013), written once over [`Lanes`] so that the single-ray
//! kernel (`f32`) and the 8-ray packet kernel ([`F32x8`]) perform exactly the same floating-point
//! operations and agree bit for bit.
//!
//! The ray is sheared and permuted so that it becomes the +z axis through the origin; the
//! triangle's 2D edge functions U, V, W are then evaluated at the origin. A ray through a shared
//! edge or vertex gets the same edge-function value in both triangles, so it hits at least one
//! of them (no cracks) and, with the tie rule of the kernels, always the same one. Edge values
//! of exactly zero are recomputed in double precision, as the paper prescribes.

use glam::Vec3;
use igi_simd::{F32x8, LaneMask, Lanes, M32x8, Vec3x8};

/// The edge functions U, V, W of the sheared vertices (a, b, c) in double precision, each
/// rounded once to `f32`: the values where a single-precision one is exactly zero (module
/// documentation).
#[inline]
fn edges_f64([ax, ay, bx, by, cx, cy]: [f32; 6]) -> [f32; 3] {
    let edge = |ax: f32, ay: f32, bx: f32, by: f32| (bx as f64 * ay as f64 - by as f64 * ax as f64) as f32;
    [edge(bx, by, cx, cy), edge(cx, cy, ax, ay), edge(ax, ay, bx, by)]
}

/// The per-ray constants of the test: the permutation (kx, ky, kz) that makes z the dominant
/// direction axis (swapping kx and ky when that axis points backwards, to keep the winding) and
/// the shear (Sx, Sy, Sz) that maps the ray direction to +z (paper, section 3).
pub(crate) trait Shear<L: Lanes> {
    /// The permuted components (v[kx], v[ky], v[kz]) of a vector given per lane.
    fn permute(&self, v: [L; 3]) -> [L; 3];
    /// (Sx, Sy, Sz).
    fn shear(&self) -> [L; 3];
}

/// Picks (kx, ky, kz) for one ray direction.
#[inline]
fn permutation(d: Vec3) -> [usize; 3] {
    let a = d.abs();
    let kz = if a.x >= a.y && a.x >= a.z {
        0
    } else if a.y >= a.z {
        1
    } else {
        2
    };
    let (kx, ky) = ((kz + 1) % 3, (kz + 2) % 3);
    if d[kz] < 0.0 { [ky, kx, kz] } else { [kx, ky, kz] }
}

/// Shear constants for one direction and its permutation.
#[inline]
fn shear_of(d: Vec3, k: [usize; 3]) -> [f32; 3] {
    [d[k[0]] / d[k[2]], d[k[1]] / d[k[2]], 1.0 / d[k[2]]]
}

/// Test constants of rays that all share one permutation: a single ray (`L = f32`), or a packet
/// whose active lanes do (the common case for coherent rays, where the permutation costs
/// nothing).
#[derive(Clone, Copy, Debug)]
pub(crate) struct ShearUniform<L> {
    k: [usize; 3],
    s: [L; 3],
}

impl ShearUniform<f32> {
    /// The test constants of one ray along `dir`.
    pub(crate) fn new(dir: Vec3) -> Self {
        let k = permutation(dir);
        Self { k, s: shear_of(dir, k) }
    }
}

impl<L: Lanes> Shear<L> for ShearUniform<L> {
    #[inline(always)]
    fn permute(&self, v: [L; 3]) -> [L; 3] {
        [v[self.k[0]], v[self.k[1]], v[self.k[2]]]
    }
    #[inline(always)]
    fn shear(&self) -> [L; 3] {
        self.s
    }
}

/// Test constants of a packet whose lanes differ in permutation: each permuted component is
/// selected lane by lane.
#[derive(Clone, Copy, Debug)]
pub(crate) struct ShearMixed8 {
    /// Per output component c: lanes whose k[c] is 0, and lanes whose k[c] is 1 (else 2).
    is0: [M32x8; 3],
    is1: [M32x8; 3],
    s: [F32x8; 3],
}

/// Packet test constants, uniform or mixed.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Shear8 {
    Uniform(ShearUniform<F32x8>),
    Mixed(ShearMixed8),
}

impl Shear8 {
    /// The constants for the lanes of `dir`; lanes outside `active` are given the permutation of
    /// an active lane, so that they do not force the mixed path.
    pub(crate) fn new(dir: &Vec3x8, active: M32x8) -> Self {
        // `permutation` lane by lane in SIMD: the dominant axis kz (first of the largest), then
        // (kx, ky) swapped where the direction points backwards along kz.
        let (ax, ay, az) = (dir.x.abs(), dir.y.abs(), dir.z.abs());
        let kz0 = ax.ge(ay) & ax.ge(az);
        let kz1 = !kz0 & ay.ge(az);
        let kz2 = !(kz0 | kz1);
        let neg = F32x8::select(kz0, dir.x, F32x8::select(kz1, dir.y, dir.z)).lt(F32x8::ZERO);
        let d = [dir.x, dir.y, dir.z];
        // The shear is computed from the permuted direction with the same divisions as
        // `shear_of`, so each lane equals the single-ray constants bit for bit.
        let shear_from = |[dx, dy, dz]: [F32x8; 3]| [dx / dz, dy / dz, F32x8::splat(1.0) / dz];
        let a = active.bitmask();
        let all_or_none = |m: M32x8| {
            let b = m.bitmask() & a;
            b == 0 || b == a
        };
        let uniform_kz = [kz0, kz1, kz2].iter().position(|m| m.bitmask() & a == a);
        if let (Some(kz), true) = (uniform_kz, all_or_none(neg)) {
            let backwards = a != 0 && neg.bitmask() & a == a;
            let (kx, ky) = ((kz + 1) % 3, (kz + 2) % 3);
            let k = if backwards { [ky, kx, kz] } else { [kx, ky, kz] };
            let s = ShearUniform { k, s: [F32x8::ZERO; 3] };
            return Shear8::Uniform(ShearUniform { s: shear_from(s.permute(d)), ..s });
        }
        let pos = !neg;
        let mut s = ShearMixed8 {
            is0: [(kz1 & neg) | (kz2 & pos), (kz1 & pos) | (kz2 & neg), kz0],
            is1: [(kz0 & pos) | (kz2 & neg), (kz0 & neg) | (kz2 & pos), kz1],
            s: [F32x8::ZERO; 3],
        };
        s.s = shear_from(s.permute(d));
        Shear8::Mixed(s)
    }
}

impl Shear<F32x8> for ShearMixed8 {
    #[inline(always)]
    fn permute(&self, v: [F32x8; 3]) -> [F32x8; 3] {
        std::array::from_fn(|c| F32x8::select(self.is0[c], v[0], F32x8::select(self.is1[c], v[1], v[2])))
    }
    #[inline(always)]
    fn shear(&self) -> [F32x8; 3] {
        self.s
    }
}

/// Result of one triangle test: lanes that hit within `[tnear, tfar]`, their distances and the
/// barycentric weights (u, v) of the second and third vertex.
pub(crate) struct TriangleHit<L: Lanes> {
    pub mask: L::Mask,
    pub t: L,
    pub u: L,
    pub v: L,
}

/// Intersects the ray(s) `org + t·dir` (dir described by `shear`) with triangle (p0, p1, p2).
/// Both sides of the triangle are hit (no culling).
#[inline(always)]
pub(crate) fn intersect<L: Lanes, S: Shear<L>>(
    org: [L; 3],
    shear: &S,
    p0: Vec3,
    p1: Vec3,
    p2: Vec3,
    tnear: L,
    tfar: L,
) -> TriangleHit<L> {
    let rel =
        |p: Vec3| shear.permute([L::splat(p.x) - org[0], L::splat(p.y) - org[1], L::splat(p.z) - org[2]]);
    let [sx, sy, sz] = shear.shear();
    // Vertices relative to the origin, permuted, then sheared into ray space (paper, Fig. 4).
    let [a0, a1, a2] = rel(p0);
    let [b0, b1, b2] = rel(p1);
    let [c0, c1, c2] = rel(p2);
    // The shear uses fused multiply-adds: it depends only on the vertex and the ray, so a
    // vertex shared by two triangles is still sheared identically in both.
    let (nsx, nsy) = (L::splat(0.0) - sx, L::splat(0.0) - sy);
    let (ax, ay) = (nsx.mul_add(a2, a0), nsy.mul_add(a2, a1));
    let (bx, by) = (nsx.mul_add(b2, b0), nsy.mul_add(b2, b1));
    let (cx, cy) = (nsx.mul_add(c2, c0), nsy.mul_add(c2, c1));
    // Scaled barycentric coordinates: 2D edge functions at the origin. These stay unfused: a
    // shared edge must give exactly opposite values in its two triangles.
    let mut u = cx * by - cy * bx;
    let mut v = ax * cy - ay * cx;
    let mut w = bx * ay - by * ax;
    let zero = L::splat(0.0);
    let on_edge = u.eq(zero) | v.eq(zero) | w.eq(zero);
    if on_edge.any() {
        [u, v, w] = L::recompute(on_edge, [u, v, w], [ax, ay, bx, by, cx, cy], edges_f64);
    }
    let has_neg = u.lt(zero) | v.lt(zero) | w.lt(zero);
    let has_pos = u.gt(zero) | v.gt(zero) | w.gt(zero);
    let det = u + v + w;
    let (az, bz, cz) = (sz * a2, sz * b2, sz * c2);
    let t_scaled = w.mul_add(cz, v.mul_add(bz, u * az));
    let rcp = L::splat(1.0) / det;
    let t = t_scaled * rcp;
    let mask = !(has_neg & has_pos) & !det.eq(zero) & t.ge(tnear) & t.le(tfar);
    TriangleHit { mask, t, u: v * rcp, v: w * rcp }
}

/// The watertight test for one ray and one triangle, outside any BVH: the hit distance in
/// `[ray.tnear, ray.tfar]` and the barycentric weights (u, v) of the second and third vertex.
/// Exactly the arithmetic of the BVH kernels, so a brute-force loop over the triangles (the
/// traversal tests' reference) must agree with them bit for bit.
pub fn intersect_triangle(ray: &crate::Ray, tri: [Vec3; 3]) -> Option<(f32, f32, f32)> {
    let h = intersect(
        ray.origin.to_array(),
        &ShearUniform::new(ray.dir),
        tri[0],
        tri[1],
        tri[2],
        ray.tnear,
        ray.tfar,
    );
    h.mask.then_some((h.t, h.u, h.v))
}
