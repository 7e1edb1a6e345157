//! The cluster over real MPI (Open MPI, all ranks on this machine): the images of `mpirun -n 2`
//! and `-n 3` equal those of `-n 1` and of the local renderer byte for byte, for a still and an
//! animated scene over several frames, in the same-binary and the split launch; a render node
//! killed mid-frame ends the job with a non-zero status within 10 s; while a render node is
//! stopped (SIGSTOP) the other one renders every frame, and the stopped one takes part again
//! once continued (SIGCONT), or ends the job naming its rank if it stays stopped; rank 0's
//! transport receives from the others while a node is stopped halfway through a large message.
//!
//! Built with the `mpi` feature only (`cargo test -p igi --features mpi --test cluster_mpi`);
//! skips with a message where `mpirun` is missing.
#![cfg(feature = "mpi")]

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
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
        // One frame per image: a converging mean stops by its time budget too, which a
        // comparison of bytes cannot allow.
        "--frames",
        "1",
        // Several tiles per frame, so that every node gets some.
        "--tile-size",
        "64",
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
    app.extend(["--threads", "1", "--aa", "4", "--frames", "1", "--sequence", "10000", "--cluster"]);
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
        "--tile-size",
        "64",
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

/// A job started by `mpirun` (the test's child) with a render node it may have stopped. However
/// the test ends, the node is continued and the job ended, so no process is left behind.
struct Job {
    mpirun: Child,
    ranks: Vec<(u32, u32)>,
}

impl Job {
    /// Starts `app` under `mpirun`, stderr captured.
    fn start(app: &[&str], env: &[(&str, &str)]) -> Self {
        let mut cmd = mpirun(&[app]);
        cmd.envs(env.iter().copied()).stdout(Stdio::null()).stderr(Stdio::piped());
        Self { mpirun: cmd.spawn().unwrap(), ranks: Vec::new() }
    }

    /// Sends `signal` to the process of `rank`.
    fn signal(&mut self, rank: u32, signal: &str) {
        if self.ranks.is_empty() {
            self.ranks = ranks_of(self.mpirun.id());
        }
        let pid = self.ranks.iter().find(|&&(r, _)| r == rank).expect("the rank runs").1;
        assert!(Command::new("kill").args([signal, &pid.to_string()]).status().unwrap().success());
    }

    /// The job's status and stderr once it ends; panics if that takes longer than `limit`.
    fn wait(&mut self, limit: Duration) -> (std::process::ExitStatus, String) {
        let start = Instant::now();
        let status = loop {
            if let Some(status) = self.mpirun.try_wait().unwrap() {
                break status;
            }
            assert!(start.elapsed() < limit, "the job still runs after {limit:?}");
            std::thread::sleep(Duration::from_millis(50));
        };
        let mut stderr = String::new();
        std::io::Read::read_to_string(self.mpirun.stderr.as_mut().unwrap(), &mut stderr).unwrap();
        (status, stderr)
    }
}

impl Drop for Job {
    fn drop(&mut self) {
        if self.ranks.is_empty() {
            self.ranks = ranks_of(self.mpirun.id());
        }
        let kill = |signal: &str, pid: u32| {
            let _ = Command::new("kill").args([signal, &pid.to_string()]).stderr(Stdio::null()).status();
        };
        self.ranks.iter().for_each(|&(_, pid)| kill("-CONT", pid));
        if self.mpirun.try_wait().ok().flatten().is_none() {
            // mpirun ends its ranks on SIGTERM; whatever is left after 5 s is killed.
            kill("-TERM", self.mpirun.id());
            let start = Instant::now();
            while self.mpirun.try_wait().ok().flatten().is_none() && start.elapsed() < Duration::from_secs(5)
            {
                std::thread::sleep(Duration::from_millis(50));
            }
            self.ranks.iter().for_each(|&(_, pid)| kill("-KILL", pid));
            let _ = self.mpirun.kill();
            let _ = self.mpirun.wait();
        }
    }
}

