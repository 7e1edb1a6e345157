//! `power-plant`: the paper's largest scene (abstract, Figure 1 centre: "four instances of a
//! 12.5-million-triangle power plant", 50 million triangles) as a deterministic generator. One
//! plant is an open steel structure five storeys high with three boilers inside, about 900
//! pipes routed through it (finely tessellated cylinders joined by torus elbows, flanged at
//! the ends), grated floors, stairs, a tank farm, horizontal drums on saddles, a chimney and a
//! hyperbolic cooling tower; four instances of it stand on a concrete apron under a sun and a
//! sky. Seen from anywhere, most of it hides behind the rest, which is the point: ray tracing
//! pays for what a ray meets, not for what the scene holds.
//!
//! The layout (where every beam, pipe and tank goes) is fixed; the triangle count asked for
//! sets how finely the round shapes are tessellated (the pipes' and tanks' segments, the
//! elbows' and domes' rings), found by bisection on one detail factor.

use super::daylight::outdoors;
use glam::{Affine3A, Quat, Vec2, Vec3};
use rayon::prelude::*;

use super::random::Random;
use super::shapes::{annulus, dome, lathe, parallelepiped, quad, torus_arc, tube};
use crate::model::{Camera, Instance, Material, Scene};
use crate::validate::{MeshBuilder, Part};

/// Triangles of one plant unless asked otherwise: the paper's model has 12.5 million.
pub(super) const DEFAULT_TRIANGLES: usize = 12_500_000;

/// Width of a bay of the steel structure, between column lines.
const BAY: f32 = 6.0;
/// Column lines along x and along z.
const COLUMNS: [u32; 2] = [13, 9];
/// Floors of the structure, one every [`BAY`] metres up.
const LEVELS: u32 = 5;
/// Pipes routed through the structure.
const PIPES: u32 = 900;

const CONCRETE: u32 = 0;
const STEEL: u32 = 1;
const GRATING: u32 = 2;
/// The pipes' paints: white insulation, yellow, red, green, bare steel.
const PIPE_PAINTS: [u32; 5] = [3, 4, 5, 6, 7];
const TANK: u32 = 8;
const BOILER: u32 = 9;
const TOWER: u32 = 10;
const CHIMNEY: u32 = 11;
const SAFETY: u32 = 12;

fn materials() -> Vec<Material> {
    let diffuse = |name: &str, rgb: [f32; 3]| Material::diffuse(name, Vec3::from(rgb));
    vec![
        diffuse("concrete", [0.42, 0.41, 0.39]),
        diffuse("steel frame", [0.2, 0.3, 0.45]),
        diffuse("grating", [0.3, 0.3, 0.28]),
        diffuse("insulation", [0.75, 0.75, 0.72]),
        diffuse("yellow paint", [0.75, 0.58, 0.1]),
        diffuse("red paint", [0.6, 0.1, 0.08]),
        diffuse("green paint", [0.15, 0.42, 0.2]),
        Material { glossy: Vec3::splat(0.15), exponent: 40.0, ..diffuse("pipe steel", [0.45, 0.45, 0.47]) },
        diffuse("tank", [0.8, 0.8, 0.78]),
        diffuse("boiler", [0.35, 0.33, 0.3]),
        diffuse("cooling tower", [0.6, 0.58, 0.55]),
        diffuse("chimney", [0.55, 0.32, 0.26]),
        diffuse("safety yellow", [0.7, 0.55, 0.1]),
    ]
}

/// A tessellation count that grows with the detail factor: `base` × detail, at least `min`,
/// rounded at a phase of the shape's own (see [`Level`]).
#[derive(Clone, Copy, Debug)]
struct Tess {
    base: f32,
    min: u32,
}

impl Tess {
    const fn new(base: f32, min: u32) -> Self {
        Self { base, min }
    }

    fn at(self, level: Level) -> u32 {
        ((self.base * level.detail + level.phase).floor() as u32).max(self.min)
    }
}

/// How finely one shape is tessellated: the plant's detail factor, and the shape's rounding
/// phase in [0, 1). Shapes round at different phases so that the plant's triangle count grows
/// smoothly with the detail instead of in steps as large as a thousand elbows gaining a ring
/// at once, and [`detail_for`] can come close to any count.
#[derive(Clone, Copy, Debug)]
struct Level {
    detail: f32,
    phase: f32,
}

