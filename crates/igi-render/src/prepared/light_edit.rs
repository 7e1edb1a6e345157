//! [`LightEdit`]: a viewer's change to one of the scene's light sources, part of a frame's
//! [`crate::ScenePose`] so that every render node applies it alike.
//!
//! A light source is a punctual light of the scene ([`LightId::Punctual`]: point, spot or
//! directional) or an emissive material ([`LightId::Emissive`]: its area lights, the triangles
//! that carry it, wherever they are). An edit scales the emitted power per colour channel and
//! moves a punctual light by a world transform: a point or spot light's position and
//! direction, a directional light's direction. Emissive surfaces move with their instance
//! (`ScenePose::moved`). Edits apply after the animation's pose, as object moves do.

use glam::{Affine3A, Vec3};
use igi_scene::Light;
use serde::{Deserialize, Serialize};

/// Which light source an edit changes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
pub enum LightId {
    /// The scene's punctual light of this index ([`crate::PreparedScene::lights`]).
    Punctual(u32),
    /// The emissive material of this index: every triangle that carries it.
    Emissive(u32),
}

/// A change to one light source.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LightEdit {
    /// The source.
    pub light: LightId,
    /// Factor on its emitted power per channel (intensity, irradiance or emitted radiance):
    /// 1 as loaded, 0 off.
    pub power: Vec3,
    /// Extra world transform of a punctual light (applied to its position and direction);
    /// ignored for an emissive material.
    pub transform: Affine3A,
}

impl LightEdit {
    /// No change to `light`.
    pub fn none(light: LightId) -> Self {
        Self { light, power: Vec3::ONE, transform: Affine3A::IDENTITY }
    }

    /// `light` (the punctual light this edit names, as posed) with the edit applied.
    pub fn apply(&self, light: &Light) -> Light {
        let m = &self.transform;
        let turn = |d: Vec3| m.transform_vector3(d).normalize_or(d);
        match *light {
            Light::Point { position, intensity } => {
                Light::Point { position: m.transform_point3(position), intensity: intensity * self.power }
            }
            Light::Spot { position, direction, angle_deg, intensity } => Light::Spot {
                position: m.transform_point3(position),
                direction: turn(direction),
                angle_deg,
                intensity: intensity * self.power,
            },
            Light::Directional { direction, irradiance } => {
                Light::Directional { direction: turn(direction), irradiance: irradiance * self.power }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_edit_scales_power_and_moves_a_punctual_light() {
        let edit = LightEdit {
            light: LightId::Punctual(0),
            power: Vec3::new(2.0, 1.0, 0.0),
            transform: Affine3A::from_translation(Vec3::X),
        };
        let point = Light::Point { position: Vec3::ZERO, intensity: Vec3::ONE };
        assert_eq!(
            edit.apply(&point),
            Light::Point { position: Vec3::X, intensity: Vec3::new(2.0, 1.0, 0.0) }
        );
        // A translation leaves a direction alone; a rotation turns it.
        let sun = Light::Directional { direction: Vec3::NEG_Y, irradiance: Vec3::ONE };
        assert_eq!(edit.apply(&sun), Light::Directional { direction: Vec3::NEG_Y, irradiance: edit.power });
        let turned = LightEdit {
            transform: Affine3A::from_rotation_z(std::f32::consts::FRAC_PI_2),
            ..LightEdit::none(LightId::Punctual(0))
        };
        let Light::Directional { direction, .. } = turned.apply(&sun) else { unreachable!() };
        assert!((direction - Vec3::X).length() < 1e-6, "{direction}");
        assert_eq!(LightEdit::none(LightId::Emissive(3)).apply(&point), point);
    }
}
