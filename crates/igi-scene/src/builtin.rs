//! Scenes compiled into the binary, so that tests, benchmarks and a first `igi render` need no
//! files: [`builtin`] by name, [`builtin_names`] to list them, and [`builtin_spec`] for a name
//! with parameters (`power-plant:triangles=2M`).
//!
//! They are built from the same pieces as loaded scenes and pass through the same
//! [`MeshBuilder`](crate::validate::MeshBuilder), so they keep the same invariants.

mod animated_room;
mod cornell_box;
mod daylight;
mod displaced_sphere;
mod maple_tree;
mod power_plant;
mod procedural_room;
mod random;
mod shapes;
mod shirley_room;
mod two_rooms;

use std::path::Path;

use crate::error::{Location, SceneError};
use crate::model::Scene;

/// Names accepted by [`builtin`], in the order `igi` lists them.
const NAMES: &[&str] = &[
    "cornell-box",
    "shirley-room",
    "procedural-room",
    "procedural-room-lambert",
    "animated-room",
    "two-rooms",
    "power-plant",
    "maple-tree",
    "displaced-sphere",
];

/// The built-in scenes generated to a size, as a list for messages.
const GENERATED: &str = "power-plant, maple-tree, displaced-sphere";

/// Most triangles a generated scene's `triangles=` may ask for (about 6 GB of mesh and BVH).
pub const MAX_GENERATED_TRIANGLES: usize = 100_000_000;

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
///   for VPLs that start at the lights);
/// - `power-plant`: four instances of a generated 12.5-million-triangle industrial plant
///   (pipes, tanks, steel, a cooling tower) under a sun and a sky, 50 million triangles (the
///   paper's Figure 1, centre);
/// - `maple-tree`: a generated tree of 1.5 million triangles, mostly leaves, over a meadow
///   under a sun and a sky (the paper's Figure 1, right);
/// - `displaced-sphere`: a bumpy sphere of a million flat triangles over a floor under a
///   point light, the scene of `igi bench scale`.
///
/// The three generated scenes take their default size here; [`builtin_spec`] sets it.
pub fn builtin(name: &str) -> Option<Scene> {
    match name {
        "power-plant" => Some(power_plant::scene(power_plant::DEFAULT_TRIANGLES)),
        "maple-tree" => Some(maple_tree::scene(maple_tree::DEFAULT_TRIANGLES)),
        "displaced-sphere" => Some(displaced_sphere::scene(displaced_sphere::DEFAULT_TRIANGLES)),
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

/// The built-in scene name closest to `spec` (its part before any `:`), if one is close enough
/// to be what was meant: a Jaro-Winkler similarity of at least 0.8, ignoring case (as
/// `cornel-box`, `Maple-Tree` or `shirley` are to theirs).
pub fn closest_builtin(spec: &str) -> Option<&'static str> {
    let name = spec.split(':').next().unwrap_or(spec).to_lowercase();
    NAMES
        .iter()
        .map(|&candidate| (strsim::jaro_winkler(&name, candidate), candidate))
        .filter(|&(similarity, _)| similarity >= 0.8)
        .max_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, candidate)| candidate)
}

