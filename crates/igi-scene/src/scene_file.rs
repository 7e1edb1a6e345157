//! Scene files: a TOML description that places mesh files, adds lights and sets the camera.
//!
//! ```toml
//! [camera]
//! position = [0, 1, 3.5]
//! target = [0, 1, 0]
//! up = [0, 1, 0]                 # optional, default +Y
//! fov = 39.3                     # optional, default 40: vertical, degrees
//!
//! [[view]]                       # optional, any number: named cameras (saved views)
//! name = "from the door"         # unique; `igi render --view NAME`, the viewers' list
//! position = [0, 1.6, 5]         # and the fields of [camera]
//! target = [0, 1, 0]
//! fov = 50
//!
//! [[mesh]]
//! file = "CornellBox-Original.obj"          # .obj .gltf .glb .ply, relative to this file
//! translate = [0, 0, 0]                     # optional
//! rotate = [0, 90, 0]                       # optional, degrees about X, Y, Z
//! scale = 2.0                               # optional, or [sx, sy, sz]
//! instances = [ { translate = [3, 0, 0] }, { rotate = [0, 45, 0] } ]   # optional
//! material = { diffuse = [0.8, 0.8, 0.8] }  # optional: replaces every material of the file
//!
//! [mesh.animation]                          # optional: keyframes of translate/rotate/scale
//! interpolation = "smooth"                  # step | linear (default) | smooth
//! loop = true                               # default true: repeat after the last key
//! keys = [ { time = 0, rotate = [0, 0, 0] }, { time = 4, rotate = [0, 360, 0] } ]
//!
//! [[light]]
//! type = "quad"                  # quad | point | spot | directional
//! position = [350, 640, -210]    # quad: centre
//! u = [400, 0, 0]                # quad: half-edge vectors; emits toward normalize(u × v)
//! v = [0, 0, 200]
//! radiance = [10, 10, 10]        # W/(sr m²)
//! # point: position, intensity = [r, g, b] (W/sr)
//! # spot: position, direction, angle (full cone, degrees), intensity
//! # directional: direction (the way the light travels), irradiance = [r, g, b] (W/m²)
//! # animation = { interpolation = "linear", loop = true, keys = [ { time = 0, ... } ] }:
//! #   quad: position, rotate (about its centre); point: position, intensity;
//! #   spot: position, direction, intensity; directional: direction, irradiance
//!
//! [[shader]]
//! target = "floor"               # a material name, or else a mesh name
//! type = "marble"                # checker | marble | wood | brick | turbulence
//! scale = 2.0                    # optional, default 1: pattern features per unit length
//! colors = [[0.9, 0.9, 0.85], [0.3, 0.3, 0.35]]   # optional, default [[0.8]*3, [0.2]*3]
//! specular = [0.05, 0.05, 0.05]  # optional, default [0, 0, 0]: the glossy lobe's reflectance
//! exponent = 40.0                # optional, default 20
//! bump = 0.002                   # optional, default 0 (no bump)
//! # marble: octaves (default 4), turbulence (default 5)
//! # wood: rings (default 4), turbulence (default 0.5)
//! # brick: size = [x, y, z] (default [3, 1, 1.5]), mortar (default 0.1)
//! # turbulence: octaves (default 4)
//!
//! [environment]                  # optional: what rays leaving the scene see
//! color = [0.4, 0.6, 1.0]        # a constant sky radiance (W/(sr m²), may exceed 1), or
//! # file = "sky.hdr"             # an equirectangular image relative to this file (.hdr,
//! # intensity = 1.0              # .exr, or LDR .png/.jpg read as sRGB), with optional
//! # rotate = 0.0                 # factor (default 1) and turn about +Y in degrees
//! ```
//!
//! Transforms: `translate`, `rotate` and `scale` make T·R·S, with R = Rz·Ry·Rx, i.e. the
//! rotation about X is applied first, then Y, then Z, all about the fixed world axes. Each
//! entry of `instances` is a transform of the same form applied *after* the mesh's own, so a
//! placement is `instance · mesh`: the mesh transform fits the file into the scene (units,
//! up axis), the instances then place copies of it. A mesh file's own instances (glTF nodes)
//! come first of all, and its lights and camera move with it. Without `instances` the mesh
//! is placed once. A `material` replaces every material of the file (useful for PLY, which has
//! none), and then the file's own materials and textures are dropped.
//!
//! Animation: each key sets a time in seconds and any of the fields its entry may animate;
//! each field is a track over the keys that set it, and replaces the entry's own value (a
//! keyed `rotate` replaces the mesh's `rotate`, and so on). Rotations are keyed as angles, so
//! a turn from 0 to 360 degrees is one revolution. `smooth` is a Catmull-Rom spline that
//! eases in and out at the first and last key ([`crate::animation`]). A looping entry
//! repeats with the period of its last key. An animated mesh moves everything its file
//! contains, glTF animations included, and `instances` place copies that move alike.
//!
//! The camera of the scene file wins; without one, the first mesh file's camera (glTF) is
//! used. The views are the scene file's `[[view]]`s, then those of the mesh files (glTF
//! cameras, placed like their file's first instance; renamed `NAME (2)` where a name is
//! taken). A quad light becomes a mesh of two one-sided emissive triangles whose geometric
//! normal is normalize(u × v), with a black diffuse emissive material and an identity instance.
//!
//! A `[[shader]]` gives a procedural [`ShaderDesc`](crate::ShaderDesc) to the materials its
//! `target` names, after every mesh and light is in place; entries apply in order, so a later
//! one wins. The target is looked up among material names first (OBJ `newmtl`, glTF material
//! names, the `light[i]` material of a quad light), and every material of that name gets the
//! shader. If no material has that name, it is looked up among mesh names (a glTF mesh name, an
//! OBJ or PLY file's stem, `light[i]`): the triangles of those meshes get their own copies of
//! their materials carrying the shader, so other meshes sharing a material keep it unchanged. A
//! target that matches neither is an error. Colours and `specular` are reflectances in [0, 1];
//! `octaves` is 1 to 16; `scale`, `rings` and the brick `size` must be positive; `mortar` must
//! be narrower than every brick dimension.
//!
//! `[environment]` takes `color` or `file`, not both; `intensity` and `rotate` only go with
//! `file`. The image's mapping and rotation are those of [`Environment`](crate::Environment).
//! Unlike a material's texture, an environment image that is missing or cannot be decoded is an
//! error: without it the scene has different lighting, not just a different-looking surface.
//!
//! Unknown fields are errors (a typo like `rotation` must not be silently ignored), and every
//! error names the scene file, the line and the field.
//!
//! The submodules: `schema` (the tables as written), `checker` (checks of values, errors that
//! point at a field's line, with `field_spans`), `keyframes` (`animation` tables), and one per
//! kind of entry: `placement` (`[[mesh]]`), `lights`, `shaders` and `environment`.

