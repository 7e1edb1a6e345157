//! [`ViewImportance`]: which VPLs can light what the camera sees, and with what probability a
//! frame keeps the others.
//!
//! Light paths start where the lights' power is (see [`crate::igi::vpl`]), not where the camera
//! looks. Where light enters through an opening, most of them leave their VPLs where no
//! visible point can see them: the sun and the sky of Sponza's atrium send their paths through
//! a disc across the whole model, and nine in ten end on the outside of the roof or under the
//! floor. A frame of V VPLs per pixel then lights the view with a handful; one frame (what a
//! viewer shows after every camera move) has black shadows and is much darker than the mean
//! of many frames that a still view shows.
//!
//! So a frame keeps VPLs by their importance to the view (Georgiev & Slusallek 2010, "Simple
//! and Robust Iterative Importance Sampling of Virtual Point Lights", with the visibility
//! from the view as the importance): a VPL that a point of a coarse grid of camera
//! hits sees is kept; any other is kept with probability [`UNSEEN_ACCEPTANCE`] and its power
//! divided by it, so every VPL keeps its expected contribution and the estimate stays
//! unbiased (a grid point stands for the pixels around it, which may see a VPL it does not).
//! The frame then starts as many more paths as it takes to keep V VPLs per set ([`crate::igi::vpl`],
//! "Paths per set"), so a frame's VPLs light what the camera sees. Where the camera sees
//! every VPL, as in the Cornell box, all are kept and nothing changes.

use crate::camera::PinholeCamera;
use crate::frame::FrameState;
use crate::prepared::PreparedScene;
use crate::prepared::lights::SHADOW_SHORTEN;
use glam::Vec3;
use igi_bvh::{Accel, Ray, offset_ray_origin};
use igi_shade::brdf::dielectric::{Interface, glass_exit_side, reflect, refract};

/// The probability of keeping a VPL that no point of the grid sees. The smaller, the less of
/// a frame's VPLs go where the camera does not look; the larger, the less a kept one that
/// lights pixels between the grid points stands out (it carries 1/p times a path's power).
pub const UNSEEN_ACCEPTANCE: f32 = 1.0 / 16.0;

/// Columns of the grid of camera rays (its rows follow the image's aspect ratio).
const GRID_COLUMNS: u32 = 16;
/// Most mirror and glass bounces a grid ray follows: glass splits every ray in two.
const MAX_SPECULAR_BOUNCES: u32 = 4;

/// A point the camera sees: the offset origin of rays from it and the normal of its visible
/// side.
#[derive(Clone, Copy, Debug)]
struct ViewPoint {
    origin: Vec3,
    normal: Vec3,
}

/// The points a frame's camera sees on a coarse grid, which decide the probability of keeping
/// a VPL.
#[derive(Clone, Debug, Default)]
pub struct ViewImportance {
    points: Vec<ViewPoint>,
}

impl ViewImportance {
    /// The points the camera sees through the centres of `frame`'s grid cells (at most
    /// [`GRID_COLUMNS`] columns): each ray's first hit with a diffuse or glossy lobe, and
    /// through mirrors and glass the points they show, up to [`MAX_SPECULAR_BOUNCES`]
    /// reflections and refractions (the camera paths of `TilePipeline` follow the same lobes).
    pub fn new(scene: &PreparedScene, frame: &FrameState) -> Self {
        let (width, height) = (frame.settings.width.max(1), frame.settings.height.max(1));
        let camera = PinholeCamera::new(&frame.camera, width, height);
        let columns = GRID_COLUMNS.min(width);
        let rows = ((columns as f32 * height as f32 / width as f32).round() as u32).clamp(1, height);
        let bounces = frame.settings.specular_bounces.min(MAX_SPECULAR_BOUNCES);
        let mut points = Vec::with_capacity((columns * rows) as usize);
        let mut rays = Vec::new();
        for row in 0..rows {
            for column in 0..columns {
                let x = ((2 * column + 1) * width / (2 * columns)).min(width - 1);
                let y = ((2 * row + 1) * height / (2 * rows)).min(height - 1);
                rays.push((camera.ray(x, y), 0));
                while let Some((ray, bounce)) = rays.pop() {
                    let hit = scene.accel().intersect(&ray);
                    if !hit.is_hit() {
                        continue;
                    }
                    let surface = scene.surface(&hit);
                    let params = scene.shade(&surface, 0.0);
                    let dir = ray.dir.normalize();
                    let ng = surface.geometric_normal;
                    let facing = if ng.dot(dir) < 0.0 { ng } else { -ng };
                    if params.has_non_delta() && facing.is_finite() {
                        points.push(ViewPoint {
                            origin: offset_ray_origin(surface.position, facing),
                            normal: facing,
                        });
                    }
                    if bounce == bounces {
                        continue;
                    }
                    if params.mirror.max_element() > 0.0 {
                        let ns =
                            if ng.dot(dir) < 0.0 { params.shading_normal } else { -params.shading_normal };
                        let reflected = reflect(dir, ns);
                        if reflected.dot(facing) > 0.0 {
                            rays.push((
                                Ray::new(offset_ray_origin(surface.position, facing), reflected),
                                bounce + 1,
                            ));
                        }
                    }
                    if params.glass > 0.0 {
                        let interface = Interface::new(dir, params.shading_normal, params.ior);
                        let reflected = reflect(dir, interface.normal);
                        let refracted = refract(dir, interface.normal, interface.eta);
                        let continuations = [(Some(reflected), true), (refracted, false)];
                        for (out, reflection) in continuations {
                            let Some(out) = out else { continue };
                            if let Some(side) = glass_exit_side(dir, out, ng, reflection) {
                                rays.push((
                                    Ray::new(offset_ray_origin(surface.position, side), out),
                                    bounce + 1,
                                ));
                            }
                        }
                    }
                }
            }
        }
        Self { points }
    }

    /// The probability of keeping a surface VPL at `position` emitting on the side of
    /// `normal`: 1 if a grid point sees it, else [`UNSEEN_ACCEPTANCE`] (1 when the camera sees
    /// nothing at all: no VPL matters then).
    pub fn surface_acceptance(&self, accel: &Accel, position: Vec3, normal: Vec3) -> f32 {
        let seen = self.points.iter().any(|p| {
            let to_vpl = position - p.origin;
            p.normal.dot(to_vpl) > 0.0
                && normal.dot(to_vpl) < 0.0
                && !accel.occluded(&Ray { origin: p.origin, dir: to_vpl, tnear: 0.0, tfar: SHADOW_SHORTEN })
        });
        self.acceptance(seen)
    }

    /// The probability of keeping a sky VPL whose light travels along `direction`: 1 if it
    /// reaches a grid point unoccluded, else [`UNSEEN_ACCEPTANCE`].
    pub fn sky_acceptance(&self, accel: &Accel, direction: Vec3) -> f32 {
        let seen = self
            .points
            .iter()
            .any(|p| p.normal.dot(direction) < 0.0 && !accel.occluded(&Ray::new(p.origin, -direction)));
        self.acceptance(seen)
    }

    fn acceptance(&self, seen: bool) -> f32 {
        if seen || self.points.is_empty() { 1.0 } else { UNSEEN_ACCEPTANCE }
    }
}
