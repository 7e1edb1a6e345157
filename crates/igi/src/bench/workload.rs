//! The ray workload of `../shared/tools/embree-bench`, reproduced so that `igi bench rays` and
//! `embree_bench` trace identical rays: its VPL random walk and its VPL file format
//! (`set slot px py pz nx ny nz depth`). Its pinhole camera is the renderer's
//! ([`igi_render::PinholeCamera`], which computes embree-bench's primary rays bit for bit).

use anyhow::{Context, Result, bail};
use glam::Vec3;
use igi_bvh::{Accel, Ray};
use rand_core::{RngCore, SeedableRng};
use rand_xoshiro::SplitMix64;
use std::path::Path;

/// A virtual point light as embree-bench writes it: position, normal ((0,0,0) for an omni
/// start point) and bounce count (0 on the light; the file's `depth` column).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BenchVpl {
    /// Position.
    pub p: Vec3,
    /// Surface normal, or zero.
    pub n: Vec3,
    /// Bounces from the light.
    pub bounces: u32,
}

/// SplitMix64 (Steele et al. 2014), embree-bench's generator, so seeds mean the same.
pub struct Random(SplitMix64);

impl Random {
    /// A generator with the given seed.
    pub fn new(seed: u64) -> Self {
        Self(SplitMix64::seed_from_u64(seed))
    }

    /// Uniform in [0, 1).
    pub fn uniform(&mut self) -> f32 {
        (self.0.next_u64() >> 40) as f32 * (1.0 / (1u64 << 24) as f32)
    }
}

/// Cosine-distributed direction about `n` (Malley's method).
fn cosine_dir(n: Vec3, u1: f32, u2: f32) -> Vec3 {
    let r = u1.sqrt();
    let phi = std::f32::consts::TAU * u2;
    let (t, b) = n.any_orthonormal_pair();
    (t * (r * phi.cos()) + b * (r * phi.sin()) + n * (1.0 - u1).max(0.0).sqrt()).normalize()
}

