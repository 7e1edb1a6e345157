//! First sight: what a scene that brings no camera or no usable light is shown with, so that
//! every scene shows on the first command: where the camera starts
//! ([`start_camera`](mod@start_camera)) and the light igi adds when the scene's own lights do
//! not show the view ([`default_light`]): a sun and the [`daylight_sky`](mod@daylight_sky) in
//! the open, lamps under the ceiling ([`ceiling_lights`](mod@ceiling_lights)) in an interior.

pub mod ceiling_lights;
pub mod daylight_sky;
pub mod default_light;
pub mod start_camera;
