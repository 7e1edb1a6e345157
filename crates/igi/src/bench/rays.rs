//! `igi bench rays`: Mrays/s of the single-ray and 8-ray packet kernels for primary rays
//! (closest hit) and shadow rays to VPLs (any hit), with 1..N threads, plus BVH build time, SAH
//! cost and bytes per triangle. Ray definitions, tiling and timing follow
//! `../shared/tools/embree-bench` (its README), so both tools measure the same work.

use super::workload::{BenchVpl, WalkSource, random_walk_vpls, read_vpl_file};
use anyhow::{Context, Result, bail};
use clap::Args;
use glam::Vec3;
use igi_bvh::{Accel, Ray, RayPacket8, ShadowCache, TriangleMesh};
use igi_render::frame::limits::{MAX_INTERLEAVE, MAX_SIDE, MAX_VPLS_PER_PIXEL};
use igi_render::{PinholeCamera, PreparedScene};
use igi_simd::{F32x8, M32x8, Vec3x8};
use serde::Serialize;
use std::path::PathBuf;
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

/// Arguments of `igi bench rays`.
#[derive(Debug, Args)]
pub struct RaysArgs {
    /// Built-in scene name or scene file.
    pub scene: String,
    /// Camera overrides.
    #[command(flatten)]
    pub camera: crate::camera_args::CameraArgs,
    /// Resolutions, comma separated.
    #[arg(long, default_value = "640x480,1024x1024", value_delimiter = ',', value_parser = parse_res)]
    pub res: Vec<(u32, u32)>,
    /// VPLs per pixel (per interleaved set).
    #[arg(long, default_value_t = 16)]
    pub k: usize,
    /// G for G x G interleaved VPL sets (packets hold pixels of one set).
    #[arg(long, default_value_t = 3)]
    pub sets: usize,
    /// Thread counts, comma separated.
    #[arg(long, default_value = "1,2", value_delimiter = ',')]
    pub threads: Vec<usize>,
    /// Kernels to time, comma separated: `single`, `packet8`, `cached8` (shadow rays only: the
    /// packets of `packet8` grouped VPL by VPL with a shadow cache, as the renderer traces
    /// them). The primary pass of `single` or `packet8` provides the shadow rays' origins
    /// (with `cached8` alone, `packet8`'s runs untimed).
    #[arg(long, default_value = "single,packet8,cached8", value_delimiter = ',', value_parser = ["single", "packet8", "cached8"])]
    pub kernels: Vec<String>,
    /// Timed repetitions per measurement (the median is reported).
    #[arg(long, default_value_t = 5)]
    pub reps: usize,
    /// Seed of the VPL random walk.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Read the VPLs from an embree-bench VPL file instead of generating them.
    #[arg(long)]
    pub vpl_file: Option<PathBuf>,
    /// Point light that starts the VPL walks (default: the scene's emissive triangles).
    #[arg(long, value_parser = crate::camera_args::parse_vec3, allow_hyphen_values = true)]
    pub light: Option<Vec3>,
    /// Write all results as JSON.
    #[arg(long)]
    pub json: Option<PathBuf>,
}

/// Largest `--reps` (as `igi bench frame --frames`).
const MAX_REPS: usize = 100_000;

pub(super) fn parse_res(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s.split_once('x').ok_or_else(|| format!("resolution {s:?} is not WxH"))?;
    let p = |v: &str| v.parse::<u32>().ok().filter(|&v| (1..=MAX_SIDE).contains(&v));
    match (p(w), p(h)) {
        (Some(w), Some(h)) => Ok((w, h)),
        _ => Err(format!("resolution {s:?} is not WxH with sides in 1..={MAX_SIDE}")),
    }
}

/// One measurement, as the JSON reports it.
#[derive(Debug, Serialize)]
struct Measurement {
    phase: &'static str,
    kernel: &'static str,
    threads: usize,
    width: u32,
    height: u32,
    rays: u64,
    mrays_per_s: f64,
    /// Primary rays that hit, or shadow rays that were blocked.
    hits: u64,
}

#[derive(Debug, Serialize)]
struct BuildReport {
    ms: f64,
    sah_cost: f32,
    bytes_per_triangle: f64,
}

#[derive(Debug, Serialize)]
struct Report {
    scene: String,
    triangles: usize,
    simd_backend: &'static str,
    k: usize,
    sets: usize,
    vpls: usize,
    build: BuildReport,
    results: Vec<Measurement>,
}

