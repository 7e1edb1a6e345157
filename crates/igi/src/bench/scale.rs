//! `igi bench scale`: how the cost of a ray grows with the scene, the paper's claim of
//! logarithmic cost in scene size (abstract; issue 17). The same view of the built-in
//! `displaced-sphere` tessellated at 10⁴, 10⁵, … unique triangles, then as a wall of 10 × 10
//! instances of spheres a tenth the size (100 discs of a tenth the radius cover what one disc
//! does, so the image coverage stays the same) at 10⁵ and 10⁶ triangles each, 10⁷ and 10⁸ in
//! all. For each: build time, bytes per stored triangle of mesh and BVH, and nanoseconds per
//! primary ray (8-ray packets) and per shadow ray (8-ray packets VPL by VPL with the shadow
//! cache, as the renderer traces them), on all threads; a table, and JSON with `--json`.

use super::rays::{
    HitRec, ShadowCtx, Tiling, build_ms, median_run, primary_packet8, shadow_cached8, timed_tiles,
};
use super::workload::{WalkSource, random_walk_vpls};
use anyhow::{Context, Result, bail};
use clap::Args;
use glam::{Affine3A, Vec3};
use igi_render::{PinholeCamera, PreparedScene};
use igi_scene::{Instance, Light, Scene};
use serde::Serialize;
use std::path::PathBuf;
use std::sync::Mutex;

/// Arguments of `igi bench scale`.
#[derive(Debug, Args)]
pub struct ScaleArgs {
    /// Largest unique triangle count as a power of ten (4 to 7); the instanced steps use the
    /// sizes up to one below it.
    #[arg(long, default_value_t = 7, value_parser = clap::value_parser!(u32).range(4..=7))]
    pub max_exponent: u32,
    /// Image width and height.
    #[arg(long, default_value = "640x480", value_parser = super::rays::parse_res)]
    pub res: (u32, u32),
    /// VPLs per pixel (per interleaved 3x3 set).
    #[arg(long, default_value_t = 8, value_parser = clap::value_parser!(u32).range(1..=64))]
    pub k: u32,
    /// Threads (default: all cores).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub threads: Option<u32>,
    /// Timed repetitions per measurement (the median is reported).
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u32).range(1..=1000))]
    pub reps: u32,
    /// Write the results as JSON.
    #[arg(long)]
    pub json: Option<PathBuf>,
}

/// Interleaved VPL sets per side, the renderer's default.
const SETS: usize = 3;
/// Instances per side of the instanced steps' wall of spheres.
const WALL: u32 = 10;

/// One scene of the family and what it cost.
#[derive(Debug, Serialize)]
struct Step {
    /// Triangles the rays can meet (instances counted every time).
    triangles: u64,
    /// Triangles stored (instances counted once).
    unique_triangles: u64,
    instances: u32,
    /// Building the whole two-level BVH, including copying the vertex and index buffers.
    build_ms: f64,
    /// Vertices, indices and BVH per stored triangle.
    bytes_per_triangle: f64,
    primary_ns_per_ray: f64,
    shadow_ns_per_ray: f64,
    primary_rays: u64,
    shadow_rays: u64,
}

#[derive(Debug, Serialize)]
struct Report {
    width: u32,
    height: u32,
    vpls_per_pixel: u32,
    threads: usize,
    simd_backend: &'static str,
    steps: Vec<Step>,
}

/// The displaced sphere of `triangles` triangles, alone or as the wall of instances.
fn family_scene(triangles: u64, wall: bool) -> Result<Scene> {
    let mut scene = igi_scene::load_named(&format!("displaced-sphere:triangles={triangles}"))
        .context("generating displaced-sphere")?;
    if wall {
        // Mesh 0 is the sphere, mesh 1 the floor; the wall stands where the sphere was.
        let step = 2.0 / WALL as f32;
        scene.instances = (0..WALL * WALL)
            .map(|i| {
                let at = |k: u32| -1.0 + step * (k as f32 + 0.5);
                let place = Vec3::new(at(i % WALL), at(i / WALL), 0.0);
                Instance {
                    mesh: 0,
                    transform: Affine3A::from_scale_rotation_translation(
                        Vec3::splat(step / 2.0),
                        glam::Quat::IDENTITY,
                        place,
                    ),
                }
            })
            .chain([Instance { mesh: 1, transform: Affine3A::IDENTITY }])
            .collect();
    }
    Ok(scene)
}

