//! A viewer session rendered by the cluster (over the in-process transport): the moving frame
//! comes as 8-bit pixels and equals the local session's; once the view is still, linear frames
//! accumulate, one frame behind the local session (whose first frame had linear pixels too),
//! and give the same images byte for byte.

use igi_cluster::{ClusterError, ClusterSource, InProcess, Master, MasterConfig, Setup, WorkerSummary};
use igi_render::PreparedScene;
use igi_session::{Session, ViewerSettings};
use std::thread::JoinHandle;

fn session(source: Option<Box<dyn igi_render::FrameSource>>) -> Session {
    let scene = PreparedScene::new(igi_scene::builtin("cornell-box").unwrap());
    let camera = *scene.camera().unwrap();
    let settings = ViewerSettings {
        frame: igi_render::FrameSettings {
            width: 48,
            height: 40,
            ..ViewerSettings::for_scene(scene.bounds().diagonal()).frame
        },
        playing: false,
        ..ViewerSettings::for_scene(scene.bounds().diagonal())
    };
    match source {
        Some(source) => Session::with_source(scene, camera, settings, source).unwrap(),
        None => Session::new(scene, camera, settings, 2).unwrap(),
    }
}

/// A cluster of `nodes` one-thread render nodes (threads over the in-process transport) on
/// the Cornell box, as a session's frame source, and the nodes' threads.
fn cluster(nodes: usize) -> (ClusterSource<InProcess>, Vec<JoinHandle<Result<WorkerSummary, ClusterError>>>) {
    let mut ranks = igi_cluster::in_process(nodes + 1).into_iter();
    let root = ranks.next().unwrap();
    let nodes = ranks
        .map(|mut t| {
            std::thread::spawn(move || {
                igi_cluster::run_worker(&mut t, 1, |s| {
                    igi_scene::load_named(&s.scene).map_err(|e| e.to_string())
                })
            })
        })
        .collect();
    let setup = Setup {
        version: igi_cluster::protocol::PROTOCOL_VERSION,
        scene: "cornell-box".into(),
        files: vec![],
        digest: igi_scene::builtin("cornell-box").unwrap().digest(),
        default_light: true,
    };
    let master = Master::connect(root, &setup, MasterConfig::default()).unwrap();
    (ClusterSource::new(master, Box::new(|e| panic!("the cluster failed: {e}"))), nodes)
}

#[test]
fn a_cluster_session_shows_the_local_sessions_frames() {
    let (source, nodes) = cluster(2);
    let mut cluster = session(Some(Box::new(source)));
    let mut local = session(None);

    let local_frames: Vec<_> = (0..4).map(|_| local.render(0.0).unwrap()).collect();
    let cluster_frames: Vec<_> = (0..5).map(|_| cluster.render(0.0).unwrap()).collect();
    // The first frame: 8-bit pixels from the nodes, the same bytes, no linear film.
    assert!(cluster_frames[0].image.srgb8() == local_frames[0].image.srgb8());
    assert!(cluster_frames[0].image.film().is_none());
    // Still: the cluster's mean of k frames is the local session's mean of k frames.
    for k in 1..4 {
        assert_eq!(cluster_frames[k + 1].stats.accumulated, local_frames[k].stats.accumulated);
        assert!(
            cluster_frames[k + 1].image.srgb8() == local_frames[k].image.srgb8(),
            "accumulated frame {k} differs"
        );
        assert!(
            cluster_frames[k + 1].image.film().unwrap().pixels()
                == local_frames[k].image.film().unwrap().pixels()
        );
    }
    drop(cluster);
    nodes.into_iter().for_each(|n| assert!(n.join().unwrap().is_ok()));
}

/// The probe's frame of hours on one node (3840x2160, 64 AA samples, 4096 VPLs per pixel) is
/// given up on rank 0 too when new input comes: the input's frame comes in seconds, and the
/// long frame is never shown.
#[test]
fn a_cluster_viewer_gives_up_a_long_frame_for_new_input() {
    use igi_session::{Input, RenderLoop};
    use std::time::Duration;
    let (source, nodes) = cluster(1);
    let session = session(Some(Box::new(source)));
    let fast = ViewerSettings { accumulate: false, ..session.settings().clone() };
    let slow = ViewerSettings {
        frame: igi_render::FrameSettings {
            width: 3840,
            height: 2160,
            vpls_per_pixel: 4096,
            aa: 64,
            ..fast.clone().frame
        },
        ..fast.clone()
    };
    let render_loop = RenderLoop::spawn(session);
    render_loop.send(Input::Settings { settings: fast.clone() });
    render_loop.latest().wait_newer(0, Duration::from_secs(30)).expect("a first frame");
    render_loop.send(Input::Settings { settings: slow });
    // Let the long frame start.
    std::thread::sleep(Duration::from_secs(1));
    let seq = render_loop.send(Input::Settings { settings: fast.clone() });
    let mut frame = render_loop.latest().get().unwrap();
    while frame.stats.input_seq < seq {
        let Some(newer) = render_loop.latest().wait_newer(frame.stats.id, Duration::from_secs(20)) else {
            panic!("no frame within 20 s of the input: rank 0 waited for the long frame");
        };
        assert_eq!(newer.stats.settings, fast, "frame {} has the long frame's settings", newer.stats.id);
        frame = newer;
    }
    drop(render_loop);
    nodes.into_iter().for_each(|n| assert!(n.join().unwrap().is_ok()));
}