/// A primary hit as the shadow pass needs it: the position, or none.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct HitRec {
    p: Vec3,
    valid: bool,
}

/// The image cut into square tiles handed out to threads on demand.
pub(super) struct Tiling {
    size: u32,
    cols: u32,
    rows: u32,
}

impl Tiling {
    /// Tiles of 16·`sets` pixels (whole 4x2 packets of every interleaved set) over the image.
    pub(super) fn new(cam: &PinholeCamera, sets: usize) -> Self {
        let size = 16 * sets as u32;
        Self { size, cols: cam.width.div_ceil(size), rows: cam.height.div_ceil(size) }
    }

    /// Pixels of one tile.
    pub(super) fn pixels(&self) -> usize {
        (self.size * self.size) as usize
    }

    pub(super) fn count(&self) -> usize {
        (self.cols * self.rows) as usize
    }
    fn origin(&self, tile: usize) -> (u32, u32) {
        ((tile as u32 % self.cols) * self.size, (tile as u32 / self.cols) * self.size)
    }
}

/// Runs `work` over all tiles on `threads` threads pulling tiles from an atomic counter; thread
/// start and join are inside the timed region (as in embree-bench). Returns seconds and the sum
/// of the per-tile (rays, hits) counts.
pub(super) fn timed_tiles(
    threads: usize,
    tiles: usize,
    work: &(dyn Fn(usize) -> (u64, u64) + Sync),
) -> (f64, u64, u64) {
    let next = AtomicUsize::new(0);
    let start = Instant::now();
    let (rays, hits) = std::thread::scope(|s| {
        let handles: Vec<_> = (0..threads)
            .map(|_| {
                s.spawn(|| {
                    let (mut r, mut h) = (0, 0);
                    loop {
                        let t = next.fetch_add(1, Ordering::Relaxed);
                        if t >= tiles {
                            break (r, h);
                        }
                        let (tr, th) = work(t);
                        r += tr;
                        h += th;
                    }
                })
            })
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().expect("bench thread"))
            .fold((0, 0), |a, b| (a.0 + b.0, a.1 + b.1))
    });
    (start.elapsed().as_secs_f64(), rays, hits)
}

/// Median seconds over `reps` timed runs after one warm-up run.
pub(super) fn median_run(reps: usize, mut f: impl FnMut() -> (f64, u64, u64)) -> (f64, u64, u64) {
    let warm = f();
    let mut times: Vec<f64> = (0..reps.max(1)).map(|_| f().0).collect();
    times.sort_by(f64::total_cmp);
    (times[times.len() / 2], warm.1, warm.2)
}

/// Milliseconds to build `scene`'s acceleration structure as embree-bench times it: copying the
/// vertex and index buffers plus building the whole two-level structure (per-mesh BVHs and the
/// top level).
pub(super) fn build_ms(scene: &igi_scene::Scene) -> f64 {
    let instances: Vec<(u32, glam::Affine3A)> =
        scene.instances.iter().map(|i| (i.mesh, i.transform)).collect();
    let start = Instant::now();
    let meshes = scene
        .meshes
        .iter()
        .map(|m| TriangleMesh { positions: m.positions.clone(), indices: m.indices.clone() })
        .collect();
    drop(Accel::build(meshes, &instances));
    start.elapsed().as_secs_f64() * 1e3
}

fn hit_record(ray: &Ray, t: f32) -> HitRec {
    HitRec { p: ray.at(t), valid: true }
}

