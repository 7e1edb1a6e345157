//! The inner loop of instant radiosity: for each VPL of a set, the shadow rays of all shading
//! points of the set (those the shadow-ray roulette keeps, [`ShadowRoulette`]) gathered into
//! 8-ray packets (any hit), and the accumulation of the contributions (paper 3.1.2), eight
//! points at a time.
//!
//! What is accumulated per point is the irradiance divided by π, D = E/π (the *diffuse
//! radiance*: what a white Lambertian surface reflects), so that a Lambertian lobe of
//! reflectance ρ_d reflects L = ρ_d·D, and for points with a glossy lobe also
//! G = Σ E · (n+2)/(2π) cosⁿα (the *glossy radiance*: what the modified Phong lobe of
//! [`igi_shade::brdf::phong`] reflects at unit reflectance, summed over the directions of the
//! lights), so that the glossy lobe reflects L = ρ_s·G. A point with the glTF GGX lobe
//! ([`igi_shade::brdf::ggx`], f = ρ_d(1 − s)/π + (F₀(1 − s) + s)·D·V) accumulates instead
//! D = Σ E(1 − s)/π, G = Σ E (1 − s)·D·V and the *Schlick radiance* S = Σ E s·D·V, so that it
//! reflects L = ρ_d·D + F₀·G + S: every factor that depends on the light's direction is in
//! the sums, every factor that a texture sets is outside them. The BRDF shaders
//! are thus evaluated eight points at a time for every VPL. The discontinuity filter smooths
//! D and G before the reflectances multiply them back in (paper 2.1), which keeps texture
//! detail sharp. Per light:
//!
//! ```text
//! surface VPL at y, normal n_y, diffuse power Φ, glossy power Φ_s (see `Vpl`):
//!     E = w · (Φ/π + Φ_s · lobe_y(x − y)) · cosθ_x · cosθ_y / max(|x − y|², d_min²) · V(x, y)
//!     (a GGX VPL: Φ(1 − s)/π + (Φ_s(1 − s) + Φ_S s)·D·V in the parentheses, Φ_S its
//!     Schlick power)
//! point light (intensity I; a spot light only inside its cone):
//!     E = I · cosθ_x / |x − p|² · V(x, p)
//! directional light (irradiance E_l toward −direction):
//!     E = E_l · cosθ_x · V(x, ∞)
//! ```
//!
//! A GGX lobe lit by VPLs (surface and sky VPLs, not the exact lights) is widened to at
//! least [`MIN_VPL_ALPHA`], at the receiver and at the VPL: a lobe narrower than the angle
//! between neighbouring VPLs turns each VPL into its own highlight, a sparkle per pixel on
//! smooth metal and glass-like paint (path-space regularisation, Kaplanyan & Dachsbacher
//! 2013: a biased but bounded and noise-free estimate). The exact lights keep the true width,
//! so their highlights stay sharp, and the Phong lobe is left as it is.
//!
//! with w the weight of the VPL in this sample (N for a VPL shared among N anti-aliasing
//! samples, paper 3.3) and d_min the clamp that bounds the 1/d² singularity (the bias the
//! paper mentions). Point and directional lights are exact direct light, not samples of it,
//! so they are neither clamped nor weighted.

use crate::frame::FrameSettings;
use crate::igi::packet::Packet8;
use crate::igi::vpl::Vpl;
use crate::image::stats::RayCounts;
use crate::prepared::lights::{SHADOW_SHORTEN, SpotCone};
use crate::sampling::hash_combine;
use glam::Vec3;
use igi_bvh::{Accel, Ray, RayPacket8, ShadowCache, offset_ray_origin};
use igi_scene::Light;
use igi_shade::brdf::ggx::ggx_terms;
use igi_shade::brdf::phong::{mirror_direction, phong_lobe8};
use igi_shade::{BrdfParams, GlossyModel};
use igi_simd::{F32x8, M32x8, Vec3x8};

/// A glossy lobe with one of its two directions fixed, as the VPL loop evaluates it toward the
/// other: at a shading point the fixed direction is the viewer's, at a VPL the light's (the
/// lobes are reciprocal, so either direction may be the fixed one).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum GlossyLobe {
    /// A modified Phong lobe: the unit mirror direction of the fixed direction, the exponent.
    Phong {
        /// Unit lobe axis.
        axis: Vec3,
        /// Phong exponent.
        exponent: f32,
    },
    /// A GGX lobe (glTF): the fixed unit direction, in the hemisphere of the normal, and α.
    Ggx {
        /// The fixed unit direction.
        fixed: Vec3,
        /// GGX width α.
        alpha: f32,
    },
}

/// The smallest GGX width α with which VPLs light a point or a VPL lights (see the module
/// documentation): glTF roughness 0.45.
pub const MIN_VPL_ALPHA: f32 = 0.2;

impl GlossyLobe {
    /// The lobe as VPLs see it: a GGX lobe widened to at least [`MIN_VPL_ALPHA`].
    pub fn regularised(self) -> Self {
        match self {
            Self::Ggx { fixed, alpha } => Self::Ggx { fixed, alpha: alpha.max(MIN_VPL_ALPHA) },
            phong => phong,
        }
    }

