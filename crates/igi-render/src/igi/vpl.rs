//! Virtual point lights (VPLs): the particle tracing of instant radiosity (Keller 1997) as
//! instant global illumination uses it (paper 2.1). This module owns the light paths of a
//! frame: which light each starts at, how it bounces, and the VPLs it leaves.
//!
//! # Lights
//!
//! Point, spot and directional lights (or, in a scene without any light, the headlight
//! [`eye_light`](crate::prepared::lights::eye_light)) are evaluated exactly by the renderer in every set; they are kept in
//! [`VplSets::lights`] and paths starting at them leave no VPL at the light. The emissive
//! triangles have no such exact term: the first vertex of a path on an area light is a VPL
//! ("light-surface samples are VPLs too"), and these VPLs are the direct light of area lights.
//!
//! Exact terms cost a shadow ray per light and pixel, and they count toward the VPLs per pixel
//! (see "Paths per set"), so a scene with more punctual lights than [`exact_light_limit`]
//! (half the VPLs per pixel) has none: its punctual lights are sources of light paths like
//! the others, and a path that starts at light l leaves the light itself, scaled by
//! 1/(p_l · P), among its set's sky VPLs. Each set then holds an unbiased, power-proportional
//! sample of the lights, and the filter merges the sets' samples as it merges their VPLs
//! (200,000 point lights used to cost 600,000 shadow rays per pixel).
//!
//! A path starts at light l with probability p_l ∝ luminance of its power Φ_l:
//!
//! | light | Φ_l | start point and direction |
//! |---|---|---|
//! | emissive triangles | π · area · L_e each | [`AreaLights::sample`] (density p_A), cosine |
//! | point | 4π I | the light, uniform on the sphere |
//! | spot, full angle 2α | 2π (1 − cos α) I | the light, uniform in the (hard) cone |
//! | directional | π R² E | uniform on a disc of radius R across the light, along the light |
//! | environment (sky) | π R² ∫ L dω | ω by the sky's importance, then a disc across ω, along −ω |
//!
//! where R is the radius of the bounding sphere of the scene bounds: the disc is perpendicular
//! to the light direction, centred on the sphere's axis, and set back beyond the sphere, so
//! every ray the light sends into the scene crosses it. All emissive triangles together are
//! one entry of this choice (weight: luminance of their total power); [`AreaLights::sample`]
//! then picks the triangle by its own power.
//!
//! With P paths in its set, a particle starts with power (per RGB channel)
//!
//! ```text
//! Φ = Φ_l / (p_l · P)                               (punctual and directional lights)
//! Φ = L(ω) · π R² / (p_ω(ω) · p_l · P)              (sky, direction density p_ω)
//! Φ = L_e(y) · cosθ / (p_l · p_A(y) · (cosθ / π) · P) = π L_e(y) / (p_l · p_A(y) · P)   (area)
//! ```
//!
//! # Random walk
//!
//! At each surface the particle hits, the surface shader gives the BRDF parameters and
//! [`Bsdf`] reads them (two-sided reflection):
//!
//! - If the surface has a diffuse or glossy lobe, a VPL stays there: the incident power Φ, the
//!   shading normal turned to the side the particle came from (decided by the geometric
//!   normal), and the surface's non-delta BRDF for light from that direction. The VPL thus
//!   emits radiant intensity
//!
//!   ```text
//!   I(ω) = Φ · f_r(ω_in, ω) · cosθ_ω = cosθ_ω · (Φ ρ_d / π  +  Φ ρ_s · (n+2)/(2π) · max(0, r·ω)ⁿ)
//!   ```
//!
//!   with r the mirror direction of ω_in (toward the light): a glossy VPL lights mostly the
//!   mirror direction of the light that reached it. On a glTF (GGX) surface the parentheses
//!   hold that BRDF instead, Φ·f_r(ω_in, ω) = Φρ_d(1 − s)/π + (Φρ_s(1 − s) + Φ s)·D·V
//!   ([`igi_shade::brdf::ggx`]). The original system kept only the diffuse
//!   part (paper section 5 names this a weakness); here a VPL carries its glossy lobe.
//! - The walk goes on in a direction sampled from the whole BSDF ([`Bsdf::sample`]: diffuse,
//!   glossy, mirror or glass lobe, the lobe chosen by reflectance), carrying Φ ← Φ·w/q with w
//!   the sample's weight and q = min(1, max w) the Russian-roulette survival probability.
//!   Glass refracts or reflects by the Fresnel reflectance (Φ unchanged: flux is not scaled
//!   by η²).
//!
//! A walk ends on a miss, by roulette, after [`MAX_BOUNCES`] surface interactions, on
//! non-finite values, or where a shading normal would send a reflection below the geometric
//! surface (as in pbrt: light would leak through the surface otherwise).
//!
//! For a point x with BRDF f_x and a VPL i at y_i,
//!
//! ```text
//! L(x → ω_o) ≈ Σ_i f_x(ω_i, ω_o) · I_i(y_i → x) cosθ_x / d_i² · V(x, y_i)  +  Σ_lights (exact terms)
//! ```
//!
//! is an unbiased estimate of the light x reflects (before the renderer clamps the 1/d² term),
//! except for the energy beyond the bounce cap.
//!
//! # Sampling
//!
//! The sets of a frame are consecutive blocks of one Owen-scrambled Sobol sequence
//! ([`sobol4`]), with the scramble seed `hash_combine(span.seed, VPL_STREAM)` of the frame's
//! span ([`FrameState::sequence`]). Frames that continue one sequence (progressive
//! accumulation) take its next P = [`VplSets::paths`] samples, set s the s-th block (the first
//! sets one path more where S does not divide P), so the frames together are one sequence.
//! Frames that repeat their samples (a still or animated view, whose light paths follow the
//! light when it moves) give set s the s-th block of c = ⌈P / S⌉ samples, all of them traced,
//! or the first c − 1 where S does not divide P: one path more or less in an animated frame
//! then changes one set, not the blocks of every set after it (which made the animated room
//! flicker). Each set is then an
//! unbiased randomized quasi-Monte Carlo estimate on its own (a stratified net when P is a
//! power of two), the S sets that the filter combines are spread evenly together, and
//! progressive frames continue the same sequence. Its 4D dimension
//! sets are
//! 0: light choice, triangle choice, point on the triangle or directional disc;
//! 1: emission direction; 2 + b: lobe choice, direction and roulette at surface interaction b.
//! Sets run in parallel and are returned in set order, so the VPLs depend only
//! on the scene and the [`FrameState`], never on the thread count.
//!
//! # Paths per set
//!
//! [`FrameSettings::vpls_per_pixel`](crate::frame::FrameSettings::vpls_per_pixel) asks for V
//! VPLs per set, the lights of [`VplSets::lights`] included, so the target of surface VPLs is
//! T = max(1, V − lights): a set keeps at least one path even when the punctual lights alone
//! exhaust V, or it would hold no indirect light. The frame starts round(S·T / e) paths, at
//! least one and at most min(64·T, [`MAX_SAMPLES`] / S) per set, shared out so that sets
//! differ by at most one path, where e is the expected number of VPLs a path leaves and the
//! frame keeps (see "Keeping the VPLs the view needs" below). (Rounding
//! per set instead, with e = 2.5 and T = 11, would give every set 4 paths and 10 VPLs.) The walk
//! makes e depend on the scene's reflectances, textures, specular surfaces and on how much
//! light escapes through openings, which no closed formula over the materials captures (a
//! closed scene of mean reflectance r leaves P_area + 1/(1 − r) VPLs per path; for the
//! Cornell box, open at the front, that is 4.0 against 2.9 measured). So e is measured: a
//! pilot of [`PILOT_PATHS`] paths with a fixed seed runs the same walk and sums the
//! probabilities of keeping its VPLs. The pilot depends only on the scene and the camera, so
//! the paths do not change between frames of a still scene, and the pilot's own VPLs are
//! discarded, so the estimate stays unbiased. The number of VPLs in a set is random, about V
//! on average.
//!
//! # Keeping the VPLs the view needs
//!
//! Each VPL a path leaves, on a surface or in the sky, is kept with the probability
//! [`ViewImportance`] gives it: 1 if it can light a point the camera sees, else
//! [`UNSEEN_ACCEPTANCE`](crate::igi::view_importance::UNSEEN_ACCEPTANCE), its power then divided
//! by that probability (unbiased). The decision is a hash of the frame's seed, the path and
//! the vertex, so the sets still depend only on the scene and the [`FrameState`]; the walk
//! goes on either way, so the paths and their Sobol dimensions do not change. A scene lit
//! through an opening (Sponza's atrium) thereby starts four times the paths and lights the
//! view with V VPLs per set instead of a handful, and a viewer's one-frame solution after a
//! camera move is as bright as the still view's mean instead of half as bright.
//!
//! [`AreaLights::sample`]: crate::prepared::lights::AreaLights::sample

