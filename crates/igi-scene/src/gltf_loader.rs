//! glTF 2.0 (`.gltf` with external or `data:` buffers, `.glb`), parsed and validated by the
//! `gltf` crate.
//!
//! What becomes of a glTF file:
//! - Every glTF mesh used by the scene becomes one [`Mesh`](crate::Mesh) (its primitives merged, a material
//!   per primitive); every node that uses it becomes an [`Instance`] with the node's composed
//!   world transform, so a mesh used by two nodes is stored once. Only `TRIANGLES`
//!   primitives are loaded (others are skipped with a warning). Skinned and morphed meshes are
//!   loaded in their bind pose (the base positions), with a warning.
//! - The scene is the `scene` property, else `scenes[0]`, else every root node.
//! - Materials (metallic-roughness mapped onto the Phong-style model simply):
//!   `diffuse` = baseColor·(1 − metallic), `specular` = mix(0.04, baseColor, metallic),
//!   `exponent` = 2/α² − 2 with α = roughness² (the Blinn-Phong exponent matching a GGX lobe
//!   of that width), `diffuse_texture` = baseColorTexture (sRGB); metallic ≥ 0.99 with
//!   roughness ≤ 0.01 is a [`MaterialKind::Mirror`], a KHR_materials_transmission factor > 0
//!   a [`MaterialKind::Glass`] with the KHR_materials_ior index (default 1.5).
//!   `emission` = emissiveFactor × KHR_materials_emissive_strength × the *average* of the
//!   emissiveTexture: the model has no emission maps, and the average keeps the emitted power
//!   right, which is what instant radiosity's light sampling needs (an emissive map that
//!   cannot be read gives no emission rather than a uniform glow). `normal_texture` and
//!   `normal_scale` = normalTexture (linear) and its scale. Textures take the wrap modes of
//!   their samplers (wrapS, wrapT). Metallic-roughness and occlusion
//!   maps are not used (the factors are). Primitives without a material get the grey default
//!   of the other formats rather than glTF's white metal.
//! - KHR_lights_punctual: colour × intensity, with candela read as W/sr and lux as W/m² (the
//!   renderer works in unitless linear RGB, so no 683 lm/W factor); a spot's full cone angle
//!   is twice its outer cone angle (the inner angle is dropped); `range` is ignored. Lights
//!   point down their node's −Z.
//! - The first perspective camera met in the node hierarchy: position from its node, target
//!   one unit down the node's −Z, up the node's +Y, `yfov` converted to degrees.
//! - Animations (glTF 3.11) of node translation, rotation and scale, STEP, LINEAR and
//!   CUBICSPLINE, all playing at once, each looping with its own period (`channels.rs` reads
//!   them). Every animated node, and every node under one, becomes an [`AnimationNode`] with
//!   its local transform at rest, after its parent; the instances and lights on those nodes are
//!   listed in [`Scene::animation`], and stand in [`Scene::instances`] and [`Scene::lights`]
//!   at rest. Nodes that neither move nor sit under a moving node stay baked into world
//!   transforms, as in a still file. A camera does not follow its node's animation, and
//!   morph-target weights and skins are not animated (with warnings).
//!
//! Robustness: the `gltf` crate panics on some malformed files (a GLB length shorter than its
//! header, an out-of-range POSITION accessor index in its own validation, images without a
//! `mimeType` or `uri`, cameras without their projection, accessors whose data does not fit
//! their buffer view or have an unexpected type, `count = 0`, URIs that percent-decode to
//! invalid UTF-8). So those fields are checked before the crate sees them, every accessor is
//! checked against its buffer before it is read, and URIs are resolved here, not by the crate.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use glam::{Affine3A, Mat4, Quat, Vec2, Vec3, Vec4};
use gltf::accessor::{DataType, Dimensions};
use gltf::khr_lights_punctual::Kind;
use gltf::mesh::Mode;

use crate::animation::{AnimatedInstance, AnimatedLight, AnimationNode, RotationTrack, Track};
use crate::error::{Location, SceneError};
use crate::light::Light;
use crate::model::{Camera, Instance, Material, MaterialKind, Scene, Wrap};
use crate::report::LoadReport;
use crate::resources;
use crate::texels::ColorSpace;
use crate::texture::TextureSet;
use crate::validate::{MeshBuilder, Part};

