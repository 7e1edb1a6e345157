//! Alpha cut-outs (glTF `alphaMode: MASK`, glTF 2.0 section 3.9.4; MTL `map_d`) as the
//! acceleration structure's [`CutoutTest`]: a hit on a triangle of a masked material is no hit
//! where the coverage there (the mask's factor × its texel at the hit's texture coordinates)
//! is below the cutoff. Every ray asks the same question whatever it is for (camera, shadow,
//! VPL walk, path tracer), so a cut texel is not there for any of them. The walk knows no ray
//! footprint, so the texel is read bilinearly at full resolution (as the VPL walks and the path
//! tracer read every texture).

use crate::image::tonemap::luminance;
use glam::Vec2;
use igi_bvh::CutoutTest;
use igi_scene::{CoverageChannel, Material};
use igi_shade::texture::MipMap;
use std::sync::Arc;

/// A material's cut-out, ready for lookups.
#[derive(Debug)]
struct Mask {
    factor: f32,
    map: Option<Arc<MipMap>>,
    channel: CoverageChannel,
    cutoff: f32,
}

impl Mask {
    /// True if the coverage at texture coordinates `uv` is below the cutoff.
    #[inline]
    fn is_cut(&self, uv: Vec2) -> bool {
        let coverage = self.map.as_ref().map_or(1.0, |map| {
            let texel = map.bilinear(uv, 0);
            match self.channel {
                CoverageChannel::Alpha => texel.w,
                CoverageChannel::Luminance => luminance(texel.truncate()),
            }
        });
        self.factor * coverage < self.cutoff
    }
}

/// Marks a triangle without a cut-out in [`MeshCutouts::mask`].
const OPAQUE: u32 = u32::MAX;

/// The cut-outs of one mesh that has some.
#[derive(Debug)]
struct MeshCutouts {
    /// Per stored triangle: its material's mask in [`AlphaCutouts::masks`], or [`OPAQUE`].
    mask: Vec<u32>,
    /// Per stored triangle: the texture coordinates of its corners (zero without any).
    uvs: Vec<[Vec2; 3]>,
}

/// The alpha cut-outs of a scene, per mesh.
#[derive(Debug)]
pub struct AlphaCutouts {
    masks: Vec<Mask>,
    meshes: Vec<Option<MeshCutouts>>,
}

/// One mesh as [`AlphaCutouts::new`] reads it: the material of each stored triangle, the
/// triangles' corners, and the vertex texture coordinates if it has any.
pub struct MeshMaterials<'a> {
    /// Material index per stored triangle.
    pub material_ids: &'a [u32],
    /// Corner indices per stored triangle.
    pub indices: &'a [[u32; 3]],
    /// Texture coordinates per vertex.
    pub uvs: Option<&'a [Vec2]>,
}

impl AlphaCutouts {
    /// The cut-outs of `meshes`, whose materials are `materials` and whose mask textures have
    /// their pyramids in `maps` (indexed by texture); with, per mesh and stored triangle,
    /// whether it may be cut (what [`igi_bvh::Accel::set_cutouts`] takes). `None` if no
    /// triangle has a cut-out material.
    pub fn new<'a>(
        materials: &[Material],
        maps: &[Option<Arc<MipMap>>],
        meshes: impl Iterator<Item = MeshMaterials<'a>>,
    ) -> Option<(Self, Vec<Vec<bool>>)> {
        let mut index = vec![OPAQUE; materials.len()];
        let mut masks = Vec::new();
        for (slot, material) in index.iter_mut().zip(materials) {
            if let Some(mask) = &material.alpha_mask {
                *slot = masks.len() as u32;
                masks.push(Mask {
                    factor: mask.factor,
                    map: mask.texture.and_then(|t| maps.get(t as usize).cloned().flatten()),
                    channel: mask.channel,
                    cutoff: mask.cutoff,
                });
            }
        }
        if masks.is_empty() {
            return None;
        }
        let mut flags = Vec::new();
        let cut_meshes = meshes
            .map(|mesh| {
                let mask: Vec<u32> = mesh.material_ids.iter().map(|&m| index[m as usize]).collect();
                let may_cut: Vec<bool> = mask.iter().map(|&k| k != OPAQUE).collect();
                let any = may_cut.contains(&true);
                flags.push(if any { may_cut } else { Vec::new() });
                any.then(|| MeshCutouts {
                    mask,
                    uvs: mesh
                        .indices
                        .iter()
                        .map(|corners| mesh.uvs.map_or([Vec2::ZERO; 3], |uv| corners.map(|i| uv[i as usize])))
                        .collect(),
                })
            })
            .collect();
        Some((Self { masks, meshes: cut_meshes }, flags))
    }
}

impl CutoutTest for AlphaCutouts {
    fn is_cut(&self, mesh: u32, prim: u32, u: f32, v: f32) -> bool {
        let Some(Some(cutouts)) = self.meshes.get(mesh as usize) else { return false };
        let Some(mask) = self.masks.get(cutouts.mask[prim as usize] as usize) else { return false };
        // The texture coordinates as `PreparedScene::surface` interpolates them.
        let [t0, t1, t2] = cutouts.uvs[prim as usize];
        mask.is_cut((1.0 - u - v) * t0 + u * t1 + v * t2)
    }
}