/// Frames of a sequence written so far.
fn frames_written(d: &Path) -> usize {
    std::fs::read_dir(d)
        .unwrap()
        .flatten()
        .filter(|e| e.file_name().to_string_lossy().starts_with("seq-"))
        .count()
}

/// Waits until at least `frames` frames are written; false if `limit` passes first.
fn await_frames(d: &Path, frames: usize, limit: Duration) -> bool {
    let start = Instant::now();
    while frames_written(d) < frames {
        if start.elapsed() > limit {
            return false;
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    true
}

#[test]
fn a_stopped_node_is_worked_around_and_takes_part_again_once_continued() {
    if !have_mpirun() {
        return;
    }
    let d = dir("sigstop");
    let out = d.join("seq.png");
    let frames = 100;
    let count = frames.to_string();
    let extra = ["--sequence", count.as_str(), "--fps", "10"];
    let mut app = vec!["-n", "3"];
    app.extend(render_args("animated-room", out.to_str().unwrap(), &extra));
    app.push("--cluster");
    let mut job = Job::start(&app, &[("RUST_LOG", "warn,igi::cluster=info")]);
    assert!(await_frames(&d, 3, Duration::from_secs(120)), "no third frame");
    job.signal(2, "-STOP");
    let stopped = Instant::now();
    let at_stop = frames_written(&d);
    // A stalled job takes at least the tile deadline (1 s) per frame: ten frames in the 9 s
    // before the silence limit show that rank 1 renders rank 2's tiles without waiting.
    let kept_on = await_frames(&d, at_stop + 10, Duration::from_secs(9));
    let while_stopped = frames_written(&d) - at_stop;
    job.signal(2, "-CONT");
    assert!(
        kept_on,
        "{while_stopped} frames in {:.1} s while rank 2 was stopped",
        stopped.elapsed().as_secs_f64()
    );
    let at_cont = frames_written(&d);
    let (status, stderr) = job.wait(Duration::from_secs(300));
    assert!(status.success(), "the job failed: {status}\n{stderr}");
    assert!(stderr.contains("rank 2 has not answered"), "rank 0 says rank 2 is silent: {stderr}");
    assert!(stderr.contains("rank 2 answers again"), "rank 0 says rank 2 is back: {stderr}");
    // Rank 2 had at most 3 frames more than were written when it stopped; after it was
    // continued it took part in the frames begun from then on.
    let taken_part = stderr
        .lines()
        .find_map(|l| l.split("rank 2: ").nth(1)?.split(" frames").next()?.parse::<usize>().ok())
        .unwrap_or_else(|| panic!("rank 2's summary: {stderr}"));
    assert!(
        taken_part >= at_cont + 10,
        "rank 2 took part in {taken_part} frames, {at_cont} were written when it was continued"
    );

    let local = d.join("local.png");
    let mut cmd = Command::new(IGI);
    cmd.args(&render_args("animated-room", local.to_str().unwrap(), &extra)[1..]);
    run(cmd);
    for k in 0..frames {
        let name = |stem: &str| d.join(format!("{stem}-{k:04}.png"));
        assert!(bytes(&name("seq")) == bytes(&name("local")), "frame {k} differs from the local renderer's");
    }
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn a_node_stopped_for_good_ends_the_job_naming_its_rank_after_the_10_s_limit() {
    if !have_mpirun() {
        return;
    }
    let d = dir("sigstop-for-good");
    let out = d.join("seq.png");
    let mut app = vec!["-n", "3"];
    app.extend(render_args("animated-room", out.to_str().unwrap(), &["--sequence", "1000000", "--cluster"]));
    let mut job = Job::start(&app, &[]);
    assert!(await_frames(&d, 3, Duration::from_secs(120)), "no third frame");
    job.signal(1, "-STOP");
    let stopped = Instant::now();
    let at_stop = frames_written(&d);
    // The limit counts only time rank 0 listens, never more than the time since the stop.
    let (status, stderr) = job.wait(Duration::from_secs(40));
    let after = stopped.elapsed();
    assert!(!status.success(), "the job ended with success while a node was stopped");
    assert!(stderr.contains("rank 1 has not answered for"), "the message names the silent rank: {stderr}");
    assert!(after >= Duration::from_secs(9), "the job ended {after:?} after the stop, before the limit");
    let while_stopped = frames_written(&d) - at_stop;
    assert!(while_stopped >= 10, "only {while_stopped} frames while rank 1 was stopped");
    eprintln!("ended {:.2} s after the stop, {while_stopped} frames in between", after.as_secs_f64());
    let _ = std::fs::remove_dir_all(&d);
}

/// Set in the ranks of [`a_receive_never_waits_for_a_sender_stopped_halfway`], which run this
/// test executable under `mpirun`.
const TRANSPORT_RANK: &str = "IGI_TEST_TRANSPORT_RANK";

#[test]
fn a_receive_never_waits_for_a_sender_stopped_halfway() {
    if std::env::var_os(TRANSPORT_RANK).is_some() {
        return transport_rank();
    }
    if !have_mpirun() {
        return;
    }
    let exe = std::env::current_exe().unwrap();
    let app = [
        "-n",
        "3",
        "-x",
        TRANSPORT_RANK,
        exe.to_str().unwrap(),
        "a_receive_never_waits_for_a_sender_stopped_halfway",
        "--exact",
        "--nocapture",
        "--test-threads",
        "1",
    ];
    let mut job = Job::start(&app, &[(TRANSPORT_RANK, "1")]);
    let (status, stderr) = job.wait(Duration::from_secs(60));
    assert!(status.success(), "{status}\n{stderr}");
}

/// One rank of the test above. Rank 2 sends its pid, then a message of 1 MiB, beyond the eager
/// limit: its header goes out at once, its data only while rank 2 runs. Rank 2 stops itself
/// before it calls MPI again. Rank 0 must go on receiving (rank 1's message) and gets the large
/// message whole once rank 2 is continued; a blocking receive (`MPI_Mrecv`) waited for good.
fn transport_rank() {
    use igi_cluster::Transport;
    let mut t = igi_cluster::MpiTransport::init().unwrap();
    let large: Vec<u8> = (0..1 << 20).map(|i| (i % 251) as u8).collect();
    let next = |t: &mut igi_cluster::MpiTransport| {
        let start = Instant::now();
        loop {
            if let Some(message) = t.recv(Duration::from_millis(100)).unwrap() {
                break message;
            }
            assert!(start.elapsed() < Duration::from_secs(30), "rank {}: no message", t.rank());
        }
    };
    match t.rank() {
        0 => {
            let (from, pid) = next(&mut t);
            assert_eq!(from, 2);
            let pid = u32::from_le_bytes(pid.try_into().unwrap()).to_string();
            let stopped = || {
                let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).unwrap();
                stat.rsplit(')').next().unwrap().split_whitespace().next() == Some("T")
            };
            let start = Instant::now();
            while !stopped() {
                assert!(start.elapsed() < Duration::from_secs(30), "rank 2 does not stop");
                std::thread::sleep(Duration::from_millis(10));
            }
            assert_eq!(
                t.recv(Duration::from_millis(200)).unwrap(),
                None,
                "rank 2's large message came whole"
            );
            t.send(1, b"go").unwrap();
            assert_eq!(next(&mut t), (1, b"alive".to_vec()), "rank 1's message while rank 2 is stopped");
            assert!(Command::new("kill").args(["-CONT", &pid]).status().unwrap().success());
            let (from, bytes) = next(&mut t);
            assert!(from == 2 && bytes == large, "rank 2's large message, whole, once continued");
        }
        1 => {
            assert_eq!(next(&mut t), (0, b"go".to_vec()));
            t.send(0, b"alive").unwrap();
        }
        _ => {
            let pid = std::process::id();
            t.send(0, &pid.to_le_bytes()).unwrap();
            t.send(0, &large).unwrap();
            assert!(Command::new("kill").args(["-STOP", &pid.to_string()]).status().unwrap().success());
        }
    }
}
