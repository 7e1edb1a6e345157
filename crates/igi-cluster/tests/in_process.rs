//! The cluster protocol and scheduling over the in-process transport: render nodes on
//! threads give bit for bit the frames of the local renderer, late tiles are copied to other
//! nodes, and a dead node or a node with other files ends the job with its rank named.

use igi_cluster::protocol::{Message, Ready};
use igi_cluster::{ClusterError, FrameJob, InProcess, Master, MasterConfig, PixelFormat, Setup, Transport};
use igi_render::{
    FrameRenderer, FrameState, IgiSettings, PreparedScene, ToneMap, ToneMapper, default_camera,
};
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
    }
}

/// Starts `nodes` render nodes with one thread each; returns rank 0's transport.
fn start(nodes: usize) -> (InProcess, Vec<JoinHandle<Result<igi_cluster::WorkerSummary, ClusterError>>>) {
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
    let settings = IgiSettings {
        width: 96,
        height: 72,
        tile_size: 16,
        aa: 1,
        clamp: IgiSettings::clamp_for(scene.bounds().diagonal()),
        ..IgiSettings::default()
    };
    let camera = scene.camera().copied().unwrap_or_else(|| default_camera(&scene.bounds()));
    FrameState {
        camera,
        settings,
        tone_map: ToneMapper::new(ToneMap::default(), &Default::default()),
        frame: 0,
        seed: 3,
    }
}

fn job(state: FrameState, time: f32, pixels: PixelFormat) -> FrameJob {
    FrameJob { id: 0, state, time, moved: vec![], pixels }
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
        local_scene.set_time(t);
        let local = renderer.render(&local_scene, &state, &|_, _| {}).unwrap();
        let remote = master.render(job(state, t, PixelFormat::Srgb8)).unwrap();
        assert!(remote.srgb8.as_ref() == Some(&local.srgb8), "{name} at t = {t}: 8-bit images differ");
        assert_eq!(remote.stats, local.stats, "{name} at t = {t}: statistics differ");
        assert_eq!(remote.rays, local.rays);
        assert_eq!(remote.tiles_per_node.iter().sum::<u32>(), 30);
        let linear = master.render(job(state, t, PixelFormat::Linear)).unwrap();
        assert!(
            linear.film.as_ref().unwrap().pixels() == local.film.pixels(),
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
fn the_frame_is_independent_of_the_number_of_nodes() {
    let scene = PreparedScene::new(load("cornell-box"));
    let state = first_frame(&scene);
    let mut images = Vec::new();
    for nodes in [1, 3] {
        let (root, handles) = start(nodes);
        let mut master = Master::connect(root, &setup("cornell-box"), MasterConfig::default()).unwrap();
        let frame = master.render(job(state, 0.0, PixelFormat::Srgb8)).unwrap();
        assert_eq!(frame.tiles_per_node.len(), nodes);
        images.push(frame.srgb8.unwrap());
        drop(master);
        handles.into_iter().for_each(|h| assert!(h.join().unwrap().is_ok()));
    }
    assert!(images[0] == images[1]);
}

/// A fake node that loads nothing, answers the setup with `ready`, and then only sends
/// heartbeats (`beat`) or nothing at all: it holds its tiles forever.
fn stalled_node(mut t: InProcess, ready: Ready, beat: bool) -> JoinHandle<()> {
    std::thread::spawn(move || {
        t.send(0, &Message::Ready(ready).encode()).unwrap();
        loop {
            match t.recv(Duration::from_millis(100)) {
                Ok(Some((_, bytes))) if Message::decode(&bytes).unwrap() == Message::Shutdown => return,
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
    let scene = PreparedScene::new(load(name));
    let state = first_frame(&scene);
    let local = FrameRenderer::new(1).render(&scene, &state, &|_, _| {}).unwrap();
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
    let frame = master.render(job(state, 0.0, PixelFormat::Srgb8)).unwrap();
    assert!(frame.srgb8.unwrap() == local.srgb8);
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
    let config = MasterConfig { silence_limit: Duration::from_millis(300), ..MasterConfig::default() };
    let mut master = Master::connect(root, &setup(name), config).unwrap();
    let start = Instant::now();
    let err = master.render(job(state, 0.0, PixelFormat::Srgb8)).unwrap_err();
    assert!(matches!(err, ClusterError::NodeLost { rank: 1, .. }), "{err}");
    assert!(err.to_string().contains("rank 1"), "{err}");
    assert!(start.elapsed() < Duration::from_secs(5));
    drop(master);
    dead.join().unwrap();
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
