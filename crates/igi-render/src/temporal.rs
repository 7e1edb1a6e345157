//! Temporal reuse: a view's frames averaged across camera and object motion, each frame
//! still computing all its light anew (ARCHITECTURE.md, "Temporal reuse while the view
//! moves"). [`surface_buffer`] traces what each pixel sees; [`history`] reprojects the running
//! mean through it, refuses it where the surface was hidden or the light changed, and blends.

pub mod history;
pub mod surface_buffer;
