//! What pixels a frame carries: the [`PixelFormat`] a frame asks for, a tile's [`Pixels`] (and
//! the [`TileOutput`] an estimator delivers for a tile) and a frame's [`FrameImage`].
//!
//! A display needs only tone-mapped 8-bit pixels, which is what render nodes send while the
//! view moves (paper 3.4): a quarter of the bytes of linear radiance. Linear radiance is asked
//! for where it is averaged (progressive refinement), written to EXR, or tone-mapped from the
//! image's own statistics; a linear frame still carries its display image. A frame shown with
//! temporal reuse asks for its [`DiffuseLayer`] as well: the part of the radiance the
//! history may carry to another view (ARCHITECTURE.md, "Temporal reuse while the view moves").

use crate::image::film::{Film, copy_tile};
use crate::image::output::to_srgb8;
use crate::image::stats::{Phase, PhaseTimes, RayCounts};
use crate::image::tile::Tile;
use crate::image::tonemap::{LuminanceStats, ToneMapper};
use glam::Vec3;
use serde::{Deserialize, Serialize};
use std::time::Instant;

/// The pixels a frame delivers.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum PixelFormat {
    /// Tone-mapped, sRGB-encoded 8-bit RGB: what a display shows (paper 3.4).
    Srgb8,
    /// Linear radiance (32-bit float RGB), and the display image made from it.
    #[default]
    Linear,
    /// Linear radiance with its [`DiffuseLayer`], and the display image: for temporal
    /// reuse, which reprojects the layer and takes the rest from the frame itself.
    Layered,
}

/// The diffuse layer of a frame: the light a camera ray's first hit reflects through its
/// diffuse lobe, from the VPLs (ρ_d·D, with the bias compensation's light) and from the exact
/// lights. It is the part of the radiance that looks the same from every direction, and it
/// holds all of the VPLs' diffuse noise, so temporal reuse reprojects it. Emission, glossy
/// reflection and everything seen through mirrors and glass are the rest: view-dependent or
/// noise-free, so temporal reuse takes them from each new frame while the view moves (a
/// glossy highlight reprojected from earlier views would trail the camera, and a bright
/// emitter would bleed into its neighbours through the resampling).
#[derive(Clone, Debug, PartialEq)]
pub struct DiffuseLayer(pub Film);

/// The pixels of one tile, row-major within the tile, in the frame's [`PixelFormat`]. The
/// display image is encoded with the tile (while it is in cache) in either format.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Pixels {
    /// 3 bytes per pixel, tone-mapped with the frame's tone map.
    Srgb8(Vec<u8>),
    /// Linear RGB radiance per pixel, and its display image as in [`Pixels::Srgb8`].
    Linear {
        /// The radiance.
        radiance: Vec<Vec3>,
        /// For [`PixelFormat::Layered`]: the radiance's [`DiffuseLayer`] part per pixel.
        diffuse_layer: Option<Vec<Vec3>>,
        /// `radiance` tone-mapped and sRGB-encoded, 3 bytes per pixel.
        srgb8: Vec<u8>,
    },
}

impl Pixels {
    /// A tile's `radiance` in `format`: the display image tone-mapped with `tone_map` and
    /// sRGB-encoded (while the tile is in cache, for either format), with the radiance itself
    /// for a linear frame, and for a layered one its [`DiffuseLayer`] part `diffuse_layer` (an
    /// estimator without VPLs has none: then temporal reuse carries all of its radiance).
    pub fn encode(
        radiance: Vec<Vec3>,
        diffuse_layer: Option<Vec<Vec3>>,
        format: PixelFormat,
        tone_map: &ToneMapper,
    ) -> Self {
        let mut srgb8 = vec![0u8; 3 * radiance.len()];
        tone_map.encode_pixels(&radiance, &mut srgb8);
        match format {
            PixelFormat::Linear => Self::Linear { radiance, diffuse_layer: None, srgb8 },
            PixelFormat::Layered => Self::Linear { radiance, diffuse_layer, srgb8 },
            PixelFormat::Srgb8 => Self::Srgb8(srgb8),
        }
    }

    /// Whether these pixels can stand in a frame of `format`.
    pub fn fits(&self, format: PixelFormat) -> bool {
        match self {
            Self::Srgb8(_) => format == PixelFormat::Srgb8,
            Self::Linear { diffuse_layer: None, .. } => format != PixelFormat::Srgb8,
            Self::Linear { diffuse_layer: Some(_), .. } => format == PixelFormat::Layered,
        }
    }

    /// Number of pixels, or `None` if the parts disagree (a byte count not a multiple of 3,
    /// or a display image of another size than the radiance).
    pub fn pixel_count(&self) -> Option<usize> {
        match self {
            Self::Srgb8(bytes) => (bytes.len() % 3 == 0).then_some(bytes.len() / 3),
            Self::Linear { radiance, diffuse_layer, srgb8 } => (srgb8.len() == 3 * radiance.len()
                && diffuse_layer.as_ref().is_none_or(|layer| layer.len() == radiance.len()))
            .then_some(radiance.len()),
        }
    }

    /// The display image.
    pub fn srgb8(&self) -> &[u8] {
        match self {
            Self::Srgb8(bytes) | Self::Linear { srgb8: bytes, .. } => bytes,
        }
    }
}

