//! Virtual point lights (VPLs): generation by random walks from the light sources (paper 2.1,
//! instant radiosity, Keller 1997). HELPER FILLS THIS IN.

use crate::frame::FrameState;
use crate::prepared::PreparedScene;
use glam::Vec3;
use igi_scene::Light;

/// A virtual point light on a surface: a Lambertian emitter whose radiant intensity toward a
/// unit direction ω is `power · max(0, normal · ω) / π`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Vpl {
    /// Position on the surface.
    pub position: Vec3,
    /// Unit normal of the emitting side (the side the light arrived from).
    pub normal: Vec3,
    /// Emitted power Φ per channel (already multiplied by the surface's albedo).
    pub power: Vec3,
}

/// The VPLs of one frame: n·m interleaved sets of surface VPLs, plus the punctual lights that
/// light every set exactly.
#[derive(Clone, Debug, Default)]
pub struct VplSets {
    lights: Vec<Light>,
    sets: Vec<Vec<Vpl>>,
    paths_per_set: u32,
}

impl VplSets {
    /// Generates the sets of `frame` in `scene`.
    pub fn generate(scene: &PreparedScene, frame: &FrameState) -> Self {
        let _ = (scene, frame);
        todo!()
    }

    /// Point, spot and directional lights (or the headlight): exact direct light, in every set.
    pub fn lights(&self) -> &[Light] {
        &self.lights
    }

    /// Surface VPLs of set `s`.
    pub fn set(&self, s: u32) -> &[Vpl] {
        &self.sets[s as usize]
    }

    /// Number of sets.
    pub fn set_count(&self) -> u32 {
        self.sets.len() as u32
    }

    /// Light paths started per set.
    pub fn paths_per_set(&self) -> u32 {
        self.paths_per_set
    }
}
