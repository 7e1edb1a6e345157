//! The image of a frame: rectangles of pixels ([`pixel_rect`]) and the frame's tiles
//! ([`tile`]), the framebuffer of linear radiance ([`film`]), the pixels a frame
//! delivers ([`frame_image`]), tone mapping from per-tile statistics ([`tonemap`], paper 3.4),
//! the running mean of a still view ([`progressive`]), what a frame cost ([`stats`]), and the
//! image files igi writes ([`output`]).

pub mod blotch;
pub mod convergence;
pub mod film;
pub mod frame_image;
pub mod output;
pub mod pixel_rect;
pub mod progressive;
pub mod stats;
pub mod tile;
pub mod tonemap;