/// Runs the benchmark and prints (and optionally writes) the results.
pub fn run(args: &RaysArgs) -> Result<()> {
    // The renderer's bounds: --k is its --vpls, --sets its --interleave side.
    if !(1..=MAX_VPLS_PER_PIXEL as usize).contains(&args.k) {
        bail!("--k: {} is not between 1 and {MAX_VPLS_PER_PIXEL}", args.k);
    }
    if !(1..=MAX_INTERLEAVE as usize).contains(&args.sets) {
        bail!("--sets: {} is not between 1 and {MAX_INTERLEAVE}", args.sets);
    }
    if args.threads.iter().any(|&t| t == 0 || t > 1024) {
        bail!("--threads must be between 1 and 1024");
    }
    if !(1..=MAX_REPS).contains(&args.reps) {
        bail!("--reps: {} is not between 1 and {MAX_REPS}", args.reps);
    }
    super::json_report::check_json(args.json.as_deref())?;
    let file_vpls = args
        .vpl_file
        .as_deref()
        .map(|path| read_vpl_file(path, args.sets * args.sets, args.k))
        .transpose()?;
    let scene = igi_scene::load_named(&args.scene).context("cannot load scene")?;

    let mut build_ms: Vec<f64> = (0..5).map(|_| build_ms(&scene)).collect();
    build_ms.sort_by(f64::total_cmp);
    let build_ms = build_ms[build_ms.len() / 2];
    let prepared = PreparedScene::new(scene);
    let camera = args.camera.resolve(&prepared)?;
    let accel = prepared.accel();
    let triangles: usize = accel.meshes().iter().map(|m| m.indices.len()).sum();
    let bounds = accel.bounds();
    let eps_abs = 1e-5 * bounds.diagonal();

    let vpls = match file_vpls {
        Some(vpls) => vpls,
        None => {
            let emitters = prepared.emissive_triangle_corners();
            let source = match args.light {
                Some(p) => WalkSource::Point(p),
                None if !emitters.is_empty() => WalkSource::Emitters(&emitters),
                None => {
                    let c = bounds.centroid();
                    let p = Vec3::new(c.x, bounds.max.y - 0.1 * bounds.extent().y, c.z);
                    tracing::warn!(
                        "no emissive triangles and no --light: VPL walks start at a point light at {p}"
                    );
                    WalkSource::Point(p)
                }
            };
            random_walk_vpls(
                accel,
                |i, p| prepared.is_emissive(i, p),
                source,
                args.sets * args.sets,
                args.k,
                args.seed,
                eps_abs,
            )?
        }
    };

    let mut results = Vec::new();
    outln!(
        "scene={} triangles={triangles} build_ms={:.2} sah={:.2} bytes/tri={:.1} vpls={} backend={}",
        args.scene,
        build_ms,
        accel.sah_cost(),
        accel.bytes() as f64 / triangles.max(1) as f64,
        vpls.len(),
        igi_simd::BACKEND
    );
    outln!(
        "{:>10} {:>7} {:>8} {:>4} {:>10} {:>10} {:>9}",
        "res",
        "phase",
        "kernel",
        "thr",
        "rays",
        "hits",
        "Mrays/s"
    );
    for &(w, h) in &args.res {
        let cam = PinholeCamera::new(&camera, w, h);
        let tiling = Tiling::new(&cam, args.sets);
        let tile_px = tiling.pixels();
        let hits: Vec<Mutex<Vec<HitRec>>> =
            (0..tiling.count()).map(|_| Mutex::new(vec![HitRec::default(); tile_px])).collect();
        for &threads in &args.threads {
            let mut record = |phase, kernel, (secs, rays, n): (f64, u64, u64)| {
                let m = Measurement {
                    phase,
                    kernel,
                    threads,
                    width: w,
                    height: h,
                    rays,
                    mrays_per_s: rays as f64 / secs / 1e6,
                    hits: n,
                };
                outln!(
                    "{:>10} {:>7} {:>8} {:>4} {:>10} {:>10} {:>9.2}",
                    format!("{w}x{h}"),
                    m.phase,
                    m.kernel,
                    threads,
                    m.rays,
                    m.hits,
                    m.mrays_per_s
                );
                results.push(m);
            };
            let run = |f: &(dyn Fn(usize) -> (u64, u64) + Sync)| {
                median_run(args.reps, || timed_tiles(threads, tiling.count(), f))
            };
            let wants = |k: &str| args.kernels.iter().any(|x| x == k);
            if wants("single") {
                record("primary", "single", run(&|t| primary_single(accel, &cam, &tiling, t, &hits[t])));
            }
            if wants("packet8") {
                record("primary", "packet8", run(&|t| primary_packet8(accel, &cam, &tiling, t, &hits[t])));
            } else if !wants("single") {
                // `cached8` alone: the origins still come from a primary pass, untimed.
                timed_tiles(threads, tiling.count(), &|t| primary_packet8(accel, &cam, &tiling, t, &hits[t]));
            }
            let ctx = ShadowCtx {
                accel,
                cam: &cam,
                tiling: &tiling,
                vpls: &vpls,
                k: args.k,
                g: args.sets as u32,
                eps_abs,
            };
            if wants("single") {
                record("shadow", "single", run(&|t| shadow_single(&ctx, t, &hits[t].lock().expect("tile"))));
            }
            if wants("packet8") {
                record(
                    "shadow",
                    "packet8",
                    run(&|t| shadow_packet8(&ctx, t, &hits[t].lock().expect("tile"))),
                );
            }
            if wants("cached8") {
                record(
                    "shadow",
                    "cached8",
                    run(&|t| shadow_cached8(&ctx, t, &hits[t].lock().expect("tile"))),
                );
            }
        }
    }
    if let Some(path) = &args.json {
        let report = Report {
            scene: args.scene.clone(),
            triangles,
            simd_backend: igi_simd::BACKEND,
            k: args.k,
            sets: args.sets,
            vpls: vpls.len(),
            build: BuildReport {
                ms: build_ms,
                sah_cost: accel.sah_cost(),
                bytes_per_triangle: accel.bytes() as f64 / triangles.max(1) as f64,
            },
            results,
        };
        super::json_report::write_json(path, &report)?;
    }
    Ok(())
}