mod channels;

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

/// Parses a glTF document or GLB container held in memory; `name` is used in messages.
/// External buffers and images are looked up in `base_dir`; with `None` only embedded data
/// (GLB chunks, `data:` URIs) is available and an external buffer is an error.
pub fn parse(
    bytes: &[u8],
    name: &str,
    base_dir: Option<&Path>,
    report: &mut LoadReport,
) -> Result<Scene, SceneError> {
    TextureSet::default().owning(|textures| parse_file(bytes, Path::new(name), base_dir, textures, report))
}

/// Parses the glTF document or GLB container of `file`, whose external buffers and images
/// are looked up in `base_dir` and whose textures go into `textures` (the scene's).
pub(crate) fn parse_file(
    bytes: &[u8],
    file: &Path,
    base_dir: Option<&Path>,
    textures: &mut TextureSet,
    report: &mut LoadReport,
) -> Result<Scene, SceneError> {
    check_glb_length(bytes, file)?;
    let gltf::Gltf { document, blob } = gltf::Gltf::from_slice_without_validation(bytes)
        .map_err(|e| SceneError::parse(file, Location::File, e.to_string()))?;
    let mut root = document.into_json();
    check_unchecked_fields(&root, file)?;
    check_extensions(&mut root, file, report)?;
    let document = gltf::Document::from_json(root).map_err(|e| validation_error(e, file))?;
    let buffers = load_buffers(&document, blob, file, base_dir, report)?;
    let tracks = channels::read(&document, &buffers, file, report);
    let mut loader = Loader {
        file,
        base_dir,
        buffers: &buffers,
        report,
        scene: Scene::default(),
        textures,
        meshes: HashMap::new(),
        materials: HashMap::new(),
        emissive_means: HashMap::new(),
        tracks,
    };
    loader.walk(&document)?;
    Ok(loader.scene)
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

/// Decodes `%XX` escapes of a relative URI.
fn percent_decode(uri: &str) -> Option<String> {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let hex = std::str::from_utf8(bytes.get(i + 1..i + 3)?).ok()?;
            out.push(u8::from_str_radix(hex, 16).ok()?);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    String::from_utf8(out).ok()
}

/// Where the bytes of a buffer or image come from.
enum Uri {
    /// A `data:` URI, decoded.
    Data(Vec<u8>),
    /// A file, relative to the document.
    File(String),
}

fn classify_uri(uri: &str) -> Result<Uri, String> {
    if uri.starts_with("data:") {
        let data = gltf::buffer::Data::from_source(gltf::buffer::Source::Uri(uri), None)
            .map_err(|e| format!("bad data URI: {e}"))?;
        Ok(Uri::Data(data.0))
    } else if uri.contains(':') {
        Err(format!("unsupported URI scheme in `{uri}`"))
    } else {
        percent_decode(uri)
            .map(Uri::File)
            .ok_or_else(|| format!("URI `{uri}` is not valid percent-encoded UTF-8"))
    }
}

fn load_buffers(
    document: &gltf::Document,
    mut blob: Option<Vec<u8>>,
    file: &Path,
    base_dir: Option<&Path>,
    report: &mut LoadReport,
) -> Result<Vec<Vec<u8>>, SceneError> {
    let mut buffers = Vec::new();
    for buffer in document.buffers() {
        let at = || Location::Json(format!("buffers[{}]", buffer.index()));
        let data = match buffer.source() {
            gltf::buffer::Source::Bin => blob
                .take()
                .ok_or_else(|| SceneError::invalid(file, at(), "refers to a missing GLB BIN chunk"))?,
            gltf::buffer::Source::Uri(uri) => {
                match classify_uri(uri).map_err(|m| SceneError::invalid(file, at(), m))? {
                    Uri::Data(data) => data,
                    Uri::File(relative) => {
                        let Some(dir) = base_dir else {
                            return Err(SceneError::unsupported(
                                file,
                                at(),
                                format!(
                                    "external buffer `{relative}` cannot be read when parsing from memory"
                                ),
                            ));
                        };
                        let path =
                            resources::resolve(dir, &relative).ok_or_else(|| SceneError::MissingFile {
                                file: file.to_path_buf(),
                                at: at(),
                                missing: dir.join(&relative),
                            })?;
                        resources::read(&path, report)?
                    }
                }
            }
        };
        if data.len() < buffer.length() {
            return Err(SceneError::invalid(
                file,
                at(),
                format!("byteLength is {} but only {} bytes are present", buffer.length(), data.len()),
            ));
        }
        buffers.push(data);
    }
    Ok(buffers)
}

/// Checks that an accessor has one of the `allowed` types and that all of its elements lie
/// inside its buffer view and buffer, so that the `gltf` crate's reader can neither panic nor
/// silently return fewer elements than `count`.
fn check_accessor(
    accessor: &gltf::Accessor,
    allowed: &[(DataType, Dimensions)],
    buffers: &[Vec<u8>],
) -> Result<(), String> {
    let kind = (accessor.data_type(), accessor.dimensions());
    if !allowed.contains(&kind) {
        return Err(format!(
            "accessor {}: type {:?} {:?} is not supported here",
            accessor.index(),
            kind.0,
            kind.1
        ));
    }
    let count = accessor.count();
    if count == 0 {
        return Err(format!("accessor {}: count is 0", accessor.index()));
    }
    let element = accessor.size();
    let fits = |view: gltf::buffer::View, offset: usize, count: usize, element: usize| {
        let stride = view.stride().unwrap_or(element);
        let end = stride
            .checked_mul(count - 1)
            .and_then(|n| n.checked_add(offset))
            .and_then(|n| n.checked_add(element));
        let view_end = view.offset().checked_add(view.length());
        let buffer_len = buffers.get(view.buffer().index()).map_or(0, Vec::len);
        stride >= element
            && end.is_some_and(|end| end <= view.length())
            && view_end.is_some_and(|end| end <= buffer_len)
    };
    if let Some(view) = accessor.view() {
        if !fits(view, accessor.offset(), count, element) {
            return Err(format!("accessor {}: data extends past its buffer view", accessor.index()));
        }
    }
    if let Some(sparse) = accessor.sparse() {
        let n = sparse.count();
        let indices = sparse.indices();
        let values = sparse.values();
        if n == 0
            || n > count
            || !fits(indices.view(), indices.offset(), n, indices.index_type().size())
            || !fits(values.view(), values.offset(), n, element)
        {
            return Err(format!("accessor {}: sparse data extends past its buffer view", accessor.index()));
        }
    }
    Ok(())
}

/// glTF node transform as a matrix, with the rotation quaternion normalised (exporters write
/// slightly non-unit ones, e.g. the Cameras sample).
fn local_transform(node: &gltf::Node) -> Option<Mat4> {
    match node.transform() {
        gltf::scene::Transform::Matrix { matrix } => Some(Mat4::from_cols_array_2d(&matrix)),
        gltf::scene::Transform::Decomposed { translation, rotation, scale } => {
            let rotation = Quat::from_vec4(Vec4::from(rotation).try_normalize()?);
            Some(Mat4::from_scale_rotation_translation(Vec3::from(scale), rotation, Vec3::from(translation)))
        }
    }
}

/// State of one glTF load.
struct Loader<'a> {
    file: &'a Path,
    base_dir: Option<&'a Path>,
    buffers: &'a [Vec<u8>],
    report: &'a mut LoadReport,
    scene: Scene,
    textures: &'a mut TextureSet,
    /// glTF mesh index → scene mesh index (`None`: the mesh has no triangles).
    meshes: HashMap<usize, Option<u32>>,
    /// glTF material index (`None`: the default material) → scene material index.
    materials: HashMap<Option<usize>, u32>,
    /// glTF image index → average linear colour.
    emissive_means: HashMap<usize, Option<Vec3>>,
    /// glTF node index → its animation tracks (taken when the node is visited).
    tracks: HashMap<usize, channels::NodeTracks>,
}

