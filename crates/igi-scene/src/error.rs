//! The one error type of every loader, [`SceneError`], and [`Location`], the place in a file it
//! points at.
//!
//! Every message names the file and, where the format allows, the place in it: a line for text
//! formats, an element for binary PLY, a JSON path for glTF, a field for scene files. A user
//! fixing a broken 300 MB scene needs to know where to look, not just that something is wrong.

use std::fmt;
use std::path::PathBuf;

/// Where in a file an error was found.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Location {
    /// Somewhere in the file; the format or the error gives no finer position.
    File,
    /// A 1-based line of a text file (OBJ, MTL, ascii PLY, scene TOML).
    Line(usize),
    /// A field of a scene file, e.g. `mesh[1].file`, with its 1-based line where known.
    Field {
        /// 1-based line, if the parser reported one.
        line: Option<usize>,
        /// Dotted path of the field.
        path: String,
    },
    /// A JSON path into a glTF document, e.g. `meshes[0].primitives[1].indices`.
    Json(String),
    /// A 0-based element of a PLY payload, e.g. `face 17`.
    Element {
        /// The element name from the PLY header.
        name: String,
        /// 0-based index of the element.
        index: usize,
    },
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::File => Ok(()),
            Self::Line(line) => write!(f, "line {line}: "),
            Self::Field { line: Some(line), path } => write!(f, "line {line}, field `{path}`: "),
            Self::Field { line: None, path } => write!(f, "field `{path}`: "),
            Self::Json(path) => write!(f, "{path}: "),
            Self::Element { name, index } => write!(f, "{name} {index}: "),
        }
    }
}

/// Why a scene could not be loaded.
///
/// Loaders never panic and never trust a count in a header further than the bytes behind it;
/// anything they cannot make sense of ends up here.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The file could not be read (missing, unreadable, a directory, ...).
    #[error("{}: {source}", file.display())]
    Io {
        /// The file that could not be read.
        file: PathBuf,
        /// The underlying I/O error.
        #[source]
        source: std::io::Error,
    },
    /// A file refers to another file (mesh, buffer, material library) that does not exist.
    #[error("{}: {at}{} not found", file.display(), missing.display())]
    MissingFile {
        /// The file that holds the reference.
        file: PathBuf,
        /// Where the reference is.
        at: Location,
        /// The path that was looked for.
        missing: PathBuf,
    },
    /// The file name's extension is not one of the supported formats.
    #[error("{}: unsupported file type (expected .obj, .gltf, .glb, .ply or .toml)", file.display())]
    UnknownFormat {
        /// The file.
        file: PathBuf,
    },
    /// What was given where a built-in scene or a scene file is accepted ([`crate::load_named`])
    /// is neither: a mistyped name, a folder, a file of another type.
    #[error("{}", unknown_scene_message(name, closest, folder.as_deref()))]
    UnknownScene {
        /// What was given.
        name: String,
        /// The built-in scene whose name is closest to it, if one is close.
        closest: Option<&'static str>,
        /// If it is a folder: the scene files directly in it (file names, sorted, at most 8).
        folder: Option<Vec<String>>,
    },
    /// The file is not well-formed in its format (syntax, truncation, bad header).
    #[error("{}: {at}{message}", file.display())]
    Parse {
        /// The file.
        file: PathBuf,
        /// Where in the file.
        at: Location,
        /// What is wrong.
        message: String,
    },
    /// The file is well-formed but its content is unusable (non-finite coordinates, indices
    /// out of range, counts larger than the file, degenerate transforms, ...).
    #[error("{}: {at}{message}", file.display())]
    Invalid {
        /// The file.
        file: PathBuf,
        /// Where in the file.
        at: Location,
        /// What is wrong.
        message: String,
    },
    /// The file uses a feature igi does not implement (e.g. a required glTF extension).
    #[error("{}: {at}{message}", file.display())]
    Unsupported {
        /// The file.
        file: PathBuf,
        /// Where in the file.
        at: Location,
        /// What is not supported.
        message: String,
    },
}

impl SceneError {
    /// Shorthand for [`SceneError::Parse`].
    pub(crate) fn parse(file: impl Into<PathBuf>, at: Location, message: impl Into<String>) -> Self {
        Self::Parse { file: file.into(), at, message: message.into() }
    }

    /// Shorthand for [`SceneError::Invalid`].
    pub(crate) fn invalid(file: impl Into<PathBuf>, at: Location, message: impl Into<String>) -> Self {
        Self::Invalid { file: file.into(), at, message: message.into() }
    }

    /// Shorthand for [`SceneError::Unsupported`].
    pub(crate) fn unsupported(file: impl Into<PathBuf>, at: Location, message: impl Into<String>) -> Self {
        Self::Unsupported { file: file.into(), at, message: message.into() }
    }

    /// Shorthand for [`SceneError::Io`].
    pub(crate) fn io(file: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Self::Io { file: file.into(), source }
    }
}

/// The message of [`SceneError::UnknownScene`]: what was wrong, what was probably meant, and
/// what would have been accepted.
fn unknown_scene_message(name: &str, closest: &Option<&'static str>, folder: Option<&[String]>) -> String {
    let builtins = crate::builtin_names().join(", ");
    match folder {
        Some([]) => format!(
            "{name} is a folder with no scene file (.obj, .gltf, .glb, .ply or .toml) in it; \
             built-in scenes: {builtins}"
        ),
        Some(files) => {
            format!(
                "{name} is a folder: give one of its scene files ({}) or a built-in scene",
                files.join(", ")
            )
        }
        None => {
            let hint = closest.map(|c| format!(" Did you mean {c}?")).unwrap_or_default();
            format!(
                "{name}: neither a built-in scene nor a scene file (.obj, .gltf, .glb, .ply or \
                 .toml).{hint} Built-in scenes: {builtins}"
            )
        }
    }
}
