//! Wavefront OBJ files, parsed by `tobj`, become one [`Mesh`](crate::Mesh) (all objects and
//! groups merged, a material per triangle) placed by one identity [`Instance`](crate::Instance).
//!
//! `tobj` is used for what it does well (grouping by material, building unique vertices from
//! the separate `v/vt/vn` index streams, triangulating). It is not fed the file directly,
//! because on real and fuzzed files it
//! - rejects `usemtl\tname` and misreads indented `usemtl`/`mtllib` lines (it splits on a
//!   single space),
//! - panics with an arithmetic overflow on a face index far out of range (`f 1/-99999999999`),
//! - turns polylines (`l 1 2 3`) into faces,
//! - forgets the name of a `usemtl` whose material is missing, so the CornellBox-Glossy light
//!   (`usemtl light` with no `light` in its MTL) could not be recognised,
//! - reports errors without a line number.
//!
//! So `prepare` first walks the file once: it checks every `v`/`vt`/`vn`/`f` statement
//! (finite numbers, indices in range, reported with their line), and writes a canonical text
//! for `tobj` with only the statements it needs. All `mtllib` statements are hoisted into one
//! at the top whose loader returns the complete material table, including a fallback for every
//! `usemtl` name no library defines: `light` becomes an emitter (`Ke 17 12 4`, `Kd 0.78`, the
//! CornellBox-Original light), anything else grey, each with a warning.
//!
//! Texture coordinates are flipped to the model's convention (v = 0 at the top row) and kept
//! only if some material has a texture: most big OBJ scenes carry `vt`s they never use
//! (conference), and 8 bytes per vertex matter at 64 bytes per triangle.
//! A missing MTL library is a warning (the scene renders grey); so is a missing texture (see
//! the [crate] documentation).

use std::collections::HashSet;
use std::path::Path;

use glam::{Vec2, Vec3};

use crate::error::{Location, SceneError};
use crate::model::{Material, Scene};
use crate::mtl;
use crate::report::LoadReport;
use crate::resources;
use crate::statements::{Statement, statements};
use crate::texture::TextureSet;
use crate::validate::{MeshBuilder, Part};

/// Name of the single `mtllib` statement `prepare` writes; its loader ignores the name.
const HOISTED_LIBRARY: &str = "materials";

/// Parses the OBJ text of `file`, whose material libraries and textures are looked up in
/// `base_dir` (with `None` nothing is read from disk and materials fall back to defaults) and
/// whose textures go into `textures` (the scene's).
pub(crate) fn parse(
    bytes: &[u8],
    file: &Path,
    base_dir: Option<&Path>,
    textures: &mut TextureSet,
    report: &mut LoadReport,
) -> Result<Scene, SceneError> {
    let text = String::from_utf8_lossy(bytes);
    let prepared = prepare(&text, file)?;
    let mut materials = Vec::new();
    if let Some(dir) = base_dir {
        for (library, line) in &prepared.libraries {
            materials.extend(load_library(dir, library, *line, file, textures, report)?);
        }
    }
    let mut by_name = mtl::index_by_name(&materials);
    for name in &prepared.material_names {
        if !by_name.contains_key(name) {
            by_name.insert(name.clone(), materials.len());
            materials.push(fallback_material(name, file, report));
        }
    }

    let options =
        tobj::LoadOptions { triangulate: true, single_index: true, ignore_points: true, ignore_lines: true };
    // `tobj` only uses the name → index map; the materials themselves are already ours.
    let (models, _) = tobj::load_obj_buf(&mut prepared.text.as_bytes(), &options, |_| {
        Ok((Vec::new(), by_name.iter().map(|(k, &v)| (k.clone(), v)).collect()))
    })
    .map_err(|e| SceneError::parse(file, Location::File, e.to_string()))?;

    let textured = materials.iter().any(|m| m.diffuse_texture.is_some() || m.bump_texture.is_some());
    let mut default_material = None;
    let mut builder = MeshBuilder::new(mesh_name(file));
    let mut partial_attributes = false;
    for model in models {
        let mesh = model.mesh;
        let material = match mesh.material_id.and_then(|id| u32::try_from(id).ok()) {
            Some(id) => id,
            None => *default_material.get_or_insert_with(|| {
                materials.push(Material::default());
                (materials.len() - 1) as u32
            }),
        };
        let (part, partial) = part_from(&mesh, material, textured);
        partial_attributes |= partial;
        // Only reachable through `v x y z w` with a tiny w: everything else was checked with
        // its line by `prepare`.
        builder.add(part).map_err(|defect| SceneError::invalid(file, Location::File, defect.to_string()))?;
    }
    if partial_attributes {
        report.warn(
            file,
            "some faces of a material group have texture coordinates or normals and others \
             do not; those attributes were dropped for the group",
        );
    }
    let built = builder.finish();
    report.degenerate(file, prepared.short_faces + built.degenerate);
    if built.normals_dropped {
        report.warn(file, "normals dropped: only some faces have them");
    }
    Ok(built.into_scene(materials, file, report))
}

