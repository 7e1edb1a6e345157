//! KHR_lights_punctual lights, placed by their nodes.

use glam::{Mat4, Vec3};
use gltf::khr_lights_punctual::Kind;

use super::loader::Loader;
use crate::animation::AnimatedLight;
use crate::light::Light;

impl Loader<'_> {
    /// Adds a KHR_lights_punctual light at the node's world transform; a node that moves
    /// (`moving`) carries it.
    pub(super) fn light(
        &mut self,
        node: &gltf::Node,
        light: gltf::khr_lights_punctual::Light,
        world: Mat4,
        moving: Option<u32>,
    ) {
        let Some(converted) = punctual(&light, world) else {
            self.report.warn(
                self.file,
                format!("nodes[{}]: light with a degenerate transform or intensity skipped", node.index()),
            );
            return;
        };
        self.scene.lights.push(converted);
        if let (Some(carrier), Some(rest)) = (moving, punctual(&light, Mat4::IDENTITY)) {
            self.scene.animation.lights.push(AnimatedLight {
                light: (self.scene.lights.len() - 1) as u32,
                rest,
                node: Some(carrier),
                position: None,
                direction: None,
                power: None,
            });
        }
    }
}

/// A KHR_lights_punctual light placed by `transform`: it sits at the origin of its node and
/// shines down the node's −Z. `None` if the transform or the intensity is degenerate.
fn punctual(light: &gltf::khr_lights_punctual::Light, transform: Mat4) -> Option<Light> {
    let power = Vec3::from(light.color()) * light.intensity();
    if !power.is_finite() {
        return None;
    }
    let position = transform.transform_point3(Vec3::ZERO);
    let direction = transform.transform_vector3(Vec3::NEG_Z).try_normalize();
    match (light.kind(), direction) {
        (Kind::Point, _) => Some(Light::Point { position, intensity: power }),
        (Kind::Spot { outer_cone_angle, .. }, Some(direction)) => Some(Light::Spot {
            position,
            direction,
            angle_deg: 2.0 * outer_cone_angle.clamp(0.0, std::f32::consts::FRAC_PI_2).to_degrees(),
            intensity: power,
        }),
        (Kind::Directional, Some(direction)) => Some(Light::Directional { direction, irradiance: power }),
        _ => None,
    }
}
