//! [`PreparedScene`]: a [`Scene`] made ready to render. The triangle geometry moves into the
//! acceleration structure ([`Accel`], which reorders each mesh's triangles into BVH leaf
//! order); everything else a shader needs per triangle (material, vertex normals, texture
//! coordinates) stays here, permuted to the same order, next to the materials, textures,
//! lights and the table of emissive triangles.
//!
//! Shading reads a hit through [`PreparedScene::surface`]: world position (from the
//! barycentrics, not from `t`, for a robust shadow-ray origin), object-space position,
//! geometric and shading normal, texture coordinates, tangents and material; then the
//! material's surface shader ([`PreparedScene::shade8`], eight hits at a time) turns it into
//! BRDF parameters. Each material gets its shader from [`ShaderTable`] (its procedural
//! `[[shader]]`, or the textured material shader), and a user may replace it by their own
//! [`SurfaceShader`] ([`PreparedScene::set_shader`]).
//!
//! Materials with an alpha cut-out make the acceleration structure pass through their cut
//! texels ([`AlphaCutouts`], given to [`Accel::set_cutouts`]), so no query of any renderer
//! sees them.

//!
//! Its parts: the light sources as the renderers sample them ([`lights`]), the environment
//! (sky) light ([`environment_light`]), alpha cut-outs ([`cutout`]), a viewer's changes to the
//! lights ([`light_edit`]) and where the scene stands for a frame ([`scene_pose`]).

pub mod cutout;
pub mod environment_light;
pub mod light_edit;
pub mod lights;
pub mod scene_pose;

use crate::prepared::cutout::{AlphaCutouts, MeshMaterials};
use crate::prepared::environment_light::EnvironmentLight;
use crate::prepared::light_edit::{LightEdit, LightId};
use crate::prepared::lights::{AreaLights, EmissionMap, EmissiveTriangle, eye_light, footprint_mean};
use crate::prepared::scene_pose::ScenePose;
use glam::{Affine3A, Mat3A, Vec2, Vec3};
use igi_bvh::{Aabb, Accel, Hit, TriangleMesh};
use igi_scene::{Animation, Camera, Environment, Light, Material, Pose, SavedView, Scene, Texture};
use igi_shade::texture::MipMap;
use igi_shade::{BrdfParams, BrdfParams8, MaterialShader, ShaderTable, ShadingHit8, SurfaceShader};
use igi_simd::{F32x8, I32x8, M32x8, Vec3x8};
use std::sync::Arc;

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

impl MeshShading {
    /// Bytes of its per-vertex normals and texture coordinates and per-triangle materials.
    pub fn bytes(&self) -> usize {
        self.normals.as_ref().map_or(0, |n| n.len() * size_of::<Vec3>())
            + self.uvs.as_ref().map_or(0, |t| t.len() * size_of::<Vec2>())
            + self.material_ids.len() * size_of::<u32>()
    }
}

/// What a prepared scene's geometry occupies in memory, in bytes (`igi info`; issue 17's
/// budget of mesh plus BVH per triangle).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GeometryBytes {
    /// Triangles stored in the meshes (each counted once however often it is instanced).
    pub stored_triangles: usize,
    /// Vertex positions and index triples ([`Accel::triangle_bytes`]).
    pub triangles: usize,
    /// BVH nodes, triangle order, top level and placements ([`Accel::bvh_bytes`]).
    pub bvh: usize,
    /// Normals, texture coordinates and material indices ([`MeshShading::bytes`]).
    pub shading: usize,
}

impl GeometryBytes {
    /// All of it.
    pub fn total(&self) -> usize {
        self.triangles + self.bvh + self.shading
    }
}