/// Name of the mesh of `file`: its stem.
fn mesh_name(file: &Path) -> String {
    file.file_stem().map_or_else(|| "obj".into(), |s| s.to_string_lossy().into_owned())
}

fn load_library(
    dir: &Path,
    library: &str,
    line: usize,
    file: &Path,
    textures: &mut TextureSet,
    report: &mut LoadReport,
) -> Result<Vec<Material>, SceneError> {
    let Some(path) = resources::resolve(dir, library) else {
        report.warn(
            file,
            format!(
                "line {line}: material library `{library}` not found; its materials fall back to defaults"
            ),
        );
        return Ok(Vec::new());
    };
    let bytes = resources::read(&path, report)?;
    let texture_dir = resources::base_dir(&path);
    mtl::parse_library(&bytes, &path, Some(&texture_dir), textures, report)
}

/// The material for a `usemtl` name that no library defines.
fn fallback_material(name: &str, file: &Path, report: &mut LoadReport) -> Material {
    if name == "light" {
        report.warn(
            file,
            "material `light` is not defined; using an emitter (Kd 0.78, Ke 17 12 4) as in \
             CornellBox-Original",
        );
        Material {
            name: name.into(),
            diffuse: Vec3::splat(0.78),
            emission: Vec3::new(17.0, 12.0, 4.0),
            ..Material::default()
        }
    } else {
        report.warn(file, format!("material `{name}` is not defined; using grey"));
        Material { name: name.into(), ..Material::default() }
    }
}

/// Converts one `tobj` model (a material group) into a [`Part`]. The flag tells whether an
/// attribute was present for only some of its vertices (and so had to be dropped).
fn part_from(mesh: &tobj::Mesh, material: u32, keep_uvs: bool) -> (Part, bool) {
    let count = mesh.positions.len() / 3;
    let positions = mesh.positions.chunks_exact(3).map(|p| Vec3::new(p[0], p[1], p[2])).collect();
    let complete = |len: usize, per_vertex: usize| len == count * per_vertex;
    let partial = (!mesh.texcoords.is_empty() && !complete(mesh.texcoords.len(), 2))
        || (!mesh.normals.is_empty() && !complete(mesh.normals.len(), 3));
    let uvs = (keep_uvs && !mesh.texcoords.is_empty() && complete(mesh.texcoords.len(), 2))
        .then(|| mesh.texcoords.chunks_exact(2).map(|t| Vec2::new(t[0], 1.0 - t[1])).collect());
    let normals = (!mesh.normals.is_empty() && complete(mesh.normals.len(), 3))
        .then(|| mesh.normals.chunks_exact(3).map(|n| Vec3::new(n[0], n[1], n[2])).collect());
    let triangles = mesh.indices.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect();
    let part = Part { positions, normals, uvs, triangles, material };
    (part, partial)
}

/// The result of the checking pass over an OBJ text.
#[derive(Debug, Default)]
struct Prepared {
    /// Canonical OBJ text for `tobj`.
    text: String,
    /// `mtllib` references with their line.
    libraries: Vec<(String, usize)>,
    /// Every `usemtl` name, in order of first use.
    material_names: Vec<String>,
    /// Faces with fewer than three vertices (zero area), left out.
    short_faces: usize,
}

/// Running counts of the attribute statements seen so far, which relative (negative) and
/// absolute face indices are resolved against.
#[derive(Default)]
struct Counts {
    v: usize,
    vt: usize,
    vn: usize,
}