    /// The glossy lobe of `params` at a point of unit shading normal `n` (on the lit side)
    /// with the unit direction `fixed` fixed, or `None` if the point has no glossy lobe. A
    /// GGX direction at or below the shading horizon (a bent normal) is lifted just above it,
    /// where the lobe is finite.
    pub fn new(params: &BrdfParams, n: Vec3, fixed: Vec3) -> Option<Self> {
        if !params.has_glossy() {
            return None;
        }
        Some(match params.model {
            GlossyModel::Phong => Self::Phong { axis: mirror_direction(fixed, n), exponent: params.exponent },
            GlossyModel::Ggx => {
                const MIN_COS: f32 = 1e-4;
                let cos = fixed.dot(n);
                let fixed = if cos >= MIN_COS { fixed } else { (fixed + n * (MIN_COS - cos)).normalize() };
                Self::Ggx { fixed, alpha: params.alpha }
            }
        })
    }
}
use std::f32::consts::{FRAC_1_PI, PI};

/// Eight shading points in structure-of-arrays form.
#[derive(Clone, Copy, Debug)]
struct Chunk {
    /// Shadow-ray origins (the points, moved off their surfaces on the lit side).
    origin: [[f32; 8]; 3],
    /// Unit shading normals on the lit side.
    ns: [[f32; 8]; 3],
    /// Unit geometric normals on the lit side.
    ng: [[f32; 8]; 3],
    /// Axes of the Phong lobes (unit; the mirror direction of the direction to the viewer).
    lobe_axis: [[f32; 8]; 3],
    /// Phong exponents of the glossy lobes.
    exponent: [f32; 8],
    /// Cosines to the lobe axes below which the lobes are negligible ([`lobe_cutoff`]).
    lobe_cos_min: [f32; 8],
    /// Unit directions to the viewer of the GGX lobes.
    view: [[f32; 8]; 3],
    /// GGX widths α.
    alpha: [f32; 8],
    /// The points' roulette seeds ([`Receivers::push`]).
    seed: [u32; 8],
    /// Occupied lanes.
    bits: u32,
    /// Occupied lanes with a glossy lobe (Phong or GGX).
    glossy_bits: u32,
    /// Occupied lanes with a GGX lobe.
    ggx_bits: u32,
}

impl Chunk {
    const EMPTY: Chunk = Chunk {
        origin: [[0.0; 8]; 3],
        ns: [[0.0; 8]; 3],
        ng: [[0.0; 8]; 3],
        lobe_axis: [[0.0; 8]; 3],
        exponent: [1.0; 8],
        lobe_cos_min: [1.0; 8],
        view: [[0.0; 8]; 3],
        alpha: [1.0; 8],
        seed: [0; 8],
        bits: 0,
        glossy_bits: 0,
        ggx_bits: 0,
    };

    #[inline]
    fn set(
        &mut self,
        lane: usize,
        (origin, seed): (Vec3, u32),
        ns: Vec3,
        ng: Vec3,
        glossy: Option<GlossyLobe>,
    ) {
        self.seed[lane] = seed;
        let ((lobe_axis, exponent), (view, alpha)) = match glossy {
            Some(GlossyLobe::Phong { axis, exponent }) => ((axis, exponent), (ns, 1.0)),
            Some(GlossyLobe::Ggx { fixed, alpha }) => ((ns, 1.0), (fixed, alpha)),
            None => ((ns, 1.0), (ns, 1.0)),
        };
        for axis in 0..3 {
            self.origin[axis][lane] = origin[axis];
            self.ns[axis][lane] = ns[axis];
            self.ng[axis][lane] = ng[axis];
            self.lobe_axis[axis][lane] = lobe_axis[axis];
            self.view[axis][lane] = view[axis];
        }
        self.exponent[lane] = exponent;
        self.lobe_cos_min[lane] = lobe_cutoff(exponent);
        self.alpha[lane] = alpha;
        self.bits |= 1 << lane;
        self.glossy_bits &= !(1 << lane);
        self.ggx_bits &= !(1 << lane);
        match glossy {
            Some(GlossyLobe::Phong { .. }) => self.glossy_bits |= 1 << lane,
            Some(GlossyLobe::Ggx { .. }) => {
                self.glossy_bits |= 1 << lane;
                self.ggx_bits |= 1 << lane;
            }
            None => {}
        }
    }

    /// π times the glossy lobes of the lanes toward the unit directions `wi` (zero in lanes
    /// without a glossy lobe, or where the lobe is negligible): the factor that turns D = E/π
    /// into G. Sharp lobes are mostly negligible toward a given light, so the `powf` is
    /// skipped where no lane is inside its lobe.
    #[inline(always)]
    fn glossy_factor(&self, wi: Vec3x8) -> F32x8 {
        let phong_bits = self.glossy_bits & !self.ggx_bits;
        let cos_alpha = load(&self.lobe_axis).dot(wi);
        let inside = M32x8::from_bitmask(phong_bits) & cos_alpha.gt(F32x8::from_array(self.lobe_cos_min));
        if inside.none() {
            return F32x8::ZERO;
        }
        let lobe = phong_lobe8(F32x8::from_array(self.exponent), cos_alpha);
        F32x8::select(inside, lobe * F32x8::splat(PI), F32x8::ZERO)
    }

