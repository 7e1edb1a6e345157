//! The options shared by the interactive viewers, `igi view` and `igi serve`: the scene, the
//! frame options of `igi render` and the clock, turned into an [`igi_session::Session`].

use crate::cluster::{ClusterArgs, Rank};
use crate::frame_args::{FrameArgs, prepare_scene};
use crate::progress::Stages;
use anyhow::{Context, Result};
use clap::Args;
use igi_session::settings::DEFAULT_CONVERGE_FRAMES;
use igi_session::{SceneCatalog, Session, ViewerSettings};

/// Primary rays per pixel of the viewers: an interactive frame first.
const VIEWER_AA: u32 = 1;

/// Options of `igi view` and `igi serve`.
#[derive(Debug, Args)]
pub struct ViewerArgs {
    /// Built-in scene (listed below) or scene file (.obj, .ply, .gltf, .glb, .toml).
    pub scene: String,
    /// Fixed exposure in stops, linear with a clip at 1, instead of the automatic tone map.
    #[arg(long, allow_hyphen_values = true, conflicts_with = "tone_map", help_heading = "Output")]
    pub exposure: Option<f32>,
    /// Start with the animation clock stopped.
    #[arg(long, help_heading = "Animation")]
    pub paused: bool,
    /// Animation speed: scene seconds per second.
    #[arg(long, default_value_t = 1.0, help_heading = "Animation")]
    pub speed: f32,
    /// Show single frames only (no progressive accumulation while the view is still).
    #[arg(long, help_heading = "Sampling")]
    pub no_accumulate: bool,
    /// Show each frame on its own while the camera or objects move (no temporal reuse of the
    /// reprojected history; also in the panel).
    #[arg(long, help_heading = "Sampling")]
    pub no_temporal: bool,
    /// A still view is converged, and rendering stops, after this many accumulated frames
    /// (also in the panel).
    #[arg(long, default_value_t = DEFAULT_CONVERGE_FRAMES, help_heading = "Sampling")]
    pub converge_frames: u32,
    /// ... or once its accumulated frames took this many seconds to render (0: no limit).
    #[arg(long, default_value_t = 0.0, help_heading = "Sampling")]
    pub converge_seconds: f32,
    /// Frame options (as for `igi render`; `--aa` defaults to 1 here).
    #[command(flatten)]
    pub frame: FrameArgs,
    /// Cluster options.
    #[command(flatten, next_help_heading = "Cluster")]
    pub cluster: ClusterArgs,
}

impl ViewerArgs {
    /// The scenes a local viewer may open instead: the built-in ones, then the scene files
    /// under the folder it started in ([`igi_scene::scene_files_under`]), opened as the
    /// first scene was (the default light unless `--no-default-light`); and the catalog's name
    /// of the scene shown, so that the list shows it: its path relative to that folder, else
    /// the scene as named on the command line, added to the list if it is not in it.
    fn catalog(&self) -> Result<(SceneCatalog, String)> {
        let folder = std::env::current_dir().context("the current folder")?;
        let mut names: Vec<String> = igi_scene::builtin_names().iter().map(|n| n.to_string()).collect();
        names.extend(igi_scene::scene_files_under(&folder));
        let current = catalog_name(&folder, &self.scene);
        if !names.contains(&current) {
            names.push(current.clone());
        }
        let default_light = !self.frame.no_default_light;
        let open = move |name: &str| {
            // A file under the folder (or an absolute path: `join` keeps it), else a built-in
            // scene's name with its parameters.
            let file = folder.join(name);
            let spec = match file.is_file() {
                true => file.to_string_lossy().into_owned(),
                false => name.to_string(),
            };
            let scene = igi_scene::load_named(&spec).map_err(|e| e.to_string())?;
            crate::scene_load::warn_if_no_geometry(name, &scene);
            Ok(prepare_scene(scene, default_light, None))
        };
        Ok((SceneCatalog::new(names, Box::new(open)), current))
    }

