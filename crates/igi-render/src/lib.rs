//! Frame rendering for igi: everything between a loaded scene and an image file, following the
//! frame pipeline of ARCHITECTURE.md (paper sections 2.1, 3.1-3.4).
//!
//! The pieces, each in its own module:
//! - [`frame`]: [`FrameState`], the small serialisable description of a whole frame (camera,
//!   settings ([`IgiSettings`]), scene pose ([`ScenePose`]), tone map, pixel format, seeds).
//! - [`frame_image`]: what pixels a frame carries ([`PixelFormat`], a tile's [`Pixels`], a
//!   frame's [`FrameImage`]).
//! - [`progressive`]: [`Progressive`], the one owner of accumulation and tone-map feedback.
//! - [`prepared`]: [`PreparedScene`], the scene plus its acceleration structure and shading
//!   tables (materials per triangle, normals, texture coordinates, emissive triangles).
//! - [`camera`]: the pinhole camera ([`PinholeCamera`]), identical to the Embree benchmark's;
//!   [`viewpoint`]: where a scene without a camera is seen from.
//! - [`lights`], [`environment`] and [`sampling`]: light sources, the environment (sky)
//!   light and deterministic sample sequences; [`light_edit`]: a viewer's changes to the
//!   light sources ([`LightEdit`]), carried by the scene pose. How surfaces scatter light (surface shaders
//!   feeding BRDF shaders) is the `igi-shade` crate's, shared by every estimator here.
//! - [`vpl`]: virtual point lights from random walks (instant radiosity), kept by
//!   [`view_importance`], their importance to what the camera sees.
//! - [`interleave`]: interleaved sampling of VPL sets and anti-aliasing samples.
//! - [`tile_pipeline`] and [`vpl_lighting`]: the streaming per-tile pipeline and its inner
//!   shadow-ray loop.
//! - [`discontinuity`]: the discontinuity-buffer filter.
//! - [`pixel_rect`], [`tile`], [`scheduler`] and [`frame_renderer`]: rectangles of pixels,
//!   tiles, persistent worker threads taking tiles on demand, and [`FrameRenderer`], which
//!   poses the scene, plans a frame ([`FramePlan`]) and puts it together.
//! - [`cancel`]: [`CancelToken`], which abandons a frame between tiles.
//! - [`path_tracer`]: the reference path tracer.
//! - [`stats`], [`film`], [`tonemap`] and [`output`]: costs, the framebuffer, tone mapping,
//!   EXR and PNG files.
//!
//! A minimal render:
//!
//! ```no_run
//! # fn demo(scene: igi_scene::Scene) -> Result<(), Box<dyn std::error::Error>> {
//! use igi_render::{FrameRenderer, FrameState, IgiSettings, PreparedScene, ToneMap, ToneMapper};
//! use igi_render::{start_camera, write_image};
//! let mut prepared = PreparedScene::new(scene);
//! let camera = start_camera(&prepared);
//! let settings = IgiSettings { clamp: IgiSettings::clamp_for(prepared.bounds().diagonal()), ..IgiSettings::default() };
//! let out = FrameRenderer::new(0).render(&mut prepared, &FrameState::new(camera, settings), &|_, _| {})?;
//! let mapper = ToneMapper::new(ToneMap::default(), &out.stats);
//! write_image(out.image.film().expect("a linear frame"), "out.png".as_ref(), &mapper)?;
//! # Ok(()) }
//! ```

pub mod camera;
pub mod cancel;
pub mod cutout;
pub mod default_light;
pub mod discontinuity;
pub mod environment;
pub mod film;
pub mod frame;
pub mod frame_image;
pub mod frame_renderer;
pub mod interleave;
pub mod light_edit;
pub mod lights;
pub mod output;
mod packet;
pub mod path_tracer;
pub mod pixel_rect;
pub mod prepared;
pub mod progressive;
pub mod sampling;
pub mod scheduler;
pub mod stats;
pub mod tile;
pub mod tile_pipeline;
pub mod tonemap;
pub mod view_importance;
pub mod viewpoint;
pub mod vpl;
pub mod vpl_lighting;

pub use camera::PinholeCamera;
pub use cancel::{CancelToken, Cancelled};
pub use default_light::{DefaultLight, add_default_light};
pub use film::Film;
pub use frame::{FrameState, IgiSettings, ScenePose};
pub use frame_image::{FrameImage, PixelFormat, Pixels};
pub use frame_renderer::{FrameError, FrameOutput, FramePlan, FrameRenderer};
pub use light_edit::{LightEdit, LightId};
pub use output::{OutputError, write_exr, write_image, write_png};
pub use pixel_rect::PixelRect;
pub use prepared::{GeometryBytes, PreparedScene, SurfacePoint};
pub use progressive::{Progressive, Shown};
pub use stats::{Phase, PhaseTimes, RayCounts};
pub use tile::{Tile, TileGrid};
pub use tonemap::{ToneMap, ToneMapper};
pub use viewpoint::{default_camera, start_camera};
