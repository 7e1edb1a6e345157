//! `[[shader]]` entries: a procedural [`ShaderDesc`] with every parameter checked, given to the
//! materials its target names or, failing those, to the triangles of the meshes it names.

use toml::Spanned;

use super::checker::Checker;
use super::schema::{ShaderKind, ShaderSpec};
use crate::error::SceneError;
use crate::model::Scene;
use crate::report::LoadReport;
use crate::shader::{Pattern, ShaderDesc};

/// Defaults of the optional `[[shader]]` fields (listed in the module doc of [`crate::scene_file`]).
const SHADER_COLORS: [[f32; 3]; 2] = [[0.8; 3], [0.2; 3]];
const SHADER_EXPONENT: f32 = 20.0;
const DEFAULT_OCTAVES: u32 = 4;
const MARBLE_TURBULENCE: f32 = 5.0;
const WOOD_RINGS: f32 = 4.0;
const WOOD_TURBULENCE: f32 = 0.5;
const BRICK_SIZE: [f32; 3] = [3.0, 1.0, 1.5];
const BRICK_MORTAR: f32 = 0.1;
/// Octaves beyond 16 add detail far below a texel at any sensible scale and only cost time.
const MAX_OCTAVES: u32 = 16;

/// Gives the shader of `[[shader]]` entry `index` to its target. A target that names nothing
/// is an error, or only a warning when `files_skipped` (mesh files were not read, so it may
/// name a material of one).
pub(super) fn add_shader(
    check: &Checker,
    scene: &mut Scene,
    index: usize,
    entry: &Spanned<ShaderSpec>,
    files_skipped: bool,
    report: &mut LoadReport,
) -> Result<(), SceneError> {
    let shader = shader_from(check, index, entry)?;
    if !assign_shader(scene, entry.get_ref().target.get_ref(), &shader) {
        let target = &entry.get_ref().target;
        let path = format!("shader[{index}].target");
        let message = format!("`{}` is neither a material nor a mesh name", target.get_ref());
        if files_skipped {
            report.warn(check.file, format!("{path}: {message} (not checked: mesh files were not loaded)"));
        } else {
            return Err(check.error(&target.span(), path, message));
        }
    }
    Ok(())
}

/// The [`ShaderDesc`] of `[[shader]]` entry `index`, every parameter checked.
fn shader_from(check: &Checker, index: usize, entry: &Spanned<ShaderSpec>) -> Result<ShaderDesc, SceneError> {
    let span = entry.span();
    let spec = entry.get_ref();
    let path = |field: &str| format!("shader[{index}].{field}");
    check.allowed_fields(&span, &spec.present(), spec.kind.fields(), path, |field| {
        format!("a {} shader has no `{field}`", spec.kind.name())
    })?;
    let octaves = || {
        let octaves = spec.octaves.unwrap_or(DEFAULT_OCTAVES);
        if (1..=MAX_OCTAVES).contains(&octaves) {
            Ok(octaves)
        } else {
            Err(check.error(&span, path("octaves"), format!("must be 1 to {MAX_OCTAVES}")))
        }
    };
    let turbulence =
        |default: f32| check.amount(&span, path("turbulence"), spec.turbulence.unwrap_or(default), true);
    let pattern = match spec.kind {
        ShaderKind::Checker => Pattern::Checker,
        ShaderKind::Marble => {
            Pattern::Marble { octaves: octaves()?, turbulence: turbulence(MARBLE_TURBULENCE)? }
        }
        ShaderKind::Wood => Pattern::Wood {
            rings: check.amount(&span, path("rings"), spec.rings.unwrap_or(WOOD_RINGS), false)?,
            turbulence: turbulence(WOOD_TURBULENCE)?,
        },
        ShaderKind::Brick => {
            let size = check.vector(&span, path("size"), spec.size.unwrap_or(BRICK_SIZE))?;
            if size.min_element() <= 0.0 {
                return Err(check.error(&span, path("size"), "brick dimensions must be positive"));
            }
            let mortar = check.amount(&span, path("mortar"), spec.mortar.unwrap_or(BRICK_MORTAR), true)?;
            if mortar >= size.min_element() {
                return Err(check.error(
                    &span,
                    path("mortar"),
                    "the mortar must be narrower than every brick dimension",
                ));
            }
            Pattern::Brick { size, mortar }
        }
        ShaderKind::Turbulence => Pattern::Turbulence { octaves: octaves()? },
    };
    let [first, second] = spec.colors.unwrap_or(SHADER_COLORS);
    Ok(ShaderDesc {
        pattern,
        scale: check.amount(&span, path("scale"), spec.scale.unwrap_or(1.0), false)?,
        colors: [
            check.reflectance(&span, path("colors"), first)?,
            check.reflectance(&span, path("colors"), second)?,
        ],
        glossy: check.reflectance(&span, path("specular"), spec.specular.unwrap_or_default())?,
        exponent: check.amount(&span, path("exponent"), spec.exponent.unwrap_or(SHADER_EXPONENT), true)?,
        bump: check.amount(&span, path("bump"), spec.bump.unwrap_or(0.0), true)?,
    })
}

