//! The shading of queued hits (step 2 of the tile pipeline, [`super`]: surface shaders, paper
//! 3.2) and step 3, the specular streams: mirror and glass rays traced bounce by bounce as
//! packets.

use super::{COMPENSATION, PathState, PendingHit, ShadingPoint, SpecularRay, TilePipeline, TileScratch};
use crate::igi::packet::Packet8;
use crate::igi::vpl_lighting::GlossyLobe;
use crate::image::stats::RayCounts;
use glam::Vec3;
use igi_bvh::{Hit, Ray, offset_ray_origin};
use igi_shade::BrdfParams;
use igi_shade::brdf::dielectric::{Interface, glass_exit_side, reflect, refract};

impl TilePipeline<'_> {
    /// Step 3: the specular stream, bounce by bounce: the rays queued by the previous step
    /// are traced as packets and shaded, which queues the next bounce.
    pub(super) fn trace_specular(&self, s: &mut TileScratch, rays: &mut RayCounts) {
        let accel = self.scene.accel();
        loop {
            std::mem::swap(&mut s.stream, &mut s.next_stream);
            if s.stream.is_empty() {
                return;
            }
            let stream = std::mem::take(&mut s.stream);
            for chunk in stream.chunks(8) {
                let mut packet = Packet8::new();
                for (lane, r) in chunk.iter().enumerate() {
                    packet.set(lane, r.ray);
                }
                rays.specular += u64::from(packet.len());
                let traced = packet.intersect(accel);
                for (r, hit) in chunk.iter().zip(&traced.hits) {
                    if hit.is_hit() {
                        self.queue_hit(r.ray.dir, hit, r.state, s);
                    } else {
                        let sky =
                            r.state.coverage as f32 * r.state.throughput * self.scene.background(r.ray.dir);
                        s.emitted[(r.state.pixel * self.interleave.aa + r.state.sample) as usize] += sky;
                    }
                }
            }
            s.stream = stream;
            s.stream.clear();
            self.shade_queued(s);
        }
    }

    /// Queues `hit` of a ray in unit direction `dir` for [`TilePipeline::shade_queued`], or,
    /// where its material's parameters are the same at every hit (a constant material),
    /// scatters it at once.
    pub(super) fn queue_hit(&self, dir: Vec3, hit: &Hit, state: PathState, s: &mut TileScratch) {
        let hit = PendingHit { state, dir, t: hit.t, surface: self.scene.surface(hit), whole_pixel: None };
        self.queue(hit, s);
    }

    /// Queues a hit whose surface is known (see [`TilePipeline::queue_hit`]).
    pub(super) fn queue(&self, hit: PendingHit, s: &mut TileScratch) {
        match self.scene.uniform_shading(&hit.surface) {
            Some(params) => self.scatter(&hit, &params, s),
            None => s.pending.push(hit),
        }
    }

    /// Runs the surface shaders over the queued hits, up to eight consecutive hits of one
    /// material at a time, and turns each hit into what its BRDF asks for
    /// ([`TilePipeline::scatter`]). Hits stay in the order they were queued: neighbouring
    /// pixels, whose runs of one material are long, and which the shadow packets want
    /// together.
    pub(super) fn shade_queued(&self, s: &mut TileScratch) {
        let pending = std::mem::take(&mut s.pending);
        let mut out = [BrdfParams::black(Vec3::Z); 8];
        let mut start = 0;
        while start < pending.len() {
            let material = pending[start].surface.material;
            let run = pending[start..].iter().take(8).take_while(|p| p.surface.material == material).count();
            let batch = &pending[start..start + run];
            let point = |lane: usize| {
                let p = &batch[lane];
                (&p.surface, (p.state.depth + p.t) * self.pixel_angle)
            };
            self.scene.shade8(material, run, point, &mut out);
            for (p, b) in batch.iter().zip(&out) {
                self.scatter(p, b, s);
            }
            start += run;
        }
        s.pending = pending;
        s.pending.clear();
    }

    /// What a shaded hit becomes: emission seen, a shading point for its diffuse and glossy
    /// lobes, and the reflection and refraction rays of its mirror and glass lobes (into the
    /// next stream).
    pub(super) fn scatter(&self, hit: &PendingHit, b: &BrdfParams, s: &mut TileScratch) {
        let (sp, dir, state) = (&hit.surface, hit.dir, hit.state);
        let front = sp.geometric_normal.dot(dir) < 0.0;
        let (ng, ns) = if front {
            (sp.geometric_normal, b.shading_normal)
        } else {
            (-sp.geometric_normal, -b.shading_normal)
        };
        if front && b.emission.max_element() > 0.0 {
            if state.path & COMPENSATION != 0 {
                s.points[state.root as usize].compensation += state.throughput * b.emission;
            } else {
                s.emitted[(state.pixel * self.interleave.aa + state.sample) as usize] +=
                    state.coverage as f32 * state.throughput * b.emission;
            }
        }
        let depth = state.depth + hit.t;
        if let Some(w) = hit.whole_pixel.filter(|_| b.mirror.max_element() > 0.0 || b.glass > 0.0) {
            s.split.push(w);
            return;
        }
        let sample_origins = hit.whole_pixel.and_then(|w| w.sample_origins);
        if let Some(at) = sample_origins {
            let at = at as usize;
            for o in &mut s.sample_origins[at..at + self.interleave.aa as usize] {
                *o = offset_ray_origin(*o, ng);
            }
        }
        if b.has_non_delta() {
            s.points.push(ShadingPoint {
                state,
                origin: offset_ray_origin(sp.position, ng),
                ns,
                ng,
                depth,
                material: sp.material,
                albedo: b.diffuse,
                glossy: b.glossy,
                lobe: GlossyLobe::new(b, ns, -dir),
                diffuse_radiance: Vec3::ZERO,
                glossy_radiance: [Vec3::ZERO; 2],
                exact: [Vec3::ZERO; 2],
                compensation: Vec3::ZERO,
                sample_origins,
            });
        }
        if state.bounces >= self.specular_bounces {
            return;
        }
        if b.mirror.max_element() > 0.0 {
            // About the shading normal; a reflection that an interpolated normal sends
            // below the surface ends the path (as in the VPL walk and the path tracer).
            let dir = reflect(dir, ns);
            if dir.dot(ng) > 0.0 {
                self.continue_path(state, 0, b.mirror, depth, offset_ray_origin(sp.position, ng), dir, s);
            }
        }
        if b.glass > 0.0 {
            // About the shading normal; a continuation that a bent normal sends to the
            // wrong side of the geometric surface ends (as in the walk and path tracer).
            let interface = Interface::new(dir, b.shading_normal, b.ior);
            let n = interface.normal;
            let f = interface.reflectance;
            let ng = sp.geometric_normal;
            let reflected = reflect(dir, n);
            if let Some(side) = glass_exit_side(dir, reflected, ng, true) {
                let origin = offset_ray_origin(sp.position, side);
                self.continue_path(state, 0, Vec3::splat(b.glass * f), depth, origin, reflected, s);
            }
            let refracted =
                refract(dir, n, interface.eta).and_then(|t| Some((t, glass_exit_side(dir, t, ng, false)?)));
            if let Some((t, side)) = refracted {
                let origin = offset_ray_origin(sp.position, side);
                self.continue_path(state, 1, Vec3::splat(b.glass * (1.0 - f)), depth, origin, t, s);
            }
        }
    }

    /// Queues the continuation of a camera path through a specular bounce.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn continue_path(
        &self,
        state: PathState,
        branch: u32,
        weight: Vec3,
        depth: f32,
        origin: Vec3,
        dir: Vec3,
        s: &mut TileScratch,
    ) {
        let throughput = state.throughput * weight;
        if throughput.max_element() < MIN_SPECULAR_THROUGHPUT
            || !dir.is_finite()
            || s.next_stream.len() >= MAX_SPECULAR_STREAM
        {
            return;
        }
        s.next_stream.push(SpecularRay {
            state: PathState {
                path: state.path << 1 | branch,
                throughput,
                depth,
                bounces: state.bounces + 1,
                ..state
            },
            ray: Ray::new(origin, dir),
        });
    }
}

/// Specular chains carrying less than this (per channel, relative to the camera ray) end: glass
/// splits every ray in two, and without a floor the branches of weak internal reflections
/// would grow as 2^bounces. Two glass reflections (0.04² at normal incidence) still pass.
const MIN_SPECULAR_THROUGHPUT: f32 = 1e-3;

/// Largest number of rays in one bounce of a set's specular stream (a memory bound for
/// pathological scenes; ordinary mirrors and glass stay far below it).
const MAX_SPECULAR_STREAM: usize = 1 << 18;
