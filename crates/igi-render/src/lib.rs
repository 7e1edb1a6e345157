//! Frame rendering for igi: everything between a loaded scene and an image file.
//!
//! The pieces, each in its own module:
//! - [`prepared`]: [`PreparedScene`], the scene plus its acceleration structure and shading
//!   tables (materials per triangle, normals, texture coordinates, emissive triangles).
//! - [`camera`]: the pinhole camera ([`PinholeCamera`]), identical to the Embree benchmark's.
//! - [`lights`] and [`sampling`]: light sources as sampled by the renderer, deterministic
//!   sample sequences.
//! - [`texture`]: texture filtering.
//! - [`direct`]: direct lighting with shadow rays ([`DirectLighting`]), the shading of this
//!   first renderer; instant radiosity (DESIGN.md section 1) builds on it.
//! - [`tile`] and [`mod@render`]: tiles and the local tile scheduler ([`render()`]).
//! - [`film`], [`tonemap`] and [`output`]: the framebuffer, tone mapping, EXR and PNG files.
//!
//! A minimal render:
//!
//! ```no_run
//! # fn demo(scene: igi_scene::Scene) -> Result<(), igi_render::output::OutputError> {
//! use igi_render::{PreparedScene, RenderSettings, default_camera, render, write_image};
//! let prepared = PreparedScene::new(scene);
//! let camera = prepared.camera().copied().unwrap_or_else(|| default_camera(&prepared.bounds()));
//! let settings = RenderSettings::default();
//! let film = render(&prepared, &camera, &settings);
//! write_image(&film, "out.png".as_ref(), settings.tone_map())?;
//! # Ok(()) }
//! ```

pub mod camera;
pub mod direct;
pub mod film;
pub mod frame;
pub mod lights;
pub mod output;
pub mod path_tracer;
pub mod prepared;
pub mod render;
pub mod sampling;
pub mod scattering;
pub mod scheduler;
pub mod texture;
pub mod tile;
pub mod tonemap;
pub mod vpl;

pub use camera::{PinholeCamera, default_camera};
pub use direct::{DirectLighting, RayCounts};
pub use film::Film;
pub use output::{OutputError, write_exr, write_image, write_png};
pub use prepared::{PreparedScene, SurfacePoint};
pub use render::{RenderSettings, RenderStats, TileRenderer, render, render_with_stats};
pub use tile::{Tile, TileGrid};
pub use tonemap::{ToneMap, ToneMapper};