impl Level {
    /// The level of the layout's shape number `index` at `detail`.
    fn of(index: usize, detail: f32) -> Self {
        Self { detail, phase: Random::new(index as u64).unit() }
    }
}

/// One piece of the layout, tessellated at a detail factor by [`Shape::part`].
#[derive(Clone, Debug)]
enum Shape {
    /// A parallelepiped: corner and edge vectors.
    Block { origin: Vec3, edges: [Vec3; 3], material: u32 },
    /// A cylinder or cone frustum's side from `a` to `b`.
    Tube { a: Vec3, b: Vec3, radii: [f32; 2], around: Tess, material: u32 },
    /// A quarter torus joining two pipe runs.
    Elbow {
        centre: Vec3,
        from: Vec3,
        toward: Vec3,
        radii: [f32; 2],
        around: Tess,
        along: Tess,
        material: u32,
    },
    /// A flat ring or disc.
    Ring { centre: Vec3, normal: Vec3, radii: [f32; 2], around: Tess, material: u32 },
    /// A hemisphere.
    Dome { centre: Vec3, axis: Vec3, radius: f32, around: Tess, rings: Tess, material: u32 },
    /// The hyperbolic shell of a cooling tower standing at `base`.
    Shell { base: Vec3, around: Tess, rings: Tess, material: u32 },
}

/// The cooling tower's shell: r(y) = r_throat √(1 + ((y − y_throat) / c)²), 17 m wide at the
/// ground, 10 m at the throat 40 m up, 11.2 m at the top, 52 m up.
const SHELL: [f32; 4] = [10.0, 40.0, 23.5, 52.0];

impl Shape {
    /// How many triangles [`Shape::part`] makes at `level`.
    fn triangles(&self, level: Level) -> usize {
        let n = |tess: &Tess| tess.at(level) as usize;
        match self {
            Self::Block { .. } => 12,
            Self::Tube { around, .. } => 2 * n(around),
            Self::Elbow { around, along, .. } => 2 * n(around) * n(along),
            Self::Ring { radii, around, .. } => (if radii[0] > 0.0 { 2 } else { 1 }) * n(around),
            Self::Dome { around, rings, .. } => (2 * n(rings) - 1) * n(around),
            Self::Shell { around, rings, .. } => 2 * n(around) * n(rings),
        }
    }

    /// The shape's triangles at `level`.
    fn part(&self, level: Level) -> Part {
        match *self {
            Self::Block { origin, edges: [x, y, z], material } => parallelepiped(origin, x, y, z, material),
            Self::Tube { a, b, radii, around, material } => tube(a, b, radii, around.at(level), 1, material),
            Self::Elbow { centre, from, toward, radii, around, along, material } => torus_arc(
                centre,
                [from, toward],
                radii,
                std::f32::consts::FRAC_PI_2,
                around.at(level),
                along.at(level),
                material,
            ),
            Self::Ring { centre, normal, radii, around, material } => {
                annulus(centre, normal, radii, around.at(level), material)
            }
            Self::Dome { centre, axis, radius, around, rings, material } => {
                dome(centre, axis, radius, around.at(level), rings.at(level), material)
            }
            Self::Shell { base, around, rings, material } => {
                let [throat, throat_height, c, height] = SHELL;
                let rings = rings.at(level);
                let profile: Vec<[f32; 2]> = (0..=rings)
                    .map(|i| {
                        let y = height * i as f32 / rings as f32;
                        [throat * (1.0 + ((y - throat_height) / c).powi(2)).sqrt(), y]
                    })
                    .collect();
                lathe(base, &profile, around.at(level), material)
            }
        }
    }
}

/// A vertical cylinder the pipes must not pass through: a boiler.
struct Obstacle {
    centre: Vec2,
    radius: f32,
    height: f32,
}

