//! The scene's cameras: every perspective camera met in the node hierarchy is a view, named
//! by the camera (else its node, else its index); the first is the scene's camera.

use glam::{Mat4, Vec3};

use super::loader::Loader;
use crate::model::{Camera, SavedView};

impl Loader<'_> {
    /// Adds the node's camera to the views, and takes it as the scene's if it is the first
    /// perspective one. Cameras do not move, so a camera on a moving node (`moving`) stays at
    /// rest.
    pub(super) fn camera(
        &mut self,
        node: &gltf::Node,
        camera: gltf::Camera,
        world: Mat4,
        moving: Option<u32>,
    ) {
        let gltf::camera::Projection::Perspective(perspective) = camera.projection() else {
            self.report.warn(self.file, format!("nodes[{}]: orthographic camera skipped", node.index()));
            return;
        };
        let position = world.transform_point3(Vec3::ZERO);
        let forward = world.transform_vector3(Vec3::NEG_Z).try_normalize();
        let up = world.transform_vector3(Vec3::Y).try_normalize();
        let fov_y_deg = perspective.yfov().to_degrees();
        match (forward, up) {
            (Some(forward), Some(up)) if fov_y_deg > 0.0 && fov_y_deg < 180.0 => {
                let view = Camera { position, target: position + forward, up, fov_y_deg };
                self.scene.camera.get_or_insert(view);
                let name = camera
                    .name()
                    .or(node.name())
                    .filter(|n| !n.trim().is_empty())
                    .map_or_else(|| format!("camera {}", camera.index()), str::to_string);
                let name = SavedView::free_name(&self.scene.views, name);
                self.scene.views.push(SavedView { name, camera: view });
                if moving.is_some() {
                    self.report.warn(
                        self.file,
                        format!(
                            "nodes[{}]: the camera does not follow the animation; it stays at rest",
                            node.index()
                        ),
                    );
                }
            }
            _ => self.report.warn(self.file, format!("nodes[{}]: degenerate camera skipped", node.index())),
        }
    }
}