mod checker;
mod environment;
mod field_spans;
mod keyframes;
mod lights;
mod placement;
mod schema;
mod shaders;

use std::path::Path;

use toml::Spanned;

use crate::error::{Location, SceneError};
use crate::model::{Camera, SavedView, Scene};
use crate::report::LoadReport;
use crate::resources;
use crate::texture::TextureSet;
use crate::validate::MAX_INSTANCES;
use checker::{Checker, toml_error};
use schema::{CameraSpec, SceneSpec, ViewSpec};

/// Loads a scene file whose textures (those of every mesh file and the sky's) go into
/// `textures`, so each image is decoded once for the whole scene and within one budget.
pub(crate) fn load_into(
    path: &Path,
    textures: &mut TextureSet,
    report: &mut LoadReport,
) -> Result<Scene, SceneError> {
    // Refused before it is read if it is too large (`check_size` bounds text from memory).
    let bytes = resources::read_at_most(path, MAX_SCENE_FILE_BYTES as u64, report)?;
    let text = std::str::from_utf8(&bytes)
        .map_err(|e| SceneError::parse(path, Location::File, format!("not UTF-8 text: {e}")))?;
    parse_file(text, path, Some(&resources::base_dir(path)), textures, report)
}

/// Parses scene-file text; `name` is used in messages. Mesh files are looked up in
/// `base_dir`; with `None` their entries are checked but no file is read (with a warning).
pub fn parse(
    text: &str,
    name: &str,
    base_dir: Option<&Path>,
    report: &mut LoadReport,
) -> Result<Scene, SceneError> {
    TextureSet::default().owning(|textures| parse_file(text, Path::new(name), base_dir, textures, report))
}

