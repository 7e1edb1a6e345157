//! Glossy surfaces in the instant-global-illumination renderer: the 8-wide modified Phong BRDF
//! shader of the VPL loop against its closed form, and glossy VPLs (whose emission follows the
//! BRDF at the VPL) against the path tracer, which samples the same lobes one direction at a
//! time.

mod common;

use common::*;
use glam::{Vec2, Vec3};
use igi_render::igi::vpl::VplSets;
use igi_render::igi::vpl_lighting::GlossyLobe;
use igi_render::image::tonemap::luminance;
use igi_render::{Film, PinholeCamera, PreparedScene};
use igi_scene::{Light, Material, MaterialKind};
use std::f32::consts::PI;

/// The glossy plane's lobes.
const RHO_D: f32 = 0.3;
const RHO_S: f32 = 0.5;
const EXPONENT: f32 = 40.0;

fn glossy(name: &str) -> Material {
    Material {
        name: name.into(),
        diffuse: Vec3::splat(RHO_D),
        glossy: Vec3::splat(RHO_S),
        exponent: EXPONENT,
        ..Material::default()
    }
}

/// The point light of the highlight tests, its intensity, and the eye that looks at its
/// highlight on the plane y = 0.
const LIGHT: Vec3 = Vec3::new(0.0, 1.5, -1.0);
const INTENSITY: Vec3 = Vec3::new(2.0, 1.5, 1.0);
const EYE: Vec3 = Vec3::new(0.0, 1.5, 1.0);

/// One exact frame (pixel-centre rays, no filter) of a 10 × 10 plane of `material` lit by
/// the point light at [`LIGHT`], seen from [`EYE`] at 48 × 36, and its camera.
fn plane_under_the_light(material: Material) -> (Film, PinholeCamera) {
    let mut prepared = PreparedScene::new(scene(
        vec![horizontal_square("plane", Vec3::ZERO, Vec2::new(10.0, 10.0), true, 0)],
        vec![material],
        vec![Light::Point { position: LIGHT, intensity: INTENSITY }],
    ));
    let cam = camera(EYE, Vec3::ZERO, 50.0);
    let frame = exact_frame(cam, 48, 36);
    (render_igi(&mut prepared, &frame), PinholeCamera::new(&cam, 48, 36))
}

/// Where the ray from `origin` along `d` meets the plane y = 0 inside |x|, |z| < `half`.
fn floor_point(origin: Vec3, d: Vec3, half: f32) -> Option<Vec3> {
    (d.y < 0.0).then(|| origin - origin.y / d.y * d).filter(|p| p.x.abs() < half && p.z.abs() < half)
}

#[test]
fn point_light_highlight_on_a_glossy_plane_matches_the_closed_form() {
    // One frame, pixel-centre rays, no filter: a point light over a plane that cannot light
    // itself is exact, so every pixel is (ρ_d/π + ρ_s (n+2)/(2π) cosⁿα) I cos θ / d², with α
    // between the light direction and the mirror direction of the view direction. The camera
    // looks at the highlight, so the glossy term dominates near its centre.
    let (light, intensity, eye) = (LIGHT, INTENSITY, EYE);
    let (film, pin) = plane_under_the_light(glossy("plane"));
    let (w, h) = (film.width(), film.height());
    let (mut checked, mut highlight) = (0, 0);
    for y in 0..h {
        for x in 0..w {
            let Some(p) = floor_point(eye, pin.direction(x, y), 9.0) else { continue };
            let (wo, l) = ((eye - p).normalize(), light - p);
            let wi = l.normalize();
            let r = Vec3::new(-wo.x, wo.y, -wo.z);
            let cos_alpha = r.dot(wi).max(0.0);
            let lobe = (EXPONENT + 2.0) / (2.0 * PI) * cos_alpha.powf(EXPONENT);
            let want = (RHO_D / PI + RHO_S * lobe) * intensity * wi.y / l.length_squared();
            let got = film.get(x, y);
            assert!(rel_err(got, want) < 1e-4, "pixel ({x}, {y}) at {p}: got {got}, want {want}");
            checked += 1;
            highlight += usize::from(RHO_S * lobe > 2.0 * RHO_D / PI);
        }
    }
    assert!(checked > 1000 && highlight > 20, "{checked} pixels, {highlight} in the highlight");
}

