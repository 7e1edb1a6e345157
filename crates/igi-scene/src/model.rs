//! The scene model every loader produces and every renderer consumes: triangle meshes,
//! materials, textures, lights, a camera and instances of meshes.
//!
//! Conventions: right-handed, +Y up, linear RGB radiometric quantities. Area lights are not a
//! separate type: any triangle whose material has a non-zero `emission` is an area light, and a
//! `quad` light of a scene file becomes two such triangles; punctual and distant lights are
//! [`Light`]s.

use crate::animation::Animation;
use crate::environment::Environment;
use crate::light::Light;
use crate::shader::ShaderDesc;
use crate::texels::{Image, Texels};
use glam::{Affine3A, Vec2, Vec3};
use igi_bvh::Aabb;

/// A triangle mesh in its own object space. Meshes are placed in the world by [`Instance`]s.
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    /// Name from the source file (object, mesh or file name), for messages and `igi info`.
    pub name: String,
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Optional per-vertex shading normals (same length as `positions`, unit length).
    pub normals: Option<Vec<Vec3>>,
    /// Optional per-vertex texture coordinates (same length as `positions`), with v = 0 at the
    /// top row of the texture as in glTF (the OBJ and PLY loaders flip v).
    pub uvs: Option<Vec<Vec2>>,
    /// Triangles as indices into the vertex arrays. Every index is in range and every triangle
    /// has a non-zero area: loaders drop degenerate triangles (and count them).
    pub indices: Vec<[u32; 3]>,
    /// Per-triangle index into [`Scene::materials`].
    pub material_ids: Vec<u32>,
}

impl Mesh {
    /// The object-space corners of triangle `t`.
    pub fn triangle(&self, t: usize) -> [Vec3; 3] {
        self.indices[t].map(|i| self.positions[i as usize])
    }

    /// The unit geometric normal of triangle `t`: the right-hand rule on its winding, the side
    /// an emissive triangle emits to.
    pub fn triangle_normal(&self, t: usize) -> Vec3 {
        let [a, b, c] = self.triangle(t);
        (b - a).cross(c - a).normalize_or_zero()
    }

    /// Object-space bounds of the vertices.
    pub fn bounds(&self) -> Aabb {
        Aabb::from_points(self.positions.iter().copied())
    }
}

/// How a surface scatters light. Parameters follow the OBJ/MTL reading of them, except for
/// glTF's [`MaterialKind::MetallicRoughness`]; the renderer's BRDF shaders interpret them
/// (Lambert plus an optional Phong lobe, the glTF GGX BRDF, mirror, glass).
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    /// Name from the source file.
    pub name: String,
    /// Diffuse reflectance ρ_d (linear RGB, each channel in [0, 1]); the base colour of a
    /// [`MaterialKind::MetallicRoughness`] material.
    pub diffuse: Vec3,
    /// Optional texture that multiplies `diffuse` (index into [`Scene::textures`]).
    pub diffuse_texture: Option<u32>,
    /// Reflectance ρ_s of the glossy Phong lobe (linear RGB; MTL `Ks`, the scene file's
    /// `specular`). A [`MaterialKind::Mirror`] has no glossy lobe and reads it as the mirror's
    /// reflectance instead, as MTL's `illum` 3 reads `Ks`.
    pub glossy: Vec3,
    /// Phong exponent of the glossy lobe.
    pub exponent: f32,
    /// Metalness of a [`MaterialKind::MetallicRoughness`] material (glTF `metallicFactor`,
    /// in [0, 1]).
    pub metallic: f32,
    /// Perceptual roughness of a [`MaterialKind::MetallicRoughness`] material (glTF
    /// `roughnessFactor`, in [0, 1]; the GGX width α is its square).
    pub roughness: f32,
    /// Optional glTF `metallicRoughnessTexture` (index into [`Scene::textures`], linear): its
    /// blue channel multiplies `metallic` and its green channel `roughness`, per texel.
    pub metallic_roughness_texture: Option<u32>,
    /// Emitted radiance L_e in W/(sr m²) toward the front side (the winding normal); with
    /// `emission_texture`, the factor its texels multiply.
    pub emission: Vec3,
    /// Optional emissive texture (glTF `emissiveTexture`, MTL `map_Ke`; index into
    /// [`Scene::textures`], sRGB): the emitted radiance at a point is `emission` × the texel
    /// there (glTF 2.0, section 3.9.3: "emissiveFactor … multiplied by the emissive texture").
    pub emission_texture: Option<u32>,
    /// Optional bump or height map (index into [`Scene::textures`]).
    pub bump_texture: Option<u32>,
    /// Optional tangent-space normal map (glTF `normalTexture`; index into
    /// [`Scene::textures`], linear RGB, +X along u, +Y toward decreasing v, +Z out).
    pub normal_texture: Option<u32>,
    /// Scale of the normal map's X and Y (glTF `normalTexture.scale`).
    pub normal_scale: f32,
    /// Fraction of light transmitted (1 - opacity), as the source gives it; the renderer's glass
    /// comes from `kind`, and alpha blending (glTF `BLEND`, MTL `d` < 1) is not rendered: such
    /// surfaces are opaque. Cut-outs are `alpha_mask`.
    pub transparency: f32,
    /// An alpha cut-out (glTF `alphaMode: MASK`, MTL `map_d`): where the coverage falls below
    /// its cutoff the surface is not there for any ray.
    pub alpha_mask: Option<AlphaMask>,
    /// Index of refraction of a [`MaterialKind::Glass`] material.
    pub ior: f32,
    /// Perfect-mirror or glass behaviour requested by the source (MTL `illum` 3-7).
    pub kind: MaterialKind,
    /// A procedural shader that replaces the constant and textured parameters above (scene
    /// file `[[shader]]`); `emission` still makes the material an area light.
    pub shader: Option<ShaderDesc>,
}