/// Gives `shader` to the materials named `target` or, if there are none, to the triangles of
/// the meshes named `target` (through copies of their materials). False if nothing matched.
fn assign_shader(scene: &mut Scene, target: &str, shader: &ShaderDesc) -> bool {
    let mut matched = false;
    for material in scene.materials.iter_mut().filter(|m| m.name == target) {
        material.shader = Some(shader.clone());
        matched = true;
    }
    if matched {
        return true;
    }
    // One copy per original material, shared by every mesh of that name.
    let mut copies: std::collections::HashMap<u32, u32> = std::collections::HashMap::new();
    for mesh in scene.meshes.iter_mut().filter(|m| m.name == target) {
        matched = true;
        for id in &mut mesh.material_ids {
            *id = *copies.entry(*id).or_insert_with(|| {
                let mut copy = scene.materials.get(*id as usize).cloned().unwrap_or_default();
                copy.shader = Some(shader.clone());
                scene.materials.push(copy);
                scene.materials.len() as u32 - 1
            });
        }
    }
    matched
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::super::tests::parse_str;
    use super::*;
    use crate::model::{Material, Mesh};
    use crate::scene_file::parse;

    /// A quad light (material and mesh `light[0]`) followed by `shader`.
    fn with_shader(shader: &str) -> Result<Scene, SceneError> {
        parse_str(&format!(
            "[[light]]\ntype = \"quad\"\nposition = [0, 2, 0]\nu = [1, 0, 0]\nv = [0, 0, 1]\nradiance = [1, 1, 1]\n\n[[shader]]\ntarget = \"light[0]\"\n{shader}"
        ))
    }

    fn shader_of(shader: &str) -> ShaderDesc {
        let scene = with_shader(shader).unwrap_or_else(|e| panic!("{e}"));
        scene.materials[0].shader.clone().expect("the shader is assigned")
    }

    #[test]
    fn every_shader_type_parses_with_its_parameters_and_defaults() {
        let common = ShaderDesc {
            pattern: Pattern::Checker,
            scale: 1.0,
            colors: [Vec3::splat(0.8), Vec3::splat(0.2)],
            glossy: Vec3::ZERO,
            exponent: 20.0,
            bump: 0.0,
        };
        assert_eq!(shader_of("type = \"checker\"\n"), common);
        let full = shader_of(
            "type = \"checker\"\nscale = 2.5\ncolors = [[0.9, 0.9, 0.85], [0.3, 0.3, 0.35]]\nspecular = [0.05, 0.05, 0.05]\nexponent = 40\nbump = 0.002\n",
        );
        assert_eq!(
            full,
            ShaderDesc {
                scale: 2.5,
                colors: [Vec3::new(0.9, 0.9, 0.85), Vec3::new(0.3, 0.3, 0.35)],
                glossy: Vec3::splat(0.05),
                exponent: 40.0,
                bump: 0.002,
                ..common.clone()
            }
        );
        let cases = [
            ("type = \"marble\"\n", Pattern::Marble { octaves: 4, turbulence: 5.0 }),
            (
                "type = \"marble\"\noctaves = 7\nturbulence = 2.5\n",
                Pattern::Marble { octaves: 7, turbulence: 2.5 },
            ),
            ("type = \"wood\"\n", Pattern::Wood { rings: 4.0, turbulence: 0.5 }),
            ("type = \"wood\"\nrings = 12\nturbulence = 0\n", Pattern::Wood { rings: 12.0, turbulence: 0.0 }),
            ("type = \"brick\"\n", Pattern::Brick { size: Vec3::new(3.0, 1.0, 1.5), mortar: 0.1 }),
            (
                "type = \"brick\"\nsize = [2, 0.5, 1]\nmortar = 0.05\n",
                Pattern::Brick { size: Vec3::new(2.0, 0.5, 1.0), mortar: 0.05 },
            ),
            ("type = \"turbulence\"\n", Pattern::Turbulence { octaves: 4 }),
            ("type = \"turbulence\"\noctaves = 16\n", Pattern::Turbulence { octaves: 16 }),
        ];
        for (text, pattern) in cases {
            assert_eq!(shader_of(text), ShaderDesc { pattern, ..common.clone() }, "{text}");
        }
    }

    #[test]
    fn bad_shader_parameters_name_the_file_and_field() {
        // (fields after `target`, field named, part of the message)
        let cases = [
            ("type = \"plaid\"\n", "shader[0].type", "unknown variant `plaid`"),
            ("type = \"checker\"\nscale = 0\n", "shader[0].scale", "positive"),
            ("type = \"checker\"\nscale = -2\n", "shader[0].scale", "positive"),
            ("type = \"checker\"\nscale = inf\n", "shader[0].scale", "finite"),
            ("type = \"checker\"\nscale = nan\n", "shader[0].scale", "finite"),
            ("type = \"checker\"\ncolors = [[1.5, 0, 0], [0, 0, 0]]\n", "shader[0].colors", "[0, 1]"),
            ("type = \"checker\"\ncolors = [[1, 1, 1], [0, -0.1, 0]]\n", "shader[0].colors", "negative"),
            ("type = \"checker\"\ncolors = [[1, 1], [0, 0, 0]]\n", "shader[0].colors", "length"),
            ("type = \"checker\"\ncolors = [[1, 1, 1]]\n", "shader[0].colors", "length"),
            ("type = \"checker\"\nspecular = [2, 2, 2]\n", "shader[0].specular", "[0, 1]"),
            ("type = \"checker\"\nexponent = -1\n", "shader[0].exponent", "not negative"),
            ("type = \"checker\"\nbump = nan\n", "shader[0].bump", "finite"),
            ("type = \"marble\"\noctaves = 0\n", "shader[0].octaves", "1 to 16"),
            ("type = \"turbulence\"\noctaves = 17\n", "shader[0].octaves", "1 to 16"),
            ("type = \"turbulence\"\noctaves = -1\n", "shader[0].octaves", "u32"),
            ("type = \"wood\"\nrings = 0\n", "shader[0].rings", "positive"),
            ("type = \"marble\"\nturbulence = -1\n", "shader[0].turbulence", "not negative"),
            ("type = \"brick\"\nsize = [1, 0, 1]\n", "shader[0].size", "positive"),
            ("type = \"brick\"\nsize = [1, 1, 1]\nmortar = 1\n", "shader[0].mortar", "narrower"),
            ("type = \"checker\"\noctaves = 3\n", "shader[0].octaves", "a checker shader has no `octaves`"),
            ("type = \"wood\"\nsize = [1, 1, 1]\n", "shader[0].size", "a wood shader has no `size`"),
            ("type = \"checker\"\ncolour = [1, 1, 1]\n", "shader[0].colour", "unknown field `colour`"),
        ];
        for (text, field, message) in cases {
            let err = with_shader(text).expect_err(text).to_string();
            assert!(err.starts_with("s.toml: line "), "{text}: {err}");
            assert!(err.contains(&format!("field `{field}`: ")), "{text}: {err}");
            assert!(err.contains(message), "{text}: {err}");
        }
        let err = with_shader("type = \"checker\"\n\n[[shader]]\ntarget = \"nothing\"\ntype = \"wood\"\n")
            .unwrap_err()
            .to_string();
        assert_eq!(
            err,
            "s.toml: line 13, field `shader[1].target`: `nothing` is neither a material nor a mesh name"
        );
    }

    #[test]
    fn a_mesh_target_copies_only_that_meshs_materials() {
        let triangle = |name: &str, material: u32| Mesh {
            name: name.into(),
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
            indices: vec![[0, 1, 2], [0, 2, 1]],
            material_ids: vec![material, 1],
            ..Mesh::default()
        };
        let mut scene = Scene {
            meshes: vec![triangle("floor", 0), triangle("wall", 0), triangle("floor", 0)],
            materials: vec![
                Material { name: "stone".into(), ..Material::default() },
                Material { name: "plaster".into(), ..Material::default() },
            ],
            ..Scene::default()
        };
        let shader = shader_of("type = \"checker\"\n");
        assert!(assign_shader(&mut scene, "floor", &shader));
        assert_eq!(scene.materials.len(), 4, "one copy of each material the meshes use");
        assert_eq!(scene.meshes[0].material_ids, vec![2, 3]);
        assert_eq!(scene.meshes[2].material_ids, vec![2, 3], "meshes of one name share the copies");
        assert_eq!(scene.meshes[1].material_ids, vec![0, 1], "the wall is untouched");
        assert!(scene.materials[..2].iter().all(|m| m.shader.is_none()));
        assert_eq!(
            (scene.materials[2].name.as_str(), scene.materials[3].name.as_str()),
            ("stone", "plaster")
        );
        assert!(scene.materials[2..].iter().all(|m| m.shader.as_ref() == Some(&shader)));

        // A material name wins over a mesh name and reaches every material of that name,
        // the copies included.
        let marble = shader_of("type = \"marble\"\n");
        assert!(assign_shader(&mut scene, "stone", &marble));
        assert_eq!(scene.materials[0].shader.as_ref(), Some(&marble));
        assert_eq!(scene.materials[2].shader.as_ref(), Some(&marble));
        assert_eq!(scene.materials[3].shader.as_ref(), Some(&shader));
        assert!(!assign_shader(&mut scene, "ceiling", &marble));
    }

    #[test]
    fn unchecked_targets_warn_when_parsing_from_memory() {
        let mut report = LoadReport::default();
        let scene = parse(
            "[[mesh]]\nfile = \"room.obj\"\n\n[[shader]]\ntarget = \"floor\"\ntype = \"checker\"\n",
            "s.toml",
            None,
            &mut report,
        )
        .unwrap();
        assert!(scene.materials.is_empty());
        assert_eq!(report.warnings.len(), 2, "{report:?}");
        assert!(report.warnings[1].contains("shader[0].target: `floor`"), "{report:?}");
    }
}