/// Everything shading needs to know about a ray hit, in world space.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SurfacePoint {
    /// Hit position, interpolated from the triangle's corners.
    pub position: Vec3,
    /// The hit position in the object space of its instance.
    pub object_position: Vec3,
    /// Unit geometric normal, following the triangle's winding (the emitting side of an area
    /// light).
    pub geometric_normal: Vec3,
    /// Unit shading normal: interpolated vertex normals where the mesh has them, else the
    /// geometric normal. Always in the same hemisphere as `geometric_normal`.
    pub shading_normal: Vec3,
    /// Interpolated texture coordinates (zero if the mesh has none).
    pub uv: Vec2,
    /// World-space ∂p/∂u and ∂p/∂v of the triangle's texture mapping (without texture
    /// coordinates, or where they are degenerate: the triangle's two edges from its first
    /// corner).
    pub dpdu: Vec3,
    /// See `dpdu`.
    pub dpdv: Vec3,
    /// The instance hit.
    pub instance: u32,
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
    views: Vec<SavedView>,
    front: Option<Vec3>,
    area_lights: AreaLights,
    /// The sky, if the scene has one that emits anything.
    environment: Option<EnvironmentLight>,
    /// Per instance: the matrix taking object-space normals to world space (inverse
    /// transpose), or `None` for the identity.
    normal_matrices: Vec<Option<Mat3A>>,
    /// The surface shader of each material.
    shaders: Vec<Arc<dyn SurfaceShader>>,
    /// The pyramid of every texture a material shader reads, indexed by texture (the area
    /// lights read the emission textures' too).
    maps: Vec<Option<Arc<MipMap>>>,
    /// Per material, the energy-conserving parameters of a shader that gives every hit the
    /// same ([`SurfaceShader::uniform`]).
    uniform: Vec<Option<BrdfParams>>,
    /// The pose the scene was last placed in ([`PreparedScene::pose`]); `None` as loaded.
    posed: Option<ScenePose>,
    /// How instances and lights move with the clock.
    animation: Animation,
    /// Instance transforms and lights as loaded: a [`Pose`] overrides some of them.
    rest_transforms: Vec<Affine3A>,
    rest_lights: Vec<Light>,
    /// Each material's emitted radiance as loaded: a [`LightEdit`] scales it.
    rest_emission: Vec<Vec3>,
    /// The instances that have emissive triangles.
    emitter_instances: Vec<u32>,
    /// True if the last placement moved some instance away from its animation's pose.
    is_displaced: bool,
    /// True if the headlight [`eye_light`] lights the scene: as prepared, a scene without any
    /// light source; after [`PreparedScene::set_headlight`], as that says.
    headlight: bool,
}

/// The matrix taking object-space normals to world space (the inverse transpose), `None` for
/// the identity.
fn normal_matrix(m: &Affine3A) -> Option<Mat3A> {
    (*m != Affine3A::IDENTITY).then(|| m.matrix3.inverse().transpose())
}

impl PreparedScene {
    /// What the geometry occupies in memory.
    pub fn geometry_bytes(&self) -> GeometryBytes {
        GeometryBytes {
            stored_triangles: self.meshes.iter().map(|m| m.material_ids.len()).sum(),
            triangles: self.accel.triangle_bytes(),
            bvh: self.accel.bvh_bytes(),
            shading: self.meshes.iter().map(MeshShading::bytes).sum(),
        }
    }

