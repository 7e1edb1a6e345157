//! Geometry helpers for the built-in scenes: quads, boxes and spheres as [`Part`]s, and the
//! assembly of parts into a one-mesh [`Scene`].

use std::f32::consts::{FRAC_PI_2, PI, TAU};

use glam::{Quat, Vec3};

use crate::model::{Camera, Material, Scene};
use crate::validate::{MeshBuilder, Part};

/// A planar quad from its four corners, split along the 0–2 diagonal like an OBJ quad.
pub(super) fn quad_corners(corners: [Vec3; 4], material: u32) -> Part {
    Part { positions: corners.to_vec(), triangles: vec![[0, 1, 2], [0, 2, 3]], material, ..Part::default() }
}

/// A flat-shaded quad centred at `centre` with half-edge vectors `a` and `b`, facing
/// `a × b` (counter-clockwise seen from that side).
pub(super) fn quad(centre: Vec3, a: Vec3, b: Vec3, material: u32) -> Part {
    let normal = a.cross(b).normalize();
    let mut part = quad_corners([centre - a - b, centre + a - b, centre + a + b, centre - a + b], material);
    part.normals = Some(vec![normal; 4]);
    part
}

/// The six faces of a box as (outward normal, tangent a, tangent b) with a × b = normal.
const FACES: [(Vec3, Vec3, Vec3); 6] = [
    (Vec3::X, Vec3::Y, Vec3::Z),
    (Vec3::NEG_X, Vec3::Z, Vec3::Y),
    (Vec3::Y, Vec3::Z, Vec3::X),
    (Vec3::NEG_Y, Vec3::X, Vec3::Z),
    (Vec3::Z, Vec3::X, Vec3::Y),
    (Vec3::NEG_Z, Vec3::Y, Vec3::X),
];

/// A box standing on `base` (the centre of its bottom face), `size` wide/high/deep, turned by
/// `yaw_deg` about +Y. With `inward`, the faces look inside (a room).
pub(super) fn cuboid(base: Vec3, size: Vec3, yaw_deg: f32, inward: bool, material: u32) -> Vec<Part> {
    let turn = Quat::from_rotation_y(yaw_deg.to_radians());
    let half = size / 2.0;
    let centre = base + Vec3::Y * half.y;
    FACES
        .iter()
        .map(|&(n, a, b)| {
            let face_centre = centre + turn * (n * half);
            let (a, b) = (turn * (a * half), turn * (b * half));
            if inward { quad(face_centre, b, a, material) } else { quad(face_centre, a, b, material) }
        })
        .collect()
}

/// A smooth UV sphere: `segments` around the Y axis, `rings` from pole to pole, triangles
/// counter-clockwise seen from outside.
pub(super) fn sphere(centre: Vec3, radius: f32, segments: u32, rings: u32, material: u32) -> Part {
    let mut normals = vec![Vec3::Y];
    for ring in 1..rings {
        let theta = PI * ring as f32 / rings as f32;
        for segment in 0..segments {
            let phi = TAU * segment as f32 / segments as f32;
            normals.push(Vec3::new(theta.sin() * phi.cos(), theta.cos(), -theta.sin() * phi.sin()));
        }
    }
    normals.push(Vec3::NEG_Y);
    let bottom = normals.len() as u32 - 1;
    let at = |ring: u32, segment: u32| 1 + (ring - 1) * segments + segment % segments;
    let mut triangles = Vec::new();
    for s in 0..segments {
        triangles.push([0, at(1, s), at(1, s + 1)]);
        for ring in 1..rings - 1 {
            let (a, b) = (at(ring, s), at(ring, s + 1));
            let (c, d) = (at(ring + 1, s), at(ring + 1, s + 1));
            triangles.push([a, c, d]);
            triangles.push([a, d, b]);
        }
        triangles.push([bottom, at(rings - 1, s + 1), at(rings - 1, s)]);
    }
    Part {
        positions: normals.iter().map(|&n| centre + n * radius).collect(),
        normals: Some(normals),
        uvs: None,
        triangles,
        material,
    }
}

