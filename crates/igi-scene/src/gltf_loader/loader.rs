//! The state of one glTF load, which the node walk, the meshes, the materials, the lights and
//! the camera fill in.

use std::collections::HashMap;
use std::path::Path;

use super::channels::NodeTracks;
use crate::model::Scene;
use crate::report::LoadReport;
use crate::texture::TextureSet;

/// State of one glTF load.
pub(super) struct Loader<'a> {
    pub(super) file: &'a Path,
    pub(super) base_dir: Option<&'a Path>,
    pub(super) buffers: &'a [Vec<u8>],
    pub(super) report: &'a mut LoadReport,
    pub(super) scene: Scene,
    pub(super) textures: &'a mut TextureSet,
    /// glTF mesh index → scene mesh index (`None`: the mesh has no triangles).
    pub(super) meshes: HashMap<usize, Option<u32>>,
    /// glTF material index (`None`: the default material) → scene material index.
    pub(super) materials: HashMap<Option<usize>, u32>,
    /// glTF node index → its animation tracks (taken when the node is visited).
    pub(super) tracks: HashMap<usize, NodeTracks>,
}

impl<'a> Loader<'a> {
    /// A load of `file` with its `buffers` and its nodes' animation `tracks`.
    pub(super) fn new(
        file: &'a Path,
        base_dir: Option<&'a Path>,
        buffers: &'a [Vec<u8>],
        tracks: HashMap<usize, NodeTracks>,
        textures: &'a mut TextureSet,
        report: &'a mut LoadReport,
    ) -> Self {
        Self {
            file,
            base_dir,
            buffers,
            report,
            // glTF 2.0: "the front of a glTF asset faces +Z".
            scene: Scene { front: Some(glam::Vec3::Z), ..Scene::default() },
            textures,
            meshes: HashMap::new(),
            materials: HashMap::new(),
            tracks,
        }
    }
}