#[test]
fn a_vpl_on_a_glossy_surface_carries_its_lobe_around_the_mirror_direction() {
    // A point light straight above a glossy floor: every first-bounce VPL on the floor has
    // diffuse power Φ·ρ_d, glossy power Φ·ρ_s (in that ratio) and its lobe axis is the mirror
    // direction of the direction back to the light.
    let light = Vec3::new(0.2, 2.0, -0.3);
    let prepared = PreparedScene::new(scene(
        vec![horizontal_square("floor", Vec3::ZERO, Vec2::new(4.0, 4.0), true, 0)],
        vec![glossy("floor")],
        vec![Light::Point { position: light, intensity: Vec3::splat(1.0) }],
    ));
    let frame = igi_frame(camera(Vec3::new(0.0, 2.0, 3.0), Vec3::ZERO, 50.0), 32, 32);
    let vpls = VplSets::generate(&prepared, &frame);
    let mut seen = 0;
    for s in 0..vpls.set_count() {
        for vpl in vpls.set(s) {
            assert!(vpl.is_glossy());
            assert!((vpl.glossy.x / vpl.power.x - RHO_S / RHO_D).abs() < 1e-4, "{vpl:?}");
            let to_light = (light - vpl.position).normalize();
            let mirror = Vec3::new(-to_light.x, to_light.y, -to_light.z);
            let Some(GlossyLobe::Phong { axis, exponent }) = vpl.lobe else { panic!("{vpl:?}") };
            assert!(axis.dot(mirror) > 1.0 - 1e-5, "axis {axis} vs mirror {mirror}");
            assert_eq!(exponent, EXPONENT);
            seen += 1;
        }
    }
    assert!(seen > 50, "{seen} VPLs");
}

/// The built-in Cornell box with glossy white walls, floor and boxes: half their reflectance
/// moved into a Phong lobe of exponent 20.
fn glossy_cornell() -> (PreparedScene, igi_scene::Camera) {
    cornell_with(|m| {
        m.glossy = 0.5 * m.diffuse;
        m.diffuse *= 0.5;
        m.exponent = 20.0;
    })
}

/// The built-in Cornell box, prepared, with `change` applied to every material that does not
/// emit, and its camera.
fn cornell_with(change: impl Fn(&mut Material)) -> (PreparedScene, igi_scene::Camera) {
    let mut scene = igi_scene::builtin("cornell-box").expect("built-in cornell-box");
    scene.materials.iter_mut().filter(|m| !m.is_emissive()).for_each(change);
    let camera = scene.camera.expect("the Cornell box has its camera");
    (PreparedScene::new(scene), camera)
}

#[test]
fn converged_igi_with_glossy_vpls_matches_the_path_tracer() {
    // Glossy receivers and glossy VPLs: unclamped IGI is unbiased (up to the bounce cap), so
    // its converged image mean must match the path tracer's, which reaches the same lobes by
    // sampling. Dropping the VPLs' lobes (treating them as Lambertian emitters) changes the
    // indirect light by more than the tolerance.
    let (mut scene, camera) = glossy_cornell();
    let (mi, mp) = converged_means(&mut scene, camera, 32, 256, 512);
    eprintln!("glossy Cornell: IGI {mi}, PT {mp}, ratio {}", luminance(mi) / luminance(mp));
    assert!(rel_err(mi, mp) < 0.03, "IGI mean {mi}, path-traced mean {mp}");
}

/// A glTF metallic-roughness material (the GGX BRDF of glTF 2.0 appendix B).
fn gltf(name: &str, base: Vec3, metallic: f32, roughness: f32) -> Material {
    Material {
        name: name.into(),
        kind: MaterialKind::MetallicRoughness,
        diffuse: base,
        metallic,
        roughness,
        ..Material::default()
    }
}

#[test]
fn point_light_highlight_on_a_ggx_plane_matches_the_appendix_b_brdf() {
    // As for Phong above: every pixel of a plane lit by one point light is f · I cos θ / d²,
    // here with f the glTF BRDF (written out below from appendix B, not from igi_shade) of a
    // half-metallic gold plane: the 8-wide GGX terms of the VPL loop (D, G and S, each
    // multiplied back in after lighting) must reproduce it.
    let (light, intensity, eye) = (LIGHT, INTENSITY, EYE);
    let (base, metallic, roughness) = (Vec3::new(1.0, 0.78, 0.34), 0.5f32, 0.3f32);
    let (film, pin) = plane_under_the_light(gltf("plane", base, metallic, roughness));
    let (w, h) = (film.width(), film.height());
    let a2 = roughness.powi(4);
    let f0 = Vec3::splat(0.04).lerp(base, metallic);
    let (mut checked, mut highlight) = (0, 0);
    for y in 0..h {
        for x in 0..w {
            let Some(p) = floor_point(eye, pin.direction(x, y), 9.0) else { continue };
            let (v, l) = ((eye - p).normalize(), light - p);
            let wi = l.normalize();
            let hv = (v + wi).normalize();
            let fresnel = f0 + (Vec3::ONE - f0) * (1.0 - v.dot(hv)).powi(5);
            let d = a2 / (PI * (hv.y * hv.y * (a2 - 1.0) + 1.0).powi(2));
            let vis = 0.5
                / (wi.y * (v.y * v.y * (1.0 - a2) + a2).sqrt()
                    + v.y * (wi.y * wi.y * (1.0 - a2) + a2).sqrt());
            let specular = fresnel * d * vis;
            let diffuse = (Vec3::ONE - fresnel) * base * (1.0 - metallic) / PI;
            let want = (diffuse + specular) * intensity * wi.y / l.length_squared();
            let got = film.get(x, y);
            assert!(rel_err(got, want) < 2e-4, "pixel ({x}, {y}) at {p}: got {got}, want {want}");
            checked += 1;
            highlight += usize::from(specular.max_element() > 2.0 * diffuse.max_element());
        }
    }
    assert!(checked > 1000 && highlight > 20, "{checked} pixels, {highlight} in the highlight");
}

