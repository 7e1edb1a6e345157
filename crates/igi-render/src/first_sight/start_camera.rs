//! The camera a scene starts with when it brings none ([`default_camera`]): where a person
//! would stand.
//!
//! Scenes are modelled +Y up (OBJ by custom, glTF by definition). Two kinds are told apart by
//! probing the scene with rays:
//!
//! - **An interior** (Sponza's atrium, Sibenik's nave, the conference room): the model
//!   encloses its centre, seen from inside. A point is enclosed when at least [`ENCLOSED`] of
//!   the sideways [`PROBES`] hit geometry (rays upward may escape through a roof opening) and
//!   at least [`FRONT_FACING`] of all hits see a surface's front side (inside a closed solid
//!   the rays meet back faces, and a room's walls face into the room). The eye then stands
//!   on a floor under one of a grid of points through the bounds, at [`EYE_HEIGHT`] of the
//!   clearance above it (at most of the model's typical storey: in Sponza's courtyard, open
//!   to the sky, as high as under its galleries), at an enclosed point whose space spans most
//!   of the model ([`INTERIOR_SPAN`]), in the main space: the most room around the eye (the
//!   median free distance along [`HORIZONTAL`] horizontal directions) times the height above
//!   it. It steps back along the longest horizontal line through that point and looks down
//!   the line, a little upwards: along the space's long axis.
//! - **An object** (the armadillo, the glTF samples): a view from a little above its front,
//!   turned a little to one side, the front +Z for glTF (the specification's), else the side
//!   its shape reaches toward (a figure's arms and head: the armadillo faces −Z); what the
//!   view sees of the object fills the image with a margin.
//!
//! Every probe is deterministic, so every node of a cluster chooses the same camera.

use crate::prepared::PreparedScene;
use crate::sampling::fibonacci_sphere;
use glam::Vec3;
use igi_bvh::{Aabb, Ray, offset_ray_origin};
use igi_scene::Camera;
use std::collections::HashSet;

/// Candidate points per horizontal axis of the bounds.
const GRID: u32 = 12;
/// Candidate heights through the bounds.
const LEVELS: u32 = 6;
/// Rays that test whether geometry encloses a point (a Fibonacci sphere).
const PROBES: u32 = 256;
/// The share of the sideways [`PROBES`] (within [`SIDEWAYS`] of the horizon) that must hit
/// geometry for a point to count as enclosed. Rays upward may escape: a courtyard open to the
/// sky (Sponza's) is still inside the building, a box open at its front (the Cornell box) is
/// seen from outside.
const ENCLOSED: f32 = 0.97;
/// The sine of the elevation below which a probe ray counts as sideways (30°).
const SIDEWAYS: f32 = 0.5;
/// The share of the bounds' chord that an interior's long axis must span.
const INTERIOR_SPAN: f32 = 0.6;
/// The share of an enclosed point's hits that must see front faces.
const FRONT_FACING: f32 = 0.6;
/// Horizontal directions along which the open space around a point is measured.
const HORIZONTAL: u32 = 16;
/// The eye stands at this share of the clearance between floor and ceiling (at most of the
/// model's storey): 1.2 m in a room 2.7 m high, 1.9 m in Sponza (its galleries are 4.2 m
/// high; its courtyard, open to the sky, counts as one storey). Scene units are unknown, so
/// the height follows the architecture, not a person.
const EYE_HEIGHT: f32 = 0.45;
/// The points around the centre tested for enclosure lie this share of the bounds' size off
/// it.
const CENTRE_SPREAD: f32 = 0.1;
/// A clearance below this share of the bounds' diagonal is a gap in the geometry (between a
/// floor and the slab under it), not a room.
const MIN_CLEARANCE: f32 = 0.02;
/// How far back along its long axis the eye steps from the chosen point: this share of the
/// free distance behind it.
const STEP_BACK: f32 = 0.6;
/// The upward tilt of an interior view (radians): rooms show more of interest above eye
/// height than below.
const INTERIOR_TILT: f32 = 0.12;
/// Vertical field of view of an interior view (degrees), wide as in architectural photographs.
const INTERIOR_FOV: f32 = 65.0;
/// Vertical field of view of an object view (degrees).
const OBJECT_FOV: f32 = 40.0;
/// The image aspect ratio an object view is fitted for (the renderers' default 640 × 480).
const OBJECT_ASPECT: f32 = 4.0 / 3.0;
/// Share of the image an object's box, then what the view sees of it, fills along the
/// tighter axis.
const OBJECT_FILL: f32 = 0.8;
/// The elevation of an object's view above its centre (degrees): a person looks at a statue,
/// an animal or a helmet on a table from a little above, from the side; from 30° the bunny
/// showed its back and the helmet its crown more than its visor.
const OBJECT_ELEVATION: f32 = 15.0;
/// How far an object's view turns from its front toward a side (degrees): enough to show its
/// depth, not so far that its front turns away.
const OBJECT_AZIMUTH: f32 = 30.0;
/// The share of its depth by which an object's surface centroid must lie off the centre of its
/// box for its shape to tell its front ([`object_front`]).
const SHAPE_FRONT_MARGIN: f32 = 0.005;
/// The share of what a view of an object sees that must be front faces for the view to show
/// it as it is meant to be seen: a closed object shows nothing else, an open box's inside
/// seen through its opening nearly nothing else. An open box seen from a little off its open
/// side also shows the outside of a wall (a box open at its front, turned 30°: 68 %).
const CLOSED_SHARE: f32 = 0.9;
/// The elevation of the view straight into an open box (degrees).
const OPEN_SIDE_ELEVATION: f32 = 5.0;
/// Rays per side of the grid that counts the triangles an object view sees.
const VIEW_PROBE: u32 = 48;