    /// Adds the light `e` = E/π arriving from the unit directions `wi` to the lanes' D, G and
    /// S (see the module documentation): Lambert and Phong lanes take e and e·π·lobe, GGX lanes
    /// e(1 − s), e·π(1 − s)·D·V and e·π s·D·V. Lanes with nothing to add must hold e = 0.
    #[inline(always)]
    fn add(
        &self,
        e: Vec3x8,
        wi: Vec3x8,
        acc: &mut Vec3x8,
        acc_glossy: &mut Vec3x8,
        acc_schlick: &mut Vec3x8,
    ) {
        self.add_weighted(e, &self.weights(wi), acc, acc_glossy, acc_schlick);
    }

    /// The lanes' weights of light arriving from the unit directions `wi` in their D, G and S
    /// (see [`Chunk::add`]).
    #[inline(always)]
    fn weights(&self, wi: Vec3x8) -> ReceiverWeights {
        if self.ggx_bits == 0 {
            return ReceiverWeights::Phong((self.glossy_bits != 0).then(|| self.glossy_factor(wi)));
        }
        let ns = load(&self.ns);
        let (s, dv) = ggx_terms(
            F32x8::from_array(self.alpha),
            <[F32x8; 3]>::from(ns),
            load_array(&self.view),
            <[F32x8; 3]>::from(wi),
        );
        // Lanes without light may have directions on which the GGX terms are not finite.
        let ggx = M32x8::from_bitmask(self.ggx_bits) & ns.dot(wi).gt(F32x8::ZERO);
        let (zero, one) = (F32x8::ZERO, F32x8::splat(1.0));
        ReceiverWeights::Ggx([
            F32x8::select(ggx, one - s, one),
            F32x8::select(ggx, (one - s) * dv * F32x8::splat(PI), self.glossy_factor(wi)),
            F32x8::select(ggx, s * dv * F32x8::splat(PI), zero),
        ])
    }

    /// [`Chunk::add`] with the weights already computed.
    #[inline(always)]
    fn add_weighted(
        &self,
        e: Vec3x8,
        w: &ReceiverWeights,
        acc: &mut Vec3x8,
        acc_glossy: &mut Vec3x8,
        acc_schlick: &mut Vec3x8,
    ) {
        match w {
            ReceiverWeights::Phong(glossy) => {
                *acc = *acc + e;
                if let Some(glossy) = glossy {
                    *acc_glossy = *acc_glossy + e * *glossy;
                }
            }
            ReceiverWeights::Ggx([diffuse, glossy, schlick]) => {
                *acc = *acc + e * *diffuse;
                *acc_glossy = *acc_glossy + e * *glossy;
                *acc_schlick = *acc_schlick + e * *schlick;
            }
        }
    }
}

/// What light arriving at a chunk's lanes adds to their D, G and S ([`Chunk::weights`]).
#[derive(Clone, Debug)]
enum ReceiverWeights {
    /// Lambert and Phong lanes: all of it to D, and times the lobe (π·lobe) to G if any lane
    /// is glossy.
    Phong(Option<F32x8>),
    /// With GGX lanes: the weights in D, G and S.
    Ggx([F32x8; 3]),
}

impl ReceiverWeights {
    /// The sum of the weights, per lane: how much the light counts in the lane's pixel at
    /// most (for reflectances up to one).
    #[inline(always)]
    fn total(&self) -> F32x8 {
        match self {
            ReceiverWeights::Phong(None) => F32x8::splat(1.0),
            ReceiverWeights::Phong(Some(g)) => F32x8::splat(1.0) + *g,
            ReceiverWeights::Ggx([d, g, s]) => *d + *g + *s,
        }
    }
}

/// A surface VPL as the VPL loop sees it: its position lifted off its surface (the shadow
/// rays end there, so that surface does not count as a blocker) and its powers scaled by its
/// weight and 1/π², as splatted constants.
struct VplEmitter {
    y: Vec3x8,
    ny: Vec3x8,
    /// Diffuse power times weight/π² (D = E/π of a Lambertian VPL is colour · g).
    colour: Vec3,
    /// The sum of `colour`'s channels: the roulette's threshold is relative to it.
    colour_sum: f32,
    glossy_colour: Vec3,
    schlick_colour: Vec3,
    lobe: Option<GlossyLobe>,
    axis: Vec3x8,
    cos_min: F32x8,
    exponent: F32x8,
}