/// Parses the scene-file text of `file`: the meshes, then the lights, then the shaders (every
/// mesh and light is in place, so a target can name any of them), the sky and the camera.
fn parse_file(
    text: &str,
    file: &Path,
    base_dir: Option<&Path>,
    textures: &mut TextureSet,
    report: &mut LoadReport,
) -> Result<Scene, SceneError> {
    check_size(text, file)?;
    let spec: SceneSpec = toml::from_str(text).map_err(|e| toml_error(&e, text, file))?;
    let check = Checker { file, text };
    let mut scene = Scene::default();
    for (index, entry) in spec.mesh.iter().enumerate() {
        placement::add_mesh(&check, &mut scene, index, entry, base_dir, textures, report)?;
    }
    for (index, entry) in spec.light.iter().enumerate() {
        lights::add_light(&check, &mut scene, index, entry)?;
    }
    // Without a base directory no mesh file was read, so a target may name a material of a
    // file that was skipped: warn rather than fail.
    let files_skipped = base_dir.is_none() && !spec.mesh.is_empty();
    for (index, entry) in spec.shader.iter().enumerate() {
        shaders::add_shader(&check, &mut scene, index, entry, files_skipped, report)?;
    }
    if let Some(environment) = &spec.environment {
        scene.environment = environment::environment_from(&check, textures, environment, base_dir, report)?;
    }
    if let Some(camera) = &spec.camera {
        scene.camera = Some(camera_from(&check, camera.span(), camera.get_ref(), "camera")?);
    }
    let from_files = std::mem::take(&mut scene.views);
    for (index, view) in spec.view.iter().enumerate() {
        scene.views.push(view_from(&check, &scene.views, index, view)?);
    }
    for view in from_files {
        let name = SavedView::free_name(&scene.views, view.name);
        scene.views.push(SavedView { name, ..view });
    }
    Ok(scene)
}

/// `[[view]]` entry `index`, whose name none of `views` (the entries before it) has.
fn view_from(
    check: &Checker,
    views: &[SavedView],
    index: usize,
    view: &Spanned<ViewSpec>,
) -> Result<SavedView, SceneError> {
    let field = format!("view[{index}]");
    let spec = view.get_ref();
    if spec.name.trim().is_empty() {
        return Err(check.error(&view.span(), format!("{field}.name"), "must not be empty"));
    }
    if let Some(earlier) = views.iter().position(|v| v.name == spec.name) {
        return Err(check.error(
            &view.span(),
            format!("{field}.name"),
            format!("\"{}\" is already the name of view[{earlier}]", spec.name),
        ));
    }
    let camera = camera_from(check, view.span(), &spec.camera(), &field)?;
    Ok(SavedView { name: spec.name.clone(), camera })
}

/// The camera of `spec`, checked; errors name `field` (`camera`, `view[2]`) and `span`'s line.
fn camera_from(
    check: &Checker,
    span: std::ops::Range<usize>,
    spec: &CameraSpec,
    field: &str,
) -> Result<Camera, SceneError> {
    let camera = Camera {
        position: spec.position.into(),
        target: spec.target.into(),
        up: spec.up.into(),
        fov_y_deg: spec.fov,
    };
    camera.check().map_err(|d| check.error(&span, format!("{field}.{}", d.field), d.problem))?;
    Ok(Camera { up: camera.up.normalize(), ..camera })
}

/// True if `path` holds a scene file as far as its tables go: TOML that parses into a scene
/// file's tables ([`SceneSpec`]), so that a folder's `Cargo.toml` or a tool's settings are not
/// offered as scenes. Nothing is loaded and no value is checked beyond its type; a file over
/// the size limit, or unreadable, is not one.
pub(crate) fn is_scene_file(path: &Path) -> bool {
    let small = std::fs::metadata(path).is_ok_and(|m| m.len() <= MAX_SCENE_FILE_BYTES as u64);
    let Some(text) = small.then(|| std::fs::read_to_string(path).ok()).flatten() else { return false };
    check_size(&text, path).is_ok() && toml::from_str::<SceneSpec>(&text).is_ok()
}

/// Largest scene file. Scene files place and light meshes that live in files of their own;
/// a scene of [`MAX_INSTANCES`] instances takes a few MiB.
const MAX_SCENE_FILE_BYTES: usize = 16 << 20;
/// Most tables a scene file may hold, inline (`{ ... }`), in arrays (`[[light]]`), headed
/// (`[camera]`) or made by a dotted key (`a.b = 1` makes the table `a`): one per instance, and
/// as many again for keyframes, materials, lights and views.
const MAX_TABLES: usize = 2 * MAX_INSTANCES;

