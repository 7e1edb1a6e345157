//! Scene files: a TOML description that places mesh files, adds lights and sets the camera.
//!
//! ```toml
//! [camera]
//! position = [0, 1, 3.5]
//! target = [0, 1, 0]
//! up = [0, 1, 0]                 # optional, default +Y
//! fov = 39.3                     # vertical, degrees
//!
//! [[mesh]]
//! file = "CornellBox-Original.obj"          # .obj .gltf .glb .ply, relative to this file
//! translate = [0, 0, 0]                     # optional
//! rotate = [0, 90, 0]                       # optional, degrees about X, Y, Z
//! scale = 2.0                               # optional, or [sx, sy, sz]
//! instances = [ { translate = [3, 0, 0] }, { rotate = [0, 45, 0] } ]   # optional
//! material = { diffuse = [0.8, 0.8, 0.8] }  # optional: replaces every material of the file
//!
//! [mesh.animation]                          # optional: keyframes of translate/rotate/scale
//! interpolation = "smooth"                  # step | linear (default) | smooth
//! loop = true                               # default true: repeat after the last key
//! keys = [ { time = 0, rotate = [0, 0, 0] }, { time = 4, rotate = [0, 360, 0] } ]
//!
//! [[light]]
//! type = "quad"                  # quad | point | spot | directional
//! position = [350, 640, -210]    # quad: centre
//! u = [400, 0, 0]                # quad: half-edge vectors; emits toward normalize(u × v)
//! v = [0, 0, 200]
//! radiance = [10, 10, 10]        # W/(sr m²)
//! # point: position, intensity = [r, g, b] (W/sr)
//! # spot: position, direction, angle (full cone, degrees), intensity
//! # directional: direction (the way the light travels), irradiance = [r, g, b] (W/m²)
//! # animation = { interpolation = "linear", loop = true, keys = [ { time = 0, ... } ] }:
//! #   quad: position, rotate (about its centre); point: position, intensity;
//! #   spot: position, direction, intensity; directional: direction, irradiance
//!
//! [[shader]]
//! target = "floor"               # a material name, or else a mesh name
//! type = "marble"                # checker | marble | wood | brick | turbulence
//! scale = 2.0                    # optional, default 1: pattern features per unit length
//! colors = [[0.9, 0.9, 0.85], [0.3, 0.3, 0.35]]   # optional, default [[0.8]*3, [0.2]*3]
//! specular = [0.05, 0.05, 0.05]  # optional, default [0, 0, 0]
//! exponent = 40.0                # optional, default 20
//! bump = 0.002                   # optional, default 0 (no bump)
//! # marble: octaves (default 4), turbulence (default 5)
//! # wood: rings (default 4), turbulence (default 0.5)
//! # brick: size = [x, y, z] (default [3, 1, 1.5]), mortar (default 0.1)
//! # turbulence: octaves (default 4)
//!
//! [environment]                  # optional: what rays leaving the scene see
//! color = [0.4, 0.6, 1.0]        # a constant sky radiance (W/(sr m²), may exceed 1), or
//! # file = "sky.hdr"             # an equirectangular image relative to this file (.hdr,
//! # intensity = 1.0              # .exr, or LDR .png/.jpg read as sRGB), with optional
//! # rotate = 0.0                 # factor (default 1) and turn about +Y in degrees
//! ```
//!
//! Transforms: `translate`, `rotate` and `scale` make T·R·S, with R = Rz·Ry·Rx, i.e. the
//! rotation about X is applied first, then Y, then Z, all about the fixed world axes. Each
//! entry of `instances` is a transform of the same form applied *after* the mesh's own, so a
//! placement is `instance · mesh`: the mesh transform fits the file into the scene (units,
//! up axis), the instances then place copies of it. A mesh file's own instances (glTF nodes)
//! come first of all, and its lights and camera move with it. Without `instances` the mesh
//! is placed once. A `material` replaces every material of the file (useful for PLY, which has
//! none), and then the file's own materials and textures are dropped.
//!
//! Animation: each key sets a time in seconds and any of the fields its entry may animate;
//! each field is a track over the keys that set it, and replaces the entry's own value (a
//! keyed `rotate` replaces the mesh's `rotate`, and so on). Rotations are keyed as angles, so
//! a turn from 0 to 360 degrees is one revolution. `smooth` is a Catmull-Rom spline that
//! eases in and out at the first and last key ([`crate::animation`]). A looping entry
//! repeats with the period of its last key. An animated mesh moves everything its file
//! contains, glTF animations included, and `instances` place copies that move alike.
//!
//! The camera of the scene file wins; without one, the first mesh file's camera (glTF) is
//! used. A quad light becomes a mesh of two one-sided emissive triangles whose geometric
//! normal is normalize(u × v), with a black diffuse emissive material and an identity instance.
//!
//! A `[[shader]]` gives a procedural [`ShaderDesc`] to the materials its `target` names,
//! after every mesh and light is in place; entries apply in order, so a later one wins. The
//! target is looked up among material names first (OBJ `newmtl`, glTF material names, the
//! `light[i]` material of a quad light), and every material of that name gets the shader. If
//! no material has that name, it is looked up among mesh names (a glTF mesh name, an OBJ or
//! PLY file's stem, `light[i]`): the triangles of those meshes get their own copies of their
//! materials carrying the shader, so other meshes sharing a material keep it unchanged. A
//! target that matches neither is an error. Colours and `specular` are reflectances in
//! [0, 1]; `octaves` is 1 to 16; `scale`, `rings` and the brick `size` must be positive;
//! `mortar` must be narrower than every brick dimension.
//!
//! `[environment]` takes `color` or `file`, not both; `intensity` and `rotate` only go with
//! `file`. The image's mapping and rotation are those of [`Environment`]. Unlike a material's
//! texture, an environment image that is missing or cannot be decoded is an error: without
//! it the scene has different lighting, not just a different-looking surface.
//!
//! Unknown fields are errors (a typo like `rotation` must not be silently ignored), and every
//! error names the scene file, the line and the field.

mod field_spans;

use std::ops::Range;
use std::path::Path;

use glam::{Affine3A, Vec3};
use serde::Deserialize;
use toml::Spanned;

use crate::animation::{
    AnimatedInstance, AnimatedLight, AnimationNode, Finite, Keyable, RotationTrack, Track, euler_degrees,
};
use crate::environment::Environment;
use crate::error::{Location, SceneError};
use crate::format;
use crate::light::Light;
use crate::model::{Camera, Instance, Material, Mesh, Scene};
use crate::report::LoadReport;
use crate::resources;
use crate::shader::{Pattern, ShaderDesc};
use crate::texels::ColorSpace;
use crate::texture::TextureSet;
use crate::validate::MAX_INSTANCES;

/// Loads a scene file whose textures (those of every mesh file and the sky's) go into
/// `textures`, so each image is decoded once for the whole scene and within one budget.
pub(crate) fn load_into(
    path: &Path,
    textures: &mut TextureSet,
    report: &mut LoadReport,
) -> Result<Scene, SceneError> {
    // Refused before it is read if it is too large (`check_size` bounds text from memory).
    let bytes = resources::read_at_most(path, MAX_SCENE_FILE_BYTES as u64, report)?;
    let text = std::str::from_utf8(&bytes)
        .map_err(|e| SceneError::parse(path, Location::File, format!("not UTF-8 text: {e}")))?;
    parse_file(text, path, Some(&resources::base_dir(path)), textures, report)
}

