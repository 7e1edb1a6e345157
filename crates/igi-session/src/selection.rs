//! [`Selection`]: the object or light a viewer's user picked, by name, with its outline on the
//! image, which the viewers draw over the frame: for an object, the edges of its oriented
//! bounding box (the mesh's object-space bounds under the instance's transform, as Blender
//! draws an object's bounds); for a point or spot light, a marker around where it is.

use crate::light_control::LightControl;
use glam::{Affine3A, Vec2, Vec3};
use igi_bvh::Aabb;
use igi_render::{PinholeCamera, PreparedScene};
use serde::Serialize;

/// Distance in front of the eye at which outline edges are clipped: an edge passing behind
/// the eye is drawn up to where it leaves the view frustum's near side.
const NEAR: f32 = 1e-4;

/// Half the size of a light's marker, pixels.
const MARKER: f32 = 8.0;

/// The selected object or light of a frame.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Selection {
    /// The selected instance, if an object is selected.
    pub instance: Option<u32>,
    /// The selected light source's index in [`crate::FrameStats::lights`], if a light is.
    pub light: Option<usize>,
    /// An object's mesh name from the scene's file (`instance N` for a mesh without one), or
    /// the light's name.
    pub name: String,
    /// Its bounding box's edges seen through the frame's camera, as line segments
    /// `[x0, y0, x1, y1]` in pixels of the image (from the top-left corner; they may reach
    /// beyond the image).
    pub outline: Vec<[f32; 4]>,
}

impl Selection {
    /// Light source `index` of `lights` in `scene`'s current pose, seen through `camera`.
    pub fn of_light(
        scene: &PreparedScene,
        lights: &[LightControl],
        index: usize,
        camera: &PinholeCamera,
    ) -> Self {
        let light = &lights[index];
        let outline = light
            .position(scene)
            .and_then(|p| camera.project(p))
            .map(|c| {
                // A diamond and a cross through it.
                let (x, y, r) = (c.x, c.y, MARKER);
                vec![
                    [x - r, y, x, y - r],
                    [x, y - r, x + r, y],
                    [x + r, y, x, y + r],
                    [x, y + r, x - r, y],
                    [x - r, y, x + r, y],
                    [x, y - r, x, y + r],
                ]
            })
            .unwrap_or_default();
        Self { instance: None, light: Some(index), name: light.name.clone(), outline }
    }

    /// Instance `instance` of `scene` in its current pose, seen through `camera`.
    pub fn of_instance(scene: &PreparedScene, instance: u32, camera: &PinholeCamera) -> Self {
        let accel = scene.accel();
        let mesh = accel.instance_mesh(instance);
        let name = match scene.meshes().get(mesh as usize).map(|m| m.name.as_str()) {
            Some(name) if !name.is_empty() => name.to_string(),
            _ => format!("instance {instance}"),
        };
        let outline = box_outline(accel.mesh_bounds(mesh), accel.instance_transform(instance), camera);
        Self { instance: Some(instance), light: None, name, outline }
    }
}

/// The twelve edges of `bounds` under `to_world`, projected by `camera`; the parts behind the
/// eye are clipped away.
fn box_outline(bounds: Aabb, to_world: Affine3A, camera: &PinholeCamera) -> Vec<[f32; 4]> {
    if !(bounds.min.is_finite() && bounds.max.is_finite()) || bounds.min.cmpgt(bounds.max).any() {
        return Vec::new();
    }
    let corner = |i: usize| {
        let pick = |bit: usize, axis: usize| if i & bit != 0 { bounds.max[axis] } else { bounds.min[axis] };
        to_world.transform_point3(Vec3::new(pick(1, 0), pick(2, 1), pick(4, 2)))
    };
    // Corners i and i | bit differ along one axis: those pairs are the edges.
    let edges =
        (0..8).flat_map(|i| [1, 2, 4].into_iter().filter(move |&b| i & b == 0).map(move |b| (i, i | b)));
    edges
        .filter_map(|(a, b)| {
            let (a, b) = clip_to_near(corner(a), corner(b), camera)?;
            let (a, b): (Vec2, Vec2) = (camera.project(a)?, camera.project(b)?);
            Some([a.x, a.y, b.x, b.y])
        })
        .collect()
}

/// The part of segment `a`–`b` at least [`NEAR`] in front of the eye, if any.
fn clip_to_near(a: Vec3, b: Vec3, camera: &PinholeCamera) -> Option<(Vec3, Vec3)> {
    let depth = |p: Vec3| (p - camera.origin).dot(camera.forward) - NEAR;
    let (da, db) = (depth(a), depth(b));
    match (da > 0.0, db > 0.0) {
        (true, true) => Some((a, b)),
        (false, false) => None,
        // The point where the depth crosses zero replaces the end behind.
        (true, false) => Some((a, a + (b - a) * (da / (da - db)))),
        (false, true) => Some((b + (a - b) * (db / (db - da)), b)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use igi_scene::Camera;

    fn camera() -> PinholeCamera {
        let camera =
            Camera { position: Vec3::new(0.0, 0.0, 5.0), target: Vec3::ZERO, up: Vec3::Y, fov_y_deg: 40.0 };
        PinholeCamera::new(&camera, 200, 100)
    }

    #[test]
    fn a_box_in_view_has_twelve_edges_around_its_centre() {
        let unit = Aabb { min: Vec3::splat(-0.5), max: Vec3::splat(0.5) };
        let outline = box_outline(unit, Affine3A::from_translation(Vec3::new(1.0, 0.0, 0.0)), &camera());
        assert_eq!(outline.len(), 12);
        let centre = camera().project(Vec3::new(1.0, 0.0, 0.0)).unwrap();
        let xs = outline.iter().flat_map(|e| [e[0], e[2]]);
        let ys = outline.iter().flat_map(|e| [e[1], e[3]]);
        let (x0, x1) = xs.fold((f32::MAX, f32::MIN), |(lo, hi), x| (lo.min(x), hi.max(x)));
        let (y0, y1) = ys.fold((f32::MAX, f32::MIN), |(lo, hi), y| (lo.min(y), hi.max(y)));
        assert!(x0 < centre.x && centre.x < x1 && y0 < centre.y && centre.y < y1);
        // The front face (z = 0.5, 4.5 from the eye) spans 1 / (4.5 · tan 20°) of half the
        // image height: 30.5 pixels of 100.
        let front = 100.0 / (4.5 * 20f32.to_radians().tan()) / 2.0;
        assert!((y1 - y0 - front).abs() < 0.1, "{} against {front}", y1 - y0);
    }

    #[test]
    fn edges_behind_the_eye_are_clipped_or_dropped() {
        // A long box through the eye: its edges along z keep their parts in front.
        let rod = Aabb { min: Vec3::new(-0.1, -0.1, -10.0), max: Vec3::new(0.1, 0.1, 10.0) };
        let outline = box_outline(rod, Affine3A::IDENTITY, &camera());
        assert_eq!(outline.len(), 4 + 4, "4 edges along z and the far face's 4; the near face is behind");
        assert!(outline.iter().flatten().all(|v| v.is_finite()));
        assert!(box_outline(Aabb::EMPTY, Affine3A::IDENTITY, &camera()).is_empty());
        let behind = Aabb { min: Vec3::new(-1.0, -1.0, 6.0), max: Vec3::new(1.0, 1.0, 7.0) };
        assert!(box_outline(behind, Affine3A::IDENTITY, &camera()).is_empty());
    }
}
