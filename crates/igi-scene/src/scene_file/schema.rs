//! The schema of a scene file: the tables `toml` deserialises it into, as written, before any
//! value is checked. Tables keep their spans (`Spanned`) so that errors found later point at
//! a line.

use serde::Deserialize;
use toml::Spanned;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct SceneSpec {
    pub(super) camera: Option<Spanned<CameraSpec>>,
    #[serde(default)]
    pub(super) view: Vec<Spanned<ViewSpec>>,
    #[serde(default)]
    pub(super) mesh: Vec<Spanned<MeshSpec>>,
    #[serde(default)]
    pub(super) light: Vec<Spanned<LightSpec>>,
    #[serde(default)]
    pub(super) shader: Vec<Spanned<ShaderSpec>>,
    pub(super) environment: Option<Spanned<EnvironmentSpec>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct CameraSpec {
    pub(super) position: [f32; 3],
    pub(super) target: [f32; 3],
    #[serde(default = "up_y")]
    pub(super) up: [f32; 3],
    #[serde(default = "default_fov")]
    pub(super) fov: f32,
}

/// A `[[view]]`: a named camera, with the fields of `[camera]` (serde cannot flatten them
/// into a table that refuses unknown fields).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct ViewSpec {
    pub(super) name: String,
    pub(super) position: [f32; 3],
    pub(super) target: [f32; 3],
    #[serde(default = "up_y")]
    pub(super) up: [f32; 3],
    #[serde(default = "default_fov")]
    pub(super) fov: f32,
}

impl ViewSpec {
    /// The camera fields.
    pub(super) fn camera(&self) -> CameraSpec {
        CameraSpec { position: self.position, target: self.target, up: self.up, fov: self.fov }
    }
}

fn up_y() -> [f32; 3] {
    [0.0, 1.0, 0.0]
}

/// The vertical field of view, in degrees, of a `[camera]` or `[[view]]` without `fov`: the one
/// igi frames an object with when a scene has no camera (a 33 mm lens on 35 mm film, held
/// landscape), neither wide nor long.
pub(super) const DEFAULT_FOV: f32 = 40.0;

fn default_fov() -> f32 {
    DEFAULT_FOV
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct MeshSpec {
    pub(super) file: Spanned<String>,
    pub(super) translate: Option<[f32; 3]>,
    pub(super) rotate: Option<[f32; 3]>,
    pub(super) scale: Option<Scale>,
    pub(super) instances: Option<Vec<TransformSpec>>,
    pub(super) material: Option<MaterialSpec>,
    pub(super) animation: Option<AnimationSpec>,
}

/// `[mesh.animation]` or `[light.animation]`: keyframes of some of the entry's fields.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct AnimationSpec {
    pub(super) interpolation: Option<InterpolationKind>,
    #[serde(rename = "loop")]
    pub(super) looping: Option<bool>,
    pub(super) keys: Vec<KeySpec>,
}

#[derive(Clone, Copy, Deserialize)]
#[serde(rename_all = "lowercase")]
pub(super) enum InterpolationKind {
    Step,
    Linear,
    Smooth,
}

/// One keyframe: a time and any of the fields its entry may animate.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct KeySpec {
    pub(super) time: f32,
    pub(super) translate: Option<[f32; 3]>,
    pub(super) rotate: Option<[f32; 3]>,
    pub(super) scale: Option<Scale>,
    pub(super) position: Option<[f32; 3]>,
    pub(super) direction: Option<[f32; 3]>,
    pub(super) intensity: Option<[f32; 3]>,
    pub(super) irradiance: Option<[f32; 3]>,
}