/// One primary ray per pixel, traced one at a time.
pub(super) fn primary_single(
    accel: &Accel,
    cam: &PinholeCamera,
    tiling: &Tiling,
    tile: usize,
    out: &Mutex<Vec<HitRec>>,
) -> (u64, u64) {
    let (x0, y0) = tiling.origin(tile);
    let mut out = out.lock().expect("tile");
    let (mut rays, mut hits) = (0, 0);
    for y in y0..(y0 + tiling.size).min(cam.height) {
        for x in x0..(x0 + tiling.size).min(cam.width) {
            let ray = cam.ray(x, y);
            let h = accel.intersect(&ray);
            let i = ((y - y0) * tiling.size + (x - x0)) as usize;
            out[i] = if h.is_hit() { hit_record(&ray, h.t) } else { HitRec::default() };
            rays += 1;
            hits += h.is_hit() as u64;
        }
    }
    (rays, hits)
}

/// Primary rays as 8-ray packets of 4x2 pixel blocks.
pub(super) fn primary_packet8(
    accel: &Accel,
    cam: &PinholeCamera,
    tiling: &Tiling,
    tile: usize,
    out: &Mutex<Vec<HitRec>>,
) -> (u64, u64) {
    let (x0, y0) = tiling.origin(tile);
    let mut out = out.lock().expect("tile");
    let (mut rays, mut hits) = (0, 0);
    for by in (0..tiling.size).step_by(2) {
        for bx in (0..tiling.size).step_by(4) {
            let inside = |i: u32| x0 + bx + i % 4 < cam.width && y0 + by + i / 4 < cam.height;
            let mask = M32x8::from_bools(std::array::from_fn(|i| inside(i as u32)));
            if mask.none() {
                continue;
            }
            let lane_rays: [Ray; 8] = std::array::from_fn(|i| {
                let i = i as u32;
                if inside(i) { cam.ray(x0 + bx + i % 4, y0 + by + i / 4) } else { cam.ray(0, 0) }
            });
            let hp = accel.intersect8(&RayPacket8::from_rays(&lane_rays), mask);
            let hit_mask = hp.hit_mask() & mask;
            for (i, ray) in lane_rays.iter().enumerate() {
                if !mask.lane(i) {
                    continue;
                }
                let p = ((by + i as u32 / 4) * tiling.size + bx + i as u32 % 4) as usize;
                out[p] = if hit_mask.lane(i) { hit_record(ray, hp.t.lane(i)) } else { HitRec::default() };
            }
            rays += mask.bitmask().count_ones() as u64;
            hits += hit_mask.bitmask().count_ones() as u64;
        }
    }
    (rays, hits)
}

/// What the shadow kernels share: the scene, the image and its tiles, and the VPLs of every
/// interleaved set (`k` per set, `g` × `g` sets).
pub(super) struct ShadowCtx<'a> {
    pub accel: &'a Accel,
    pub cam: &'a PinholeCamera,
    pub tiling: &'a Tiling,
    pub vpls: &'a [BenchVpl],
    pub k: usize,
    pub g: u32,
    pub eps_abs: f32,
}

/// Shadow-ray tnear/tfar convention of embree-bench: tfar = distance · (1 - 1e-4).
const SHADOW_TFAR_SCALE: f32 = 1.0 - 1e-4;

