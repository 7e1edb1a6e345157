//! Alpha cut-outs in the renderer: a quad with a checkerboard alpha texture above a plane lit
//! by a directional light. The camera sees the plane through the cut squares, and the plane is
//! shadowed only where the light's ray meets an opaque square: every pixel against the closed
//! form, direct light only. Packets equal single rays through the cut-outs.

mod common;

use common::*;
use glam::{Vec2, Vec3};
use igi_bvh::{Ray, RayPacket8};
use igi_render::{PinholeCamera, PreparedScene};
use igi_scene::{AlphaMask, CoverageChannel, Light, Material, Mesh, Texture, Wrap};
use igi_simd::M32x8;
use std::f32::consts::PI;

/// Squares per side of the checkerboard.
const SQUARES: usize = 4;
/// The quad's reflectance.
const RHO_QUAD: f32 = 0.8;

/// True if square (i, j) of the checkerboard is opaque.
fn opaque(i: usize, j: usize) -> bool {
    (i + j).is_multiple_of(2)
}

/// The grey plane under a directional light, and the quad [−1, 1]² at height 1 facing up,
/// u = (x + 1)/2 and v = (z + 1)/2 on a 4 × 4 checkerboard of alpha 1 and 0 (clamped at the
/// edges).
fn checker_case(direction: Vec3, irradiance: Vec3) -> PreparedScene {
    let corners = [(-1.0, 1.0), (1.0, 1.0), (1.0, -1.0), (-1.0, -1.0)];
    let quad = Mesh {
        name: "checker".into(),
        positions: corners.map(|(x, z)| Vec3::new(x, 1.0, z)).to_vec(),
        normals: None,
        uvs: Some(corners.map(|(x, z)| Vec2::new((x + 1.0) / 2.0, (z + 1.0) / 2.0)).to_vec()),
        indices: vec![[0, 1, 2], [0, 2, 3]],
        material_ids: vec![1; 2],
    };
    let mask = AlphaMask { factor: 1.0, texture: Some(0), channel: CoverageChannel::Alpha, cutoff: 0.5 };
    let material = Material { alpha_mask: Some(mask), ..diffuse("checker", RHO_QUAD) };
    let mut scene =
        plane_scene(vec![quad], vec![material], vec![Light::Directional { direction, irradiance }]);
    let texels = (0..SQUARES * SQUARES)
        .map(|k| if opaque(k % SQUARES, k / SQUARES) { [1.0; 4] } else { [1.0, 1.0, 1.0, 0.0] })
        .collect();
    let checker = Texture::from_linear("checker", SQUARES as u32, SQUARES as u32, texels);
    scene.textures.push(Texture { wrap: [Wrap::Clamp; 2], ..checker });
    PreparedScene::new(scene)
}

/// Where a point of the plane y = 1 falls on the checkerboard: `Some(true)` on an opaque
/// square, `Some(false)` on a cut one or off the quad, `None` within 5 % of a square's edge
/// (where the bilinear alpha crosses one half).
fn square_at(q: Vec3) -> Option<bool> {
    if q.x.abs() >= 1.0 || q.z.abs() >= 1.0 {
        return Some(false);
    }
    let (u, v) = ((q.x + 1.0) / 2.0 * SQUARES as f32, (q.z + 1.0) / 2.0 * SQUARES as f32);
    let near_edge = |c: f32| (c - c.round()).abs() < 0.05;
    if near_edge(u) || near_edge(v) {
        return None;
    }
    Some(opaque(u as usize, v as usize))
}

#[test]
fn the_camera_sees_through_cut_squares_and_only_opaque_squares_cast_shadows() {
    let direction = Vec3::new(0.3, -1.0, 0.2).normalize();
    let irradiance = Vec3::new(2.0, 1.5, 1.0);
    let mut prepared = checker_case(direction, irradiance);
    let eye = Vec3::new(0.4, 4.0, 2.5);
    let cam = camera(eye, Vec3::new(0.0, 0.5, 0.0), 50.0);
    let (w, h) = (96, 72);
    let mut frame = exact_frame(cam, w, h);
    frame.settings.bounces = 0;
    let film = render_igi(&mut prepared, &frame);
    let pin = PinholeCamera::new(&cam, w, h);
    let to_light = -direction;
    let (mut quad, mut through, mut shadowed) = (0, 0, 0);
    for y in 0..h {
        for x in 0..w {
            let d = pin.direction(x, y);
            let q = eye + (1.0 - eye.y) / d.y * d;
            let want = match square_at(q) {
                None => continue,
                Some(true) => {
                    quad += 1;
                    RHO_QUAD / PI * irradiance * to_light.y
                }
                Some(false) => {
                    let Some(p) = hit_floor(eye, d, 9.0) else { continue };
                    // The light's ray from p meets the quad's plane at p + to_light / to_light.y.
                    match square_at(p + to_light / to_light.y) {
                        None => continue,
                        Some(true) => {
                            shadowed += 1;
                            Vec3::ZERO
                        }
                        Some(false) => {
                            through += usize::from(q.x.abs() < 1.0 && q.z.abs() < 1.0);
                            RHO / PI * irradiance * to_light.y
                        }
                    }
                }
            };
            let got = film.get(x, y);
            let tolerance = 1e-3 * want.max_element().max(1e-3);
            assert!(
                (got - want).abs().max_element() <= tolerance,
                "pixel ({x}, {y}): got {got}, want {want}"
            );
        }
    }
    assert!(
        quad > 300 && through > 300 && shadowed > 100,
        "{quad} quad, {through} seen through, {shadowed} shadowed"
    );
}

#[test]
fn packets_equal_single_rays_through_cut_outs() {
    let prepared = checker_case(-Vec3::Y, Vec3::ONE);
    let eye = Vec3::new(0.3, 3.0, 2.0);
    let pin = PinholeCamera::new(&camera(eye, Vec3::ZERO, 60.0), 64, 64);
    let accel = prepared.accel();
    let mut cut = 0;
    for by in 0..32 {
        for bx in 0..16 {
            let rays: [Ray; 8] = std::array::from_fn(|i| {
                let (x, y) = (4 * bx + i as u32 % 4, 2 * by + i as u32 / 4);
                Ray::new(eye, pin.direction(x, y))
            });
            let packet = RayPacket8::from_rays(&rays);
            let hits = accel.intersect8(&packet, M32x8::ALL);
            let blocked = accel.occluded8(&packet, M32x8::ALL);
            for (i, ray) in rays.iter().enumerate() {
                let single = accel.intersect(ray);
                let lane = (hits.t.lane(i), hits.u.lane(i), hits.v.lane(i), hits.prim.lane(i) as u32);
                assert_eq!(lane, (single.t, single.u, single.v, single.prim), "lane {i} of {ray:?}");
                assert_eq!(hits.instance.lane(i) as u32, single.instance, "lane {i} of {ray:?}");
                assert_eq!(blocked.lane(i), accel.occluded(ray), "lane {i} of {ray:?}");
                // A ray that crosses the quad but hits the plane (instance 0) passed a cut.
                let q = eye + (1.0 - eye.y) / ray.dir.y * ray.dir;
                cut += usize::from(q.x.abs() < 1.0 && q.z.abs() < 1.0 && single.instance == 0);
            }
        }
    }
    assert!(cut > 100, "{cut} rays through cut squares");
}
