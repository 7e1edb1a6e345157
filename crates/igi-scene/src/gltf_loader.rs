//! glTF 2.0 (`.gltf` with external or `data:` buffers, `.glb`), parsed and validated by the
//! `gltf` crate.
//!
//! What becomes of a glTF file:
//! - Every glTF mesh used by the scene becomes one [`Mesh`](crate::Mesh) (its primitives
//!   merged, a material per primitive); every node that uses it becomes an
//!   [`Instance`](crate::Instance) with the node's composed world transform, so a mesh used by
//!   two nodes is stored once. Only `TRIANGLES` primitives are loaded (others are skipped with
//!   a warning). Skinned and morphed meshes are loaded in their bind pose (the base positions),
//!   with a warning.
//! - The scene is the `scene` property, else `scenes[0]`, else every root node.
//! - Materials are [`MaterialKind::MetallicRoughness`](crate::MaterialKind::MetallicRoughness)
//!   (the glTF 2.0 BRDF of appendix B, GGX, which the renderer evaluates per texel):
//!   `diffuse` = baseColorFactor, `diffuse_texture` = baseColorTexture (sRGB), `metallic` and
//!   `roughness` = their factors, `metallic_roughness_texture` = metallicRoughnessTexture
//!   (linear; B metalness, G roughness); metallic ≥ 0.99 with roughness ≤ 0.01 and no
//!   metallic-roughness texture is a [`MaterialKind::Mirror`](crate::MaterialKind::Mirror), a
//!   KHR_materials_transmission factor > 0 a [`MaterialKind::Glass`](crate::MaterialKind::Glass)
//!   with the KHR_materials_ior index (default 1.5).
//!   `emission` = emissiveFactor × KHR_materials_emissive_strength and `emission_texture` =
//!   emissiveTexture (sRGB), which multiplies it per texel (glTF 3.9.3): the surface shader
//!   shows the texture and the renderer's light sampling chooses emissive triangles by the
//!   texture's integral over them (an emissive map that cannot be read gives no emission
//!   rather than a uniform glow). `normal_texture` and
//!   `normal_scale` = normalTexture (linear) and its scale. `alphaMode: MASK` becomes an
//!   `alpha_mask` (coverage = baseColorFactor.a × the base colour texture's alpha, cut below
//!   `alphaCutoff`, default 0.5; glTF 3.9.4), which every ray of the renderer passes through;
//!   `BLEND` is kept only as `transparency` and renders opaque, as does `OPAQUE`. Textures take the wrap modes of
//!   their samplers (wrapS, wrapT). Occlusion maps are not used. Primitives without a material get the grey default
//!   of the other formats rather than glTF's white metal.
//! - KHR_lights_punctual: colour × intensity, with candela read as W/sr and lux as W/m² (the
//!   renderer works in unitless linear RGB, so no 683 lm/W factor); a spot's full cone angle
//!   is twice its outer cone angle (the inner angle is dropped); `range` is ignored. Lights
//!   point down their node's −Z.
//! - The first perspective camera met in the node hierarchy: position from its node, target
//!   one unit down the node's −Z, up the node's +Y, `yfov` converted to degrees.
//! - Animations (glTF 3.11) of node translation, rotation and scale, STEP, LINEAR and
//!   CUBICSPLINE, all playing at once, each looping with its own period (`channels.rs` reads
//!   them). Every animated node, and every node under one, becomes an
//!   [`AnimationNode`](crate::animation::AnimationNode) with its local transform at rest, after
//!   its parent; the instances and lights on those nodes are listed in [`Scene::animation`],
//!   and stand in [`Scene::instances`] and [`Scene::lights`] at rest. Nodes that neither move
//!   nor sit under a moving node stay baked into world transforms, as in a still file. A camera
//!   does not follow its node's animation, and morph-target weights and skins are not animated
//!   (with warnings).
//!
//! Robustness: the `gltf` crate panics on some malformed files (a GLB length shorter than its
//! header, an out-of-range POSITION accessor index in its own validation, images without a
//! `mimeType` or `uri`, cameras without their projection, accessors whose data does not fit
//! their buffer view or have an unexpected type, `count = 0`, URIs that percent-decode to
//! invalid UTF-8). So those fields are checked before the crate sees them, every accessor is
//! checked against its buffer before it is read, and URIs are resolved here, not by the crate.
//! What the meshes and animations will read is added up from the accessors' counts before any
//! is read (`read_budget`), since a count need not be backed by data in the file.
//!
//! One submodule per part of the file: `document` (the checks before the `gltf` crate sees the
//! document, required extensions), `read_budget`, `buffers` (URIs and buffer bytes), `accessors`, `nodes` (the
//! node forest, instances, animation nodes), `meshes`, `materials`, `lights`, `camera` and
//! `channels` (animations); all but `document`, `buffers` and `channels` fill in the state of
//! the load, `loader::Loader`.

use std::path::Path;

use crate::error::SceneError;
use crate::model::Scene;
use crate::report::LoadReport;
use crate::texture::TextureSet;
use loader::Loader;

mod accessors;
mod buffers;
mod camera;
mod channels;
mod document;
mod lights;
mod loader;
mod materials;
mod meshes;
mod nodes;
mod read_budget;

pub use read_budget::GLTF_READ_BUDGET;

/// Parses the glTF document or GLB container of `file`, whose external buffers and images
/// are looked up in `base_dir` (with `None` only embedded data, GLB chunks and `data:` URIs,
/// is available and an external buffer is an error) and whose textures go into `textures`
/// (the scene's).
pub(crate) fn parse(
    bytes: &[u8],
    file: &Path,
    base_dir: Option<&Path>,
    textures: &mut TextureSet,
    report: &mut LoadReport,
) -> Result<Scene, SceneError> {
    let (document, blob) = document::read(bytes, file, report)?;
    read_budget::check(&document, file, GLTF_READ_BUDGET)?;
    let buffers = buffers::load_buffers(&document, blob, file, base_dir, report)?;
    let tracks = channels::read(&document, &buffers, file, report);
    let mut loader = Loader::new(file, base_dir, &buffers, tracks, textures, report);
    loader.walk(&document)?;
    Ok(loader.scene)
}
