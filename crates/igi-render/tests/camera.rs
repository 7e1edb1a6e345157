//! The pinhole camera against its defining formula (the Embree benchmark's camera).

use glam::{DVec3, Vec3};
use igi_render::PinholeCamera;
use igi_scene::Camera;

fn cornell() -> Camera {
    Camera {
        position: Vec3::new(0.0, 1.0, 3.5),
        target: Vec3::new(0.0, 1.0, 0.0),
        up: Vec3::Y,
        fov_y_deg: 39.3077,
    }
}

#[test]
fn centre_pixel_looks_forward() {
    let cam = Camera {
        position: Vec3::new(1.0, 2.0, 3.0),
        target: Vec3::new(-2.0, 0.5, -1.0),
        up: Vec3::Y,
        fov_y_deg: 50.0,
    };
    let pin = PinholeCamera::new(&cam, 641, 481);
    let forward = (cam.target - cam.position).normalize();
    let d = pin.direction(320, 240);
    assert!((d - forward).length() < 1e-6, "{d} vs {forward}");
    assert_eq!(pin.ray(320, 240).origin, cam.position);
}

#[test]
fn directions_follow_the_formula() {
    let cam = Camera {
        position: Vec3::new(0.5, 1.0, 3.0),
        target: Vec3::new(0.0, 0.8, 0.0),
        up: Vec3::new(0.1, 1.0, 0.0),
        fov_y_deg: 60.0,
    };
    let (w, h) = (320u32, 200u32);
    let pin = PinholeCamera::new(&cam, w, h);
    let (pos, target, up) = (cam.position.as_dvec3(), cam.target.as_dvec3(), cam.up.as_dvec3());
    let fwd = (target - pos).normalize();
    let right = fwd.cross(up).normalize();
    let up2 = right.cross(fwd);
    let tan_half = (0.5 * f64::from(cam.fov_y_deg)).to_radians().tan();
    let aspect = f64::from(w) / f64::from(h);
    for (x, y) in [(0, 0), (w - 1, 0), (0, h - 1), (w - 1, h - 1), (17, 123), (250, 3)] {
        let sx = (2.0 * (f64::from(x) + 0.5) / f64::from(w) - 1.0) * tan_half * aspect;
        let sy = (1.0 - 2.0 * (f64::from(y) + 0.5) / f64::from(h)) * tan_half;
        let want: DVec3 = (fwd + right * sx + up2 * sy).normalize();
        let got = pin.direction(x, y).as_dvec3();
        assert!((got - want).length() < 1e-6, "pixel ({x}, {y}): {got} vs {want}");
        // The sub-pixel variant at the centre is the same ray.
        assert_eq!(pin.direction_at(x, y, 0.5, 0.5), pin.direction(x, y));
    }
    // Top-left pixel is up and to the left.
    let tl = pin.direction(0, 0).as_dvec3();
    assert!(tl.dot(up2) > 0.0 && tl.dot(right) < 0.0);
}

/// The eight-lane directions of the tile pipeline are the scalar ones, bit for bit, so its
/// primary rays are the rays `igi bench rays` and embree-bench trace.
#[test]
fn eight_directions_at_once_equal_the_scalar_ones_bit_for_bit() {
    let pin = PinholeCamera::new(&cornell(), 640, 480);
    let mut state = 12345u32;
    let mut next = || {
        state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        state
    };
    for _ in 0..1000 {
        let x: [u32; 8] = std::array::from_fn(|_| next() % 640);
        let y: [u32; 8] = std::array::from_fn(|_| next() % 480);
        let dx: [f32; 8] = std::array::from_fn(|_| (next() >> 8) as f32 / (1u32 << 24) as f32);
        let dy: [f32; 8] = std::array::from_fn(|_| (next() >> 8) as f32 / (1u32 << 24) as f32);
        let d = pin.directions_at8(x, y, dx, dy);
        for lane in 0..8 {
            let want = pin.direction_at(x[lane], y[lane], dx[lane], dy[lane]);
            assert_eq!(d.lane(lane).map(f32::to_bits), want.to_array().map(f32::to_bits), "lane {lane}");
        }
    }
}

#[test]
fn frame_is_orthonormal_and_fov_is_vertical() {
    let pin = PinholeCamera::new(&cornell(), 512, 512);
    assert!((pin.forward.length() - 1.0).abs() < 1e-6);
    assert!(pin.forward.dot(pin.right).abs() < 1e-6 && pin.forward.dot(pin.up).abs() < 1e-6);
    assert!((pin.right - Vec3::X).length() < 1e-6, "image +x is +X for the Cornell view");
    // The top edge of the image plane is at fov/2 from the axis.
    let top = pin.direction_at(256, 0, 0.0, 0.0);
    let angle = top.dot(pin.forward).acos().to_degrees();
    assert!((angle - 39.3077 / 2.0).abs() < 0.05, "{angle}");
}

#[test]
fn up_parallel_to_view_still_gives_a_frame() {
    let cam = Camera { position: Vec3::new(0.0, 5.0, 0.0), target: Vec3::ZERO, up: Vec3::Y, fov_y_deg: 45.0 };
    let pin = PinholeCamera::new(&cam, 10, 10);
    assert!(pin.right.is_finite() && (pin.right.length() - 1.0).abs() < 1e-5);
    assert!(pin.direction(5, 5).is_finite());
}

#[test]
fn projecting_a_point_on_a_pixel_ray_gives_that_pixel() {
    let pin = PinholeCamera::new(&cornell(), 640, 480);
    for (x, y, dx, dy) in
        [(0, 0, 0.0, 0.0), (320, 240, 0.5, 0.5), (639, 17, 0.25, 0.75), (100, 479, 1.0, 1.0)]
    {
        for distance in [0.1, 3.0, 100.0] {
            let point = pin.origin + distance * pin.direction_at(x, y, dx, dy);
            let p = pin.project(point).expect("in front of the eye");
            let want = glam::Vec2::new(x as f32 + dx, y as f32 + dy);
            assert!((p - want).length() < 2e-3, "pixel {want} at distance {distance} projects to {p}");
        }
    }
    assert_eq!(pin.project(pin.origin - pin.forward), None, "behind the eye");
    assert_eq!(pin.project(pin.origin + pin.right), None, "in the eye's plane");
}