/// A parallelepiped from corner `origin` spanned by edge vectors `x`, `y` and `z` (a
/// right-handed triple), six flat quads facing out: boxes, steps, sloped stair stringers.
pub(super) fn parallelepiped(origin: Vec3, x: Vec3, y: Vec3, z: Vec3, material: u32) -> Part {
    let corner = |i: u32, j: u32, k: u32| origin + x * i as f32 + y * j as f32 + z * k as f32;
    // Each face counter-clockwise seen from outside, as (corners, outward normal).
    let faces = [
        ([corner(0, 0, 0), corner(0, 0, 1), corner(0, 1, 1), corner(0, 1, 0)], -x),
        ([corner(1, 0, 0), corner(1, 1, 0), corner(1, 1, 1), corner(1, 0, 1)], x),
        ([corner(0, 0, 0), corner(1, 0, 0), corner(1, 0, 1), corner(0, 0, 1)], -y),
        ([corner(0, 1, 0), corner(0, 1, 1), corner(1, 1, 1), corner(1, 1, 0)], y),
        ([corner(0, 0, 0), corner(0, 1, 0), corner(1, 1, 0), corner(1, 0, 0)], -z),
        ([corner(0, 0, 1), corner(1, 0, 1), corner(1, 1, 1), corner(0, 1, 1)], z),
    ];
    let mut part = Part { material, normals: Some(Vec::with_capacity(24)), ..Part::default() };
    for (corners, outward) in faces {
        let base = part.positions.len() as u32;
        // The normal of the face's plane (x, y, z need not be orthogonal), turned outward.
        let plane = (corners[1] - corners[0]).cross(corners[3] - corners[0]).normalize();
        let normal = if plane.dot(outward) >= 0.0 { plane } else { -plane };
        part.positions.extend(corners);
        part.normals.as_mut().unwrap().extend([normal; 4]);
        part.triangles.extend([[base, base + 1, base + 2], [base, base + 2, base + 3]]);
    }
    part
}

/// Unit vectors u, v perpendicular to the unit vector `axis` with u × v = `axis`: the frame in
/// which the round shapes below lay out their circles, counter-clockwise about `axis`.
fn frame(axis: Vec3) -> (Vec3, Vec3) {
    let u = axis.any_orthonormal_vector();
    (u, axis.cross(u))
}

/// The side of a cylinder or cone frustum from `a` (radius `ra`) to `b` (radius `rb`):
/// `around` segments, `along` rings of quads, smooth normals, open ends.
pub(super) fn tube(a: Vec3, b: Vec3, [ra, rb]: [f32; 2], around: u32, along: u32, material: u32) -> Part {
    let length = a.distance(b);
    let axis = (b - a) / length;
    let (u, v) = frame(axis);
    let mut part = Part { material, normals: Some(Vec::new()), ..Part::default() };
    let normals = part.normals.as_mut().unwrap();
    for ring in 0..=along {
        let t = ring as f32 / along as f32;
        let (centre, radius) = (a.lerp(b, t), ra + (rb - ra) * t);
        for segment in 0..around {
            let (sin, cos) = (TAU * segment as f32 / around as f32).sin_cos();
            let radial = u * cos + v * sin;
            part.positions.push(centre + radial * radius);
            // A frustum's normal leans toward its narrow end by the slope (ra - rb) / length.
            normals.push((radial * length + axis * (ra - rb)).normalize());
        }
    }
    part.triangles = grid_triangles(around, along);
    part
}

/// A bent tube: the part of a torus of radii `major` (to the tube's centre line) and `minor`
/// around `centre`, sweeping `angle` radians from direction `from` toward the perpendicular
/// direction `toward` (both unit); `around` segments round the tube, `along` along the bend.
/// A pipe's elbow.
#[allow(clippy::too_many_arguments)]
pub(super) fn torus_arc(
    centre: Vec3,
    [from, toward]: [Vec3; 2],
    [major, minor]: [f32; 2],
    angle: f32,
    around: u32,
    along: u32,
    material: u32,
) -> Part {
    // Circles laid out counter-clockwise about the direction the bend advances in.
    let binormal = toward.cross(from);
    let mut part = Part { material, normals: Some(Vec::new()), ..Part::default() };
    let normals = part.normals.as_mut().unwrap();
    for ring in 0..=along {
        let (sin, cos) = (angle * ring as f32 / along as f32).sin_cos();
        let outward = from * cos + toward * sin;
        let spine = centre + outward * major;
        for segment in 0..around {
            let (s, c) = (TAU * segment as f32 / around as f32).sin_cos();
            let radial = outward * c + binormal * s;
            part.positions.push(spine + radial * minor);
            normals.push(radial);
        }
    }
    part.triangles = grid_triangles(around, along);
    part
}

/// The triangles of `along` rings of quads between `along + 1` circles of `around` vertices
/// each (vertex `ring * around + segment`), closed round the circle; counter-clockwise seen
/// from outside when the circles are laid out counter-clockwise about the direction the
/// rings advance in.
fn grid_triangles(around: u32, along: u32) -> Vec<[u32; 3]> {
    let at = |ring: u32, segment: u32| ring * around + segment % around;
    let mut triangles = Vec::with_capacity(2 * (around * along) as usize);
    for ring in 0..along {
        for s in 0..around {
            let (a, b, c, d) = (at(ring, s), at(ring, s + 1), at(ring + 1, s + 1), at(ring + 1, s));
            triangles.push([a, b, c]);
            triangles.push([a, c, d]);
        }
    }
    triangles
}

