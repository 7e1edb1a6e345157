//! First sight: what a scene that brings no camera or no usable light is shown with, so that
//! every scene shows on the first command: where the camera starts
//! ([`start_camera`](mod@start_camera)) and the light igi adds when the scene's own lights do
//! not show the view ([`default_light`]).

pub mod default_light;
pub mod start_camera;
