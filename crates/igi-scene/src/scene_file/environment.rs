//! The `[environment]` table: a constant sky radiance, or an equirectangular image read
//! beside the scene file (an image that cannot be had is an error, see the module doc of
//! [`crate::scene_file`]).

use std::path::Path;

use toml::Spanned;

use super::checker::{Checker, line_of};
use super::schema::EnvironmentSpec;
use crate::environment::Environment;
use crate::error::{Location, SceneError};
use crate::report::LoadReport;
use crate::resources;
use crate::texels::ColorSpace;
use crate::texture::TextureSet;

/// The `[environment]` table; an image goes into `textures`. `None` (with a warning) for an
/// image when parsing from memory.
pub(super) fn environment_from(
    check: &Checker,
    textures: &mut TextureSet,
    entry: &Spanned<EnvironmentSpec>,
    base_dir: Option<&Path>,
    report: &mut LoadReport,
) -> Result<Option<Environment>, SceneError> {
    let span = entry.span();
    let spec = entry.get_ref();
    let path = |field: &str| format!("environment.{field}");
    let file = match (&spec.file, spec.color) {
        (Some(file), Some(_)) => {
            return Err(check.error(&file.span(), path("file"), "give either `color` or `file`, not both"));
        }
        (None, None) => {
            return Err(check.error(&span, "environment".into(), "needs `color` or `file`"));
        }
        (None, Some(color)) => {
            let present = [("intensity", spec.intensity.is_some()), ("rotate", spec.rotate.is_some())];
            check.allowed_fields(&span, &present, &[], path, |field| {
                format!("a constant environment (`color`) has no `{field}`")
            })?;
            let radiance = check.colour(&span, path("color"), color)?;
            return Ok(Some(Environment::Constant { radiance }));
        }
        (Some(file), None) => file,
    };
    let intensity = check.amount(&span, path("intensity"), spec.intensity.unwrap_or(1.0), true)?;
    let rotation_deg = spec.rotate.unwrap_or(0.0);
    if !rotation_deg.is_finite() {
        return Err(check.error(&span, path("rotate"), "must be finite"));
    }
    let name = file.get_ref();
    let Some(dir) = base_dir else {
        report.warn(check.file, format!("environment.file `{name}` not loaded: parsing from memory"));
        return Ok(None);
    };
    let at = || Location::Field { line: Some(line_of(check.text, file.span().start)), path: path("file") };
    let image_path = resources::resolve(dir, name).ok_or_else(|| SceneError::MissingFile {
        file: check.file.to_path_buf(),
        at: at(),
        missing: dir.join(name),
    })?;
    // Float images (.hdr, .exr) are linear whatever the colour space; 8- and 16-bit images
    // are sRGB-encoded pictures.
    let texture = textures
        .sky_file(&image_path, ColorSpace::Srgb, check.file, report)
        .map_err(|e| SceneError::invalid(check.file, at(), format!("`{name}` could not be loaded: {e}")))?;
    Ok(Some(Environment::Map { texture, intensity, rotation_deg }))
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::super::tests::parse_str;
    use super::*;
    use crate::scene_file::parse;

    #[test]
    fn constant_environment_and_its_errors() {
        let scene = parse_str("[environment]\ncolor = [0.4, 0.6, 2.5]\n").unwrap();
        assert_eq!(scene.environment, Some(Environment::Constant { radiance: Vec3::new(0.4, 0.6, 2.5) }));
        assert!(scene.textures.is_empty());
        assert_eq!(parse_str("").unwrap().environment, None);
        let cases = [
            ("color = [1, -1, 1]\n", "field `environment.color`: values must not be negative"),
            ("color = [1, nan, 1]\n", "field `environment.color`: values must be finite"),
            ("color = [1, 1]\n", "field `environment.color`: invalid length 2"),
            (
                "color = [1, 1, 1]\nfile = \"sky.hdr\"\n",
                "field `environment.file`: give either `color` or `file`",
            ),
            ("intensity = 2\n", "field `environment`: needs `color` or `file`"),
            ("color = [1, 1, 1]\nintensity = 2\n", "field `environment.intensity`: a constant environment"),
            ("color = [1, 1, 1]\nrotate = 90\n", "field `environment.rotate`: a constant environment"),
            (
                "file = \"sky.hdr\"\nintensity = -1\n",
                "field `environment.intensity`: must be finite and not negative",
            ),
            ("file = \"sky.hdr\"\nrotate = inf\n", "field `environment.rotate`: must be finite"),
            ("colour = [1, 1, 1]\n", "field `environment.colour`: unknown field `colour`"),
        ];
        for (text, expected) in cases {
            let err = parse_str(&format!("[environment]\n{text}")).expect_err(text).to_string();
            assert!(err.starts_with("s.toml: line "), "{text}: {err}");
            assert!(err.contains(expected), "{text}: {err}");
        }
        let mut report = LoadReport::default();
        let scene = parse("[environment]\nfile = \"sky.hdr\"\n", "s.toml", None, &mut report).unwrap();
        assert_eq!(scene.environment, None);
        assert!(report.warnings[0].contains("environment.file `sky.hdr` not loaded"), "{report:?}");
    }
}
