//! [`LoadReport`]: what a load repaired or skipped without failing.
//!
//! The scene model has no room for load diagnostics (its fields are shared with the renderer),
//! so loaders write them here. Each warning is also logged through `tracing` the moment it is
//! found, so [`crate::load`] can drop the report and still leave a trace in the log.

use std::path::Path;

/// Diagnostics of one load: counts of dropped data and every warning, in order.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct LoadReport {
    /// Zero-area triangles dropped, summed over all files of the load.
    pub degenerate_dropped: usize,
    /// Every warning of the load, each naming its file (missing textures, fallback materials,
    /// skipped glTF primitives, dropped normals, ...).
    pub warnings: Vec<String>,
    /// Every file the load read, in the order it read them (what a cluster's rank 0 sends
    /// its nodes with `--broadcast-scene`).
    pub files: Vec<std::path::PathBuf>,
}

impl LoadReport {
    /// Records and logs a warning about `file`.
    pub(crate) fn warn(&mut self, file: &Path, message: impl AsRef<str>) {
        let text = format!("{}: {}", file.display(), message.as_ref());
        tracing::warn!("{text}");
        self.warnings.push(text);
    }

    /// Records the zero-area triangles dropped from `file`: one warning per file, not one per
    /// triangle, so a sloppy export does not flood the log.
    pub(crate) fn degenerate(&mut self, file: &Path, dropped: usize) {
        if dropped > 0 {
            self.degenerate_dropped += dropped;
            self.warn(file, format!("dropped {dropped} zero-area triangle(s)"));
        }
    }
}