/// Every valid pixel to each VPL of its interleaved set, one ray at a time.
pub(super) fn shadow_single(c: &ShadowCtx, tile: usize, hits: &[HitRec]) -> (u64, u64) {
    let (x0, y0) = c.tiling.origin(tile);
    let (mut rays, mut blocked) = (0, 0);
    for y in y0..(y0 + c.tiling.size).min(c.cam.height) {
        for x in x0..(x0 + c.tiling.size).min(c.cam.width) {
            let h = hits[((y - y0) * c.tiling.size + (x - x0)) as usize];
            if !h.valid {
                continue;
            }
            let set = ((x % c.g) + c.g * (y % c.g)) as usize;
            for l in &c.vpls[set * c.k..(set + 1) * c.k] {
                let d = l.p - h.p;
                let dist = d.length();
                // d · (1/dist), as the packet set-up and embree-bench compute it.
                let dir = if dist > 0.0 { d * (1.0 / dist) } else { Vec3::ZERO };
                let ray = Ray { origin: h.p, dir, tnear: c.eps_abs, tfar: dist * SHADOW_TFAR_SCALE };
                rays += 1;
                blocked += c.accel.occluded(&ray) as u64;
            }
        }
    }
    (rays, blocked)
}

/// The shadow-ray origins of set (`sx`, `sy`) in `tile` as 8-ray packets: 4x2 blocks of the
/// set's sub-image (pixel stride G, paper Figure 2), with their valid lanes; blocks without a
/// valid pixel are left out.
fn set_packets(c: &ShadowCtx, tile: usize, hits: &[HitRec], (sx, sy): (u32, u32)) -> Vec<(Vec3x8, M32x8)> {
    let (x0, y0) = c.tiling.origin(tile);
    let sub = c.tiling.size / c.g;
    let mut packets = Vec::new();
    for by in (0..sub).step_by(2) {
        for bx in (0..sub).step_by(4) {
            let lane: [HitRec; 8] = std::array::from_fn(|i| {
                let (lx, ly) = (sx + c.g * (bx + i as u32 % 4), sy + c.g * (by + i as u32 / 4));
                if x0 + lx < c.cam.width && y0 + ly < c.cam.height {
                    hits[(ly * c.tiling.size + lx) as usize]
                } else {
                    HitRec::default()
                }
            });
            let valid = M32x8::from_bools(lane.map(|h| h.valid));
            if valid.any() {
                packets.push((Vec3x8::from_lanes(lane.map(|h| h.p.to_array())), valid));
            }
        }
    }
    packets
}

/// The shadow rays from `org` to VPL `l`, as embree-bench sets them up.
fn shadow_packet(c: &ShadowCtx, l: &BenchVpl, org: Vec3x8) -> RayPacket8 {
    let d = Vec3x8::splat(l.p.to_array()) - org;
    let dist = d.length();
    let inv = F32x8::select(dist.gt(F32x8::ZERO), F32x8::splat(1.0) / dist, F32x8::ZERO);
    RayPacket8 {
        origin: org,
        dir: d * inv,
        tnear: F32x8::splat(c.eps_abs),
        tfar: dist * F32x8::splat(SHADOW_TFAR_SCALE),
    }
}

/// The VPLs of set (`sx`, `sy`).
fn set_vpls<'c>(c: &'c ShadowCtx, (sx, sy): (u32, u32)) -> &'c [BenchVpl] {
    &c.vpls[(sx + c.g * sy) as usize * c.k..][..c.k]
}

/// Shadow rays as 8-ray packets ([`set_packets`]), each packet to every VPL of its set in
/// turn, as embree-bench groups them.
fn shadow_packet8(c: &ShadowCtx, tile: usize, hits: &[HitRec]) -> (u64, u64) {
    let (mut rays, mut blocked) = (0, 0);
    for set in (0..c.g).flat_map(|sy| (0..c.g).map(move |sx| (sx, sy))) {
        for (org, valid) in set_packets(c, tile, hits, set) {
            for l in set_vpls(c, set) {
                rays += u64::from(valid.bitmask().count_ones());
                blocked +=
                    u64::from(c.accel.occluded8(&shadow_packet(c, l, org), valid).bitmask().count_ones());
            }
        }
    }
    (rays, blocked)
}

