//! The scene side of igi: the scene model every loader produces and every renderer consumes,
//! the loaders, and the built-in scenes.
//!
//! - Model: [`Scene`] holds [`Mesh`]es placed by [`Instance`]s, [`Material`]s, [`Texture`]s,
//!   punctual [`Light`]s, an optional [`Environment`] (sky) and an optional [`Camera`]. Area
//!   lights are triangles with an emissive material.
//! - Loading: [`load`] picks the format from the file extension: Wavefront OBJ/MTL
//!   ([`obj`], [`mtl`]), glTF 2.0 ([`gltf_loader`]), Stanford PLY ([`ply`]) and igi's own TOML
//!   scene files ([`scene_file`]) that place such files and add lights and a camera.
//!   [`load_with_report`] also returns the [`LoadReport`] (dropped triangles, warnings);
//!   [`load_named`] accepts a built-in scene name ([`builtin_names`]) as well as a path.
//! - Every format module also parses from memory (`parse`), which is what the fuzz targets and
//!   property tests drive.
//!
//! What every loader guarantees, whatever the input: no panic; no allocation sized by a count
//! the file cannot back with bytes; an error ([`SceneError`]) that names the file and, where
//! the format allows, the line, element, JSON path or field; and meshes that keep the
//! invariants documented on [`Mesh`] (finite, indices in range, no zero-area triangles, unit
//! normals). What can be repaired without changing the scene's meaning is repaired with a
//! warning instead of failing: zero-area triangles are dropped and counted, a missing
//! texture or material library falls back to constant colours, an undefined OBJ material
//! gets a default.

pub mod animation;
mod builtin;
mod digest;
mod environment;
mod error;
pub mod gltf_loader;
mod model;
pub mod mtl;
pub mod obj;
pub mod ply;
mod report;
mod resources;
pub mod scene_file;
mod shader;
mod texels;
mod texture;
mod validate;

use std::path::Path;

pub use animation::{Animation, Interpolation, Pose, Track};
pub use builtin::{builtin, builtin_names};
pub use environment::Environment;
pub use error::{Location, SceneError};
pub use model::CameraDefect;
pub use model::{Camera, Instance, Light, Material, MaterialKind, Mesh, Scene, Texture, Wrap};
pub use report::LoadReport;
pub use resources::read_regular_file;
pub use shader::{Pattern, ShaderDesc};
pub use texels::{ColorSpace, Image, Texels, srgb_to_linear};
pub use texture::DEFAULT_TEXTURE_BUDGET;
use texture::TextureSet;

/// The file formats [`load`] reads, by extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Format {
    Obj,
    Gltf,
    Ply,
    SceneFile,
}

fn format_of(path: &Path) -> Option<Format> {
    let extension = path.extension()?.to_str()?.to_ascii_lowercase();
    match extension.as_str() {
        "obj" => Some(Format::Obj),
        "gltf" | "glb" => Some(Format::Gltf),
        "ply" => Some(Format::Ply),
        "toml" => Some(Format::SceneFile),
        _ => None,
    }
}

/// Refuses a scene of more than [`MAX_INSTANCES`] instances.
pub(crate) fn check_instance_count(file: &Path, count: usize) -> Result<(), SceneError> {
    if count <= MAX_INSTANCES {
        return Ok(());
    }
    Err(SceneError::invalid(
        file,
        Location::File,
        format!("{count} instances; a scene may have at most {MAX_INSTANCES}"),
    ))
}

/// True if `path` names a mesh file (`.obj`, `.gltf`, `.glb`, `.ply`).
pub(crate) fn is_model_file(path: &Path) -> bool {
    matches!(format_of(path), Some(Format::Obj | Format::Gltf | Format::Ply))
}

/// Loads a mesh file (`.obj`, `.gltf`, `.glb`, `.ply`): what a scene file may place. Its
/// textures go into `textures` (the scene's).
pub(crate) fn load_model_file(
    path: &Path,
    textures: &mut TextureSet,
    report: &mut LoadReport,
) -> Result<Scene, SceneError> {
    match format_of(path) {
        Some(Format::Obj) => obj::load_into(path, textures, report),
        Some(Format::Gltf) => gltf_loader::load_into(path, textures, report),
        Some(Format::Ply) => ply::load(path, report),
        Some(Format::SceneFile) | None => {
            Err(SceneError::UnknownFormat { file: path.to_path_buf(), builtin_hint: false })
        }
    }
}

/// Loads a scene from a file, choosing the format by extension: `.obj`, `.gltf`, `.glb`,
/// `.ply` or `.toml` (scene file). Warnings are logged through `tracing`; use
/// [`load_with_report`] to get them as data.
pub fn load(path: impl AsRef<Path>) -> Result<Scene, SceneError> {
    load_with_report(path).map(|(scene, _)| scene)
}

/// Like [`load`], and also returns what the load repaired or skipped.
pub fn load_with_report(path: impl AsRef<Path>) -> Result<(Scene, LoadReport), SceneError> {
    load_with(path.as_ref(), &LoadOptions::default())
}

/// Most instances a scene may have. Far above real scenes (the paper's largest has four), it
/// bounds what a hostile file can cost: every ray may meet every instance when they overlap,
/// and 100,000 coincident instances still render a small frame in seconds.
pub const MAX_INSTANCES: usize = 100_000;

/// What a load may take.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LoadOptions {
    /// Bytes that all textures of the scene, with their mipmaps, may occupy
    /// ([`DEFAULT_TEXTURE_BUDGET`] unless set). An image that does not fit what is left is
    /// downscaled, with a warning.
    pub texture_budget: u64,
}

impl Default for LoadOptions {
    fn default() -> Self {
        Self { texture_budget: DEFAULT_TEXTURE_BUDGET }
    }
}

/// Loads a scene file or mesh file with `options`, and returns what the load repaired or
/// skipped.
pub fn load_with(path: &Path, options: &LoadOptions) -> Result<(Scene, LoadReport), SceneError> {
    let mut report = LoadReport::default();
    let scene = TextureSet::with_budget(options.texture_budget).owning(|textures| {
        if format_of(path) == Some(Format::SceneFile) {
            scene_file::load_into(path, textures, &mut report)
        } else {
            load_model_file(path, textures, &mut report)
        }
    })?;
    check_instance_count(path, scene.instances.len())?;
    Ok((scene, report))
}

/// Loads `spec`: a built-in scene if it is one of [`builtin_names`], otherwise a file as
/// [`load`] does.
pub fn load_named(spec: &str) -> Result<Scene, SceneError> {
    load_named_with_report(spec).map(|(scene, _)| scene)
}

/// Like [`load_named`], and also returns the [`LoadReport`] (empty for a built-in scene).
pub fn load_named_with_report(spec: &str) -> Result<(Scene, LoadReport), SceneError> {
    load_named_with(spec, &LoadOptions::default())
}

/// Like [`load_named_with_report`], with `options`.
pub fn load_named_with(spec: &str, options: &LoadOptions) -> Result<(Scene, LoadReport), SceneError> {
    if let Some(scene) = builtin(spec) {
        return Ok((scene, LoadReport::default()));
    }
    let path = Path::new(spec);
    if format_of(path).is_none() {
        return Err(SceneError::UnknownFormat { file: path.to_path_buf(), builtin_hint: true });
    }
    load_with(path, options)
}
