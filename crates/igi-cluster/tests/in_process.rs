//! The cluster protocol and scheduling over the in-process transport: render nodes on
//! threads give bit for bit the frames of the local renderer, late tiles are copied to other
//! nodes, a node that stops answering has its tiles rendered by the others until it answers
//! again, and a node silent past the limit or a node with other files ends the job with its
//! rank named.

use igi_cluster::protocol::{Message, Ready};
use igi_cluster::transport::TransportError;
use igi_cluster::{ClusterError, FrameJob, InProcess, Master, MasterConfig, Setup, Transport, WorkerSummary};
use igi_render::{
    Estimator, FrameRenderer, FrameSettings, FrameState, PixelFormat, PreparedScene, ScenePose, ToneMap,
    ToneMapper, start_camera,
};
use std::sync::{Arc, Condvar, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

fn load(name: &str) -> igi_scene::Scene {
    igi_scene::load_named(name).expect("built-in scene")
}

fn setup(name: &str) -> Setup {
    Setup {
        version: igi_cluster::protocol::PROTOCOL_VERSION,
        scene: name.into(),
        files: vec![],
        digest: load(name).digest(),
        default_light: true,
        view: None,
    }
}

/// A render node's thread.
type Node = JoinHandle<Result<WorkerSummary, ClusterError>>;

/// Starts `nodes` render nodes with one thread each; returns rank 0's transport.
fn start(nodes: usize) -> (InProcess, Vec<Node>) {
    let mut ranks = igi_cluster::in_process(nodes + 1).into_iter();
    let root = ranks.next().unwrap();
    let handles = ranks
        .map(|mut t| {
            std::thread::spawn(move || {
                igi_cluster::run_worker(&mut t, 1, |s| {
                    igi_scene::load_named(&s.scene).map_err(|e| e.to_string())
                })
            })
        })
        .collect();
    (root, handles)
}

fn first_frame(scene: &PreparedScene) -> FrameState {
    let settings = FrameSettings {
        width: 96,
        height: 72,
        tile_size: 16,
        aa: 1,
        seed: 3,
        ..FrameSettings::for_scene(scene.bounds().diagonal())
    };
    let camera = start_camera(scene);
    FrameState {
        tone_map: ToneMapper::new(ToneMap::default(), &Default::default()),
        ..FrameState::new(camera, settings)
    }
}

/// `state` at scene time `time`, delivered as `pixels`.
fn at(state: &FrameState, time: f32, pixels: PixelFormat) -> FrameState {
    FrameState { pose: ScenePose::at(time), pixels, ..state.clone() }
}

fn job(state: &FrameState, time: f32, pixels: PixelFormat) -> FrameJob {
    FrameJob { id: 0, frame: at(state, time, pixels) }
}

/// A sequence of frames of an animated scene, each tone-mapped with the previous frame's
/// statistics (paper 3.4), from the cluster and from the local renderer: the same bytes.
fn sequence_matches_local(name: &str, nodes: usize, times: &[f32]) {
    let mut local_scene = PreparedScene::new(load(name));
    let renderer = FrameRenderer::new(2);
    let (root, handles) = start(nodes);
    let mut master = Master::connect(root, &setup(name), MasterConfig::default()).unwrap();
    let mut state = first_frame(&local_scene);
    for &t in times {
        let local =
            renderer.render(&mut local_scene, &at(&state, t, PixelFormat::Linear), &|_, _| {}).unwrap();
        let remote = master.render(job(&state, t, PixelFormat::Srgb8)).unwrap();
        let tiles_per_node = remote.tiles_per_node;
        let remote = remote.output;
        assert!(remote.image.film().is_none(), "an 8-bit frame carries no film");
        assert!(remote.image.srgb8() == local.image.srgb8(), "{name} at t = {t}: 8-bit images differ");
        assert_eq!(remote.stats, local.stats, "{name} at t = {t}: statistics differ");
        // A render node traces its tiles' aprons for the filter, which the local renderer's two
        // passes do not (ARCHITECTURE.md, "A frame in two passes"): more rays, the same image.
        assert!(remote.rays.primary > local.rays.primary, "{name} at t = {t}: {:?}", remote.rays);
        assert_eq!(tiles_per_node.iter().sum::<u32>(), 30);
        let linear = master.render(job(&state, t, PixelFormat::Linear)).unwrap().output;
        assert!(
            linear.image.film().unwrap().pixels() == local.image.film().unwrap().pixels(),
            "{name} at t = {t}: films differ"
        );
        state.tone_map = ToneMapper::new(ToneMap::default(), &remote.stats);
    }
    drop(master);
    handles.into_iter().for_each(|h| assert!(h.join().unwrap().is_ok(), "nodes end cleanly"));
}

#[test]
fn a_still_scene_equals_the_local_renderer_bit_for_bit() {
    sequence_matches_local("cornell-box", 2, &[0.0, 0.0]);
}

#[test]
fn an_animated_scene_equals_the_local_renderer_frame_by_frame() {
    sequence_matches_local("animated-room", 3, &[0.0, 0.4, 1.3]);
}

#[test]
fn the_nodes_run_the_frame_s_estimator_the_path_tracer_too() {
    // The estimator is part of the frame: a path-traced frame from the cluster is the local
    // path tracer's, bit for bit, and not instant radiosity's image.
    let mut local_scene = PreparedScene::new(load("cornell-box"));
    let state = first_frame(&local_scene);
    let traced = FrameState { estimator: Estimator::PathTracer { spp: 2 }, ..state.clone() };
    let local = FrameRenderer::new(2).render(&mut local_scene, &traced, &|_, _| {}).unwrap();
    let (root, handles) = start(2);
    let mut master = Master::connect(root, &setup("cornell-box"), MasterConfig::default()).unwrap();
    let remote = master.render(FrameJob { id: 0, frame: traced }).unwrap().output;
    let igi = master.render(FrameJob { id: 1, frame: state }).unwrap().output;
    let film = |o: &igi_render::FrameOutput| o.image.film().unwrap().pixels().to_vec();
    assert!(film(&remote) == film(&local), "the cluster's path-traced film differs from the local one");
    assert_eq!((remote.rays, remote.vpls), (local.rays, 0));
    assert!(film(&igi) != film(&remote), "the IGI frame must not be the path tracer's");
    drop(master);
    handles.into_iter().for_each(|h| assert!(h.join().unwrap().is_ok(), "nodes end cleanly"));
}

#[test]
fn the_frame_is_independent_of_the_number_of_nodes() {
    let scene = PreparedScene::new(load("cornell-box"));
    let state = first_frame(&scene);
    let mut images = Vec::new();
    for nodes in [1, 3] {
        let (root, handles) = start(nodes);
        let mut master = Master::connect(root, &setup("cornell-box"), MasterConfig::default()).unwrap();
        let frame = master.render(job(&state, 0.0, PixelFormat::Srgb8)).unwrap();
        assert_eq!(frame.tiles_per_node.len(), nodes);
        images.push(frame.output.image.srgb8().to_vec());
        drop(master);
        handles.into_iter().for_each(|h| assert!(h.join().unwrap().is_ok()));
    }
    assert!(images[0] == images[1]);
}

/// A fake node that loads nothing, answers the setup with `ready`, and then only sends
/// heartbeats and its bye (`beat`) or nothing at all: it holds its tiles forever.
fn stalled_node(mut t: InProcess, ready: Ready, beat: bool) -> JoinHandle<()> {
    std::thread::spawn(move || {
        t.send(0, &Message::Ready(ready).encode()).unwrap();
        loop {
            match t.recv(Duration::from_millis(100)) {
                Ok(Some((_, bytes))) if Message::decode(&bytes).unwrap() == Message::Shutdown => {
                    if beat {
                        t.send(0, &Message::Bye.encode()).unwrap();
                    }
                    return;
                }
                Ok(_) if beat => t.send(0, &Message::Heartbeat.encode()).unwrap(),
                Ok(_) => {}
                Err(_) => return,
            }
        }
    })
}

#[test]
fn tiles_a_stalled_node_holds_are_copied_to_another_after_the_deadline() {
    let name = "cornell-box";
    let mut scene = PreparedScene::new(load(name));
    let state = first_frame(&scene);
    let local = FrameRenderer::new(1).render(&mut scene, &state, &|_, _| {}).unwrap();
    let mut ranks = igi_cluster::in_process(3).into_iter();
    let root = ranks.next().unwrap();
    let mut good = ranks.next().unwrap();
    let worker = std::thread::spawn(move || {
        igi_cluster::run_worker(&mut good, 1, |s| igi_scene::load_named(&s.scene).map_err(|e| e.to_string()))
            .unwrap()
    });
    let ready = Ready::Loaded { digest: load(name).digest(), threads: 1 };
    let stalled = stalled_node(ranks.next().unwrap(), ready, true);
    let config = MasterConfig { min_deadline: Duration::from_millis(200), ..MasterConfig::default() };
    let mut master = Master::connect(root, &setup(name), config).unwrap();
    let frame = master.render(job(&state, 0.0, PixelFormat::Srgb8)).unwrap();
    assert!(frame.output.image.srgb8() == local.image.srgb8());
    assert_eq!(frame.tiles_per_node, vec![30, 0], "the stalled node returned nothing");
    drop(master);
    assert_eq!(worker.join().unwrap().tiles, 30);
    stalled.join().unwrap();
}

#[test]
fn a_silent_node_ends_the_job_naming_its_rank() {
    let name = "cornell-box";
    let scene = PreparedScene::new(load(name));
    let state = first_frame(&scene);
    let mut ranks = igi_cluster::in_process(2).into_iter();
    let root = ranks.next().unwrap();
    let ready = Ready::Loaded { digest: load(name).digest(), threads: 1 };
    let dead = stalled_node(ranks.next().unwrap(), ready, false);
    let config = MasterConfig {
        suspect_after: Duration::from_millis(100),
        silence_limit: Duration::from_millis(300),
        ..MasterConfig::default()
    };
    let mut master = Master::connect(root, &setup(name), config).unwrap();
    let start = Instant::now();
    let err = master.render(job(&state, 0.0, PixelFormat::Srgb8)).unwrap_err();
    assert!(matches!(err, ClusterError::NodeLost { rank: 1, .. }), "{err}");
    assert!(err.to_string().contains("rank 1"), "{err}");
    assert!(start.elapsed() < Duration::from_secs(5));
    drop(master);
    dead.join().unwrap();
}

#[test]
fn the_job_carries_on_while_a_node_is_silent_and_ends_naming_it_once_silent_past_the_limit() {
    let limit = Duration::from_secs(3);
    let (mut master, nodes, switches, mut animation) = two_stoppable_nodes(limit);
    // Frames of two small tiles, over in far less time than rank 0 takes between two looks
    // for silent nodes: the silence is still found.
    animation.state.settings.width = 32;
    animation.state.settings.height = 8;
    animation.state.settings.tile_size = 16;
    animation.frame(&mut master).unwrap();
    switches[1].stop();
    let stopped = Instant::now();
    let mut frames_while_silent = 0;
    let err = loop {
        match animation.frame(&mut master) {
            Ok(tiles) => {
                assert_eq!(tiles[1], 0);
                frames_while_silent += 1;
            }
            Err(e) => break e,
        }
        assert!(stopped.elapsed() < Duration::from_secs(60), "rank 2 silent for a minute, the job goes on");
    };
    assert!(frames_while_silent > 0, "no frame was finished while rank 2 was silent");
    let ClusterError::NodeLost { rank, silent } = err else { panic!("{err}") };
    assert_eq!(rank, 2, "{err}");
    // Rank 0 looks every 10 ms while it listens, short frames or not.
    assert!(silent > limit && silent < limit + Duration::from_secs(1), "{err}");
    assert!(err.to_string().contains("rank 2"), "{err}");
    drop(master);
    switches[1].resume();
    nodes.into_iter().for_each(|n| drop(n.join().unwrap()));
}

#[test]
fn a_node_with_another_scene_is_refused_by_digest() {
    let (root, handles) = start(2);
    let mut wrong = setup("cornell-box");
    wrong.digest ^= 1;
    let err = Master::connect(root, &wrong, MasterConfig::default()).unwrap_err();
    assert!(matches!(err, ClusterError::SceneMismatch { .. }), "{err}");
    assert!(err.to_string().contains("different scene"), "{err}");
    // Rank 0 is gone: the nodes end (a node still loading finds no one to answer).
    handles.into_iter().for_each(|h| drop(h.join().unwrap()));
}

#[test]
fn a_node_that_cannot_load_the_scene_says_why() {
    let mut ranks = igi_cluster::in_process(2).into_iter();
    let root = ranks.next().unwrap();
    let mut node = ranks.next().unwrap();
    let handle = std::thread::spawn(move || {
        igi_cluster::run_worker(&mut node, 1, |s| igi_scene::load_named(&s.scene).map_err(|e| e.to_string()))
    });
    let mut s = setup("cornell-box");
    s.scene = "/no/such/scene.obj".into();
    let err = Master::connect(root, &s, MasterConfig::default()).unwrap_err();
    assert!(
        err.to_string().contains("rank 1 failed") && err.to_string().contains("/no/such/scene.obj"),
        "{err}"
    );
    assert!(handle.join().unwrap().is_err());
}

/// Stops a node's transport as SIGSTOP stops its process: while stopped, the node neither
/// sends nor receives (its next send or receive waits), and rank 0 hears nothing from it.
#[derive(Clone, Default)]
struct Switch(Arc<(Mutex<bool>, Condvar)>);

impl Switch {
    fn stop(&self) {
        *self.0.0.lock().unwrap() = true;
    }

    fn resume(&self) {
        *self.0.0.lock().unwrap() = false;
        self.0.1.notify_all();
    }

    fn wait_while_stopped(&self) {
        let mut stopped = self.0.0.lock().unwrap();
        while *stopped {
            stopped = self.0.1.wait(stopped).unwrap();
        }
    }
}

/// A node's transport with a [`Switch`].
struct Stoppable {
    inner: InProcess,
    switch: Switch,
}

impl Transport for Stoppable {
    fn rank(&self) -> usize {
        self.inner.rank()
    }
    fn size(&self) -> usize {
        self.inner.size()
    }
    fn send(&mut self, to: usize, bytes: &[u8]) -> Result<(), TransportError> {
        self.switch.wait_while_stopped();
        self.inner.send(to, bytes)
    }
    fn recv(&mut self, timeout: Duration) -> Result<Option<(usize, Vec<u8>)>, TransportError> {
        self.switch.wait_while_stopped();
        self.inner.recv(timeout)
    }
    fn abort(&mut self, code: i32) {
        self.inner.abort(code);
    }
}

/// Starts `nodes` render nodes of one thread, each with a switch; returns rank 0's transport.
fn start_stoppable(nodes: usize) -> (InProcess, Vec<Node>, Vec<Switch>) {
    let mut ranks = igi_cluster::in_process(nodes + 1).into_iter();
    let root = ranks.next().unwrap();
    let switches: Vec<Switch> = (0..nodes).map(|_| Switch::default()).collect();
    let handles = ranks
        .zip(&switches)
        .map(|(inner, switch)| {
            let mut t = Stoppable { inner, switch: switch.clone() };
            std::thread::spawn(move || {
                igi_cluster::run_worker(&mut t, 1, |s| {
                    igi_scene::load_named(&s.scene).map_err(|e| e.to_string())
                })
            })
        })
        .collect();
    (root, handles, switches)
}

/// An animation of `animated-room`: frame `k` at 0.1 k s, rendered by the cluster and checked
/// against the local renderer byte for byte (a tile of another frame would show).
struct Animation {
    scene: PreparedScene,
    state: FrameState,
    renderer: FrameRenderer,
    next: u32,
}

impl Animation {
    fn new() -> Self {
        let scene = PreparedScene::new(load("animated-room"));
        let mut state = first_frame(&scene);
        state.settings.width = 64;
        state.settings.height = 48;
        Self { state, scene, renderer: FrameRenderer::new(1), next: 0 }
    }

    /// The next frame from `master`, checked; its tiles per node, or the cluster's error.
    fn frame(&mut self, master: &mut Master<InProcess>) -> Result<Vec<u32>, ClusterError> {
        let t = 0.1 * self.next as f32;
        self.next += 1;
        let remote = master.render(job(&self.state, t, PixelFormat::Srgb8))?;
        let local = self
            .renderer
            .render(&mut self.scene, &at(&self.state, t, PixelFormat::Linear), &|_, _| {})
            .unwrap();
        assert!(
            remote.output.image.srgb8() == local.image.srgb8(),
            "frame {} differs from the local renderer's",
            self.next - 1
        );
        Ok(remote.tiles_per_node)
    }
}

/// Silence as the tests below set it: suspected after 200 ms; no deadline copies (an hour),
/// so only reassignment can finish a frame whose node stopped.
fn stop_config(silence_limit: Duration) -> MasterConfig {
    MasterConfig {
        suspect_after: Duration::from_millis(200),
        silence_limit,
        min_deadline: Duration::from_secs(3600),
        ..MasterConfig::default()
    }
}

/// Rank 0 of two stoppable render nodes of the animated room, with a silence limit of
/// `silence_limit` ([`stop_config`]), and the animation its frames follow.
fn two_stoppable_nodes(silence_limit: Duration) -> (Master<InProcess>, Vec<Node>, Vec<Switch>, Animation) {
    let (root, nodes, switches) = start_stoppable(2);
    let master = Master::connect(root, &setup("animated-room"), stop_config(silence_limit)).unwrap();
    (master, nodes, switches, Animation::new())
}

#[test]
fn a_node_that_stops_answering_has_its_tiles_rendered_by_the_others_at_once() {
    let (mut master, nodes, switches, mut animation) = two_stoppable_nodes(Duration::from_secs(60));
    let both = animation.frame(&mut master).unwrap();
    assert_eq!(both.iter().sum::<u32>(), 12);
    switches[1].stop();
    // Rank 2 holds tiles of the next frame when it stops; the deadline is an hour and the
    // silence limit a minute, so only handing its tiles to rank 1 finishes these frames.
    for k in 0..4 {
        let tiles =
            animation.frame(&mut master).unwrap_or_else(|e| panic!("frame {k} while rank 2 is stopped: {e}"));
        assert_eq!(tiles, vec![12, 0], "frame {k} while rank 2 is stopped");
    }
    switches[1].resume();
    drop(master);
    nodes.into_iter().for_each(|n| assert!(n.join().unwrap().is_ok(), "nodes end cleanly"));
}

#[test]
fn a_node_that_answers_again_is_given_tiles_again_and_its_stale_tiles_are_dropped() {
    let (mut master, nodes, switches, mut animation) = two_stoppable_nodes(Duration::from_secs(60));
    animation.frame(&mut master).unwrap();
    switches[1].stop();
    for _ in 0..2 {
        assert_eq!(animation.frame(&mut master).unwrap()[1], 0);
    }
    // Rank 2 catches up on the frames it missed (their tiles are of no use any more: they
    // would show in the images, which are checked) and then takes part again.
    switches[1].resume();
    let back = (0..50).any(|_| animation.frame(&mut master).unwrap()[1] > 0);
    assert!(back, "rank 2 rendered nothing in 50 frames after it answered again");
    drop(master);
    nodes.into_iter().for_each(|n| assert!(n.join().unwrap().is_ok(), "nodes end cleanly"));
}

#[test]
fn a_node_still_silent_at_the_end_of_the_job_is_waited_for_then_the_job_is_aborted() {
    let (mut master, nodes, switches, mut animation) = two_stoppable_nodes(Duration::from_secs(3));
    animation.frame(&mut master).unwrap();
    switches[1].stop();
    animation.frame(&mut master).unwrap();
    // Over MPI the job could end only once rank 2 does: rank 0 waits for it up to the limit,
    // then aborts the job rather than hang.
    let ending = Instant::now();
    drop(master);
    assert!(ending.elapsed() < Duration::from_secs(30), "the end of the job waits for the stopped node");
    switches[1].resume();
    let mut results = nodes.into_iter().map(|n| n.join().unwrap());
    drop(results.next());
    let rank2 = results.next().unwrap();
    assert!(
        matches!(rank2, Err(ClusterError::Transport(TransportError::Aborted))),
        "rank 2 finds the job aborted: {rank2:?}"
    );
}

#[test]
fn a_node_that_answers_while_the_job_ends_ends_with_it() {
    let (mut master, nodes, switches, mut animation) = two_stoppable_nodes(Duration::from_secs(60));
    animation.frame(&mut master).unwrap();
    switches[1].stop();
    animation.frame(&mut master).unwrap();
    let switch = switches[1].clone();
    let resume = std::thread::spawn(move || {
        std::thread::sleep(Duration::from_millis(300));
        switch.resume();
    });
    drop(master);
    resume.join().unwrap();
    nodes.into_iter().for_each(|n| assert!(n.join().unwrap().is_ok(), "nodes end cleanly"));
}