/// The built-in scene `spec` asks for, if its name (before any `:`) is one of
/// [`builtin_names`]: a plain name as [`builtin`] gives it, or a generated scene's name with
/// its triangle count, `power-plant:triangles=N`, `maple-tree:triangles=N` or
/// `displaced-sphere:triangles=N` (N a whole
/// number, or with a `k` or `M` suffix: `500k`, `12.5M`). For the power plant N counts one of
/// its four instances. An error names what is wrong with the parameter.
pub fn builtin_spec(spec: &str) -> Option<Result<Scene, SceneError>> {
    let (name, parameters) = spec.split_once(':').unwrap_or((spec, ""));
    if !NAMES.contains(&name) {
        return None;
    }
    if parameters.is_empty() {
        return builtin(name).map(Ok);
    }
    let error = |message: String| SceneError::invalid(Path::new(spec), Location::File, message);
    let minimum = match name {
        "power-plant" => power_plant::minimum_triangles(),
        "maple-tree" => maple_tree::minimum_triangles(),
        "displaced-sphere" => displaced_sphere::MINIMUM_TRIANGLES,
        _ => {
            let message = format!("`{name}` takes no parameters (only the generated scenes do: {GENERATED})");
            return Some(Err(error(message)));
        }
    };
    let triangles = match parameters.strip_prefix("triangles=").map(parse_count) {
        Some(Some(n)) => n,
        Some(None) => {
            return Some(Err(error(
                "`triangles=` wants a whole number such as 2000000, 500k or 12.5M".into(),
            )));
        }
        None => {
            return Some(Err(error(format!(
                "unknown parameter `{parameters}`; `{name}` takes `triangles=N`"
            ))));
        }
    };
    if !(minimum..=MAX_GENERATED_TRIANGLES).contains(&triangles) {
        let message = format!(
            "`triangles={triangles}`: `{name}` is made of {minimum} to {MAX_GENERATED_TRIANGLES} triangles"
        );
        return Some(Err(error(message)));
    }
    Some(Ok(match name {
        "power-plant" => power_plant::scene(triangles),
        "maple-tree" => maple_tree::scene(triangles),
        _ => displaced_sphere::scene(triangles),
    }))
}

/// A count written as digits, or as a decimal number with a `k` (thousand) or `M` (million)
/// suffix.
fn parse_count(text: &str) -> Option<usize> {
    let (number, scale) = match text.strip_suffix(['k', 'K']) {
        Some(number) => (number, 1e3),
        None => match text.strip_suffix('M') {
            Some(number) => (number, 1e6),
            None => return text.parse().ok().filter(|_| text.chars().all(|c| c.is_ascii_digit())),
        },
    };
    if number.is_empty() || !number.chars().all(|c| c.is_ascii_digit() || c == '.') {
        return None;
    }
    let value = (number.parse::<f64>().ok()? * scale).round();
    (value <= MAX_GENERATED_TRIANGLES as f64 * 10.0).then_some(value as usize)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_name_builds() {
        for name in builtin_names() {
            // The generated scenes at a small size: their default takes seconds and gigabytes.
            let scene = match *name {
                "power-plant" | "maple-tree" => {
                    builtin_spec(&format!("{name}:triangles=600k")).unwrap().unwrap()
                }
                _ => builtin(name).unwrap(),
            };
            assert!(scene.triangle_count() > 0, "{name}");
            assert!(scene.camera.is_some(), "{name}");
            let lit = scene.emissive_triangle_count() > 0 || !scene.lights.is_empty();
            assert!(lit, "{name} has a light");
        }
        assert!(builtin("cornell").is_none());
    }

    #[test]
    fn specs_set_the_size_of_generated_scenes_and_refuse_what_they_cannot_be() {
        assert_eq!(parse_count("12.5M"), Some(12_500_000));
        assert_eq!(parse_count("500k"), Some(500_000));
        assert_eq!(parse_count("2000"), Some(2000));
        assert_eq!(parse_count("1.1M"), Some(1_100_000));
        for bad in ["", "k", "1.5", "-3", "1e9", "2G", "1..2M"] {
            assert_eq!(parse_count(bad), None, "{bad}");
        }
        let tree = builtin_spec("maple-tree:triangles=300k").unwrap().unwrap();
        assert!(tree.triangle_count() <= 300_002 && tree.triangle_count() > 299_000);
        assert!(builtin_spec("scenes/maple-tree.obj").is_none());
        for (spec, says) in [
            ("maple-tree:leaves=3", "unknown parameter `leaves=3`"),
            ("maple-tree:triangles=lots", "whole number"),
            ("maple-tree:triangles=10", "is made of"),
            ("power-plant:triangles=1000M", "is made of"),
            ("cornell-box:triangles=5", "takes no parameters"),
        ] {
            let message = builtin_spec(spec).unwrap().unwrap_err().to_string();
            assert!(message.starts_with(spec) && message.contains(says), "{message}");
        }
    }
}
