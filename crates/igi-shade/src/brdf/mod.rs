//! The BRDF shaders (paper 3.2): a small fixed set of lobes, evaluated eight shading points at
//! a time inside the VPL loop and sampled one direction at a time by the VPL random walk and
//! the path tracer. Directions are unit vectors pointing away from the surface.

mod lambert;

pub use lambert::lambert;
