//! Wavefront MTL material libraries, parsed by `tobj` and mapped onto [`Material`].
//!
//! `tobj`'s MTL parser panics on a colour with fewer than three values (`Kd 0.5 0.5`), keeps
//! `# comment` tails in names (`map_Kd wall.png # old`), does not separate texture options
//! from file names (`map_Kd -s 2 2 1 wall.png`) and reports errors without a line. So every
//! line first goes through `normalise`, which checks the statements `tobj` parses, reports
//! problems with their line, and hands `tobj` a text it cannot trip over. `tobj` then does the
//! parsing proper.
//!
//! Mapping onto the model:
//!
//! | MTL | [`Material`] |
//! |---|---|
//! | `Kd`, `map_Kd` | `diffuse` (clamped to [0, 1]), `diffuse_texture` (sRGB) |
//! | `Ks`, `Ns` | `glossy` (a mirror's reflectance for `illum` 3, 5), `exponent` |
//! | `Ke`, `map_Ke` | `emission` (radiance), `emission_texture` (sRGB, multiplies `Ke`; without `Ke` the texture alone gives the radiance, `Ke` 1) |
//! | `bump`, `map_bump`, `map_Bump` | `bump_texture` (linear) |
//! | `map_d` | `alpha_mask` (cutoff 0.5): the image's alpha, or for an image opaque everywhere (a grey dissolve map) its luminance |
//! | `d`, else `Tr` | `transparency` = 1 − `d`, else `Tr`. `Tr` is *transparency*: files that write both (`d 1` and `Tr 0`) agree, and `d` wins when they don't |
//! | `Ni` | `ior` (glass without `Ni` gets 1.5) |
//! | `illum` 3, 5 / 4, 6, 7 | `kind` Mirror / Glass, otherwise Plastic |
//!
//! `Ka`, `Tf`, `map_Ka` and the other maps have no place in the model and are ignored; so is
//! `d` < 1 as blending (the surface renders opaque).

use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::Path;

use glam::Vec3;

use crate::error::{Location, SceneError};
use crate::model::{AlphaMask, CoverageChannel, Material, MaterialKind};
use crate::report::LoadReport;
use crate::statements::{Statement, statements};
use crate::texels::ColorSpace;
use crate::texture::TextureSet;

/// Parses an MTL library on its own, without loading its textures: the entry point for fuzzing
/// and for tools that only want the materials. `name` is used in messages.
pub fn parse(bytes: &[u8], name: &str) -> Result<Vec<Material>, SceneError> {
    parse_library(bytes, Path::new(name), None, &mut TextureSet::default(), &mut LoadReport::default())
}

/// Parses an MTL library. Textures are resolved against `texture_dir` and loaded into
/// `textures`; with `None`, texture statements are ignored.
pub(crate) fn parse_library(
    bytes: &[u8],
    file: &Path,
    texture_dir: Option<&Path>,
    textures: &mut TextureSet,
    report: &mut LoadReport,
) -> Result<Vec<Material>, SceneError> {
    let text = String::from_utf8_lossy(bytes);
    let normalised = normalise(&text, file, report)?;
    let (parsed, _) = tobj::load_mtl_buf(&mut normalised.as_bytes())
        .map_err(|e| SceneError::parse(file, Location::File, e.to_string()))?;
    Ok(parsed.iter().map(|m| material(m, file, texture_dir, textures, report)).collect())
}

/// Statements whose argument is a texture file, possibly preceded by options.
fn is_map_statement(keyword: &str) -> bool {
    keyword.starts_with("map_") || matches!(keyword, "bump" | "disp" | "decal" | "refl")
}

