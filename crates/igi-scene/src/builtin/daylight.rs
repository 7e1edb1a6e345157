//! The daylight of the generated outdoor scenes (`power-plant`, `maple-tree`): a warm sun and
//! a blue sky, so both are lit alike.

use crate::environment::Environment;
use crate::light::Light;
use crate::model::Scene;
use glam::Vec3;

/// The sun's irradiance on a surface facing it.
const SUN: Vec3 = Vec3::new(7.0, 6.6, 6.0);
/// The sky's radiance.
const SKY: Vec3 = Vec3::new(0.3, 0.42, 0.7);

/// `scene` under the sun, shining along `sun_direction` (normalised here), and the sky.
pub(super) fn outdoors(scene: Scene, sun_direction: Vec3) -> Scene {
    Scene {
        lights: vec![Light::Directional { direction: sun_direction.normalize(), irradiance: SUN }],
        environment: Some(Environment::Constant { radiance: SKY }),
        ..scene
    }
}
