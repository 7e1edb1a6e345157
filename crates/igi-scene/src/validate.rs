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

use std::fmt;
use std::path::Path;

use glam::{Affine3A, DVec3, Vec2, Vec3};
use rayon::prelude::*;

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
    /// Normals of the vertices up to the last part that had them (zero for vertices of parts
    /// without), empty until one had.
    normals: Vec<Vec3>,
    /// Texture coordinates, as `normals`.
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
        let out_of_range = part.triangles.par_iter().enumerate().find_map_first(|(triangle, tri)| {
            tri.iter().find(|&&i| i as usize >= count).map(|&index| (triangle, index))
        });
        if let Some((triangle, index)) = out_of_range {
            return Err(Defect::IndexOutOfRange { triangle, index, vertex_count: count });
        }
        let base = u32::try_from(self.positions.len())
            .ok()
            .filter(|base| u32::try_from(count).is_ok_and(|n| base.checked_add(n).is_some()))
            .ok_or(Defect::TooManyVertices)?;

        let mut triangles = part.triangles;
        // Checked in parallel first: files rarely have zero-area triangles, and then the
        // triangles are kept as they are, not copied.
        if !triangles.par_iter().all(|&tri| has_area(&part.positions, tri)) {
            let before = triangles.len();
            triangles.retain(|&tri| has_area(&part.positions, tri));
            self.degenerate += before - triangles.len();
        }

        // Normals and uvs are stored only once some part has them; the parts before are
        // padded with zeros then, and the parts after on arrival or in `finish`.
        let vertices_before = self.positions.len();
        match part.normals {
            Some(normals) => {
                self.normals_present = true;
                self.normals.resize(vertices_before, Vec3::ZERO);
                append(&mut self.normals, unit_normals(normals, &part.positions, &triangles));
            }
            None => self.normals_missing = true,
        }
        if let Some(uvs) = part.uvs {
            self.uvs_present = true;
            self.uvs.resize(vertices_before, Vec2::ZERO);
            append(&mut self.uvs, uvs);
        }
        append(&mut self.positions, part.positions);
        self.material_ids.extend(std::iter::repeat_n(part.material, triangles.len()));
        if base == 0 {
            append(&mut self.indices, triangles);
        } else {
            self.indices.extend(triangles.into_iter().map(|t| t.map(|i| i + base)));
        }
        Ok(())
    }

    /// The finished mesh. Vertices no triangle uses are removed and exact duplicates (same
    /// position, uv and normal bits) are merged; shading normals that only repeat the
    /// triangles' own normals are dropped. Both matter for memory: a Minecraft-style scene
    /// (lost-empire) has a unique `v/vt/vn` triple at almost every quad corner, but its normals
    /// are all flat, and without them half of the vertices turn out to be duplicates.
    pub fn finish(mut self) -> Built {
        let normals_dropped = self.normals_present && self.normals_missing;
        let keep_normals = self.normals_present
            && !self.normals_missing
            && !all_flat(&self.normals, &self.positions, &self.indices);
        if self.uvs_present {
            self.uvs.resize(self.positions.len(), Vec2::ZERO);
        }
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

/// Appends `values` to `to`, moving them when `to` is empty (the first part of a mesh, or
/// its only one) instead of copying.
fn append<T>(to: &mut Vec<T>, mut values: Vec<T>) {
    if to.is_empty() {
        *to = values;
    } else {
        to.append(&mut values);
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

fn check_finite<T: Sync>(
    name: &'static str,
    values: &[T],
    finite: impl Fn(&T) -> bool + Sync,
) -> Result<(), Defect> {
    match values.par_iter().position_first(|v| !finite(v)) {
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
    triangles.par_iter().all(|&[a, b, c]| {
        let [pa, pb, pc] = [a, b, c].map(|i| positions[i as usize].as_dvec3());
        let geometric = (pb - pa).cross(pc - pa).normalize_or_zero();
        [a, b, c].iter().all(|&i| normals[i as usize].as_dvec3().dot(geometric) >= COS_TOLERANCE)
    })
}

/// Renumbers vertices in order of first use by the triangles, dropping unused ones and
/// merging bit-identical ones.
fn weld(mesh: &mut Mesh) {
    let first = first_of_key(mesh);
    // Indexed by the first vertex of a key: its new index, once a triangle has used it.
    let mut new_index = vec![u32::MAX; mesh.positions.len()];
    let mut order: Vec<u32> = Vec::new();
    for index in mesh.indices.as_flattened_mut() {
        let first = first[*index as usize];
        let new = &mut new_index[first as usize];
        if *new == u32::MAX {
            // At most one per vertex, and the builder keeps the vertex count within `u32`.
            *new = order.len() as u32;
            order.push(first);
        }
        *index = *new;
    }
    drop(new_index);
    mesh.positions = order.iter().map(|&i| mesh.positions[i as usize]).collect();
    if let Some(uvs) = &mut mesh.uvs {
        *uvs = order.iter().map(|&i| uvs[i as usize]).collect();
    }
    if let Some(normals) = &mut mesh.normals {
        *normals = order.iter().map(|&i| normals[i as usize]).collect();
    }
}

/// The bits that make two vertices the same: position, uv and normal (zero when absent).
type VertexKey = [u32; 8];

fn vertex_key(mesh: &Mesh, i: usize) -> VertexKey {
    let [x, y, z] = mesh.positions[i].to_array().map(f32::to_bits);
    let [u, v] = mesh.uvs.as_ref().map_or([0; 2], |uv| uv[i].to_array().map(f32::to_bits));
    let [nx, ny, nz] = mesh.normals.as_ref().map_or([0; 3], |n| n[i].to_array().map(f32::to_bits));
    [x, y, z, u, v, nx, ny, nz]
}

/// A 64-bit hash of a key (FxHash's multiply-rotate over two words at a time). Equal hashes
/// are only a hint: keys are compared in full, so collisions cost time, never correctness.
fn key_hash(key: &VertexKey) -> u64 {
    const K: u64 = 0xf135_7aea_2e62_a9c5;
    let mut hash = 0u64;
    for pair in key.chunks_exact(2) {
        let word = u64::from(pair[0]) | (u64::from(pair[1]) << 32);
        hash = (hash.rotate_left(26) ^ word).wrapping_mul(K);
    }
    hash ^ (hash >> 29)
}

/// For every vertex, the smallest index of a vertex with the same key.
///
/// The vertices are sorted by hash and index in parallel (hash in the high and index in the
/// low bits of one `u128`, so the order is total and the result the same at any thread
/// count); a run of equal hashes is then sorted by key, stably, so each group of equal keys
/// starts with its smallest index. The cost is O(n log n) whatever the keys, where a hash map
/// of 32-byte keys took most of a large file's load time.
fn first_of_key(mesh: &Mesh) -> Vec<u32> {
    let count = mesh.positions.len();
    // The builder keeps the vertex count within `u32`.
    let mut sorted: Vec<u128> = Vec::with_capacity(count);
    (0..count)
        .into_par_iter()
        .map(|i| (u128::from(key_hash(&vertex_key(mesh, i))) << 64) | i as u128)
        .collect_into_vec(&mut sorted);
    sorted.par_sort_unstable();
    let vertex = |entry: u128| entry as u32;
    let mut first: Vec<u32> = (0..count as u32).collect();
    for run in sorted.chunk_by_mut(|a, b| a >> 64 == b >> 64) {
        if run.len() == 1 {
            continue;
        }
        run.sort_by_key(|&entry| vertex_key(mesh, vertex(entry) as usize));
        for group in run
            .chunk_by(|&a, &b| vertex_key(mesh, vertex(a) as usize) == vertex_key(mesh, vertex(b) as usize))
        {
            let smallest = vertex(group[0]);
            for &entry in &group[1..] {
                first[vertex(entry) as usize] = smallest;
            }
        }
    }
    first
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::*;

    /// `weld` as first written: a hash map from key to new index, filled in order of first use.
    fn reference_weld(mesh: &mut Mesh) {
        let mut new_of_key = std::collections::HashMap::new();
        let mut order = Vec::new();
        let mut indices = std::mem::take(&mut mesh.indices);
        for index in indices.as_flattened_mut() {
            let old = *index as usize;
            let next = order.len() as u32;
            *index = *new_of_key.entry(vertex_key(mesh, old)).or_insert_with(|| {
                order.push(old);
                next
            });
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

    /// Meshes with many duplicate and unused vertices: coordinates from a handful of values
    /// (with both zeros, whose bits differ), attributes present or not.
    fn duplicated_mesh() -> impl Strategy<Value = Mesh> {
        let value = prop::sample::select(vec![0.0f32, -0.0, 1.0, 2.5, -3.0]);
        let vertex = (
            prop::array::uniform3(value.clone()),
            prop::array::uniform2(value.clone()),
            prop::array::uniform3(value),
        );
        (
            prop::collection::vec(vertex, 1..60),
            any::<bool>(),
            any::<bool>(),
            prop::collection::vec(any::<prop::sample::Index>(), 0..120),
        )
            .prop_map(|(vertices, with_uvs, with_normals, corners)| {
                let count = vertices.len();
                Mesh {
                    positions: vertices.iter().map(|v| Vec3::from(v.0)).collect(),
                    uvs: with_uvs.then(|| vertices.iter().map(|v| Vec2::from(v.1)).collect()),
                    normals: with_normals.then(|| vertices.iter().map(|v| Vec3::from(v.2)).collect()),
                    indices: corners
                        .chunks_exact(3)
                        .map(|c| [0, 1, 2].map(|k| c[k].index(count) as u32))
                        .collect(),
                    ..Mesh::default()
                }
            })
    }

    proptest! {
        #[test]
        fn weld_matches_the_reference(mesh in duplicated_mesh()) {
            let mut welded = mesh.clone();
            weld(&mut welded);
            let mut expected = mesh;
            reference_weld(&mut expected);
            prop_assert_eq!(welded.indices, expected.indices);
            let bits = |v: &[Vec3]| v.iter().map(|p| p.to_array().map(f32::to_bits)).collect::<Vec<_>>();
            prop_assert_eq!(bits(&welded.positions), bits(&expected.positions));
            prop_assert_eq!(welded.normals.as_deref().map(bits), expected.normals.as_deref().map(bits));
            let uv_bits = |v: &[Vec2]| v.iter().map(|p| p.to_array().map(f32::to_bits)).collect::<Vec<_>>();
            prop_assert_eq!(welded.uvs.as_deref().map(uv_bits), expected.uvs.as_deref().map(uv_bits));
        }
    }

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
