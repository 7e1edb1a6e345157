//! The traversal kernels against brute force and against each other: the BVH never misses what
//! a loop over all triangles finds, packets equal single rays lane by lane, instancing equals
//! baked geometry, rays cannot slip through the shared edges of a closed mesh, cut-out hits
//! are no hits for any query, packets included, and the shadow cache changes no answer.

use glam::{Affine3A, Quat, Vec3};
use igi_bvh::{
    Aabb, Accel, CutoutTest, Hit, HitPacket8, INVALID_ID, Ray, RayPacket8, ShadowCache, TriangleMesh,
    intersect_triangle, offset_ray_origin,
};
use igi_simd::M32x8;
use rand_core::{RngCore, SeedableRng};
use rand_xoshiro::SplitMix64;
use std::sync::Arc;

/// Small deterministic generator (SplitMix64) so failures reproduce.
struct Rng(SplitMix64);
impl Rng {
    fn f(&mut self) -> f32 {
        (self.0.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }
    fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.f()
    }
    fn v(&mut self, lo: f32, hi: f32) -> Vec3 {
        Vec3::new(self.range(lo, hi), self.range(lo, hi), self.range(lo, hi))
    }
    fn dir(&mut self) -> Vec3 {
        loop {
            let v = self.v(-1.0, 1.0);
            if v.length_squared() > 1e-4 && v.length_squared() <= 1.0 {
                return v.normalize();
            }
        }
    }
}

fn soup(rng: &mut Rng, n: usize, size: f32) -> TriangleMesh {
    let mut m = TriangleMesh::default();
    for i in 0..n {
        let c = rng.v(-10.0, 10.0);
        for _ in 0..3 {
            m.positions.push(c + rng.v(-size, size));
        }
        let b = 3 * i as u32;
        m.indices.push([b, b + 1, b + 2]);
    }
    m
}

fn single(mesh: TriangleMesh) -> (Accel, TriangleMesh) {
    let (accel, _) = Accel::build(vec![mesh], &[(0, Affine3A::IDENTITY)]);
    let stored = accel.meshes()[0].clone();
    (accel, stored)
}

/// The closest hit by looping over every triangle, with the kernels' tie rule.
fn brute_closest(mesh: &TriangleMesh, ray: &Ray) -> Hit {
    brute_closest_kept(mesh, ray, |_, _, _| true)
}

/// [`brute_closest`] of the hits (triangle, u, v) that `kept` keeps.
fn brute_closest_kept(mesh: &TriangleMesh, ray: &Ray, kept: impl Fn(u32, f32, f32) -> bool) -> Hit {
    let mut best = Hit::miss(ray.tfar);
    for p in 0..mesh.indices.len() as u32 {
        let r = Ray { tfar: best.t, ..*ray };
        if let Some((t, u, v)) = intersect_triangle(&r, mesh.triangle(p)).filter(|&(_, u, v)| kept(p, u, v)) {
            if t < best.t || (t == best.t && p < best.prim) {
                best = Hit { t, u, v, instance: 0, prim: p };
            }
        }
    }
    best
}

/// A random ray; every other one is aimed at a random triangle's centroid so that even tiny
/// soups are hit often.
fn random_ray(rng: &mut Rng, mesh: &TriangleMesh) -> Ray {
    let origin = rng.v(-15.0, 15.0);
    let target = if rng.f() < 0.5 {
        rng.v(-10.0, 10.0)
    } else {
        let [a, b, c] = mesh.triangle((rng.0.next_u64() % mesh.indices.len() as u64) as u32);
        (a + b + c) / 3.0
    };
    let mut r = Ray::new(origin, target - origin);
    if rng.f() < 0.3 {
        r.tfar = rng.range(0.2, 1.2);
    }
    r
}

#[test]
fn closest_and_any_hit_equal_brute_force() {
    let mut rng = Rng(SplitMix64::seed_from_u64(1));
    for (n, size) in [(1, 3.0), (7, 2.0), (300, 1.5), (3000, 0.8)] {
        let (accel, mesh) = single(soup(&mut rng, n, size));
        let mut hits = 0;
        for _ in 0..2000 {
            let ray = random_ray(&mut rng, &mesh);
            let want = brute_closest(&mesh, &ray);
            let got = accel.intersect(&ray);
            assert_eq!(got, want, "closest hit, {n} triangles, ray {ray:?}");
            assert_eq!(accel.occluded(&ray), want.is_hit(), "any hit, {n} triangles, ray {ray:?}");
            hits += want.is_hit() as u32;
        }
        assert!(hits > 500, "the test must exercise hits ({hits} with {n} triangles)");
    }
}