/// Checks and rewrites an MTL text line by line (same number of lines) into a form `tobj`
/// parses without panicking: comment tails cut, colours expanded to three values, numbers
/// checked, texture options stripped.
fn normalise(text: &str, file: &Path, report: &mut LoadReport) -> Result<String, SceneError> {
    let mut out = String::with_capacity(text.len());
    for Statement { line: line_number, text: line, keyword, rest } in statements(text) {
        let error = |message: String| SceneError::parse(file, Location::Line(line_number), message);
        match keyword {
            "" => {}
            "Ka" | "Kd" | "Ks" | "Ke" | "Tf" => match colour(rest) {
                Ok(Some([r, g, b])) => {
                    let _ = write!(out, "{keyword} {r} {g} {b}");
                }
                Ok(None) => report.warn(
                    file,
                    format!("line {line_number}: `{keyword} {rest}`: spectral and CIE XYZ colours are not supported, statement ignored"),
                ),
                Err(message) => return Err(error(format!("`{keyword}`: {message}"))),
            },
            "Ns" | "Ni" | "d" | "Tr" | "sharpness" => {
                let value = rest
                    .split_whitespace()
                    .next()
                    .ok_or_else(|| error(format!("`{keyword}` needs a value")))?;
                finite_number(value).map_err(|m| error(format!("`{keyword}`: {m}")))?;
                let _ = write!(out, "{keyword} {value}");
            }
            "illum" => {
                let value = rest.split_whitespace().next().unwrap_or("");
                value
                    .parse::<u8>()
                    .map_err(|_| error(format!("`illum` needs a model number 0-10, found `{value}`")))?;
                let _ = write!(out, "illum {value}");
            }
            "newmtl" => {
                if rest.is_empty() {
                    return Err(error("`newmtl` without a material name".into()));
                }
                let _ = write!(out, "newmtl {rest}");
            }
            keyword if is_map_statement(keyword) => {
                let texture = texture_file(rest);
                if texture.is_empty() {
                    return Err(error(format!("`{keyword}` without a file name")));
                }
                let _ = write!(out, "{keyword} {texture}");
            }
            _ => out.push_str(line),
        }
        out.push('\n');
    }
    Ok(out)
}

fn finite_number(token: &str) -> Result<f32, String> {
    match token.parse::<f32>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(_) => Err(format!("`{token}` is not finite")),
        Err(_) => Err(format!("`{token}` is not a number")),
    }
}

/// An MTL colour: one value (grey) or three; `None` for the unsupported `spectral` and `xyz`
/// forms.
fn colour(rest: &str) -> Result<Option<[f32; 3]>, String> {
    let tokens: Vec<&str> = rest.split_whitespace().collect();
    if matches!(tokens.first(), Some(&"spectral" | &"xyz")) {
        return Ok(None);
    }
    let values = tokens.iter().take(3).map(|t| finite_number(t)).collect::<Result<Vec<f32>, String>>()?;
    match values[..] {
        [v] => Ok(Some([v; 3])),
        [r, g, b] => Ok(Some([r, g, b])),
        _ => Err(format!("expected 1 or 3 values, found {}", values.len())),
    }
}

/// The file name of a texture statement, without its options (`-s 1 1 1`, `-bm 0.5`, ...).
fn texture_file(rest: &str) -> String {
    let mut tokens = rest.split_whitespace().peekable();
    while let Some(&token) = tokens.peek() {
        let arguments = match token {
            "-blendu" | "-blendv" | "-bm" | "-boost" | "-cc" | "-clamp" | "-imfchan" | "-texres"
            | "-type" => 1,
            "-mm" => 2,
            "-o" | "-s" | "-t" => 3,
            _ => break,
        };
        tokens.next();
        for _ in 0..arguments {
            // `-o`, `-s` and `-t` take one to three numbers, the others exactly their count.
            let numeric = tokens.peek().is_some_and(|t| t.parse::<f32>().is_ok());
            if numeric || !matches!(token, "-o" | "-s" | "-t") {
                tokens.next();
            }
        }
    }
    tokens.collect::<Vec<_>>().join(" ")
}

