//! The scene's camera: the first perspective camera met in the node hierarchy.

use glam::{Mat4, Vec3};

use super::loader::Loader;
use crate::model::Camera;

impl Loader<'_> {
    /// Takes the node's camera as the scene's if it is the first perspective one. The scene's
    /// camera does not move, so a camera on a moving node (`moving`) stays at rest.
    pub(super) fn camera(
        &mut self,
        node: &gltf::Node,
        camera: gltf::Camera,
        world: Mat4,
        moving: Option<u32>,
    ) {
        if self.scene.camera.is_some() {
            return;
        }
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
                self.scene.camera = Some(Camera { position, target: position + forward, up, fov_y_deg });
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
