//! glTF meshes: each becomes one [`Mesh`](crate::Mesh), its `TRIANGLES` primitives merged
//! with a material each.

use glam::{Vec2, Vec3};
use gltf::accessor::{DataType, Dimensions};
use gltf::mesh::Mode;

use super::accessors::{VEC3, check_accessor};
use super::loader::Loader;
use crate::error::{Location, SceneError};
use crate::validate::{MeshBuilder, Part};

impl Loader<'_> {
    pub(super) fn load_mesh(&mut self, mesh: &gltf::Mesh, skinned: bool) -> Result<Option<u32>, SceneError> {
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
}
