//! Frame rendering for igi: everything between a loaded scene and an image file, following the
//! frame pipeline of ARCHITECTURE.md (paper sections 2.1, 3.1-3.4).
//!
//! The rooms, each a module with one file per concept:
//! - [`frame`]: [`FrameState`], the small serialisable description of a whole frame (camera,
//!   settings ([`FrameSettings`]), scene pose ([`ScenePose`]), tone map, pixel format, seeds).
//! - [`prepared`]: [`PreparedScene`], the scene plus its acceleration structure and shading
//!   tables, its light sources as the renderers sample them, the environment (sky) light,
//!   alpha cut-outs and a viewer's light edits ([`LightEdit`]). How surfaces scatter light
//!   (surface shaders feeding BRDF shaders) is the `igi-shade` crate's.
//! - [`first_sight`]: where a scene without a camera is seen from and the light added to a
//!   scene whose own lights do not show it.
//! - [`igi`]: the instant-global-illumination estimator: VPLs, view importance, interleaved
//!   sampling, the streaming tile pipeline by stage, VPL lighting, the discontinuity filter.
//! - [`path_tracer`]: the reference path tracer.
//! - [`schedule`]: persistent worker threads taking tiles on demand, cancellation,
//!   [`FrameRenderer`], which poses the scene, plans a frame with its estimator
//!   ([`FramePlan`]) and puts it together, and [`FrameSource`], the one interface every caller
//!   renders frames through (this machine or a cluster; accumulation included).
//! - [`image`]: pixel rectangles and tiles ([`Tile`]), the framebuffer ([`Film`]), a frame's
//!   pixels ([`FrameImage`]), tone mapping, the running mean of a still view
//!   ([`Progressive`]), costs, and EXR and PNG files.
//! - [`temporal`]: a view's frames averaged across camera and object motion (reprojection,
//!   history refused at disocclusions and where the light changed).
//! - [`camera`] and [`sampling`]: the pinhole camera ([`PinholeCamera`]), identical to the
//!   Embree benchmark's, and deterministic sample sequences, shared by every room.
//!
//! A minimal render:
//!
//! ```no_run
//! # fn demo(scene: igi_scene::Scene) -> Result<(), Box<dyn std::error::Error>> {
//! use igi_render::{FrameRenderer, FrameState, FrameSettings, PreparedScene, ToneMap, ToneMapper};
//! use igi_render::{start_camera, write_image};
//! let mut prepared = PreparedScene::new(scene);
//! let camera = start_camera(&prepared);
//! let settings = FrameSettings::for_scene(prepared.bounds().diagonal());
//! let out = FrameRenderer::new(0).render(&mut prepared, &FrameState::new(camera, settings), &|_, _| {})?;
//! let mapper = ToneMapper::new(ToneMap::default(), &out.stats);
//! write_image(out.image.film().expect("a linear frame"), "out.png".as_ref(), &mapper)?;
//! # Ok(()) }
//! ```

pub mod camera;
pub mod first_sight;
pub mod frame;
pub mod igi;
pub mod image;
pub mod path_tracer;
pub mod prepared;
pub mod sampling;
pub mod schedule;
pub mod temporal;

pub use camera::PinholeCamera;
pub use first_sight::default_light::{DefaultLight, add_default_light};
pub use first_sight::start_camera::{default_camera, start_camera};
pub use frame::{Estimator, FrameSettings, FrameState};
pub use image::convergence::{Stopped, StoppingRule, Until};
pub use image::film::Film;
pub use image::frame_image::{DiffuseLayer, FrameImage, PixelFormat, Pixels};
pub use image::output::{OutputError, write_exr, write_image, write_png};
pub use image::pixel_rect::PixelRect;
pub use image::progressive::{Progressive, Shown};
pub use image::stats::{Phase, PhaseTimes, RayCounts};
pub use image::tile::{Tile, TileGrid};
pub use image::tonemap::{ToneMap, ToneMapper};
pub use prepared::light_edit::{LightEdit, LightId};
pub use prepared::scene_pose::ScenePose;
pub use prepared::{GeometryBytes, PreparedScene, SurfacePoint};
pub use schedule::cancel::{CancelToken, Cancelled};
pub use schedule::frame_renderer::{FrameError, FrameOutput, FramePlan, FrameRenderer};
pub use schedule::frame_source::{Accumulated, FrameDone, FrameSource};
pub use temporal::history::{Motion, TemporalHistory};
pub use temporal::surface_buffer::SurfaceBuffer;