/// Lane `i` of a packet's hits as a single hit record.
fn lane_hit(hits: &HitPacket8, i: usize) -> Hit {
    Hit {
        t: hits.t.lane(i),
        u: hits.u.lane(i),
        v: hits.v.lane(i),
        instance: hits.instance.lane(i) as u32,
        prim: hits.prim.lane(i) as u32,
    }
}

fn packet_of(rays: &[Ray; 8]) -> RayPacket8 {
    RayPacket8::from_rays(rays)
}

fn check_packet(accel: &Accel, rays: &[Ray; 8], active: M32x8) {
    let p = packet_of(rays);
    let hits = accel.intersect8(&p, active);
    let occ = accel.occluded8(&p, active);
    for (i, ray) in rays.iter().enumerate() {
        if active.lane(i) {
            assert_eq!(lane_hit(&hits, i), accel.intersect(ray), "lane {i} closest, ray {ray:?}");
            assert_eq!(occ.lane(i), accel.occluded(ray), "lane {i} any, ray {ray:?}");
        } else {
            assert_eq!(lane_hit(&hits, i).prim, INVALID_ID, "inactive lane {i} must miss");
            assert!(!occ.lane(i), "inactive lane {i} must not be occluded");
        }
    }
}

/// The rays of packet `round`: incoherent packets (mixed permutations) alternate with
/// coherent ones (a pinhole camera's 4x2 block, or shadow rays converging on one point).
fn packet_rays(rng: &mut Rng, mesh: &TriangleMesh, round: u32) -> [Ray; 8] {
    match round % 3 {
        0 => std::array::from_fn(|_| random_ray(rng, mesh)),
        1 => {
            let o = rng.v(-15.0, 15.0);
            let d = rng.dir();
            std::array::from_fn(|i| Ray::new(o, d + 0.02 * Vec3::new((i % 4) as f32, (i / 4) as f32, 0.0)))
        }
        _ => {
            let light = rng.v(-12.0, 12.0);
            let c = rng.v(-10.0, 10.0);
            std::array::from_fn(|_| {
                let o = c + rng.v(-1.0, 1.0);
                Ray { origin: o, dir: light - o, tnear: 1e-4, tfar: 1.0 - 1e-4 }
            })
        }
    }
}

#[test]
fn packets_equal_single_rays_lane_by_lane() {
    let mut rng = Rng(SplitMix64::seed_from_u64(2));
    let (accel, mesh) = single(soup(&mut rng, 2000, 1.0));
    for round in 0..1500 {
        let rays = packet_rays(&mut rng, &mesh, round);
        let active =
            M32x8::from_bitmask(if round % 5 == 0 { (rng.0.next_u64() & 0xff) as u32 } else { 0xff });
        check_packet(&accel, &rays, active);
    }
}

/// A stand-in for an alpha texture: even triangles are cut where u > 0.3.
#[derive(Debug)]
struct CutEvenTriangles;

impl CutoutTest for CutEvenTriangles {
    fn is_cut(&self, _mesh: u32, prim: u32, u: f32, _v: f32) -> bool {
        prim.is_multiple_of(2) && u > 0.3
    }
}

