//! Reading files that scenes refer to: the one place that touches the file system for loaders.
//!
//! Scene files in the wild were authored on case-insensitive Windows file systems with
//! backslash separators and sometimes absolute paths of the author's machine (Sponza's MTL
//! names `00_SKAP.JPG` for `00_skap.JPG`). [`resolve`] finds such files anyway.

use std::fs;
use std::io::{self, Read};
use std::path::{Component, Path, PathBuf};

use crate::error::SceneError;
use crate::report::LoadReport;

/// Reads a whole regular file and lists it in the report's files. Scene files are read
/// whatever their size (a scene's geometry can take gigabytes); see [`read_regular_file`].
pub(crate) fn read(path: &Path, report: &mut LoadReport) -> Result<Vec<u8>, SceneError> {
    read_at_most(path, u64::MAX, report)
}

/// [`read`] of a file that may have at most `max_bytes` bytes.
pub(crate) fn read_at_most(
    path: &Path,
    max_bytes: u64,
    report: &mut LoadReport,
) -> Result<Vec<u8>, SceneError> {
    let bytes = read_regular_file(path, max_bytes)?;
    report.files.push(path.to_path_buf());
    Ok(bytes)
}

/// Reads a whole regular file of at most `max_bytes` bytes: the guarded reader of every file
/// igi takes as input. Devices, FIFOs and directories are refused, so a reference to
/// `/dev/zero` in a fuzzed or malicious file cannot make a read go on forever; a file larger
/// than `max_bytes` is refused before it is read, and one that grows while it is read (or
/// claims 0 bytes, as `/proc` files do) is refused once it passes the bound.
pub fn read_regular_file(path: &Path, max_bytes: u64) -> Result<Vec<u8>, SceneError> {
    let metadata = fs::metadata(path).map_err(|e| SceneError::io(path, e))?;
    if !metadata.is_file() {
        return Err(SceneError::io(path, io::Error::new(io::ErrorKind::InvalidInput, "not a regular file")));
    }
    let too_large = |size: String| {
        SceneError::io(
            path,
            io::Error::new(
                io::ErrorKind::FileTooLarge,
                format!("{size} bytes, more than the {max_bytes} allowed"),
            ),
        )
    };
    if metadata.len() > max_bytes {
        return Err(too_large(metadata.len().to_string()));
    }
    let file = fs::File::open(path).map_err(|e| SceneError::io(path, e))?;
    let mut bytes = Vec::with_capacity(usize::try_from(metadata.len()).unwrap_or(0));
    file.take(max_bytes.saturating_add(1)).read_to_end(&mut bytes).map_err(|e| SceneError::io(path, e))?;
    if bytes.len() as u64 > max_bytes {
        return Err(too_large(format!("over {max_bytes}")));
    }
    Ok(bytes)
}

/// Finds the file a scene refers to as `reference`, relative to `dir`.
///
/// Tries, in order: the path as written, relative to `dir` unless absolute (with `\` read as a
/// separator); the same path matching each component case-insensitively; and the bare file
/// name in `dir`, for absolute paths from the author's machine. Returns `None` if nothing
/// matches.
pub(crate) fn resolve(dir: &Path, reference: &str) -> Option<PathBuf> {
    let normalised = reference.replace('\\', "/");
    let path = Path::new(&normalised);
    let direct = dir.join(path);
    if direct.is_file() {
        return Some(direct);
    }
    if path.is_relative() {
        if let Some(found) = resolve_ignoring_case(dir, path) {
            return Some(found);
        }
    }
    resolve_ignoring_case(dir, Path::new(path.file_name()?))
}

fn resolve_ignoring_case(dir: &Path, relative: &Path) -> Option<PathBuf> {
    let mut current = dir.to_path_buf();
    for component in relative.components() {
        match component {
            Component::Normal(name) => {
                let exact = current.join(name);
                if exact.exists() {
                    current = exact;
                    continue;
                }
                let wanted = name.to_str()?;
                let entry = fs::read_dir(&current).ok()?.flatten().find(|entry| {
                    entry.file_name().to_str().is_some_and(|n| n.eq_ignore_ascii_case(wanted))
                })?;
                current = entry.path();
            }
            Component::ParentDir => current.push(".."),
            Component::CurDir => {}
            Component::RootDir | Component::Prefix(_) => return None,
        }
    }
    current.is_file().then_some(current)
}

/// Directory to resolve references of `file` against: its parent, or the current directory.
pub(crate) fn base_dir(file: &Path) -> PathBuf {
    match file.parent() {
        Some(parent) if !parent.as_os_str().is_empty() => parent.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_files_whatever_the_case_and_separators() {
        let dir = std::env::temp_dir().join(format!("igi-scene-resolve-{}", std::process::id()));
        fs::create_dir_all(dir.join("Textures")).unwrap();
        fs::write(dir.join("Textures").join("Wall.JPG"), b"x").unwrap();
        let expected = dir.join("Textures").join("Wall.JPG");
        assert_eq!(resolve(&dir, "Textures/Wall.JPG"), Some(expected.clone()));
        assert_eq!(resolve(&dir, "textures\\wall.jpg"), Some(expected.clone()));
        assert_eq!(resolve(&dir.join("Textures"), "C:\\work\\WALL.jpg"), Some(expected));
        assert_eq!(resolve(&dir, "missing.png"), None);
        fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn refuses_devices() {
        let err = read(Path::new("/dev/zero"), &mut LoadReport::default()).unwrap_err();
        assert!(err.to_string().contains("not a regular file"), "{err}");
    }

    #[test]
    fn refuses_files_beyond_the_bound() {
        let path = std::env::temp_dir().join(format!("igi-scene-bound-{}", std::process::id()));
        fs::write(&path, [b'x'; 100]).unwrap();
        assert_eq!(read_regular_file(&path, 100).unwrap().len(), 100);
        let err = read_regular_file(&path, 99).unwrap_err().to_string();
        assert!(err.contains("100 bytes, more than the 99 allowed"), "{err}");
        fs::remove_file(&path).unwrap();
        // A regular file whose size says 0 but whose reads go on.
        let stat = Path::new("/proc/self/stat");
        if stat.is_file() {
            let err = read_regular_file(stat, 4).unwrap_err().to_string();
            assert!(err.contains("over 4 bytes"), "{err}");
        }
    }
}