use crate::frame::FrameState;
use crate::frame::limits::MAX_BOUNCES;
use crate::igi::view_importance::ViewImportance;
use crate::igi::vpl_lighting::GlossyLobe;
use crate::image::tonemap::luminance;
use crate::prepared::PreparedScene;
use crate::prepared::lights::SpotCone;
use crate::sampling::{Cdf, MAX_SAMPLES, hash_combine, sobol4};
use crate::sampling::{concentric_disc, uniform_cone, uniform_sphere};
use glam::{Vec2, Vec3};
use igi_bvh::{Ray, offset_ray_origin};
use igi_scene::Light;
use igi_shade::brdf::{Bsdf, cosine_hemisphere};
use rayon::prelude::*;
use std::f32::consts::PI;
use std::sync::atomic::{AtomicBool, Ordering};

/// Light paths of the pilot that measures the expected VPLs per path.
pub const PILOT_PATHS: u32 = 256;

/// Sobol dimension set of the light choice and the start point.
const LIGHT_DIMENSIONS: u32 = 0;
/// Sobol dimension set of the emission direction.
const EMISSION_DIMENSIONS: u32 = 1;
/// Sobol dimension set of the first surface interaction; interaction b uses this plus b.
const BOUNCE_DIMENSIONS: u32 = 2;