#[test]
fn cut_out_hits_are_no_hits_and_packets_equal_single_rays_through_them() {
    let mut rng = Rng(SplitMix64::seed_from_u64(5));
    let (mut accel, mesh) = single(soup(&mut rng, 2000, 1.0));
    let flags: Vec<bool> = (0..mesh.indices.len()).map(|p| p.is_multiple_of(2)).collect();
    accel.set_cutouts(&[flags], Arc::new(CutEvenTriangles));
    let (mut passed, mut hits) = (0, 0);
    for _ in 0..3000 {
        let ray = random_ray(&mut rng, &mesh);
        let want = brute_closest_kept(&mesh, &ray, |p, u, v| !CutEvenTriangles.is_cut(0, p, u, v));
        assert_eq!(accel.intersect(&ray), want, "closest hit, ray {ray:?}");
        assert_eq!(accel.occluded(&ray), want.is_hit(), "any hit, ray {ray:?}");
        hits += u32::from(want.is_hit());
        passed += u32::from(brute_closest(&mesh, &ray) != want);
    }
    assert!(hits > 500 && passed > 100, "{hits} hits, {passed} rays passed a cut");
    for round in 0..1500 {
        let rays = packet_rays(&mut rng, &mesh, round);
        let active =
            M32x8::from_bitmask(if round % 5 == 0 { (rng.0.next_u64() & 0xff) as u32 } else { 0xff });
        check_packet(&accel, &rays, active);
    }
}

/// A mesh placed three times under rotations, scales and translations hits exactly where the
/// same triangles transformed into world space ("baked") are hit.
#[test]
fn instanced_hits_equal_baked_geometry() {
    let mut rng = Rng(SplitMix64::seed_from_u64(3));
    let mesh = soup(&mut rng, 400, 1.0);
    let transforms = [
        Affine3A::IDENTITY,
        Affine3A::from_scale_rotation_translation(
            Vec3::splat(0.5),
            Quat::from_rotation_y(0.7),
            Vec3::new(30.0, 0.0, 0.0),
        ),
        Affine3A::from_scale_rotation_translation(
            Vec3::new(1.0, 2.0, 0.7),
            Quat::from_euler(glam::EulerRot::XYZ, 0.3, -1.1, 2.0),
            Vec3::new(-5.0, 25.0, 8.0),
        ),
    ];
    let instances: Vec<(u32, Affine3A)> = transforms.iter().map(|&m| (0, m)).collect();
    let (inst_accel, _) = Accel::build(vec![mesh.clone()], &instances);
    let stored = inst_accel.meshes()[0].clone();
    let baked_meshes: Vec<TriangleMesh> = transforms
        .iter()
        .map(|m| TriangleMesh {
            positions: stored.positions.iter().map(|&p| m.transform_point3(p)).collect(),
            indices: stored.indices.clone(),
        })
        .collect();
    // The baked scene keeps each copy as its own mesh so that (instance, prim) ids line up.
    let baked_instances: Vec<(u32, Affine3A)> = (0..3).map(|i| (i, Affine3A::IDENTITY)).collect();
    let (baked, orders) = Accel::build(baked_meshes, &baked_instances);
    let mut checked = 0;
    for _ in 0..3000 {
        // Aim at a triangle centroid so the ray is far from edges in both versions.
        let inst = (rng.0.next_u64() % 3) as usize;
        let prim = (rng.0.next_u64() % stored.indices.len() as u64) as u32;
        let [a, b, c] = stored.triangle(prim);
        let target = transforms[inst].transform_point3((a + b + c) / 3.0);
        let origin = target + rng.dir() * rng.range(3.0, 40.0);
        let ray = Ray::new(origin, target - origin);
        // Grazing rays amplify rounding in t by 1/cos; keep to well-conditioned hits.
        let n = inst_accel.geometric_normal(inst as u32, prim);
        if n.dot(ray.dir.normalize()).abs() < 0.2 {
            continue;
        }
        let h = inst_accel.intersect(&ray);
        let g = baked.intersect(&ray);
        assert_eq!(h.is_hit(), g.is_hit());
        if !h.is_hit() {
            continue;
        }
        let baked_prim = orders[g.instance as usize][g.prim as usize];
        assert_eq!((h.instance, h.prim), (g.instance, baked_prim), "same triangle of the same copy");
        assert!(
            (h.t - g.t).abs() <= 1e-4 * g.t.max(1.0),
            "t {} vs {} inst {} prim {} ray {ray:?}",
            h.t,
            g.t,
            h.instance,
            h.prim
        );
        let n1 = inst_accel.geometric_normal(h.instance, h.prim);
        let n2 = baked.geometric_normal(g.instance, g.prim);
        assert!(n1.dot(n2) > 0.9999, "normals {n1} vs {n2}");
        // Packets through instances equal single rays.
        check_packet(&inst_accel, &[ray; 8], M32x8::ALL);
        checked += 1;
    }
    assert!(checked > 1500, "only {checked} rays checked");
}

