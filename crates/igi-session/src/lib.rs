//! The interaction model of igi's viewers, shared by the native window (`igi view`) and the
//! browser viewer (`igi serve`), and tested here without either.
//!
//! - [`input`]: what a user can do ([`Input`]): keys, drags, scrolls, picks and settings, as
//!   serialisable messages (the browser sends them as JSON).
//! - [`camera_control`]: fly (WASD/QE + mouse look) and orbit (drag around a target) cameras.
//! - [`settings`]: [`ViewerSettings`], the render and display settings a viewer exposes.
//! - [`session`]: [`Session`], which owns the prepared scene, the scene clock, the selection
//!   and the view's [`igi_render::Progressive`] (accumulation and tone-map feedback), and
//!   turns inputs into frames rendered by an [`igi_render::FrameSource`] (this machine's
//!   threads or a cluster): while the camera and the scene are still, frames accumulate with fresh VPL sets (progressive convergence); any change shows
//!   the instant one-frame solution at once (paper section 1).
//! - [`light_control`]: [`LightControl`], a light source's intensity, colour and move as a
//!   viewer edits them.
//! - [`selection`]: [`Selection`], the picked object's name and outline on the image.
//! - [`catalog`]: [`SceneCatalog`], the scenes a viewer may open instead (by name only).
//! - [`render_loop`]: [`RenderLoop`], a thread rendering the next frame while the viewer
//!   shows the newest one; inputs go in, only the newest frame comes out.
//! - [`refusals`]: [`Refusals`], one viewer's messages about its refused inputs, bounded.

pub mod camera_control;
pub mod catalog;
pub mod input;
pub mod light_control;
pub mod refusals;
pub mod render_loop;
pub mod selection;
pub mod session;
pub mod settings;

pub use camera_control::CameraController;
pub use catalog::{SceneCatalog, SceneOpener};
pub use input::{Button, CameraMode, Input, InputError, Key};
pub use light_control::{LightControl, LightKind};
pub use refusals::Refusals;
pub use render_loop::{LatestFrame, RenderLoop, Watching};
pub use selection::Selection;
pub use session::{Frame, FrameStats, Session};
pub use settings::ViewerSettings;