// Every interaction of a capped walk has its own Sobol dimensions.
const _: () = assert!(BOUNCE_DIMENSIONS + MAX_BOUNCES <= sobol_burley::NUM_DIMENSION_SETS_4D);

/// Mixed into the frame seed so the VPL sequences differ from the pixels' sequences.
const VPL_STREAM: u32 = 0x5650_4c53;
/// Mixed into the frame seed for the decisions which VPLs to keep ([`ViewImportance`]).
const KEEP_STREAM: u32 = 0x6b65_6570;
/// Scramble seed of the pilot: fixed, so the number of paths does not follow the frame seed.
const PILOT_SEED: u32 = 0x7069_6c74;
/// Paths per set are at most this many times the target T (bounds the work where the pilot
/// sees almost no VPLs, as for light that mostly leaves the scene).
const MAX_PATHS_PER_TARGET: u32 = 64;
/// The directional light's disc sits this fraction of R beyond the bounding sphere, so no
/// start point lies on a surface touching the sphere.
const DISC_MARGIN: f32 = 1e-3;

/// A virtual point light on a surface: radiant intensity toward a unit direction ω of
///
/// ```text
/// I(ω) = max(0, normal · ω) · (power / π + glossy · (exponent + 2)/(2π) · max(0, axis · ω)^exponent)
/// ```
///
/// for a Phong `lobe`, and for a GGX `lobe` with ω_in its fixed direction and s, D·V its
/// terms between ω_in and ω ([`igi_shade::brdf::ggx`])
///
/// ```text
/// I(ω) = max(0, normal · ω) · (power·(1 − s)/π + (glossy·(1 − s) + schlick·s)·D·V)
/// ```
///
/// (the surface's diffuse and glossy reflection of the light that reached it; see the module
/// documentation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Vpl {
    /// Position on the surface.
    pub position: Vec3,
    /// Unit normal of the emitting side (the side the light arrived from).
    pub normal: Vec3,
    /// Power Φ·ρ_d of the diffuse part per channel.
    pub power: Vec3,
    /// Power Φ·ρ_s of the glossy part per channel (Φ·F₀ for GGX; zero for a Lambertian VPL).
    pub glossy: Vec3,
    /// Power Φ of the Schlick part of a GGX lobe (zero otherwise).
    pub schlick: Vec3,
    /// The glossy lobe, its fixed direction toward the light (`None` for a Lambertian VPL).
    pub lobe: Option<GlossyLobe>,
}

impl Vpl {
    /// A Lambertian VPL (a point on an area light, or on a matte surface).
    pub fn diffuse(position: Vec3, normal: Vec3, power: Vec3) -> Self {
        Self { position, normal, power, glossy: Vec3::ZERO, schlick: Vec3::ZERO, lobe: None }
    }

