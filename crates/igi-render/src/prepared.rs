//! [`PreparedScene`]: a [`Scene`] made ready to render. The triangle geometry moves into the
//! acceleration structure ([`Accel`], which reorders each mesh's triangles into BVH leaf
//! order); everything else a shader needs per triangle (material, vertex normals, texture
//! coordinates) stays here, permuted to the same order, next to the materials, textures,
//! lights and the table of emissive triangles.
//!
//! Shading reads a hit through [`PreparedScene::surface`]: world position (from the
//! barycentrics, not from `t`, for a robust shadow-ray origin), geometric and shading normal,
//! texture coordinates and material.

use crate::lights::{AreaLights, EmissiveTriangle};
use crate::texture::{self, Filter};
use glam::{Affine3A, Mat3A, Vec2, Vec3};
use igi_bvh::{Aabb, Accel, Hit, TriangleMesh};
use igi_scene::{Camera, Light, Material, Scene, Texture};

/// Per-triangle and per-vertex shading data of one mesh, in the accel's triangle order.
#[derive(Clone, Debug, Default)]
pub struct MeshShading {
    /// Name from the source file.
    pub name: String,
    /// Per-vertex unit normals (object space), if the source had them.
    pub normals: Option<Vec<Vec3>>,
    /// Per-vertex texture coordinates, if the source had them.
    pub uvs: Option<Vec<Vec2>>,
    /// Material index of each stored triangle (always a valid index into the materials).
    pub material_ids: Vec<u32>,
}

/// Everything shading needs to know about a ray hit, in world space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfacePoint {
    /// Hit position, interpolated from the triangle's corners.
    pub position: Vec3,
    /// Unit geometric normal, following the triangle's winding (the emitting side of an area
    /// light).
    pub geometric_normal: Vec3,
    /// Unit shading normal: interpolated vertex normals where the mesh has them, else the
    /// geometric normal. Always in the same hemisphere as `geometric_normal`.
    pub shading_normal: Vec3,
    /// Interpolated texture coordinates (zero if the mesh has none).
    pub uv: Vec2,
    /// Material index.
    pub material: u32,
}

/// A scene ready for rendering: acceleration structure plus shading data.
#[derive(Debug)]
pub struct PreparedScene {
    accel: Accel,
    meshes: Vec<MeshShading>,
    materials: Vec<Material>,
    textures: Vec<Texture>,
    lights: Vec<Light>,
    camera: Option<Camera>,
    area_lights: AreaLights,
    /// Per instance: the matrix taking object-space normals to world space (inverse
    /// transpose), or `None` for the identity.
    normal_matrices: Vec<Option<Mat3A>>,
    texture_filter: Filter,
}

impl PreparedScene {
    /// Builds the acceleration structure over `scene` and the shading tables. Material ids
    /// out of range (which a valid scene never has) fall back to a default grey material.
    /// Logs a warning if the scene has no light at all (the renderer then lights it with a
    /// headlight at the camera).
    pub fn new(scene: Scene) -> Self {
        let Scene { meshes, instances, mut materials, textures, lights, camera, environment: _ } = scene;

        let valid = materials.len();
        let mut fallback = None;
        let mut geometry = Vec::with_capacity(meshes.len());
        let mut shading = Vec::with_capacity(meshes.len());
        for mesh in meshes {
            let mut ids = mesh.material_ids;
            ids.resize(mesh.indices.len(), u32::MAX);
            for id in &mut ids {
                if *id as usize >= valid {
                    *id = *fallback.get_or_insert_with(|| {
                        materials.push(Material { name: "igi-fallback".into(), ..Material::default() });
                        (materials.len() - 1) as u32
                    });
                }
            }
            geometry.push(TriangleMesh { positions: mesh.positions, indices: mesh.indices });
            shading.push(MeshShading {
                name: mesh.name,
                normals: mesh.normals,
                uvs: mesh.uvs,
                material_ids: ids,
            });
        }
        let placements: Vec<(u32, Affine3A)> = instances.iter().map(|i| (i.mesh, i.transform)).collect();
        let (accel, orders) = Accel::build(geometry, &placements);
        for (mesh, order) in shading.iter_mut().zip(&orders) {
            mesh.material_ids = order.iter().map(|&i| mesh.material_ids[i as usize]).collect();
        }

        let normal_matrices = placements
            .iter()
            .map(|(_, m)| (*m != Affine3A::IDENTITY).then(|| m.matrix3.inverse().transpose()))
            .collect();

        let mut prepared = Self {
            accel,
            meshes: shading,
            materials,
            textures,
            lights,
            camera,
            area_lights: AreaLights::default(),
            normal_matrices,
            texture_filter: Filter::Bilinear,
        };
        prepared.area_lights = AreaLights::new(prepared.collect_emissive());
        if !prepared.has_lights() {
            tracing::warn!("the scene has no light source; lighting it with a headlight at the camera");
        }
        prepared
    }

    /// The emissive triangles of every instance, in world space.
    fn collect_emissive(&self) -> Vec<EmissiveTriangle> {
        let mut out = Vec::new();
        for instance in 0..self.accel.instance_count() as u32 {
            let mesh_index = self.accel.instance_mesh(instance) as usize;
            let mesh = &self.accel.meshes()[mesh_index];
            let shading = &self.meshes[mesh_index];
            let m = self.accel.instance_transform(instance);
            for (prim, &material) in shading.material_ids.iter().enumerate() {
                let material = &self.materials[material as usize];
                if !material.is_emissive() {
                    continue;
                }
                let [a, b, c] = mesh.triangle(prim as u32).map(|p| m.transform_point3(p));
                let (e1, e2) = (b - a, c - a);
                out.push(EmissiveTriangle {
                    instance,
                    prim: prim as u32,
                    p0: a,
                    e1,
                    e2,
                    normal: self.accel.geometric_normal(instance, prim as u32),
                    area: 0.5 * e1.cross(e2).length(),
                    emission: material.emission,
                });
            }
        }
        out
    }

