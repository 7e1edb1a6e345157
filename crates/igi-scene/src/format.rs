//! Which loader reads a file, told by its extension, and loading a mesh file (OBJ, glTF, PLY):
//! what [`crate::load`] and a scene file's `[[mesh]]` entries share.

use std::path::Path;

use crate::error::SceneError;
use crate::model::Scene;
use crate::report::LoadReport;
use crate::texture::TextureSet;
use crate::{gltf_loader, obj, ply, resources};

/// The file formats igi reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Format {
    /// A mesh file: what a scene file may place.
    Mesh(MeshFormat),
    /// igi's TOML scene file.
    SceneFile,
}

/// The formats of mesh files.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MeshFormat {
    /// Wavefront OBJ text, with MTL material libraries.
    Obj,
    /// A glTF 2.0 document (`.gltf`) or GLB container (`.glb`).
    Gltf,
    /// Stanford PLY, ASCII or binary.
    Ply,
}

/// The format of `path` by its extension (any case), if igi reads it.
pub(crate) fn format_of(path: &Path) -> Option<Format> {
    let extension = path.extension()?.to_str()?.to_ascii_lowercase();
    match extension.as_str() {
        "obj" => Some(Format::Mesh(MeshFormat::Obj)),
        "gltf" | "glb" => Some(Format::Mesh(MeshFormat::Gltf)),
        "ply" => Some(Format::Mesh(MeshFormat::Ply)),
        "toml" => Some(Format::SceneFile),
        _ => None,
    }
}

/// True if `path` names a mesh file (`.obj`, `.gltf`, `.glb`, `.ply`).
pub(crate) fn is_model_file(path: &Path) -> bool {
    matches!(format_of(path), Some(Format::Mesh(_)))
}

/// Loads a mesh file (`.obj`, `.gltf`, `.glb`, `.ply`): what a scene file may place. The files
/// it refers to are looked up beside it; its textures go into `textures` (the scene's).
pub(crate) fn load_model_file(
    path: &Path,
    textures: &mut TextureSet,
    report: &mut LoadReport,
) -> Result<Scene, SceneError> {
    let Some(Format::Mesh(format)) = format_of(path) else {
        return Err(SceneError::UnknownFormat { file: path.to_path_buf() });
    };
    let bytes = resources::read(path, report)?;
    parse_mesh_file(format, &bytes, path, Some(&resources::base_dir(path)), textures, report)
}

/// Parses a mesh file held in memory; `name` is used in messages. The files it refers to
/// (material libraries, external buffers, textures) are looked up in `base_dir`; with `None`
/// nothing is read from disk: OBJ materials fall back to defaults, and a glTF file has only
/// its embedded data.
pub fn parse_mesh(
    format: MeshFormat,
    bytes: &[u8],
    name: &str,
    base_dir: Option<&Path>,
    report: &mut LoadReport,
) -> Result<Scene, SceneError> {
    TextureSet::default()
        .owning(|textures| parse_mesh_file(format, bytes, Path::new(name), base_dir, textures, report))
}

/// Parses the mesh file `file` of `format` from its `bytes`, whose textures go into
/// `textures` (the scene's).
fn parse_mesh_file(
    format: MeshFormat,
    bytes: &[u8],
    file: &Path,
    base_dir: Option<&Path>,
    textures: &mut TextureSet,
    report: &mut LoadReport,
) -> Result<Scene, SceneError> {
    match format {
        MeshFormat::Obj => obj::parse(bytes, file, base_dir, textures, report),
        MeshFormat::Gltf => gltf_loader::parse(bytes, file, base_dir, textures, report),
        MeshFormat::Ply => ply::parse(bytes, file, report),
    }
}
