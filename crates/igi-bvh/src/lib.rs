//! Ray tracing core of igi: BVH builders, the node layouts, the watertight triangle test and
//! the traversal kernels for single rays and 8-ray SIMD packets (closest hit and any hit), over
//! a two-level structure (one 8-wide BVH per mesh, one binary BVH over the instances).
//!
//! The crate knows nothing about materials or scenes: it takes triangle meshes and their
//! placements, and answers ray queries.

mod aabb;
mod accel;
pub mod build;
mod bvh;
mod bvh8;
mod node;
mod offset;
mod ray;
mod traverse;
mod triangle;

pub use aabb::Aabb;
pub use accel::{Accel, CutoutTest, ShadowCache, TriangleMesh};
pub use build::{BuildParams, build_binned_sah, build_binned_sah_by, build_sweep_sah};
pub use bvh::Bvh;
pub use bvh8::{Bvh8, Bvh8Node};
pub use node::Node;
pub use offset::offset_ray_origin;
pub use ray::{Hit, HitPacket8, INVALID_ID, Ray, RayPacket8};
pub use traverse::TRAVERSAL_STACK_SIZE;
pub use triangle::intersect_triangle;
