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
pub(crate) enum MeshFormat {
    Obj,
    Gltf,
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
    let base_dir = resources::base_dir(path);
    match format {
        MeshFormat::Obj => obj::parse_file(&bytes, path, Some(&base_dir), textures, report),
        MeshFormat::Gltf => gltf_loader::parse_file(&bytes, path, Some(&base_dir), textures, report),
        MeshFormat::Ply => ply::parse_file(&bytes, path, report),
    }
}