/// Checks an OBJ text and writes the canonical text `tobj` gets (see the module docs).
fn prepare(text: &str, file: &Path) -> Result<Prepared, SceneError> {
    let mut prepared = Prepared { text: String::with_capacity(text.len() + 32), ..Prepared::default() };
    let mut seen_names = HashSet::new();
    let mut counts = Counts::default();
    let mut body = String::with_capacity(text.len());
    for Statement { line: line_number, keyword, rest, .. } in statements(text) {
        let error = |message: String| SceneError::parse(file, Location::Line(line_number), message);
        match keyword {
            "v" => {
                let tokens: Vec<&str> = rest.split_whitespace().collect();
                // x y z, x y z w, x y z r g b or x y z w r g b: colours are dropped.
                let coordinates = match tokens.len() {
                    3 | 6 => 3,
                    4 | 7 => 4,
                    n => {
                        return Err(error(format!(
                            "`v` needs 3 coordinates (plus optional w and colour), found {n} values"
                        )));
                    }
                };
                let values = numbers(&tokens[..coordinates]).map_err(error)?;
                if coordinates == 4 && values[3] == 0.0 {
                    return Err(error("`v` with w = 0".into()));
                }
                body.push('v');
                push_tokens(&mut body, &tokens[..coordinates]);
                counts.v += 1;
            }
            "vt" => {
                let tokens: Vec<&str> = rest.split_whitespace().take(2).collect();
                if tokens.is_empty() {
                    return Err(error("`vt` without coordinates".into()));
                }
                numbers(&tokens).map_err(error)?;
                body.push_str("vt");
                push_tokens(&mut body, &tokens);
                if tokens.len() == 1 {
                    body.push_str(" 0");
                }
                counts.vt += 1;
            }
            "vn" => {
                let tokens: Vec<&str> = rest.split_whitespace().take(3).collect();
                if tokens.len() < 3 {
                    return Err(error(format!("`vn` needs 3 values, found {}", tokens.len())));
                }
                numbers(&tokens).map_err(error)?;
                body.push_str("vn");
                push_tokens(&mut body, &tokens);
                counts.vn += 1;
            }
            "f" => {
                let tokens: Vec<&str> = rest.split_whitespace().collect();
                for token in &tokens {
                    check_face_vertex(token, &counts).map_err(error)?;
                }
                if tokens.len() < 3 {
                    prepared.short_faces += 1;
                    continue;
                }
                body.push('f');
                push_tokens(&mut body, &tokens);
            }
            "usemtl" => {
                if rest.is_empty() {
                    return Err(error("`usemtl` without a material name".into()));
                }
                if seen_names.insert(rest) {
                    prepared.material_names.push(rest.to_owned());
                }
                body.push_str("usemtl ");
                body.push_str(rest);
            }
            "mtllib" => {
                prepared.libraries.extend(rest.split_whitespace().map(|name| (name.to_owned(), line_number)));
                continue;
            }
            // Objects, groups, smoothing groups, polylines, points, free-form geometry and
            // unknown statements do not change the triangles or their materials.
            _ => continue,
        }
        body.push('\n');
    }
    if !prepared.material_names.is_empty() {
        prepared.text.push_str("mtllib ");
        prepared.text.push_str(HOISTED_LIBRARY);
        prepared.text.push('\n');
    }
    prepared.text.push_str(&body);
    Ok(prepared)
}

fn push_tokens(out: &mut String, tokens: &[&str]) {
    for token in tokens {
        out.push(' ');
        out.push_str(token);
    }
}

fn numbers(tokens: &[&str]) -> Result<Vec<f32>, String> {
    tokens
        .iter()
        .map(|token| match token.parse::<f32>() {
            Ok(v) if v.is_finite() => Ok(v),
            Ok(_) => Err(format!("`{token}` is not a finite number")),
            Err(_) => Err(format!("`{token}` is not a number")),
        })
        .collect()
}