/// A VPL's light at a chunk's points before visibility.
struct Unshadowed {
    /// Lanes the VPL lights (both faces turned to each other).
    valid: M32x8,
    /// Distances to the VPL.
    dist: F32x8,
    /// Squared distances to the VPL and their clamped values.
    dist2: (F32x8, F32x8),
    /// Unit directions to the VPL.
    wi: Vec3x8,
    /// D = E/π from the VPL's diffuse part and its glossy lobe toward the points.
    e: Vec3x8,
    /// The points' weights of this light; none where a Lambertian VPL lights matte points.
    weights: Option<ReceiverWeights>,
}

impl Unshadowed {
    /// How much the light counts in the lanes' pixels at most, as the roulette sees it: e's
    /// channels summed, times the receivers' total weight, with the geometry term clamped at
    /// the squared distance `d_min2` instead of the frame's.
    #[inline(always)]
    fn roulette_strength(&self, d_min2: F32x8) -> F32x8 {
        let (e, (dist2, clamped)) = (self.e, self.dist2);
        let weight = self.weights.as_ref().map_or(F32x8::splat(1.0), ReceiverWeights::total);
        (e.x + e.y + e.z) * weight * (clamped / dist2.max(d_min2))
    }
}

impl VplEmitter {
    fn new(vpl: &Vpl, weight: f32) -> Self {
        let colour = vpl.power * (weight * FRAC_1_PI * FRAC_1_PI);
        let (axis, exponent) = match vpl.lobe {
            Some(GlossyLobe::Phong { axis, exponent }) => (axis, exponent),
            _ => (vpl.normal, 1.0),
        };
        Self {
            y: Vec3x8::splat(offset_ray_origin(vpl.position, vpl.normal).to_array()),
            ny: Vec3x8::splat(vpl.normal.to_array()),
            colour,
            colour_sum: colour.x + colour.y + colour.z,
            glossy_colour: vpl.glossy * (weight * FRAC_1_PI),
            schlick_colour: vpl.schlick * (weight * FRAC_1_PI),
            lobe: vpl.lobe,
            axis: Vec3x8::splat(axis.to_array()),
            cos_min: F32x8::splat(lobe_cutoff(exponent)),
            exponent: F32x8::splat(exponent),
        }
    }

    /// The VPL's light at the points of `chunk` before visibility, with the clamp `d_min2`;
    /// `None` if it lights none of them.
    #[inline(always)]
    fn unshadowed(&self, chunk: &Chunk, d_min2: F32x8) -> Option<Unshadowed> {
        let d = self.y - load(&chunk.origin);
        let dist2 = d.dot(d);
        let dist = dist2.sqrt();
        let wi = d * (F32x8::splat(1.0) / dist);
        let cos_x = load(&chunk.ns).dot(wi);
        let cos_y = -self.ny.dot(wi);
        let zero = F32x8::ZERO;
        let valid = M32x8::from_bitmask(chunk.bits)
            & cos_x.gt(zero)
            & cos_y.gt(zero)
            & load(&chunk.ng).dot(wi).gt(zero);
        if valid.none() {
            return None;
        }
        let clamped = dist2.max(d_min2);
        let g = cos_x * cos_y / clamped;
        // Every term is a multiple of g.
        let mut e = Vec3x8::splat(self.colour.to_array()) * g;
        match self.lobe {
            None => {}
            Some(GlossyLobe::Phong { .. }) => {
                let cos_alpha = -self.axis.dot(wi);
                let inside = cos_alpha.gt(self.cos_min);
                if inside.any() {
                    let lobe_y = F32x8::select(inside, phong_lobe8(self.exponent, cos_alpha), zero);
                    e = e + Vec3x8::splat(self.glossy_colour.to_array()) * (g * lobe_y);
                }
            }
            Some(GlossyLobe::Ggx { fixed, alpha }) => {
                // The VPL's BRDF between the light's direction and x: its diffuse part
                // weighted by 1 − s, its specular part by F₀(1 − s) + s.
                let fixed = Vec3x8::splat(fixed.to_array());
                let (s, dv) =
                    ggx_terms(F32x8::splat(alpha), <[F32x8; 3]>::from(self.ny), fixed.into(), (-wi).into());
                let one = F32x8::splat(1.0);
                let (s, dv) = (F32x8::select(valid, s, zero), F32x8::select(valid, dv, zero));
                e = e * (one - s)
                    + Vec3x8::splat(self.glossy_colour.to_array()) * (g * (one - s) * dv)
                    + Vec3x8::splat(self.schlick_colour.to_array()) * (g * s * dv);
            }
        }
        let weights = (self.lobe.is_some() || chunk.glossy_bits != 0).then(|| chunk.weights(wi));
        Some(Unshadowed { valid, dist, dist2: (dist2, clamped), wi, e, weights })
    }
}

/// A chunk's light from one VPL waiting for the answers of its shadow rays, which are traced
/// gathered into full packets ([`ShadowQueue`]).
#[derive(Clone, Debug)]
struct PendingLight {
    /// Index of the chunk.
    chunk: u32,
    /// Light, scaled by the roulette.
    e: Vec3x8,
    weights: Option<ReceiverWeights>,
    /// Lanes whose shadow ray reached the VPL.
    lit: u32,
}