/// An alpha cut-out: the coverage at a point is `factor` × the texel's `channel`, and the
/// surface is absent where it is below `cutoff` (glTF 2.0, 3.9.4: "the rendered output is
/// either fully opaque or fully transparent depending on the alpha value and the specified
/// alpha cutoff value").
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AlphaMask {
    /// Constant coverage (glTF `baseColorFactor` alpha; 1 for MTL).
    pub factor: f32,
    /// The texture whose texels multiply `factor` (index into [`Scene::textures`]; glTF's base
    /// colour texture, MTL's `map_d`).
    pub texture: Option<u32>,
    /// Which value of a texel is its coverage.
    pub channel: CoverageChannel,
    /// Coverage below this cuts (glTF `alphaCutoff`, default 0.5; 0.5 for MTL).
    pub cutoff: f32,
}

/// Which value of a texel an [`AlphaMask`] reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CoverageChannel {
    /// The alpha channel (glTF; an MTL `map_d` image with an alpha channel that is not opaque
    /// everywhere).
    Alpha,
    /// The luminance of the colour (an MTL `map_d` grey image, whose value is the dissolve).
    Luminance,
}

/// The BRDF family a material asks for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum MaterialKind {
    /// Lambertian diffuse plus an optional glossy Phong lobe.
    #[default]
    Plastic,
    /// The glTF 2.0 metallic-roughness BRDF (specification appendix B): base colour
    /// `diffuse` × `diffuse_texture`, `metallic` and `roughness` × `metallic_roughness_texture`,
    /// a GGX lobe with Smith masking and Schlick Fresnel over a Fresnel-weighted diffuse lobe.
    MetallicRoughness,
    /// Perfect mirror with reflectance `glossy` (white if zero).
    Mirror,
    /// Dielectric with index `ior`.
    Glass,
}

impl Default for Material {
    fn default() -> Self {
        Self {
            name: "default".into(),
            diffuse: Vec3::splat(0.8),
            diffuse_texture: None,
            glossy: Vec3::ZERO,
            exponent: 1.0,
            metallic: 0.0,
            roughness: 1.0,
            metallic_roughness_texture: None,
            emission: Vec3::ZERO,
            emission_texture: None,
            bump_texture: None,
            normal_texture: None,
            normal_scale: 1.0,
            transparency: 0.0,
            alpha_mask: None,
            ior: 1.0,
            kind: MaterialKind::Plastic,
            shader: None,
        }
    }
}

impl Material {
    /// A Lambertian material called `name` of reflectance `diffuse`.
    pub fn diffuse(name: &str, diffuse: Vec3) -> Self {
        Self { name: name.into(), diffuse, ..Self::default() }
    }

    /// True if triangles with this material are area lights.
    pub fn is_emissive(&self) -> bool {
        self.emission.max_element() > 0.0
    }
}

