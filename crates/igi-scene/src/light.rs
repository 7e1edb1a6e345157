//! Punctual and distant light sources: what lights a scene besides its emissive triangles
//! (area lights, see [`crate::model`]) and its environment.

use glam::Vec3;

/// A punctual or distant light source. Area lights are emissive triangles (see the module doc).
#[derive(Clone, Debug, PartialEq)]
pub enum Light {
    /// Isotropic point light with radiant intensity `intensity` in W/sr.
    Point {
        /// Position in world space.
        position: Vec3,
        /// Radiant intensity I in W/sr.
        intensity: Vec3,
    },
    /// Spot light: a point light restricted to a cone around `direction`.
    Spot {
        /// Position in world space.
        position: Vec3,
        /// Unit direction of the cone axis.
        direction: Vec3,
        /// Full opening angle of the cone in degrees.
        angle_deg: f32,
        /// Radiant intensity I in W/sr inside the cone.
        intensity: Vec3,
    },
    /// Distant light (a sun): parallel light travelling along `direction`.
    Directional {
        /// Unit direction the light travels in (pointing away from the light).
        direction: Vec3,
        /// Irradiance E in W/m² on a surface facing the light.
        irradiance: Vec3,
    },
}

impl Light {
    /// The same light with its emitted power (intensity or irradiance) times `factor`.
    pub fn scaled(&self, factor: f32) -> Self {
        match *self {
            Light::Point { position, intensity } => Light::Point { position, intensity: intensity * factor },
            Light::Spot { position, direction, angle_deg, intensity } => {
                Light::Spot { position, direction, angle_deg, intensity: intensity * factor }
            }
            Light::Directional { direction, irradiance } => {
                Light::Directional { direction, irradiance: irradiance * factor }
            }
        }
    }
}
