//! The loaders' texture-driven material fields: emission textures (glTF `emissiveTexture`, MTL
//! `map_Ke`) and alpha cut-outs (glTF `alphaMode: MASK` with `alphaCutoff`, MTL `map_d`).

mod common;

use common::{directory, textured_triangle_gltf};
use glam::Vec3;
use igi_scene::{AlphaMask, ColorSpace, CoverageChannel, Scene, Texels, load};
use std::path::Path;

/// Writes a 2 × 1 PNG: an RGBA one whose second pixel is transparent, or a grey one.
fn write_png(path: &Path, rgba: bool) {
    if rgba {
        image::RgbaImage::from_raw(2, 1, vec![200, 100, 50, 255, 10, 20, 30, 0]).unwrap().save(path).unwrap();
    } else {
        image::GrayImage::from_raw(2, 1, vec![255, 0]).unwrap().save(path).unwrap();
    }
}

/// A glTF file with one triangle per material of `materials` (JSON objects) and one texture,
/// `rgba.png`.
fn gltf_scene(test: &str, materials: &[&str]) -> Scene {
    let json = textured_triangle_gltf("rgba.png", materials);
    let dir = directory(test, &[("scene.gltf", &json)]);
    write_png(&dir.join("rgba.png"), true);
    load(dir.join("scene.gltf")).unwrap()
}

#[test]
fn gltf_alpha_mode_mask_cuts_at_alpha_cutoff_and_blend_and_opaque_do_not() {
    let textured =
        r#""pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 0.8], "baseColorTexture": {"index": 0}}"#;
    let scene = gltf_scene(
        "gltf_alpha_mode",
        &[
            &format!(r#"{{{textured}, "alphaMode": "MASK", "alphaCutoff": 0.3}}"#),
            &format!(r#"{{{textured}, "alphaMode": "MASK"}}"#),
            &format!(r#"{{{textured}, "alphaMode": "BLEND"}}"#),
            &format!(r#"{{{textured}}}"#),
        ],
    );
    let texture = scene.materials[0].diffuse_texture;
    assert!(texture.is_some());
    let mask = |cutoff| Some(AlphaMask { factor: 0.8, texture, channel: CoverageChannel::Alpha, cutoff });
    assert_eq!(scene.materials[0].alpha_mask, mask(0.3));
    assert_eq!(scene.materials[1].alpha_mask, mask(0.5), "alphaCutoff defaults to 0.5");
    assert_eq!(scene.materials[2].alpha_mask, None, "BLEND is not a cut-out");
    assert!((scene.materials[2].transparency - 0.2).abs() < 1e-6);
    assert_eq!(scene.materials[3].alpha_mask, None, "OPAQUE ignores alpha");
}

#[test]
fn gltf_emissive_texture_multiplies_the_emissive_factor() {
    let scene = gltf_scene(
        "gltf_emissive",
        &[
            r#"{"emissiveFactor": [1, 0.5, 0.25], "emissiveTexture": {"index": 0}}"#,
            r#"{"emissiveFactor": [2, 2, 2]}"#,
        ],
    );
    let glowing = &scene.materials[0];
    assert_eq!(glowing.emission, Vec3::new(1.0, 0.5, 0.25), "the factor, not the map's average");
    let texture = &scene.textures[glowing.emission_texture.expect("emissiveTexture") as usize];
    assert!(matches!(texture.image.texels, Texels::Rgba8 { space: ColorSpace::Srgb, .. }));
    assert_eq!((scene.materials[1].emission, scene.materials[1].emission_texture), (Vec3::splat(2.0), None));
}

#[test]
fn mtl_map_d_cuts_by_alpha_or_by_grey_level_and_map_ke_is_the_emission_texture() {
    let mtl = "newmtl leaves\nmap_Kd rgba.png\nmap_d rgba.png\n\
               newmtl grille\nmap_d grey.png\n\
               newmtl sign\nKe 2 2 2\nmap_Ke rgba.png\n\
               newmtl screen\nmap_Ke grey.png\n\
               newmtl plain\nd 0.5\n";
    let mut obj = String::from("mtllib scene.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n");
    for name in ["leaves", "grille", "sign", "screen", "plain"] {
        obj.push_str(&format!("usemtl {name}\nf 1/1 2/2 3/3\n"));
    }
    let dir = directory("mtl_maps", &[("scene.mtl", mtl), ("scene.obj", &obj)]);
    write_png(&dir.join("rgba.png"), true);
    write_png(&dir.join("grey.png"), false);
    let scene = load(dir.join("scene.obj")).unwrap();
    let material = |name: &str| scene.materials.iter().find(|m| m.name == name).unwrap();
    let cut = |name: &str| material(name).alpha_mask.expect("map_d");
    let leaves = cut("leaves");
    assert_eq!((leaves.factor, leaves.channel, leaves.cutoff), (1.0, CoverageChannel::Alpha, 0.5));
    let grille = cut("grille");
    assert_eq!(grille.channel, CoverageChannel::Luminance, "a grey dissolve map is read by its value");
    let grey = &scene.textures[grille.texture.unwrap() as usize];
    assert!(matches!(grey.image.texels, Texels::Rgba8 { space: ColorSpace::Linear, .. }), "dissolve is data");
    assert_eq!(material("plain").alpha_mask, None, "d alone blends, which is not rendered");
    let sign = material("sign");
    assert_eq!(sign.emission, Vec3::splat(2.0));
    assert!(sign.emission_texture.is_some());
    let screen = material("screen");
    assert_eq!(screen.emission, Vec3::ONE, "map_Ke without Ke: the texture alone");
    let screen_map = &scene.textures[screen.emission_texture.unwrap() as usize];
    assert!(matches!(screen_map.image.texels, Texels::Rgba8 { space: ColorSpace::Srgb, .. }));
}
