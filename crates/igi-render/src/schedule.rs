//! Scheduling a frame (paper 2.1, 3.4): persistent worker threads taking tiles on demand
//! ([`scheduler`]), the token that abandons a frame between tiles ([`cancel`]), and
//! [`frame_renderer`], which poses the scene, plans a frame and puts its tiles together, keeping
//! its threads' memory from frame to frame ([`pool`]).

pub mod cancel;
pub mod frame_renderer;
pub mod frame_source;
pub mod pool;
pub mod scheduler;
