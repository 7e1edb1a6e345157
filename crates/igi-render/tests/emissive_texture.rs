//! Emission textures (glTF `emissiveTexture`, MTL `map_Ke`) as lights: a triangle is chosen by
//! the texture's integral over it, a point on it carries the texel there, and a triangle whose
//! texture is black is no light. Checked against the closed form of a half-lit rectangle, with
//! both renderers, and on the DamagedHelmet's emissive map.

mod common;

use common::*;
use glam::{Vec2, Vec3};
use igi_render::FrameSource;
use igi_render::{Film, FrameRenderer, PinholeCamera, PreparedScene};
use igi_scene::{Material, Mesh, Texture, Wrap};
use igi_shade::texture::MipMap;
use std::f32::consts::PI;

/// Half extents and height of the emitter of [`half_lit_case`].
const HX: f32 = 1.0;
const HZ: f32 = 0.75;
const H: f32 = 1.0;

/// The emitter's radiance factor.
const LE: Vec3 = Vec3::new(4.0, 3.0, 2.0);

/// A 2 × 1.5 emitter at height 1 facing down over the grey plane, made of four strips across
/// x, with u = (x + 1)/2 on a 64 × 1 emission texture whose left half (x < 0) is black and
/// whose right half is white (clamped at the edges).
fn half_lit_case() -> PreparedScene {
    let (mut positions, mut uvs, mut indices) = (Vec::new(), Vec::new(), Vec::new());
    for strip in 0..4 {
        let (x0, x1) = (-HX + 0.5 * strip as f32, -HX + 0.5 * (strip + 1) as f32);
        let base = positions.len() as u32;
        // a, d, c, b of `horizontal_square` facing down: (x0, +z), (x0, −z), (x1, −z), (x1, +z).
        for (x, z) in [(x0, HZ), (x0, -HZ), (x1, -HZ), (x1, HZ)] {
            positions.push(Vec3::new(x, H, z));
            uvs.push(Vec2::new((x + HX) / (2.0 * HX), (z + HZ) / (2.0 * HZ)));
        }
        indices.extend([[base, base + 1, base + 2], [base, base + 2, base + 3]]);
    }
    let light = Mesh {
        name: "light".into(),
        positions,
        normals: None,
        uvs: Some(uvs),
        material_ids: vec![1; indices.len()],
        indices,
    };
    let material = Material { emission_texture: Some(0), ..emitter("light", LE) };
    let mut scene = plane_scene(vec![light], vec![material], vec![]);
    let texels = (0..64).map(|i| if i < 32 { [0.0, 0.0, 0.0, 1.0] } else { [1.0; 4] }).collect();
    scene.textures.push(Texture { wrap: [Wrap::Clamp; 2], ..Texture::from_linear("half", 64, 1, texels) });
    PreparedScene::new(scene)
}

/// Form factor from (`px`, `pz`) on the plane, facing up, to the rectangle [x0, x1] × [z0, z1]
/// at height `h` facing down: the signed corner rectangles of Howell's B-3.
fn rect_form_factor(px: f64, pz: f64, [x0, x1, z0, z1]: [f64; 4], h: f64) -> f64 {
    corner_form_factor(x1 - px, z1 - pz, h)
        - corner_form_factor(x0 - px, z1 - pz, h)
        - corner_form_factor(x1 - px, z0 - pz, h)
        + corner_form_factor(x0 - px, z0 - pz, h)
}

#[test]
fn only_the_lit_half_of_an_emission_texture_is_a_light_and_it_carries_its_power() {
    let prepared = half_lit_case();
    let lights = prepared.area_lights();
    let strip = |t: &igi_render::prepared::lights::EmissiveTriangle| {
        ((t.p0.x + t.e1.x / 3.0 + t.e2.x / 3.0 + HX) / 0.5) as u32
    };
    let strips: Vec<u32> = lights.triangles().iter().map(strip).collect();
    assert!(!strips.contains(&0), "the black strip is no light: {strips:?}");
    assert_eq!(strips.iter().filter(|&&s| s >= 2).count(), 4, "both white strips are: {strips:?}");
    // Power π L_e A over the white half (1 × 1.5); the strip beside the edge picks up what the
    // bilinear lookups blur across it, and the white strip beside it loses as much.
    let want = PI * LE * (HX * 2.0 * HZ);
    let got = lights.total_power();
    assert!(rel_err(got, want) < 0.02, "power {got}, want {want}");
    // A sampled point carries the texel where it lies: black never, white as L_e.
    for i in 0..64 {
        let u = (i as f32 + 0.5) / 64.0;
        let s = lights.sample(u, Vec2::new(0.37, 0.61)).expect("lights");
        assert!(s.emission == LE || s.point.x < 0.02, "{s:?}");
        assert!(s.point.x > -0.5, "{s:?}");
    }
}

/// The plane's radiance through the pixels of a 24 × 24 camera looking straight down from
/// below the emitter, averaged over the pixels left of x = −0.15 and right of x = 0.15:
/// (left, right).
fn region_means(film: &Film, pin: &PinholeCamera, eye: Vec3) -> (Vec3, Vec3) {
    let (mut left, mut right, mut nl, mut nr) = (Vec3::ZERO, Vec3::ZERO, 0, 0);
    for y in 0..film.height() {
        for x in 0..film.width() {
            let d = pin.direction(x, y);
            let p = eye - eye.y / d.y * d;
            if p.x < -0.15 {
                left += film.get(x, y);
                nl += 1;
            } else if p.x > 0.15 {
                right += film.get(x, y);
                nr += 1;
            }
        }
    }
    (left / nl as f32, right / nr as f32)
}

