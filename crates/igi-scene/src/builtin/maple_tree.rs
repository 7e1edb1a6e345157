//! `maple-tree`: the paper's other large scene (Figure 1 right, Figure 9: a tree of 1.5
//! million triangles whose shadow dapples the ground) as a deterministic generator. A trunk
//! branches six times over, each branch into a leader, two forks and a side shoot, into about
//! 4,000 twigs; the twigs carry five-lobed leaves of ten triangles each, as many as the
//! triangle count asked for leaves room for. It stands on a meadow under a low sun from the
//! side and a blue sky, so its shadow lies across the ground in front of the camera.

use super::daylight::outdoors;
use std::f32::consts::TAU;

use glam::Vec3;

use super::random::Random;
use super::shapes::{quad, tube};
use crate::model::{Camera, Material, Scene};
use crate::validate::{MeshBuilder, Part};

/// Triangles of the tree unless asked otherwise: the paper's model has 1.5 million.
pub(super) const DEFAULT_TRIANGLES: usize = 1_500_000;

/// Times the trunk branches; twigs are the branches of the last generation.
const GENERATIONS: u32 = 6;
/// Triangles of one leaf: a fan over its five lobes' tips and the notches between them.
const LEAF_TRIANGLES: usize = 10;
/// Straight pieces a branch bends through.
const PIECES: u32 = 3;

const BARK: u32 = 0;
const GRASS: u32 = 1;
/// The leaves' three greens.
const LEAVES: [u32; 3] = [2, 3, 4];

fn materials() -> Vec<Material> {
    let diffuse = |name: &str, rgb: [f32; 3]| Material::diffuse(name, Vec3::from(rgb));
    vec![
        diffuse("bark", [0.22, 0.17, 0.13]),
        diffuse("grass", [0.2, 0.32, 0.1]),
        diffuse("leaf", [0.16, 0.4, 0.08]),
        diffuse("leaf, light", [0.3, 0.5, 0.1]),
        diffuse("leaf, dark", [0.1, 0.3, 0.07]),
    ]
}

/// One straight piece of a branch.
struct Piece {
    a: Vec3,
    b: Vec3,
    radii: [f32; 2],
    /// Segments round it: thick limbs get more.
    around: u32,
}

/// The woody skeleton: every branch's pieces, and the twigs (as their pieces' end points)
/// that carry the leaves.
#[derive(Default)]
struct Skeleton {
    pieces: Vec<Piece>,
    twigs: Vec<[Vec3; 2]>,
}

impl Skeleton {
    fn triangles(&self) -> usize {
        self.pieces.iter().map(|p| 2 * p.around as usize).sum()
    }

    /// Grows a branch of generation `generation` from `start` along `direction`, then its
    /// children.
    fn grow(
        &mut self,
        random: &mut Random,
        start: Vec3,
        direction: Vec3,
        length: f32,
        radius: f32,
        generation: u32,
    ) {
        let end_radius = radius * 0.65;
        let mut at = start;
        let mut heading = direction;
        for piece in 0..PIECES {
            // A little wander, and a little lift toward the light.
            heading = (heading + random_unit(random) * 0.18 + Vec3::Y * 0.08).normalize();
            let next = at + heading * (length / PIECES as f32);
            let t = |k: u32| k as f32 / PIECES as f32;
            let radii =
                [radius + (end_radius - radius) * t(piece), radius + (end_radius - radius) * t(piece + 1)];
            let around = (radius * 60.0).clamp(4.0, 16.0) as u32;
            self.pieces.push(Piece { a: at, b: next, radii, around });
            at = next;
        }
        if generation == GENERATIONS {
            self.twigs.push([start, at]);
            return;
        }
        let spin = random.range(0.0, TAU);
        // The leader carries on; two forks and a side shoot spread out at the golden angle.
        let children = [(0.0, 0.8, 0.75), (0.6, 0.7, 0.6), (0.75, 0.65, 0.55), (0.9, 0.5, 0.45)];
        for (k, &(bend, scale, thickness)) in children.iter().enumerate() {
            let azimuth = spin + k as f32 * 2.4;
            let from = if k == 3 { start.lerp(at, 0.5) } else { at };
            let side = perpendicular(heading, azimuth);
            let dir = (heading * (1.0 - bend) + side * bend + Vec3::Y * 0.15).normalize();
            let length = length * scale * random.range(0.85, 1.15);
            self.grow(random, from, dir, length, end_radius * thickness / 0.65, generation + 1);
        }
    }
}

/// A unit vector perpendicular to the unit `axis`, at `azimuth` about it.
fn perpendicular(axis: Vec3, azimuth: f32) -> Vec3 {
    let u = axis.any_orthonormal_vector();
    let v = axis.cross(u);
    u * azimuth.cos() + v * azimuth.sin()
}

