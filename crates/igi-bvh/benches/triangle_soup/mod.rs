//! Triangle soups for the BVH build tests, benchmark and report: a minimal OBJ reader (vertex
//! positions and faces only) for the shared test scenes, and seeded random triangles.
//! Shared by `tests/build.rs`, `benches/build.rs` and `examples/build_report.rs` via `#[path]`.

use rand_core::{RngCore, SeedableRng};
use rand_xoshiro::SplitMix64;
use std::path::PathBuf;

use glam::Vec3;
use igi_bvh::Aabb;

/// A triangle's three corners.
pub type Triangle = [Vec3; 3];

/// The real scenes used for measurements: name and path below `shared/scenes`.
pub const SCENES: [(&str, &str); 2] =
    [("conference", "conference/conference.obj"), ("sponza", "sponza-dabrovic/sponza.obj")];

/// Reads the triangles of an OBJ file below the shared scenes folder (next to the repository),
/// or returns `None` with a message if it is absent. Only `v` and `f` lines matter: faces use
/// the position index of each `v/vt/vn` corner (1-based, or negative = relative to the end)
/// and polygons are split into fans.
pub fn load_scene(relative_path: &str) -> Option<Vec<Triangle>> {
    let path =
        PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/scenes")).join(relative_path);
    let Ok(text) = std::fs::read_to_string(&path) else {
        println!("skipped: scene {} not found", path.display());
        return None;
    };
    let mut positions: Vec<Vec3> = Vec::new();
    let mut triangles = Vec::new();
    for line in text.lines() {
        let mut fields = line.split_whitespace();
        match fields.next() {
            Some("v") => {
                let mut xyz = fields.map(|f| f.parse::<f32>().expect("OBJ vertex coordinate"));
                let mut next = || xyz.next().expect("OBJ vertex with three coordinates");
                positions.push(Vec3::new(next(), next(), next()));
            }
            Some("f") => {
                let corners: Vec<Vec3> = fields
                    .map(|corner| {
                        let index: i64 = corner.split('/').next().unwrap().parse().expect("OBJ index");
                        let index = if index < 0 { positions.len() as i64 + index } else { index - 1 };
                        positions[index as usize]
                    })
                    .collect();
                for i in 2..corners.len() {
                    triangles.push([corners[0], corners[i - 1], corners[i]]);
                }
            }
            _ => {}
        }
    }
    Some(triangles)
}

/// `n` random triangles in the unit cube, seeded: corners within a small cube around a uniform
/// random centre, edge lengths about the mean spacing of the centres.
pub fn random_triangles(n: usize, seed: u64) -> Vec<Triangle> {
    let mut rng = Rng::new(seed);
    let size = 2.0 / (n as f32).cbrt();
    (0..n)
        .map(|_| {
            let centre = rng.vec3();
            [0; 3].map(|_| centre + size * (rng.vec3() - 0.5))
        })
        .collect()
}

/// The bounding box of each triangle.
pub fn triangle_bounds(triangles: &[Triangle]) -> Vec<Aabb> {
    triangles.iter().map(|&t| Aabb::from_points(t)).collect()
}

/// A small seeded generator (SplitMix64), enough for test data.
pub struct Rng(SplitMix64);

impl Rng {
    /// A generator from a seed.
    pub fn new(seed: u64) -> Self {
        Self(SplitMix64::seed_from_u64(seed))
    }

    /// A uniform `u64`.
    pub fn next_u64(&mut self) -> u64 {
        self.0.next_u64()
    }

    /// A uniform float in [0, 1).
    pub fn f32(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }

    /// A point uniform in the unit cube.
    pub fn vec3(&mut self) -> Vec3 {
        Vec3::new(self.f32(), self.f32(), self.f32())
    }
}