/// The same shadow rays grouped as the renderer traces them: VPL by VPL, each VPL's packets in
/// pixel order with its shadow cache (`igi_bvh::ShadowCache`; ARCHITECTURE.md).
pub(super) fn shadow_cached8(c: &ShadowCtx, tile: usize, hits: &[HitRec]) -> (u64, u64) {
    let (mut rays, mut blocked) = (0, 0);
    for set in (0..c.g).flat_map(|sy| (0..c.g).map(move |sx| (sx, sy))) {
        let packets = set_packets(c, tile, hits, set);
        for l in set_vpls(c, set) {
            let mut cache = ShadowCache::default();
            for &(org, valid) in &packets {
                rays += u64::from(valid.bitmask().count_ones());
                let b = c.accel.occluded8_cached(&shadow_packet(c, l, org), valid, &mut cache);
                blocked += u64::from(b.bitmask().count_ones());
            }
        }
    }
    (rays, blocked)
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    /// `igi bench rays`' arguments alone.
    #[derive(Debug, Parser)]
    struct Line {
        #[command(flatten)]
        args: RaysArgs,
    }

    /// The arguments of a whole command line: `igi`, `bench`, `rays`, then the arguments.
    fn args(line: &[&str]) -> RaysArgs {
        let line = std::iter::once(line[0]).chain(line[3..].iter().copied());
        Line::try_parse_from(line).expect("valid command line").args
    }

    fn error_of(line: &[&str]) -> String {
        format!("{:#}", run(&args(line)).unwrap_err())
    }

    #[test]
    fn vpl_counts_beyond_the_renderers_bounds_are_refused() {
        let err = error_of(&["igi", "bench", "rays", "cornell-box", "--k", "1000000000"]);
        assert!(err.contains("--k: 1000000000 is not between 1 and 4096"), "{err}");
        let err = error_of(&["igi", "bench", "rays", "cornell-box", "--sets", "17"]);
        assert!(err.contains("--sets: 17 is not between 1 and 16"), "{err}");
        let err = error_of(&["igi", "bench", "rays", "cornell-box", "--reps", "100000000000"]);
        assert!(err.contains("--reps: 100000000000 is not between 1 and 100000"), "{err}");
    }

    #[test]
    fn vpl_files_are_read_through_the_guarded_reader() {
        let err = error_of(&["igi", "bench", "rays", "cornell-box", "--vpl-file", "/dev/zero"]);
        assert!(err.contains("/dev/zero: not a regular file"), "{err}");
        // A sparse file just beyond the bound: refused by its size, before it is read.
        let path = std::env::temp_dir().join(format!("igi-bench-vpls-{}.txt", std::process::id()));
        let file = std::fs::File::create(&path).unwrap();
        file.set_len(super::super::workload::MAX_VPL_FILE_BYTES + 1).unwrap();
        let err = error_of(&["igi", "bench", "rays", "cornell-box", "--vpl-file", path.to_str().unwrap()]);
        assert!(err.contains("bytes, more than the 268435456 allowed"), "{err}");
        std::fs::remove_file(&path).unwrap();
    }

    #[test]
    fn a_missing_json_folder_fails_before_the_scene_is_loaded() {
        let err =
            error_of(&["igi", "bench", "rays", "/no/such/scene.obj", "--json", "/nonexistent-igi/r.json"]);
        assert!(
            err.contains(
                "--json: /nonexistent-igi/r.json: cannot create files in the folder /nonexistent-igi"
            ),
            "{err}"
        );
    }

    /// The renderer's grouping (VPL by VPL, with the shadow cache) and the single-ray kernel
    /// trace the same rays as embree-bench's packets and find the same ones blocked, on a scene
    /// where about a quarter are, among them a ray parallel to an axis that lies in a BVH box's
    /// face (ARCHITECTURE.md, "Rays in a box face").
    #[test]
    fn cached_shadow_packets_and_single_rays_block_what_the_plain_packets_block() {
        let path = std::env::temp_dir().join(format!("igi-bench-rays-{}.json", std::process::id()));
        let line =
            ["igi", "bench", "rays", "cornell-box", "--res", "150x100", "--threads", "1", "--reps", "1"];
        let extra = ["--kernels", "single,packet8,cached8", "--json", path.to_str().unwrap()];
        run(&args(&[&line[..], &extra[..]].concat())).expect("benchmark runs");
        let report: serde_json::Value = serde_json::from_slice(&std::fs::read(&path).unwrap()).unwrap();
        std::fs::remove_file(&path).unwrap();
        let shadow = |kernel: &str| {
            let m = report["results"]
                .as_array()
                .unwrap()
                .iter()
                .find(|m| m["phase"] == "shadow" && m["kernel"] == kernel)
                .expect("measured");
            (m["rays"].as_u64().unwrap(), m["hits"].as_u64().unwrap())
        };
        let (rays, blocked) = shadow("packet8");
        assert_eq!(shadow("cached8"), (rays, blocked));
        assert_eq!(shadow("single"), (rays, blocked));
        assert!(blocked > rays / 10 && blocked < rays / 2, "{blocked} of {rays} blocked");
    }
}
