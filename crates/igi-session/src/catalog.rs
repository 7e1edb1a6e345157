//! [`SceneCatalog`]: the scenes a viewer may open instead of the one it started with, and how
//! to open them. A viewer names an entry of the list and nothing else: a browser never gives
//! the server a path.

use crate::refusals::quote_name;
use igi_render::PreparedScene;

/// Opens the scene of a catalog entry's name, ready to render, or says why it cannot.
pub type SceneOpener = Box<dyn Fn(&str) -> Result<PreparedScene, String> + Send>;

/// The scenes a viewer lists and how to open one.
pub struct SceneCatalog {
    names: Vec<String>,
    open: SceneOpener,
}

impl std::fmt::Debug for SceneCatalog {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SceneCatalog").field("names", &self.names).finish_non_exhaustive()
    }
}

impl SceneCatalog {
    /// The catalog of `names` (built-in scene names, files under the viewer's start folder),
    /// opened by `open`.
    pub fn new(names: Vec<String>, open: SceneOpener) -> Self {
        Self { names, open }
    }

    /// The names a viewer lists.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// Opens entry `name`; a name that is not in the list is refused without a look at the
    /// file system. An entry that does not open is logged (a warning naming it and why), for
    /// whoever runs the viewer: the viewer that asked is told as well.
    pub fn open(&self, name: &str) -> Result<PreparedScene, String> {
        if !self.names.iter().any(|n| n == name) {
            return Err(format!("{} is not in the list of scenes", quote_name(name)));
        }
        (self.open)(name).inspect_err(|why| tracing::warn!("cannot open the scene {name}: {why}"))
    }
}