impl KeySpec {
    /// The animatable fields this key sets.
    pub(super) fn present(&self) -> [(&'static str, bool); 7] {
        [
            ("translate", self.translate.is_some()),
            ("rotate", self.rotate.is_some()),
            ("scale", self.scale.is_some()),
            ("position", self.position.is_some()),
            ("direction", self.direction.is_some()),
            ("intensity", self.intensity.is_some()),
            ("irradiance", self.irradiance.is_some()),
        ]
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct TransformSpec {
    pub(super) translate: Option<[f32; 3]>,
    pub(super) rotate: Option<[f32; 3]>,
    pub(super) scale: Option<Scale>,
}

#[derive(Clone, Copy, Deserialize)]
#[serde(untagged, expecting = "expected a number or an array of three numbers")]
pub(super) enum Scale {
    Uniform(f32),
    Axes([f32; 3]),
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct MaterialSpec {
    pub(super) diffuse: Option<[f32; 3]>,
    pub(super) specular: Option<[f32; 3]>,
    pub(super) exponent: Option<f32>,
    pub(super) emission: Option<[f32; 3]>,
}

/// A `[[light]]` table. One flat struct rather than an enum tagged by `type`: serde buffers
/// tagged enums, which loses the spans that make `toml` errors point at a line.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct LightSpec {
    #[serde(rename = "type")]
    pub(super) kind: LightKind,
    pub(super) position: Option<[f32; 3]>,
    pub(super) u: Option<[f32; 3]>,
    pub(super) v: Option<[f32; 3]>,
    pub(super) radiance: Option<[f32; 3]>,
    pub(super) intensity: Option<[f32; 3]>,
    pub(super) direction: Option<[f32; 3]>,
    pub(super) angle: Option<f32>,
    pub(super) irradiance: Option<[f32; 3]>,
    pub(super) animation: Option<AnimationSpec>,
}

impl LightSpec {
    /// The fields this light sets besides `type` and `animation`.
    pub(super) fn present(&self) -> [(&'static str, bool); 8] {
        [
            ("position", self.position.is_some()),
            ("u", self.u.is_some()),
            ("v", self.v.is_some()),
            ("radiance", self.radiance.is_some()),
            ("intensity", self.intensity.is_some()),
            ("direction", self.direction.is_some()),
            ("angle", self.angle.is_some()),
            ("irradiance", self.irradiance.is_some()),
        ]
    }
}

#[derive(Clone, Copy, Deserialize)]
#[serde(rename_all = "lowercase")]
pub(super) enum LightKind {
    Quad,
    Point,
    Spot,
    Directional,
}

impl LightKind {
    pub(super) fn name(self) -> &'static str {
        match self {
            Self::Quad => "quad",
            Self::Point => "point",
            Self::Spot => "spot",
            Self::Directional => "directional",
        }
    }

    /// The fields a light of this kind takes besides `type`.
    pub(super) fn fields(self) -> &'static [&'static str] {
        match self {
            Self::Quad => &["position", "u", "v", "radiance"],
            Self::Point => &["position", "intensity"],
            Self::Spot => &["position", "direction", "angle", "intensity"],
            Self::Directional => &["direction", "irradiance"],
        }
    }

    /// The fields keyframes of a light of this kind may set.
    pub(super) fn keyed_fields(self) -> &'static [&'static str] {
        match self {
            Self::Quad => &["position", "rotate"],
            Self::Point => &["position", "intensity"],
            Self::Spot => &["position", "direction", "intensity"],
            Self::Directional => &["direction", "irradiance"],
        }
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct EnvironmentSpec {
    pub(super) color: Option<[f32; 3]>,
    pub(super) file: Option<Spanned<String>>,
    pub(super) intensity: Option<f32>,
    pub(super) rotate: Option<f32>,
}

/// A `[[shader]]` table: flat for the same reason as [`LightSpec`].
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct ShaderSpec {
    pub(super) target: Spanned<String>,
    #[serde(rename = "type")]
    pub(super) kind: ShaderKind,
    pub(super) scale: Option<f32>,
    pub(super) colors: Option<[[f32; 3]; 2]>,
    pub(super) specular: Option<[f32; 3]>,
    pub(super) exponent: Option<f32>,
    pub(super) bump: Option<f32>,
    pub(super) octaves: Option<u32>,
    pub(super) turbulence: Option<f32>,
    pub(super) rings: Option<f32>,
    pub(super) size: Option<[f32; 3]>,
    pub(super) mortar: Option<f32>,
}

impl ShaderSpec {
    /// The pattern parameters this shader sets.
    pub(super) fn present(&self) -> [(&'static str, bool); 5] {
        [
            ("octaves", self.octaves.is_some()),
            ("turbulence", self.turbulence.is_some()),
            ("rings", self.rings.is_some()),
            ("size", self.size.is_some()),
            ("mortar", self.mortar.is_some()),
        ]
    }
}

#[derive(Clone, Copy, Deserialize)]
#[serde(rename_all = "lowercase")]
pub(super) enum ShaderKind {
    Checker,
    Marble,
    Wood,
    Brick,
    Turbulence,
}

impl ShaderKind {
    pub(super) fn name(self) -> &'static str {
        match self {
            Self::Checker => "checker",
            Self::Marble => "marble",
            Self::Wood => "wood",
            Self::Brick => "brick",
            Self::Turbulence => "turbulence",
        }
    }

    /// The pattern parameters a shader of this kind takes (besides the common ones).
    pub(super) fn fields(self) -> &'static [&'static str] {
        match self {
            Self::Checker => &[],
            Self::Marble => &["octaves", "turbulence"],
            Self::Wood => &["rings", "turbulence"],
            Self::Brick => &["size", "mortar"],
            Self::Turbulence => &["octaves"],
        }
    }
}
