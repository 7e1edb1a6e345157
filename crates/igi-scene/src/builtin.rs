//! Scenes compiled into the binary, so that tests, benchmarks and a first `igi render` need no
//! files: [`builtin`] by name, [`builtin_names`] to list them.
//!
//! They are built from the same pieces as loaded scenes and pass through the same
//! [`MeshBuilder`](crate::validate::MeshBuilder), so they keep the same invariants.

mod animated_room;
mod cornell_box;
mod procedural_room;
mod shapes;
mod shirley_room;
mod two_rooms;

use crate::model::Scene;

/// Names accepted by [`builtin`], in the order `igi` lists them.
const NAMES: &[&str] = &[
    "cornell-box",
    "shirley-room",
    "procedural-room",
    "procedural-room-lambert",
    "animated-room",
    "two-rooms",
];

/// The built-in scene called `name`, if there is one:
/// - `cornell-box`: the geometry, materials, light and camera of the McGuire archive's
///   `CornellBox-Original` (36 triangles), the project's reference scene;
/// - `shirley-room`: a closed 5 × 3 × 5 m room lit by a ceiling quad, with boxes, a table and
///   a sphere, in the spirit of the "Shirley" test scenes of the interactive GI papers
///   (about 700 triangles);
/// - `procedural-room`: a closed 6 × 3 × 6 m room showing the procedural shaders of paper 3.2
///   (marble floor, bump-mapped brick walls, a wooden table, a glossy turbulence sphere, a
///   checkered box), lit by a ceiling quad and a point light (710 triangles);
/// - `procedural-room-lambert`: the same room with constant Lambert materials of about the
///   patterns' mean colours, the baseline for the cost of procedural shading;
/// - `animated-room`: a 6 × 3 × 6 m room with a swinging area lamp, a turning statue and a
///   point light circling it while changing colour (paper Figure 1, left), the dynamic scene;
/// - `two-rooms`: two 4 × 2.8 × 4 m rooms joined by a doorway, the lamp in one and the camera
///   in the other, which sees only light that came through the door and bounced (the hard case
///   for VPLs that start at the lights).
pub fn builtin(name: &str) -> Option<Scene> {
    match name {
        "cornell-box" => Some(cornell_box::scene()),
        "shirley-room" => Some(shirley_room::scene()),
        "procedural-room" => Some(procedural_room::scene()),
        "procedural-room-lambert" => Some(procedural_room::lambert_scene()),
        "animated-room" => Some(animated_room::scene()),
        "two-rooms" => Some(two_rooms::scene()),
        _ => None,
    }
}

/// The names [`builtin`] accepts.
pub fn builtin_names() -> &'static [&'static str] {
    NAMES
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_name_builds() {
        for name in builtin_names() {
            let scene = builtin(name).unwrap();
            assert!(scene.triangle_count() > 0, "{name}");
            assert!(scene.camera.is_some(), "{name}");
            assert!(scene.emissive_triangle_count() > 0, "{name} has a light");
        }
        assert!(builtin("cornell").is_none());
    }
}
