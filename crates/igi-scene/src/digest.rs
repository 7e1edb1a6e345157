//! [`Scene::digest`]: a 64-bit fingerprint of a loaded scene's content, so render nodes that
//! load "the same" scene can check that they really hold the same triangles, materials, lights
//! and animation before they render tiles of one image together.

use crate::model::{Mesh, Scene, Texture};
use crate::texels::Texels;
use std::fmt::Write as _;
use std::hash::{DefaultHasher, Hasher};

/// Feeds formatted text into a hasher without building the string, so the `Debug` form of a
/// large structure costs no memory.
struct HashWriter(DefaultHasher);

impl std::fmt::Write for HashWriter {
    fn write_str(&mut self, s: &str) -> std::fmt::Result {
        self.0.write(s.as_bytes());
        Ok(())
    }
}

impl HashWriter {
    fn floats(&mut self, values: impl IntoIterator<Item = f32>) {
        values.into_iter().for_each(|v| self.0.write_u32(v.to_bits()));
    }

    fn mesh(&mut self, mesh: &Mesh) {
        let _ = write!(self, "{}|{}|", mesh.name, mesh.positions.len());
        self.floats(mesh.positions.iter().flat_map(|p| p.to_array()));
        if let Some(normals) = &mesh.normals {
            self.0.write_u8(1);
            self.floats(normals.iter().flat_map(|n| n.to_array()));
        }
        if let Some(uvs) = &mesh.uvs {
            self.0.write_u8(2);
            self.floats(uvs.iter().flat_map(|uv| uv.to_array()));
        }
        self.0.write_usize(mesh.indices.len());
        mesh.indices.iter().flatten().for_each(|&i| self.0.write_u32(i));
        mesh.material_ids.iter().for_each(|&m| self.0.write_u32(m));
    }

    fn texture(&mut self, texture: &Texture) {
        let image = &texture.image;
        let _ = write!(self, "{}|{}x{}|{:?}|", texture.name, image.width, image.height, texture.wrap);
        match &image.texels {
            Texels::Rgba8 { texels, space } => {
                let _ = write!(self, "{space:?}");
                self.0.write(texels.as_flattened());
            }
            Texels::Rgba16 { texels, space } => {
                let _ = write!(self, "{space:?}");
                texels.iter().flatten().for_each(|&v| self.0.write_u16(v));
            }
            Texels::RgbaF32(texels) => self.floats(texels.iter().flatten().copied()),
        }
    }
}

impl Scene {
    /// A fingerprint of everything that affects an image: geometry, materials, textures,
    /// lights, sky, camera and animation (bit patterns of the floats, so −0 and 0 differ).
    /// The same scene loaded by the same build of igi gives the same value on every machine;
    /// it is a check against mismatched files, not a cryptographic hash.
    pub fn digest(&self) -> u64 {
        let mut w = HashWriter(DefaultHasher::new());
        w.0.write_usize(self.meshes.len());
        self.meshes.iter().for_each(|m| w.mesh(m));
        w.0.write_usize(self.textures.len());
        self.textures.iter().for_each(|t| w.texture(t));
        // The rest is small: its Debug form names every field and prints floats exactly.
        let _ = write!(
            w,
            "{:?}{:?}{:?}{:?}{:?}{:?}",
            self.instances, self.materials, self.lights, self.environment, self.camera, self.animation
        );
        w.0.finish()
    }
}

#[cfg(test)]
mod tests {
    use crate::builtin;

    #[test]
    fn same_content_same_digest_any_change_another() {
        let a = builtin("cornell-box").unwrap();
        let b = builtin("cornell-box").unwrap();
        assert_eq!(a.digest(), b.digest());
        let mut moved = b.clone();
        moved.meshes[0].positions[0].x += 1e-3;
        assert_ne!(a.digest(), moved.digest());
        let mut recoloured = b.clone();
        recoloured.materials[0].diffuse.y *= 0.5;
        assert_ne!(a.digest(), recoloured.digest());
        assert_ne!(a.digest(), builtin("animated-room").unwrap().digest());
    }
}