#[test]
fn a_half_black_emitter_lights_the_plane_from_its_white_half_in_both_renderers() {
    let mut prepared = half_lit_case();
    let eye = Vec3::new(0.0, 0.9, 0.0);
    let cam = camera(eye, Vec3::ZERO, 60.0);
    let size = 24;
    let pin = PinholeCamera::new(&cam, size, size);
    // The closed form: ρ L_e F(p) with F the form factor to the white half only, at 4 × 4
    // points per pixel (the camera's samples are jittered over the pixel).
    let mut closed = Film::new(size, size);
    let mut full = Film::new(size, size);
    for y in 0..size {
        for x in 0..size {
            let (mut white, mut all) = (0.0, 0.0);
            for j in 0..4 {
                for i in 0..4 {
                    let d = pin.direction_at(x, y, (i as f32 + 0.5) / 4.0, (j as f32 + 0.5) / 4.0);
                    let p = eye - eye.y / d.y * d;
                    let (px, pz) = (f64::from(p.x), f64::from(p.z));
                    let (hx, hz) = (f64::from(HX), f64::from(HZ));
                    white += rect_form_factor(px, pz, [0.0, hx, -hz, hz], f64::from(H)) / 16.0;
                    all += rect_form_factor(px, pz, [-hx, hx, -hz, hz], f64::from(H)) / 16.0;
                }
            }
            closed.set(x, y, RHO * LE * white as f32);
            full.set(x, y, RHO * LE * all as f32);
        }
    }
    let (want_left, want_right) = region_means(&closed, &pin, eye);
    let (full_left, _) = region_means(&full, &pin, eye);
    assert!(want_left.x < 0.7 * full_left.x, "the case tells the halves apart: {want_left} {full_left}");

    let mut renderer = FrameRenderer::new(2);
    let mut frame = igi_frame(cam, size, size);
    // One filter level: the second level's 9-pixel window, a third of this 24-pixel image,
    // would average the irradiance across the light's edge that the halves measure.
    frame.settings.coarse_interleave = 1;
    let igi = renderer
        .render_accumulated(&mut prepared, &frame, 32, &|_, _| {})
        .expect("valid settings")
        .image
        .into_film()
        .unwrap();
    let (pt, _) = path_traced(&mut prepared, &frame, 256, 2);
    for (name, film) in [("IGI", &igi), ("path tracer", &pt)] {
        let (left, right) = region_means(film, &pin, eye);
        eprintln!("{name}: left {left} (want {want_left}), right {right} (want {want_right})");
        assert!(rel_err(left, want_left) < 0.03, "{name}: left {left}, want {want_left}");
        assert!(rel_err(right, want_right) < 0.03, "{name}: right {right}, want {want_right}");
    }
}

#[test]
fn the_helmets_emissive_power_is_the_integral_of_its_emissive_map() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/scenes/gltf-samples/DamagedHelmet/glTF/DamagedHelmet.gltf");
    if !path.is_file() {
        println!(
            "the_helmets_emissive_power_is_the_integral_of_its_emissive_map: skipped, {} not found",
            path.display()
        );
        return;
    }
    let prepared = PreparedScene::new(igi_scene::load(&path).unwrap());
    // The reference: every triangle of the emissive material, its map read at full resolution
    // at 8 × 8 stratified points of its uv footprint.
    let mut want = Vec3::ZERO;
    let mut maps = std::collections::HashMap::new();
    let accel = prepared.accel();
    for instance in 0..accel.instance_count() as u32 {
        let mesh_index = accel.instance_mesh(instance) as usize;
        let (mesh, shading) = (&accel.meshes()[mesh_index], &prepared.meshes()[mesh_index]);
        let m = accel.instance_transform(instance);
        for (prim, &id) in shading.material_ids.iter().enumerate() {
            let material = &prepared.materials()[id as usize];
            let Some(t) = material.emission_texture.filter(|_| material.is_emissive()) else { continue };
            let map = maps.entry(t).or_insert_with(|| MipMap::new(&prepared.textures()[t as usize]));
            let [a, b, c] = mesh.triangle(prim as u32).map(|p| m.transform_point3(p));
            let area = 0.5 * (b - a).cross(c - a).length();
            let [t0, t1, t2] = mesh.indices[prim].map(|i| shading.uvs.as_ref().unwrap()[i as usize]);
            let mut mean = Vec3::ZERO;
            for j in 0..8 {
                for i in 0..8 {
                    let s = ((i as f32 + 0.5) / 8.0).sqrt();
                    let (b1, b2) = (s * (1.0 - (j as f32 + 0.5) / 8.0), s * (j as f32 + 0.5) / 8.0);
                    mean += map.bilinear(t0 + b1 * (t1 - t0) + b2 * (t2 - t0), 0).truncate() / 64.0;
                }
            }
            want += PI * area * material.emission * mean;
        }
    }
    let lights = prepared.area_lights();
    let got = lights.total_power();
    eprintln!(
        "helmet: {} of {} triangles emit; power {got}, integral {want}",
        lights.triangles().len(),
        prepared.triangle_count()
    );
    assert!(rel_err(got, want) < 0.03, "power {got}, integral {want}");
    assert!(lights.triangles().len() < prepared.triangle_count() / 2, "the black texels are no lights");
}