/// A flat ring (an annulus, or a disc if `inner` is zero) around `centre` facing `normal`,
/// between radii `inner` and `outer`, in `around` segments: a tank's bottom, a flange's face.
pub(super) fn annulus(
    centre: Vec3,
    normal: Vec3,
    [inner, outer]: [f32; 2],
    around: u32,
    material: u32,
) -> Part {
    let (u, v) = frame(normal);
    let mut part = Part { material, ..Part::default() };
    for radius in [inner, outer] {
        for segment in 0..around {
            let (sin, cos) = (TAU * segment as f32 / around as f32).sin_cos();
            part.positions.push(centre + (u * cos + v * sin) * radius);
        }
    }
    let at = |ring: u32, segment: u32| ring * around + segment % around;
    for s in 0..around {
        // u × v = normal, so segments advance counter-clockwise seen from the normal's side.
        part.triangles.push([at(0, s), at(1, s), at(1, s + 1)]);
        if inner > 0.0 {
            part.triangles.push([at(0, s), at(1, s + 1), at(0, s + 1)]);
        }
    }
    part.normals = Some(vec![normal; part.positions.len()]);
    part
}

/// A hemisphere of `radius` on `centre`, bulging along the unit `axis`: `around` segments and
/// `rings` rings from its rim to its pole, smooth normals. A tank's or a drum's end.
pub(super) fn dome(centre: Vec3, axis: Vec3, radius: f32, around: u32, rings: u32, material: u32) -> Part {
    let (u, v) = frame(axis);
    let mut part = Part { material, normals: Some(Vec::new()), ..Part::default() };
    let normals = part.normals.as_mut().unwrap();
    for ring in 0..rings {
        let (sin_lat, cos_lat) = (FRAC_PI_2 * ring as f32 / rings as f32).sin_cos();
        for segment in 0..around {
            let (sin, cos) = (TAU * segment as f32 / around as f32).sin_cos();
            let n = (u * cos + v * sin) * cos_lat + axis * sin_lat;
            part.positions.push(centre + n * radius);
            normals.push(n);
        }
    }
    let pole = part.positions.len() as u32;
    part.positions.push(centre + axis * radius);
    normals.push(axis);
    part.triangles = grid_triangles(around, rings - 1);
    let last = (rings - 1) * around;
    part.triangles.extend((0..around).map(|s| [last + s, last + (s + 1) % around, pole]));
    part
}

/// A surface of revolution about the vertical line through `base`: the `profile`'s
/// (radius, height) points joined ring to ring from the first to the last, `around` segments,
/// smooth normals from the profile's slope. A cooling tower's shell.
pub(super) fn lathe(base: Vec3, profile: &[[f32; 2]], around: u32, material: u32) -> Part {
    let (u, v) = frame(Vec3::Y);
    let mut part = Part { material, normals: Some(Vec::new()), ..Part::default() };
    let normals = part.normals.as_mut().unwrap();
    let last = profile.len() - 1;
    for (i, &[radius, height]) in profile.iter().enumerate() {
        // The profile's tangent by central differences, turned a quarter outward.
        let [r0, y0] = profile[i.saturating_sub(1)];
        let [r1, y1] = profile[(i + 1).min(last)];
        let (dr, dy) = (r1 - r0, y1 - y0);
        for segment in 0..around {
            let (sin, cos) = (TAU * segment as f32 / around as f32).sin_cos();
            let radial = u * cos + v * sin;
            part.positions.push(base + radial * radius + Vec3::Y * height);
            normals.push((radial * dy - Vec3::Y * dr).normalize());
        }
    }
    part.triangles = grid_triangles(around, last as u32);
    part
}

/// One mesh of all `parts`, placed once, with the given materials and camera.
pub(super) fn assemble(name: &str, parts: Vec<Part>, materials: Vec<Material>, camera: Camera) -> Scene {
    let mut builder = MeshBuilder::new(name);
    for part in parts {
        builder.add(part).expect("built-in geometry is finite and indexed in range");
    }
    Scene::placed_once(vec![builder.finish().mesh], materials, camera)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn outward(part: &Part, centre: Vec3) -> bool {
        part.triangles.iter().all(|&[a, b, c]| {
            let [a, b, c] = [a, b, c].map(|i| part.positions[i as usize]);
            (b - a).cross(c - a).dot((a + b + c) / 3.0 - centre) > 0.0
        })
    }

    #[test]
    fn windings_face_the_intended_side() {
        let s = sphere(Vec3::ONE, 0.5, 12, 8, 0);
        assert_eq!(s.triangles.len(), 12 * 2 + 12 * 6 * 2);
        assert!(outward(&s, Vec3::ONE));
        let centre = Vec3::new(0.0, 0.5, 0.0);
        for face in cuboid(Vec3::ZERO, Vec3::ONE, 30.0, false, 0) {
            assert!(outward(&face, centre));
        }
        for face in cuboid(Vec3::ZERO, Vec3::ONE, 0.0, true, 0) {
            assert!(!outward(&face, centre));
        }
    }
}
