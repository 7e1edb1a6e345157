//! Criterion benchmarks of the traversal kernels on a synthetic closed scene (a finely
//! tessellated sphere inside a box, seen from inside the box): primary rays (closest hit) and
//! shadow rays toward a point (any hit), single rays against 8-ray packets. `igi bench rays`
//! measures the same kernels on real scenes against Embree.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use glam::{Affine3A, Vec3};
use igi_bvh::{Accel, Ray, RayPacket8, TriangleMesh};
use igi_simd::M32x8;
use std::hint::black_box;

fn scene() -> Accel {
    let mut m = TriangleMesh::default();
    let (rings, segs) = (200u32, 400u32);
    for r in 0..=rings {
        let th = std::f32::consts::PI * r as f32 / rings as f32;
        for s in 0..=segs {
            let ph = std::f32::consts::TAU * s as f32 / segs as f32;
            m.positions.push(Vec3::new(th.sin() * ph.cos(), th.cos() + 1.2, th.sin() * ph.sin()) * 0.5);
        }
    }
    let at = |r: u32, s: u32| r * (segs + 1) + s;
    for r in 0..rings {
        for s in 0..segs {
            m.indices.push([at(r, s), at(r, s + 1), at(r + 1, s)]);
            m.indices.push([at(r, s + 1), at(r + 1, s + 1), at(r + 1, s)]);
        }
    }
    // A 4 x 4 x 4 box around it (12 triangles).
    let b = m.positions.len() as u32;
    for z in [-2.0, 2.0] {
        for y in [-1.0, 3.0] {
            for x in [-2.0, 2.0] {
                m.positions.push(Vec3::new(x, y, z));
            }
        }
    }
    for [a, c, d, e] in [[0, 1, 3, 2], [4, 6, 7, 5], [0, 4, 5, 1], [2, 3, 7, 6], [0, 2, 6, 4], [1, 5, 7, 3]] {
        m.indices.push([b + a, b + c, b + d]);
        m.indices.push([b + a, b + d, b + e]);
    }
    Accel::build(vec![m], &[(0, Affine3A::IDENTITY)]).0
}

/// 8-ray packets of a 64 x 64 pinhole image in 4x2 blocks.
fn camera_packets() -> Vec<[Ray; 8]> {
    let eye = Vec3::new(0.0, 1.0, 1.9);
    let ray = |x: u32, y: u32| {
        let (sx, sy) = ((x as f32 + 0.5) / 64.0 - 0.5, 0.5 - (y as f32 + 0.5) / 64.0);
        Ray::new(eye, Vec3::new(sx, sy, -1.0).normalize())
    };
    let mut out = Vec::new();
    for by in (0..64).step_by(2) {
        for bx in (0..64).step_by(4) {
            out.push(std::array::from_fn(|i| ray(bx + i as u32 % 4, by + i as u32 / 4)));
        }
    }
    out
}

fn bench(c: &mut Criterion) {
    let accel = scene();
    let packets = camera_packets();
    let light = Vec3::new(0.3, 2.8, -0.5);
    let shadow: Vec<[Ray; 8]> = packets
        .iter()
        .map(|p| {
            p.map(|r| {
                let h = accel.intersect(&r);
                let o = r.at(h.t.min(10.0));
                Ray { origin: o, dir: light - o, tnear: 1e-4, tfar: 1.0 - 1e-4 }
            })
        })
        .collect();
    let n = (packets.len() * 8) as u64;
    let mut g = c.benchmark_group("kernels");
    g.throughput(Throughput::Elements(n));
    g.bench_function("primary/single", |b| {
        b.iter(|| packets.iter().flatten().filter(|r| accel.intersect(black_box(r)).is_hit()).count())
    });
    g.bench_function("primary/packet8", |b| {
        b.iter(|| {
            packets
                .iter()
                .map(|p| {
                    accel
                        .intersect8(&RayPacket8::from_rays(black_box(p)), M32x8::ALL)
                        .hit_mask()
                        .bitmask()
                        .count_ones()
                })
                .sum::<u32>()
        })
    });
    g.bench_function("shadow/single", |b| {
        b.iter(|| shadow.iter().flatten().filter(|r| accel.occluded(black_box(r))).count())
    });
    g.bench_function("shadow/packet8", |b| {
        b.iter(|| {
            shadow
                .iter()
                .map(|p| {
                    accel.occluded8(&RayPacket8::from_rays(black_box(p)), M32x8::ALL).bitmask().count_ones()
                })
                .sum::<u32>()
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