fn material(
    m: &tobj::Material,
    file: &Path,
    texture_dir: Option<&Path>,
    textures: &mut TextureSet,
    report: &mut LoadReport,
) -> Material {
    let defaults = Material::default();
    let kind = match m.illumination_model {
        Some(3 | 5) => MaterialKind::Mirror,
        Some(4 | 6 | 7) => MaterialKind::Glass,
        _ => MaterialKind::Plastic,
    };
    let tr = m.unknown_param.get("Tr").and_then(|v| v.parse::<f32>().ok());
    let transparency = match (m.dissolve, tr) {
        (Some(d), _) => 1.0 - d,
        (None, Some(tr)) => tr,
        (None, None) => 0.0,
    };
    let diffuse = m.diffuse.map_or(defaults.diffuse, Vec3::from);
    let clamped = diffuse.clamp(Vec3::ZERO, Vec3::ONE);
    if clamped != diffuse {
        report.warn(file, format!("material `{}`: Kd {diffuse} clamped to [0, 1]", m.name));
    }
    let mut load = |name: &Option<String>, space| {
        let (dir, name) = (texture_dir?, name.as_deref()?);
        textures.file(dir, name, space, file, report)
    };
    let emission_texture = load(&m.unknown_param.get("map_Ke").cloned(), ColorSpace::Srgb);
    let emission = match (m.emissive, emission_texture) {
        (Some(ke), _) => Vec3::from(ke).max(Vec3::ZERO),
        (None, Some(_)) => Vec3::ONE,
        (None, None) => defaults.emission,
    };
    let diffuse_texture = load(&m.diffuse_texture, ColorSpace::Srgb);
    let bump_texture = load(&m.normal_texture, ColorSpace::Linear);
    let dissolve_texture = load(&m.dissolve_texture, ColorSpace::Linear);
    // A dissolve map cuts where its value is below one half; its value is the alpha channel
    // if the image has one in use, else the grey level.
    let alpha_mask = dissolve_texture.map(|texture| AlphaMask {
        factor: 1.0,
        texture: Some(texture),
        channel: if textures.is_opaque(texture) {
            CoverageChannel::Luminance
        } else {
            CoverageChannel::Alpha
        },
        cutoff: 0.5,
    });
    Material {
        name: m.name.clone(),
        diffuse: clamped,
        diffuse_texture,
        glossy: m.specular.map_or(defaults.glossy, Vec3::from).max(Vec3::ZERO),
        exponent: m.shininess.unwrap_or(defaults.exponent).max(0.0),
        metallic: defaults.metallic,
        roughness: defaults.roughness,
        metallic_roughness_texture: None,
        emission,
        emission_texture,
        bump_texture,
        normal_texture: None,
        normal_scale: 1.0,
        transparency: transparency.clamp(0.0, 1.0),
        alpha_mask,
        ior: m.optical_density.filter(|&ni| ni > 0.0).unwrap_or(if kind == MaterialKind::Glass {
            1.5
        } else {
            defaults.ior
        }),
        kind,
        shader: None,
    }
}

/// Index of every material name; a name defined twice refers to its last definition, as in
/// every OBJ reader.
pub(crate) fn index_by_name(materials: &[Material]) -> HashMap<String, usize> {
    materials.iter().enumerate().map(|(i, m)| (m.name.clone(), i)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn one(text: &str) -> Material {
        let mut materials = parse(text.as_bytes(), "test.mtl").unwrap();
        assert_eq!(materials.len(), 1);
        materials.remove(0)
    }

    #[test]
    fn quirks_of_published_files() {
        let m = one(
            "  newmtl tallBox \r\n  Kd 0.2 0.3 0.4 # comment\r\n\tKd 0.5\nKe 17 12 4\nNs 1000\nillum 5\n",
        );
        assert_eq!(m.name, "tallBox", "indented, trailing blank, CRLF");
        assert_eq!(m.diffuse, Vec3::splat(0.5), "last Kd wins, one value means grey");
        assert_eq!(m.emission, Vec3::new(17.0, 12.0, 4.0));
        assert_eq!(m.exponent, 1000.0);
        assert_eq!(m.kind, MaterialKind::Mirror);
    }

    #[test]
    fn tr_is_transparency_and_d_wins() {
        assert_eq!(one("newmtl a\nd 1.0\nTr 0.0\n").transparency, 0.0);
        assert_eq!(one("newmtl a\nTr 0.0\nd 1.0\n").transparency, 0.0);
        assert_eq!(one("newmtl a\nTr 0.25\n").transparency, 0.25);
        assert_eq!(one("newmtl a\nd 0.75\nTr 0.9\n").transparency, 0.25);
        let glass = one("newmtl a\nillum 7\n");
        assert_eq!((glass.kind, glass.ior), (MaterialKind::Glass, 1.5));
    }

    #[test]
    fn texture_options_and_comments_are_stripped() {
        assert_eq!(texture_file("-s 2 2 1 -bm 0.5 wall 1.png"), "wall 1.png");
        assert_eq!(texture_file("-o 0.5 wall.png"), "wall.png");
        assert_eq!(texture_file("-clamp on a.jpg"), "a.jpg");
    }

    #[test]
    fn errors_name_the_line() {
        let err = parse(b"newmtl a\nKd 0.5 0.5\n", "lib.mtl").unwrap_err();
        assert_eq!(err.to_string(), "lib.mtl: line 2: `Kd`: expected 1 or 3 values, found 2");
        let err = parse(b"newmtl a\n\nNs nan\n", "lib.mtl").unwrap_err();
        assert!(err.to_string().starts_with("lib.mtl: line 3: `Ns`"), "{err}");
        let err = parse(b"newmtl\n", "lib.mtl").unwrap_err();
        assert!(err.to_string().contains("line 1"), "{err}");
    }
}
