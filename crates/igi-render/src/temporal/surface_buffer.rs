//! [`SurfaceBuffer`]: what each pixel's centre sees in a posed scene, the geometry that
//! temporal reuse reprojects with (ARCHITECTURE.md, "Temporal reuse while the view moves").
//!
//! It is traced where the history lives (the viewer, or a cluster's rank 0), one closest-hit
//! ray per pixel in 4×2 packets, so no frame source has to send it: a cluster's nodes send the
//! frame's radiance only.

use crate::camera::PinholeCamera;
use crate::prepared::PreparedScene;
use glam::{Affine3A, Vec3};
use igi_bvh::{Hit, INVALID_ID, Ray, RayPacket8};
use igi_simd::M32x8;
use rayon::prelude::*;

/// The surfaces seen through the pixel centres of one frame.
#[derive(Clone, Debug)]
pub struct SurfaceBuffer {
    /// The frame's camera.
    pub camera: PinholeCamera,
    /// Distance from the eye to the surface per pixel, row-major (infinite where the ray
    /// leaves the scene).
    pub distance: Vec<f32>,
    /// The instance seen per pixel ([`INVALID_ID`] where the ray leaves the scene).
    pub instance: Vec<u32>,
    /// Unit geometric normal per pixel, turned toward the eye (zero where the ray leaves the
    /// scene): the side of the surface the pixel shows.
    pub normal: Vec<Vec3>,
    /// Object-to-world transform of every instance in the frame's pose.
    pub transforms: Vec<Affine3A>,
}

impl SurfaceBuffer {
    /// Traces the pixel centres of `camera` in `scene` as it stands now.
    pub fn trace(scene: &PreparedScene, camera: PinholeCamera) -> Self {
        let (w, h) = (camera.width as usize, camera.height as usize);
        let accel = scene.accel();
        let mut distance = vec![f32::INFINITY; w * h];
        let mut instance = vec![INVALID_ID; w * h];
        let mut normal = vec![Vec3::ZERO; w * h];
        // Bands of two rows, traced in 4×2 packets.
        let bands = distance
            .par_chunks_mut(2 * w)
            .zip(instance.par_chunks_mut(2 * w))
            .zip(normal.par_chunks_mut(2 * w));
        bands.enumerate().for_each(|(band, ((distance, instance), normal))| {
            let rows = distance.len() / w;
            for x0 in (0..w).step_by(4) {
                let mut rays = [Ray::new(camera.origin, camera.forward); 8];
                let mut active = 0u32;
                for (lane, ray) in rays.iter_mut().enumerate() {
                    let (x, row) = (x0 + lane % 4, lane / 4);
                    if x < w && row < rows {
                        *ray = camera.ray((x) as u32, (2 * band + row) as u32);
                        active |= 1 << lane;
                    }
                }
                let hits = accel.intersect8(&RayPacket8::from_rays(&rays), M32x8::from_bitmask(active));
                let (t, prim, inst) = (hits.t.to_array(), hits.prim.to_array(), hits.instance.to_array());
                let (u, v) = (hits.u.to_array(), hits.v.to_array());
                for lane in (0..8).filter(|l| active & (1 << l) != 0) {
                    let at = (lane / 4) * w + x0 + lane % 4;
                    if prim[lane] != INVALID_ID as i32 {
                        // Camera directions are unit vectors: t is the distance.
                        distance[at] = t[lane];
                        instance[at] = inst[lane] as u32;
                        let hit = Hit {
                            t: t[lane],
                            u: u[lane],
                            v: v[lane],
                            instance: inst[lane] as u32,
                            prim: prim[lane] as u32,
                        };
                        let n = scene.surface(&hit).geometric_normal;
                        normal[at] = if n.dot(rays[lane].dir) > 0.0 { -n } else { n };
                    }
                }
            }
        });
        let transforms = (0..accel.instance_count() as u32).map(|i| accel.instance_transform(i)).collect();
        Self { camera, distance, instance, normal, transforms }
    }

    /// The world point seen at pixel `(x, y)`, or `None` where the ray left the scene.
    pub fn point(&self, x: u32, y: u32) -> Option<Vec3> {
        let i = y as usize * self.camera.width as usize + x as usize;
        let t = self.distance[i];
        t.is_finite().then(|| self.camera.origin + self.camera.direction(x, y) * t)
    }
}
