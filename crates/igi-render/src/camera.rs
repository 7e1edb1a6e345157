//! The pinhole camera: primary ray directions for pixels, exactly as
//! `../shared/tools/embree-bench/embree_bench.cpp` computes them (so igi and Embree can be
//! compared ray for ray).
//!
//! ```text
//! fwd = normalize(target - position); right = normalize(cross(fwd, up)); up' = cross(right, fwd)
//! sx = (2 (x + 0.5) / W - 1) · tan(fov/2) · W/H;  sy = (1 - 2 (y + 0.5) / H) · tan(fov/2)
//! dir = normalize(fwd + right · sx + up' · sy)        (pixel (0, 0) is the top left)
//! ```
//!
//! All arithmetic is scalar f32 in the same order as the C++ (which is built without FP
//! contraction), so the directions agree bit for bit.

use glam::Vec3;
use igi_bvh::Ray;
use igi_scene::Camera;
use igi_simd::{F32x8, Vec3x8};

/// `a · (1 / |a|)` as the reference code normalises (zero stays zero).
#[inline]
fn normalize(a: Vec3) -> Vec3 {
    let l = (a.x * a.x + a.y * a.y + a.z * a.z).sqrt();
    if l > 0.0 { a * (1.0 / l) } else { a }
}

#[inline]
fn cross(a: Vec3, b: Vec3) -> Vec3 {
    Vec3::new(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x)
}

/// A camera set up for one image size: the orthonormal frame and the screen scale.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PinholeCamera {
    /// Eye position, the origin of every primary ray.
    pub origin: Vec3,
    /// Unit viewing direction.
    pub forward: Vec3,
    /// Unit image +x direction.
    pub right: Vec3,
    /// Unit image +y direction (up on the screen).
    pub up: Vec3,
    /// tan(fov_y / 2).
    pub tan_half: f32,
    /// Width / height.
    pub aspect: f32,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
}

impl PinholeCamera {
    /// The camera `camera` for a `width` × `height` image. If `up` is parallel to the view
    /// direction, another axis (+Z, else +X) stands in for it.
    pub fn new(camera: &Camera, width: u32, height: u32) -> Self {
        let forward = normalize(camera.target - camera.position);
        let mut right = normalize(cross(forward, camera.up));
        if right.length_squared() < 0.5 || !right.is_finite() {
            let alt = if forward.z.abs() < 0.9 { Vec3::Z } else { Vec3::X };
            right = normalize(cross(forward, alt));
        }
        let up = cross(right, forward);
        let tan_half = (0.5 * camera.fov_y_deg * std::f32::consts::PI / 180.0).tan();
        Self {
            origin: camera.position,
            forward,
            right,
            up,
            tan_half,
            aspect: width as f32 / height as f32,
            width,
            height,
        }
    }

    /// Unit direction through the point `(x + dx, y + dy)` of the image plane, in pixel
    /// units from the top-left corner; `dx = dy = 0.5` is the pixel centre. For
    /// anti-aliasing, `(dx, dy)` ranges over [0, 1)².
    #[inline]
    pub fn direction_at(&self, x: u32, y: u32, dx: f32, dy: f32) -> Vec3 {
        let (w, h) = (self.width as f32, self.height as f32);
        let sx = (2.0 * (x as f32 + dx) / w - 1.0) * self.tan_half * self.aspect;
        let sy = (1.0 - 2.0 * (y as f32 + dy) / h) * self.tan_half;
        normalize(self.forward + self.right * sx + self.up * sy)
    }

    /// [`PinholeCamera::direction_at`] of eight points at once, lane by lane: the same
    /// operations in the same order on eight lanes, so every lane equals the scalar direction
    /// bit for bit (primary rays stay embree-bench's rays).
    #[inline]
    pub fn directions_at8(&self, x: [u32; 8], y: [u32; 8], dx: [f32; 8], dy: [f32; 8]) -> Vec3x8 {
        let f = |v: [u32; 8]| F32x8::from_array(v.map(|v| v as f32));
        let (x, y, dx, dy) = (f(x), f(y), F32x8::from_array(dx), F32x8::from_array(dy));
        let s = F32x8::splat;
        let (w, h) = (s(self.width as f32), s(self.height as f32));
        let sx = (s(2.0) * (x + dx) / w - s(1.0)) * s(self.tan_half) * s(self.aspect);
        let sy = (s(1.0) - s(2.0) * (y + dy) / h) * s(self.tan_half);
        let axis = |a: usize| s(self.forward[a]) + s(self.right[a]) * sx + s(self.up[a]) * sy;
        let v = Vec3x8::new(axis(0), axis(1), axis(2));
        // `normalize`: a · (1 / |a|), zero staying zero.
        let l = (v.x * v.x + v.y * v.y + v.z * v.z).sqrt();
        let inv = s(1.0) / l;
        let keep = l.gt(F32x8::ZERO);
        let scaled = |c: F32x8| F32x8::select(keep, c * inv, c);
        Vec3x8::new(scaled(v.x), scaled(v.y), scaled(v.z))
    }

    /// The image point, in pixel units from the top-left corner, where `point` appears: the
    /// inverse of [`PinholeCamera::direction_at`]. `None` for a point not in front of the eye.
    pub fn project(&self, point: Vec3) -> Option<glam::Vec2> {
        let v = point - self.origin;
        let z = v.dot(self.forward);
        if z.is_nan() || z <= 0.0 {
            return None;
        }
        let sx = v.dot(self.right) / (z * self.tan_half * self.aspect);
        let sy = v.dot(self.up) / (z * self.tan_half);
        let (w, h) = (self.width as f32, self.height as f32);
        Some(glam::Vec2::new(0.5 * (sx + 1.0) * w, 0.5 * (1.0 - sy) * h))
    }

    /// Unit direction through the centre of pixel `(x, y)`.
    #[inline]
    pub fn direction(&self, x: u32, y: u32) -> Vec3 {
        self.direction_at(x, y, 0.5, 0.5)
    }

    /// The primary ray through the centre of pixel `(x, y)`, over `[0, inf)`.
    #[inline]
    pub fn ray(&self, x: u32, y: u32) -> Ray {
        Ray::new(self.origin, self.direction(x, y))
    }

    /// The primary ray through the sub-pixel point `(x + dx, y + dy)`.
    #[inline]
    pub fn ray_at(&self, x: u32, y: u32, dx: f32, dy: f32) -> Ray {
        Ray::new(self.origin, self.direction_at(x, y, dx, dy))
    }
}
