//! [`scene_files_under`]: the scene files a folder holds, for the viewers' list of scenes to
//! open (a browser picks from this list and never names a path itself).

use std::path::Path;

use crate::format::{Format, format_of};
use crate::scene_file::is_scene_file;

/// Most files listed: a folder of thousands of meshes (a fuzzing corpus, say) lists its first.
pub const MAX_CATALOG_FILES: usize = 200;
/// Folder levels looked into below the folder itself.
const MAX_DEPTH: usize = 2;
/// Folders not looked into besides hidden ones: build output and packages.
const SKIPPED: [&str; 2] = ["target", "node_modules"];

/// The files under `folder` that igi loads (mesh files by extension, as [`crate::load`]
/// decides; `.toml` files only if they hold a scene file's tables, not a `Cargo.toml`), as
/// paths relative to it with `/` between components, sorted; at most [`MAX_CATALOG_FILES`],
/// at most two folder levels deep (`a/b/scene.obj`), not in hidden folders, `target` or `node_modules`, not
/// through symbolic links to folders (a link loop, or a link out of the folder). A folder that
/// cannot be read lists nothing.
pub fn scene_files_under(folder: &Path) -> Vec<String> {
    let walk = walkdir::WalkDir::new(folder).max_depth(MAX_DEPTH + 1).sort_by_file_name().into_iter();
    let mut names: Vec<String> = walk
        .filter_entry(|e| {
            let name = e.file_name().to_string_lossy();
            e.depth() == 0
                || !(name.starts_with('.') || (e.file_type().is_dir() && SKIPPED.contains(&&*name)))
        })
        .filter_map(Result::ok)
        .filter(|e| {
            e.file_type().is_file()
                && match format_of(e.path()) {
                    Some(Format::SceneFile) => is_scene_file(e.path()),
                    Some(Format::Mesh(_)) => true,
                    None => false,
                }
        })
        .filter_map(|e| name_under(folder, e.path()))
        .take(MAX_CATALOG_FILES)
        .collect();
    names.sort();
    names
}

/// The name [`scene_files_under`] gives `path` under `folder`: its path relative to `folder`
/// with `/` between components; `None` if it is not under `folder` or not UTF-8.
pub fn name_under(folder: &Path, path: &Path) -> Option<String> {
    let parts: Option<Vec<&str>> =
        path.strip_prefix(folder).ok()?.components().map(|c| c.as_os_str().to_str()).collect();
    Some(parts?.join("/"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lists_scene_files_by_relative_path_and_skips_the_rest() {
        let dir = tempfile::tempdir().unwrap();
        let root = dir.path();
        for (file, text) in [
            ("a.toml", "[camera]\nposition = [0, 1, 2]\ntarget = [0, 0, 0]\nfov = 40\n"),
            ("Cargo.toml", "[package]\nname = \"x\"\n"),
        ] {
            std::fs::write(root.join(file), text).unwrap();
        }
        for file in [
            "scenes/b.obj",
            "scenes/deep/c.glb",
            "x/y/z/too-deep.ply",
            "notes.txt",
            ".hidden/d.obj",
            "target/e.ply",
            "node_modules/f.gltf",
        ] {
            let path = root.join(file);
            std::fs::create_dir_all(path.parent().unwrap()).unwrap();
            std::fs::write(path, "").unwrap();
        }
        assert_eq!(scene_files_under(root), ["a.toml", "scenes/b.obj", "scenes/deep/c.glb"]);
        assert!(scene_files_under(&root.join("missing")).is_empty());
    }

    #[test]
    fn a_large_folder_lists_at_most_the_limit() {
        let dir = tempfile::tempdir().unwrap();
        for i in 0..MAX_CATALOG_FILES + 10 {
            std::fs::write(dir.path().join(format!("m{i:04}.ply")), "").unwrap();
        }
        assert_eq!(scene_files_under(dir.path()).len(), MAX_CATALOG_FILES);
    }
}
