//! [`ShadingHit8`]: what a surface shader may read about eight hits.

use igi_simd::{F32x8, I32x8, M32x8, Vec3x8};

/// Eight ray hits on surfaces of one material, in structure-of-arrays form: the input of a
/// [`crate::SurfaceShader`]. Inactive lanes hold copies of an active lane (every value is
/// finite), so a shader may compute on all eight lanes and let the caller ignore the rest.
#[derive(Clone, Copy, Debug)]
pub struct ShadingHit8 {
    /// World-space hit positions.
    pub position: Vec3x8,
    /// The hit positions in the object space of the hit instance (solid textures that move
    /// with their object use these).
    pub object_position: Vec3x8,
    /// Unit geometric normals (world space), following the triangle's winding.
    pub geometric_normal: Vec3x8,
    /// Unit interpolated vertex normals (world space), in the hemisphere of
    /// `geometric_normal`; the geometric normal where the mesh has none.
    pub shading_normal: Vec3x8,
    /// Texture coordinate u (0 where the mesh has none).
    pub u: F32x8,
    /// Texture coordinate v (0 at the top row of an image, as in glTF).
    pub v: F32x8,
    /// World-space ∂p/∂u: the surface tangent along which u grows (where the mesh has no
    /// texture coordinates, the triangle's edges: ∂p/∂u and ∂p/∂v then span its plane but
    /// need not be orthogonal).
    pub dpdu: Vec3x8,
    /// World-space ∂p/∂v.
    pub dpdv: Vec3x8,
    /// World-space width of the camera ray's footprint at the hit (a ray cone: distance times
    /// the pixel's angle), for choosing a texture's mipmap level.
    pub footprint: F32x8,
    /// The instance hit (its index in the scene).
    pub object: I32x8,
    /// Lanes holding a hit to shade.
    pub active: M32x8,
    /// The material of all eight hits (index into the scene's materials).
    pub material: u32,
    /// Scene time of the frame, in seconds.
    pub time: f32,
}
