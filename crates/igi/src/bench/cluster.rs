//! `igi bench cluster`: the cluster's frame rate as the render nodes grow from 1 to all of
//! them, run under MPI (`mpirun -n N+1 igi bench cluster SCENE`). For each node count: frames
//! per second, rank 0's time waiting for tiles and its own work per frame, the bytes that
//! travel per frame against the raw 8-bit image, the tiles each rank rendered, and the scaling
//! efficiency; then a model that projects larger clusters from these measurements. The nodes
//! send what a viewer asks for (`--pixels`): 8-bit pixels while the view moves, or linear
//! radiance with its diffuse layer with temporal reuse.

use super::frame::ANIMATION_FPS;
use crate::cluster::{ClusterArgs, Rank};
use crate::frame_args::FrameArgs;
use anyhow::{Context, Result, bail};
use clap::{Args, ValueEnum};
use igi_cluster::FrameJob;
use igi_render::{PixelFormat, Progressive};
use serde::Serialize;
use std::path::PathBuf;
use std::time::{Duration, Instant};

/// Arguments of `igi bench cluster`.
#[derive(Debug, Args)]
pub struct ClusterBenchArgs {
    /// The scene and the frames timed, per node count.
    #[command(flatten)]
    pub timed: super::TimedFrames,
    /// Play the scene's animation (every node poses the scene each frame).
    #[arg(long)]
    pub animate: bool,
    /// Send the scene's files from rank 0 instead of loading them on every node.
    #[arg(long)]
    pub broadcast_scene: bool,
    /// The pixels the nodes send.
    #[arg(long, value_enum, default_value_t = WirePixels::Srgb8)]
    pub pixels: WirePixels,
    /// Write the results as JSON.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Frame options (`--threads` is per rank).
    #[command(flatten)]
    pub frame: FrameArgs,
}

/// The pixels a viewer asks its nodes for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum WirePixels {
    /// Tone-mapped 8-bit pixels: a viewer without temporal reuse while the view moves.
    Srgb8,
    /// Linear radiance: a still view's mean.
    Linear,
    /// Linear radiance and its diffuse layer: a viewer with temporal reuse.
    Layered,
}

impl WirePixels {
    fn format(self) -> PixelFormat {
        match self {
            Self::Srgb8 => PixelFormat::Srgb8,
            Self::Linear => PixelFormat::Linear,
            Self::Layered => PixelFormat::Layered,
        }
    }
}

/// One node count's measurements.
#[derive(Debug, Serialize)]
struct Step {
    nodes: usize,
    fps: f64,
    frame_ms: f64,
    /// Rank 0's time in `finish`, waiting for the last tile, per frame.
    wait_ms: f64,
    /// Rank 0's own work per frame (message handling and assembly).
    rank0_busy_ms: f64,
    /// Bytes rank 0 received per frame (tiles, heartbeats).
    bytes_in: f64,
    /// Bytes rank 0 sent per frame (frame jobs, tile numbers).
    bytes_out: f64,
    /// Tiles per frame each rank rendered (rank 1 first).
    tiles_per_rank: Vec<f64>,
    /// fps / (nodes × fps of one node).
    efficiency: f64,
}

/// The projection of one cluster size and link speed.
#[derive(Debug, Serialize)]
struct Projection {
    nodes: usize,
    gbit_per_s: f64,
    fps: f64,
    limit: &'static str,
}

#[derive(Debug, Serialize)]
struct Report {
    scene: String,
    width: u32,
    height: u32,
    threads_per_rank: usize,
    aa: u32,
    frames: u32,
    animate: bool,
    pixels: WirePixels,
    raw_8bit_bytes: u64,
    steps: Vec<Step>,
    model: Vec<Projection>,
}