    /// True if the VPL has a glossy part.
    pub fn is_glossy(&self) -> bool {
        self.lobe.is_some()
    }
}

/// The most point, spot and directional lights that light every set exactly: half the VPLs
/// per pixel, at least one (see the module documentation, "Lights").
pub fn exact_light_limit(vpls_per_pixel: u32) -> usize {
    (vpls_per_pixel / 2).max(1) as usize
}

/// The VPLs of one frame: n·m interleaved sets of surface VPLs and sky VPLs, plus the
/// punctual lights that light every set exactly.
#[derive(Clone, Debug, Default)]
pub struct VplSets {
    lights: Vec<Light>,
    sets: Vec<Vec<Vpl>>,
    sky: Vec<Vec<Light>>,
    paths: u32,
    expected_vpls_per_path: f32,
}

impl VplSets {
    /// Generates the sets of `frame` in `scene`: `frame.settings.set_count()` sets sharing
    /// [`VplSets::paths`] light paths (see the module documentation). The result
    /// depends only on `scene` and `frame`. A scene whose lights all have zero power gets
    /// empty sets.
    pub fn generate(scene: &PreparedScene, frame: &FrameState) -> Self {
        let punctual = scene.punctual_lights(&frame.camera);
        let sampled_lights = punctual.len() > exact_light_limit(frame.settings.vpls_per_pixel);
        let lights = if sampled_lights { Vec::new() } else { punctual.clone() };
        let view = ViewImportance::new(scene, frame);
        let Some(emitters) = Emitters::new(scene, &punctual, sampled_lights, frame.settings.bounces, view)
        else {
            let sets = vec![Vec::new(); frame.settings.set_count() as usize];
            let sky = sets.iter().map(|_| Vec::new()).collect();
            return Self { lights, sets, sky, paths: 0, expected_vpls_per_path: 0.0 };
        };

        let expected_vpls_per_path = emitters.pilot();
        let light_count = u32::try_from(lights.len()).unwrap_or(u32::MAX);
        let target = frame.settings.vpls_per_pixel.saturating_sub(light_count).max(1);
        let set_count = frame.settings.set_count().max(1);
        // All sets of a frame share one Sobol sequence, so the paths of all sets must fit in it.
        let max_paths = target.saturating_mul(MAX_PATHS_PER_TARGET).min(MAX_SAMPLES / set_count) * set_count;
        // The frame's paths are rounded as a whole and shared out (sets differ by at most one
        // path), so the VPL count per set is V on average, not round(V / e) · e.
        let paths = if expected_vpls_per_path > 0.0 {
            // The float-to-int cast saturates; the clamp keeps at least one path per set.
            let wanted = (target as f32 * set_count as f32 / expected_vpls_per_path).round() as u32;
            if wanted > max_paths {
                // Once per process: a viewer would repeat it every frame.
                static WARNED: AtomicBool = AtomicBool::new(false);
                let got = (max_paths as f32 * expected_vpls_per_path / set_count as f32).round();
                let message = format!(
                    "{} VPLs per pixel would take {wanted} light paths per frame in this scene (most \
                     paths leave it without a bounce), more than one frame's {MAX_SAMPLES} samples \
                     hold for {set_count} VPL sets: about {got} per pixel instead; a smaller \
                     interleave (fewer VPL sets) or fewer VPLs per pixel avoids this",
                    frame.settings.vpls_per_pixel,
                );
                if WARNED.swap(true, Ordering::Relaxed) {
                    tracing::debug!("{message}");
                } else {
                    tracing::warn!("{message}");
                }
            }
            wanted.clamp(set_count, max_paths)
        } else {
            max_paths
        };

        let sharing = if frame.reseed_per_frame { Sharing::Contiguous } else { Sharing::FixedBlocks };
        let span = frame.sequence(sharing.span(paths, set_count));
        let seed = hash_combine(span.seed, VPL_STREAM);
        let capacity = (paths as f32 / set_count as f32 * expected_vpls_per_path * 1.25) as usize + 8;
        let (sets, sky) = (0..set_count)
            .into_par_iter()
            .map(|s| {
                let mut set = PathVpls { surface: Vec::with_capacity(capacity), ..PathVpls::default() };
                let (first, count) = sharing.share(paths, set_count, s);
                for k in span.first + first..span.first + first + count {
                    emitters.trace_path(k, seed, count, &mut set);
                }
                (set.surface, set.sky)
            })
            .unzip();
        Self { lights, sets, sky, paths, expected_vpls_per_path }
    }

