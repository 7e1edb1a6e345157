//! Writing a [`Film`] to disk: OpenEXR with the linear radiance (32-bit float RGB, through the
//! `exr` crate, written deterministically), or PNG with tone-mapped, sRGB-encoded 8-bit RGB (through `image`). The file
//! extension picks the format. Every file is replaced at once ([`atomic_file`]).

mod atomic_file;

pub use atomic_file::{check_writable, end_writes, write_atomically};

use crate::image::film::Film;
use crate::image::tonemap::ToneMapper;
use rayon::prelude::*;
use std::path::{Path, PathBuf};

/// Why an output file could not be written.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    /// The output's folder is missing or takes no new files.
    #[error("{}: cannot create files in the folder {}: {error}", path.display(), folder.display())]
    Folder {
        /// The output file.
        path: PathBuf,
        /// The folder it would go to.
        folder: PathBuf,
        /// Why a file could not be created there.
        error: std::io::Error,
    },
    /// The output path names a folder.
    #[error(
        "{} is a folder: name a file in it, such as {}",
        .0.display(),
        .0.join("image.png").display()
    )]
    IsFolder(PathBuf),
    /// The extension names no supported format.
    #[error("{}: unknown image format: the name must end in .png (tone-mapped) or .exr (linear)", .0.display())]
    UnknownFormat(PathBuf),
    /// Encoding or writing the PNG failed.
    #[error("{}: cannot write PNG: {error}", path.display())]
    Png {
        /// The output file.
        path: PathBuf,
        /// The encoder's error (part of the message, so not also reported as the source).
        error: image::ImageError,
    },
    /// Encoding or writing the EXR failed.
    #[error("{}: cannot write EXR: {error}", path.display())]
    Exr {
        /// The output file.
        path: PathBuf,
        /// The encoder's error (part of the message, so not also reported as the source).
        error: exr::error::Error,
    },
}

/// Output file formats.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImageFormat {
    /// Tone-mapped 8-bit sRGB PNG.
    Png,
    /// Linear 32-bit float OpenEXR.
    Exr,
}

impl ImageFormat {
    /// The format named by `path`'s extension (case-insensitive `.png` or `.exr`). A path
    /// without one that names a folder (`-o renders`) is refused as a folder, which is what
    /// the user got wrong, not the format.
    pub fn from_path(path: &Path) -> Result<Self, OutputError> {
        match path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() {
            Some("png") => Ok(Self::Png),
            Some("exr") => Ok(Self::Exr),
            _ if path.is_dir() => Err(OutputError::IsFolder(path.to_owned())),
            _ => Err(OutputError::UnknownFormat(path.to_owned())),
        }
    }
}

/// Writes `film` to `path` in the format of its extension; `tone_map` applies to PNG only.
pub fn write_image(film: &Film, path: &Path, tone_map: &ToneMapper) -> Result<(), OutputError> {
    match ImageFormat::from_path(path)? {
        ImageFormat::Png => write_png(film, path, tone_map),
        ImageFormat::Exr => write_exr(film, path),
    }
}

/// The tone-mapped 8-bit sRGB pixels of `film`, row-major RGB, row 0 at the top, encoded on
/// the current rayon pool (the pixels are independent, so the bytes are the same on any
/// number of threads).
pub fn to_srgb8(film: &Film, tone_map: &ToneMapper) -> Vec<u8> {
    const CHUNK: usize = 4096;
    let mut out = vec![0u8; 3 * film.pixels().len()];
    out.par_chunks_mut(3 * CHUNK)
        .zip(film.pixels().par_chunks(CHUNK))
        .for_each(|(out, pixels)| tone_map.encode_pixels(pixels, out));
    out
}

/// Writes `film` as a tone-mapped sRGB PNG.
pub fn write_png(film: &Film, path: &Path, tone_map: &ToneMapper) -> Result<(), OutputError> {
    write_png_rgb8(&to_srgb8(film, tone_map), film.width(), film.height(), path)
}

/// Writes 8-bit sRGB pixels (3 bytes each, row-major, row 0 at the top) as a PNG: a display
/// image as the tiles delivered it.
pub fn write_png_rgb8(rgb8: &[u8], width: u32, height: u32, path: &Path) -> Result<(), OutputError> {
    write_atomically(path, |out| {
        image::write_buffer_with_format(
            out,
            rgb8,
            width,
            height,
            image::ExtendedColorType::Rgb8,
            image::ImageFormat::Png,
        )
    })
    .map_err(|error| OutputError::Png { path: path.to_owned(), error })
}

/// Writes `film` as a linear 32-bit float RGB OpenEXR file. Blocks are compressed and written
/// in order on the calling thread, so the same film always gives the same bytes.
pub fn write_exr(film: &Film, path: &Path) -> Result<(), OutputError> {
    use exr::prelude::{Image, SpecificChannels, Vec2, WritableImage};
    let channels = SpecificChannels::rgb(|Vec2(x, y): Vec2<usize>| {
        let p = film.get(x as u32, y as u32);
        (p.x, p.y, p.z)
    });
    let image = Image::from_channels((film.width() as usize, film.height() as usize), channels);
    write_atomically(path, |out| image.write().non_parallel().to_buffered(out))
        .map_err(|error| OutputError::Exr { path: path.to_owned(), error })
}
