//! A render node leaves a frame behind when rank 0 moves on: a newer job or a shutdown stops
//! its render threads before their next tile, so a frame of minutes does not hold up the next
//! one. Rank 0 is played by the test over the in-process transport.

use igi_cluster::protocol::{Message, PROTOCOL_VERSION, Ready};
use igi_cluster::{FrameJob, InProcess, Setup, Transport};
use igi_render::{FrameSettings, FrameState, PixelFormat, PreparedScene, TileGrid};
use std::time::{Duration, Instant};

const SCENE: &str = "cornell-box";
const THREADS: usize = 2;

fn frame(scene: &PreparedScene, settings: FrameSettings) -> FrameState {
    let settings = FrameSettings { clamp: FrameSettings::clamp_for(scene.bounds().diagonal()), ..settings };
    FrameState { pixels: PixelFormat::Srgb8, ..FrameState::new(*scene.camera().unwrap(), settings) }
}

/// Sends job `id` and every one of its tiles; returns its tile count.
fn send_job(root: &mut InProcess, id: u64, state: &FrameState) -> u32 {
    let tiles = TileGrid::new(state.settings.width, state.settings.height, state.settings.tile_size).len();
    let job = FrameJob { id, frame: state.clone() };
    root.send(1, &Message::Frame(Box::new(job)).encode()).unwrap();
    root.send(1, &Message::Tiles { job: id, tiles: (0..tiles).collect() }.encode()).unwrap();
    tiles
}

/// The job of the next tile the node sends, waiting at most until `deadline`.
fn next_tile(root: &mut InProcess, deadline: Instant) -> Option<u64> {
    while let Some(left) = deadline.checked_duration_since(Instant::now()) {
        if let Some((_, bytes)) = root.recv(left).unwrap() {
            match Message::decode(&bytes).unwrap() {
                Message::Tile(tile) => return Some(tile.job),
                Message::Heartbeat => {}
                other => panic!("unexpected {}", other.kind()),
            }
        }
    }
    None
}

#[test]
fn a_node_abandons_a_frame_when_a_newer_job_or_a_shutdown_comes() {
    let scene = PreparedScene::new(igi_scene::builtin(SCENE).unwrap());
    // 2040 tiles of 4096 pixels with 4096 VPLs each (2 · 10¹⁰ rays): minutes on two threads,
    // a fraction of a second per tile.
    let slow = frame(
        &scene,
        FrameSettings { width: 3840, height: 2160, vpls_per_pixel: 4096, aa: 1, ..FrameSettings::default() },
    );
    let quick =
        frame(&scene, FrameSettings { width: 64, height: 48, tile_size: 16, ..FrameSettings::default() });

    let mut ranks = igi_cluster::in_process(2).into_iter();
    let mut root = ranks.next().unwrap();
    let mut node = ranks.next().unwrap();
    let worker = std::thread::spawn(move || {
        igi_cluster::run_worker(&mut node, THREADS, |s| {
            igi_scene::load_named(&s.scene).map_err(|e| e.to_string())
        })
    });
    let setup = Setup {
        version: PROTOCOL_VERSION,
        scene: SCENE.into(),
        files: vec![],
        digest: igi_scene::builtin(SCENE).unwrap().digest(),
        default_light: true,
        view: None,
    };
    root.send(1, &Message::Setup(setup).encode()).unwrap();
    let (_, ready) = root.recv(Duration::from_secs(60)).unwrap().expect("the node loads the scene");
    assert!(matches!(Message::decode(&ready).unwrap(), Message::Ready(Ready::Loaded { .. })));

    // The slow job is under way once its first tile is back.
    let slow_tiles = send_job(&mut root, 1, &slow);
    assert_eq!(next_tile(&mut root, Instant::now() + Duration::from_secs(60)), Some(1));
    let mut slow_done = 1;

    // A newer job: its tiles all come within seconds. Of the slow job's, only those finished
    // before the node saw the new job come, and none once the new job's tiles come.
    let start = Instant::now();
    let quick_tiles = send_job(&mut root, 2, &quick);
    let mut quick_done = 0;
    while quick_done < quick_tiles {
        match next_tile(&mut root, start + Duration::from_secs(10)) {
            Some(1) => {
                assert_eq!(quick_done, 0, "a tile of the old job after the new job's tiles");
                slow_done += 1;
            }
            Some(_) => quick_done += 1,
            None => panic!("{quick_done} of {quick_tiles} tiles of the newer job within 10 s"),
        }
    }
    eprintln!("the newer job's tiles came within {:?}; {slow_done} tiles of the old job", start.elapsed());
    assert!(slow_done < slow_tiles / 4, "{slow_done} of {slow_tiles} tiles of the old job");

    // A shutdown in the middle of a slow job ends the node within seconds.
    send_job(&mut root, 3, &slow);
    assert_eq!(next_tile(&mut root, Instant::now() + Duration::from_secs(60)), Some(3));
    let start = Instant::now();
    root.send(1, &Message::Shutdown.encode()).unwrap();
    while !worker.is_finished() {
        assert!(start.elapsed() < Duration::from_secs(10), "the node still renders 10 s after the shutdown");
        std::thread::sleep(Duration::from_millis(20));
    }
    let summary = worker.join().unwrap().expect("the node ends cleanly");
    assert!(summary.tiles < u64::from(slow_tiles), "{summary:?}");
}