    /// Point, spot and directional lights (or the headlight): exact direct light, in every set.
    pub fn lights(&self) -> &[Light] {
        &self.lights
    }

    /// Surface VPLs of set `s`.
    pub fn set(&self, s: u32) -> &[Vpl] {
        &self.sets[s as usize]
    }

    /// Sky VPLs of set `s`: directional lights, each a sample of the light the sky sends,
    /// and in a scene with more punctual lights than [`exact_light_limit`] the lights its
    /// paths started at, scaled (see the module documentation).
    pub fn sky(&self, s: u32) -> &[Light] {
        &self.sky[s as usize]
    }

    /// Number of sets.
    pub fn set_count(&self) -> u32 {
        self.sets.len() as u32
    }

    /// Light paths started in all sets together.
    pub fn paths(&self) -> u32 {
        self.paths
    }

    /// Surface and sky VPLs of all sets together.
    pub fn total_vpls(&self) -> usize {
        self.sets.iter().map(Vec::len).sum::<usize>() + self.sky.iter().map(Vec::len).sum::<usize>()
    }

    /// The pilot's estimate of the VPLs one light path leaves, which chose
    /// [`VplSets::paths`] (0 if no light has any power).
    pub fn expected_vpls_per_path(&self) -> f32 {
        self.expected_vpls_per_path
    }
}

/// How a frame's paths are shared out over its sets (module documentation, "Sampling").
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Sharing {
    /// One path after the other: the frame's paths are the first P samples of its span. For
    /// frames that continue one sequence (progressive accumulation).
    Contiguous,
    /// In fixed blocks of ⌈P / S⌉ samples, so that one path more or less changes one set. For
    /// frames that repeat their samples (a still or animated view).
    FixedBlocks,
}

impl Sharing {
    /// The samples of the frame's span that `paths` paths over `sets` sets own.
    fn span(self, paths: u32, sets: u32) -> u32 {
        match self {
            Self::Contiguous => paths,
            Self::FixedBlocks => paths.div_ceil(sets) * sets,
        }
    }

    /// The first path (relative to the frame's span) and the number of paths of set `s` when
    /// `paths` are shared out over `sets` sets. Contiguous: the first paths mod sets sets take
    /// one path more. Fixed blocks: set s owns the c = ⌈paths / sets⌉ samples from s·c on and
    /// traces all of them if the sets divide the paths evenly or s < paths mod sets, else the
    /// first c − 1; one path more or less (an animated scene's pilot estimate crossing a
    /// rounding step) then changes one set's paths, not those of every set after it.
    fn share(self, paths: u32, sets: u32, s: u32) -> (u32, u32) {
        let extra = paths % sets;
        match self {
            Self::Contiguous => {
                let base = paths / sets;
                (s * base + s.min(extra), base + u32::from(s < extra))
            }
            Self::FixedBlocks => {
                let stride = paths.div_ceil(sets);
                (s * stride, if extra == 0 || s < extra { stride } else { stride - 1 })
            }
        }
    }
}

/// The VPLs light paths leave: on surfaces, and in the sky.
#[derive(Debug, Default)]
struct PathVpls {
    surface: Vec<Vpl>,
    sky: Vec<Light>,
    /// The VPLs kept in expectation: the sum of their probabilities of being kept.
    expected: f32,
}

/// Where a light path starts.
#[derive(Clone, Copy, Debug)]
enum Source {
    /// All emissive triangles, the triangle chosen by [`AreaLights::sample`].
    Area,
    /// The punctual light of this index in [`Emitters::lights`] (point, spot or directional).
    Punctual(usize),
    /// The sky ([`PreparedScene::environment`]).
    Environment,
}

