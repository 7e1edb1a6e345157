//! A server on a free localhost port with a small session of the animated room, and a list
//! of scenes to open in which one does not.

use igi_render::PreparedScene;
use igi_session::{RenderLoop, Session, ViewerSettings};
use std::net::SocketAddr;
use std::sync::Arc;
use tokio::sync::oneshot;

/// The scenes the server lists: `toml/missing_mesh.toml` does not open, with [`MISSING`].
pub const SCENES: [&str; 3] = ["animated-room", "cornell-box", "toml/missing_mesh.toml"];

/// Why `toml/missing_mesh.toml` does not open.
#[allow(dead_code)] // Not every test file uses every helper.
pub const MISSING: &str = "toml/missing_mesh.toml: mesh file missing.obj: No such file or directory";

/// A running server; dropping it stops the server.
pub struct TestServer {
    pub address: SocketAddr,
    stop: Option<oneshot::Sender<()>>,
    thread: Option<std::thread::JoinHandle<()>>,
}

impl Drop for TestServer {
    fn drop(&mut self) {
        if let Some(stop) = self.stop.take() {
            let _ = stop.send(());
        }
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}

/// Serves the animated room, `width` × `height`, paused and without accumulation (a frame
/// changes only when an input changes it), on its own runtime thread.
#[allow(dead_code)] // Not every test file uses every helper.
pub fn start(width: u32, height: u32) -> TestServer {
    start_with(width, height, igi_serve::Limits::default())
}

/// [`start`] within `limits`.
#[allow(dead_code)] // Not every test file uses every helper.
pub fn start_with(width: u32, height: u32, limits: igi_serve::Limits) -> TestServer {
    let scene = PreparedScene::new(igi_scene::builtin("animated-room").unwrap());
    let camera = *scene.camera().unwrap();
    let settings = ViewerSettings {
        frame: igi_render::FrameSettings {
            width,
            height,
            ..ViewerSettings::for_scene(scene.bounds().diagonal()).frame
        },
        playing: false,
        accumulate: false,
        ..ViewerSettings::for_scene(scene.bounds().diagonal())
    };
    let mut session = Session::new(scene, camera, settings, 1).unwrap();
    // Two built-in scenes to open, and a scene file that does not open.
    let names: Vec<String> = SCENES.iter().map(|n| n.to_string()).collect();
    let open =
        |name: &str| igi_scene::builtin(name).map(PreparedScene::new).ok_or_else(|| MISSING.to_string());
    session.set_catalog(igi_session::SceneCatalog::new(names.clone(), Box::new(open)), "animated-room");
    let (stop, stopped) = oneshot::channel::<()>();
    let (ready, address) = std::sync::mpsc::channel();
    let thread = std::thread::spawn(move || {
        let runtime =
            tokio::runtime::Builder::new_multi_thread().worker_threads(1).enable_all().build().unwrap();
        runtime.block_on(async move {
            let listener = tokio::net::TcpListener::bind("127.0.0.1:0").await.unwrap();
            ready.send(listener.local_addr().unwrap()).unwrap();
            let render_loop = Arc::new(RenderLoop::spawn_on_demand(session));
            igi_serve::serve(render_loop, names, listener, limits, async {
                let _ = stopped.await;
            })
            .await
            .unwrap();
        });
    });
    TestServer { address: address.recv().unwrap(), stop: Some(stop), thread: Some(thread) }
}