/// Axis-aligned boxes on a grid of whole coordinates, two triangles per face: their BVH boxes
/// share planes with the triangles.
fn grid_boxes(rng: &mut Rng, n: usize) -> TriangleMesh {
    let mut m = TriangleMesh::default();
    for _ in 0..n {
        let lo = Vec3::new(rng.range(-6.0, 5.0), rng.range(-6.0, 5.0), rng.range(-6.0, 5.0)).floor();
        let hi = lo + Vec3::new(rng.range(1.0, 3.0), rng.range(1.0, 3.0), rng.range(1.0, 3.0)).floor();
        let b = m.positions.len() as u32;
        for i in 0..8 {
            let pick = |bit: usize, a: f32, b: f32| if i & bit == 0 { a } else { b };
            m.positions.push(Vec3::new(pick(1, lo.x, hi.x), pick(2, lo.y, hi.y), pick(4, lo.z, hi.z)));
        }
        for [p, q, r, s] in
            [[0, 1, 3, 2], [4, 6, 7, 5], [0, 4, 5, 1], [2, 3, 7, 6], [0, 2, 6, 4], [1, 5, 7, 3]]
        {
            m.indices.push([b + p, b + q, b + r]);
            m.indices.push([b + p, b + r, b + s]);
        }
    }
    m
}

/// A ray parallel to two axes (directions with exact zeros) whose origin lies on whole
/// coordinates, so in the planes of box faces and of the BVH's boxes.
fn grid_ray(rng: &mut Rng) -> Ray {
    let whole = |rng: &mut Rng| rng.range(-7.0, 7.0).floor();
    let origin = Vec3::new(whole(rng), whole(rng), whole(rng));
    let axis = (rng.0.next_u64() % 3) as usize;
    let mut dir = Vec3::ZERO;
    dir[axis] = if rng.f() < 0.5 { 1.0 } else { -1.0 };
    Ray { origin, dir, tnear: 1e-3, tfar: 20.0 }
}

/// A ray whose direction has an exact zero component and whose origin lies in the plane of a
/// BVH box's face on that axis is inside the box's slab on that axis: the box test must enter
/// the box, or the walk misses what brute force hits (ARCHITECTURE.md, "Rays in a box face").
#[test]
fn rays_in_box_faces_equal_brute_force() {
    let mut rng = Rng(SplitMix64::seed_from_u64(7));
    let (accel, mesh) = single(grid_boxes(&mut rng, 40));
    let mut hits = 0;
    for round in 0..2000 {
        let rays: [Ray; 8] = std::array::from_fn(|_| grid_ray(&mut rng));
        let want = brute_closest(&mesh, &rays[0]);
        assert_eq!(accel.intersect(&rays[0]), want, "closest hit, ray {:?}", rays[0]);
        assert_eq!(accel.occluded(&rays[0]), want.is_hit(), "any hit, ray {:?}", rays[0]);
        hits += want.is_hit() as u32;
        // The same rays in packets: mixed, and eight copies of one ray (one octant).
        check_packet(&accel, &rays, M32x8::ALL);
        check_packet(&accel, &[rays[round % 8]; 8], M32x8::ALL);
    }
    assert!(hits > 400, "the test must exercise hits ({hits})");
}

/// Rays with NaN in their origin or direction hit nothing and do not upset the walks (their
/// plane distances are all NaN, which the box tests fold into no interval: the walks must
/// still enter only the nodes' used slots), alone and as lanes of packets.
#[test]
fn rays_with_nan_hit_nothing() {
    let mut rng = Rng(SplitMix64::seed_from_u64(11));
    let (accel, mesh) = single(soup(&mut rng, 3000, 0.8));
    let nan = f32::NAN;
    let odd = [
        Ray::new(Vec3::new(nan, 0.0, 0.0), Vec3::X),
        Ray::new(Vec3::ZERO, Vec3::new(0.0, nan, 1.0)),
        Ray::new(Vec3::splat(nan), Vec3::splat(nan)),
    ];
    for ray in odd {
        assert!(!accel.intersect(&ray).is_hit(), "{ray:?}");
        assert!(!accel.occluded(&ray), "{ray:?}");
    }
    for round in 0..200 {
        let mut rays = packet_rays(&mut rng, &mesh, round);
        rays[round as usize % 8] = odd[round as usize % 3];
        check_packet(&accel, &rays, M32x8::ALL);
    }
}