    /// Loads the scene and starts a session with these options (errors name the flag).
    /// `None` on a render node of a cluster job, once the job is over.
    pub fn session(&self) -> Result<Option<Session>> {
        // A render node spends the whole job in `cluster::start`: no stages there.
        let stages = (!self.cluster.cluster).then(|| Stages::spinner(format!("loading {}", self.scene)));
        let (scene, source) = if self.cluster.cluster {
            match crate::cluster::start(&self.cluster, &self.scene, &self.frame)? {
                Rank::Root(root) => {
                    (root.scene, Some(crate::cluster::source(root.master, self.frame.threads)))
                }
                Rank::NodeDone => return Ok(None),
            }
        } else {
            (crate::scene_load::load_scene(&self.scene)?, None)
        };
        let stages = Stages::preparing(stages, &self.scene, Stages::spinner);
        let prepared = self.frame.prepare(scene);
        drop(stages);
        let mut frame = self.frame.frame_state(&prepared)?;
        frame.settings.aa = self.frame.aa.unwrap_or(VIEWER_AA);
        let settings = ViewerSettings {
            exposure: self.exposure,
            accumulate: !self.no_accumulate,
            temporal: !self.no_temporal,
            converge_frames: self.converge_frames,
            converge_seconds: self.converge_seconds,
            playing: !self.paused,
            speed: self.speed,
            ..ViewerSettings::new(frame.settings)
        };
        let mut session = match source {
            Some(source) => Session::with_source(prepared, frame.camera, settings, source)?,
            None => {
                let mut session = Session::new(prepared, frame.camera, settings, self.frame.threads)?;
                let (catalog, current) = self.catalog()?;
                session.set_catalog(catalog, &current);
                session
            }
        };
        session.set_clock(frame.pose.time);
        Ok(Some(session))
    }
}

/// The name the catalog of `folder` gives the scene named `scene` on the command line: a
/// file under `folder` as [`igi_scene::scene_files_under`] names it
/// ([`igi_scene::name_under`]); a file elsewhere by its absolute path; a
/// built-in scene by its name.
fn catalog_name(folder: &std::path::Path, scene: &str) -> String {
    let Ok(file) = std::fs::canonicalize(scene) else { return scene.to_string() };
    if !file.is_file() {
        return scene.to_string();
    }
    let relative =
        std::fs::canonicalize(folder).ok().and_then(|folder| igi_scene::name_under(&folder, &file));
    relative.unwrap_or_else(|| file.to_string_lossy().into_owned())
}

#[cfg(test)]
mod tests {
    use super::{ViewerArgs, catalog_name};
    use crate::cmd_render::RenderArgs;
    use clap::Parser;

    /// `igi view`'s arguments alone.
    #[derive(Debug, Parser)]
    struct ViewerLine {
        #[command(flatten)]
        args: ViewerArgs,
    }

    /// `igi render`'s arguments alone.
    #[derive(Debug, Parser)]
    struct RenderLine {
        #[command(flatten)]
        args: RenderArgs,
    }

    /// The bits of an image's linear radiance.
    type Bits = Vec<[u32; 3]>;

    /// The first frame a viewer started with `options` shows (not accumulating, no temporal
    /// reuse, the clock paused: the moving frame), and the EXR `igi render --moving-frame` writes with the same
    /// options from the viewer's camera, as bits. (A viewer's camera controller keeps a view
    /// as position, angles and distance, so its camera can differ from the one it started
    /// with in the last bits; the settings are what is compared here.)
    fn viewer_and_render(scene: &str, options: &[&str], folder: &std::path::Path) -> (Bits, Bits) {
        let bits = |pixels: &mut dyn Iterator<Item = [f32; 3]>| -> Bits {
            pixels.map(|p| p.map(f32::to_bits)).collect()
        };
        let line = ["igi", scene, "--no-accumulate", "--no-temporal", "--paused"]
            .into_iter()
            .chain(options.iter().copied());
        let viewer = ViewerLine::try_parse_from(line).expect("a viewer's command line").args;
        let mut session = viewer.session().expect("the session starts").expect("not a cluster node");
        let frame = session.render(0.0).expect("the first frame");
        let film = frame.image.film().expect("a local frame carries its radiance");
        let shown = bits(&mut film.pixels().iter().map(|p| p.to_array()));

        let camera = frame.stats.camera;
        let vector = |flag: &str, v: glam::Vec3| format!("--camera-{flag}={},{},{}", v.x, v.y, v.z);
        let seen_from = [
            vector("position", camera.position),
            vector("target", camera.target),
            vector("up", camera.up),
            format!("--fov={}", camera.fov_y_deg),
        ];
        let options =
            options.iter().copied().filter(|o| !o.starts_with("--camera-") && !o.starts_with("--fov"));
        let output = folder.join("render.exr");
        let output = output.to_str().unwrap();
        let line = ["igi", scene, "-o", output, "--moving-frame"]
            .into_iter()
            .chain(options)
            .chain(seen_from.iter().map(String::as_str));
        let render = RenderLine::try_parse_from(line).expect("a render command line").args;
        crate::cmd_render::run(&render).expect("igi render");
        let written = image::open(output).expect("the EXR igi render wrote").to_rgb32f();
        let written = bits(&mut written.pixels().map(|p| p.0));
        (shown, written)
    }