    /// Builds the acceleration structure over `scene` and the shading tables. Material ids
    /// out of range (which a valid scene never has) fall back to a default grey material.
    /// A scene without any light source is lit by the headlight at the camera until
    /// [`PreparedScene::set_headlight`] says otherwise.
    pub fn new(scene: Scene) -> Self {
        let Scene {
            meshes,
            instances,
            mut materials,
            textures,
            lights,
            camera,
            views,
            front,
            environment,
            animation,
        } = scene;

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
        let start = std::time::Instant::now();
        let (accel, orders) = Accel::build(geometry, &placements);
        tracing::info!(
            "BVH over {} stored triangles in {} meshes and {} instances built in {:.3} s ({:.1} MiB with the meshes)",
            accel.meshes().iter().map(|m| m.indices.len()).sum::<usize>(),
            accel.meshes().len(),
            placements.len(),
            start.elapsed().as_secs_f64(),
            (accel.triangle_bytes() + accel.bvh_bytes()) as f64 / f64::from(1 << 20)
        );
        for (mesh, order) in shading.iter_mut().zip(&orders) {
            mesh.material_ids = order.iter().map(|&i| mesh.material_ids[i as usize]).collect();
        }

        let normal_matrices = placements.iter().map(|(_, m)| normal_matrix(m)).collect();
        let lights_copy = lights.clone();

        let mut prepared = Self {
            accel,
            meshes: shading,
            materials,
            textures,
            lights,
            camera,
            views,
            front,
            area_lights: AreaLights::default(),
            environment: None,
            normal_matrices,
            shaders: Vec::new(),
            maps: Vec::new(),
            uniform: Vec::new(),
            posed: None,
            animation,
            rest_transforms: placements.iter().map(|&(_, m)| m).collect(),
            rest_lights: lights_copy,
            rest_emission: Vec::new(),
            emitter_instances: Vec::new(),
            is_displaced: false,
            headlight: false,
        };
        prepared.rest_emission = prepared.materials.iter().map(|m| m.emission).collect();
        let table = ShaderTable::new(&prepared.materials, &prepared.textures);
        prepared.maps = table.maps().to_vec();
        prepared.shaders = table.into_shaders();
        let meshes =
            prepared.meshes.iter().zip(prepared.accel.meshes()).map(|(shading, mesh)| MeshMaterials {
                material_ids: &shading.material_ids,
                indices: &mesh.indices,
                uvs: shading.uvs.as_deref(),
            });
        if let Some((cutouts, may_cut)) = AlphaCutouts::new(&prepared.materials, &prepared.maps, meshes) {
            prepared.accel.set_cutouts(&may_cut, Arc::new(cutouts));
        }
        prepared.uniform = prepared.shaders.iter().map(|s| s.uniform().map(BrdfParams::conserving)).collect();
        prepared.area_lights = AreaLights::new(
            prepared.collect_emissive(0..prepared.accel.instance_count() as u32),
            prepared.maps.clone(),
        );
        if let Err(e) =
            prepared.animation.validate(prepared.rest_transforms.len(), prepared.rest_lights.len())
        {
            tracing::warn!("ignoring the scene's animation: {e}");
            prepared.animation = Animation::default();
        }
        prepared.emitter_instances = prepared.area_lights.triangles().iter().map(|t| t.instance).collect();
        prepared.emitter_instances.dedup();
        prepared.environment = environment
            .map(|e| EnvironmentLight::new(&e, &prepared.textures))
            .filter(|e| e.integral().max_element() > 0.0);
        prepared.headlight = !prepared.has_lights();
        prepared
    }

    /// The scene's animation.
    pub fn animation(&self) -> &Animation {
        &self.animation
    }

    /// Scene time of the last placement (seconds; 0 as loaded): the surface shaders see it.
    pub fn time(&self) -> f32 {
        self.posed.as_ref().map_or(0.0, |p| p.time)
    }

    /// Places the scene as `pose` says: the animated instances and lights take their pose at
    /// its time, the instances it moves are also transformed by their matrix in world space
    /// (a viewer's object moves), its light edits change the lights, the top-level BVH is
    /// rebuilt over the moved instances (the per-mesh BVHs stay), and the surface shaders see
    /// its time. Everything else the renderer derives from the scene (VPLs, lighting) is
    /// recomputed by the next frame anyway. A scene already in this pose stays as it is.
    pub fn pose(&mut self, pose: &ScenePose) {
        if self.posed.as_ref() == Some(pose) {
            return;
        }
        if let Some(sky) = &mut self.environment {
            sky.set_strength(pose.sky);
        }
        let animated = self.animation.pose(pose.time);
        if !self.animation.is_empty() || !pose.moved.is_empty() || self.is_displaced {
            self.place(&animated, &pose.moved);
            self.is_displaced = !pose.moved.is_empty();
        }
        let edited = self.posed.as_ref().is_some_and(|p| !p.lights.is_empty());
        if !self.animation.is_empty() || !pose.lights.is_empty() || edited {
            self.light(&animated, &pose.lights);
        }
        self.posed = Some(pose.clone());
    }