/// The lights of a frame as sources of light paths, with the distribution that picks one.
struct Emitters<'a> {
    scene: &'a PreparedScene,
    /// The frame's point, spot and directional lights.
    lights: &'a [Light],
    /// Whether the punctual lights are sampled by the paths ([`exact_light_limit`]): a path
    /// that starts at one leaves it, scaled as a VPL, among the set's [`PathVpls::sky`].
    sampled_lights: bool,
    /// The sources with their power Φ_l per channel (unused for [`Source::Area`], whose
    /// particles take the power of the sampled point).
    sources: Vec<(Source, Vec3)>,
    /// Chooses a source in proportion to the luminance of its power.
    choice: Cdf,
    /// Centre and radius of the scene's bounding sphere (directional lights).
    sphere: (Vec3, f32),
    /// Surface interactions a walk follows ([`FrameSettings::bounces`](crate::FrameSettings::bounces)).
    bounces: u32,
    /// Which VPLs the view needs.
    view: ViewImportance,
}

impl<'a> Emitters<'a> {
    /// The sources of `scene`'s area lights and of `lights` (`sampled_lights`: see the
    /// field); `None` if none emits any power.
    fn new(
        scene: &'a PreparedScene,
        lights: &'a [Light],
        sampled_lights: bool,
        bounces: u32,
        view: ViewImportance,
    ) -> Option<Self> {
        let bounds = scene.bounds();
        let sphere =
            if bounds.is_empty() { (Vec3::ZERO, 0.0) } else { (bounds.centroid(), 0.5 * bounds.diagonal()) };
        let mut sources = Vec::with_capacity(lights.len() + 1);
        if !scene.area_lights().is_empty() {
            sources.push((Source::Area, scene.area_lights().total_power()));
        }
        if let Some(sky) = scene.environment() {
            // The flux through a disc of radius R across the scene from every direction.
            sources.push((Source::Environment, PI * sphere.1 * sphere.1 * sky.integral()));
        }
        for (index, light) in lights.iter().enumerate() {
            let power = match *light {
                Light::Point { intensity, .. } => 4.0 * PI * intensity,
                Light::Spot { direction, angle_deg, intensity, .. } => {
                    let cone = SpotCone::new(direction, angle_deg);
                    if cone.axis == Vec3::ZERO {
                        Vec3::ZERO
                    } else {
                        2.0 * PI * (1.0 - cone.cos_half) * intensity
                    }
                }
                Light::Directional { direction, irradiance } => {
                    if direction.normalize_or_zero() == Vec3::ZERO {
                        Vec3::ZERO
                    } else {
                        PI * sphere.1 * sphere.1 * irradiance
                    }
                }
            };
            sources.push((Source::Punctual(index), power));
        }
        let choice = Cdf::new(sources.iter().map(|(_, power)| {
            let w = luminance(*power);
            if w.is_finite() { w } else { 0.0 }
        }));
        (!choice.is_empty()).then_some(Self {
            scene,
            lights,
            sampled_lights,
            sources,
            choice,
            sphere,
            bounces: bounces.min(MAX_BOUNCES),
            view,
        })
    }

    /// The mean number of VPLs kept (in expectation) of [`PILOT_PATHS`] paths under the
    /// fixed pilot seed.
    fn pilot(&self) -> f32 {
        // In parallel (each kept VPL may cost a shadow ray per grid point), summed in path
        // order so the sum does not depend on the threads.
        let expected: Vec<f32> = (0..PILOT_PATHS)
            .into_par_iter()
            .map(|k| {
                let mut vpls = PathVpls::default();
                self.trace_path(k, PILOT_SEED, 1, &mut vpls);
                vpls.expected
            })
            .collect();
        expected.iter().sum::<f32>() / PILOT_PATHS as f32
    }

    /// Traces path `k` of `paths` of the set with scramble seed `seed`, appending the VPLs it
    /// keeps ([`Emitters::keep`]).
    fn trace_path(&self, k: u32, seed: u32, paths: u32, out: &mut PathVpls) {
        let (surface_before, sky_before) = (out.surface.len(), out.sky.len());
        self.start_path(k, seed, paths, out);
        self.keep(k, seed, surface_before, sky_before, out);
    }

