//! A viewer session rendered by the cluster (over the in-process transport). With temporal
//! reuse (the default) the history lives on rank 0 and every frame comes as linear radiance:
//! moving, still and after a move, the cluster's frames are the local session's byte for byte.
//! Without it the moving frame comes as 8-bit pixels and equals the local session's; once the
//! view is still, linear frames accumulate, one frame behind the local session (whose first
//! frame had linear pixels too), and give the same images byte for byte.

use igi_cluster::{ClusterError, ClusterSource, InProcess, Master, MasterConfig, Setup, WorkerSummary};
use igi_render::PreparedScene;
use igi_session::{Button, CameraMode, Input, Session, ViewerSettings};
use std::thread::JoinHandle;

fn session(source: Option<Box<dyn igi_render::FrameSource>>, temporal: bool) -> Session {
    let scene = PreparedScene::new(igi_scene::builtin("cornell-box").unwrap());
    let camera = *scene.camera().unwrap();
    let settings = ViewerSettings {
        frame: igi_render::FrameSettings {
            width: 48,
            height: 40,
            ..ViewerSettings::for_scene(scene.bounds().diagonal()).frame
        },
        playing: false,
        temporal,
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
        view: None,
    };
    let master = Master::connect(root, &setup, MasterConfig::default()).unwrap();
    (ClusterSource::new(master, Box::new(|e| panic!("the cluster failed: {e}"))), nodes)
}

#[test]
fn a_cluster_session_shows_the_local_sessions_frames() {
    let (source, nodes) = cluster(2);
    let mut cluster = session(Some(Box::new(source)), false);
    let mut local = session(None, false);

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

#[test]
fn with_temporal_reuse_a_cluster_session_shows_the_local_sessions_frames_while_moving() {
    let (source, nodes) = cluster(2);
    let mut sessions = [session(Some(Box::new(source)), true), session(None, true)];
    let frames: Vec<Vec<_>> = sessions
        .iter_mut()
        .map(|s| {
            s.handle(&Input::Mode { mode: CameraMode::Orbit }).unwrap();
            let mut frames = vec![s.render(0.0).unwrap()];
            for _ in 0..3 {
                s.handle(&Input::Drag { dx: 0.5, dy: 0.0, button: Button::Primary }).unwrap();
                frames.push(s.render(0.0).unwrap());
            }
            frames.push(s.render(0.0).unwrap());
            frames
        })
        .collect();
    for (k, (c, l)) in frames[0].iter().zip(&frames[1]).enumerate() {
        assert_eq!(c.stats.history_kept, l.stats.history_kept, "frame {k}");
        assert!(c.image.srgb8() == l.image.srgb8(), "frame {k} differs");
        assert!(c.image.film().unwrap().pixels() == l.image.film().unwrap().pixels(), "frame {k} differs");
    }
    assert!(frames[1][3].stats.history_kept.is_some_and(|k| k > 0.5), "the moving frames kept history");
    drop(sessions);
    nodes.into_iter().for_each(|n| assert!(n.join().unwrap().is_ok()));
}