/// Parses scene-file text; `name` is used in messages. Mesh files are looked up in
/// `base_dir`; with `None` their entries are checked but no file is read (with a warning).
pub fn parse(
    text: &str,
    name: &str,
    base_dir: Option<&Path>,
    report: &mut LoadReport,
) -> Result<Scene, SceneError> {
    TextureSet::default().owning(|textures| parse_file(text, Path::new(name), base_dir, textures, report))
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SceneSpec {
    camera: Option<Spanned<CameraSpec>>,
    #[serde(default)]
    mesh: Vec<Spanned<MeshSpec>>,
    #[serde(default)]
    light: Vec<Spanned<LightSpec>>,
    #[serde(default)]
    shader: Vec<Spanned<ShaderSpec>>,
    environment: Option<Spanned<EnvironmentSpec>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CameraSpec {
    position: [f32; 3],
    target: [f32; 3],
    #[serde(default = "up_y")]
    up: [f32; 3],
    fov: f32,
}

fn up_y() -> [f32; 3] {
    [0.0, 1.0, 0.0]
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MeshSpec {
    file: Spanned<String>,
    translate: Option<[f32; 3]>,
    rotate: Option<[f32; 3]>,
    scale: Option<Scale>,
    instances: Option<Vec<TransformSpec>>,
    material: Option<MaterialSpec>,
    animation: Option<AnimationSpec>,
}

/// `[mesh.animation]` or `[light.animation]`: keyframes of some of the entry's fields.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct AnimationSpec {
    interpolation: Option<InterpolationKind>,
    #[serde(rename = "loop")]
    looping: Option<bool>,
    keys: Vec<KeySpec>,
}

#[derive(Clone, Copy, Deserialize)]
#[serde(rename_all = "lowercase")]
enum InterpolationKind {
    Step,
    Linear,
    Smooth,
}

/// One keyframe: a time and any of the fields its entry may animate.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct KeySpec {
    time: f32,
    translate: Option<[f32; 3]>,
    rotate: Option<[f32; 3]>,
    scale: Option<Scale>,
    position: Option<[f32; 3]>,
    direction: Option<[f32; 3]>,
    intensity: Option<[f32; 3]>,
    irradiance: Option<[f32; 3]>,
}

impl KeySpec {
    /// The animatable fields this key sets.
    fn present(&self) -> [(&'static str, bool); 7] {
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
struct TransformSpec {
    translate: Option<[f32; 3]>,
    rotate: Option<[f32; 3]>,
    scale: Option<Scale>,
}

#[derive(Clone, Copy, Deserialize)]
#[serde(untagged, expecting = "expected a number or an array of three numbers")]
enum Scale {
    Uniform(f32),
    Axes([f32; 3]),
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MaterialSpec {
    diffuse: Option<[f32; 3]>,
    specular: Option<[f32; 3]>,
    exponent: Option<f32>,
    emission: Option<[f32; 3]>,
}

/// A `[[light]]` table. One flat struct rather than an enum tagged by `type`: serde buffers
/// tagged enums, which loses the spans that make `toml` errors point at a line.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct LightSpec {
    #[serde(rename = "type")]
    kind: LightKind,
    position: Option<[f32; 3]>,
    u: Option<[f32; 3]>,
    v: Option<[f32; 3]>,
    radiance: Option<[f32; 3]>,
    intensity: Option<[f32; 3]>,
    direction: Option<[f32; 3]>,
    angle: Option<f32>,
    irradiance: Option<[f32; 3]>,
    animation: Option<AnimationSpec>,
}

#[derive(Clone, Copy, Deserialize)]
#[serde(rename_all = "lowercase")]
enum LightKind {
    Quad,
    Point,
    Spot,
    Directional,
}

impl LightKind {
    fn name(self) -> &'static str {
        match self {
            Self::Quad => "quad",
            Self::Point => "point",
            Self::Spot => "spot",
            Self::Directional => "directional",
        }
    }

    /// The fields a light of this kind takes besides `type`.
    fn fields(self) -> &'static [&'static str] {
        match self {
            Self::Quad => &["position", "u", "v", "radiance"],
            Self::Point => &["position", "intensity"],
            Self::Spot => &["position", "direction", "angle", "intensity"],
            Self::Directional => &["direction", "irradiance"],
        }
    }

    /// The fields keyframes of a light of this kind may set.
    fn keyed_fields(self) -> &'static [&'static str] {
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
struct EnvironmentSpec {
    color: Option<[f32; 3]>,
    file: Option<Spanned<String>>,
    intensity: Option<f32>,
    rotate: Option<f32>,
}

/// A `[[shader]]` table: flat for the same reason as [`LightSpec`].
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ShaderSpec {
    target: Spanned<String>,
    #[serde(rename = "type")]
    kind: ShaderKind,
    scale: Option<f32>,
    colors: Option<[[f32; 3]; 2]>,
    specular: Option<[f32; 3]>,
    exponent: Option<f32>,
    bump: Option<f32>,
    octaves: Option<u32>,
    turbulence: Option<f32>,
    rings: Option<f32>,
    size: Option<[f32; 3]>,
    mortar: Option<f32>,
}

#[derive(Clone, Copy, Deserialize)]
#[serde(rename_all = "lowercase")]
enum ShaderKind {
    Checker,
    Marble,
    Wood,
    Brick,
    Turbulence,
}

impl ShaderKind {
    fn name(self) -> &'static str {
        match self {
            Self::Checker => "checker",
            Self::Marble => "marble",
            Self::Wood => "wood",
            Self::Brick => "brick",
            Self::Turbulence => "turbulence",
        }
    }

    /// The pattern parameters a shader of this kind takes (besides the common ones).
    fn fields(self) -> &'static [&'static str] {
        match self {
            Self::Checker => &[],
            Self::Marble => &["octaves", "turbulence"],
            Self::Wood => &["rings", "turbulence"],
            Self::Brick => &["size", "mortar"],
            Self::Turbulence => &["octaves"],
        }
    }
}

/// Defaults of the optional `[[shader]]` fields (listed in the module doc).
const SHADER_COLORS: [[f32; 3]; 2] = [[0.8; 3], [0.2; 3]];
const SHADER_EXPONENT: f32 = 20.0;
const DEFAULT_OCTAVES: u32 = 4;
const MARBLE_TURBULENCE: f32 = 5.0;
const WOOD_RINGS: f32 = 4.0;
const WOOD_TURBULENCE: f32 = 0.5;
const BRICK_SIZE: [f32; 3] = [3.0, 1.0, 1.5];
const BRICK_MORTAR: f32 = 0.1;
/// Octaves beyond 16 add detail far below a texel at any sensible scale and only cost time.
const MAX_OCTAVES: u32 = 16;

/// Turns semantic problems into errors that point at a field of the file.
struct Checker<'a> {
    file: &'a Path,
    text: &'a str,
}