    /// The scene's light sources a viewer can edit, with names for a list: the punctual
    /// lights (`point light 0`, `spot light 1`, `sun 2`), then the emissive materials by name.
    pub fn light_sources(&self) -> Vec<(LightId, String)> {
        let punctual = self.rest_lights.iter().enumerate().map(|(i, light)| {
            let kind = match light {
                Light::Point { .. } => "point light",
                Light::Spot { .. } => "spot light",
                Light::Directional { .. } => "sun",
            };
            (LightId::Punctual(i as u32), format!("{kind} {i}"))
        });
        let emissive =
            self.rest_emission.iter().enumerate().filter(|(_, e)| e.max_element() > 0.0).map(|(m, _)| {
                let name = &self.materials[m].name;
                let name = if name.is_empty() { format!("emissive material {m}") } else { name.clone() };
                (LightId::Emissive(m as u32), name)
            });
        punctual.chain(emissive).collect()
    }

    /// Sets the punctual lights to their rest state overridden by `animated` and then
    /// changed by `edits`, and each emissive material's radiance to its rest value times its
    /// edit's power (rebuilding its shader and, if any changed, the table of emissive
    /// triangles).
    fn light(&mut self, animated: &Pose, edits: &[LightEdit]) {
        self.lights.clone_from(&self.rest_lights);
        for (i, light) in &animated.lights {
            if let Some(l) = self.lights.get_mut(*i as usize) {
                *l = light.clone();
            }
        }
        let mut power = vec![Vec3::ONE; self.materials.len()];
        for edit in edits {
            match edit.light {
                LightId::Punctual(i) => {
                    if let Some(l) = self.lights.get_mut(i as usize) {
                        *l = edit.apply(l);
                    }
                }
                LightId::Emissive(m) => {
                    if let Some(p) = power.get_mut(m as usize) {
                        *p *= edit.power;
                    }
                }
            }
        }
        let mut changed = false;
        for (m, (&rest, power)) in self.rest_emission.iter().zip(power).enumerate() {
            let emission = rest * power;
            if self.materials[m].emission == emission {
                continue;
            }
            self.materials[m].emission = emission;
            if self.materials[m].shader.is_none() {
                self.shaders[m] = Arc::new(MaterialShader::new(&self.materials[m], &self.maps));
            }
            self.uniform[m] = self.shaders[m].uniform().map(BrdfParams::conserving);
            changed = true;
        }
        if changed {
            self.area_lights = AreaLights::new(
                self.collect_emissive(self.emitter_instances.iter().copied()),
                self.maps.clone(),
            );
        }
    }

    /// Places the instances: each at its rest transform (as loaded), overridden by `pose`,
    /// and then the instances in `moved` (a viewer's object moves) transformed once more by
    /// their matrix (applied in world space, after the pose). Rebuilds the top level of the
    /// acceleration structure and, if an emitter may have moved, the table of emissive
    /// triangles.
    fn place(&mut self, pose: &Pose, moved: &[(u32, Affine3A)]) {
        let mut transforms = self.rest_transforms.clone();
        for &(i, m) in &pose.instances {
            if let Some(t) = transforms.get_mut(i as usize) {
                *t = m;
            }
        }
        for &(i, m) in moved {
            if let Some(t) = transforms.get_mut(i as usize) {
                *t = m * *t;
            }
        }
        let emitters_moved = self
            .emitter_instances
            .iter()
            .any(|&i| transforms[i as usize] != self.accel.instance_transform(i));
        self.accel.set_transforms(&transforms);
        self.normal_matrices = transforms.iter().map(normal_matrix).collect();
        if emitters_moved {
            // Only the instances that have emitters need a look (not every triangle).
            self.area_lights = AreaLights::new(
                self.collect_emissive(self.emitter_instances.iter().copied()),
                self.maps.clone(),
            );
        }
    }