/// Shadow rays toward one VPL gathered into full 8-ray packets, each lane with the pending
/// light and lane it answers for (ARCHITECTURE.md, "Shadow rays gathered into full packets"):
/// the roulette leaves about three of a chunk's eight lanes, and a packet costs about the same
/// with three lanes as with eight. The rays come in pixel order and all end at the VPL, so a
/// gathered packet stays coherent.
struct ShadowQueue {
    rays: Packet8,
    /// Per lane, the pending light and its lane the ray answers for.
    owners: [(u32, u32); 8],
}

impl ShadowQueue {
    fn new() -> Self {
        Self { rays: Packet8::new(), owners: [(0, 0); 8] }
    }

    /// Adds `ray` answering for `owner` (pending light, lane); true when the queue is full.
    #[inline(always)]
    fn push(&mut self, ray: Ray, owner: (u32, u32)) -> bool {
        let lane = self.rays.len() as usize;
        self.rays.set(lane, ray);
        self.owners[lane] = owner;
        lane + 1 == 8
    }

    /// Traces the queued rays and marks the lanes of `pending` whose ray reached its end.
    fn trace(
        &mut self,
        accel: &Accel,
        cache: &mut ShadowCache,
        pending: &mut [PendingLight],
        counts: &mut RayCounts,
    ) {
        let len = self.rays.len() as usize;
        if len == 0 {
            return;
        }
        let (packet, valid) = self.rays.packet();
        let lit = unoccluded(accel, &packet, valid, cache, counts).bitmask();
        for (i, &(slot, lane)) in self.owners[..len].iter().enumerate() {
            pending[slot as usize].lit |= (lit >> i & 1) << lane;
        }
        self.rays = Packet8::new();
    }
}

fn load(a: &[[f32; 8]; 3]) -> Vec3x8 {
    Vec3x8::new(F32x8::from_array(a[0]), F32x8::from_array(a[1]), F32x8::from_array(a[2]))
}

fn load_array(a: &[[f32; 8]; 3]) -> [F32x8; 3] {
    a.map(F32x8::from_array)
}

/// The shading points of one interleave group and their accumulated diffuse radiance D = E/π,
/// glossy radiance G and Schlick radiance S (see the module documentation), in chunks
/// of eight. Keep one per thread and reuse it: [`Receivers::clear`] keeps the memory.
#[derive(Clone, Debug, Default)]
pub struct Receivers {
    chunks: Vec<Chunk>,
    diffuse_radiance: Vec<Vec3x8>,
    glossy_radiance: Vec<Vec3x8>,
    schlick_radiance: Vec<Vec3x8>,
    /// Per chunk, the light of all the VPLs being added before visibility
    /// ([`Unshadowed::roulette_strength`]): the roulette's relative threshold.
    unshadowed_total: Vec<F32x8>,
    /// Per chunk, the running sums of the roulette's systematic sampling.
    roulette_sum: Vec<F32x8>,
    /// The chunks' light from the VPL being added, waiting for its shadow rays.
    pending: Vec<PendingLight>,
    len: usize,
}

impl Receivers {
    /// Each chunk of eight points with its diffuse, glossy and Schlick sums, in order: what
    /// every light and VPL walks.
    #[inline(always)]
    fn chunks_and_sums(
        &mut self,
    ) -> impl Iterator<Item = (&Chunk, (&mut Vec3x8, (&mut Vec3x8, &mut Vec3x8)))> {
        self.chunks.iter().zip(
            self.diffuse_radiance
                .iter_mut()
                .zip(self.glossy_radiance.iter_mut().zip(self.schlick_radiance.iter_mut())),
        )
    }

    /// Removes every point.
    pub fn clear(&mut self) {
        self.chunks.clear();
        self.diffuse_radiance.clear();
        self.glossy_radiance.clear();
        self.schlick_radiance.clear();
        self.len = 0;
    }

    /// Adds a point with its shadow-ray origin and unit shading and geometric normals, both
    /// turned to the side being lit, and for a point with a glossy lobe that lobe toward the
    /// viewer. Points are lit in the order they were added; neighbours in that
    /// order share packets, so add them in a coherent order. `seed` draws the point's shadow-ray
    /// roulette: a hash of what the point is (pixel, sample, frame), never of its position,
    /// whose last bits may differ where it is computed on another path.
    #[inline]
    pub fn push(&mut self, (origin, seed): (Vec3, u32), ns: Vec3, ng: Vec3, glossy: Option<GlossyLobe>) {
        let lane = self.len % 8;
        if lane == 0 {
            // Unoccupied lanes repeat the first point, so every lane of a packet holds a valid
            // ray (the packet kernels decide the traversal order from all lanes' signs).
            let mut chunk = Chunk::EMPTY;
            for l in 0..8 {
                chunk.set(l, (origin, seed), ns, ng, None);
            }
            chunk.bits = 0;
            self.chunks.push(chunk);
            self.diffuse_radiance.push(Vec3x8::splat([0.0; 3]));
            self.glossy_radiance.push(Vec3x8::splat([0.0; 3]));
            self.schlick_radiance.push(Vec3x8::splat([0.0; 3]));
        }
        if let Some(chunk) = self.chunks.last_mut() {
            chunk.set(lane, (origin, seed), ns, ng, glossy);
        }
        self.len += 1;
    }