impl Checker<'_> {
    /// An error about the field at `path`, at the line of its value, or else (a default
    /// that is not in the file) of `span`, its table's.
    fn error(&self, span: &Range<usize>, path: String, message: impl Into<String>) -> SceneError {
        let at = field_spans::value_span(self.text, &path).map_or(span.start, |value| value.start);
        SceneError::invalid(self.file, Location::Field { line: Some(line_of(self.text, at)), path }, message)
    }

    fn vector(&self, span: &Range<usize>, path: String, v: [f32; 3]) -> Result<Vec3, SceneError> {
        self.vector_at(span, || path, v)
    }

    /// [`Checker::vector`] with the path formatted only for a message.
    fn vector_at(
        &self,
        span: &Range<usize>,
        path: impl FnOnce() -> String,
        v: [f32; 3],
    ) -> Result<Vec3, SceneError> {
        let v = Vec3::from(v);
        if v.is_finite() { Ok(v) } else { Err(self.error(span, path(), "values must be finite")) }
    }

    fn colour(&self, span: &Range<usize>, path: String, v: [f32; 3]) -> Result<Vec3, SceneError> {
        let c = self.vector(span, path.clone(), v)?;
        if c.min_element() < 0.0 {
            return Err(self.error(span, path, "values must not be negative"));
        }
        Ok(c)
    }

    /// A reflectance: finite and in [0, 1].
    fn reflectance(&self, span: &Range<usize>, path: String, v: [f32; 3]) -> Result<Vec3, SceneError> {
        let c = self.colour(span, path.clone(), v)?;
        if c.max_element() > 1.0 {
            return Err(self.error(span, path, "reflectance must be in [0, 1]"));
        }
        Ok(c)
    }

    /// A finite number that is positive (`zero_ok` false) or not negative (`zero_ok` true).
    fn amount(
        &self,
        span: &Range<usize>,
        path: String,
        value: f32,
        zero_ok: bool,
    ) -> Result<f32, SceneError> {
        let ok = value.is_finite() && if zero_ok { value >= 0.0 } else { value > 0.0 };
        if ok {
            Ok(value)
        } else if zero_ok {
            Err(self.error(span, path, "must be finite and not negative"))
        } else {
            Err(self.error(span, path, "must be finite and positive"))
        }
    }

    fn direction(&self, span: &Range<usize>, path: String, v: [f32; 3]) -> Result<Vec3, SceneError> {
        self.vector(span, path.clone(), v)?
            .try_normalize()
            .ok_or_else(|| self.error(span, path, "direction must not be zero"))
    }

    /// The placement of `translate`, `rotate` (degrees) and `scale`; `path` is the prefix of
    /// their field paths, formatted only for a message (instance lists are long).
    fn transform(
        &self,
        span: &Range<usize>,
        path: impl Fn() -> String,
        translate: Option<[f32; 3]>,
        rotate: Option<[f32; 3]>,
        scale: Option<Scale>,
    ) -> Result<Affine3A, SceneError> {
        let translation =
            self.vector_at(span, || format!("{}translate", path()), translate.unwrap_or_default())?;
        let degrees = self.vector_at(span, || format!("{}rotate", path()), rotate.unwrap_or_default())?;
        let scale = self.scale(span, || format!("{}scale", path()), scale.unwrap_or(Scale::Uniform(1.0)))?;
        Ok(Affine3A::from_scale_rotation_translation(scale, euler_degrees(degrees), translation))
    }

    fn scale(
        &self,
        span: &Range<usize>,
        path: impl FnOnce() -> String,
        scale: Scale,
    ) -> Result<Vec3, SceneError> {
        let scale = match scale {
            Scale::Uniform(s) => Vec3::splat(s),
            Scale::Axes(axes) => Vec3::from(axes),
        };
        if !scale.is_finite() || scale.cmpeq(Vec3::ZERO).any() {
            return Err(self.error(span, path(), "scale must be finite and non-zero"));
        }
        Ok(scale)
    }

    /// Checks an `animation` table's keys: at least one, times finite and ≥ 0, and only the
    /// fields in `allowed` (`entry` names the kind of entry in the message).
    fn keys(
        &self,
        span: &Range<usize>,
        path: &str,
        spec: &AnimationSpec,
        allowed: &[&str],
        entry: &str,
    ) -> Result<(), SceneError> {
        if spec.keys.is_empty() {
            return Err(self.error(span, format!("{path}keys"), "an animation needs at least one key"));
        }
        for (k, key) in spec.keys.iter().enumerate() {
            if !(key.time.is_finite() && key.time >= 0.0) {
                return Err(self.error(
                    span,
                    format!("{path}keys[{k}].time"),
                    "must be a finite number of seconds ≥ 0",
                ));
            }
            for (field, present) in key.present() {
                if present && !allowed.contains(&field) {
                    return Err(self.error(
                        span,
                        format!("{path}keys[{k}].{field}"),
                        format!("{entry} cannot animate `{field}` (it can: {})", allowed.join(", ")),
                    ));
                }
            }
        }
        Ok(())
    }

    /// The track of one field over the keys that set it (`None` if no key does); `value`
    /// reads and checks a key's value, given the field's path for messages.
    fn track<T: Keyable + Finite>(
        &self,
        span: &Range<usize>,
        path: &str,
        spec: &AnimationSpec,
        field: &str,
        value: impl Fn(&KeySpec, String) -> Result<Option<T>, SceneError>,
    ) -> Result<Option<Track<T>>, SceneError> {
        let mut times = Vec::new();
        let mut values = Vec::new();
        for (k, key) in spec.keys.iter().enumerate() {
            if let Some(v) = value(key, format!("{path}keys[{k}].{field}"))? {
                times.push(key.time);
                values.push(v);
            }
        }
        if times.is_empty() {
            return Ok(None);
        }
        let track = match spec.interpolation.unwrap_or(InterpolationKind::Linear) {
            InterpolationKind::Step => Track::step(times, values),
            InterpolationKind::Linear => Track::linear(times, values),
            InterpolationKind::Smooth => Track::smooth(times, values),
        };
        track.map(Some).map_err(|e| self.error(span, format!("{path}keys"), format!("`{field}` keys: {e}")))
    }
}

/// Makes every track of one entry repeat with the entry's period (its last key time), if the
/// entry loops (`loop`, default true).
fn looped<T: Keyable>(track: Option<Track<T>>, spec: &AnimationSpec, period: f32) -> Option<Track<T>> {
    track.map(|t| if spec.looping.unwrap_or(true) { t.looping(period) } else { t })
}

/// The transform node of a `[[mesh]]`: its `translate`/`rotate`/`scale` as rest, with the
/// tracks of its `[mesh.animation]`, if any.
fn mesh_node(
    check: &Checker,
    span: &Range<usize>,
    path: &str,
    own: Affine3A,
    spec: Option<&AnimationSpec>,
) -> Result<AnimationNode, SceneError> {
    let mut node = AnimationNode::fixed(None, own);
    let Some(spec) = spec else {
        return Ok(node);
    };
    let path = format!("{path}animation.");
    check.keys(span, &path, spec, &["translate", "rotate", "scale"], "a mesh")?;
    let translation = check.track(span, &path, spec, "translate", |key, at| {
        key.translate.map(|v| check.vector(span, at, v)).transpose()
    })?;
    let rotation = check.track(span, &path, spec, "rotate", |key, at| {
        key.rotate.map(|v| check.vector(span, at, v)).transpose()
    })?;
    let scale = check.track(span, &path, spec, "scale", |key, at| {
        key.scale.map(|v| check.scale(span, || at, v)).transpose()
    })?;
    let period = [translation.as_ref(), rotation.as_ref(), scale.as_ref()]
        .into_iter()
        .flatten()
        .map(Track::end)
        .fold(0.0, f32::max);
    node.translation = looped(translation, spec, period);
    node.rotation = looped(rotation, spec, period).map(RotationTrack::EulerDegrees);
    node.scale = looped(scale, spec, period);
    Ok(node)
}

fn parse_file(
    text: &str,
    file: &Path,
    base_dir: Option<&Path>,
    textures: &mut TextureSet,
    report: &mut LoadReport,
) -> Result<Scene, SceneError> {
    check_size(text, file)?;
    let spec: SceneSpec = toml::from_str(text).map_err(|e| toml_error(&e, text, file))?;
    let check = Checker { file, text };
    let mut scene = Scene::default();

    for (index, entry) in spec.mesh.iter().enumerate() {
        let span = entry.span();
        let path = format!("mesh[{index}].");
        let mesh = entry.get_ref();
        let own = check.transform(&span, || path.clone(), mesh.translate, mesh.rotate, mesh.scale)?;
        let own = mesh_node(&check, &span, &path, own, mesh.animation.as_ref())?;
        let placements = match &mesh.instances {
            None => vec![Affine3A::IDENTITY],
            Some(instances) => instances
                .iter()
                .enumerate()
                .map(|(i, t)| {
                    check.transform(
                        &span,
                        || format!("{path}instances[{i}]."),
                        t.translate,
                        t.rotate,
                        t.scale,
                    )
                })
                .collect::<Result<_, _>>()?,
        };
        let material = mesh
            .material
            .as_ref()
            .map(|m| material_override(&check, &span, &path, m, &mesh.file))
            .transpose()?;
        if placements.is_empty() {
            report.warn(file, format!("{path}instances is empty; `{}` is not placed", mesh.file.get_ref()));
            continue;
        }
        let Some(dir) = base_dir else {
            report
                .warn(file, format!("{path}file `{}` not loaded: parsing from memory", mesh.file.get_ref()));
            continue;
        };
        let sub = load_mesh_file(&check, dir, index, &mesh.file, textures, report)?;
        let count =
            placements.len().saturating_mul(sub.instances.len()).saturating_add(scene.instances.len());
        if count > MAX_INSTANCES {
            return Err(check.error(
                &span,
                format!("{path}instances"),
                format!("the scene would have {count} instances; it may have at most {}", MAX_INSTANCES),
            ));
        }
        append(&mut scene, sub, &placements, &own, material);
    }

    for (index, entry) in spec.light.iter().enumerate() {
        add_light(&check, &mut scene, index, entry)?;
    }

    // Without a base directory no mesh file was read, so a target may name a material of a
    // file that was skipped: warn rather than fail.
    let files_skipped = base_dir.is_none() && !spec.mesh.is_empty();
    for (index, entry) in spec.shader.iter().enumerate() {
        let shader = shader_from(&check, index, entry)?;
        if !assign_shader(&mut scene, entry.get_ref().target.get_ref(), &shader) {
            let target = &entry.get_ref().target;
            let path = format!("shader[{index}].target");
            let message = format!("`{}` is neither a material nor a mesh name", target.get_ref());
            if files_skipped {
                report.warn(file, format!("{path}: {message} (not checked: mesh files were not loaded)"));
            } else {
                return Err(check.error(&target.span(), path, message));
            }
        }
    }

    if let Some(environment) = &spec.environment {
        scene.environment = environment_from(&check, textures, environment, base_dir, report)?;
    }

    if let Some(camera) = &spec.camera {
        scene.camera = Some(camera_from(&check, camera)?);
    }
    Ok(scene)
}