    /// The acceleration structure (stored triangles in leaf order).
    pub fn accel(&self) -> &Accel {
        &self.accel
    }

    /// Shading data per mesh.
    pub fn meshes(&self) -> &[MeshShading] {
        &self.meshes
    }

    /// The materials (every material id of every mesh indexes this).
    pub fn materials(&self) -> &[Material] {
        &self.materials
    }

    /// The textures.
    pub fn textures(&self) -> &[Texture] {
        &self.textures
    }

    /// Point, spot and directional lights.
    pub fn lights(&self) -> &[Light] {
        &self.lights
    }

    /// The scene's own camera, if it had one.
    pub fn camera(&self) -> Option<&Camera> {
        self.camera.as_ref()
    }

    /// The emissive triangles and their sampling distribution.
    pub fn area_lights(&self) -> &AreaLights {
        &self.area_lights
    }

    /// True if the scene has any light source (emissive triangle or punctual light).
    pub fn has_lights(&self) -> bool {
        !self.lights.is_empty() || !self.area_lights.is_empty()
    }

    /// World bounds of all instances.
    pub fn bounds(&self) -> Aabb {
        self.accel.bounds()
    }

    /// Number of triangles in the world (each instance counts its mesh's triangles).
    pub fn triangle_count(&self) -> usize {
        (0..self.accel.instance_count() as u32)
            .map(|i| self.accel.meshes()[self.accel.instance_mesh(i) as usize].indices.len())
            .sum()
    }

    /// Texture filter used by [`PreparedScene::albedo`] (bilinear by default).
    pub fn set_texture_filter(&mut self, filter: Filter) {
        self.texture_filter = filter;
    }

    /// Material index of stored triangle `prim` of `instance`.
    #[inline]
    pub fn material_id(&self, instance: u32, prim: u32) -> u32 {
        let mesh = self.accel.instance_mesh(instance) as usize;
        self.meshes[mesh].material_ids[prim as usize]
    }

    /// True if stored triangle `prim` of `instance` is an area light.
    #[inline]
    pub fn is_emissive(&self, instance: u32, prim: u32) -> bool {
        self.materials[self.material_id(instance, prim) as usize].is_emissive()
    }

    /// World-space corners of every emissive triangle, in the order of
    /// [`AreaLights::triangles`] (corners in the stored winding order).
    pub fn emissive_triangle_corners(&self) -> Vec<[Vec3; 3]> {
        self.area_lights.triangles().iter().map(|t| [t.p0, t.p0 + t.e1, t.p0 + t.e2]).collect()
    }

    /// The surface at a hit (`hit.is_hit()` must hold): see [`SurfacePoint`].
    pub fn surface(&self, hit: &Hit) -> SurfacePoint {
        let (instance, prim) = (hit.instance, hit.prim);
        let mesh_index = self.accel.instance_mesh(instance) as usize;
        let mesh = &self.accel.meshes()[mesh_index];
        let shading = &self.meshes[mesh_index];
        let idx = mesh.indices[prim as usize];
        let [a, b, c] = idx.map(|i| mesh.positions[i as usize]);
        let (u, v) = (hit.u, hit.v);
        let local = a + u * (b - a) + v * (c - a);
        let m = self.accel.instance_transform(instance);
        let position =
            if self.normal_matrices[instance as usize].is_some() { m.transform_point3(local) } else { local };
        // The winding normal, through the inverse transpose for a transformed instance (the
        // same as `Accel::geometric_normal`, from the corners already at hand).
        let n = (b - a).cross(c - a);
        let geometric_normal = match &self.normal_matrices[instance as usize] {
            Some(nm) => Vec3::from(nm.mul_vec3a(n.into())),
            None => n,
        }
        .normalize();

        let w = 1.0 - u - v;
        let shading_normal = shading
            .normals
            .as_ref()
            .map(|n| {
                let [n0, n1, n2] = idx.map(|i| n[i as usize]);
                let n = w * n0 + u * n1 + v * n2;
                let n = match &self.normal_matrices[instance as usize] {
                    Some(nm) => Vec3::from(nm.mul_vec3a(n.into())),
                    None => n,
                };
                n.normalize_or_zero()
            })
            .filter(|n| *n != Vec3::ZERO && n.is_finite())
            .map_or(geometric_normal, |n| if n.dot(geometric_normal) < 0.0 { -n } else { n });

        let uv = shading.uvs.as_ref().map_or(Vec2::ZERO, |t| {
            let [t0, t1, t2] = idx.map(|i| t[i as usize]);
            w * t0 + u * t1 + v * t2
        });

        SurfacePoint {
            position,
            geometric_normal,
            shading_normal,
            uv,
            material: shading.material_ids[prim as usize],
        }
    }

    /// Diffuse reflectance ρ at texture coordinates `uv` of `material`: the material's
    /// `diffuse` times its diffuse texture (RGB), if any.
    #[inline]
    pub fn albedo(&self, material: u32, uv: Vec2) -> Vec3 {
        let m = &self.materials[material as usize];
        match m.diffuse_texture.and_then(|t| self.textures.get(t as usize)) {
            Some(tex) => m.diffuse * texture::sample(tex, uv, self.texture_filter).truncate(),
            None => m.diffuse,
        }
    }
}