/// Runs `igi bench cluster` (on rank 0; the other ranks render).
pub fn run(args: &ClusterBenchArgs) -> Result<()> {
    if !(1..=100_000).contains(&args.timed.frames) {
        bail!("--frames must be between 1 and 100000");
    }
    if args.timed.warmup == 0 {
        bail!("--warmup must be at least 1: the end of the warm-up starts the clock");
    }
    let cluster = ClusterArgs { cluster: true, broadcast_scene: args.broadcast_scene };
    let root = match crate::cluster::start(&cluster, &args.timed.scene, &args.frame)? {
        Rank::Root(root) => root,
        Rank::NodeDone => return Ok(()),
    };
    // Only rank 0 writes the report.
    super::json_report::check_json(args.json.as_deref())?;
    let mut state = args.frame.frame_state(&args.frame.prepare(root.scene))?;
    let Some(mut master) = root.master else {
        bail!(
            "igi bench cluster needs rank 0 and at least one render node: mpirun -n 3 igi bench cluster SCENE"
        );
    };
    let s = state.settings;
    let raw = 3 * u64::from(s.width) * u64::from(s.height);
    let threads = master.threads() / master.nodes().max(1);

    let mut steps: Vec<Step> = Vec::new();
    for nodes in node_counts(master.nodes()) {
        master.use_nodes(nodes);
        let mut view = Progressive::new(state.settings.tone_map());
        let job = |i: u32, state: &igi_render::FrameState| {
            let mut frame = state.clone();
            frame.pose.time =
                if args.animate { args.frame.time + i as f32 / ANIMATION_FPS } else { args.frame.time };
            frame.pixels = args.pixels.format();
            FrameJob { id: 0, frame }
        };
        // Pipelined as a viewer runs: the next frame starts as soon as the last tile of this
        // one is in, with the tone map of this one's statistics (paper 3.4).
        state.tone_map = view.tone_mapper();
        master.begin(job(0, &state))?;
        let total = args.timed.warmup + args.timed.frames;
        let (mut wait, mut busy, mut bytes_in, mut bytes_out) = (Duration::ZERO, Duration::ZERO, 0u64, 0u64);
        let mut tiles = vec![0u64; master.nodes()];
        let mut timed_from = Instant::now();
        for i in 0..total {
            let out = master.finish().with_context(|| format!("frame {i} with {nodes} node(s)"))?;
            view.add(out.output.image, out.output.stats);
            view.show();
            if i + 1 < total {
                state.tone_map = view.tone_mapper();
                master.begin(job(i + 1, &state))?;
            }
            if i + 1 == args.timed.warmup {
                timed_from = Instant::now();
            }
            if i >= args.timed.warmup {
                wait += out.wait;
                busy += out.busy;
                bytes_in += out.bytes_in;
                bytes_out += out.bytes_out;
                tiles.iter_mut().zip(&out.tiles_per_node).for_each(|(t, &n)| *t += u64::from(n));
            }
        }
        let elapsed = timed_from.elapsed().as_secs_f64();
        let n = f64::from(args.timed.frames);
        let fps = n / elapsed.max(1e-12);
        let one = steps.first().map_or(fps, |s| s.fps);
        steps.push(Step {
            nodes,
            fps,
            frame_ms: 1e3 * elapsed / n,
            wait_ms: wait.as_secs_f64() * 1e3 / n,
            rank0_busy_ms: busy.as_secs_f64() * 1e3 / n,
            bytes_in: bytes_in as f64 / n,
            bytes_out: bytes_out as f64 / n,
            tiles_per_rank: tiles.iter().map(|&t| t as f64 / n).collect(),
            efficiency: fps / (nodes as f64 * one),
        });
    }
    let model = project(steps.last().context("no node count measured")?);
    let report = Report {
        scene: args.timed.scene.clone(),
        width: s.width,
        height: s.height,
        threads_per_rank: threads,
        aa: s.aa,
        frames: args.timed.frames,
        animate: args.animate,
        pixels: args.pixels,
        raw_8bit_bytes: raw,
        steps,
        model,
    };
    print_report(&report);
    if let Some(path) = &args.json {
        super::json_report::write_json(path, &report)?;
    }
    Ok(())
}

/// 1, 2, 4, … up to `max`, and `max` itself.
fn node_counts(max: usize) -> Vec<usize> {
    let mut counts: Vec<usize> =
        std::iter::successors(Some(1usize), |n| Some(n * 2)).take_while(|&n| n < max).collect();
    counts.push(max);
    counts
}

/// Frame rates of larger clusters from the measurements with the most nodes: each node adds
/// its measured share of the frame rate, the link into rank 0 carries the measured bytes per
/// frame, and rank 0 spends its measured own time per frame; the smallest of the three rates
/// wins (the paper's nodes scale until rank 0 or its link saturates, section 4).
fn project(step: &Step) -> Vec<Projection> {
    let per_node = step.fps / step.nodes as f64;
    let mut out = Vec::new();
    for nodes in [8, 24, 48] {
        for gbit in [1.0, 10.0] {
            let limits = [
                (nodes as f64 * per_node, "render nodes"),
                (gbit * 1e9 / 8.0 / step.bytes_in.max(1.0), "rank 0's link"),
                (1e3 / step.rank0_busy_ms.max(1e-6), "rank 0's CPU"),
            ];
            let (fps, limit) =
                limits.into_iter().fold((f64::INFINITY, ""), |a, b| if b.0 < a.0 { b } else { a });
            out.push(Projection { nodes, gbit_per_s: gbit, fps, limit });
        }
    }
    out
}

fn print_report(r: &Report) {
    outln!(
        "{}: {}x{}, aa {}, {} thread(s) per rank, {} frames per node count{}, {:?} pixels; raw 8-bit image {} bytes",
        r.scene,
        r.width,
        r.height,
        r.aa,
        r.threads_per_rank,
        r.frames,
        if r.animate { ", animated" } else { "" },
        r.pixels,
        r.raw_8bit_bytes
    );
    for s in &r.steps {
        let tiles: Vec<String> = s.tiles_per_rank.iter().map(|t| format!("{t:.1}")).collect();
        outln!(
            "  {} node(s): {:.2} fps ({:.1} ms/frame), efficiency {:.0} %, rank 0 waits {:.1} ms and works {:.2} ms per frame, {:.0} bytes in ({:.3}x the raw image) + {:.0} out per frame, tiles per rank [{}]",
            s.nodes,
            s.fps,
            s.frame_ms,
            100.0 * s.efficiency,
            s.wait_ms,
            s.rank0_busy_ms,
            s.bytes_in,
            s.bytes_in / r.raw_8bit_bytes as f64,
            s.bytes_out,
            tiles.join(", ")
        );
    }
    outln!("  model (nodes like these ranks):");
    for p in &r.model {
        outln!(
            "    {:>2} nodes, {:>4} Gbit/s: {:>7.1} fps, limited by {}",
            p.nodes,
            p.gbit_per_s,
            p.fps,
            p.limit
        );
    }
}
