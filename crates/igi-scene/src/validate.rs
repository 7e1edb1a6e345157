//! Validation shared by every loader: [`MeshBuilder`] turns the raw pieces a parser produced
//! into a [`Mesh`] that keeps the model's promises, and [`MAX_INSTANCES`] bounds a scene's
//! instances.
//!
//! Those promises (see [`Mesh`]) are what lets the BVH builder and the shaders skip checks on
//! their hot paths: every coordinate finite, every index in range, every triangle of non-zero
//! area, attribute arrays as long as the position array, shading normals of unit length.
//! Loaders differ in how they report a position in the source, so a [`Defect`] carries indices
//! relative to the part it was found in and the loader turns it into a
//! [`SceneError`](crate::SceneError) with its own location.

use std::collections::HashMap;
use std::fmt;
use std::path::Path;

use glam::{Affine3A, DVec3, Vec2, Vec3};

use crate::error::{Location, SceneError};
use crate::model::{Instance, Material, Mesh, Scene};
use crate::report::LoadReport;

/// Most instances a scene may have. Far above real scenes (the paper's largest has four), it
/// bounds what a hostile file can cost: every ray may meet every instance when they overlap,
/// and 100,000 coincident instances still render a small frame in seconds.
pub const MAX_INSTANCES: usize = 100_000;

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

/// One piece of a mesh with a single material: an OBJ material group, a glTF primitive, a PLY
/// file. Indices are local to the part.
#[derive(Clone, Debug, Default)]
pub(crate) struct Part {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Per-vertex shading normals, any length (normalised by the builder).
    pub normals: Option<Vec<Vec3>>,
    /// Per-vertex texture coordinates, v = 0 at the top row of the image.
    pub uvs: Option<Vec<Vec2>>,
    /// Triangles indexing `positions`.
    pub triangles: Vec<[u32; 3]>,
    /// Index into the scene's materials for every triangle of the part.
    pub material: u32,
}

/// Why a part was rejected. Indices are relative to the part.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Defect {
    /// An attribute array does not have one entry per position.
    AttributeCount {
        /// `"normal"` or `"uv"`.
        attribute: &'static str,
        /// Its length.
        count: usize,
        /// The number of positions.
        expected: usize,
    },
    /// A NaN or infinite component.
    NonFinite {
        /// `"position"`, `"normal"` or `"uv"`.
        attribute: &'static str,
        /// The vertex.
        vertex: usize,
    },
    /// A triangle refers to a vertex that does not exist.
    IndexOutOfRange {
        /// The triangle.
        triangle: usize,
        /// The offending index.
        index: u32,
        /// The number of vertices of the part.
        vertex_count: usize,
    },
    /// The mesh would have more vertices than a `u32` index can address.
    TooManyVertices,
}

impl Defect {
    /// The vertex the defect is at, if it is about one vertex.
    pub fn vertex(&self) -> Option<usize> {
        match self {
            Self::NonFinite { vertex, .. } => Some(*vertex),
            _ => None,
        }
    }
}

impl fmt::Display for Defect {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::AttributeCount { attribute, count, expected } => {
                write!(f, "{count} {attribute} values for {expected} vertex positions (they must match)")
            }
            Self::NonFinite { attribute, vertex } => {
                write!(f, "vertex {vertex} has a NaN or infinite {attribute}")
            }
            Self::IndexOutOfRange { triangle, index, vertex_count } => write!(
                f,
                "triangle {triangle} refers to vertex {index}, but there are only \
                 {vertex_count} vertices"
            ),
            Self::TooManyVertices => write!(f, "more than 2^32 vertices in one mesh"),
        }
    }
}

/// What [`MeshBuilder::finish`] hands back besides the mesh.
#[derive(Debug)]
pub(crate) struct Built {
    /// The validated mesh.
    pub mesh: Mesh,
    /// Zero-area triangles that were dropped.
    pub degenerate: usize,
    /// True if some parts had normals and others did not, so the mesh has none (a mesh carries
    /// normals for all of its vertices or for none).
    pub normals_dropped: bool,
}