    /// Every frame option the viewers share with `igi render` changes the viewer's frame as it
    /// changes `igi render`'s: the first frame of a viewer started with an option is, bit for
    /// bit, what `igi render --moving-frame` writes with it (issue 31: the viewers once dropped
    /// `--seed` and `--tile-size` on the way to their settings), and the options that should
    /// change the image do.
    #[test]
    fn every_frame_option_changes_the_viewer_as_it_changes_igi_render() {
        let folder = tempfile::tempdir().unwrap();
        // A scene without light sources, for the default light.
        let unlit = folder.path().join("unlit.obj");
        std::fs::write(&unlit, "v -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\nv 0 1 0\nf 1 2 3 4\nf 1 2 5\n")
            .unwrap();
        let unlit = unlit.to_str().unwrap();
        // (scene, options, whether the image must differ from the scene's with no option;
        // `None` where it may or may not).
        let cases: &[(&str, &[&str], Option<bool>)] = &[
            ("cornell-box", &[], Some(false)),
            ("cornell-box", &["--seed", "3"], Some(true)),
            ("cornell-box", &["--tile-size", "16"], Some(false)),
            ("cornell-box", &["--threads", "1"], Some(false)),
            ("cornell-box", &["--vpls", "5"], Some(true)),
            ("cornell-box", &["--interleave", "2x2"], Some(true)),
            ("cornell-box", &["--coarse-interleave", "1"], Some(true)),
            ("cornell-box", &["--aa", "2"], Some(true)),
            ("cornell-box", &["--no-filter"], Some(true)),
            ("cornell-box", &["--filter-normal", "0.999", "--filter-depth", "0.001"], Some(true)),
            ("cornell-box", &["--clamp", "0.5"], Some(true)),
            ("cornell-box", &["--compensate"], Some(true)),
            ("cornell-box", &["--bounces", "0"], Some(true)),
            ("cornell-box", &["--specular-bounces", "0"], None),
            ("cornell-box", &["--width", "32", "--height", "24"], Some(true)),
            ("cornell-box", &["--camera-position=0.2,1,3.5", "--fov=30"], Some(true)),
            ("animated-room", &[], Some(false)),
            ("animated-room", &["--time", "1.5"], Some(true)),
            (unlit, &["--no-default-light"], Some(true)),
        ];
        // Small frames of one primary ray per pixel (the viewers' default is not `igi
        // render`'s) unless a case sets them.
        let common = [["--width", "40"], ["--height", "30"], ["--aa", "1"], ["--threads", "2"]];
        let mut unchanged = std::collections::HashMap::new();
        for &(scene, options, changes) in cases {
            let mut line: Vec<&str> =
                common.iter().filter(|[flag, _]| !options.contains(flag)).flatten().copied().collect();
            line.extend_from_slice(options);
            let (viewer, render) = viewer_and_render(scene, &line, folder.path());
            assert!(viewer == render, "{scene} {options:?}: the viewer's frame differs from igi render's");
            let unchanged = unchanged
                .entry(scene)
                .or_insert_with(|| viewer_and_render(scene, common.as_flattened(), folder.path()).0);
            if let Some(changes) = changes {
                assert_eq!(viewer != *unchanged, changes, "{scene} {options:?}: does the image change?");
            }
        }
    }

    /// The scene a viewer starts with is named as the catalog names it, so that the list of
    /// scenes shows it selected: relative to the folder, absolute outside it, built-in by name.
    #[test]
    fn the_starting_scene_is_named_as_the_catalog_names_it() {
        let folder = tempfile::tempdir().unwrap();
        let elsewhere = tempfile::tempdir().unwrap();
        let inside = folder.path().join("scenes/room.toml");
        std::fs::create_dir_all(inside.parent().unwrap()).unwrap();
        std::fs::write(&inside, "").unwrap();
        let outside = elsewhere.path().join("room.obj");
        std::fs::write(&outside, "").unwrap();
        assert_eq!(catalog_name(folder.path(), inside.to_str().unwrap()), "scenes/room.toml");
        let absolute = std::fs::canonicalize(&outside).unwrap();
        assert_eq!(catalog_name(folder.path(), outside.to_str().unwrap()), absolute.to_str().unwrap());
        assert_eq!(catalog_name(folder.path(), "cornell-box"), "cornell-box");
    }
}