/// Checks one `v`, `v/vt`, `v//vn` or `v/vt/vn` face vertex against the statements so far.
fn check_face_vertex(token: &str, counts: &Counts) -> Result<(), String> {
    let mut parts = token.split('/');
    let streams = [("v", counts.v), ("vt", counts.vt), ("vn", counts.vn)];
    for (slot, (kind, count)) in streams.into_iter().enumerate() {
        let Some(part) = parts.next() else { break };
        if part.is_empty() && slot > 0 {
            continue;
        }
        let index: i64 =
            part.parse().map_err(|_| format!("face vertex `{token}`: `{part}` is not an index"))?;
        let resolved = if index < 0 { i64::try_from(count).map_or(-1, |c| c + index) } else { index - 1 };
        if index == 0 || resolved < 0 || resolved >= i64::try_from(count).unwrap_or(i64::MAX) {
            return Err(format!(
                "face vertex `{token}`: {kind} index {index} is out of range ({count} `{kind}` statements so far)"
            ));
        }
    }
    if parts.next().is_some() {
        return Err(format!("face vertex `{token}` has more than three indices"));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use std::collections::HashMap;

    use glam::Affine3A;

    use super::*;

    fn names_of(scene: &Scene) -> HashMap<&str, &Material> {
        scene.materials.iter().map(|m| (m.name.as_str(), m)).collect()
    }

    fn parse_str(text: &str) -> Result<(Scene, LoadReport), SceneError> {
        let mut report = LoadReport::default();
        crate::parse_mesh(crate::MeshFormat::Obj, text.as_bytes(), "t.obj", None, &mut report)
            .map(|s| (s, report))
    }

    const QUAD: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n";

    #[test]
    fn negative_indices_tabs_crlf_and_quads() {
        let (scene, _) =
            parse_str("v\t0 0 0\r\nv 1\t0 0\r\nv 1 1 0\r\nv 0 1 0\r\nf -4 -3 -2 -1\r\n").unwrap();
        let mesh = &scene.meshes[0];
        assert_eq!(mesh.indices.len(), 2);
        assert_eq!(mesh.positions.len(), 4);
        assert_eq!(scene.instances[0].transform, Affine3A::IDENTITY);
    }

    #[test]
    fn usemtl_with_tabs_and_indentation_and_missing_materials() {
        let text = format!("{QUAD}usemtl\tlight\nf 1 2 3\n  usemtl wall # x\nf 1 3 4\nf 1 2 4\n");
        let (scene, report) = parse_str(&text).unwrap();
        let names = names_of(&scene);
        assert_eq!(names["light"].emission, Vec3::new(17.0, 12.0, 4.0));
        assert_eq!(names["wall"].emission, Vec3::ZERO);
        let mesh = &scene.meshes[0];
        let light = scene.materials.iter().position(|m| m.name == "light").unwrap() as u32;
        let wall = scene.materials.iter().position(|m| m.name == "wall").unwrap() as u32;
        assert_eq!(mesh.material_ids, vec![light, wall, wall]);
        assert_eq!(report.warnings.len(), 2, "{:?}", report.warnings);
    }

    #[test]
    fn faces_before_usemtl_get_the_default_material() {
        let (scene, _) = parse_str(&format!("{QUAD}f 1 2 3\n")).unwrap();
        assert_eq!(scene.materials, vec![Material::default()]);
        assert_eq!(scene.meshes[0].material_ids, vec![0]);
    }

    #[test]
    fn errors_name_the_line() {
        let err = parse_str(&format!("{QUAD}f 1 2 5\n")).unwrap_err();
        assert_eq!(
            err.to_string(),
            "t.obj: line 5: face vertex `5`: v index 5 is out of range (4 `v` statements so far)"
        );
        let err = parse_str(&format!("{QUAD}f -5 1 2\n")).unwrap_err();
        assert!(err.to_string().starts_with("t.obj: line 5: "), "{err}");
        let err = parse_str("v 0 0 0\nv 0 nan 0\n").unwrap_err();
        assert_eq!(err.to_string(), "t.obj: line 2: `nan` is not a finite number");
        let err = parse_str(&format!("{QUAD}f 1/-99999999999 2 3\n")).unwrap_err();
        assert!(err.to_string().contains("vt index"), "{err}");
        let err = parse_str(&format!("{QUAD}vt 0 0\nvn 0 0 1\nf 1/1/1/1 2 3\n")).unwrap_err();
        assert!(err.to_string().contains("more than three"), "{err}");
        let err = parse_str("v 1 2\n").unwrap_err();
        assert!(err.to_string().contains("line 1"), "{err}");
    }

    #[test]
    fn degenerate_faces_are_dropped_and_counted() {
        let text = format!("{QUAD}f 1 2 3\nf 1 1 2\nf 1 2\nl 1 2 3\n");
        let (scene, report) = parse_str(&text).unwrap();
        assert_eq!(scene.meshes[0].indices.len(), 1);
        assert_eq!(report.degenerate_dropped, 2);
    }

    #[test]
    fn texture_coordinates_only_when_textured() {
        let text = format!("{QUAD}vt 0 0.25\nf 1/1 2/1 3/1\n");
        let (scene, _) = parse_str(&text).unwrap();
        assert!(scene.meshes[0].uvs.is_none(), "no material has a texture");
    }

    #[test]
    fn empty_file_has_no_mesh() {
        let (scene, report) = parse_str("# nothing\n").unwrap();
        assert!(scene.meshes.is_empty() && scene.instances.is_empty());
        assert_eq!(report.warnings, vec!["t.obj: no triangles".to_string()]);
    }
}
