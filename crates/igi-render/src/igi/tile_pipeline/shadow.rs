//! Step 4 of the tile pipeline ([`super`]): each shading point lit by the lights, sky VPLs
//! and VPLs of its set, through shadow packets and the BRDF shaders ([`crate::igi::vpl_lighting`]).

use super::{COMPENSATION, COMPENSATION_VPL_STRIDE, PathState, ShadingPoint, TilePipeline, TileScratch};
use crate::igi::vpl_lighting::Receivers;
use crate::image::pixel_rect::PixelRect;
use crate::image::stats::RayCounts;
use crate::sampling::{hash_combine, pixel_seed};
use glam::Vec3;

impl TilePipeline<'_> {
    /// Step 4: the lights and the VPLs on the shading points of fine set `fine` from index
    /// `first` on, each point lit by the set of its pixel's coarse group
    /// ([`Interleave::set`]), with its share of the set's VPLs ([`TilePipeline::vpl_share`]):
    /// each pixel uses each VPL of its set once. The exact lights light every point with
    /// weight 1.
    pub(super) fn light(
        &self,
        region: &PixelRect,
        fine: u32,
        first: usize,
        s: &mut TileScratch,
        rays: &mut RayCounts,
    ) {
        let TileScratch { points, receivers, order, sample_origins, .. } = s;
        // The lighting group of a point: its set, then the share of the set's VPLs that
        // lights it ([`TilePipeline::vpl_share`]).
        let group = |p: &ShadingPoint| {
            let (x, y) = region.pixel(p.state.pixel);
            let (skip, step) = self.vpl_share(&p.state, x, y);
            u64::from(self.interleave.set(fine, x, y)) << 32 | u64::from(step) << 16 | u64::from(skip)
        };
        order.clear();
        order.extend((first..points.len()).map(|i| (group(&points[i]), i as u32)));
        // Stable: each group keeps the pixel order its shadow packets want.
        order.sort_by_key(|&(g, _)| g);
        let accel = self.scene.accel();
        for run in order.chunk_by(|a, b| a.0 == b.0) {
            let set = (run[0].0 >> 32) as u32;
            let (skip, step) = ((run[0].0 & 0xffff) as usize, (run[0].0 >> 16 & 0xffff) as usize);
            let weight = step as f32;
            if !self.vpls.lights().is_empty() {
                self.light_exactly(points, run, sample_origins, receivers, rays);
            }
            receivers.clear();
            for &(_, i) in run {
                let p = &points[i as usize];
                let (x, y) = region.pixel(p.state.pixel);
                let frame = pixel_seed(x, y, self.roulette_seed);
                let seed = hash_combine(hash_combine(frame, p.state.sample), p.state.path);
                receivers.push((p.origin, seed), p.ns, p.ng, p.lobe);
            }
            receivers.regularise();
            let sky = self.vpls.sky(set).iter().skip(skip).step_by(step);
            receivers.add_lights(accel, sky, weight, rays);
            let vpls = self.vpls.set(set).iter().skip(skip).step_by(step);
            receivers.add_vpls(accel, vpls, weight, self.d_min2, self.roulette, rays);
            for (k, &(_, i)) in run.iter().enumerate() {
                let p = &mut points[i as usize];
                let (d, g, schlick) = receivers.radiance(k);
                (p.diffuse_radiance, p.glossy_radiance) = (d, [g, schlick]);
            }
        }
    }

    /// The share of its set's VPLs that lights a point of pixel (x, y): the VPLs `skip`,
    /// `skip + step`, `skip + 2·step`, … each weighted by `step`. A point that stands for its
    /// whole pixel takes all of them, a point of sample j of an edge pixel every N-th from j
    /// (paper 3.3). A point of the bias compensation takes every
    /// [`COMPENSATION_VPL_STRIDE`]-th of its camera sample's share, starting at an offset
    /// drawn per pixel and frame: its light is one short ray's estimate that the filter
    /// averages over the neighbours anyway, and lighting it with every VPL would cost as
    /// many shadow rays as the camera's own point.
    pub(super) fn vpl_share(&self, state: &PathState, x: u32, y: u32) -> (u32, u32) {
        let aa = self.interleave.aa;
        let (skip, step) = if state.coverage == aa { (0, 1) } else { (state.sample, aa) };
        if state.path & COMPENSATION == 0 {
            return (skip, step);
        }
        let offset = hash_combine(pixel_seed(x, y, self.sequence.seed), !self.sequence.first)
            % COMPENSATION_VPL_STRIDE;
        (skip + step * offset, step * COMPENSATION_VPL_STRIDE)
    }

    /// The light of the exact lights (point, spot, directional) reflected at the points
    /// `run` of `points`; a whole pixel's point is lit from each of its samples' positions
    /// ([`ShadingPoint::sample_origins`]) and takes their mean, so a hard shadow's edge across
    /// the pixel stays anti-aliased.
    pub(super) fn light_exactly(
        &self,
        points: &mut [ShadingPoint],
        run: &[(u64, u32)],
        sample_origins: &[Vec3],
        receivers: &mut Receivers,
        rays: &mut RayCounts,
    ) {
        let aa = self.interleave.aa as usize;
        let origins = |p: &ShadingPoint| match p.sample_origins {
            Some(at) => at as usize..at as usize + aa,
            None => 0..1,
        };
        let origin = |p: &ShadingPoint, k: usize| match p.sample_origins {
            Some(_) => sample_origins[k],
            None => p.origin,
        };
        receivers.clear();
        for &(_, i) in run {
            let p = &points[i as usize];
            for k in origins(p) {
                // The exact lights' rays are all traced: no roulette seed.
                receivers.push((origin(p, k), 0), p.ns, p.ng, p.lobe);
            }
        }
        receivers.add_lights(self.scene.accel(), self.vpls.lights().iter(), 1.0, rays);
        let mut k = 0;
        for &(_, i) in run {
            let p = &mut points[i as usize];
            let n = origins(p).len();
            let (mut diffuse, mut glossy) = (Vec3::ZERO, Vec3::ZERO);
            for _ in 0..n {
                let (d, g, schlick) = receivers.radiance(k);
                diffuse += p.albedo * d;
                glossy += p.glossy * g + schlick;
                k += 1;
            }
            p.exact = [diffuse / n as f32, glossy / n as f32];
        }
    }
}
