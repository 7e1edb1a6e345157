//! The scene side of igi: the scene model every loader produces and every renderer consumes,
//! the loaders, and the built-in scenes.
//!
//! - Model: [`Scene`] holds [`Mesh`]es placed by [`Instance`]s, [`Material`]s, [`Texture`]s,
//!   punctual [`Light`]s, an optional [`Environment`] (sky) and an optional [`Camera`]. Area
//!   lights are triangles with an emissive material.
//! - Loading: [`load`] picks the format from the file extension: Wavefront OBJ/MTL
//!   (`obj`, [`mtl`]), glTF 2.0 (`gltf_loader`), Stanford PLY (`ply`) and igi's own TOML
//!   scene files ([`scene_file`]) that place such files and add lights and a camera.
//!   [`load_with_report`] also returns the [`LoadReport`] (dropped triangles, warnings);
//!   [`load_named`] accepts a built-in scene name ([`builtin_names`]) as well as a path;
//!   [`scene_files_under`] lists the scene files of a folder (the viewers' "open scene").
//! - Every format also parses from memory ([`parse_mesh`] for the mesh files, [`mtl::parse`],
//!   [`scene_file::parse`]), which is what the fuzz targets and property tests drive.
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
mod format;
mod gltf_loader;
mod light;
mod model;
pub mod mtl;
mod obj;
mod ply;
mod report;
mod resources;
pub mod scene_file;
mod scene_files;
mod shader;
mod statements;
mod texels;
mod texture;
mod validate;

use std::path::Path;

pub use animation::{Animation, Pose, Track};
pub use builtin::{MAX_GENERATED_TRIANGLES, builtin, builtin_names, builtin_spec, closest_builtin};
pub use environment::Environment;
pub use error::{Location, SceneError};
use format::{Format, format_of};
pub use format::{MeshFormat, parse_mesh};
pub use gltf_loader::GLTF_READ_BUDGET;
pub use light::Light;
pub use model::CameraDefect;
pub use model::{
    AlphaMask, Camera, CoverageChannel, Instance, Material, MaterialKind, Mesh, SavedView, Scene, Texture,
    Wrap,
};
pub use report::LoadReport;
pub use resources::read_regular_file;
pub use scene_files::{MAX_CATALOG_FILES, name_under, scene_files_under};
pub use shader::{Pattern, ShaderDesc};
pub use texels::{ColorSpace, Image, Texels, srgb_to_linear};
use texture::TextureSet;
pub use texture::{DEFAULT_TEXTURE_BUDGET, SKY_BYTES_PER_TEXEL};
pub use validate::MAX_INSTANCES;
use validate::check_instance_count;

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
            format::load_model_file(path, textures, &mut report)
        }
    })?;
    check_instance_count(path, scene.instances.len())?;
    check_placed_bounds(path, &scene)?;
    Ok((scene, report))
}

/// The largest coordinate placed geometry may have, in scene units. The renderer squares
/// distances and the scene's radius in 32-bit floats (a directional light's power is its
/// irradiance times πR²), so coordinates far below f32's 3.4e38 already overflow: a
/// `scale = 3e38` made the bounds infinite, and the renderer found no light paths and drew
/// nothing, without a word.
pub const MAX_COORDINATE: f32 = 1e15;

/// Refuses a scene whose placed geometry reaches beyond [`MAX_COORDINATE`].
fn check_placed_bounds(path: &Path, scene: &Scene) -> Result<(), SceneError> {
    let bounds: Vec<igi_bvh::Aabb> = scene.meshes.iter().map(Mesh::bounds).collect();
    for (k, instance) in scene.instances.iter().enumerate() {
        let Some(b) = bounds.get(instance.mesh as usize).filter(|b| !b.is_empty()) else { continue };
        let inside = |p: glam::Vec3| p.is_finite() && p.abs().max_element() <= MAX_COORDINATE;
        if !b.corners().iter().all(|&p| inside(instance.transform.transform_point3(p))) {
            return Err(SceneError::invalid(
                path,
                Location::File,
                format!(
                    "mesh `{}` (instance {k}) is placed beyond {MAX_COORDINATE:e} scene units, where \
                     32-bit floats no longer hold its distances (a scale or translation too large)",
                    scene.meshes[instance.mesh as usize].name
                ),
            ));
        }
    }
    Ok(())
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
    let start = std::time::Instant::now();
    let (scene, report) = if let Some(scene) = builtin_spec(spec) {
        (scene?, LoadReport::default())
    } else {
        let path = Path::new(spec);
        if format_of(path).is_none() {
            let folder = path.is_dir().then(|| scene_files_in(path));
            let closest = if folder.is_some() { None } else { closest_builtin(spec) };
            return Err(SceneError::UnknownScene { name: spec.to_string(), closest, folder });
        }
        load_with(path, options)?
    };
    tracing::info!(
        "{spec}: {} triangles ({} stored in {} meshes), {} materials, {} textures ({:.1} MiB), {} point, spot or directional lights, \
         loaded in {:.3} s",
        scene.triangle_count(),
        scene.meshes.iter().map(|m| m.indices.len()).sum::<usize>(),
        scene.meshes.len(),
        scene.materials.len(),
        scene.textures.len(),
        scene.texel_bytes() as f64 / f64::from(1 << 20),
        scene.lights.len(),
        start.elapsed().as_secs_f64()
    );
    Ok((scene, report))
}

/// The names of the scene files directly in `folder`, sorted, at most 8 (for a message).
fn scene_files_in(folder: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(folder)
        .map(|entries| {
            entries
                .filter_map(Result::ok)
                .filter(|e| e.path().is_file() && format_of(&e.path()).is_some())
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .collect()
        })
        .unwrap_or_default();
    names.sort();
    names.truncate(8);
    names
}