/// The `[environment]` table; an image goes into `textures`. `None` (with a warning) for an
/// image when parsing from memory.
fn environment_from(
    check: &Checker,
    textures: &mut TextureSet,
    entry: &Spanned<EnvironmentSpec>,
    base_dir: Option<&Path>,
    report: &mut LoadReport,
) -> Result<Option<Environment>, SceneError> {
    let span = entry.span();
    let spec = entry.get_ref();
    let path = |field: &str| format!("environment.{field}");
    let file = match (&spec.file, spec.color) {
        (Some(file), Some(_)) => {
            return Err(check.error(&file.span(), path("file"), "give either `color` or `file`, not both"));
        }
        (None, None) => {
            return Err(check.error(&span, "environment".into(), "needs `color` or `file`"));
        }
        (None, Some(color)) => {
            for (field, is_present) in
                [("intensity", spec.intensity.is_some()), ("rotate", spec.rotate.is_some())]
            {
                if is_present {
                    return Err(check.error(
                        &span,
                        path(field),
                        format!("a constant environment (`color`) has no `{field}`"),
                    ));
                }
            }
            let radiance = check.colour(&span, path("color"), color)?;
            return Ok(Some(Environment::Constant { radiance }));
        }
        (Some(file), None) => file,
    };
    let intensity = check.amount(&span, path("intensity"), spec.intensity.unwrap_or(1.0), true)?;
    let rotation_deg = spec.rotate.unwrap_or(0.0);
    if !rotation_deg.is_finite() {
        return Err(check.error(&span, path("rotate"), "must be finite"));
    }
    let name = file.get_ref();
    let Some(dir) = base_dir else {
        report.warn(check.file, format!("environment.file `{name}` not loaded: parsing from memory"));
        return Ok(None);
    };
    let at = || Location::Field { line: Some(line_of(check.text, file.span().start)), path: path("file") };
    let image_path = resources::resolve(dir, name).ok_or_else(|| SceneError::MissingFile {
        file: check.file.to_path_buf(),
        at: at(),
        missing: dir.join(name),
    })?;
    // Float images (.hdr, .exr) are linear whatever the colour space; 8- and 16-bit images
    // are sRGB-encoded pictures.
    let texture = textures
        .required_file(&image_path, ColorSpace::Srgb, check.file, report)
        .map_err(|e| SceneError::invalid(check.file, at(), format!("`{name}` could not be loaded: {e}")))?;
    Ok(Some(Environment::Map { texture, intensity, rotation_deg }))
}

fn load_mesh_file(
    check: &Checker,
    dir: &Path,
    index: usize,
    file: &Spanned<String>,
    textures: &mut TextureSet,
    report: &mut LoadReport,
) -> Result<Scene, SceneError> {
    let name = file.get_ref();
    let at = || Location::Field {
        line: Some(line_of(check.text, file.span().start)),
        path: format!("mesh[{index}].file"),
    };
    let path = resources::resolve(dir, name).ok_or_else(|| SceneError::MissingFile {
        file: check.file.to_path_buf(),
        at: at(),
        missing: dir.join(name),
    })?;
    if !format::is_model_file(&path) {
        return Err(SceneError::unsupported(
            check.file,
            at(),
            format!("`{name}` is not an .obj, .gltf, .glb or .ply file"),
        ));
    }
    format::load_model_file(&path, textures, report)
}

fn material_override(
    check: &Checker,
    span: &Range<usize>,
    path: &str,
    spec: &MaterialSpec,
    file: &Spanned<String>,
) -> Result<Material, SceneError> {
    let defaults = Material::default();
    let colour = |name: &str, value: Option<[f32; 3]>, default: Vec3| {
        value.map_or(Ok(default), |v| check.colour(span, format!("{path}material.{name}"), v))
    };
    let diffuse = colour("diffuse", spec.diffuse, defaults.diffuse)?;
    if diffuse.max_element() > 1.0 {
        return Err(check.error(span, format!("{path}material.diffuse"), "reflectance must be at most 1"));
    }
    let exponent = spec.exponent.unwrap_or(defaults.exponent);
    if !(exponent.is_finite() && exponent >= 0.0) {
        return Err(check.error(span, format!("{path}material.exponent"), "must be finite and not negative"));
    }
    Ok(Material {
        name: file.get_ref().clone(),
        diffuse,
        specular: colour("specular", spec.specular, defaults.specular)?,
        exponent,
        emission: colour("emission", spec.emission, defaults.emission)?,
        ..defaults
    })
}

/// Appends the scene of one mesh file, placed once per entry of `placements` (each placing
/// the mesh entry's node `own`: a placement is `placement · own`).
fn append(
    scene: &mut Scene,
    sub: Scene,
    placements: &[Affine3A],
    own: &AnimationNode,
    material: Option<Material>,
) {
    let mesh_base = scene.meshes.len() as u32;
    let material_base = scene.materials.len() as u32;
    let mut meshes = sub.meshes;
    match material {
        Some(material) => {
            scene.materials.push(material);
            for mesh in &mut meshes {
                mesh.material_ids.fill(material_base);
            }
        }
        None => {
            for mesh in &mut meshes {
                for id in &mut mesh.material_ids {
                    *id += material_base;
                }
            }
            // Texture indices refer to the scene's one texture set already.
            scene.materials.extend(sub.materials);
        }
    }
    scene.meshes.extend(meshes);
    let animated = own.is_animated() || !sub.animation.is_empty();
    let own_at_rest = own.local(0.0);
    for &outer in placements {
        let placement = outer * own_at_rest;
        let (instance_base, light_base) = (scene.instances.len() as u32, scene.lights.len() as u32);
        scene.instances.extend(sub.instances.iter().map(|instance| Instance {
            mesh: instance.mesh + mesh_base,
            transform: placement * instance.transform,
        }));
        scene.lights.extend(sub.lights.iter().map(|light| transform_light(light, &placement)));
        if !animated {
            continue;
        }
        // A fixed node for the placement and, under it, the entry's own (maybe keyed) node,
        // which carries the file's instances and lights and its own animation's roots.
        let root = scene.animation.nodes.len() as u32;
        scene.animation.nodes.push(AnimationNode::fixed(None, outer));
        scene.animation.nodes.push(AnimationNode { parent: Some(root), ..own.clone() });
        let carrier = root + 1;
        if own.is_animated() {
            let moving = |i: u32| sub.animation.instances.iter().any(|a| a.instance == i);
            let keyed = |l: u32| sub.animation.lights.iter().any(|a| a.light == l);
            for (i, instance) in (0..).zip(&sub.instances).filter(|(i, _)| !moving(*i)) {
                scene.animation.instances.push(AnimatedInstance {
                    instance: instance_base + i,
                    node: carrier,
                    local: instance.transform,
                });
            }
            for (l, light) in (0..).zip(&sub.lights).filter(|(l, _)| !keyed(*l)) {
                scene.animation.lights.push(AnimatedLight {
                    light: light_base + l,
                    rest: light.clone(),
                    node: Some(carrier),
                    position: None,
                    direction: None,
                    power: None,
                });
            }
        }
        scene.animation.append(&sub.animation, instance_base, light_base, Some(carrier));
    }
    if scene.camera.is_none() {
        if let (Some(camera), Some(placement)) = (sub.camera, placements.first().map(|&p| p * own_at_rest)) {
            scene.camera = Some(Camera {
                position: placement.transform_point3(camera.position),
                target: placement.transform_point3(camera.target),
                up: placement.transform_vector3(camera.up).normalize_or(camera.up),
                fov_y_deg: camera.fov_y_deg,
            });
        }
    }
}

