//! The messages between rank 0 and the render nodes, and their encoding (postcard: compact,
//! and a malformed message is an error, never a panic or an unbounded allocation).
//!
//! One exchange per frame (paper sections 2.1 and 3.4): rank 0 sends every node the
//! [`FrameJob`] (the whole [`FrameState`]), then tile numbers on demand; each node
//! derives the frame's VPLs itself, renders, filters and tone-maps its tiles, and sends back
//! [`TileResult`]s: the tile's pixels in the frame's format (8-bit while the view moves, paper
//! 3.4; linear radiance where rank 0 averages) and its luminance statistics, from which rank 0 combines
//! the next frame's tone map in tile order.

use igi_render::image::stats::{PhaseTimes, RayCounts};
use igi_render::image::tonemap::LuminanceStats;
use igi_render::{FrameState, Pixels};
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// The version of this protocol; a node of another build refuses to take part.
pub const PROTOCOL_VERSION: u32 = 5;

/// What rank 0 tells a node before the first frame: which scene to load.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Setup {
    /// [`PROTOCOL_VERSION`] of rank 0.
    pub version: u32,
    /// The scene as the user named it (a built-in name or a path).
    pub scene: String,
    /// The scene's files sent along (`--broadcast-scene`): each path as rank 0 read it and
    /// its bytes. Empty: the node loads `scene` from its own file system.
    pub files: Vec<(PathBuf, Vec<u8>)>,
    /// Rank 0's [`igi_scene::Scene::digest`] of the loaded scene.
    pub digest: u64,
    /// True if the nodes add the default light the scene needs
    /// ([`igi_render::add_default_light`], the same decision on every node), false for
    /// `--no-default-light`.
    pub default_light: bool,
    /// The camera the user asked for (`--camera-*`, `--view`), from which every node judges
    /// the default light as rank 0 does; `None`: the scene's start camera.
    pub view: Option<igi_scene::Camera>,
}

/// A node's answer to [`Setup`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Ready {
    /// The scene is loaded and prepared.
    Loaded {
        /// The node's digest of what it loaded.
        digest: u64,
        /// Its render threads.
        threads: u32,
    },
    /// The node could not load the scene; the message says why.
    Failed(String),
}

/// One frame as every node renders it: the frame itself (camera, settings, pose, tone map,
/// pixel format, seeds) and the number rank 0 gave it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FrameJob {
    /// Number of the job, counting up from 1; tiles name the job they belong to.
    pub id: u64,
    /// The frame.
    pub frame: FrameState,
}

/// A finished tile.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TileResult {
    /// The job it belongs to.
    pub job: u64,
    /// Tile index in the frame's [`igi_render::TileGrid`].
    pub tile: u32,
    /// Its pixels, in the frame's format.
    pub pixels: Pixels,
    /// Luminance statistics of its linear pixels.
    pub stats: LuminanceStats,
    /// Rays traced for it.
    pub rays: RayCounts,
    /// Its render time per phase.
    pub times: PhaseTimes,
    /// VPLs of the frame (the node generated them).
    pub vpls: u32,
}

/// Every message, in either direction.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Message {
    /// Rank 0 → node: load this scene.
    Setup(Setup),
    /// Node → rank 0: the scene is ready (or not).
    Ready(Ready),
    /// Rank 0 → node: the next frame.
    Frame(Box<FrameJob>),
    /// Rank 0 → node: render these tiles of `job`.
    Tiles {
        /// The job.
        job: u64,
        /// Tile indices.
        tiles: Vec<u32>,
    },
    /// Node → rank 0: a finished tile; it also asks for the next one.
    Tile(Box<TileResult>),
    /// Node → rank 0: still alive (sent twice a second, also while a long tile renders).
    Heartbeat,
    /// Node → rank 0: the node cannot go on; the message says why.
    Fatal(String),
    /// Rank 0 → node: stop.
    Shutdown,
    /// Node → rank 0: stopping, as told. Rank 0 ends the job once every node has said so (a
    /// node that stays silent instead ends it with an error naming its rank).
    Bye,
}

/// A message that does not decode.
#[derive(Debug, thiserror::Error)]
#[error("malformed cluster message ({len} bytes): {error}")]
pub struct DecodeError {
    len: usize,
    error: postcard::Error,
}

impl Message {
    /// The variant's name, for protocol errors.
    pub fn kind(&self) -> &'static str {
        match self {
            Self::Setup(_) => "Setup",
            Self::Ready(_) => "Ready",
            Self::Frame(_) => "Frame",
            Self::Tiles { .. } => "Tiles",
            Self::Tile(_) => "Tile",
            Self::Heartbeat => "Heartbeat",
            Self::Fatal(_) => "Fatal",
            Self::Shutdown => "Shutdown",
            Self::Bye => "Bye",
        }
    }

    /// The wire form.
    pub fn encode(&self) -> Vec<u8> {
        // Every field is a plain value: serialising into a Vec cannot fail.
        postcard::to_allocvec(self).unwrap_or_else(|e| unreachable!("cluster message encodes: {e}"))
    }

    /// Reads a wire form.
    pub fn decode(bytes: &[u8]) -> Result<Self, DecodeError> {
        postcard::from_bytes(bytes).map_err(|error| DecodeError { len: bytes.len(), error })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{Affine3A, Vec3};
    use igi_render::{FrameSettings, LightEdit, LightId, PixelFormat, ScenePose};

    #[test]
    fn messages_round_trip() {
        let camera = igi_scene::builtin("cornell-box").and_then(|s| s.camera).unwrap();
        let mut frame = FrameState::new(camera, FrameSettings::default());
        frame.pose = ScenePose {
            time: 1.5,
            moved: vec![(2, Affine3A::from_translation(Vec3::X))],
            sky: 0.5,
            lights: vec![LightEdit {
                light: LightId::Emissive(4),
                power: Vec3::new(2.0, 1.0, 0.0),
                transform: Affine3A::from_rotation_y(0.5),
            }],
        };
        (frame.pixels, frame.number, frame.settings.seed) = (PixelFormat::Srgb8, 3, 9);
        let job = FrameJob { id: 7, frame };
        for m in [
            Message::Frame(Box::new(job)),
            Message::Tiles { job: 7, tiles: vec![0, 5] },
            Message::Heartbeat,
            Message::Bye,
            Message::Tile(Box::new(TileResult {
                job: 7,
                tile: 5,
                pixels: Pixels::Srgb8(vec![1, 2, 3]),
                stats: LuminanceStats { log_sum: -1.0, count: 1, max: 2.0, histogram: [1; 32] },
                rays: RayCounts::default(),
                times: PhaseTimes::default(),
                vpls: 100,
            })),
        ] {
            assert_eq!(Message::decode(&m.encode()).unwrap(), m);
        }
    }

    #[test]
    fn garbage_is_an_error_not_a_panic_or_a_huge_allocation() {
        // A Tiles message claiming 2^62 tile numbers in 12 bytes.
        let mut lying = Message::Tiles { job: 1, tiles: vec![] }.encode();
        lying.pop();
        lying.extend_from_slice(&[0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0x3f]);
        assert!(Message::decode(&lying).is_err());
        for bytes in [&[][..], &[0xff; 7][..], &[3, 0xff, 0xff][..]] {
            assert!(Message::decode(bytes).is_err());
        }
    }
}
