//! The options shared by the interactive viewers, `igi view` and `igi serve`: the scene, the
//! frame options of `igi render` and the clock, turned into an [`igi_session::Session`].

use crate::cluster::{ClusterArgs, Rank};
use crate::frame_args::{FrameArgs, prepare_scene};
use crate::progress::StageSpinner;
use anyhow::{Context, Result};
use clap::Args;
use igi_render::image::tonemap::DEFAULT_KEY;
use igi_session::settings::DEFAULT_CONVERGE_FRAMES;
use igi_session::{SceneCatalog, Session, ViewSettings};

/// Primary rays per pixel of the viewers: an interactive frame first.
const VIEWER_AA: u32 = 1;

/// Options of `igi view` and `igi serve`.
#[derive(Debug, Args)]
pub struct ViewerArgs {
    /// Built-in scene (listed below) or scene file (.obj, .ply, .gltf, .glb, .toml).
    pub scene: String,
    /// Fixed exposure in stops instead of Reinhard's operator.
    #[arg(long, allow_hyphen_values = true, help_heading = "Output")]
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
            Ok(prepare_scene(scene, default_light))
        };
        Ok((SceneCatalog::new(names, Box::new(open)), current))
    }

    /// Loads the scene and starts a session with these options (errors name the flag).
    /// `None` on a render node of a cluster job, once the job is over.
    pub fn session(&self) -> Result<Option<Session>> {
        let spinner = StageSpinner::new(format!("loading {}", self.scene));
        let (scene, source) = if self.cluster.cluster {
            match crate::cluster::start(&self.cluster, &self.scene, &self.frame)? {
                Rank::Root(root) => {
                    (root.scene, Some(crate::cluster::source(root.master, self.frame.threads)))
                }
                Rank::NodeDone => return Ok(None),
            }
        } else {
            (igi_scene::load_named(&self.scene).context("cannot load scene")?, None)
        };
        spinner.stage(format!("building the BVH of {}", self.scene));
        let prepared = self.frame.prepare(scene);
        drop(spinner);
        let mut frame = self.frame.frame_state(&prepared)?;
        frame.settings.aa = self.frame.aa.unwrap_or(VIEWER_AA);
        let s = &frame.settings;
        let filter = s.filter.unwrap_or_default();
        let settings = ViewSettings {
            width: s.width,
            height: s.height,
            vpls_per_pixel: s.vpls_per_pixel,
            interleave: s.interleave,
            coarse_interleave: s.coarse_interleave,
            aa: s.aa,
            filter: s.filter.is_some(),
            filter_normal: filter.min_normal_cos,
            filter_depth: filter.max_depth_ratio,
            clamp: s.clamp,
            specular_bounces: s.specular_bounces,
            bounces: s.bounces,
            exposure: self.exposure,
            key: DEFAULT_KEY,
            path_tracer: false,
            accumulate: !self.no_accumulate,
            converge_frames: self.converge_frames,
            converge_seconds: self.converge_seconds,
            playing: !self.paused,
            speed: self.speed,
            sky: 1.0,
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
        session.set_clock(self.frame.time);
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
    use super::catalog_name;

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