/// Measures one scene of the family.
fn measure(args: &ScaleArgs, threads: usize, scene: Scene) -> Result<Step> {
    let build_ms = build_ms(&scene);

    let Some(&Light::Point { position: light, .. }) = scene.lights.first() else {
        bail!("displaced-sphere has lost its point light");
    };
    let camera = scene.camera.context("displaced-sphere has a camera")?;
    let spheres = scene.instances.iter().filter(|i| i.mesh == 0).count() as u32;
    let sphere_triangles = scene.meshes[0].indices.len() as u64;
    let prepared = PreparedScene::new(scene);
    let accel = prepared.accel();
    let bytes = prepared.geometry_bytes();
    let cam = PinholeCamera::new(&camera, args.res.0, args.res.1);
    let tiling = Tiling::new(&cam, SETS);
    let eps_abs = 1e-5 * accel.bounds().diagonal();
    let vpls = random_walk_vpls(
        accel,
        |_, _| false,
        WalkSource::Point(light),
        SETS * SETS,
        args.k as usize,
        1,
        eps_abs,
    )?;
    let hits: Vec<Mutex<Vec<HitRec>>> =
        (0..tiling.count()).map(|_| Mutex::new(vec![HitRec::default(); tiling.pixels()])).collect();
    let reps = args.reps as usize;
    let (primary_s, primary_rays, _) = median_run(reps, || {
        timed_tiles(threads, tiling.count(), &|t| primary_packet8(accel, &cam, &tiling, t, &hits[t]))
    });
    let ctx = ShadowCtx {
        accel,
        cam: &cam,
        tiling: &tiling,
        vpls: &vpls,
        k: args.k as usize,
        g: SETS as u32,
        eps_abs,
    };
    let (shadow_s, shadow_rays, _) = median_run(reps, || {
        timed_tiles(threads, tiling.count(), &|t| shadow_cached8(&ctx, t, &hits[t].lock().expect("tile")))
    });
    Ok(Step {
        triangles: sphere_triangles * u64::from(spheres) + 2,
        unique_triangles: bytes.stored_triangles as u64,
        instances: spheres,
        build_ms,
        bytes_per_triangle: (bytes.triangles + bytes.bvh) as f64 / bytes.stored_triangles as f64,
        primary_ns_per_ray: primary_s * 1e9 / primary_rays.max(1) as f64,
        shadow_ns_per_ray: shadow_s * 1e9 / shadow_rays.max(1) as f64,
        primary_rays,
        shadow_rays,
    })
}

/// Runs the benchmark and prints (and optionally writes) the results.
pub fn run(args: &ScaleArgs) -> Result<()> {
    super::json_report::check_json(args.json.as_deref())?;
    let threads = args.threads.map_or_else(rayon::current_num_threads, |t| t as usize);
    let mut plan: Vec<(u64, bool)> = (4..=args.max_exponent).map(|e| (10u64.pow(e), false)).collect();
    plan.extend((5..args.max_exponent).map(|e| (10u64.pow(e), true)));
    outln!(
        "displaced-sphere, {}x{}, {} VPLs/pixel in 3x3 sets, {threads} thread(s), backend {}",
        args.res.0,
        args.res.1,
        args.k,
        igi_simd::BACKEND
    );
    outln!(
        "{:>12} {:>10} {:>5} {:>9} {:>7} {:>11} {:>8} {:>11} {:>8}",
        "triangles",
        "unique",
        "inst",
        "build ms",
        "B/tri",
        "primary ns",
        "x prev",
        "shadow ns",
        "x prev"
    );
    let mut steps: Vec<Step> = Vec::new();
    for (triangles, wall) in plan {
        let step = measure(args, threads, family_scene(triangles, wall)?)?;
        // Each step against the latest one with about a tenth of its triangles.
        let previous =
            steps.iter().rev().find(|s| (8.0..12.0).contains(&(step.triangles as f64 / s.triangles as f64)));
        let ratio = |now: f64, then: Option<f64>| then.map_or("".into(), |then| format!("{:.2}", now / then));
        outln!(
            "{:>12} {:>10} {:>5} {:>9.0} {:>7.1} {:>11.1} {:>8} {:>11.1} {:>8}",
            step.triangles,
            step.unique_triangles,
            step.instances,
            step.build_ms,
            step.bytes_per_triangle,
            step.primary_ns_per_ray,
            ratio(step.primary_ns_per_ray, previous.map(|p| p.primary_ns_per_ray)),
            step.shadow_ns_per_ray,
            ratio(step.shadow_ns_per_ray, previous.map(|p| p.shadow_ns_per_ray)),
        );
        steps.push(step);
    }
    if let Some(path) = &args.json {
        let report = Report {
            width: args.res.0,
            height: args.res.1,
            vpls_per_pixel: args.k,
            threads,
            simd_backend: igi_simd::BACKEND,
            steps,
        };
        super::json_report::write_json(path, &report)?;
    }
    Ok(())
}
