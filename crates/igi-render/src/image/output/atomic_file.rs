//! Output files replaced all at once. Every file igi writes (images, sequences, snapshots,
//! benchmark reports) goes first to a temporary file in the same folder, which is flushed,
//! synced and then renamed over the target: a reader, a crash, Ctrl-C or a full disk sees the
//! earlier file or the whole new one, never a truncated mix (a rename within one file system is
//! atomic). A write that fails removes its temporary file and leaves the target as it was, and
//! so does a process ended by a signal whose handler calls [`end_writes`] first.

use super::OutputError;
use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard, PoisonError};

/// The temporary files of the writes under way, for [`end_writes`].
static WRITING: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// A temporary file's place in [`WRITING`], given up when the write ends either way.
struct Writing(PathBuf);

impl Writing {
    fn register(path: &Path) -> Self {
        WRITING.lock().unwrap_or_else(PoisonError::into_inner).push(path.to_owned());
        Self(path.to_owned())
    }
}

impl Drop for Writing {
    fn drop(&mut self) {
        let mut writing = WRITING.lock().unwrap_or_else(PoisonError::into_inner);
        if let Some(i) = writing.iter().position(|p| *p == self.0) {
            writing.swap_remove(i);
        }
    }
}

/// Removes the temporary files of the writes under way and holds back new ones while the
/// returned guard lives: for a signal handler that then ends the process, which would
/// otherwise leave them behind (a write in progress at Ctrl-C left a hidden `.NAME.*.tmp`).
/// Each target stays as it was, or is already the whole new file.
pub fn end_writes() -> MutexGuard<'static, Vec<PathBuf>> {
    let writing = WRITING.lock().unwrap_or_else(PoisonError::into_inner);
    for path in writing.iter() {
        let _ = std::fs::remove_file(path);
    }
    writing
}

/// Writes `path` through `write`, which receives a buffered writer on a temporary file next to
/// it; the file replaces `path` only once `write` succeeded and its bytes are on the disk. On
/// any error the temporary file is removed and `path` is left untouched.
pub fn write_atomically<E: From<io::Error>>(
    path: &Path,
    write: impl FnOnce(&mut BufWriter<&File>) -> Result<(), E>,
) -> Result<(), E> {
    // Dropping the temporary file on an early return deletes it.
    let temporary = temporary_next_to(path).map_err(|error| {
        let message = format!("cannot create files in the folder {}: {error}", folder_of(path).display());
        io::Error::new(error.kind(), message)
    })?;
    // Registered before a byte is written; given up after the rename or the removal.
    let _writing = Writing::register(temporary.path());
    let mut out = BufWriter::new(temporary.as_file());
    write(&mut out)?;
    out.flush()?;
    drop(out);
    temporary.as_file().sync_all()?;
    temporary.persist(path).map_err(|e| e.error)?;
    Ok(())
}

/// Checks, before any work is done, that [`write_atomically`] can create `path`: its folder
/// exists and takes new files (tried by creating and removing a temporary file, which also
/// answers for root, read-only mounts and ACLs), and `path` is not itself a folder.
pub fn check_writable(path: &Path) -> Result<(), OutputError> {
    if path.is_dir() {
        return Err(OutputError::IsFolder(path.to_owned()));
    }
    temporary_next_to(path).map(drop).map_err(|error| OutputError::Folder {
        path: path.to_owned(),
        folder: folder_of(path),
        error,
    })
}

/// A new, empty file `.NAME.XXXXXX.tmp` in `path`'s folder (hidden, so a glob for the outputs
/// does not match it), with the permissions a newly created `path` would get. Its error is the
/// system's alone: `tempfile`'s own constructors append the temporary file's name, which means
/// nothing to a user who asked for `path` (`make_in` returns the opener's error as it is).
fn temporary_next_to(path: &Path) -> io::Result<tempfile::NamedTempFile> {
    let name = path.file_name().unwrap_or(path.as_os_str());
    let prefix = format!(".{}.", name.to_string_lossy());
    tempfile::Builder::new().prefix(&prefix).suffix(".tmp").make_in(folder_of(path), |temporary| {
        let mut options = File::options();
        options.read(true).write(true).create_new(true);
        // tempfile's default is 0600; outputs are shared like any other new file (umask
        // applies).
        #[cfg(unix)]
        std::os::unix::fs::OpenOptionsExt::mode(&mut options, 0o666);
        options.open(temporary)
    })
}