/// The camera for a scene without one: inside an interior at eye height looking along its
/// long axis, or a view of an object from a little above its front (see the module
/// documentation).
pub fn default_camera(scene: &PreparedScene) -> Camera {
    let bounds = scene.bounds();
    if bounds.is_empty() {
        return Camera { position: Vec3::Z, target: Vec3::ZERO, up: Vec3::Y, fov_y_deg: OBJECT_FOV };
    }
    interior_camera(scene, &bounds).unwrap_or_else(|| object_camera(scene, &bounds))
}

/// The unit horizontal direction `k` of [`HORIZONTAL`].
fn horizontal_direction(k: u32) -> Vec3 {
    let phi = std::f32::consts::TAU * k as f32 / HORIZONTAL as f32;
    Vec3::new(phi.cos(), 0.0, phi.sin())
}

/// What a probe ray from a point meets: the distance and whether it sees a front face, or
/// `None` if it leaves the scene.
fn probe(scene: &PreparedScene, origin: Vec3, dir: Vec3) -> Option<(f32, bool)> {
    let hit = scene.accel().intersect(&Ray::new(origin, dir));
    hit.is_hit().then(|| (hit.t, scene.surface(&hit).geometric_normal.dot(dir) < 0.0))
}

/// A point where the eye could stand: enclosed, seen from inside, with the open space
/// around it measured.
struct Candidate {
    eye: Vec3,
    /// The median free distance along the horizontal directions: the room around the eye
    /// (one long corridor does not make a space open).
    openness: f32,
    /// Free distance along each horizontal direction.
    free: [f32; HORIZONTAL as usize],
}

/// A place to stand: a floor point and the clearance above it.
#[derive(Clone, Copy)]
struct Footing {
    floor: Vec3,
    /// The distance up to a ceiling, `None` under the open sky.
    ceiling: Option<f32>,
}

/// The footing under `p`: the floor below it (a horizontal surface; the ray meets its upper
/// side) and the clearance above it, if there is room to stand.
fn footing(scene: &PreparedScene, bounds: &Aabb, p: Vec3) -> Option<Footing> {
    let down = scene.accel().intersect(&Ray::new(p, -Vec3::Y));
    if !down.is_hit() || scene.surface(&down).geometric_normal.y.abs() < 0.7 {
        return None;
    }
    let floor = p - Vec3::Y * down.t;
    let up = scene.accel().intersect(&Ray::new(offset_ray_origin(floor, Vec3::Y), Vec3::Y));
    let ceiling = up.is_hit().then_some(up.t);
    let clearance = ceiling.unwrap_or(bounds.max.y - floor.y);
    (clearance > MIN_CLEARANCE * bounds.diagonal()).then_some(Footing { floor, ceiling })
}

/// True if the model encloses its centre (or a point near it, in case a column stands
/// there), seen from inside: the mark of an interior. The Cornell box is open at its front,
/// a statue or a helmet is seen from inside its solid, a hill (Lost Empire) is solid rock
/// around its caves.
fn encloses_centre(scene: &PreparedScene, bounds: &Aabb) -> bool {
    let (centre, size) = (bounds.centroid(), bounds.extent());
    (-1..=1).any(|i| {
        (-1..=1).any(|j| {
            let offset = Vec3::new(i as f32 * size.x, 0.0, j as f32 * size.z) * CENTRE_SPREAD;
            candidate(scene, centre + offset).is_some()
        })
    })
}