    /// Widens the GGX lobes of the points for the VPLs that light them next
    /// ([`GlossyLobe::regularised`]).
    pub fn regularise(&mut self) {
        for chunk in self.chunks.iter_mut().filter(|c| c.ggx_bits != 0) {
            for (lane, alpha) in chunk.alpha.iter_mut().enumerate() {
                if chunk.ggx_bits & (1 << lane) != 0 {
                    *alpha = alpha.max(MIN_VPL_ALPHA);
                }
            }
        }
    }

    /// Sets the accumulated D and G of every point back to zero (the points stay).
    pub fn reset_radiance(&mut self) {
        self.diffuse_radiance
            .iter_mut()
            .chain(&mut self.glossy_radiance)
            .chain(&mut self.schlick_radiance)
            .for_each(|d| *d = Vec3x8::splat([0.0; 3]));
    }

    /// The diffuse radiance D, glossy radiance G and Schlick radiance S accumulated at point
    /// `i` (in the order of [`Receivers::push`]).
    #[inline]
    pub fn radiance(&self, i: usize) -> (Vec3, Vec3, Vec3) {
        let lane = |v: &[Vec3x8]| Vec3::from(v[i / 8].lane(i % 8));
        (lane(&self.diffuse_radiance), lane(&self.glossy_radiance), lane(&self.schlick_radiance))
    }

