//! Procedural surface shaders as scene data: what a scene file's `[[shader]]` table asks for.
//! The shading crate (`igi-shade`) turns a [`ShaderDesc`] into running code; this crate only
//! holds and validates the parameters.

use glam::Vec3;

/// A procedural surface shader assigned to a material (scene file `[[shader]]`). Patterns are
/// solid textures: functions of the object-space position times `scale`, so they need no
/// texture coordinates and move with their object.
#[derive(Clone, Debug, PartialEq)]
pub struct ShaderDesc {
    /// The pattern and its own parameters.
    pub pattern: Pattern,
    /// Pattern frequency: the pattern is evaluated at `scale · p` (features per unit length).
    pub scale: f32,
    /// The two linear-RGB colours the pattern blends between (diffuse reflectance).
    pub colors: [Vec3; 2],
    /// Reflectance of the glossy lobe (zero for a matte surface).
    pub glossy: Vec3,
    /// Phong exponent of the glossy lobe.
    pub exponent: f32,
    /// Bump amplitude: how far (in world units, before `scale`) the pattern's height field
    /// displaces the surface for shading; zero for none.
    pub bump: f32,
}

/// The procedural patterns.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Pattern {
    /// Alternating cubes of the two colours.
    Checker,
    /// Veins: `sin(x + turbulence · T(p))` between the colours, T the turbulence of
    /// `octaves` octaves of Perlin noise.
    Marble {
        /// Octaves of the turbulence.
        octaves: u32,
        /// Strength of the turbulence that bends the veins.
        turbulence: f32,
    },
    /// Concentric growth rings around the y axis, disturbed by noise.
    Wood {
        /// Rings per unit radius (before `scale`).
        rings: f32,
        /// Strength of the noise that bends the rings.
        turbulence: f32,
    },
    /// Bricks of colour 0 in mortar of colour 1, running bond; the mortar is recessed when
    /// `bump` is non-zero.
    Brick {
        /// Brick size (x: length, y: height, z: depth of the running bond) in pattern units.
        size: Vec3,
        /// Mortar joint width in pattern units.
        mortar: f32,
    },
    /// Turbulence (sum of |noise| over `octaves` octaves) blending the colours.
    Turbulence {
        /// Octaves summed.
        octaves: u32,
    },
}