/// A closed UV sphere: rays aimed exactly at its shared vertices and edge midpoints, from inside
/// and outside, must all hit.
#[test]
fn no_ray_leaks_through_shared_edges() {
    let (rings, segments) = (48u32, 96u32);
    let mut m = TriangleMesh::default();
    let centre = Vec3::new(0.3, -0.2, 0.1);
    m.positions.push(centre + Vec3::Y);
    for r in 1..rings {
        let th = std::f32::consts::PI * r as f32 / rings as f32;
        for s in 0..segments {
            let ph = std::f32::consts::TAU * s as f32 / segments as f32;
            m.positions.push(centre + Vec3::new(th.sin() * ph.cos(), th.cos(), th.sin() * ph.sin()));
        }
    }
    m.positions.push(centre - Vec3::Y);
    let ring = |r: u32, s: u32| 1 + (r - 1) * segments + s % segments;
    let bottom = m.positions.len() as u32 - 1;
    for s in 0..segments {
        m.indices.push([0, ring(1, s + 1), ring(1, s)]);
        m.indices.push([bottom, ring(rings - 1, s), ring(rings - 1, s + 1)]);
        for r in 1..rings - 1 {
            m.indices.push([ring(r, s), ring(r, s + 1), ring(r + 1, s)]);
            m.indices.push([ring(r, s + 1), ring(r + 1, s + 1), ring(r + 1, s)]);
        }
    }
    let mut targets: Vec<Vec3> = m.positions.clone();
    for t in &m.indices {
        for e in 0..3 {
            targets.push(0.5 * (m.positions[t[e] as usize] + m.positions[t[(e + 1) % 3] as usize]));
        }
    }
    let (accel, _) = single(m);
    let mut rng = Rng(SplitMix64::seed_from_u64(4));
    let mut rays = Vec::new();
    for &p in &targets {
        rays.push(Ray::new(centre + 0.01 * rng.v(-1.0, 1.0), p - centre));
        let outside = p + (p - centre).normalize() * 2.0 + 0.5 * rng.v(-1.0, 1.0);
        rays.push(Ray::new(outside, p - outside));
    }
    for chunk in rays.chunks_exact(8) {
        let rays: [Ray; 8] = chunk.try_into().unwrap();
        for r in &rays {
            assert!(accel.intersect(r).is_hit(), "ray {r:?} leaked");
            assert!(accel.occluded(r), "shadow ray {r:?} leaked");
        }
        let p = packet_of(&rays);
        assert_eq!(accel.intersect8(&p, M32x8::ALL).hit_mask().bitmask(), 0xff);
        assert_eq!(accel.occluded8(&p, M32x8::ALL).bitmask(), 0xff);
    }
}

/// Secondary rays leaving a convex surface from offset origins never hit the surface they left.
#[test]
fn offset_origins_avoid_self_intersection() {
    let mut rng = Rng(SplitMix64::seed_from_u64(5));
    for scale in [1e-2f32, 1.0, 1e3] {
        let mut m = soup(&mut rng, 0, 1.0);
        // A large, tilted quad far from the origin stresses the ulp-scaled offset.
        let o = Vec3::new(1234.5, -77.25, 3.5) * scale;
        let (u, v) = (Vec3::new(1.0, 0.2, 0.1) * scale, Vec3::new(-0.1, 0.3, 1.0) * scale);
        m.positions = vec![o, o + u, o + u + v, o + v];
        m.indices = vec![[0, 1, 2], [0, 2, 3]];
        let (accel, _) = single(m);
        let n = u.cross(v);
        for _ in 0..2000 {
            let p = o + rng.f() * u + rng.f() * v;
            let from = p + n.normalize() * scale;
            let h = accel.intersect(&Ray::new(from, p - from));
            if !h.is_hit() {
                continue;
            }
            let hit_p = from + h.t * (p - from);
            let start = offset_ray_origin(hit_p, n);
            let mut d = rng.dir();
            if d.dot(n) < 0.0 {
                d = -d;
            }
            assert!(!accel.occluded(&Ray::new(start, d)), "self-intersection at scale {scale}");
        }
    }
}