/// The folder `path` is in (`.` for a bare file name).
fn folder_of(path: &Path) -> PathBuf {
    match path.parent() {
        Some(parent) if !parent.as_os_str().is_empty() => parent.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn folder(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("igi-atomic-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    fn names_in(dir: &Path) -> Vec<String> {
        let mut names: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        names
    }

    #[test]
    fn a_failure_mid_write_leaves_the_earlier_file_and_no_temporary() {
        let dir = folder("mid-write");
        let path = dir.join("keep.png");
        std::fs::write(&path, b"the earlier image").unwrap();
        let result = write_atomically(&path, |out| -> io::Result<()> {
            out.write_all(&[7; 100_000])?;
            out.flush()?;
            Err(io::Error::new(io::ErrorKind::StorageFull, "injected: no space left"))
        });
        assert_eq!(result.unwrap_err().kind(), io::ErrorKind::StorageFull);
        assert_eq!(std::fs::read(&path).unwrap(), b"the earlier image");
        assert_eq!(names_in(&dir), ["keep.png"]);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_successful_write_replaces_the_file_with_the_usual_permissions() {
        let dir = folder("replace");
        let path = dir.join("out.json");
        std::fs::write(&path, b"old").unwrap();
        write_atomically(&path, |out| out.write_all(b"new")).unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"new");
        assert_eq!(names_in(&dir), ["out.json"]);
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            let plain = dir.join("plain");
            std::fs::write(&plain, b"").unwrap();
            let mode = |p: &Path| std::fs::metadata(p).unwrap().permissions().mode();
            assert_eq!(mode(&path), mode(&plain), "not the mode of a file created by fs::write");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn an_unwritable_target_fails_without_a_trace() {
        let dir = folder("unwritable");
        let path = dir.join("taken");
        std::fs::create_dir(&path).unwrap();
        std::fs::write(path.join("inside"), b"x").unwrap();
        // Renaming a file over a non-empty folder fails after the bytes were written.
        assert!(write_atomically(&path, |out| out.write_all(b"image")).is_err());
        assert_eq!(names_in(&dir), ["taken"]);
        assert_eq!(names_in(&path), ["inside"]);
        let err = check_writable(&path).unwrap_err();
        assert!(err.to_string().contains("taken"), "{err}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn missing_and_read_only_folders_are_refused_by_name() {
        let err = check_writable(Path::new("/nonexistent-igi-folder/x.png")).unwrap_err().to_string();
        assert!(
            err.contains(
                "/nonexistent-igi-folder/x.png: cannot create files in the folder /nonexistent-igi-folder"
            ),
            "{err}"
        );
        assert!(!err.contains(".tmp"), "names the temporary file: {err}");
        // A folder that vanishes between the check and the write: the same words, no
        // temporary file's name.
        let err = write_atomically(Path::new("/nonexistent-igi-folder/x.png"), |out| out.write_all(b"x"))
            .unwrap_err()
            .to_string();
        assert!(err.contains("cannot create files in the folder /nonexistent-igi-folder"), "{err}");
        assert!(!err.contains(".tmp"), "names the temporary file: {err}");
        let dir = folder("check");
        check_writable(&dir.join("x.png")).unwrap();
        assert_eq!(names_in(&dir), Vec::<String>::new(), "the check left a file");
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            std::fs::set_permissions(&dir, std::fs::Permissions::from_mode(0o555)).unwrap();
            // Root writes into read-only folders; the check then rightly passes.
            if std::fs::write(dir.join("probe"), b"").is_err() {
                let err = check_writable(&dir.join("x.png")).unwrap_err();
                assert!(err.to_string().contains(&*dir.to_string_lossy()), "{err}");
            } else {
                eprintln!("skipped the read-only folder: this user may write there anyway (root)");
            }
            std::fs::set_permissions(&dir, std::fs::Permissions::from_mode(0o755)).unwrap();
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
