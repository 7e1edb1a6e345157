//! Loading the scene a command names ([`load_scene`]): the loader's error as the command line
//! reports it, and the warning only a whole scene can give, that it has nothing to see
//! ([`warn_if_no_geometry`]).

use anyhow::{Context, Result};
use igi_scene::Scene;

/// The scene `spec` names (a built-in scene or a scene file), with a warning if it has no
/// geometry.
pub fn load_scene(spec: &str) -> Result<Scene> {
    let scene = igi_scene::load_named(spec).context("cannot load scene")?;
    warn_if_no_geometry(spec, &scene);
    Ok(scene)
}

/// Warns, naming `spec`, if `scene` has no triangle: an empty scene file, or meshes without
/// faces, renders without error but shows nothing but the sky, which looks like a renderer
/// fault rather than the file's.
pub fn warn_if_no_geometry(spec: &str, scene: &Scene) {
    if scene.triangle_count() == 0 {
        tracing::warn!("{spec}: no geometry: the scene has no triangles, so the image shows only the sky");
    }
}