impl Built {
    /// The scene of a file that is one mesh (OBJ, PLY): this mesh with `materials`, placed once
    /// by an identity [`Instance`], or no mesh (with a warning) if no triangle is left.
    pub fn into_scene(self, materials: Vec<Material>, file: &Path, report: &mut LoadReport) -> Scene {
        let mut scene = Scene { materials, ..Scene::default() };
        if self.mesh.indices.is_empty() {
            report.warn(file, "no triangles");
        } else {
            scene.meshes.push(self.mesh);
            scene.instances.push(Instance { mesh: 0, transform: Affine3A::IDENTITY });
        }
        scene
    }
}

/// Accumulates [`Part`]s into one [`Mesh`], validating each on the way in.
#[derive(Debug, Default)]
pub(crate) struct MeshBuilder {
    name: String,
    positions: Vec<Vec3>,
    /// Normals of every vertex so far; zero for parts that had none (see `normals_missing`).
    normals: Vec<Vec3>,
    uvs: Vec<Vec2>,
    indices: Vec<[u32; 3]>,
    material_ids: Vec<u32>,
    normals_present: bool,
    normals_missing: bool,
    uvs_present: bool,
    degenerate: usize,
}

impl MeshBuilder {
    /// An empty mesh called `name`.
    pub fn new(name: impl Into<String>) -> Self {
        Self { name: name.into(), ..Self::default() }
    }

    /// Validates `part` and appends it. On error nothing is appended.
    pub fn add(&mut self, part: Part) -> Result<(), Defect> {
        let count = part.positions.len();
        check_attribute("normal", part.normals.as_deref(), count)?;
        check_attribute("uv", part.uvs.as_deref(), count)?;
        check_finite("position", &part.positions, |p| p.is_finite())?;
        if let Some(normals) = &part.normals {
            check_finite("normal", normals, |n| n.is_finite())?;
        }
        if let Some(uvs) = &part.uvs {
            check_finite("uv", uvs, |uv| uv.is_finite())?;
        }
        for (triangle, tri) in part.triangles.iter().enumerate() {
            if let Some(&index) = tri.iter().find(|&&i| i as usize >= count) {
                return Err(Defect::IndexOutOfRange { triangle, index, vertex_count: count });
            }
        }
        let base = u32::try_from(self.positions.len())
            .ok()
            .filter(|base| u32::try_from(count).is_ok_and(|n| base.checked_add(n).is_some()))
            .ok_or(Defect::TooManyVertices)?;

        let kept: Vec<[u32; 3]> =
            part.triangles.iter().copied().filter(|&tri| has_area(&part.positions, tri)).collect();
        self.degenerate += part.triangles.len() - kept.len();

        match part.normals {
            Some(normals) => {
                self.normals_present = true;
                self.normals.extend(unit_normals(normals, &part.positions, &kept));
            }
            None => {
                self.normals_missing = true;
                self.normals.resize(self.normals.len() + count, Vec3::ZERO);
            }
        }
        match part.uvs {
            Some(uvs) => {
                self.uvs_present = true;
                self.uvs.extend(uvs);
            }
            None => self.uvs.resize(self.uvs.len() + count, Vec2::ZERO),
        }
        self.positions.extend(part.positions);
        self.material_ids.extend(std::iter::repeat_n(part.material, kept.len()));
        self.indices.extend(kept.into_iter().map(|t| t.map(|i| i + base)));
        Ok(())
    }

    /// The finished mesh. Vertices no triangle uses are removed and exact duplicates (same
    /// position, uv and normal bits) are merged; shading normals that only repeat the
    /// triangles' own normals are dropped. Both matter for memory: a Minecraft-style scene
    /// (lost-empire) has a unique `v/vt/vn` triple at almost every quad corner, but its normals
    /// are all flat, and without them half of the vertices turn out to be duplicates.
    pub fn finish(self) -> Built {
        let normals_dropped = self.normals_present && self.normals_missing;
        let keep_normals = self.normals_present
            && !self.normals_missing
            && !all_flat(&self.normals, &self.positions, &self.indices);
        let mut mesh = Mesh {
            name: self.name,
            positions: self.positions,
            normals: keep_normals.then_some(self.normals),
            uvs: self.uvs_present.then_some(self.uvs),
            indices: self.indices,
            material_ids: self.material_ids,
        };
        weld(&mut mesh);
        Built { mesh, degenerate: self.degenerate, normals_dropped }
    }
}