/// An image texture: a decoded image (see [`Image`] for how its texels are stored) and how
/// texture coordinates outside [0, 1] reach it.
#[derive(Clone, Debug)]
pub struct Texture {
    /// The file it came from (or a descriptive name for embedded images).
    pub name: String,
    /// The texels.
    pub image: Image,
    /// How texture coordinates outside [0, 1] map into the image, along u and along v.
    pub wrap: [Wrap; 2],
}

impl Texture {
    /// A repeating texture of `width × height` linear RGBA texels (row-major, row 0 at the
    /// top): what a program that builds its own scene hands over.
    pub fn from_linear(name: impl Into<String>, width: u32, height: u32, texels: Vec<[f32; 4]>) -> Self {
        let image = Image { width, height, texels: Texels::RgbaF32(std::sync::Arc::new(texels)) };
        Self { name: name.into(), image, wrap: [Wrap::Repeat; 2] }
    }
}

/// How a texture coordinate outside [0, 1] maps into the image (glTF sampler wrap modes).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Wrap {
    /// The image tiles the plane (the default of OBJ and glTF).
    #[default]
    Repeat,
    /// Coordinates are clamped to the edge texels.
    Clamp,
    /// The image tiles the plane, every other copy mirrored.
    MirroredRepeat,
}

/// A pinhole camera.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Camera {
    /// Eye position.
    pub position: Vec3,
    /// Point the camera looks at.
    pub target: Vec3,
    /// Up hint (need not be orthogonal to the view direction).
    pub up: Vec3,
    /// Vertical field of view in degrees.
    pub fov_y_deg: f32,
}

/// A named camera of a scene ([`Scene::views`]).
#[derive(Clone, Debug, PartialEq)]
pub struct SavedView {
    /// The name a user picks it by.
    pub name: String,
    /// Where it looks from.
    pub camera: Camera,
}

impl SavedView {
    /// `name`, or `name (2)`, `name (3)`, ..., whichever no view of `views` has (two files,
    /// or two glTF cameras, may have the same name).
    pub fn free_name(views: &[SavedView], name: String) -> String {
        let taken = |n: &str| views.iter().any(|v| v.name == n);
        if !taken(&name) {
            return name;
        }
        (2..).map(|i| format!("{name} ({i})")).find(|n| !taken(n)).expect("a free name")
    }
}

/// Why a [`Camera`] cannot frame an image: the field at fault and what is wrong with it, for
/// the scene file and the command line to report in their own terms (`camera.up`,
/// `--camera-up`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CameraDefect {
    /// `position`, `target`, `up` or `fov`.
    pub field: &'static str,
    /// What is wrong, as the end of a sentence naming the field.
    pub problem: &'static str,
}

impl Camera {
    /// A camera at `position` looking at `target`, +Y up, with a vertical field of view of
    /// `fov_y_deg` degrees.
    pub fn looking_at(position: Vec3, target: Vec3, fov_y_deg: f32) -> Self {
        Self { position, target, up: Vec3::Y, fov_y_deg }
    }

    /// The camera as a scene file's `[camera]` table (lines ending in `\n`), to paste into a
    /// scene file: what `igi info` prints and the viewers' "save view" gives.
    pub fn scene_file_snippet(&self) -> String {
        let v = |p: Vec3| format!("[{:.3}, {:.3}, {:.3}]", p.x, p.y, p.z);
        format!(
            "[camera]\nposition = {}\ntarget = {}\nup = {}\nfov = {}\n",
            v(self.position),
            v(self.target),
            v(self.up),
            self.fov_y_deg
        )
    }

    /// The camera moved by `m` (a placement of the file it came with).
    pub fn transformed(&self, m: &glam::Affine3A) -> Self {
        Self {
            position: m.transform_point3(self.position),
            target: m.transform_point3(self.target),
            up: m.transform_vector3(self.up).normalize_or(self.up),
            fov_y_deg: self.fov_y_deg,
        }
    }

    /// Checks that the camera frames an image: finite vectors, a target a finite, non-zero
    /// distance from the position, an up vector neither zero nor parallel to the view
    /// direction (either leaves the image's horizontal axis undefined), and a vertical field
    /// of view in (0, 180) degrees. Every camera a user gives goes through this one check.
    pub fn check(&self) -> Result<(), CameraDefect> {
        let defect = |field, problem| Err(CameraDefect { field, problem });
        for (field, v) in [("position", self.position), ("target", self.target), ("up", self.up)] {
            if !v.is_finite() {
                return defect(field, "values must be finite");
            }
        }
        let Some(forward) = (self.target - self.position).try_normalize() else {
            return defect("target", "must lie a finite, non-zero distance from the position");
        };
        let Some(up) = self.up.try_normalize() else {
            return defect("up", "must not be zero");
        };
        if forward.cross(up).length() < 1e-6 {
            return defect("up", "must not be parallel to the view direction");
        }
        if !(self.fov_y_deg > 0.0 && self.fov_y_deg < 180.0) {
            return defect("fov", "the vertical field of view must be in (0, 180) degrees");
        }
        Ok(())
    }
}