impl Loader<'_> {
    /// Visits the scene's node forest depth-first with an explicit stack (a hostile file can
    /// nest nodes deeper than the call stack) and rejects cycles and shared children.
    fn walk(&mut self, document: &gltf::Document) -> Result<(), SceneError> {
        let roots: Vec<gltf::Node> = match document.default_scene().or_else(|| document.scenes().next()) {
            Some(scene) => scene.nodes().collect(),
            None => {
                let mut is_child = vec![false; document.nodes().count()];
                for node in document.nodes() {
                    for child in node.children() {
                        is_child[child.index()] = true;
                    }
                }
                document.nodes().filter(|n| !is_child[n.index()]).collect()
            }
        };
        let mut visited = vec![false; document.nodes().count()];
        // (node, its parent's world transform at rest, its parent's animation node if it moves)
        let mut stack: Vec<(gltf::Node, Mat4, Option<u32>)> =
            roots.into_iter().rev().map(|n| (n, Mat4::IDENTITY, None)).collect();
        while let Some((node, parent, parent_node)) = stack.pop() {
            let at = || Location::Json(format!("nodes[{}]", node.index()));
            if std::mem::replace(&mut visited[node.index()], true) {
                return Err(SceneError::invalid(
                    self.file,
                    at(),
                    "node is reached twice (the node hierarchy must be a forest)",
                ));
            }
            let local = local_transform(&node)
                .ok_or_else(|| SceneError::invalid(self.file, at(), "rotation is a zero quaternion"))?;
            let world = parent * local;
            if !world.is_finite() {
                return Err(SceneError::invalid(self.file, at(), "transform is not finite"));
            }
            let moving = self.animation_node(&node, local, parent, parent_node);
            if let Some(mesh) = node.mesh() {
                self.instance(&node, mesh, world, moving)?;
            }
            if let Some(light) = node.light() {
                self.light(&node, light, world, moving);
            }
            if let Some(camera) = node.camera() {
                self.camera(&node, camera, world, moving);
            }
            stack.extend(node.children().collect::<Vec<_>>().into_iter().rev().map(|c| (c, world, moving)));
        }
        Ok(())
    }

    /// The node's index in the scene's [`Animation`](crate::Animation) if it moves: if it has
    /// tracks or its parent moves (`parent_node`). A still node under still nodes has none
    /// and keeps its baked world transform. `local` is the node's transform relative to its
    /// parent, `parent` the parent's world transform at rest.
    fn animation_node(
        &mut self,
        node: &gltf::Node,
        local: Mat4,
        parent: Mat4,
        parent_node: Option<u32>,
    ) -> Option<u32> {
        let animation_node = match self.tracks.remove(&node.index()) {
            Some(tracks) => {
                // The still ancestors of the topmost moving node of a branch become one fixed
                // node above it: the tracks replace parts of the node's own transform only.
                let parent_node = parent_node.or_else(|| {
                    (parent != Mat4::IDENTITY)
                        .then(|| self.push_node(AnimationNode::fixed(None, Affine3A::from_mat4(parent))))
                });
                self.animated_node(node, local, parent_node, tracks)
            }
            None => AnimationNode::fixed(Some(parent_node?), Affine3A::from_mat4(local)),
        };
        Some(self.push_node(animation_node))
    }

    /// The [`AnimationNode`] of a node with tracks: its rest transform is the node's own,
    /// which [`AnimationNode::local`] decomposes into translation, rotation and scale for the
    /// tracks to replace.
    fn animated_node(
        &mut self,
        node: &gltf::Node,
        local: Mat4,
        parent: Option<u32>,
        mut tracks: channels::NodeTracks,
    ) -> AnimationNode {
        let rest = Affine3A::from_mat4(local);
        let (scale, rotation, translation) = match node.transform() {
            gltf::scene::Transform::Decomposed { translation, rotation, scale } => (
                Vec3::from(scale),
                // `local_transform` has checked that it is not zero.
                Quat::from_vec4(Vec4::from(rotation).normalize()),
                Vec3::from(translation),
            ),
            gltf::scene::Transform::Matrix { .. } => {
                self.report.warn(
                    self.file,
                    format!(
                        "nodes[{}]: an animated node must not have a matrix (glTF 3.5.3); it is decomposed \
                         into translation, rotation and scale",
                        node.index()
                    ),
                );
                rest.to_scale_rotation_translation()
            }
        };
        if !(scale.is_finite() && rotation.is_finite()) {
            self.report.warn(
                self.file,
                format!("nodes[{}]: its matrix is singular; its animation is not shown", node.index()),
            );
            return AnimationNode::fixed(parent, rest);
        }
        // Decomposing the rest transform does not give back every TRS: glam moves the sign of
        // a negative scale onto X and the rotation with it, and a zero scale has no rotation.
        // Then a track would be combined with the wrong parts, so the parts without a track
        // are held by one-key tracks of the node's own values instead.
        let (decomposed_scale, decomposed_rotation, _) = rest.to_scale_rotation_translation();
        let tolerance = 1e-5 * scale.abs().max_element().max(1.0);
        if !(decomposed_rotation.is_finite() && decomposed_scale.abs_diff_eq(scale, tolerance)) {
            tracks.translation =
                tracks.translation.or_else(|| Track::step(vec![0.0], vec![translation]).ok());
            tracks.rotation = tracks.rotation.or_else(|| Track::step(vec![0.0], vec![rotation]).ok());
            tracks.scale = tracks.scale.or_else(|| Track::step(vec![0.0], vec![scale]).ok());
        }
        AnimationNode {
            parent,
            rest,
            translation: tracks.translation,
            rotation: tracks.rotation.map(RotationTrack::Quaternion),
            scale: tracks.scale,
        }
    }

    /// Appends a node to the scene's animation and returns its index.
    fn push_node(&mut self, node: AnimationNode) -> u32 {
        self.scene.animation.nodes.push(node);
        (self.scene.animation.nodes.len() - 1) as u32
    }

    /// Places `mesh` at the node's world transform; a node that moves (`moving`) carries it.
    fn instance(
        &mut self,
        node: &gltf::Node,
        mesh: gltf::Mesh,
        world: Mat4,
        moving: Option<u32>,
    ) -> Result<(), SceneError> {
        let index = match self.meshes.get(&mesh.index()) {
            Some(&index) => index,
            None => {
                let index = self.load_mesh(&mesh, node.skin().is_some())?;
                self.meshes.insert(mesh.index(), index);
                index
            }
        };
        let Some(index) = index else { return Ok(()) };
        let transform = Affine3A::from_mat4(world);
        if !(transform.is_finite() && transform.inverse().is_finite()) {
            // Rays are traced in the instance's own space, so its transform must invert in f32.
            let (scale, _, _) = world.to_scale_rotation_translation();
            let why = if scale.cmpeq(glam::Vec3::ZERO).any() {
                "scale is zero".to_owned()
            } else {
                format!("world transform (scale {scale}) cannot be inverted in single precision")
            };
            self.report.warn(self.file, format!("nodes[{}]: {why}; the instance is left out", node.index()));
            return Ok(());
        }
        self.scene.instances.push(Instance { mesh: index, transform });
        // A skinned mesh ignores its node's transform and follows its joints (glTF 3.7.3),
        // which are not animated here: it stays in its bind pose.
        if let Some(carrier) = moving
            && node.skin().is_none()
        {
            let instance = (self.scene.instances.len() - 1) as u32;
            self.scene.animation.instances.push(AnimatedInstance {
                instance,
                node: carrier,
                local: Affine3A::IDENTITY,
            });
        }
        Ok(())
    }

    fn load_mesh(&mut self, mesh: &gltf::Mesh, skinned: bool) -> Result<Option<u32>, SceneError> {
        let path = format!("meshes[{}]", mesh.index());
        if skinned {
            self.report.warn(self.file, format!("{path}: skinned mesh loaded in its bind pose"));
        }
        if mesh.primitives().any(|p| p.morph_targets().next().is_some()) {
            self.report.warn(self.file, format!("{path}: morph targets ignored (base shape loaded)"));
        }
        let name = mesh.name().map_or_else(|| path.clone(), str::to_owned);
        let mut builder = MeshBuilder::new(name);
        for primitive in mesh.primitives() {
            let at = format!("{path}.primitives[{}]", primitive.index());
            if primitive.mode() != Mode::Triangles {
                self.report.warn(
                    self.file,
                    format!("{at}: mode {:?} skipped (only TRIANGLES is supported)", primitive.mode()),
                );
                continue;
            }
            let part = self
                .primitive(&primitive, &at)
                .map_err(|m| SceneError::invalid(self.file, Location::Json(at.clone()), m))?;
            builder.add(part).map_err(|defect| {
                SceneError::invalid(self.file, Location::Json(at.clone()), defect.to_string())
            })?;
        }
        let built = builder.finish();
        self.report.degenerate(self.file, built.degenerate);
        if built.normals_dropped {
            self.report.warn(self.file, format!("{path}: normals dropped: only some primitives have them"));
        }
        if built.mesh.indices.is_empty() {
            self.report.warn(self.file, format!("{path}: no triangles"));
            return Ok(None);
        }
        self.scene.meshes.push(built.mesh);
        Ok(Some((self.scene.meshes.len() - 1) as u32))
    }

    fn primitive(&mut self, primitive: &gltf::Primitive, at: &str) -> Result<Part, String> {
        const VEC3: &[(DataType, Dimensions)] = &[(DataType::F32, Dimensions::Vec3)];
        const UV: &[(DataType, Dimensions)] = &[
            (DataType::F32, Dimensions::Vec2),
            (DataType::U8, Dimensions::Vec2),
            (DataType::U16, Dimensions::Vec2),
        ];
        const INDEX: &[(DataType, Dimensions)] = &[
            (DataType::U8, Dimensions::Scalar),
            (DataType::U16, Dimensions::Scalar),
            (DataType::U32, Dimensions::Scalar),
        ];
        let buffers = self.buffers;
        let reader = primitive.reader(|b| buffers.get(b.index()).map(Vec::as_slice));
        let position_accessor = primitive.get(&gltf::Semantic::Positions).ok_or("no POSITION attribute")?;
        check_accessor(&position_accessor, VEC3, buffers)?;
        let positions: Vec<Vec3> =
            reader.read_positions().ok_or("POSITION data is missing")?.map(Vec3::from).collect();
        let normals = match primitive.get(&gltf::Semantic::Normals) {
            Some(accessor) => {
                check_accessor(&accessor, VEC3, buffers)?;
                reader.read_normals().map(|n| n.map(Vec3::from).collect())
            }
            None => None,
        };
        let material = self.material(primitive.material());
        let textured = self.scene.materials[material as usize].diffuse_texture.is_some();
        let uvs = match primitive.get(&gltf::Semantic::TexCoords(0)) {
            Some(accessor) if textured => {
                check_accessor(&accessor, UV, buffers)?;
                reader.read_tex_coords(0).map(|uv| uv.into_f32().map(Vec2::from).collect())
            }
            _ => None,
        };
        let indices: Vec<u32> = match primitive.indices() {
            Some(accessor) => {
                check_accessor(&accessor, INDEX, buffers)?;
                reader.read_indices().ok_or("index data is missing")?.into_u32().collect()
            }
            None => (0..u32::try_from(positions.len()).map_err(|_| "too many vertices")?).collect(),
        };
        if !indices.len().is_multiple_of(3) {
            self.report.warn(
                self.file,
                format!(
                    "{at}: {} indices are not a multiple of 3; the incomplete last triangle is left out",
                    indices.len()
                ),
            );
        }
        Ok(Part {
            positions,
            normals,
            uvs,
            triangles: indices.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect(),
            material,
        })
    }

    fn material(&mut self, material: gltf::Material) -> u32 {
        if let Some(&index) = self.materials.get(&material.index()) {
            return index;
        }
        let converted = match material.index() {
            None => Material::default(),
            Some(index) => self.convert_material(&material, index),
        };
        self.scene.materials.push(converted);
        let index = (self.scene.materials.len() - 1) as u32;
        self.materials.insert(material.index(), index);
        index
    }

    fn convert_material(&mut self, material: &gltf::Material, index: usize) -> Material {
        let pbr = material.pbr_metallic_roughness();
        let [r, g, b, a] = pbr.base_color_factor();
        let base = Vec3::new(r, g, b).clamp(Vec3::ZERO, Vec3::ONE);
        let metallic = pbr.metallic_factor().clamp(0.0, 1.0);
        let roughness = pbr.roughness_factor().clamp(0.0, 1.0);
        let alpha = (roughness * roughness).max(1e-3);
        let transmission = material.transmission().map_or(0.0, |t| t.transmission_factor());
        let kind = if transmission > 0.0 {
            MaterialKind::Glass
        } else if metallic >= 0.99 && roughness <= 0.01 {
            MaterialKind::Mirror
        } else {
            MaterialKind::Plastic
        };
        let diffuse_texture = pbr.base_color_texture().and_then(|info| {
            if info.tex_coord() != 0 {
                self.report.warn(
                    self.file,
                    format!(
                        "materials[{index}]: base colour texture uses TEXCOORD_{}; ignored",
                        info.tex_coord()
                    ),
                );
                return None;
            }
            self.texture(info.texture(), ColorSpace::Srgb)
        });
        let (normal_texture, normal_scale) = match material.normal_texture() {
            Some(info) if info.tex_coord() == 0 => {
                (self.texture(info.texture(), ColorSpace::Linear), info.scale())
            }
            Some(info) => {
                self.report.warn(
                    self.file,
                    format!("materials[{index}]: normal texture uses TEXCOORD_{}; ignored", info.tex_coord()),
                );
                (None, 1.0)
            }
            None => (None, 1.0),
        };
        let mut emission =
            Vec3::from(material.emissive_factor()) * material.emissive_strength().unwrap_or(1.0);
        if let Some(info) = material.emissive_texture() {
            // An emissive map that cannot be read gives no emission rather than turning the
            // whole surface into a uniform emitter of `emissiveFactor`.
            emission *= self.emissive_mean(info.texture().source()).unwrap_or(Vec3::ZERO);
        }
        Material {
            name: material.name().map_or_else(|| format!("materials[{index}]"), str::to_owned),
            diffuse: base * (1.0 - metallic),
            diffuse_texture,
            specular: Vec3::splat(0.04).lerp(base, metallic),
            exponent: 2.0 / (alpha * alpha) - 2.0,
            emission: emission.max(Vec3::ZERO),
            bump_texture: None,
            normal_texture,
            normal_scale,
            transparency: if material.alpha_mode() == gltf::material::AlphaMode::Blend {
                (1.0 - a).clamp(0.0, 1.0)
            } else {
                0.0
            },
            ior: material.ior().filter(|&ior| ior > 0.0).unwrap_or(1.5),
            kind,
            shader: None,
        }
    }

    /// The texture index of a glTF texture: its image, with the wrap modes of its sampler.
    /// An image that two samplers wrap differently keeps the modes of the last one read.
    fn texture(&mut self, texture: gltf::Texture, space: ColorSpace) -> Option<u32> {
        let index = self.image(texture.source(), space)?;
        let wrap = |mode: gltf::texture::WrappingMode| match mode {
            gltf::texture::WrappingMode::ClampToEdge => Wrap::Clamp,
            gltf::texture::WrappingMode::MirroredRepeat => Wrap::MirroredRepeat,
            gltf::texture::WrappingMode::Repeat => Wrap::Repeat,
        };
        let sampler = texture.sampler();
        self.textures.set_wrap(index, [wrap(sampler.wrap_s()), wrap(sampler.wrap_t())]);
        Some(index)
    }

    /// The encoded bytes of an image, or where to find them.
    fn image_source(&mut self, image: &gltf::Image) -> Option<Result<Vec<u8>, PathBuf>> {
        let at = format!("images[{}]", image.index());
        match image.source() {
            gltf::image::Source::View { view, .. } => {
                let data = self.buffers.get(view.buffer().index())?;
                let end = view.offset().checked_add(view.length())?;
                match data.get(view.offset()..end) {
                    Some(bytes) => Some(Ok(bytes.to_vec())),
                    None => {
                        self.report.warn(self.file, format!("{at}: buffer view out of range; image skipped"));
                        None
                    }
                }
            }
            gltf::image::Source::Uri { uri, .. } => match classify_uri(uri) {
                Ok(Uri::Data(bytes)) => Some(Ok(bytes)),
                Ok(Uri::File(relative)) => Some(Err(PathBuf::from(relative))),
                Err(message) => {
                    self.report.warn(self.file, format!("{at}: {message}; image skipped"));
                    None
                }
            },
        }
    }

    fn image(&mut self, image: gltf::Image, space: ColorSpace) -> Option<u32> {
        match self.image_source(&image)? {
            Ok(bytes) => {
                // One key per embedded image, however the file's path is spelled.
                let file = std::fs::canonicalize(self.file).unwrap_or_else(|_| self.file.to_path_buf());
                let key = format!("{}#images[{}]", file.display(), image.index());
                self.textures.bytes(&key, &bytes, space, self.file, self.report)
            }
            Err(relative) => {
                let dir = self.base_dir?;
                self.textures.file(dir, &relative.to_string_lossy(), space, self.file, self.report)
            }
        }
    }

    fn emissive_mean(&mut self, image: gltf::Image) -> Option<Vec3> {
        if let Some(&mean) = self.emissive_means.get(&image.index()) {
            return mean;
        }
        let image_index = image.index();
        let mean = self.image(image, ColorSpace::Srgb).and_then(|texture| self.textures.mean_rgb(texture));
        self.emissive_means.insert(image_index, mean);
        mean
    }

    /// Adds a KHR_lights_punctual light at the node's world transform; a node that moves
    /// (`moving`) carries it.
    fn light(
        &mut self,
        node: &gltf::Node,
        light: gltf::khr_lights_punctual::Light,
        world: Mat4,
        moving: Option<u32>,
    ) {
        let Some(converted) = punctual(&light, world) else {
            self.report.warn(
                self.file,
                format!("nodes[{}]: light with a degenerate transform or intensity skipped", node.index()),
            );
            return;
        };
        self.scene.lights.push(converted);
        if let (Some(carrier), Some(rest)) = (moving, punctual(&light, Mat4::IDENTITY)) {
            self.scene.animation.lights.push(AnimatedLight {
                light: (self.scene.lights.len() - 1) as u32,
                rest,
                node: Some(carrier),
                position: None,
                direction: None,
                power: None,
            });
        }
    }

    /// Takes the node's camera as the scene's if it is the first perspective one. The scene's
    /// camera does not move, so a camera on a moving node (`moving`) stays at rest.
    fn camera(&mut self, node: &gltf::Node, camera: gltf::Camera, world: Mat4, moving: Option<u32>) {
        if self.scene.camera.is_some() {
            return;
        }
        let gltf::camera::Projection::Perspective(perspective) = camera.projection() else {
            self.report.warn(self.file, format!("nodes[{}]: orthographic camera skipped", node.index()));
            return;
        };
        let position = world.transform_point3(Vec3::ZERO);
        let forward = world.transform_vector3(Vec3::NEG_Z).try_normalize();
        let up = world.transform_vector3(Vec3::Y).try_normalize();
        let fov_y_deg = perspective.yfov().to_degrees();
        match (forward, up) {
            (Some(forward), Some(up)) if fov_y_deg > 0.0 && fov_y_deg < 180.0 => {
                self.scene.camera = Some(Camera { position, target: position + forward, up, fov_y_deg });
                if moving.is_some() {
                    self.report.warn(
                        self.file,
                        format!(
                            "nodes[{}]: the camera does not follow the animation; it stays at rest",
                            node.index()
                        ),
                    );
                }
            }
            _ => self.report.warn(self.file, format!("nodes[{}]: degenerate camera skipped", node.index())),
        }
    }
}

/// A KHR_lights_punctual light placed by `transform`: it sits at the origin of its node and
/// shines down the node's −Z. `None` if the transform or the intensity is degenerate.
fn punctual(light: &gltf::khr_lights_punctual::Light, transform: Mat4) -> Option<Light> {
    let power = Vec3::from(light.color()) * light.intensity();
    if !power.is_finite() {
        return None;
    }
    let position = transform.transform_point3(Vec3::ZERO);
    let direction = transform.transform_vector3(Vec3::NEG_Z).try_normalize();
    match (light.kind(), direction) {
        (Kind::Point, _) => Some(Light::Point { position, intensity: power }),
        (Kind::Spot { outer_cone_angle, .. }, Some(direction)) => Some(Light::Spot {
            position,
            direction,
            angle_deg: 2.0 * outer_cone_angle.clamp(0.0, std::f32::consts::FRAC_PI_2).to_degrees(),
            intensity: power,
        }),
        (Kind::Directional, Some(direction)) => Some(Light::Directional { direction, irradiance: power }),
        _ => None,
    }
}