impl Obstacle {
    /// True if the axis-aligned run from `a` to `b` of a pipe of radius `r` would cut it.
    fn cut_by(&self, a: Vec3, b: Vec3, r: f32) -> bool {
        let (lo, hi) = (a.min(b), a.max(b));
        if lo.y > self.height + self.radius + r {
            return false;
        }
        let closest = self.centre.clamp(Vec2::new(lo.x, lo.z), Vec2::new(hi.x, hi.z));
        closest.distance(self.centre) < self.radius + r + 0.3
    }

    /// True if the bay with corner `min` (x, z) overlaps it.
    fn covers_bay(&self, min: Vec2) -> bool {
        let closest = self.centre.clamp(min, min + Vec2::splat(BAY));
        closest.distance(self.centre) < self.radius + 0.3
    }
}

/// Where column line `i` (along x) and `j` (along z) cross.
fn column(i: u32, j: u32) -> Vec2 {
    Vec2::new(-36.0 + BAY * i as f32, -24.0 + BAY * j as f32)
}

/// An H-section member along `a` → `b` with its web in the plane of `up`: `depth` along `up`,
/// `width` across, as three [`Shape::Block`]s (two flanges and the web).
fn h_section(a: Vec3, b: Vec3, up: Vec3, [depth, width]: [f32; 2], material: u32, out: &mut Vec<Shape>) {
    let side = (b - a).normalize().cross(up);
    let (flange, web) = (0.04 * depth.max(width) / 0.5, 0.02);
    let mut block = |offset_up: f32, [h_up, h_side]: [f32; 2]| {
        let origin = a + up * (offset_up - h_up / 2.0) - side * (h_side / 2.0);
        out.push(Shape::Block { origin, edges: [b - a, up * h_up, side * h_side], material });
    };
    block(depth / 2.0 - flange / 2.0, [flange, width]);
    block(-(depth / 2.0 - flange / 2.0), [flange, width]);
    block(0.0, [depth - 2.0 * flange, web]);
}

/// The steel structure: H-section columns and beams, grated floors in most bays, and a stair
/// flight up to every floor.
fn structure(boilers: &[Obstacle], random: &mut Random, out: &mut Vec<Shape>) {
    let top = BAY * LEVELS as f32;
    let clear = |p: Vec2| boilers.iter().all(|b| p.distance(b.centre) > b.radius + 0.4);
    for i in 0..COLUMNS[0] {
        for j in 0..COLUMNS[1] {
            let p = column(i, j);
            if clear(p) {
                h_section(
                    Vec3::new(p.x, 0.0, p.y),
                    Vec3::new(p.x, top, p.y),
                    Vec3::X,
                    [0.4, 0.4],
                    STEEL,
                    out,
                );
            }
        }
    }
    for level in 1..=LEVELS {
        let y = BAY * level as f32 - 0.25;
        for i in 0..COLUMNS[0] {
            for j in 0..COLUMNS[1] {
                let p = column(i, j);
                for (di, dj) in [(1, 0), (0, 1)] {
                    if i + di >= COLUMNS[0] || j + dj >= COLUMNS[1] {
                        continue;
                    }
                    let q = column(i + di, j + dj);
                    if clear(p) && clear(q) && clear((p + q) / 2.0) {
                        let (a, b) = (Vec3::new(p.x, y, p.y), Vec3::new(q.x, y, q.y));
                        h_section(a, b, Vec3::Y, [0.5, 0.25], STEEL, out);
                    }
                }
            }
        }
        if level == LEVELS {
            continue;
        }
        for i in 0..COLUMNS[0] - 1 {
            for j in 0..COLUMNS[1] - 1 {
                let min = column(i, j);
                if boilers.iter().any(|b| b.covers_bay(min)) || random.chance(0.35) {
                    continue;
                }
                grating(Vec3::new(min.x, y + 0.25, min.y), out);
            }
        }
    }
    // One flight per floor, in the structure's outer bays, alternating sides.
    for level in 0..LEVELS - 1 {
        let j = if level % 2 == 0 { 0 } else { COLUMNS[1] - 2 };
        let start = column(1 + 2 * level, j);
        stair(Vec3::new(start.x, BAY * level as f32, start.y + 2.0), out);
    }
}