fn transform_light(light: &Light, placement: &Affine3A) -> Light {
    let direction = |d: Vec3| placement.transform_vector3(d).normalize_or(d);
    match *light {
        Light::Point { position, intensity } => {
            Light::Point { position: placement.transform_point3(position), intensity }
        }
        Light::Spot { position, direction: d, angle_deg, intensity } => Light::Spot {
            position: placement.transform_point3(position),
            direction: direction(d),
            angle_deg,
            intensity,
        },
        Light::Directional { direction: d, irradiance } => {
            Light::Directional { direction: direction(d), irradiance }
        }
    }
}

fn add_light(
    check: &Checker,
    scene: &mut Scene,
    index: usize,
    entry: &Spanned<LightSpec>,
) -> Result<(), SceneError> {
    let span = entry.span();
    let spec = entry.get_ref();
    let path = |field: &str| format!("light[{index}].{field}");
    let present = [
        ("position", spec.position.is_some()),
        ("u", spec.u.is_some()),
        ("v", spec.v.is_some()),
        ("radiance", spec.radiance.is_some()),
        ("intensity", spec.intensity.is_some()),
        ("direction", spec.direction.is_some()),
        ("angle", spec.angle.is_some()),
        ("irradiance", spec.irradiance.is_some()),
    ];
    for (field, is_present) in present {
        if is_present && !spec.kind.fields().contains(&field) {
            return Err(check.error(
                &span,
                path(field),
                format!("a {} light has no `{field}`", spec.kind.name()),
            ));
        }
    }
    let required = |field: &str, value: Option<[f32; 3]>| {
        value.ok_or_else(|| {
            check.error(&span, path(field), format!("a {} light needs `{field}`", spec.kind.name()))
        })
    };
    let light = match spec.kind {
        LightKind::Quad => {
            let centre = check.vector(&span, path("position"), required("position", spec.position)?)?;
            let u = check.vector(&span, path("u"), required("u", spec.u)?)?;
            let v = check.vector(&span, path("v"), required("v", spec.v)?)?;
            if u.cross(v) == Vec3::ZERO {
                return Err(check.error(&span, path("v"), "u and v must span a quad (u × v is zero)"));
            }
            let radiance = check.colour(&span, path("radiance"), required("radiance", spec.radiance)?)?;
            scene.materials.push(Material {
                name: format!("light[{index}]"),
                diffuse: Vec3::ZERO,
                emission: radiance,
                ..Material::default()
            });
            let material = scene.materials.len() as u32 - 1;
            let mesh = scene.meshes.len() as u32;
            let instance = scene.instances.len() as u32;
            match &spec.animation {
                None => {
                    scene.meshes.push(quad_mesh(format!("light[{index}]"), centre, u, v, material));
                    scene.instances.push(Instance { mesh, transform: Affine3A::IDENTITY });
                }
                Some(animation) => {
                    // A moving quad is built about the origin and placed by its node, whose
                    // translation is the keyed centre and rotation turns it about the centre.
                    let node = quad_node(check, &span, &path(""), centre, animation)?;
                    let transform = node.local(0.0);
                    scene.meshes.push(quad_mesh(format!("light[{index}]"), Vec3::ZERO, u, v, material));
                    scene.instances.push(Instance { mesh, transform });
                    let node_index = scene.animation.nodes.len() as u32;
                    scene.animation.nodes.push(node);
                    scene.animation.instances.push(AnimatedInstance {
                        instance,
                        node: node_index,
                        local: Affine3A::IDENTITY,
                    });
                }
            }
            return Ok(());
        }
        LightKind::Point => Light::Point {
            position: check.vector(&span, path("position"), required("position", spec.position)?)?,
            intensity: check.colour(&span, path("intensity"), required("intensity", spec.intensity)?)?,
        },
        LightKind::Spot => {
            let angle =
                spec.angle.ok_or_else(|| check.error(&span, path("angle"), "a spot light needs `angle`"))?;
            if !(angle > 0.0 && angle <= 180.0) {
                return Err(check.error(
                    &span,
                    path("angle"),
                    "the full cone angle must be in (0, 180] degrees",
                ));
            }
            Light::Spot {
                position: check.vector(&span, path("position"), required("position", spec.position)?)?,
                direction: check.direction(
                    &span,
                    path("direction"),
                    required("direction", spec.direction)?,
                )?,
                angle_deg: angle,
                intensity: check.colour(&span, path("intensity"), required("intensity", spec.intensity)?)?,
            }
        }
        LightKind::Directional => Light::Directional {
            direction: check.direction(&span, path("direction"), required("direction", spec.direction)?)?,
            irradiance: check.colour(&span, path("irradiance"), required("irradiance", spec.irradiance)?)?,
        },
    };
    if let Some(animation) = &spec.animation {
        let animated = light_animation(check, &span, &path(""), spec.kind, &light, animation)?;
        let light_index = scene.lights.len() as u32;
        scene.animation.lights.push(AnimatedLight { light: light_index, ..animated });
    }
    scene.lights.push(light);
    Ok(())
}

/// The node of a keyed quad light: rest at its centre, with `position` and `rotate` tracks.
fn quad_node(
    check: &Checker,
    span: &Range<usize>,
    path: &str,
    centre: Vec3,
    spec: &AnimationSpec,
) -> Result<AnimationNode, SceneError> {
    let path = format!("{path}animation.");
    check.keys(span, &path, spec, LightKind::Quad.keyed_fields(), "a quad light")?;
    let translation = check.track(span, &path, spec, "position", |key, at| {
        key.position.map(|v| check.vector(span, at, v)).transpose()
    })?;
    let rotation = check.track(span, &path, spec, "rotate", |key, at| {
        key.rotate.map(|v| check.vector(span, at, v)).transpose()
    })?;
    let period =
        [translation.as_ref(), rotation.as_ref()].into_iter().flatten().map(Track::end).fold(0.0, f32::max);
    Ok(AnimationNode {
        translation: looped(translation, spec, period),
        rotation: looped(rotation, spec, period).map(RotationTrack::EulerDegrees),
        ..AnimationNode::fixed(None, Affine3A::from_translation(centre))
    })
}

/// The tracks of a keyed point, spot or directional light (its index is set by the caller).
fn light_animation(
    check: &Checker,
    span: &Range<usize>,
    path: &str,
    kind: LightKind,
    light: &Light,
    spec: &AnimationSpec,
) -> Result<AnimatedLight, SceneError> {
    let path = format!("{path}animation.");
    check.keys(span, &path, spec, kind.keyed_fields(), &format!("a {} light", kind.name()))?;
    let position = check.track(span, &path, spec, "position", |key, at| {
        key.position.map(|v| check.vector(span, at, v)).transpose()
    })?;
    let direction = check.track(span, &path, spec, "direction", |key, at| {
        key.direction.map(|v| check.direction(span, at, v)).transpose()
    })?;
    let power_field = if matches!(kind, LightKind::Directional) { "irradiance" } else { "intensity" };
    let power = check.track(span, &path, spec, power_field, |key, at| {
        key.intensity.or(key.irradiance).map(|v| check.colour(span, at, v)).transpose()
    })?;
    let period = [position.as_ref(), direction.as_ref(), power.as_ref()]
        .into_iter()
        .flatten()
        .map(Track::end)
        .fold(0.0, f32::max);
    Ok(AnimatedLight {
        light: 0,
        rest: light.clone(),
        node: None,
        position: looped(position, spec, period),
        direction: looped(direction, spec, period),
        power: looped(power, spec, period),
    })
}