    /// Adds the light of the surface VPLs `vpls`, each weighted by `weight`, with the clamp
    /// `d_min2` = d_min² (0 for none), and the shadow rays' `roulette`.
    pub fn add_vpls<'v>(
        &mut self,
        accel: &Accel,
        vpls: impl Iterator<Item = &'v Vpl> + Clone,
        weight: f32,
        d_min2: f32,
        roulette: ShadowRoulette,
        counts: &mut RayCounts,
    ) {
        let d_min2 = F32x8::splat(d_min2);
        let roulette_d_min2 = F32x8::splat(roulette.d_min2);
        let zero = F32x8::ZERO;
        // The roulette's second threshold is a share of each point's light from all the VPLs
        // before visibility: summed first, without rays. The second pass computes each light
        // again: keeping it from this pass cost as many instructions (callgrind, Cornell box)
        // as it saved.
        self.unshadowed_total.clear();
        self.unshadowed_total.resize(self.chunks.len(), zero);
        if roulette.below > 0.0 {
            for vpl in vpls.clone() {
                let emitter = VplEmitter::new(vpl, weight);
                for (chunk, total) in self.chunks.iter().zip(&mut self.unshadowed_total) {
                    if let Some(light) = emitter.unshadowed(chunk, d_min2) {
                        let strength = light.roulette_strength(roulette_d_min2);
                        *total = *total + F32x8::select(light.valid, strength, zero);
                    }
                }
            }
        }
        // Systematic sampling of the roulette (ARCHITECTURE.md, "Shadow rays by Russian
        // roulette"): each lane walks its VPLs' survival probabilities with one running sum that
        // starts at a uniform number of its own, and a VPL's ray is traced where the sum crosses
        // an integer. Each ray is still traced with its own probability, but a point traces
        // (almost) exactly the expected number of rays, spread over its VPLs.
        self.roulette_sum.clear();
        self.roulette_sum.extend(self.chunks.iter().map(roulette_start));
        let Receivers {
            chunks,
            diffuse_radiance,
            glossy_radiance,
            schlick_radiance,
            unshadowed_total,
            roulette_sum,
            pending,
            ..
        } = self;
        for vpl in vpls {
            let emitter = VplEmitter::new(vpl, weight);
            let mut cache = ShadowCache::default();
            let mut queue = ShadowQueue::new();
            pending.clear();
            for (k, (chunk, (total, sum))) in
                chunks.iter().zip(unshadowed_total.iter().zip(roulette_sum.iter_mut())).enumerate()
            {
                let Some(light) = emitter.unshadowed(chunk, d_min2) else { continue };
                let strength = light.roulette_strength(roulette_d_min2);
                let Unshadowed { mut valid, dist, wi, mut e, weights, .. } = light;
                if roulette.below > 0.0 {
                    // Russian roulette on the shadow ray: a lane whose unoccluded light is
                    // below the threshold traces its ray with probability p and, if it
                    // survives, counts 1/p times.
                    let threshold = F32x8::splat(roulette.below * emitter.colour_sum)
                        .max(*total * F32x8::splat(SHADOW_ROULETTE_SHARE));
                    let p = F32x8::select(valid, (strength / threshold).min(F32x8::splat(1.0)), zero);
                    let next = *sum + p;
                    valid = valid & next.floor().gt(sum.floor());
                    *sum = next;
                    // Lanes the roulette drops may have p = 0: they scale by 0, not by 1/0.
                    let scale = F32x8::select(valid, F32x8::splat(1.0) / p, zero);
                    e = e * scale;
                }
                let mut bits = valid.bitmask();
                if bits == 0 {
                    continue;
                }
                let slot = pending.len() as u32;
                pending.push(PendingLight { chunk: k as u32, e, weights, lit: 0 });
                let tfar = dist * F32x8::splat(SHADOW_SHORTEN);
                while bits != 0 {
                    let lane = bits.trailing_zeros() as usize;
                    bits &= bits - 1;
                    let origin = Vec3::from(chunk.origin.map(|axis| axis[lane]));
                    let ray =
                        Ray { origin, dir: Vec3::from(wi.lane(lane)), tnear: 0.0, tfar: tfar.lane(lane) };
                    if queue.push(ray, (slot, lane as u32)) {
                        queue.trace(accel, &mut cache, pending, counts);
                    }
                }
            }
            queue.trace(accel, &mut cache, pending, counts);
            for light in pending.iter() {
                let k = light.chunk as usize;
                let (chunk, acc) = (&chunks[k], &mut diffuse_radiance[k]);
                let lit = M32x8::from_bitmask(light.lit);
                match &light.weights {
                    // E as the weighted path forms it (colour × g, then the roulette's scale,
                    // then added), so a lane's D does not depend on its chunk-mates.
                    None => *acc = *acc + Vec3x8::select(lit, light.e, Vec3x8::splat([0.0; 3])),
                    Some(weights) => {
                        let e = Vec3x8::new(
                            F32x8::select(lit, light.e.x, zero),
                            F32x8::select(lit, light.e.y, zero),
                            F32x8::select(lit, light.e.z, zero),
                        );
                        chunk.add_weighted(
                            e,
                            weights,
                            acc,
                            &mut glossy_radiance[k],
                            &mut schlick_radiance[k],
                        );
                    }
                }
            }
        }
    }

    /// Adds the direct light of point, spot and directional lights, each weighted by `weight`
    /// (1 for the exact lights of the scene; N for sky VPLs shared among N anti-aliasing
    /// samples).
    pub fn add_lights<'l>(
        &mut self,
        accel: &Accel,
        lights: impl Iterator<Item = &'l Light>,
        weight: f32,
        counts: &mut RayCounts,
    ) {
        let zero = F32x8::ZERO;
        for light in lights {
            let mut cache = ShadowCache::default();
            for (chunk, (acc, (acc_glossy, acc_schlick))) in self.chunks_and_sums() {
                let origin = load(&chunk.origin);
                let active = M32x8::from_bitmask(chunk.bits);
                let (wi, tfar, g, colour, mut valid) = match *light {
                    Light::Point { position, intensity } => {
                        let (wi, dist, dist2) = towards(origin, position);
                        (wi, dist, F32x8::splat(1.0) / dist2, intensity * FRAC_1_PI, active & dist2.gt(zero))
                    }
                    Light::Spot { position, direction, angle_deg, intensity } => {
                        let (wi, dist, dist2) = towards(origin, position);
                        let cone = SpotCone::new(direction, angle_deg);
                        let axis = Vec3x8::splat(cone.axis.to_array());
                        let inside = (-axis.dot(wi)).ge(F32x8::splat(cone.cos_half));
                        (
                            wi,
                            dist,
                            F32x8::splat(1.0) / dist2,
                            intensity * FRAC_1_PI,
                            active & inside & dist2.gt(zero),
                        )
                    }
                    Light::Directional { direction, irradiance } => {
                        let dir = -direction.normalize_or_zero();
                        if dir == Vec3::ZERO {
                            continue;
                        }
                        let wi = Vec3x8::splat(dir.to_array());
                        (wi, F32x8::splat(f32::INFINITY), F32x8::splat(1.0), irradiance / PI, active)
                    }
                };
                let cos_x = load(&chunk.ns).dot(wi);
                valid = valid & cos_x.gt(zero) & load(&chunk.ng).dot(wi).gt(zero);
                if valid.none() {
                    continue;
                }
                let packet =
                    RayPacket8 { origin, dir: wi, tnear: zero, tfar: tfar * F32x8::splat(SHADOW_SHORTEN) };
                let lit = unoccluded(accel, &packet, valid, &mut cache, counts);
                let g = F32x8::select(lit, cos_x * g * F32x8::splat(weight), zero);
                if chunk.ggx_bits != 0 {
                    chunk.add(Vec3x8::splat(colour.to_array()) * g, wi, acc, acc_glossy, acc_schlick);
                    continue;
                }
                // colour × g, then added, as `Chunk::add` forms it for a chunk with GGX lanes, so a
                // lane's D does not depend on its chunk-mates.
                let e = Vec3x8::splat(colour.to_array()) * g;
                *acc = *acc + e;
                if chunk.glossy_bits != 0 {
                    *acc_glossy = *acc_glossy + e * chunk.glossy_factor(wi);
                }
            }
        }
    }
}