/// A grated floor over the bay whose low corner is `min`: bars on edge every 30 cm, on two
/// cross bars.
fn grating(min: Vec3, out: &mut Vec<Shape>) {
    for k in 0..20 {
        let z = min.z + 0.15 + 0.3 * k as f32;
        let origin = Vec3::new(min.x, min.y, z);
        out.push(Shape::Block {
            origin,
            edges: [Vec3::X * BAY, Vec3::Y * 0.05, Vec3::Z * 0.012],
            material: GRATING,
        });
    }
    for x in [min.x + 1.5, min.x + BAY - 1.5] {
        let origin = Vec3::new(x, min.y - 0.03, min.z);
        out.push(Shape::Block {
            origin,
            edges: [Vec3::X * 0.04, Vec3::Y * 0.03, Vec3::Z * BAY],
            material: GRATING,
        });
    }
}

/// A stair flight rising one floor along +x from `foot`: 32 treads between two sloped
/// stringers, 1.1 m wide.
fn stair(foot: Vec3, out: &mut Vec<Shape>) {
    const STEPS: u32 = 32;
    let (rise, run, width) = (BAY / STEPS as f32, 0.25, 1.1);
    for step in 0..STEPS {
        let origin = foot + Vec3::new(run * step as f32, rise * (step + 1) as f32 - 0.04, 0.0);
        out.push(Shape::Block {
            origin,
            edges: [Vec3::X * (run + 0.03), Vec3::Y * 0.04, Vec3::Z * width],
            material: SAFETY,
        });
    }
    let slope = Vec3::new(run * STEPS as f32, BAY, 0.0);
    for z in [-0.04, width] {
        let origin = foot + Vec3::new(0.0, -0.1, z);
        out.push(Shape::Block { origin, edges: [slope, Vec3::Y * 0.3, Vec3::Z * 0.04], material: SAFETY });
    }
}

/// A vertical tank of `radius` and side `height` on the ground at `centre`, domed on top.
fn tank(centre: Vec2, radius: f32, height: f32, material: u32, out: &mut Vec<Shape>) {
    let (foot, top) = (Vec3::new(centre.x, 0.0, centre.y), Vec3::new(centre.x, height, centre.y));
    let around = Tess::new(96.0, 16);
    out.push(Shape::Tube { a: foot, b: top, radii: [radius; 2], around, material });
    out.push(Shape::Dome { centre: top, axis: Vec3::Y, radius, around, rings: Tess::new(20.0, 4), material });
}

/// A horizontal drum along z from `a` to `b`, domed at both ends, on two concrete saddles.
fn drum(a: Vec3, b: Vec3, radius: f32, out: &mut Vec<Shape>) {
    let around = Tess::new(72.0, 12);
    out.push(Shape::Tube { a, b, radii: [radius; 2], around, material: TANK });
    let axis = (b - a).normalize();
    for (end, outward) in [(a, -axis), (b, axis)] {
        out.push(Shape::Dome {
            centre: end,
            axis: outward,
            radius,
            around,
            rings: Tess::new(12.0, 3),
            material: TANK,
        });
    }
    for t in [0.2, 0.8] {
        let at = a.lerp(b, t);
        let origin = Vec3::new(at.x - radius * 0.8, 0.0, at.z - 0.3);
        let edges = [Vec3::X * radius * 1.6, Vec3::Y * (at.y - radius * 0.6), Vec3::Z * 0.6];
        out.push(Shape::Block { origin, edges, material: CONCRETE });
    }
}

