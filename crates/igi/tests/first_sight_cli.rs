//! The command line's side of a scene's first sight (issue 14): `igi info` prints the camera
//! renders start with as a scene-file snippet that, pasted into a scene file, gives the same
//! camera; `igi render` says in one warning what light it added and which flag turns it off,
//! and with that flag adds nothing.

use std::path::PathBuf;
use std::process::Command;

const IGI: &str = env!("CARGO_BIN_EXE_igi");

/// A folder with an OBJ file of a closed box (no camera, no light).
fn box_scene(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("igi-first-sight-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let mut obj = String::new();
    for x in [-1.0, 1.0] {
        for y in [0.0, 1.0] {
            for z in [-0.5, 0.5] {
                obj += &format!("v {x} {y} {z}\n");
            }
        }
    }
    // The six faces, wound outward (vertex k has x = bit 2, y = bit 1, z = bit 0).
    obj += "f 1 2 4 3\nf 5 7 8 6\nf 1 5 6 2\nf 3 4 8 7\nf 1 3 7 5\nf 2 6 8 4\n";
    std::fs::write(dir.join("box.obj"), obj).unwrap();
    dir
}

fn run(args: &[&str]) -> (String, String) {
    let out = Command::new(IGI).args(args).env("NO_COLOR", "1").output().unwrap();
    assert!(out.status.success(), "igi {args:?}: {}", String::from_utf8_lossy(&out.stderr));
    (String::from_utf8(out.stdout).unwrap(), String::from_utf8(out.stderr).unwrap())
}

#[test]
fn info_prints_the_default_camera_as_a_scene_file_snippet_that_gives_it_back() {
    let dir = box_scene("info");
    let obj = dir.join("box.obj");
    let (info, _) = run(&["info", obj.to_str().unwrap()]);
    let snippet: String = info
        .lines()
        .skip_while(|l| !l.starts_with("camera"))
        .skip(1)
        .take_while(|l| l.starts_with("  "))
        .map(|l| format!("{}\n", l.trim()))
        .collect();
    assert!(snippet.starts_with("[camera]\nposition = ["), "{info}");
    assert!(info.contains("default light the scene has no light source: added a sun and a sky"), "{info}");
    // Pasted into a scene file beside the mesh, the snippet is the camera the render used.
    let file = dir.join("box.toml");
    std::fs::write(&file, format!("{snippet}\n[[mesh]]\nfile = \"box.obj\"\n")).unwrap();
    let (again, _) = run(&["info", file.to_str().unwrap()]);
    let camera = |text: &str| {
        text.lines().skip_while(|l| !l.starts_with("camera")).skip(1).take(5).collect::<Vec<_>>().join("\n")
    };
    assert_eq!(camera(&again), camera(&info), "{again}");
    assert!(again.contains("camera       the scene's"), "{again}");
}

#[test]
fn render_says_which_light_it_added_and_the_flag_turns_it_off() {
    let dir = box_scene("render");
    let obj = dir.join("box.obj");
    let png = dir.join("out.png");
    let cheap = ["--width", "32", "--height", "24", "--aa", "1", "--frames", "1"];
    let mut args = vec!["render", obj.to_str().unwrap(), "-o", png.to_str().unwrap()];
    args.extend(cheap);
    let (_, log) = run(&args);
    let warnings: Vec<&str> = log.lines().filter(|l| l.contains("added a sun and a sky")).collect();
    assert_eq!(warnings.len(), 1, "one warning: {log}");
    assert!(warnings[0].contains("--no-default-light"), "{log}");
    args.push("--no-default-light");
    let (_, log) = run(&args);
    assert!(!log.contains("added"), "{log}");
    assert!(log.contains("--no-default-light leaves it dark"), "{log}");
}

/// A folder with an OBJ room 4 × 2 × 3 (walls facing in) lit by a lamp under its ceiling.
fn lit_room(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("igi-first-sight-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let mut obj = String::from("mtllib room.mtl\n");
    for x in [-2.0, 2.0] {
        for y in [0.0, 2.0] {
            for z in [-1.5, 1.5] {
                obj += &format!("v {x} {y} {z}\n");
            }
        }
    }
    // The six faces wound inward (the box of `box_scene` turned inside out), then the lamp:
    // a square facing down just under the ceiling.
    obj += "usemtl wall\nf 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n";
    obj += "v -0.5 1.95 -0.5\nv 0.5 1.95 -0.5\nv 0.5 1.95 0.5\nv -0.5 1.95 0.5\n";
    obj += "usemtl lamp\nf 9 10 11 12\n";
    std::fs::write(dir.join("room.obj"), obj).unwrap();
    std::fs::write(dir.join("room.mtl"), "newmtl wall\nKd 0.7 0.7 0.7\nnewmtl lamp\nKd 0 0 0\nKe 20 20 20\n")
        .unwrap();
    dir
}

#[test]
fn the_default_light_is_judged_from_the_camera_the_options_ask_for() {
    // Issue 34: the decision was made from the scene's start camera, so a camera asked for
    // outside a lit room (Lost Empire's hill from outside) rendered black without a word.
    let dir = lit_room("asked");
    let obj = dir.join("room.obj");
    let png = dir.join("out.png");
    let cheap = ["--width", "32", "--height", "24", "--aa", "1", "--frames", "1"];
    let mut args = vec!["render", obj.to_str().unwrap(), "-o", png.to_str().unwrap()];
    args.extend(cheap);
    let (_, log) = run(&args);
    assert!(!log.contains("added"), "the lamp lights the room seen from inside: {log}");
    args.extend(["--camera-position=0,6,12", "--camera-target=0,1,0"]);
    let (_, log) = run(&args);
    assert!(log.contains("reach little of what the camera sees: added a sun and a sky"), "{log}");
}
