//! [`ScenePose`]: where the scene stands for a frame, the one value [`crate::PreparedScene::pose`]
//! places a prepared scene by, on every render node alike.

use crate::prepared::light_edit::LightEdit;
use glam::Affine3A;
use serde::{Deserialize, Serialize};

/// Where the scene stands for a frame: the clock, the instances a user moved (their extra
/// world transforms) and the sky's strength a user set. [`crate::PreparedScene::pose`] places
/// a scene so, on every render node alike.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ScenePose {
    /// Scene clock, seconds: animated instances and lights take their pose at this time.
    pub time: f32,
    /// Moved instances and their extra world transforms (applied after the animation's pose).
    pub moved: Vec<(u32, Affine3A)>,
    /// Factor on the environment's radiance: 1 as loaded, 0 turns the sky off.
    pub sky: f32,
    /// A viewer's changes to light sources (power, colour, position), in the order applied.
    pub lights: Vec<LightEdit>,
}

impl ScenePose {
    /// The pose at time `time` with nothing moved by hand and the sky as loaded.
    pub fn at(time: f32) -> Self {
        Self { time, moved: Vec::new(), sky: 1.0, lights: Vec::new() }
    }
}

impl Default for ScenePose {
    fn default() -> Self {
        Self::at(0.0)
    }
}