/// A pipe of radius `r` along the corner points `route` (axis-aligned runs): straight runs
/// joined by elbows of bend radius 2r, a flange and a blind at both ends.
fn pipe(route: &[Vec3], r: f32, material: u32, out: &mut Vec<Shape>) {
    // Thin pipes need fewer segments for the same smoothness on screen.
    let around = Tess::new(24.0 * (r / 0.25).sqrt(), 6);
    let bend = 2.0 * r;
    let last = route.len() - 2;
    for (k, run) in route.windows(2).enumerate() {
        let d = (run[1] - run[0]).normalize();
        let a = if k == 0 { run[0] } else { run[0] + d * bend };
        let b = if k == last { run[1] } else { run[1] - d * bend };
        out.push(Shape::Tube { a, b, radii: [r; 2], around, material });
    }
    for corner in route.windows(3) {
        let (d1, d2) = ((corner[1] - corner[0]).normalize(), (corner[2] - corner[1]).normalize());
        let centre = corner[1] - d1 * bend + d2 * bend;
        let along = Tess::new(12.0, 2);
        out.push(Shape::Elbow { centre, from: -d2, toward: d1, radii: [bend, r], around, along, material });
    }
    let ends = [
        (route[0], (route[0] - route[1]).normalize()),
        (route[last + 1], (route[last + 1] - route[last]).normalize()),
    ];
    for (end, outward) in ends {
        let (flange, back) = (1.6 * r, end - outward * 0.4 * r);
        out.push(Shape::Tube { a: back, b: end, radii: [flange; 2], around, material });
        out.push(Shape::Ring { centre: back, normal: -outward, radii: [r, flange], around, material });
        out.push(Shape::Ring { centre: end, normal: outward, radii: [0.0, flange], around, material });
    }
}

/// A random pipe route inside the structure: three to seven axis-aligned runs of 3 to 16 m
/// on a 25 cm lattice, clear of the boilers, or `None` if the draw cut one.
fn route(random: &mut Random, r: f32, boilers: &[Obstacle]) -> Option<Vec<Vec3>> {
    let low = Vec3::new(-35.0, 1.0, -23.0);
    let high = Vec3::new(35.0, BAY * LEVELS as f32 - 1.0, 23.0);
    let snap = |v: f32| (v * 4.0).round() / 4.0;
    let mut at = Vec3::new(
        snap(random.range(low.x, high.x)),
        snap(random.range(low.y, high.y)),
        snap(random.range(low.z, high.z)),
    );
    let mut points = vec![at];
    let mut axis = random.below(3) as usize;
    for _ in 0..3 + random.below(5) {
        axis = (axis + 1 + random.below(2) as usize) % 3;
        let mut length = snap(random.range(3.0, 16.0));
        if random.chance(0.5) {
            length = -length;
        }
        let mut next = at;
        next[axis] = (at[axis] + length).clamp(low[axis], high[axis]);
        if (next[axis] - at[axis]).abs() < 2.5 {
            next[axis] = (at[axis] - length).clamp(low[axis], high[axis]);
        }
        if (next[axis] - at[axis]).abs() < 2.5 || boilers.iter().any(|b| b.cut_by(at, next, r)) {
            return None;
        }
        points.push(next);
        at = next;
    }
    Some(points)
}

/// Every shape of one plant, in the fixed order the layout draws them.
fn layout() -> Vec<Shape> {
    let mut random = Random::new(0x5eed_f9a5);
    let mut out = Vec::new();
    let boilers: Vec<Obstacle> = [column(3, 4), column(6, 4), column(9, 4)]
        .into_iter()
        .map(|centre| Obstacle { centre, radius: 4.5, height: 24.0 })
        .collect();
    for boiler in &boilers {
        tank(boiler.centre, boiler.radius, boiler.height, BOILER, &mut out);
    }
    structure(&boilers, &mut random, &mut out);
    let mut pipes = 0;
    while pipes < PIPES {
        // Radii from 4 to 50 cm, evenly spread in the logarithm.
        let r = 0.04 * 12.5f32.powf(random.unit());
        let paint = PIPE_PAINTS[random.below(PIPE_PAINTS.len() as u32) as usize];
        if let Some(points) = route(&mut random, r, &boilers) {
            pipe(&points, r, paint, &mut out);
            pipes += 1;
        }
    }
    // The tank farm in front of the structure, the drums beside it.
    for k in 0..5 {
        let radius = random.range(4.0, 6.0);
        tank(Vec2::new(-28.0 + 14.0 * k as f32, 36.0), radius, random.range(9.0, 15.0), TANK, &mut out);
    }
    for k in 0..3 {
        let x = 42.0 + 4.5 * k as f32;
        drum(Vec3::new(x, 2.6, -18.0), Vec3::new(x, 2.6, -4.0), 1.8, &mut out);
    }
    let chimney = Vec3::new(48.0, 0.0, 20.0);
    let around = Tess::new(96.0, 16);
    out.push(Shape::Tube {
        a: chimney,
        b: chimney + Vec3::Y * 75.0,
        radii: [3.5, 2.4],
        around,
        material: CHIMNEY,
    });
    out.push(Shape::Ring {
        centre: chimney + Vec3::Y * 75.0,
        normal: Vec3::Y,
        radii: [1.9, 2.4],
        around,
        material: CHIMNEY,
    });
    out.push(Shape::Shell {
        base: Vec3::new(-58.0, 0.0, 0.0),
        around: Tess::new(192.0, 24),
        rings: Tess::new(48.0, 8),
        material: TOWER,
    });
    out
}