fn check_attribute<T>(name: &'static str, values: Option<&[T]>, expected: usize) -> Result<(), Defect> {
    match values {
        Some(values) if values.len() != expected => {
            Err(Defect::AttributeCount { attribute: name, count: values.len(), expected })
        }
        _ => Ok(()),
    }
}

fn check_finite<T>(name: &'static str, values: &[T], finite: impl Fn(&T) -> bool) -> Result<(), Defect> {
    match values.iter().position(|v| !finite(v)) {
        Some(vertex) => Err(Defect::NonFinite { attribute: name, vertex }),
        None => Ok(()),
    }
}

/// True unless the triangle has exactly zero area. The cross product is taken in f64 so that
/// large but finite coordinates cannot overflow into a spurious infinity or NaN.
fn has_area(positions: &[Vec3], [a, b, c]: [u32; 3]) -> bool {
    let [a, b, c] = [a, b, c].map(|i| positions[i as usize].as_dvec3());
    (b - a).cross(c - a) != DVec3::ZERO
}

/// Normalises shading normals. A zero normal (exporters write them for vertices they could not
/// smooth) is replaced by the area-weighted normal of the triangles that use the vertex, which
/// is what the renderer would fall back to anyway.
fn unit_normals(mut normals: Vec<Vec3>, positions: &[Vec3], triangles: &[[u32; 3]]) -> Vec<Vec3> {
    let mut any_zero = false;
    for n in &mut normals {
        match n.try_normalize() {
            Some(unit) => *n = unit,
            None => {
                *n = Vec3::ZERO;
                any_zero = true;
            }
        }
    }
    if !any_zero {
        return normals;
    }
    let broken: Vec<bool> = normals.iter().map(|n| *n == Vec3::ZERO).collect();
    for &[a, b, c] in triangles {
        let [pa, pb, pc] = [a, b, c].map(|i| positions[i as usize].as_dvec3());
        let weighted = (pb - pa).cross(pc - pa).as_vec3();
        for i in [a, b, c] {
            if broken[i as usize] {
                normals[i as usize] += weighted;
            }
        }
    }
    for (n, &was_broken) in normals.iter_mut().zip(&broken) {
        if was_broken {
            // A vertex no triangle uses keeps +Y; `weld` removes it later.
            *n = n.try_normalize().unwrap_or(Vec3::Y);
        }
    }
    normals
}

/// True if every vertex normal equals (to within 0.1°) the normal of each triangle using it,
/// so that interpolating them reproduces the flat geometric normal everywhere.
fn all_flat(normals: &[Vec3], positions: &[Vec3], triangles: &[[u32; 3]]) -> bool {
    const COS_TOLERANCE: f64 = 0.999_998_5;
    triangles.iter().all(|&[a, b, c]| {
        let [pa, pb, pc] = [a, b, c].map(|i| positions[i as usize].as_dvec3());
        let geometric = (pb - pa).cross(pc - pa).normalize_or_zero();
        [a, b, c].iter().all(|&i| normals[i as usize].as_dvec3().dot(geometric) >= COS_TOLERANCE)
    })
}