/// The built-in Cornell box with glTF materials: walls and floor dielectrics of their colour
/// (roughness 0.5), the boxes brushed metal (metallic 1, roughness 0.45).
fn ggx_cornell() -> (PreparedScene, igi_scene::Camera) {
    cornell_with(|m| {
        let boxes = m.name.ends_with("Box");
        let (metallic, roughness) = if boxes { (1.0, 0.45) } else { (0.0, 0.5) };
        *m = Material { emission: m.emission, ..gltf(&m.name, m.diffuse, metallic, roughness) };
    })
}

#[test]
fn converged_igi_with_ggx_vpls_matches_the_path_tracer() {
    // GGX receivers and GGX VPLs (glossy VPLs keep the GGX BRDF of their surface toward the
    // light that reached them): unclamped IGI converges to the path tracer's mean, which
    // samples the same BRDF by visible normals. The lobes are at least as wide as
    // MIN_VPL_ALPHA, so the regularisation changes nothing here. Measured: within 0.3 %;
    // treating GGX VPLs as Lambertian emitters is 7.6 % off, dropping the VPLs' Schlick
    // radiance S 2.2 % off. (With walls of roughness 0.3, below the regularisation's width,
    // its bias is −1.1 %.)
    let (mut scene, camera) = ggx_cornell();
    let (mi, mp) = converged_means(&mut scene, camera, 32, 512, 1024);
    eprintln!("GGX Cornell: IGI {mi}, PT {mp}, ratio {}", luminance(mi) / luminance(mp));
    assert!(rel_err(mi, mp) < 0.015, "IGI mean {mi}, path-traced mean {mp}");
}

#[test]
fn vpls_light_smooth_ggx_metal_without_sparkles() {
    // A smooth white metal plane (roughness 0.1, α = 0.01) under a uniform sky reflects the
    // sky almost perfectly (albedo ≥ 0.99 of the lobe): L ≈ L_sky in every pixel. One frame
    // lights it by about a hundred sky VPLs; at the true width each pixel's lobe catches a
    // VPL or misses all of them (a sparkle per VPL, the pixels' spread several times their
    // mean). Regularised to α ≥ MIN_VPL_ALPHA the lobe spans many VPLs: the pixels agree,
    // with a bias of the wider lobe's masking toward the horizon. Measured: spread 0.29 and
    // mean 0.86 of the sky; at the true width (MIN_VPL_ALPHA = 0) spread 6.8 and mean 0.46.
    let sky = Vec3::new(0.4, 0.6, 1.0);
    let mut sc = scene(
        vec![horizontal_square("plane", Vec3::ZERO, Vec2::new(10.0, 10.0), true, 0)],
        vec![gltf("metal", Vec3::ONE, 1.0, 0.1)],
        vec![],
    );
    sc.environment = Some(igi_scene::Environment::Constant { radiance: sky });
    let mut prepared = PreparedScene::new(sc);
    let cam = camera(Vec3::new(0.0, 2.0, 2.0), Vec3::new(0.0, 0.0, -0.5), 50.0);
    let (w, h) = (40, 30);
    let film = render_igi(&mut prepared, &igi_frame(cam, w, h));
    let pin = PinholeCamera::new(&cam, w, h);
    let lum: Vec<f32> = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .filter(|&(x, y)| floor_point(cam.position, pin.direction(x, y), 8.0).is_some())
        .map(|(x, y)| luminance(film.get(x, y)) / luminance(sky))
        .collect();
    let n = lum.len() as f32;
    let mean = lum.iter().sum::<f32>() / n;
    let spread = (lum.iter().map(|l| (l - mean) * (l - mean)).sum::<f32>() / n).sqrt() / mean;
    eprintln!("smooth metal under the sky: {} pixels, mean {mean} of the sky, spread {spread}", lum.len());
    assert!(lum.len() > 800, "{} plane pixels", lum.len());
    assert!(spread < 0.5, "pixels spread by {spread} of their mean");
    assert!((mean - 1.0).abs() < 0.2, "mean {mean} of the sky");
}
