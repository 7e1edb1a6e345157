//! Environment light as scene data: the radiance arriving from infinitely far away along
//! every direction the scene does not block (a sky). Scene files set it with `[environment]`.
//!
//! # Equirectangular maps
//!
//! An environment image is a latitude-longitude map of the sphere of directions, in the
//! world frame (+Y up) before its rotation. For texture coordinates (u, v) in [0, 1]² (u to
//! the right, v down, (0, 0) the top-left corner of the image, as for every texture):
//!
//! ```text
//! θ = π v                        polar angle from +Y: v = 0 (top row) is straight up (+Y),
//!                                v = 1 (bottom row) straight down (−Y), v = ½ the horizon
//! φ = 2π u                       azimuth
//! d = (−sin φ sin θ,  cos θ,  cos φ sin θ)
//! ```
//!
//! so u = 0 (the left and right edges) looks along +Z, u = ¼ along −X, u = ½ (the centre
//! column) along −Z and u = ¾ along +X; inversely u = atan2(−d.x, d.z) / 2π (wrapped into
//! [0, 1)) and v = acos(d.y) / π. Seen from inside the sphere by a camera looking along −Z
//! with +Y up (the default view), the image centre is straight ahead and appears the right
//! way round (its right half is to the camera's right, +X).
//!
//! The rotation turns the map about +Y by `rotation_deg`, counter-clockwise seen from above
//! (the right-hand rule about +Y): what the unrotated map shows along direction m appears
//! along R_y(rotation_deg) · m, so +90° moves the u = 0 edge from +Z to +X.

use glam::Vec3;

/// Light from infinitely far away: what a ray that leaves the scene sees (see the module doc
/// for the image mapping).
#[derive(Clone, Debug, PartialEq)]
pub enum Environment {
    /// The same radiance from every direction (a uniform sky).
    Constant {
        /// Radiance in W/(sr m²), linear RGB; may exceed 1.
        radiance: Vec3,
    },
    /// An equirectangular image of radiance (see the module doc).
    Map {
        /// The image, an index into [`Scene::textures`](crate::Scene::textures); its texels
        /// are linear radiance in W/(sr m²) before `intensity`.
        texture: u32,
        /// Factor on every texel (finite, not negative).
        intensity: f32,
        /// Rotation of the map about +Y in degrees, counter-clockwise seen from above.
        rotation_deg: f32,
    },
}