/// The [`ShaderDesc`] of `[[shader]]` entry `index`, every parameter checked.
fn shader_from(check: &Checker, index: usize, entry: &Spanned<ShaderSpec>) -> Result<ShaderDesc, SceneError> {
    let span = entry.span();
    let spec = entry.get_ref();
    let path = |field: &str| format!("shader[{index}].{field}");
    let present = [
        ("octaves", spec.octaves.is_some()),
        ("turbulence", spec.turbulence.is_some()),
        ("rings", spec.rings.is_some()),
        ("size", spec.size.is_some()),
        ("mortar", spec.mortar.is_some()),
    ];
    for (field, is_present) in present {
        if is_present && !spec.kind.fields().contains(&field) {
            return Err(check.error(
                &span,
                path(field),
                format!("a {} shader has no `{field}`", spec.kind.name()),
            ));
        }
    }
    let octaves = || {
        let octaves = spec.octaves.unwrap_or(DEFAULT_OCTAVES);
        if (1..=MAX_OCTAVES).contains(&octaves) {
            Ok(octaves)
        } else {
            Err(check.error(&span, path("octaves"), format!("must be 1 to {MAX_OCTAVES}")))
        }
    };
    let turbulence =
        |default: f32| check.amount(&span, path("turbulence"), spec.turbulence.unwrap_or(default), true);
    let pattern = match spec.kind {
        ShaderKind::Checker => Pattern::Checker,
        ShaderKind::Marble => {
            Pattern::Marble { octaves: octaves()?, turbulence: turbulence(MARBLE_TURBULENCE)? }
        }
        ShaderKind::Wood => Pattern::Wood {
            rings: check.amount(&span, path("rings"), spec.rings.unwrap_or(WOOD_RINGS), false)?,
            turbulence: turbulence(WOOD_TURBULENCE)?,
        },
        ShaderKind::Brick => {
            let size = check.vector(&span, path("size"), spec.size.unwrap_or(BRICK_SIZE))?;
            if size.min_element() <= 0.0 {
                return Err(check.error(&span, path("size"), "brick dimensions must be positive"));
            }
            let mortar = check.amount(&span, path("mortar"), spec.mortar.unwrap_or(BRICK_MORTAR), true)?;
            if mortar >= size.min_element() {
                return Err(check.error(
                    &span,
                    path("mortar"),
                    "the mortar must be narrower than every brick dimension",
                ));
            }
            Pattern::Brick { size, mortar }
        }
        ShaderKind::Turbulence => Pattern::Turbulence { octaves: octaves()? },
    };
    let [first, second] = spec.colors.unwrap_or(SHADER_COLORS);
    Ok(ShaderDesc {
        pattern,
        scale: check.amount(&span, path("scale"), spec.scale.unwrap_or(1.0), false)?,
        colors: [
            check.reflectance(&span, path("colors"), first)?,
            check.reflectance(&span, path("colors"), second)?,
        ],
        specular: check.reflectance(&span, path("specular"), spec.specular.unwrap_or_default())?,
        exponent: check.amount(&span, path("exponent"), spec.exponent.unwrap_or(SHADER_EXPONENT), true)?,
        bump: check.amount(&span, path("bump"), spec.bump.unwrap_or(0.0), true)?,
    })
}

/// Gives `shader` to the materials named `target` or, if there are none, to the triangles of
/// the meshes named `target` (through copies of their materials). False if nothing matched.
fn assign_shader(scene: &mut Scene, target: &str, shader: &ShaderDesc) -> bool {
    let mut matched = false;
    for material in scene.materials.iter_mut().filter(|m| m.name == target) {
        material.shader = Some(shader.clone());
        matched = true;
    }
    if matched {
        return true;
    }
    // One copy per original material, shared by every mesh of that name.
    let mut copies: std::collections::HashMap<u32, u32> = std::collections::HashMap::new();
    for mesh in scene.meshes.iter_mut().filter(|m| m.name == target) {
        matched = true;
        for id in &mut mesh.material_ids {
            *id = *copies.entry(*id).or_insert_with(|| {
                let mut copy = scene.materials.get(*id as usize).cloned().unwrap_or_default();
                copy.shader = Some(shader.clone());
                scene.materials.push(copy);
                scene.materials.len() as u32 - 1
            });
        }
    }
    matched
}

/// Two triangles c−u−v, c+u−v, c+u+v and c−u−v, c+u+v, c−u+v: counter-clockwise seen from
/// the side u × v points to, so that is the side they face and emit to.
fn quad_mesh(name: String, centre: Vec3, u: Vec3, v: Vec3, material: u32) -> Mesh {
    Mesh {
        name,
        positions: vec![centre - u - v, centre + u - v, centre + u + v, centre - u + v],
        normals: None,
        uvs: None,
        indices: vec![[0, 1, 2], [0, 2, 3]],
        material_ids: vec![material; 2],
    }
}

fn camera_from(check: &Checker, camera: &Spanned<CameraSpec>) -> Result<Camera, SceneError> {
    let span = camera.span();
    let spec = camera.get_ref();
    let camera = Camera {
        position: spec.position.into(),
        target: spec.target.into(),
        up: spec.up.into(),
        fov_y_deg: spec.fov,
    };
    camera.check().map_err(|d| check.error(&span, format!("camera.{}", d.field), d.problem))?;
    Ok(Camera { up: camera.up.normalize(), ..camera })
}

/// 1-based line of a byte offset.
/// Largest scene file. Scene files place and light meshes that live in files of their own;
/// a scene of [`MAX_INSTANCES`] instances takes a few MiB.
const MAX_SCENE_FILE_BYTES: usize = 16 << 20;
/// Most inline tables (`{ ... }`) a scene file may hold: one per instance, and as many again
/// for keyframes and materials.
const MAX_INLINE_TABLES: usize = 2 * MAX_INSTANCES;

/// Bounds what parsing `text` can take before it is parsed. `toml` holds each inline table of a
/// document in a map of about a kilobyte, so a file of ten million short `{}` entries would
/// take gigabytes before the instance count could be checked.
fn check_size(text: &str, file: &Path) -> Result<(), SceneError> {
    let refuse = |message: String| Err(SceneError::invalid(file, Location::File, message));
    if text.len() > MAX_SCENE_FILE_BYTES {
        return refuse(format!(
            "{} bytes; a scene file may have at most {MAX_SCENE_FILE_BYTES} (meshes belong in mesh files)",
            text.len()
        ));
    }
    // Counting braces over-counts (a brace in a string), never under-counts.
    let tables = text.bytes().filter(|&b| b == b'{').count();
    if tables > MAX_INLINE_TABLES {
        return refuse(format!(
            "{tables} inline tables (`{{ ... }}`); a scene file may have at most {MAX_INLINE_TABLES} \
             (a scene at most {} instances)",
            MAX_INSTANCES
        ));
    }
    Ok(())
}

fn line_of(text: &str, offset: usize) -> usize {
    text.as_bytes()[..offset.min(text.len())].iter().filter(|&&b| b == b'\n').count() + 1
}