/// The candidate at `eye`, if geometry encloses it from the sides and it sees front faces.
fn candidate(scene: &PreparedScene, eye: Vec3) -> Option<Candidate> {
    let (mut sideways, mut escaped, mut hits, mut front) = (0u32, 0u32, 0u32, 0u32);
    for i in 0..PROBES {
        let dir = fibonacci_sphere(i, PROBES);
        let is_sideways = dir.y.abs() < SIDEWAYS;
        sideways += u32::from(is_sideways);
        match probe(scene, eye, dir) {
            Some((_, is_front)) => {
                hits += 1;
                front += u32::from(is_front);
            }
            None if is_sideways => escaped += 1,
            None => {}
        }
    }
    if escaped as f32 > (1.0 - ENCLOSED) * sideways as f32 || (front as f32) < FRONT_FACING * hits as f32 {
        return None;
    }
    let mut free = [0.0; HORIZONTAL as usize];
    for (k, d) in free.iter_mut().enumerate() {
        *d = probe(scene, eye, horizontal_direction(k as u32))?.0;
    }
    let mut sorted = free;
    sorted.sort_by(f32::total_cmp);
    let openness = sorted[HORIZONTAL as usize / 2];
    Some(Candidate { eye, openness, free })
}

/// The length of the chord of `bounds` through `p` (inside it) along the unit `dir`.
fn chord(bounds: &Aabb, p: Vec3, dir: Vec3) -> f32 {
    let exit = |d: Vec3| {
        let mut t = f32::INFINITY;
        for axis in 0..3 {
            if d[axis] > 0.0 {
                t = t.min((bounds.max[axis] - p[axis]) / d[axis]);
            } else if d[axis] < 0.0 {
                t = t.min((bounds.min[axis] - p[axis]) / d[axis]);
            }
        }
        t.max(0.0)
    };
    exit(dir) + exit(-dir)
}

/// The horizontal axis (an index below [`HORIZONTAL`] / 2 and its opposite) along which
/// `c` sees the longest free span.
fn long_axis(c: &Candidate) -> usize {
    let half = HORIZONTAL as usize / 2;
    let span = |k: usize| c.free[k] + c.free[k + half];
    (0..half).max_by(|&a, &b| span(a).total_cmp(&span(b))).unwrap_or(0)
}

/// True if `c` stands in a space the model is built around: its long axis spans at least
/// [`INTERIOR_SPAN`] of the bounds along that line (a truck's closed cargo box, a cave in a
/// hill are spaces inside an object, not the scene's interior).
fn spans_the_model(bounds: &Aabb, c: &Candidate) -> bool {
    let axis = long_axis(c);
    let span = c.free[axis] + c.free[axis + HORIZONTAL as usize / 2];
    span >= INTERIOR_SPAN * chord(bounds, c.eye, horizontal_direction(axis as u32))
}

/// The camera inside an interior, or `None` if no point of the scene is enclosed.
fn interior_camera(scene: &PreparedScene, bounds: &Aabb) -> Option<Camera> {
    if !encloses_centre(scene, bounds) {
        return None;
    }
    let size = bounds.extent();
    let footings: Vec<Footing> = (0..LEVELS * GRID * GRID)
        .filter_map(|n| {
            let (level, i, j) = (n / (GRID * GRID), n / GRID % GRID, n % GRID);
            let f =
                Vec3::new(i as f32 + 0.5, (level as f32 + 0.5) * GRID as f32 / LEVELS as f32, j as f32 + 0.5);
            footing(scene, bounds, bounds.min + size * f / GRID as f32)
        })
        .collect();
    // The model's storey: the median clearance under a ceiling. Under the open sky (Sponza's
    // courtyard) the eye stands as high as under the galleries around it, not a third of the
    // way up the walls.
    let mut ceilings: Vec<f32> = footings.iter().filter_map(|f| f.ceiling).collect();
    ceilings.sort_by(f32::total_cmp);
    let storey = ceilings.get(ceilings.len() / 2).copied().unwrap_or(size.y);
    let mut best: Option<(f32, Candidate)> = None;
    for f in &footings {
        let clearance = f.ceiling.unwrap_or(bounds.max.y - f.floor.y);
        let eye = f.floor + Vec3::Y * (EYE_HEIGHT * clearance.min(storey));
        let Some(c) = candidate(scene, eye).filter(|c| spans_the_model(bounds, c)) else { continue };
        // The main space: room around the eye and height above it (a nave over an aisle).
        let score = c.openness * clearance;
        if best.as_ref().is_none_or(|(b, _)| score > *b) {
            best = Some((score, c));
        }
    }
    let (_, best) = best?;
    let (axis, half) = (long_axis(&best), HORIZONTAL as usize / 2);
    tracing::debug!(
        "interior: the most open enclosed point is {} (median free distance {:.3}, span {:.3} of the model's {:.3})",
        best.eye,
        best.openness,
        best.free[axis] + best.free[axis + half],
        chord(bounds, best.eye, horizontal_direction(axis as u32)),
    );
    // Look toward the farther end, standing back toward the nearer one.
    let (ahead, behind) =
        if best.free[axis] >= best.free[axis + half] { (axis, axis + half) } else { (axis + half, axis) };
    let forward = horizontal_direction(ahead as u32);
    let back = best.eye - forward * (STEP_BACK * best.free[behind]);
    // Stay at the point itself if stepping back leaves the enclosed space.
    let eye = if candidate(scene, back).is_some() { back } else { best.eye };
    let span = best.free[axis] + best.free[axis + half];
    let look = (forward + Vec3::Y * INTERIOR_TILT.tan()).normalize();
    Some(Camera { position: eye, target: eye + look * (0.5 * span), up: Vec3::Y, fov_y_deg: INTERIOR_FOV })
}