    /// Keeps each VPL of path `k` from index `surface_before` (`sky_before` for the sky VPL)
    /// on with its probability of [`ViewImportance`], dividing the power of one kept with
    /// probability p < 1 by p; adds the probabilities to [`PathVpls::expected`].
    fn keep(&self, k: u32, seed: u32, surface_before: usize, sky_before: usize, out: &mut PathVpls) {
        let accel = self.scene.accel();
        // One uniform number per VPL: the path's surface vertex, the sky VPL after them all.
        let path_seed = hash_combine(hash_combine(seed, KEEP_STREAM), k);
        let kept = |vertex: usize, p: f32| {
            let u = (hash_combine(path_seed, vertex as u32) >> 8) as f32 / (1u32 << 24) as f32;
            (u < p).then(|| 1.0 / p)
        };
        // The kept VPLs go after the path's own, which then go.
        let end = out.surface.len();
        for i in surface_before..end {
            let v = out.surface[i];
            let p = self.view.surface_acceptance(accel, v.position, v.normal);
            out.expected += p;
            if let Some(scale) = kept(i - surface_before, p) {
                out.surface.push(Vpl { power: v.power * scale, glossy: v.glossy * scale, ..v });
            }
        }
        out.surface.drain(surface_before..end);
        let end = out.sky.len();
        for i in sky_before..end {
            // A sky VPL or a sampled directional light is kept if the view sees its
            // direction; a sampled point or spot light always is.
            let light = out.sky[i].clone();
            let p = match light {
                Light::Directional { direction, .. } => self.view.sky_acceptance(accel, direction),
                Light::Point { .. } | Light::Spot { .. } => 1.0,
            };
            out.expected += p;
            if let Some(scale) = kept(MAX_BOUNCES as usize + 1 + i - sky_before, p) {
                out.sky.push(light.scaled(scale));
            }
        }
        out.sky.drain(sky_before..end);
    }

    /// Starts path `k` of `paths` of the set with scramble seed `seed` at a light and walks
    /// it, appending every VPL it leaves.
    fn start_path(&self, k: u32, seed: u32, paths: u32, out: &mut PathVpls) {
        let [u_light, u_select, u0, u1] = sobol4(k, LIGHT_DIMENSIONS, seed);
        let [d0, d1, ..] = sobol4(k, EMISSION_DIMENSIONS, seed);
        let (index, p_light) = self.choice.sample(u_light);
        let (source, power) = self.sources[index];
        let scale = 1.0 / (p_light * paths as f32);
        let (origin, dir, power) = match source {
            Source::Area => {
                let Some(y) = self.scene.area_lights().sample(u_select, Vec2::new(u0, u1)) else { return };
                // Φ = L_e cosθ / (p_l p_A (cosθ / π) P): cosine-weighted emission cancels cosθ.
                let power = y.emission * (PI / y.pdf_area) * scale;
                out.surface.push(Vpl::diffuse(y.point, y.normal, power));
                let dir = cosine_hemisphere(y.normal, Vec2::new(d0, d1));
                (offset_ray_origin(y.point, y.normal), dir, power)
            }
            Source::Punctual(index) => {
                let light = &self.lights[index];
                if self.sampled_lights {
                    // Chosen with probability p_l among P paths: the light scaled by
                    // 1 / (p_l P) is its unbiased share of the set's direct light.
                    out.sky.push(light.scaled(scale));
                }
                match *light {
                    Light::Point { position, .. } => {
                        (position, uniform_sphere(Vec2::new(d0, d1)), power * scale)
                    }
                    Light::Spot { position, direction, angle_deg, .. } => {
                        let cone = SpotCone::new(direction, angle_deg);
                        (position, uniform_cone(cone.axis, cone.cos_half, Vec2::new(d0, d1)), power * scale)
                    }
                    Light::Directional { direction, .. } => {
                        let direction = direction.normalize_or_zero();
                        let (centre, radius) = self.sphere;
                        let (t, b) = direction.any_orthonormal_pair();
                        let disc = radius * concentric_disc(Vec2::new(u0, u1));
                        let origin =
                            centre - (1.0 + DISC_MARGIN) * radius * direction + disc.x * t + disc.y * b;
                        (origin, direction, power * scale)
                    }
                }
            }
            Source::Environment => {
                // Light arriving from ω: a direction drawn by the sky's importance (density
                // p_ω) and a point on the disc across ω (density 1/(πR²)), so
                // Φ = L(ω) πR² / (p_ω p_l P).
                let Some(sky) = self.scene.environment().and_then(|e| e.sample(Vec2::new(d0, d1))) else {
                    return;
                };
                let (centre, radius) = self.sphere;
                let (t, b) = sky.dir.any_orthonormal_pair();
                let disc = radius * concentric_disc(Vec2::new(u0, u1));
                let origin = centre + (1.0 + DISC_MARGIN) * radius * sky.dir + disc.x * t + disc.y * b;
                // The sky's direct light: a directional VPL of irradiance Φ / (πR²).
                let irradiance = sky.radiance * (scale / sky.pdf);
                out.sky.push(Light::Directional { direction: -sky.dir, irradiance });
                (origin, -sky.dir, irradiance * (PI * radius * radius))
            }
        };
        self.walk(origin, dir, power, k, seed, &mut out.surface);
    }