/// A `toml` error as a [`SceneError`] pointing at the line and, where it can be told, the
/// field (`mesh[1].scale`).
fn toml_error(error: &toml::de::Error, text: &str, file: &Path) -> SceneError {
    let message = error.message().trim().to_owned();
    let Some(span) = error.span() else {
        return SceneError::parse(file, Location::File, message);
    };
    let line = line_of(text, span.start);
    let location = match field_spans::path_at(text, span.start) {
        Some(path) => Location::Field { line: Some(line), path },
        None => Location::Line(line),
    };
    SceneError::parse(file, location, message)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse_str(text: &str) -> Result<Scene, SceneError> {
        parse(text, "s.toml", None, &mut LoadReport::default())
    }

    #[test]
    fn unknown_fields_are_named_with_their_line() {
        let err = parse_str("[camera]\nposition = [0, 1, 3.5]\ntarget = [0, 1, 0]\nfov = 39.3\nzoom = 2\n")
            .unwrap_err();
        let text = err.to_string();
        assert!(text.starts_with("s.toml: line 5, field `camera.zoom`: "), "{text}");
        assert!(text.contains("unknown field `zoom`"), "{text}");

        let err = parse_str("[[light]]\ntype = \"point\"\nposition = [0, 0, 0]\nintensity = [1, 1, 1]\n\n[[light]]\ntype = \"point\"\nposition = [0, 0, 0]\npower = [1, 1, 1]\n").unwrap_err();
        let text = err.to_string();
        assert!(text.contains("line 9, field `light[1].power`"), "{text}");
    }

    #[test]
    fn malformed_toml_names_the_line() {
        let err = parse_str("[camera]\nposition = [0, 1,\n").unwrap_err();
        assert!(err.to_string().starts_with("s.toml: line "), "{err}");
        let err =
            parse_str("[camera]\nposition = [0, 1, 3]\ntarget = [0, 1, 0]\nfov = \"wide\"\n").unwrap_err();
        assert!(err.to_string().contains("line 4, field `camera.fov`"), "{err}");
        let err = parse_str("[[mesh]]\nfile = \"a.obj\"\nscale = \"big\"\n").unwrap_err();
        assert_eq!(
            err.to_string(),
            "s.toml: line 3, field `mesh[0].scale`: expected a number or an array of three numbers"
        );
    }

    #[test]
    fn semantic_errors_name_the_field() {
        let err = parse_str("[[light]]\ntype = \"spot\"\nposition = [0, 0, 0]\ndirection = [0, 0, 0]\nangle = 30\nintensity = [1, 1, 1]\n").unwrap_err();
        // The line of the field, not of its table's header.
        assert!(
            err.to_string().contains("line 4, field `light[0].direction`: direction must not be zero"),
            "{err}"
        );
        let err = parse_str("[camera]\nposition = [0, 1, 0]\ntarget = [0, 1, 0]\nfov = 40\n").unwrap_err();
        assert!(err.to_string().contains("line 3, field `camera.target`"), "{err}");
        let err =
            parse_str("[[mesh]]\nfile = \"a.obj\"\ninstances = [\n  { scale = 1 },\n  { scale = 0 },\n]\n")
                .unwrap_err();
        assert!(err.to_string().contains("line 5, field `mesh[0].instances[1].scale`"), "{err}");
        let err = parse_str(
            "[[mesh]]\nfile = \"a.obj\"\ninstances = [\n  { scale = 1 },\n  { scale = \"x\" },\n]\n",
        )
        .unwrap_err();
        assert!(err.to_string().contains("line 5, field `mesh[0].instances[1].scale`"), "{err}");
        let err = parse_str("[[light]]\ntype = \"point\"\nposition = [0, 0, 0]\nradiance = [1, 1, 1]\n")
            .unwrap_err();
        assert!(err.to_string().contains("a point light has no `radiance`"), "{err}");
        let err = parse_str("[[light]]\ntype = \"area\"\n").unwrap_err();
        assert!(err.to_string().contains("line 2, field `light[0].type`"), "{err}");
        let err = parse_str("[[light]]\ntype = \"point\"\nposition = [0, nan, 0]\nintensity = [1, 1, 1]\n")
            .unwrap_err();
        assert!(err.to_string().contains("light[0].position"), "{err}");
    }

    #[test]
    fn quad_light_faces_u_cross_v() {
        let scene = parse_str("[[light]]\ntype = \"quad\"\nposition = [0, 2, 0]\nu = [0.5, 0, 0]\nv = [0, 0, 0.25]\nradiance = [10, 10, 10]\n").unwrap();
        let mesh = &scene.meshes[0];
        let normal = mesh.triangle_normal(0);
        let expected = Vec3::X.cross(Vec3::Z);
        assert_eq!(expected, -Vec3::Y);
        for t in 0..2 {
            assert!((mesh.triangle_normal(t) - expected).length() < 1e-6);
        }
        assert!((normal - expected).length() < 1e-6);
        assert_eq!(scene.materials[0].emission, Vec3::splat(10.0));
        assert_eq!(scene.materials[0].diffuse, Vec3::ZERO);
        assert_eq!(scene.emissive_triangle_count(), 2);
    }

    #[test]
    fn rotation_order_is_x_then_y_then_z() {
        let check = Checker { file: Path::new("s.toml"), text: "" };
        let t = check.transform(&(0..0), String::new, None, Some([90.0, 90.0, 0.0]), None).unwrap();
        // X first takes +Y to +Z, then Y takes +Z to +X.
        assert!((t.transform_vector3(Vec3::Y) - Vec3::X).length() < 1e-6);
        let t = check
            .transform(
                &(0..0),
                String::new,
                Some([1.0, 2.0, 3.0]),
                Some([0.0, 0.0, 90.0]),
                Some(Scale::Axes([2.0, 1.0, 1.0])),
            )
            .unwrap();
        // Scale, then rotate, then translate: +X → (2,0,0) → (0,2,0) → (1,4,3).
        assert!((t.transform_point3(Vec3::X) - Vec3::new(1.0, 4.0, 3.0)).length() < 1e-5);
    }

    /// A quad light (material and mesh `light[0]`) followed by `shader`.
    fn with_shader(shader: &str) -> Result<Scene, SceneError> {
        parse_str(&format!(
            "[[light]]\ntype = \"quad\"\nposition = [0, 2, 0]\nu = [1, 0, 0]\nv = [0, 0, 1]\nradiance = [1, 1, 1]\n\n[[shader]]\ntarget = \"light[0]\"\n{shader}"
        ))
    }

    fn shader_of(shader: &str) -> ShaderDesc {
        let scene = with_shader(shader).unwrap_or_else(|e| panic!("{e}"));
        scene.materials[0].shader.clone().expect("the shader is assigned")
    }

    #[test]
    fn every_shader_type_parses_with_its_parameters_and_defaults() {
        let common = ShaderDesc {
            pattern: Pattern::Checker,
            scale: 1.0,
            colors: [Vec3::splat(0.8), Vec3::splat(0.2)],
            specular: Vec3::ZERO,
            exponent: 20.0,
            bump: 0.0,
        };
        assert_eq!(shader_of("type = \"checker\"\n"), common);
        let full = shader_of(
            "type = \"checker\"\nscale = 2.5\ncolors = [[0.9, 0.9, 0.85], [0.3, 0.3, 0.35]]\nspecular = [0.05, 0.05, 0.05]\nexponent = 40\nbump = 0.002\n",
        );
        assert_eq!(
            full,
            ShaderDesc {
                scale: 2.5,
                colors: [Vec3::new(0.9, 0.9, 0.85), Vec3::new(0.3, 0.3, 0.35)],
                specular: Vec3::splat(0.05),
                exponent: 40.0,
                bump: 0.002,
                ..common.clone()
            }
        );
        let cases = [
            ("type = \"marble\"\n", Pattern::Marble { octaves: 4, turbulence: 5.0 }),
            (
                "type = \"marble\"\noctaves = 7\nturbulence = 2.5\n",
                Pattern::Marble { octaves: 7, turbulence: 2.5 },
            ),
            ("type = \"wood\"\n", Pattern::Wood { rings: 4.0, turbulence: 0.5 }),
            ("type = \"wood\"\nrings = 12\nturbulence = 0\n", Pattern::Wood { rings: 12.0, turbulence: 0.0 }),
            ("type = \"brick\"\n", Pattern::Brick { size: Vec3::new(3.0, 1.0, 1.5), mortar: 0.1 }),
            (
                "type = \"brick\"\nsize = [2, 0.5, 1]\nmortar = 0.05\n",
                Pattern::Brick { size: Vec3::new(2.0, 0.5, 1.0), mortar: 0.05 },
            ),
            ("type = \"turbulence\"\n", Pattern::Turbulence { octaves: 4 }),
            ("type = \"turbulence\"\noctaves = 16\n", Pattern::Turbulence { octaves: 16 }),
        ];
        for (text, pattern) in cases {
            assert_eq!(shader_of(text), ShaderDesc { pattern, ..common.clone() }, "{text}");
        }
    }

    #[test]
    fn bad_shader_parameters_name_the_file_and_field() {
        // (fields after `target`, field named, part of the message)
        let cases = [
            ("type = \"plaid\"\n", "shader[0].type", "unknown variant `plaid`"),
            ("type = \"checker\"\nscale = 0\n", "shader[0].scale", "positive"),
            ("type = \"checker\"\nscale = -2\n", "shader[0].scale", "positive"),
            ("type = \"checker\"\nscale = inf\n", "shader[0].scale", "finite"),
            ("type = \"checker\"\nscale = nan\n", "shader[0].scale", "finite"),
            ("type = \"checker\"\ncolors = [[1.5, 0, 0], [0, 0, 0]]\n", "shader[0].colors", "[0, 1]"),
            ("type = \"checker\"\ncolors = [[1, 1, 1], [0, -0.1, 0]]\n", "shader[0].colors", "negative"),
            ("type = \"checker\"\ncolors = [[1, 1], [0, 0, 0]]\n", "shader[0].colors", "length"),
            ("type = \"checker\"\ncolors = [[1, 1, 1]]\n", "shader[0].colors", "length"),
            ("type = \"checker\"\nspecular = [2, 2, 2]\n", "shader[0].specular", "[0, 1]"),
            ("type = \"checker\"\nexponent = -1\n", "shader[0].exponent", "not negative"),
            ("type = \"checker\"\nbump = nan\n", "shader[0].bump", "finite"),
            ("type = \"marble\"\noctaves = 0\n", "shader[0].octaves", "1 to 16"),
            ("type = \"turbulence\"\noctaves = 17\n", "shader[0].octaves", "1 to 16"),
            ("type = \"turbulence\"\noctaves = -1\n", "shader[0].octaves", "u32"),
            ("type = \"wood\"\nrings = 0\n", "shader[0].rings", "positive"),
            ("type = \"marble\"\nturbulence = -1\n", "shader[0].turbulence", "not negative"),
            ("type = \"brick\"\nsize = [1, 0, 1]\n", "shader[0].size", "positive"),
            ("type = \"brick\"\nsize = [1, 1, 1]\nmortar = 1\n", "shader[0].mortar", "narrower"),
            ("type = \"checker\"\noctaves = 3\n", "shader[0].octaves", "a checker shader has no `octaves`"),
            ("type = \"wood\"\nsize = [1, 1, 1]\n", "shader[0].size", "a wood shader has no `size`"),
            ("type = \"checker\"\ncolour = [1, 1, 1]\n", "shader[0].colour", "unknown field `colour`"),
        ];
        for (text, field, message) in cases {
            let err = with_shader(text).expect_err(text).to_string();
            assert!(err.starts_with("s.toml: line "), "{text}: {err}");
            assert!(err.contains(&format!("field `{field}`: ")), "{text}: {err}");
            assert!(err.contains(message), "{text}: {err}");
        }
        let err = with_shader("type = \"checker\"\n\n[[shader]]\ntarget = \"nothing\"\ntype = \"wood\"\n")
            .unwrap_err()
            .to_string();
        assert_eq!(
            err,
            "s.toml: line 13, field `shader[1].target`: `nothing` is neither a material nor a mesh name"
        );
    }

    #[test]
    fn a_mesh_target_copies_only_that_meshs_materials() {
        let triangle = |name: &str, material: u32| Mesh {
            name: name.into(),
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
            indices: vec![[0, 1, 2], [0, 2, 1]],
            material_ids: vec![material, 1],
            ..Mesh::default()
        };
        let mut scene = Scene {
            meshes: vec![triangle("floor", 0), triangle("wall", 0), triangle("floor", 0)],
            materials: vec![
                Material { name: "stone".into(), ..Material::default() },
                Material { name: "plaster".into(), ..Material::default() },
            ],
            ..Scene::default()
        };
        let shader = shader_of("type = \"checker\"\n");
        assert!(assign_shader(&mut scene, "floor", &shader));
        assert_eq!(scene.materials.len(), 4, "one copy of each material the meshes use");
        assert_eq!(scene.meshes[0].material_ids, vec![2, 3]);
        assert_eq!(scene.meshes[2].material_ids, vec![2, 3], "meshes of one name share the copies");
        assert_eq!(scene.meshes[1].material_ids, vec![0, 1], "the wall is untouched");
        assert!(scene.materials[..2].iter().all(|m| m.shader.is_none()));
        assert_eq!(
            (scene.materials[2].name.as_str(), scene.materials[3].name.as_str()),
            ("stone", "plaster")
        );
        assert!(scene.materials[2..].iter().all(|m| m.shader.as_ref() == Some(&shader)));

        // A material name wins over a mesh name and reaches every material of that name,
        // the copies included.
        let marble = shader_of("type = \"marble\"\n");
        assert!(assign_shader(&mut scene, "stone", &marble));
        assert_eq!(scene.materials[0].shader.as_ref(), Some(&marble));
        assert_eq!(scene.materials[2].shader.as_ref(), Some(&marble));
        assert_eq!(scene.materials[3].shader.as_ref(), Some(&shader));
        assert!(!assign_shader(&mut scene, "ceiling", &marble));
    }

    #[test]
    fn unchecked_targets_warn_when_parsing_from_memory() {
        let mut report = LoadReport::default();
        let scene = parse(
            "[[mesh]]\nfile = \"room.obj\"\n\n[[shader]]\ntarget = \"floor\"\ntype = \"checker\"\n",
            "s.toml",
            None,
            &mut report,
        )
        .unwrap();
        assert!(scene.materials.is_empty());
        assert_eq!(report.warnings.len(), 2, "{report:?}");
        assert!(report.warnings[1].contains("shader[0].target: `floor`"), "{report:?}");
    }

    #[test]
    fn constant_environment_and_its_errors() {
        let scene = parse_str("[environment]\ncolor = [0.4, 0.6, 2.5]\n").unwrap();
        assert_eq!(scene.environment, Some(Environment::Constant { radiance: Vec3::new(0.4, 0.6, 2.5) }));
        assert!(scene.textures.is_empty());
        assert_eq!(parse_str("").unwrap().environment, None);
        let cases = [
            ("color = [1, -1, 1]\n", "field `environment.color`: values must not be negative"),
            ("color = [1, nan, 1]\n", "field `environment.color`: values must be finite"),
            ("color = [1, 1]\n", "field `environment.color`: invalid length 2"),
            (
                "color = [1, 1, 1]\nfile = \"sky.hdr\"\n",
                "field `environment.file`: give either `color` or `file`",
            ),
            ("intensity = 2\n", "field `environment`: needs `color` or `file`"),
            ("color = [1, 1, 1]\nintensity = 2\n", "field `environment.intensity`: a constant environment"),
            ("color = [1, 1, 1]\nrotate = 90\n", "field `environment.rotate`: a constant environment"),
            (
                "file = \"sky.hdr\"\nintensity = -1\n",
                "field `environment.intensity`: must be finite and not negative",
            ),
            ("file = \"sky.hdr\"\nrotate = inf\n", "field `environment.rotate`: must be finite"),
            ("colour = [1, 1, 1]\n", "field `environment.colour`: unknown field `colour`"),
        ];
        for (text, expected) in cases {
            let err = parse_str(&format!("[environment]\n{text}")).expect_err(text).to_string();
            assert!(err.starts_with("s.toml: line "), "{text}: {err}");
            assert!(err.contains(expected), "{text}: {err}");
        }
        let mut report = LoadReport::default();
        let scene = parse("[environment]\nfile = \"sky.hdr\"\n", "s.toml", None, &mut report).unwrap();
        assert_eq!(scene.environment, None);
        assert!(report.warnings[0].contains("environment.file `sky.hdr` not loaded"), "{report:?}");
    }
}
