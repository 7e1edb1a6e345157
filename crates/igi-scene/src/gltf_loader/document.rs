//! The glTF document as the `gltf` crate gets it: what the crate would panic on is checked
//! before it sees the document, and required extensions are sorted into those this loader
//! reads, those it may ignore with a warning and those that are errors.

use std::path::Path;

use crate::error::{Location, SceneError};
use crate::report::LoadReport;

/// Extensions that only change appearance in ways the model cannot express anyway: a file
/// that *requires* one of them still loads, with a warning. Any other required extension we
/// do not implement (Draco or meshopt compression, quantized attributes, GPU instancing)
/// changes the geometry and is an error.
const APPEARANCE_ONLY_EXTENSIONS: &[&str] = &[
    "KHR_texture_transform",
    "KHR_texture_basisu",
    "EXT_texture_webp",
    "KHR_materials_unlit",
    "KHR_materials_specular",
    "KHR_materials_volume",
    "KHR_materials_clearcoat",
    "KHR_materials_sheen",
    "KHR_materials_variants",
    "KHR_materials_pbrSpecularGlossiness",
];

/// Extensions this loader reads.
const SUPPORTED_EXTENSIONS: &[&str] = &[
    "KHR_lights_punctual",
    "KHR_materials_emissive_strength",
    "KHR_materials_ior",
    "KHR_materials_transmission",
];

/// The validated document of a glTF file or GLB container, and the GLB's BIN chunk if it has
/// one.
pub(super) fn read(
    bytes: &[u8],
    file: &Path,
    report: &mut LoadReport,
) -> Result<(gltf::Document, Option<Vec<u8>>), SceneError> {
    check_glb_length(bytes, file)?;
    let gltf::Gltf { document, blob } = gltf::Gltf::from_slice_without_validation(bytes)
        .map_err(|e| SceneError::parse(file, Location::File, e.to_string()))?;
    let mut root = document.into_json();
    check_unchecked_fields(&root, file)?;
    check_extensions(&mut root, file, report)?;
    let document = gltf::Document::from_json(root).map_err(|e| validation_error(e, file))?;
    Ok((document, blob))
}

/// The `gltf` crate subtracts the 12-byte header from a GLB's declared length unchecked.
fn check_glb_length(bytes: &[u8], file: &Path) -> Result<(), SceneError> {
    if !bytes.starts_with(b"glTF") {
        return Ok(());
    }
    let declared = bytes.get(8..12).and_then(|b| <[u8; 4]>::try_from(b).ok()).map(u32::from_le_bytes);
    match declared {
        Some(length) if length >= 12 => Ok(()),
        _ => Err(SceneError::parse(file, Location::File, "GLB header declares a length shorter than itself")),
    }
}

/// Checks what the `gltf` crate unwraps or indexes without checking, in its validation or its
/// accessors, and which its validation does not cover: the POSITION accessor index, an
/// image's `mimeType` (with a `bufferView`) or `uri` (without), and the projection object a
/// camera's `type` names.
fn check_unchecked_fields(root: &gltf::json::Root, file: &Path) -> Result<(), SceneError> {
    use gltf::json::camera::Type;
    use gltf::json::validation::Checked;
    let invalid =
        |path: String, message: String| Err(SceneError::invalid(file, Location::Json(path), message));
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            if let Some(index) = primitive.attributes.get(&Checked::Valid(gltf::Semantic::Positions)) {
                if index.value() >= root.accessors.len() {
                    return invalid(
                        format!("meshes[{m}].primitives[{p}].attributes.POSITION"),
                        format!("accessor {} does not exist", index.value()),
                    );
                }
            }
        }
    }
    for (index, image) in root.images.iter().enumerate() {
        let problem = match (&image.buffer_view, &image.mime_type, &image.uri) {
            (Some(_), None, _) => "an image in a buffer view needs a mimeType",
            (None, _, None) => "an image needs a uri or a bufferView",
            _ => continue,
        };
        return invalid(format!("images[{index}]"), problem.into());
    }
    for (index, camera) in root.cameras.iter().enumerate() {
        let missing = match camera.type_ {
            Checked::Valid(Type::Perspective) if camera.perspective.is_none() => "perspective",
            Checked::Valid(Type::Orthographic) if camera.orthographic.is_none() => "orthographic",
            _ => continue,
        };
        return invalid(
            format!("cameras[{index}]"),
            format!("a {missing} camera needs a `{missing}` object"),
        );
    }
    Ok(())
}

fn validation_error(error: gltf::Error, file: &Path) -> SceneError {
    match error {
        gltf::Error::Validation(errors) => {
            let at = errors.first().map_or(Location::File, |(path, _)| Location::Json(path.to_string()));
            let mut message =
                errors.first().map_or_else(|| "invalid document".to_owned(), |(_, e)| e.to_string());
            if errors.len() > 1 {
                message.push_str(&format!(" (and {} more problems)", errors.len() - 1));
            }
            SceneError::invalid(file, at, message)
        }
        other => SceneError::parse(file, Location::File, other.to_string()),
    }
}

/// Rejects required extensions that change geometry and that this loader does not read, and
/// lets the appearance-only ones through with a warning (the `gltf` crate's validation would
/// reject those too, so they are taken off the required list first).
fn check_extensions(
    root: &mut gltf::json::Root,
    file: &Path,
    report: &mut LoadReport,
) -> Result<(), SceneError> {
    let mut result = Ok(());
    root.extensions_required.retain(|extension| {
        if SUPPORTED_EXTENSIONS.contains(&extension.as_str()) {
            true
        } else if APPEARANCE_ONLY_EXTENSIONS.contains(&extension.as_str()) {
            report.warn(file, format!("required extension `{extension}` is ignored"));
            false
        } else {
            if result.is_ok() {
                result = Err(SceneError::unsupported(
                    file,
                    Location::Json("extensionsRequired".into()),
                    format!("requires extension `{extension}`, which igi does not support"),
                ));
            }
            true
        }
    });
    result
}
