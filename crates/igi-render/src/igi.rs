//! The instant-global-illumination estimator (paper sections 2.1, 3.1-3.3): the frame's
//! virtual point lights from random walks ([`vpl`]), kept by their importance to the view
//! ([`view_importance`]); interleaved sampling of VPL sets and anti-aliasing samples
//! ([`interleave`]); the streaming per-tile pipeline ([`tile_pipeline`]) with its 8-ray packets
//! ([`packet`]) and its inner shadow-ray loop ([`vpl_lighting`]); and the discontinuity-buffer
//! filter that merges the interleaved sets again ([`discontinuity`]).

pub mod discontinuity;
pub mod interleave;
pub(crate) mod packet;
pub mod tile_pipeline;
pub mod view_importance;
pub mod vpl;
pub mod vpl_lighting;