/// The detail factor whose tessellation comes closest to `triangles` without exceeding it
/// (or the coarsest, if even that exceeds it).
fn detail_for(shapes: &[Shape], triangles: usize) -> f32 {
    let count = |detail: f32| count(shapes, detail);
    let (mut low, mut high) = (0.0f32, 1.0f32);
    while count(high) < triangles && high < 1e4 {
        high *= 2.0;
    }
    for _ in 0..40 {
        let mid = (low + high) / 2.0;
        if count(mid) <= triangles { low = mid } else { high = mid }
    }
    low
}

/// The triangles `shapes` make at `detail`.
fn count(shapes: &[Shape], detail: f32) -> usize {
    shapes.iter().enumerate().map(|(i, s)| s.triangles(Level::of(i, detail))).sum()
}

/// The triangles a plant has at its coarsest tessellation: the least `triangles` can ask for.
pub(super) fn minimum_triangles() -> usize {
    count(&layout(), 0.0)
}

/// Four plants of about `triangles` triangles each (one mesh placed four times, two of them
/// turned half round) on a concrete apron, under a sun from the camera's left, so that the
/// shadows fall across the view, and a blue sky.
pub(super) fn scene(triangles: usize) -> Scene {
    let shapes = layout();
    let detail = detail_for(&shapes, triangles);
    let mut builder = MeshBuilder::new("power-plant");
    // Tessellated in parallel a few thousand shapes at a time, appended in layout order.
    for (c, chunk) in shapes.chunks(4096).enumerate() {
        let parts: Vec<Part> = chunk
            .par_iter()
            .enumerate()
            .map(|(i, shape)| shape.part(Level::of(c * 4096 + i, detail)))
            .collect();
        for part in parts {
            builder.add(part).expect("generated geometry is finite and indexed in range");
        }
    }
    let plant = builder.finish().mesh;
    let mut ground = MeshBuilder::new("apron");
    ground.add(quad(Vec3::ZERO, Vec3::Z * 200.0, Vec3::X * 200.0, CONCRETE)).expect("a finite quad");
    let placements = [(-70.0, -50.0, 0.0), (70.0, -50.0, 180.0), (-70.0, 50.0, 180.0), (70.0, 50.0, 0.0)];
    let mut instances: Vec<Instance> = placements
        .iter()
        .map(|&(x, z, yaw): &(f32, f32, f32)| Instance {
            mesh: 0,
            transform: Affine3A::from_rotation_translation(
                Quat::from_rotation_y(yaw.to_radians()),
                Vec3::new(x, 0.0, z),
            ),
        })
        .collect();
    instances.push(Instance { mesh: 1, transform: Affine3A::IDENTITY });
    let camera = Camera::looking_at(Vec3::new(-175.0, 48.0, 160.0), Vec3::new(-20.0, 8.0, 10.0), 50.0);
    let plants =
        Scene { instances, ..Scene::placed_once(vec![plant, ground.finish().mesh], materials(), camera) };
    outdoors(plants, Vec3::new(0.5, -0.6, 0.62))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tessellation_meets_the_count_asked_for() {
        let shapes = layout();
        for asked in [minimum_triangles() + 100_000, 1_000_000] {
            let detail = detail_for(&shapes, asked);
            let made: usize =
                shapes.iter().enumerate().map(|(i, s)| s.part(Level::of(i, detail)).triangles.len()).sum();
            assert_eq!(made, count(&shapes, detail));
            assert!(made <= asked && made as f64 > 0.995 * asked as f64, "{made} for {asked}");
        }
    }
}