/// Bounds what parsing `text` can take before it is parsed. `toml` holds each table of a
/// document in a map of about a kilobyte, so a file of ten million short `{}`, `[[x]]` or
/// `a.b = 1` entries would take gigabytes before the instance count or an unknown field could
/// be checked. The tables are counted by `toml`'s own event parser, which builds nothing.
fn check_size(text: &str, file: &Path) -> Result<(), SceneError> {
    let refuse = |message: String| Err(SceneError::invalid(file, Location::File, message));
    if text.len() > MAX_SCENE_FILE_BYTES {
        return refuse(format!(
            "{} bytes; a scene file may have at most {MAX_SCENE_FILE_BYTES} (meshes belong in mesh files)",
            text.len()
        ));
    }
    let tables = count_tables(text);
    if tables > MAX_TABLES {
        return refuse(format!(
            "{tables} tables (`{{ ... }}`, `[...]`, `[[...]]` and each `.` of a dotted key); a scene \
             file may have at most {MAX_TABLES} (a scene at most {MAX_INSTANCES} instances)"
        ));
    }
    Ok(())
}

/// The tables parsing `text` makes at most: one per header, inline table and array-of-tables
/// element, and one per key separator (each dot of a dotted key names a table). Syntax errors
/// are left to the parse that follows.
fn count_tables(text: &str) -> usize {
    use toml_parser::parser::EventReceiver;
    use toml_parser::{ErrorSink, Span};
    struct Count(usize);
    impl EventReceiver for Count {
        fn std_table_open(&mut self, _: Span, _: &mut dyn ErrorSink) {
            self.0 += 1;
        }
        fn array_table_open(&mut self, _: Span, _: &mut dyn ErrorSink) {
            self.0 += 1;
        }
        fn inline_table_open(&mut self, _: Span, _: &mut dyn ErrorSink) -> bool {
            self.0 += 1;
            true
        }
        fn key_sep(&mut self, _: Span, _: &mut dyn ErrorSink) {
            self.0 += 1;
        }
    }
    // `toml`'s own nesting limit: deeper arrays and inline tables are its error to report,
    // and a parser without the guard recurses until the stack overflows (10,000 `[`).
    const MAX_DEPTH: u32 = 80;
    let tokens = toml_parser::Source::new(text).lex().into_vec();
    let mut count = Count(0);
    let mut guarded = toml_parser::parser::RecursionGuard::new(&mut count, MAX_DEPTH);
    toml_parser::parser::parse_document(&tokens, &mut guarded, &mut ());
    count.0
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `text` parsed from memory as `s.toml`.
    pub(super) fn parse_str(text: &str) -> Result<Scene, SceneError> {
        parse(text, "s.toml", None, &mut LoadReport::default())
    }

    #[test]
    fn tables_are_counted_where_toml_makes_them() {
        // `a` (a dotted key's), `d`, `e`, the inline table and `g` (one dot each).
        assert_eq!(count_tables("a.b = 1\n[d.e]\nf = { g.h = 1.5 }\n"), 5);
        // A float's dot and a dot in a string make none; each `[[x]]` element makes one.
        assert_eq!(count_tables("x = 1.25\ny = \"a.b.c\"\n[[z]]\n[[z]]\n"), 2);
        // Deep nesting is toml's error to report, not a stack overflow.
        let deep = format!("a = {}{}\n", "[".repeat(100_000), "]".repeat(100_000));
        assert!(count_tables(&deep) == 0 && parse_str(&deep).unwrap_err().to_string().contains("recursion"));
        let deep = format!("a = {}1{}\n", "{b = ".repeat(100_000), "}".repeat(100_000));
        assert!(count_tables(&deep) <= 82 && parse_str(&deep).unwrap_err().to_string().contains("recursion"));
    }

    #[test]
    fn unknown_fields_are_named_with_their_line() {
        let err = parse_str("[camera]\nposition = [0, 1, 3.5]\ntarget = [0, 1, 0]\nfov = 39.3\nzoom = 2\n")
            .unwrap_err();
        let text = err.to_string();
        assert!(text.starts_with("s.toml: line 5, field `camera.zoom`: "), "{text}");
        assert!(text.contains("unknown field `zoom`"), "{text}");

        let err = parse_str("[[light]]\ntype = \"point\"\nposition = [0, 0, 0]\nintensity = [1, 1, 1]\n\n[[light]]\ntype = \"point\"\nposition = [0, 0, 0]\npower = [1, 1, 1]\n").unwrap_err();
        let text = err.to_string();
        assert!(text.contains("line 9, field `light[1].power`"), "{text}");
    }

    #[test]
    fn malformed_toml_names_the_line() {
        let err = parse_str("[camera]\nposition = [0, 1,\n").unwrap_err();
        assert!(err.to_string().starts_with("s.toml: line "), "{err}");
        let err =
            parse_str("[camera]\nposition = [0, 1, 3]\ntarget = [0, 1, 0]\nfov = \"wide\"\n").unwrap_err();
        assert!(err.to_string().contains("line 4, field `camera.fov`"), "{err}");
        let err = parse_str("[[mesh]]\nfile = \"a.obj\"\nscale = \"big\"\n").unwrap_err();
        assert_eq!(
            err.to_string(),
            "s.toml: line 3, field `mesh[0].scale`: expected a number or an array of three numbers"
        );
    }

    /// `fov` has an obvious default (a normal lens), so a camera without it is not an error;
    /// the checks of the other fields stay.
    #[test]
    fn a_camera_without_fov_has_the_default_one() {
        let scene = parse_str("[camera]\nposition = [0, 1, 3.5]\ntarget = [0, 1, 0]\n").unwrap();
        assert_eq!(scene.camera.map(|c| c.fov_y_deg), Some(schema::DEFAULT_FOV));
        let scene =
            parse_str("[[view]]\nname = \"door\"\nposition = [0, 1, 3.5]\ntarget = [0, 1, 0]\n").unwrap();
        assert_eq!(scene.views[0].camera.fov_y_deg, schema::DEFAULT_FOV);
        let err = parse_str("[camera]\nposition = [0, 1, 3.5]\n").unwrap_err();
        assert!(err.to_string().contains("missing field `target`"), "{err}");
        let err = parse_str("[camera]\nposition = [0, 1, 0]\ntarget = [0, 1, 0]\n").unwrap_err();
        assert!(err.to_string().contains("field `camera.target`"), "{err}");
    }

    #[test]
    fn semantic_errors_name_the_field() {
        let err = parse_str("[[light]]\ntype = \"spot\"\nposition = [0, 0, 0]\ndirection = [0, 0, 0]\nangle = 30\nintensity = [1, 1, 1]\n").unwrap_err();
        // The line of the field, not of its table's header.
        assert!(
            err.to_string().contains("line 4, field `light[0].direction`: direction must not be zero"),
            "{err}"
        );
        let err = parse_str("[camera]\nposition = [0, 1, 0]\ntarget = [0, 1, 0]\nfov = 40\n").unwrap_err();
        assert!(err.to_string().contains("line 3, field `camera.target`"), "{err}");
        let err =
            parse_str("[[mesh]]\nfile = \"a.obj\"\ninstances = [\n  { scale = 1 },\n  { scale = 0 },\n]\n")
                .unwrap_err();
        assert!(err.to_string().contains("line 5, field `mesh[0].instances[1].scale`"), "{err}");
        let err = parse_str(
            "[[mesh]]\nfile = \"a.obj\"\ninstances = [\n  { scale = 1 },\n  { scale = \"x\" },\n]\n",
        )
        .unwrap_err();
        assert!(err.to_string().contains("line 5, field `mesh[0].instances[1].scale`"), "{err}");
        let err = parse_str("[[light]]\ntype = \"point\"\nposition = [0, 0, 0]\nradiance = [1, 1, 1]\n")
            .unwrap_err();
        assert!(err.to_string().contains("a point light has no `radiance`"), "{err}");
        let err = parse_str("[[light]]\ntype = \"area\"\n").unwrap_err();
        assert!(err.to_string().contains("line 2, field `light[0].type`"), "{err}");
        let err = parse_str("[[light]]\ntype = \"point\"\nposition = [0, nan, 0]\nintensity = [1, 1, 1]\n")
            .unwrap_err();
        assert!(err.to_string().contains("light[0].position"), "{err}");
    }
}
