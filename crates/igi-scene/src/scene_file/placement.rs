//! `[[mesh]]` entries: a mesh file placed by the entry's transform (its keys, if any) and its
//! `instances`, with its materials or the entry's `material`, its lights and camera moved
//! along, and its own animation under the entry's node.

use std::ops::Range;
use std::path::Path;

use glam::{Affine3A, Vec3};
use toml::Spanned;

use super::checker::{Checker, line_of};
use super::keyframes::looped;
use super::schema::{AnimationSpec, MaterialSpec, MeshSpec};
use crate::animation::{AnimatedInstance, AnimatedLight, AnimationNode, RotationTrack};
use crate::error::{Location, SceneError};
use crate::format;
use crate::light::Light;
use crate::model::{Instance, Material, SavedView, Scene};
use crate::report::LoadReport;
use crate::resources;
use crate::texture::TextureSet;
use crate::validate::MAX_INSTANCES;

/// Places the mesh file of `[[mesh]]` entry `index` in `scene`: once per placement of its
/// `instances`, each after the entry's own (maybe keyed) transform. Without `base_dir` the
/// entry is checked but its file is not read (with a warning).
pub(super) fn add_mesh(
    check: &Checker,
    scene: &mut Scene,
    index: usize,
    entry: &Spanned<MeshSpec>,
    base_dir: Option<&Path>,
    textures: &mut TextureSet,
    report: &mut LoadReport,
) -> Result<(), SceneError> {
    let file = check.file;
    let span = entry.span();
    let path = format!("mesh[{index}].");
    let mesh = entry.get_ref();
    let own = check.transform(&span, || path.clone(), mesh.translate, mesh.rotate, mesh.scale)?;
    let own = mesh_node(check, &span, &path, own, mesh.animation.as_ref())?;
    let placements = match &mesh.instances {
        None => vec![Affine3A::IDENTITY],
        Some(instances) => instances
            .iter()
            .enumerate()
            .map(|(i, t)| {
                check.transform(&span, || format!("{path}instances[{i}]."), t.translate, t.rotate, t.scale)
            })
            .collect::<Result<_, _>>()?,
    };
    let material =
        mesh.material.as_ref().map(|m| material_override(check, &span, &path, m, &mesh.file)).transpose()?;
    if placements.is_empty() {
        report.warn(file, format!("{path}instances is empty; `{}` is not placed", mesh.file.get_ref()));
        return Ok(());
    }
    let Some(dir) = base_dir else {
        report.warn(file, format!("{path}file `{}` not loaded: parsing from memory", mesh.file.get_ref()));
        return Ok(());
    };
    let sub = load_mesh_file(check, dir, index, &mesh.file, textures, report)?;
    let count = placements.len().saturating_mul(sub.instances.len()).saturating_add(scene.instances.len());
    if count > MAX_INSTANCES {
        return Err(check.error(
            &span,
            format!("{path}instances"),
            format!("the scene would have {count} instances; it may have at most {MAX_INSTANCES}"),
        ));
    }
    append(scene, sub, &placements, &own, material);
    Ok(())
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
    let translation = check.vector_track(span, &path, spec, "translate", |key| key.translate)?;
    let rotation = check.vector_track(span, &path, spec, "rotate", |key| key.rotate)?;
    let scale = check.track(span, &path, spec, "scale", |key, at| {
        key.scale.map(|v| check.scale(span, || at, v)).transpose()
    })?;
    let [translation, rotation, scale] = looped([translation, rotation, scale], spec);
    node.translation = translation;
    node.rotation = rotation.map(RotationTrack::EulerDegrees);
    node.scale = scale;
    Ok(node)
}

/// Loads the mesh file `file` of entry `index`, looked up in `dir`; a missing or unsupported
/// file is an error at `mesh[index].file`.
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
        glossy: colour("specular", spec.specular, defaults.glossy)?,
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
    // The file's cameras go where its first placement puts it.
    if let Some(placement) = placements.first().map(|&p| p * own_at_rest) {
        if scene.camera.is_none() {
            scene.camera = sub.camera.map(|camera| camera.transformed(&placement));
        }
        for view in sub.views {
            let name = SavedView::free_name(&scene.views, view.name);
            scene.views.push(SavedView { name, camera: view.camera.transformed(&placement) });
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
