//! `--cluster` and `igi worker`: the same binary on every MPI rank (paper section 4). Rank 0
//! runs the command it was given: render, view and serve with a [`igi_cluster::ClusterSource`]
//! as their frame source, bench cluster with the [`igi_cluster::Master`] itself; every other
//! rank becomes a render node.
//! Without the `mpi` feature the flags exist and say how to get a build that has them.

use crate::frame_args::FrameArgs;
use anyhow::Result;
use clap::Args;
use igi_cluster::protocol::PROTOCOL_VERSION;
use igi_cluster::{ClusterError, ClusterSource, Master, MasterConfig, Setup, Transport};
use igi_render::{FrameSource, PreparedScene};
use igi_scene::Scene;
use std::path::{Component, Path, PathBuf};

/// The cluster options of `render`, `view` and `serve`.
#[derive(Debug, Default, Args)]
pub struct ClusterArgs {
    /// Render on an MPI job: rank 0 runs this command, ranks 1..N render tiles (`mpirun -n N
    /// igi ... --cluster`, or `mpirun -n 1 igi ... --cluster : -n K igi worker`).
    #[arg(long)]
    pub cluster: bool,
    /// Send the scene's files from rank 0 to the nodes instead of each node reading them from
    /// the same path.
    #[arg(long, requires = "cluster")]
    pub broadcast_scene: bool,
}

/// This process's part in a cluster job.
pub enum Rank {
    /// Rank 0, connected to its render nodes, with the scene it loaded.
    Root(Box<Root>),
    /// A render node whose job has ended.
    NodeDone,
}

/// Rank 0 of a cluster job.
pub struct Root {
    /// The scene as rank 0 loaded it (for the camera, bounds and picking).
    pub scene: Scene,
    /// Rank 0's side of the job; `None` in a job of one rank, which renders by itself.
    pub master: Option<Master<Box<dyn Transport>>>,
}

/// Starts this process's part of a cluster job on `spec` (a built-in name or a scene file):
/// rank 0 loads it and waits until every node has loaded the same (by digest); any other rank
/// renders tiles with `threads` threads until rank 0 is done.
pub fn start(args: &ClusterArgs, spec: &str, frame: &FrameArgs) -> Result<Rank> {
    let threads = frame.threads;
    let transport = init()?;
    if transport.rank() != 0 {
        run_node(transport, threads);
        return Ok(Rank::NodeDone);
    }
    let (scene, report) =
        igi_scene::load_named_with_report(spec).unwrap_or_else(|e| fail(&format!("cannot load scene: {e}")));
    crate::scene_load::warn_if_no_geometry(spec, &scene);
    if transport.size() == 1 {
        tracing::warn!("the MPI job has one rank: rank 0 renders by itself");
        return Ok(Rank::Root(Box::new(Root { scene, master: None })));
    }
    let broadcast = args.broadcast_scene && !report.files.is_empty();
    let files = if broadcast { read_files(&report.files) } else { Vec::new() };
    let name = if broadcast { canonical(Path::new(spec)).display().to_string() } else { spec.to_string() };
    let setup = Setup {
        version: PROTOCOL_VERSION,
        scene: name,
        files,
        digest: scene.digest(),
        default_light: !frame.no_default_light,
        // The nodes judge the default light from the camera the user asked for, as rank 0 will;
        // options that leave fields to the start camera need the scene prepared to find it.
        view: frame
            .camera
            .asks()
            .then(|| frame.camera.requested(&PreparedScene::new(scene.clone())))
            .flatten(),
    };
    let master =
        Master::connect(transport, &setup, MasterConfig::default()).unwrap_or_else(|e| fail(&e.to_string()));
    Ok(Rank::Root(Box::new(Root { scene, master: Some(master) })))
}

/// `igi worker`: a render node of a split launch.
pub fn work(threads: usize) -> Result<()> {
    let transport = init()?;
    if transport.rank() == 0 {
        anyhow::bail!(
            "igi worker renders on ranks 1..N; rank 0 runs `igi render|view|serve SCENE --cluster` (mpirun -n 1 igi view SCENE --cluster : -n 3 igi worker)"
        );
    }
    run_node(transport, threads);
    Ok(())
}