/// Uniform direction on the sphere.
fn sphere_dir(u1: f32, u2: f32) -> Vec3 {
    let z = 1.0 - 2.0 * u1;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = std::f32::consts::TAU * u2;
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Where the VPL random walks start.
pub enum WalkSource<'a> {
    /// Area-weighted points on emissive triangles (world-space corners), emitting along the
    /// winding normal.
    Emitters(&'a [[Vec3; 3]]),
    /// An omnidirectional point light.
    Point(Vec3),
}

/// `sets · k` VPLs by embree-bench's random walk: a start point on the light (itself a VPL),
/// then a VPL at every hit, continuing with probability `cont_prob` in a cosine direction, and
/// ending at a miss or an emissive surface. VPL i goes to set i mod S, slot i / S.
pub fn random_walk_vpls(
    accel: &Accel,
    is_emissive: impl Fn(u32, u32) -> bool,
    source: WalkSource,
    sets: usize,
    k: usize,
    seed: u64,
    tnear: f32,
) -> Result<Vec<BenchVpl>> {
    const CONT_PROB: f32 = 0.5;
    let want = sets * k;
    let mut rng = Random::new(seed);
    let (cdf, total) = match &source {
        WalkSource::Emitters(tris) => {
            let mut acc = 0.0f64;
            let cdf: Vec<f64> = tris
                .iter()
                .map(|t| {
                    acc += 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length() as f64;
                    acc
                })
                .collect();
            (cdf, acc)
        }
        WalkSource::Point(_) => (Vec::new(), 0.0),
    };
    let mut all = Vec::with_capacity(want);
    for _ in 0..1_000_000 {
        if all.len() >= want {
            break;
        }
        let (mut p, n, mut d) = match &source {
            WalkSource::Emitters(tris) => {
                let u = rng.uniform() as f64 * total;
                let j = cdf.partition_point(|&c| c < u).min(tris.len() - 1);
                let [a, b, c] = tris[j];
                let (su, v2) = (rng.uniform().sqrt(), rng.uniform());
                let p = a * (1.0 - su) + b * (su * (1.0 - v2)) + c * (su * v2);
                let n = (b - a).cross(c - a).normalize();
                (p, n, cosine_dir(n, rng.uniform(), rng.uniform()))
            }
            WalkSource::Point(light) => (*light, Vec3::ZERO, sphere_dir(rng.uniform(), rng.uniform())),
        };
        all.push(BenchVpl { p, n, bounces: 0 });
        let mut bounces = 1;
        while all.len() < want {
            let hit = accel.intersect(&Ray { origin: p, dir: d, tnear, tfar: f32::INFINITY });
            if !hit.is_hit() || is_emissive(hit.instance, hit.prim) {
                break;
            }
            let q = p + d * hit.t;
            let mut ng = accel.geometric_normal(hit.instance, hit.prim);
            if ng.dot(d) > 0.0 {
                ng = -ng;
            }
            all.push(BenchVpl { p: q, n: ng, bounces });
            if rng.uniform() >= CONT_PROB {
                break;
            }
            p = q;
            d = cosine_dir(ng, rng.uniform(), rng.uniform());
            bounces += 1;
        }
    }
    if all.len() < want {
        bail!("could only place {} of {want} VPLs: the lights do not reach the scene", all.len());
    }
    let mut out = vec![all[0]; want];
    for (i, v) in all.into_iter().take(want).enumerate() {
        out[(i % sets) * k + i / sets] = v;
    }
    Ok(out)
}

/// Largest VPL file: 256 bytes a line for the most VPLs `igi bench rays` takes (16 x 16 sets of
/// 4096), where embree-bench writes about 100.
pub(super) const MAX_VPL_FILE_BYTES: u64 = 256 * 16 * 16 * 4096;

/// Reads an embree-bench VPL file (`set slot px py pz nx ny nz depth` per line, `#` comments)
/// holding exactly `sets · k` VPLs, through the loaders' guarded reader.
pub fn read_vpl_file(path: &Path, sets: usize, k: usize) -> Result<Vec<BenchVpl>> {
    let bytes = igi_scene::read_regular_file(path, MAX_VPL_FILE_BYTES).context("cannot read the VPL file")?;
    let text = String::from_utf8(bytes).with_context(|| format!("{}: not UTF-8 text", path.display()))?;
    let mut vpls = vec![None; sets * k];
    for (line_no, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let at = || format!("{}:{}", path.display(), line_no + 1);
        let f: Vec<&str> = line.split_whitespace().collect();
        if f.len() != 9 {
            bail!("{}: expected 9 fields (set slot px py pz nx ny nz depth), found {}", at(), f.len());
        }
        let int = |s: &str| s.parse::<usize>().with_context(|| format!("{}: bad integer {s:?}", at()));
        let num = |s: &str| {
            s.parse::<f32>()
                .ok()
                .filter(|v| v.is_finite())
                .with_context(|| format!("{}: bad number {s:?}", at()))
        };
        let (set, slot) = (int(f[0])?, int(f[1])?);
        if set >= sets || slot >= k {
            bail!("{}: VPL (set {set}, slot {slot}) is outside {sets} sets of {k}", at());
        }
        vpls[set * k + slot] = Some(BenchVpl {
            p: Vec3::new(num(f[2])?, num(f[3])?, num(f[4])?),
            n: Vec3::new(num(f[5])?, num(f[6])?, num(f[7])?),
            bounces: f[8].parse::<u32>().with_context(|| format!("{}: bad depth {:?}", at(), f[8]))?,
        });
    }
    let missing = vpls.iter().filter(|v| v.is_none()).count();
    if missing > 0 {
        bail!("{}: {missing} of the {} VPLs ({sets} sets of {k}) are missing", path.display(), sets * k);
    }
    Ok(vpls.into_iter().flatten().collect())
}