/// Shadow packets toward one light traced with the light's shadow cache are blocked exactly
/// where `occluded8` blocks them: through a moved instance (whose triangles are not cached),
/// cut-outs, partly active packets, and caches holding a triangle from another light.
#[test]
fn the_shadow_cache_changes_no_answer() {
    let mut rng = Rng(SplitMix64::seed_from_u64(13));
    let mesh = soup(&mut rng, 1500, 1.5);
    let instances = [
        (0, Affine3A::IDENTITY),
        (
            0,
            Affine3A::from_scale_rotation_translation(
                Vec3::splat(0.6),
                Quat::from_rotation_z(0.4),
                Vec3::X * 4.0,
            ),
        ),
    ];
    let (mut accel, _) = Accel::build(vec![mesh.clone()], &instances);
    let flags: Vec<bool> = (0..mesh.indices.len()).map(|p| p.is_multiple_of(2)).collect();
    let (mut blocked, mut free) = (0u32, 0u32);
    let mut cache = ShadowCache::default();
    for light in 0..80 {
        if light == 40 {
            accel.set_cutouts(std::slice::from_ref(&flags), Arc::new(CutEvenTriangles));
        }
        if light % 3 != 0 {
            // Every third light starts with the previous light's cache.
            cache = ShadowCache::default();
        }
        let target = rng.v(-10.0, 10.0);
        // Half the lights are surrounded by their points, so a triangle that blocks one side's
        // rays lies beyond the light for the other side (the cached test must respect tfar).
        let centre = if light % 2 == 0 { target } else { rng.v(-10.0, 10.0) };
        for _ in 0..30 {
            let rays: [Ray; 8] = std::array::from_fn(|_| {
                let o = centre + rng.v(-4.0, 4.0);
                Ray { origin: o, dir: target - o, tnear: 1e-4, tfar: 1.0 - 1e-4 }
            });
            let bits =
                if rng.0.next_u64().is_multiple_of(4) { (rng.0.next_u64() & 0xff) as u32 } else { 0xff };
            let (p, a) = (packet_of(&rays), M32x8::from_bitmask(bits));
            let want = accel.occluded8(&p, a);
            assert_eq!(accel.occluded8_cached(&p, a, &mut cache).bitmask(), want.bitmask(), "light {light}");
            blocked += want.bitmask().count_ones();
            free += a.and_not(want).bitmask().count_ones();
        }
    }
    assert!(blocked > 1000 && free > 1000, "{blocked} blocked and {free} free lanes");
}

/// The top level bounds a turned instance by its BVH's placed boxes a few levels down: every
/// placed vertex inside, and tighter than the placed box of the whole mesh's box.
#[test]
fn instance_bounds_hold_every_placed_vertex_and_hug_a_turned_mesh() {
    let mut rng = Rng(SplitMix64::seed_from_u64(11));
    // A ring of small triangles round the y axis, turned 45° about it: its extent stays a
    // 20 x 20 square while the placed box of its local box grows to 28 x 28.
    let mut mesh = soup(&mut rng, 2000, 0.05);
    for (i, p) in mesh.positions.iter_mut().enumerate() {
        let angle = (i / 3) as f32 * 0.0031;
        *p = Vec3::new(10.0 * angle.cos(), 0.0, 10.0 * angle.sin()) + (*p - Vec3::splat(0.0)) * 0.01;
    }
    let m = Affine3A::from_rotation_translation(Quat::from_rotation_y(0.785), Vec3::new(3.0, -2.0, 1.0));
    let (accel, _) = Accel::build(vec![mesh.clone()], &[(0, m)]);
    let bounds = accel.bounds();
    for &p in &mesh.positions {
        let q = m.transform_point3(p);
        assert!(q.cmpge(bounds.min).all() && q.cmple(bounds.max).all(), "{q} outside {bounds:?}");
    }
    let whole = Aabb::from_points(
        Aabb::from_points(mesh.positions.iter().copied()).corners().map(|c| m.transform_point3(c)),
    );
    assert!(
        bounds.half_area() < 0.7 * whole.half_area(),
        "{} against {}",
        bounds.half_area(),
        whole.half_area()
    );
}