/// One placement of a mesh in the world.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Instance {
    /// Index into [`Scene::meshes`].
    pub mesh: u32,
    /// Object-to-world transform (affine, invertible).
    pub transform: Affine3A,
}

/// Everything a renderer needs besides its own settings.
#[derive(Clone, Debug, Default)]
pub struct Scene {
    /// Triangle meshes in object space.
    pub meshes: Vec<Mesh>,
    /// Placements of the meshes; a mesh may be placed any number of times.
    pub instances: Vec<Instance>,
    /// Materials referenced by [`Mesh::material_ids`].
    pub materials: Vec<Material>,
    /// Textures referenced by materials and by an image [`Scene::environment`].
    pub textures: Vec<Texture>,
    /// Point, spot and directional lights (area lights are emissive triangles).
    pub lights: Vec<Light>,
    /// Light from infinitely far away seen by rays that leave the scene (a sky), if any.
    /// An image environment's texture is one of [`Scene::textures`].
    pub environment: Option<Environment>,
    /// The scene's own camera, if its file has one.
    pub camera: Option<Camera>,
    /// Further named cameras (a scene file's `[[view]]` entries, a glTF file's cameras): the
    /// viewers offer them as saved views, `igi render --view NAME` renders from one. Names
    /// are unique.
    pub views: Vec<SavedView>,
    /// The unit direction the model faces, where its format defines one (glTF 2.0: +Z);
    /// `None` for OBJ, PLY, built-in scenes and scene files. The default camera looks at an
    /// object's front.
    pub front: Option<Vec3>,
    /// How instances and lights move with the scene clock (empty for a still scene).
    pub animation: Animation,
}

impl Scene {
    /// A scene of `meshes`, each placed once where it was modelled, with `materials`, seen from
    /// `camera`; lights, sky, views and animation are the caller's to add.
    pub fn placed_once(meshes: Vec<Mesh>, materials: Vec<Material>, camera: Camera) -> Self {
        let instances =
            (0..meshes.len() as u32).map(|mesh| Instance { mesh, transform: Affine3A::IDENTITY }).collect();
        Self { meshes, instances, materials, camera: Some(camera), ..Self::default() }
    }

    /// Bytes the texels of all textures occupy, each decoded image once (the views of one image
    /// in two colour spaces share its texels); mipmaps add about a third.
    pub fn texel_bytes(&self) -> u64 {
        let mut images: Vec<(*const u8, u64)> =
            self.textures.iter().map(|t| (t.image.texels.storage(), t.image.bytes())).collect();
        images.sort_unstable();
        images.dedup();
        images.iter().map(|&(_, bytes)| bytes).sum()
    }

    /// World-space bounds of every instance, exact (each vertex is transformed, so rotated
    /// instances do not inflate it). [`Aabb::EMPTY`] for a scene without geometry.
    pub fn bounds(&self) -> Aabb {
        self.instances
            .iter()
            .filter_map(|instance| Some((instance, self.meshes.get(instance.mesh as usize)?)))
            .fold(Aabb::EMPTY, |bounds, (instance, mesh)| {
                mesh.positions.iter().fold(bounds, |b, &p| b.grow(instance.transform.transform_point3(p)))
            })
    }

    /// Triangles the renderer intersects: each mesh counted once per instance.
    pub fn triangle_count(&self) -> usize {
        self.instances
            .iter()
            .filter_map(|instance| self.meshes.get(instance.mesh as usize))
            .map(|mesh| mesh.indices.len())
            .sum()
    }

    /// Area-light triangles (emissive material), each mesh counted once per instance.
    pub fn emissive_triangle_count(&self) -> usize {
        self.instances
            .iter()
            .filter_map(|instance| self.meshes.get(instance.mesh as usize))
            .map(|mesh| {
                mesh.material_ids
                    .iter()
                    .filter(|&&m| self.materials.get(m as usize).is_some_and(Material::is_emissive))
                    .count()
            })
            .sum()
    }
}
