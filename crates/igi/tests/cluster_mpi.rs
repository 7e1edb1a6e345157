//! The cluster over real MPI (Open MPI, all ranks on this machine): the images of `mpirun -n 2`
//! and `-n 3` equal those of `-n 1` and of the local renderer byte for byte, for a still and an
//! animated scene over several frames, in the same-binary and the split launch; a render node
//! killed mid-frame ends the job with a non-zero status within 10 s.
//!
//! Built with the `mpi` feature only (`cargo test -p igi --features mpi --test cluster_mpi`);
//! skips with a message where `mpirun` is missing.
#![cfg(feature = "mpi")]

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

const IGI: &str = env!("CARGO_BIN_EXE_igi");

/// `mpirun` with the settings of a single machine: shared-memory transport, more ranks than
/// cores, and permission to run as root (CI runs as root).
fn mpirun(ranks: &[&[&str]]) -> Command {
    let mut cmd = Command::new("mpirun");
    cmd.env("OMPI_MCA_btl", "self,vader")
        .env("OMPI_MCA_btl_vader_single_copy_mechanism", "none")
        .env("OMPI_ALLOW_RUN_AS_ROOT", "1")
        .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
        .env("OMPI_MCA_rmaps_base_oversubscribe", "1")
        .arg("--oversubscribe");
    for (i, app) in ranks.iter().enumerate() {
        if i > 0 {
            cmd.arg(":");
        }
        cmd.args(*app);
    }
    cmd
}

fn have_mpirun() -> bool {
    let found = Command::new("mpirun").arg("--version").output().is_ok_and(|o| o.status.success());
    if !found {
        eprintln!("skipped: no mpirun (Debian: apt-get install -y openmpi-bin libopenmpi-dev)");
    }
    found
}

fn run(mut cmd: Command) -> Output {
    let out = cmd.output().expect("the command starts");
    assert!(out.status.success(), "{cmd:?} failed: {}\n{}", out.status, String::from_utf8_lossy(&out.stderr));
    out
}

fn dir(test: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("igi-cluster-{test}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn bytes(path: &Path) -> Vec<u8> {
    std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The render options of a test frame: small, one thread per rank.
fn render_args<'a>(scene: &'a str, out: &'a str, extra: &[&'a str]) -> Vec<&'a str> {
    let mut args = vec![
        IGI,
        "render",
        scene,
        "-o",
        out,
        "--width",
        "128",
        "--height",
        "96",
        "--aa",
        "1",
        "--threads",
        "1",
    ];
    args.extend_from_slice(extra);
    args
}