/// A session's frame source: rank 0's nodes (a failure ends the whole job), or this
/// process's `threads` in a job of one rank.
pub fn source(master: Option<Master<Box<dyn Transport>>>, threads: usize) -> Box<dyn FrameSource> {
    match master {
        Some(master) => {
            Box::new(ClusterSource::new(master, Box::new(|e: &ClusterError| fail(&e.to_string()))))
        }
        None => Box::new(igi_render::FrameRenderer::new(threads)),
    }
}

#[cfg(feature = "mpi")]
fn init() -> Result<Box<dyn Transport>> {
    let transport =
        igi_cluster::MpiTransport::init().map_err(|e| anyhow::anyhow!("cannot start MPI: {e}"))?;
    Ok(Box::new(transport))
}

#[cfg(not(feature = "mpi"))]
fn init() -> Result<Box<dyn Transport>> {
    anyhow::bail!(
        "this igi was built without MPI: install Open MPI (apt-get install libopenmpi-dev openmpi-bin libclang-dev pkgconf) and build with `cargo build --release --features mpi`"
    )
}

/// Prints the error and ends every rank of the job with a non-zero status.
pub fn fail(message: &str) -> ! {
    crate::print_error(message);
    #[cfg(feature = "mpi")]
    igi_cluster::abort_job(1);
    #[cfg(not(feature = "mpi"))]
    std::process::exit(1)
}

fn run_node(mut transport: Box<dyn Transport>, threads: usize) {
    let rank = transport.rank();
    match igi_cluster::run_worker(&mut transport, threads, load_on_node) {
        Ok(summary) => tracing::info!("rank {rank}: {} frames, {} tiles", summary.frames, summary.tiles),
        Err(e) => fail(&format!("rank {rank}: {e}")),
    }
}

/// A node's scene: the files rank 0 sent, mirrored under a private directory, or else the
/// node's own files at the same path.
fn load_on_node(setup: &Setup) -> Result<Scene, String> {
    if setup.files.is_empty() {
        return igi_scene::load_named(&setup.scene).map_err(|e| e.to_string());
    }
    let root = std::env::temp_dir().join(format!("igi-scene-{}", std::process::id()));
    let mirror = |path: &Path| -> Result<PathBuf, String> {
        let mut out = root.clone();
        for c in path.components() {
            match c {
                Component::Normal(part) => out.push(part),
                Component::RootDir => {}
                _ => {
                    return Err(format!(
                        "rank 0 sent a path that is not absolute and plain: {}",
                        path.display()
                    ));
                }
            }
        }
        Ok(out)
    };
    let scene = (|| {
        for (path, bytes) in &setup.files {
            let target = mirror(path)?;
            if let Some(dir) = target.parent() {
                std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
            }
            std::fs::write(&target, bytes).map_err(|e| format!("{}: {e}", target.display()))?;
        }
        igi_scene::load_named(&mirror(Path::new(&setup.scene))?.display().to_string())
            .map_err(|e| e.to_string())
    })();
    let _ = std::fs::remove_dir_all(&root);
    scene
}

/// The files a load read, by absolute path, each once, with their bytes.
fn read_files(files: &[PathBuf]) -> Vec<(PathBuf, Vec<u8>)> {
    let mut seen = std::collections::BTreeSet::new();
    files
        .iter()
        .map(|f| canonical(f))
        .filter(|f| seen.insert(f.clone()))
        .map(|f| {
            let bytes = std::fs::read(&f).unwrap_or_else(|e| fail(&format!("{}: {e}", f.display())));
            (f, bytes)
        })
        .collect()
}

fn canonical(path: &Path) -> PathBuf {
    std::fs::canonicalize(path).unwrap_or_else(|e| fail(&format!("{}: {e}", path.display())))
}