    /// Follows a particle of power `power` leaving `origin` along `dir` through at most
    /// `bounces` ([`MAX_BOUNCES`] or fewer) surface interactions, appending a VPL at every
    /// diffuse one.
    fn walk(&self, mut origin: Vec3, mut dir: Vec3, mut power: Vec3, k: u32, seed: u32, vpls: &mut Vec<Vpl>) {
        let scene = self.scene;
        for bounce in 0..self.bounces {
            if !(origin.is_finite() && dir.is_finite() && power.is_finite()) {
                return;
            }
            let hit = scene.accel().intersect(&Ray::new(origin, dir));
            if !hit.is_hit() {
                return;
            }
            let s = scene.surface(&hit);
            // Normals of the side the particle arrives on; the geometric normal decides.
            let ng = if s.geometric_normal.dot(dir) < 0.0 { s.geometric_normal } else { -s.geometric_normal };
            let [u_choice, u_dir0, u_dir1, u_roulette] = sobol4(k, BOUNCE_DIMENSIONS + bounce, seed);
            let params = scene.shade(&s, 0.0);
            let bsdf = Bsdf::new(params, s.geometric_normal);
            let wo = -dir;
            if params.has_non_delta() {
                let n = if params.shading_normal.dot(ng) >= 0.0 {
                    params.shading_normal
                } else {
                    -params.shading_normal
                };
                let lobe = GlossyLobe::new(&params, n, wo).map(GlossyLobe::regularised);
                let ggx = matches!(lobe, Some(GlossyLobe::Ggx { .. }));
                vpls.push(Vpl {
                    position: s.position,
                    normal: n,
                    power: power * params.diffuse,
                    glossy: power * params.glossy,
                    schlick: if ggx { power } else { Vec3::ZERO },
                    lobe,
                });
            }
            let Some(sample) = bsdf.sample(wo, u_choice, Vec2::new(u_dir0, u_dir1)) else { return };
            // Russian roulette on the sample's weight.
            let survive = sample.weight.max_element().min(1.0);
            if survive <= 0.0 || u_roulette >= survive {
                return;
            }
            power *= sample.weight / survive;
            dir = sample.wi;
            // A reflection leaves on the arrival side, a refraction on the other.
            let side = if dir.dot(ng) > 0.0 { ng } else { -ng };
            origin = offset_ray_origin(s.position, side);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Sharing;

    /// Every path is traced once within the span, in disjoint runs in set order, sets differ
    /// by at most one path, and with fixed blocks a frame with one path more changes one set's
    /// paths unless the sets divided the fewer paths evenly.
    #[test]
    fn sharing_paths_one_more_changes_one_set() {
        for sets in [1, 4, 9, 16] {
            for paths in sets..=6 * sets {
                for sharing in [Sharing::Contiguous, Sharing::FixedBlocks] {
                    let shares: Vec<(u32, u32)> = (0..sets).map(|s| sharing.share(paths, sets, s)).collect();
                    assert_eq!(shares.iter().map(|&(_, c)| c).sum::<u32>(), paths);
                    let last = shares.last().unwrap();
                    assert!(last.0 + last.1 <= sharing.span(paths, sets));
                    let counts = shares.iter().map(|s| s.1);
                    let (lo, hi) = (counts.clone().min().unwrap(), counts.max().unwrap());
                    assert!(hi - lo <= 1 && lo > 0, "{sharing:?}: {paths} paths in {sets} sets: {shares:?}");
                    assert!(shares.windows(2).all(|w| w[0].0 + w[0].1 <= w[1].0));
                }
                let share = |paths, s| Sharing::FixedBlocks.share(paths, sets, s);
                let changed = (0..sets).filter(|&s| share(paths, s) != share(paths + 1, s)).count();
                if paths % sets != 0 {
                    assert_eq!(changed, 1, "{paths} → {} paths in {sets} sets", paths + 1);
                }
            }
        }
    }
}