fn same_images(scene: &str, extra: &[&str], frames: u32, test: &str) {
    let d = dir(test);
    let local = d.join("local.png");
    let local_s = local.to_str().unwrap();
    let mut cmd = Command::new(IGI);
    cmd.args(&render_args(scene, local_s, extra)[1..]);
    run(cmd);
    let names = |base: &Path| -> Vec<PathBuf> {
        if frames == 1 {
            vec![base.to_path_buf()]
        } else {
            let stem = base.file_stem().unwrap().to_string_lossy().into_owned();
            (0..frames).map(|k| base.with_file_name(format!("{stem}-{k:04}.png"))).collect()
        }
    };
    let expected: Vec<Vec<u8>> = names(&local).iter().map(|p| bytes(p)).collect();
    for n in ["1", "2", "3"] {
        let out = d.join(format!("n{n}.png"));
        let out_s = out.to_str().unwrap();
        let mut args = render_args(scene, out_s, extra);
        args.push("--cluster");
        let mut app = vec!["-n", n];
        app.extend(args);
        run(mpirun(&[&app]));
        for (k, (p, want)) in names(&out).iter().zip(&expected).enumerate() {
            assert!(
                bytes(p) == *want,
                "{scene}: frame {k} of mpirun -n {n} differs from the local renderer's"
            );
        }
    }
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn a_still_frame_is_the_same_on_one_two_and_three_ranks_as_locally() {
    if have_mpirun() {
        same_images("cornell-box", &[], 1, "still");
    }
}

#[test]
fn an_animation_is_the_same_frame_by_frame_on_one_two_and_three_ranks() {
    if have_mpirun() {
        same_images("animated-room", &["--sequence", "3", "--fps", "4"], 3, "animated");
    }
}

#[test]
fn the_split_launch_with_igi_worker_and_a_broadcast_scene_gives_the_same_image() {
    if !have_mpirun() {
        return;
    }
    let d = dir("split");
    // A scene file only rank 0 reads: the nodes get its bytes and check them by digest.
    let obj = d.join("box.obj");
    std::fs::write(
        &obj,
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n\
         f 1 2 3 4\nf 5 8 7 6\nf 1 5 6 2\nf 2 6 7 3\nf 3 7 8 4\nf 5 1 4 8\n",
    )
    .unwrap();
    let scene = obj.to_str().unwrap();
    let local = d.join("local.exr");
    let status =
        Command::new(IGI).args(&render_args(scene, local.to_str().unwrap(), &[])[1..]).status().unwrap();
    assert!(status.success());
    let out = d.join("split.exr");
    let mut root = vec!["-n", "1"];
    root.extend(render_args(scene, out.to_str().unwrap(), &["--cluster", "--broadcast-scene"]));
    run(mpirun(&[&root, &["-n", "2", IGI, "worker", "--threads", "1"]]));
    assert!(bytes(&out) == bytes(&local), "the split launch's EXR differs from the local one");
    let _ = std::fs::remove_dir_all(&d);
}

/// The ranks of a running job: (rank, pid) of every process whose environment says it is
/// rank `OMPI_COMM_WORLD_RANK` of a job started by `mpirun` with pid `launcher`.
fn ranks_of(launcher: u32) -> Vec<(u32, u32)> {
    let mut found = Vec::new();
    let Ok(entries) = std::fs::read_dir("/proc") else { return found };
    for entry in entries.flatten() {
        let Some(pid) = entry.file_name().to_str().and_then(|s| s.parse::<u32>().ok()) else { continue };
        let Ok(stat) = std::fs::read_to_string(entry.path().join("stat")) else { continue };
        let ppid = stat
            .rsplit(')')
            .next()
            .and_then(|rest| rest.split_whitespace().nth(1))
            .and_then(|p| p.parse::<u32>().ok());
        if ppid != Some(launcher) {
            continue;
        }
        let Ok(environ) = std::fs::read(entry.path().join("environ")) else { continue };
        let rank = environ
            .split(|&b| b == 0)
            .filter_map(|kv| std::str::from_utf8(kv).ok())
            .find_map(|kv| kv.strip_prefix("OMPI_COMM_WORLD_RANK="))
            .and_then(|r| r.parse::<u32>().ok());
        if let Some(rank) = rank {
            found.push((rank, pid));
        }
    }
    found
}

#[test]
fn killing_a_node_mid_frame_ends_the_job_within_10_s() {
    if !have_mpirun() {
        return;
    }
    let d = dir("kill");
    let out = d.join("frame.png");
    // Frames long enough to be killed in the middle of: 640x480, 4 samples, many of them.
    let mut app = vec!["-n", "3", IGI, "render", "animated-room", "-o", out.to_str().unwrap()];
    app.extend(["--threads", "1", "--aa", "4", "--sequence", "10000", "--cluster"]);
    let mut child = mpirun(&[&app]).stdout(Stdio::null()).stderr(Stdio::piped()).spawn().unwrap();
    let first = d.join("frame-0000.png");
    let start = Instant::now();
    while !first.exists() {
        assert!(start.elapsed() < Duration::from_secs(120), "no first frame");
        std::thread::sleep(Duration::from_millis(50));
    }
    let node = ranks_of(child.id()).into_iter().find(|&(rank, _)| rank == 1).expect("rank 1 runs").1;
    let killed = Instant::now();
    assert!(Command::new("kill").args(["-KILL", &node.to_string()]).status().unwrap().success());
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        assert!(killed.elapsed() < Duration::from_secs(10), "the job still runs 10 s after a node died");
        std::thread::sleep(Duration::from_millis(50));
    };
    let mut stderr = String::new();
    std::io::Read::read_to_string(child.stderr.as_mut().unwrap(), &mut stderr).unwrap();
    assert!(!status.success(), "the job ended with success after a node died");
    assert!(stderr.contains("rank 1"), "the message names the dead rank: {stderr}");
    eprintln!("ended {:.2} s after the kill with {status}", killed.elapsed().as_secs_f64());
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn the_cluster_benchmark_scales_over_the_nodes_and_only_8_bit_pixels_travel() {
    if !have_mpirun() {
        return;
    }
    let d = dir("bench");
    let json = d.join("bench.json");
    let app = [
        "-n",
        "3",
        IGI,
        "bench",
        "cluster",
        "cornell-box",
        "--frames",
        "3",
        "--warmup",
        "1",
        "--width",
        "160",
        "--height",
        "120",
        "--aa",
        "1",
        "--threads",
        "1",
        "--json",
        json.to_str().unwrap(),
    ];
    run(mpirun(&[&app]));
    let report: serde_json::Value = serde_json::from_slice(&bytes(&json)).unwrap();
    let raw = report["raw_8bit_bytes"].as_f64().unwrap();
    assert_eq!(raw, 3.0 * 160.0 * 120.0);
    let steps = report["steps"].as_array().unwrap();
    let nodes: Vec<u64> = steps.iter().map(|s| s["nodes"].as_u64().unwrap()).collect();
    assert_eq!(nodes, [1, 2]);
    for s in steps {
        // 6 tiles of 64² or less: the pixels, their statistics and the message framing.
        let ratio = s["bytes_in"].as_f64().unwrap() / raw;
        assert!((1.0..1.1).contains(&ratio), "{} node(s): {ratio:.3}x the raw 8-bit image", s["nodes"]);
        let tiles: f64 = s["tiles_per_rank"].as_array().unwrap().iter().map(|t| t.as_f64().unwrap()).sum();
        assert_eq!(tiles, 6.0);
        assert!(s["fps"].as_f64().unwrap() > 0.0);
    }
    assert_eq!(report["model"].as_array().unwrap().len(), 6);
    let _ = std::fs::remove_dir_all(&d);
}
