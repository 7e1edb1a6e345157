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
    #[error(
        "{}: unsupported file type (expected .obj, .gltf, .glb, .ply or .toml){}",
        file.display(),
        if *builtin_hint { " and not a built-in scene name" } else { "" }
    )]
    UnknownFormat {
        /// The file.
        file: PathBuf,
        /// True if the name was given where a built-in scene name would also have been
        /// accepted (see [`crate::load_named`]).
        builtin_hint: bool,
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