/// The view from `dir` (unit, from the centre toward the eye) that fits
/// `bounds` into the image.
fn framing(bounds: &Aabb, dir: Vec3) -> Camera {
    let centre = bounds.centroid();
    let right = Vec3::Y.cross(dir).normalize();
    let up = dir.cross(right);
    let tan_y = (0.5 * OBJECT_FOV).to_radians().tan() * OBJECT_FILL;
    let tan_x = tan_y * OBJECT_ASPECT;
    // Every corner of the box within the view: at distance d along `dir`, a corner c (from
    // the centre) lies d − c·dir in front of the eye and c·right, c·up across.
    let mut distance: f32 = 0.0;
    for corner in bounds.corners() {
        let c = corner - centre;
        let needed = c.dot(dir) + (c.dot(right).abs() / tan_x).max(c.dot(up).abs() / tan_y);
        distance = distance.max(needed);
    }
    let distance = distance.max(1e-3 * bounds.diagonal().max(1e-6));
    Camera { position: centre + dir * distance, target: centre, up: Vec3::Y, fov_y_deg: OBJECT_FOV }
}

/// `camera` (framing the box) moved in so that what it sees of the object, not its box,
/// fills [`OBJECT_FILL`] of the image: a grid of its rays finds the rectangle of the image the
/// object covers; the camera shifts sideways to centre it and moves along its view to scale it
/// (a duck's box seen from three quarters is three times the duck).
fn fit_silhouette(scene: &PreparedScene, camera: Camera) -> Camera {
    let (width, height) = (VIEW_PROBE, (VIEW_PROBE as f32 / OBJECT_ASPECT) as u32);
    let pinhole = crate::PinholeCamera::new(&camera, width, height);
    let (mut lo, mut hi) = (glam::Vec2::splat(f32::INFINITY), glam::Vec2::splat(f32::NEG_INFINITY));
    for y in 0..height {
        for x in 0..width {
            if scene.accel().intersect(&pinhole.ray(x, y)).is_hit() {
                // The pixel's extent in [-1, 1]² (y up).
                let ndc = |px: u32, n: u32| 2.0 * px as f32 / n as f32 - 1.0;
                let (x0, x1) = (ndc(x, width), ndc(x + 1, width));
                let (y0, y1) = (-ndc(y + 1, height), -ndc(y, height));
                lo = lo.min(glam::Vec2::new(x0, y0));
                hi = hi.max(glam::Vec2::new(x1, y1));
            }
        }
    }
    if lo.x >= hi.x {
        return camera;
    }
    let (centre, half) = (0.5 * (lo + hi), 0.5 * (hi - lo));
    let scale = (half.max_element() / OBJECT_FILL).clamp(0.1, 10.0);
    let distance = (camera.target - camera.position).length();
    let shift = (pinhole.right * (centre.x * pinhole.tan_half * pinhole.aspect)
        + pinhole.up * (centre.y * pinhole.tan_half))
        * distance;
    let target = camera.target + shift;
    Camera { position: target + (camera.position - camera.target) * scale, target, ..camera }
}