/// Shadow rays by Russian roulette (Arvo & Kirk 1990; ARCHITECTURE.md, "Shadow rays by
/// Russian roulette"), as Ward's adaptive shadow testing skips the tests that cannot matter:
/// where a VPL's unoccluded light at a point is below a threshold, its shadow ray is traced
/// with probability (light / threshold) and counts 1/probability times if it is. The threshold
/// is the larger of the light of a geometry term [`SHADOW_ROULETTE`]/diagonal² (about a point a
/// diagonal away, at a grazing angle) and [`SHADOW_ROULETTE_SHARE`] of the light of all the
/// VPLs lighting the point. The estimate stays unbiased, and a skipped ray's error is below
/// the threshold. The probabilities do not depend on the frame's clamp (the roulette sees the
/// geometry terms clamped at the scene's default d_min, whatever the frame's), so a clamped
/// image traces the same rays as the unclamped one and stays darker pixel by pixel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadowRoulette {
    /// The geometry term below which a ray goes by roulette.
    below: f32,
    /// The squared distance at which the roulette clamps the geometry terms.
    d_min2: f32,
}

impl ShadowRoulette {
    /// Traces every shadow ray.
    pub const OFF: Self = Self { below: 0.0, d_min2: 0.0 };

    /// The roulette of a scene of bounding-box `diagonal`.
    pub fn for_scene(diagonal: f32) -> Self {
        if !(diagonal.is_finite() && diagonal > 0.0) {
            return Self::OFF;
        }
        let d_min = FrameSettings::clamp_for(diagonal);
        Self { below: SHADOW_ROULETTE / (diagonal * diagonal), d_min2: d_min * d_min }
    }
}

/// See [`ShadowRoulette`]. 2 measured (2026-11-28, ARCHITECTURE.md): all rays per pixel
/// 13.1 -> 11.1 on the conference room, 12.5 -> 10.9 on `sponza-roof-light`, 12.4 -> 9.8 on
/// the Cornell box, mean FLIP of one and of 16 frames within 1.3 % of tracing every ray; 5 was
/// 1-12 % worse.
const SHADOW_ROULETTE: f32 = 2.0;

/// See [`ShadowRoulette`]: a point traces at most about 1/share rays for its small lights. 0.2
/// measured (2026-11-28, ARCHITECTURE.md): all rays per pixel on the conference room
/// 11.1 -> 8.5, mean FLIP of one and of 16 frames within 2 %; 0.3 traced 7.9 but was up to
/// 4 % worse.
const SHADOW_ROULETTE_SHARE: f32 = 0.2;

/// Fraction of a glossy lobe's peak below which its value is dropped: cosⁿα < 10⁻⁶ changes the
/// light a lobe reflects by far less than a VPL's own noise.
const NEGLIGIBLE_LOBE: f32 = 1e-6;

/// The cosine to the lobe axis below which a Phong lobe of `exponent` is under
/// [`NEGLIGIBLE_LOBE`] of its peak (0 for exponents ≤ 1, whose whole hemisphere counts).
fn lobe_cutoff(exponent: f32) -> f32 {
    if exponent > 1.0 { NEGLIGIBLE_LOBE.powf(1.0 / exponent) } else { 0.0 }
}

/// Unit directions, distances and squared distances from `origin` to the point `p`.
#[inline(always)]
fn towards(origin: Vec3x8, p: Vec3) -> (Vec3x8, F32x8, F32x8) {
    let d = Vec3x8::splat(p.to_array()) - origin;
    let dist2 = d.dot(d);
    let dist = dist2.sqrt();
    (d * (F32x8::splat(1.0) / dist), dist, dist2)
}

/// Where the running sums of the shadow rays' systematic roulette start: one uniform number in
/// [0, 1) per lane hashed from the lanes' seeds ([`Receivers::push`]), so it does not depend on
/// the tile, thread or node that lights a point.
#[inline]
fn roulette_start(chunk: &Chunk) -> F32x8 {
    F32x8::from_array(std::array::from_fn(|l| {
        (hash_combine(chunk.seed[l], 0x9e37_79b9) >> 8) as f32 * (1.0 / 16_777_216.0)
    }))
}

/// The lanes of `valid` whose shadow ray reaches its end, with the shadow cache of the light
/// (the packets toward one light come in pixel order, so the triangle that blocked the last
/// one often blocks the next). A packet of one ray goes through the single-ray kernel, which is
/// faster for it.
#[inline(always)]
fn unoccluded(
    accel: &Accel,
    packet: &RayPacket8,
    valid: M32x8,
    cache: &mut ShadowCache,
    counts: &mut RayCounts,
) -> M32x8 {
    let bits = valid.bitmask();
    counts.shadow += u64::from(bits.count_ones());
    let blocked = if bits.count_ones() == 1 {
        if accel.occluded(&packet.ray(bits.trailing_zeros() as usize)) { valid } else { M32x8::NONE }
    } else {
        accel.occluded8_cached(packet, valid, cache)
    };
    valid.and_not(blocked)
}

#[cfg(test)]
mod tests;