    /// The emissive triangles of `instances`, in world space, each with its mean radiance
    /// over its footprint on its emission texture.
    fn collect_emissive(&self, instances: impl Iterator<Item = u32>) -> Vec<EmissiveTriangle> {
        let mut out = Vec::new();
        for instance in instances {
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
                // Texture coordinates as `surface` interpolates them (zero without any).
                let map = material.emission_texture.and_then(|t| {
                    let pyramid = self.maps.get(t as usize)?.as_ref()?;
                    let corners = mesh.indices[prim];
                    let uvs =
                        shading.uvs.as_ref().map_or([Vec2::ZERO; 3], |uv| corners.map(|i| uv[i as usize]));
                    Some((EmissionMap { texture: t, uvs }, footprint_mean(pyramid, uvs)))
                });
                let mean_emission = map.map_or(material.emission, |(_, mean)| material.emission * mean);
                out.push(EmissiveTriangle {
                    instance,
                    prim: prim as u32,
                    p0: a,
                    e1,
                    e2,
                    normal: self.accel.geometric_normal(instance, prim as u32),
                    area: 0.5 * e1.cross(e2).length(),
                    emission: material.emission,
                    texture: map.map(|(texture, _)| texture),
                    mean_emission,
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

    /// The point, spot and directional lights the renderers evaluate exactly: the scene's,
    /// and the headlight [`eye_light`] of `camera` where it is on (see
    /// [`PreparedScene::set_headlight`]).
    pub fn punctual_lights(&self, camera: &Camera) -> Vec<Light> {
        let mut lights = self.lights.clone();
        if self.headlight {
            lights.push(eye_light(&self.bounds(), camera));
        }
        lights
    }

    /// Turns the headlight [`eye_light`] on or off (first sight's default light, see
    /// [`crate::first_sight::default_light`]; as prepared it is on for a scene without any
    /// light source).
    pub fn set_headlight(&mut self, on: bool) {
        self.headlight = on;
    }

    /// Adds a point, spot or directional light after the scene's own (so their animation
    /// tracks keep their indices).
    pub fn add_light(&mut self, light: Light) {
        self.lights.push(light.clone());
        self.rest_lights.push(light);
    }

    /// Makes `sky` the scene's environment light.
    pub fn set_sky(&mut self, sky: &Environment) {
        self.environment = Some(EnvironmentLight::new(sky, &self.textures));
    }

    /// Makes the equirectangular image of radiance `sky` (as [`Environment::Map`] reads it)
    /// the scene's environment light, kept after the scene's own textures (first sight's
    /// daylight, [`crate::first_sight::daylight_sky`]).
    pub fn set_sky_image(&mut self, sky: Texture) {
        self.textures.push(sky);
        let texture = (self.textures.len() - 1) as u32;
        self.set_sky(&Environment::Map { texture, intensity: 1.0, rotation_deg: 0.0 });
    }

    /// The scene's own camera, if it had one, or the one [`PreparedScene::set_camera`] fixed.
    pub fn camera(&self) -> Option<&Camera> {
        self.camera.as_ref()
    }

    /// The scene's named cameras ([`igi_scene::Scene::views`]).
    pub fn views(&self) -> &[SavedView] {
        &self.views
    }

    /// The unit direction the model faces, where its format defines one (glTF: +Z).
    pub fn front(&self) -> Option<Vec3> {
        self.front
    }

    /// Fixes the camera the scene starts with (for a scene without one, the default camera
    /// chosen once, [`crate::first_sight::start_camera::default_camera`]).
    pub fn set_camera(&mut self, camera: Camera) {
        self.camera = Some(camera);
    }

    /// The emissive triangles and their sampling distribution.
    pub fn area_lights(&self) -> &AreaLights {
        &self.area_lights
    }

    /// The environment (sky) light, if the scene has one that emits anything and its pose
    /// has not turned it off.
    pub fn environment(&self) -> Option<&EnvironmentLight> {
        self.environment.as_ref().filter(|e| e.strength() > 0.0)
    }

    /// The radiance arriving along a ray of unit direction `dir` that leaves the scene: the
    /// sky's, or black.
    #[inline]
    pub fn background(&self, dir: Vec3) -> Vec3 {
        self.environment().map_or(Vec3::ZERO, |e| e.radiance(dir))
    }

    /// True if the scene has any light source of its own or added to it (emissive triangle,
    /// punctual light or sky; not the headlight).
    pub fn has_lights(&self) -> bool {
        !self.lights.is_empty() || !self.area_lights.is_empty() || self.environment.is_some()
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

        let corner_uvs = shading.uvs.as_ref().map(|t| idx.map(|i| t[i as usize]));
        let uv = corner_uvs.map_or(Vec2::ZERO, |[t0, t1, t2]| w * t0 + u * t1 + v * t2);
        let (dpdu, dpdv) = tangents(b - a, c - a, corner_uvs);
        let (dpdu, dpdv) = if self.normal_matrices[instance as usize].is_some() {
            (m.transform_vector3(dpdu), m.transform_vector3(dpdv))
        } else {
            (dpdu, dpdv)
        };

        SurfacePoint {
            position,
            object_position: local,
            geometric_normal,
            shading_normal,
            uv,
            dpdu,
            dpdv,
            instance,
            material: shading.material_ids[prim as usize],
        }
    }

    /// The surface shader of material `material`.
    pub fn shader(&self, material: u32) -> &dyn SurfaceShader {
        self.shaders[material as usize].as_ref()
    }

    /// Replaces the surface shader of every material named `name` by `shader` (a user's own
    /// [`SurfaceShader`]); returns how many materials it now shades.
    pub fn set_shader(&mut self, name: &str, shader: Arc<dyn SurfaceShader>) -> usize {
        let mut count = 0;
        let uniform = shader.uniform().map(BrdfParams::conserving);
        for ((material, slot), u) in self.materials.iter().zip(&mut self.shaders).zip(&mut self.uniform) {
            if material.name == name {
                *slot = Arc::clone(&shader);
                *u = uniform;
                count += 1;
            }
        }
        count
    }

    /// Runs the surface shader of `material` on `n` ≤ 8 points of that material, `point(i)`
    /// giving point i and its camera-ray footprint, and writes their energy-conserving BRDF
    /// parameters into `out[..n]`, with shading normals unit and in the hemisphere of the
    /// geometric normal (the interpolated normal where a shader's is unusable).
    pub fn shade8<'p>(
        &self,
        material: u32,
        n: usize,
        point: impl Fn(usize) -> (&'p SurfacePoint, f32),
        out: &mut [BrdfParams],
    ) {
        debug_assert!((1..=8).contains(&n) && out.len() >= n);
        if self.uniform[material as usize].is_some() {
            for (lane, out) in out[..n].iter_mut().enumerate() {
                *out = self.uniform_shading(point(lane).0).unwrap_or(*out);
            }
            return;
        }
        // Structure of arrays; lanes past the points repeat the first (every lane finite).
        let mut soa = [[[0.0f32; 8]; 3]; 6];
        let mut uv = [[0.0f32; 8]; 2];
        let mut footprint = [0.0f32; 8];
        let mut object = [0i32; 8];
        for lane in 0..8 {
            let (p, f) = point(if lane < n { lane } else { 0 });
            let vectors =
                [p.position, p.object_position, p.geometric_normal, p.shading_normal, p.dpdu, p.dpdv];
            for (field, v) in soa.iter_mut().zip(vectors) {
                field[0][lane] = v.x;
                field[1][lane] = v.y;
                field[2][lane] = v.z;
            }
            uv[0][lane] = p.uv.x;
            uv[1][lane] = p.uv.y;
            footprint[lane] = f;
            object[lane] = p.instance as i32;
        }
        let vec3 = |a: &[[f32; 8]; 3]| {
            Vec3x8::new(F32x8::from_array(a[0]), F32x8::from_array(a[1]), F32x8::from_array(a[2]))
        };
        let hits = ShadingHit8 {
            position: vec3(&soa[0]),
            object_position: vec3(&soa[1]),
            geometric_normal: vec3(&soa[2]),
            shading_normal: vec3(&soa[3]),
            u: F32x8::from_array(uv[0]),
            v: F32x8::from_array(uv[1]),
            dpdu: vec3(&soa[4]),
            dpdv: vec3(&soa[5]),
            footprint: F32x8::from_array(footprint),
            object: I32x8::from_array(object),
            active: M32x8::from_bitmask((1u32 << n) - 1),
            material,
            time: self.time(),
        };
        let mut params = BrdfParams8::black(hits.shading_normal);
        self.shader(material).shade(&hits, &mut params);
        let mut params = params.conserving();
        params.shading_normal = facing(params.shading_normal, hits.geometric_normal, hits.shading_normal);
        let lanes = params.to_lanes();
        out[..n].copy_from_slice(&lanes[..n]);
    }

    /// The parameters at `point` if its material's shader gives every hit the same
    /// ([`SurfaceShader::uniform`]): what [`PreparedScene::shade8`] would compute, without the
    /// 8-wide call.
    #[inline]
    pub fn uniform_shading(&self, point: &SurfacePoint) -> Option<BrdfParams> {
        self.uniform[point.material as usize]
            .map(|uniform| BrdfParams { shading_normal: point.shading_normal, ..uniform })
    }

    /// [`PreparedScene::shade8`] of one point.
    pub fn shade(&self, point: &SurfacePoint, footprint: f32) -> BrdfParams {
        let mut out = [BrdfParams::black(point.shading_normal)];
        self.shade8(point.material, 1, |_| (point, footprint), &mut out);
        out[0]
    }
}

/// Shading normals `n` from a shader made usable: unit, finite and at least slightly in the
/// hemisphere of the geometric normals `ng` (a bump that tilts one below would make the
/// surface face away from every light); `fallback` (the interpolated normals) where `n` is
/// unusable (zero length or not finite).
fn facing(n: Vec3x8, ng: Vec3x8, fallback: Vec3x8) -> Vec3x8 {
    const MIN_COS: f32 = 1e-3;
    let len = n.length();
    let usable = len.gt(F32x8::ZERO) & len.lt(F32x8::splat(f32::INFINITY));
    let n = Vec3x8::select(usable, n * (F32x8::splat(1.0) / len), fallback);
    let cos = n.dot(ng);
    let lifted = (n + ng * (F32x8::splat(MIN_COS) - cos)).normalize();
    Vec3x8::select(cos.ge(F32x8::splat(MIN_COS)), n, lifted)
}

/// ∂p/∂u and ∂p/∂v of a triangle with edges `e1`, `e2` (object space) and corner texture
/// coordinates `uvs`: the solution of e_k = Δu_k ∂p/∂u + Δv_k ∂p/∂v. Without texture
/// coordinates, or where they are degenerate, the edges themselves (the mapping u, v =
/// barycentrics), which span the triangle's plane at no cost.
fn tangents(e1: Vec3, e2: Vec3, uvs: Option<[Vec2; 3]>) -> (Vec3, Vec3) {
    if let Some([t0, t1, t2]) = uvs {
        let (d1, d2) = (t1 - t0, t2 - t0);
        let det = d1.x * d2.y - d1.y * d2.x;
        if det.abs() > 1e-12 {
            let r = 1.0 / det;
            let dpdu = (d2.y * e1 - d1.y * e2) * r;
            let dpdv = (d1.x * e2 - d2.x * e1) * r;
            if dpdu.is_finite() && dpdv.is_finite() {
                return (dpdu, dpdv);
            }
        }
    }
    (e1, e2)
}