/// A random direction, uniform on the sphere.
fn random_unit(random: &mut Random) -> Vec3 {
    let z = random.range(-1.0, 1.0);
    let phi = random.range(0.0, TAU);
    let r = (1.0 - z * z).sqrt();
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// A five-lobed leaf of span `size` around `centre`, in the plane with the unit `normal`, its
/// middle lobe toward the unit `tip`: ten triangles fanned from the centre over alternating
/// lobe tips and notches.
fn leaf(centre: Vec3, normal: Vec3, tip: Vec3, size: f32, part: &mut Part) {
    let across = normal.cross(tip);
    let base = part.positions.len() as u32;
    part.positions.push(centre);
    for k in 0..LEAF_TRIANGLES {
        let angle = TAU * k as f32 / LEAF_TRIANGLES as f32;
        // Tips on the even points, the lowest lobe pair shorter, notches at 45 %.
        let reach = if k % 2 == 1 {
            0.45
        } else if k == 4 || k == 6 {
            0.75
        } else {
            1.0
        };
        let r = 0.5 * size * reach;
        part.positions.push(centre + (tip * angle.cos() + across * angle.sin()) * r);
    }
    let n = LEAF_TRIANGLES as u32;
    part.triangles.extend((0..n).map(|k| [base, base + 1 + k, base + 1 + (k + 1) % n]));
    part.normals.get_or_insert_with(Vec::new).extend(std::iter::repeat_n(normal, LEAF_TRIANGLES + 1));
}

/// The leaves: `count` of them spread over the twigs, each on the outer four fifths of its
/// twig, facing up and out from the trunk with some scatter.
fn leaves(skeleton: &Skeleton, count: usize, random: &mut Random) -> Vec<Part> {
    let mut parts: Vec<Part> = LEAVES.iter().map(|&material| Part { material, ..Part::default() }).collect();
    let twigs = skeleton.twigs.len();
    for (t, &[a, b]) in skeleton.twigs.iter().enumerate() {
        // Leaves shared out evenly, the remainder one each to the first twigs.
        let here = count / twigs + usize::from(t < count % twigs);
        for _ in 0..here {
            let at = a.lerp(b, random.range(0.2, 1.0));
            let out = Vec3::new(at.x, 0.0, at.z).normalize_or(Vec3::X);
            let normal = (Vec3::Y * 0.8 + out * 0.5 + random_unit(random) * 0.7).normalize();
            let tip = perpendicular(normal, random.range(0.0, TAU));
            let centre = at + random_unit(random) * 0.12;
            let part = &mut parts[random.below(LEAVES.len() as u32) as usize];
            leaf(centre, normal, tip, random.range(0.11, 0.16), part);
        }
    }
    parts
}

/// The skeleton, always the same: a 3.2 m trunk, 26 cm thick at the foot.
fn skeleton() -> Skeleton {
    let mut skeleton = Skeleton::default();
    skeleton.grow(&mut Random::new(0x3a91e), Vec3::ZERO, Vec3::Y, 3.2, 0.26, 0);
    skeleton
}

/// The triangles of the tree with one leaf per twig: the least `triangles` can ask for.
pub(super) fn minimum_triangles() -> usize {
    let skeleton = skeleton();
    skeleton.triangles() + skeleton.twigs.len() * LEAF_TRIANGLES
}

/// The tree with as many leaves as about `triangles` triangles in all leave room for, on a
/// meadow, with its camera, sun and sky.
pub(super) fn scene(triangles: usize) -> Scene {
    let skeleton = skeleton();
    let leaf_count = triangles.saturating_sub(skeleton.triangles()) / LEAF_TRIANGLES;
    let mut builder = MeshBuilder::new("maple-tree");
    for piece in &skeleton.pieces {
        builder.add(tube(piece.a, piece.b, piece.radii, piece.around, 1, BARK)).expect("finite branches");
    }
    for part in leaves(&skeleton, leaf_count.max(skeleton.twigs.len()), &mut Random::new(0x1eaf)) {
        builder.add(part).expect("finite leaves");
    }
    let mut meadow = MeshBuilder::new("meadow");
    meadow.add(quad(Vec3::ZERO, Vec3::Z * 60.0, Vec3::X * 60.0, GRASS)).expect("a finite quad");
    let tree = Scene::placed_once(
        vec![builder.finish().mesh, meadow.finish().mesh],
        materials(),
        Camera::looking_at(Vec3::new(5.0, 2.2, 17.0), Vec3::new(-2.5, 4.2, 0.0), 55.0),
    );
    outdoors(tree, Vec3::new(-0.75, -0.5, 0.35))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn leaves_fill_the_count_asked_for() {
        let skeleton = skeleton();
        assert!(skeleton.twigs.len() > 2000, "{} twigs", skeleton.twigs.len());
        let asked = 300_000;
        let scene = scene(asked);
        let made = scene.meshes[0].indices.len();
        assert!(made <= asked && made + LEAF_TRIANGLES > asked, "{made} for {asked}");
    }
}