/// What a coarse grid of `camera`'s rays sees: the number of distinct triangles whose front
/// faces it sees, and the share of the rays hitting geometry that meet a front face.
fn front_faces_seen(scene: &PreparedScene, camera: &Camera) -> (usize, f32) {
    let pinhole = crate::PinholeCamera::new(camera, VIEW_PROBE, VIEW_PROBE);
    let (mut triangles, mut hits, mut front) = (HashSet::new(), 0u32, 0u32);
    for y in 0..VIEW_PROBE {
        for x in 0..VIEW_PROBE {
            let ray = pinhole.ray(x, y);
            let hit = scene.accel().intersect(&ray);
            if !hit.is_hit() {
                continue;
            }
            hits += 1;
            if scene.surface(&hit).geometric_normal.dot(ray.dir) < 0.0 {
                front += 1;
                triangles.insert((hit.instance, hit.prim));
            }
        }
    }
    (triangles.len(), if hits == 0 { 0.0 } else { front as f32 / hits as f32 })
}

/// The area-weighted centroid of the scene's surface minus the centre of its bounds, in units
/// of the bounds' size along each axis.
fn surface_centroid_offset(scene: &PreparedScene, bounds: &Aabb) -> Vec3 {
    let accel = scene.accel();
    let (mut sum, mut area) = (glam::DVec3::ZERO, 0.0f64);
    for i in 0..accel.instance_count() as u32 {
        let m = accel.instance_transform(i);
        let mesh = &accel.meshes()[accel.instance_mesh(i) as usize];
        for tri in &mesh.indices {
            let [a, b, c] = tri.map(|k| m.transform_point3(mesh.positions[k as usize]).as_dvec3());
            let w = 0.5 * (b - a).cross(c - a).length();
            sum += w * (a + b + c) / 3.0;
            area += w;
        }
    }
    if area <= 0.0 {
        return Vec3::ZERO;
    }
    ((sum / area).as_vec3() - bounds.centroid()) / bounds.extent().max(Vec3::splat(f32::MIN_POSITIVE))
}

/// The horizontal direction an object faces: its format's ([`PreparedScene::front`], glTF's
/// +Z), else ±Z by its shape. A figure reaches forward with its arms, head and hands while
/// the bulk of its body stays behind, so its surface's centroid lies behind the centre of its
/// box (the Stanford armadillo, which faces −Z: 1.9 % of its depth); within
/// [`SHAPE_FRONT_MARGIN`] of the centre, +Z.
fn object_front(scene: &PreparedScene, bounds: &Aabb) -> Vec3 {
    if let Some(front) = scene.front().map(|f| Vec3::new(f.x, 0.0, f.z)).and_then(Vec3::try_normalize) {
        return front;
    }
    let offset = surface_centroid_offset(scene, bounds).z;
    tracing::debug!("object: surface centroid {offset:.4} of its depth off the box centre along Z");
    if offset > SHAPE_FRONT_MARGIN { -Vec3::Z } else { Vec3::Z }
}

/// The view of an object: from [`OBJECT_ELEVATION`] above its front-left or front-right,
/// [`OBJECT_AZIMUTH`] off its front (whichever shows more distinct front-facing triangles),
/// the front as [`object_front`] finds it. An open box (the Cornell box) shows the backs of
/// its walls from there: where less than [`CLOSED_SHARE`] of what that view sees are front
/// faces and the view straight into its front sees more, it is seen from there.
fn object_camera(scene: &PreparedScene, bounds: &Aabb) -> Camera {
    let front = object_front(scene, bounds);
    let side = Vec3::Y.cross(front);
    let (elevation, azimuth) = (OBJECT_ELEVATION.to_radians(), OBJECT_AZIMUTH.to_radians());
    let from = |toward: f32| {
        (front * azimuth.cos() + side * (toward * azimuth.sin())) * elevation.cos()
            + Vec3::Y * elevation.sin()
    };
    let (left, right) = (framing(bounds, from(-1.0)), framing(bounds, from(1.0)));
    let (l, r) = (front_faces_seen(scene, &left), front_faces_seen(scene, &right));
    let (turned, (_, share)) = if r.0 >= l.0 { (right, r) } else { (left, l) };
    let chosen = if share >= CLOSED_SHARE {
        turned
    } else {
        let straight =
            framing(bounds, (front + Vec3::Y * OPEN_SIDE_ELEVATION.to_radians().tan()).normalize());
        if front_faces_seen(scene, &straight).1 > share { straight } else { turned }
    };
    // Twice: the first move changes the perspective, the second corrects for it.
    fit_silhouette(scene, fit_silhouette(scene, chosen))
}

/// The camera a scene starts with: its own, else [`default_camera`].
pub fn start_camera(scene: &PreparedScene) -> Camera {
    scene.camera().copied().unwrap_or_else(|| default_camera(scene))
}