/// A finished tile: its pixels and what it cost.
#[derive(Clone, Debug)]
pub struct TileOutput {
    /// The tile.
    pub tile: Tile,
    /// Its pixels in the frame's [`FrameState::pixels`](crate::FrameState::pixels) format: linear radiance, or tone-mapped
    /// with the frame's [`FrameState::tone_map`](crate::FrameState::tone_map) and sRGB-encoded, what a display shows (and
    /// what a render node sends while the view moves, paper 3.4).
    pub pixels: Pixels,
    /// Luminance statistics of the pixels (for the next frame's tone mapping, paper 3.4).
    pub stats: LuminanceStats,
    /// Rays traced.
    pub rays: RayCounts,
    /// Time per phase.
    pub times: PhaseTimes,
}

impl TileOutput {
    /// What an estimator delivers for `tile` from its `radiance` (and its [`DiffuseLayer`] part,
    /// if it has one), `rays` and `times`: its luminance statistics and its pixels in `format`
    /// ([`Pixels::encode`] with `tone_map`), the time they take counted as the tone-map phase.
    pub fn encode(
        tile: Tile,
        (radiance, diffuse_layer): (Vec<Vec3>, Option<Vec<Vec3>>),
        format: PixelFormat,
        tone_map: &ToneMapper,
        rays: RayCounts,
        mut times: PhaseTimes,
    ) -> Self {
        let start = Instant::now();
        let stats = LuminanceStats::of_pixels(&radiance);
        let pixels = Pixels::encode(radiance, diffuse_layer, format, tone_map);
        times.add(Phase::ToneMap, start.elapsed());
        Self { tile, pixels, stats, rays, times }
    }
}

/// A frame's image: the display image, and the linear radiance it was made from if the frame
/// asked for it.
#[derive(Clone, Debug, PartialEq)]
pub enum FrameImage {
    /// The display image alone.
    Srgb8 {
        /// Width in pixels.
        width: u32,
        /// Height in pixels.
        height: u32,
        /// 3 bytes per pixel, row-major, row 0 at the top.
        bytes: Vec<u8>,
    },
    /// Linear radiance and its display image.
    Linear {
        /// The radiance.
        film: Film,
        /// For a [`PixelFormat::Layered`] frame of an estimator with VPLs: the radiance's
        /// [`DiffuseLayer`] part.
        diffuse_layer: Option<DiffuseLayer>,
        /// `film` tone-mapped and sRGB-encoded, 3 bytes per pixel.
        srgb8: Vec<u8>,
    },
}

impl FrameImage {
    /// A linear image and its display image under `tone_map` ([`to_srgb8`]).
    pub fn from_film(film: Film, tone_map: &ToneMapper) -> Self {
        let srgb8 = to_srgb8(&film, tone_map);
        Self::Linear { film, diffuse_layer: None, srgb8 }
    }

    /// The image of a frame put together from its tiles, which must all be in `format` and
    /// cover the image.
    pub fn from_tiles(
        format: PixelFormat,
        width: u32,
        height: u32,
        tiles: impl IntoIterator<Item = (Tile, Pixels)>,
    ) -> Self {
        let mut bytes = vec![0u8; 3 * width as usize * height as usize];
        let mut film = (format != PixelFormat::Srgb8).then(|| Film::new(width, height));
        // The layer stays only if every tile has it (an estimator without VPLs has none).
        let mut layer = (format == PixelFormat::Layered).then(|| Film::new(width, height));
        for (tile, pixels) in tiles {
            assert!(pixels.fits(format), "a tile of another format than its frame");
            copy_tile(&mut bytes, 3 * width as usize, &tile, pixels.srgb8(), 3);
            if let (Pixels::Linear { radiance, diffuse_layer, .. }, Some(film)) = (pixels, &mut film) {
                film.write_tile(&tile, &radiance);
                match (diffuse_layer, &mut layer) {
                    (Some(part), Some(layer)) => layer.write_tile(&tile, &part),
                    _ => layer = None,
                }
            }
        }
        match film {
            Some(film) => Self::Linear { film, diffuse_layer: layer.map(DiffuseLayer), srgb8: bytes },
            None => Self::Srgb8 { width, height, bytes },
        }
    }

    /// The display image: 3 bytes per pixel, row-major, row 0 at the top.
    pub fn srgb8(&self) -> &[u8] {
        match self {
            Self::Srgb8 { bytes, .. } => bytes,
            Self::Linear { srgb8, .. } => srgb8,
        }
    }

    /// The linear radiance, if the frame asked for it.
    pub fn into_film(self) -> Option<Film> {
        match self {
            Self::Srgb8 { .. } => None,
            Self::Linear { film, .. } => Some(film),
        }
    }

    /// The linear radiance, if the frame asked for it.
    pub fn film(&self) -> Option<&Film> {
        match self {
            Self::Srgb8 { .. } => None,
            Self::Linear { film, .. } => Some(film),
        }
    }

    /// The radiance's [`DiffuseLayer`] part, if the frame asked for it and its estimator has one.
    pub fn diffuse_layer(&self) -> Option<&DiffuseLayer> {
        match self {
            Self::Srgb8 { .. } => None,
            Self::Linear { diffuse_layer, .. } => diffuse_layer.as_ref(),
        }
    }
}