/// Renumbers vertices in order of first use by the triangles, dropping unused ones and
/// merging bit-identical ones.
fn weld(mesh: &mut Mesh) {
    type Key = ([u32; 3], [u32; 2], [u32; 3]);
    let key = |i: usize| -> Key {
        (
            mesh.positions[i].to_array().map(f32::to_bits),
            mesh.uvs.as_ref().map_or([0; 2], |uv| uv[i].to_array().map(f32::to_bits)),
            mesh.normals.as_ref().map_or([0; 3], |n| n[i].to_array().map(f32::to_bits)),
        )
    };
    let mut remap = vec![u32::MAX; mesh.positions.len()];
    let mut first_use: HashMap<Key, u32> = HashMap::with_capacity(mesh.positions.len());
    let mut order: Vec<usize> = Vec::with_capacity(mesh.positions.len());
    let mut indices = std::mem::take(&mut mesh.indices);
    for tri in &mut indices {
        for index in tri.iter_mut() {
            let old = *index as usize;
            if remap[old] == u32::MAX {
                let next = order.len() as u32;
                remap[old] = *first_use.entry(key(old)).or_insert_with(|| {
                    order.push(old);
                    next
                });
            }
            *index = remap[old];
        }
    }
    mesh.indices = indices;
    mesh.positions = order.iter().map(|&i| mesh.positions[i]).collect();
    if let Some(uvs) = &mut mesh.uvs {
        *uvs = order.iter().map(|&i| uvs[i]).collect();
    }
    if let Some(normals) = &mut mesh.normals {
        *normals = order.iter().map(|&i| normals[i]).collect();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quad_part() -> Part {
        Part {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y],
            triangles: vec![[0, 1, 2], [0, 2, 3]],
            ..Part::default()
        }
    }

    #[test]
    fn drops_degenerate_triangles_and_unused_vertices() {
        let mut part = quad_part();
        part.positions.push(Vec3::splat(5.0));
        part.triangles.push([0, 0, 1]);
        part.triangles.push([0, 1, 4]);
        part.positions.push(Vec3::new(2.0, 0.0, 0.0));
        part.triangles.push([0, 1, 5]);
        let mut builder = MeshBuilder::new("m");
        builder.add(part).unwrap();
        let built = builder.finish();
        assert_eq!(built.degenerate, 2, "repeated index and collinear triangle");
        assert_eq!(built.mesh.indices.len(), 3);
        assert_eq!(built.mesh.positions.len(), 5, "the unused vertex 5 is gone");
        assert_eq!(built.mesh.material_ids, vec![0; 3]);
    }

    #[test]
    fn rejects_non_finite_and_out_of_range() {
        let mut part = quad_part();
        part.positions[2].y = f32::NAN;
        let err = MeshBuilder::new("m").add(part).unwrap_err();
        assert_eq!(err.vertex(), Some(2));

        let mut part = quad_part();
        part.triangles.push([0, 1, 4]);
        let err = MeshBuilder::new("m").add(part).unwrap_err();
        assert_eq!(err, Defect::IndexOutOfRange { triangle: 2, index: 4, vertex_count: 4 });

        let mut part = quad_part();
        part.uvs = Some(vec![Vec2::ZERO; 3]);
        assert!(matches!(
            MeshBuilder::new("m").add(part),
            Err(Defect::AttributeCount { attribute: "uv", count: 3, expected: 4 })
        ));
    }

    #[test]
    fn normals_are_unit_and_all_or_nothing() {
        let tilted = Vec3::new(0.0, 0.6, 0.8);
        let mut part = quad_part();
        part.normals = Some(vec![tilted * 2.0, Vec3::ZERO, tilted, tilted]);
        let mut builder = MeshBuilder::new("m");
        builder.add(part).unwrap();
        let built = builder.finish();
        let normals = built.mesh.normals.unwrap();
        assert!((normals[0] - tilted).length() < 1e-6, "normalised");
        assert!((normals[1] - Vec3::Z).length() < 1e-6, "zero normal replaced by the face's");

        let mut with = quad_part();
        with.normals = Some(vec![Vec3::Z; 4]);
        let mut builder = MeshBuilder::new("m");
        builder.add(with).unwrap();
        builder.add(quad_part()).unwrap();
        let built = builder.finish();
        assert!(built.normals_dropped);
        assert!(built.mesh.normals.is_none());
        assert_eq!(built.mesh.positions.len(), 4, "the second quad repeats the first");
        assert_eq!(built.mesh.indices[2], [0, 1, 2]);
    }

    #[test]
    fn flat_normals_are_dropped_and_duplicates_welded() {
        let mut builder = MeshBuilder::new("m");
        for material in 0..2 {
            let mut part = quad_part();
            part.normals = Some(vec![Vec3::Z; 4]);
            part.material = material;
            builder.add(part).unwrap();
        }
        let built = builder.finish();
        assert!(!built.normals_dropped, "nothing was lost");
        assert!(built.mesh.normals.is_none());
        assert_eq!(built.mesh.positions.len(), 4);
        assert_eq!(built.mesh.material_ids, vec![0, 0, 1, 1]);
    }
}
