//! The BVH builders: every documented invariant of `Bvh` on many input distributions (down to
//! one primitive, coincident centroids, flat clusters, empty boxes, depth-hostile spacing), the
//! same tree at any thread count, SAH cost within 5 % of the full-sweep reference, and refitting.

#[path = "../benches/triangle_soup/mod.rs"]
mod triangle_soup;

use glam::Vec3;
use igi_bvh::{
    Aabb, BuildParams, Bvh, Bvh8, Bvh8Node, TRAVERSAL_STACK_SIZE, build_binned_sah, build_sweep_sah,
};
use triangle_soup::{Rng, SCENES, Triangle, load_scene, random_triangles, triangle_bounds};

/// The smallest box containing both boxes.
fn box_union(a: Aabb, b: Aabb) -> Aabb {
    Aabb { min: a.min.min(b.min), max: a.max.max(b.max) }
}

/// True if `inner` lies inside `outer` (boundaries included).
fn contains(outer: &Aabb, inner: &Aabb) -> bool {
    outer.min.cmple(inner.min).all() && outer.max.cmpge(inner.max).all()
}

/// Checks every invariant documented on [`Bvh`], with `context` in the panic messages.
fn check_invariants(bvh: &Bvh, prims: &[Aabb], params: &BuildParams, context: &str) {
    let n = prims.len();
    assert_eq!(bvh.prim_order.len(), n, "{context}: prim_order length");
    if n == 0 {
        assert!(bvh.nodes.is_empty(), "{context}: empty input gives no nodes");
        return;
    }
    let mut seen = vec![false; n];
    for &p in &bvh.prim_order {
        assert!(!std::mem::replace(&mut seen[p as usize], true), "{context}: {p} twice in prim_order");
    }

    let mut walk = Walk {
        bvh,
        prims,
        max_leaf_size: params.max_leaf_size,
        context,
        reached: vec![false; bvh.nodes.len()],
        covered: vec![false; n],
        leaves: 0,
        next_pair: 1,
    };
    let (_, depth) = walk.node(0, 1);
    assert!(walk.reached.iter().all(|&r| r), "{context}: unreachable nodes");
    assert!(walk.covered.iter().all(|&c| c), "{context}: primitives in no leaf");
    assert!(depth <= TRAVERSAL_STACK_SIZE, "{context}: depth {depth} > TRAVERSAL_STACK_SIZE");
    assert_eq!(bvh.depth(), depth, "{context}: Bvh::depth");
    assert_eq!(bvh.leaf_count(), walk.leaves, "{context}: Bvh::leaf_count");
    if n == 1 {
        assert_eq!(bvh.nodes.len(), 1, "{context}: one primitive gives a single leaf");
    }
}

/// A walk over a BVH from the root that checks every node and records what it has seen.
struct Walk<'a> {
    bvh: &'a Bvh,
    prims: &'a [Aabb],
    max_leaf_size: u32,
    context: &'a str,
    reached: Vec<bool>,
    covered: Vec<bool>,
    leaves: usize,
    /// Where the next child pair must be in the depth-first layout: after the pairs of all the
    /// inner nodes walked so far.
    next_pair: usize,
}

impl Walk<'_> {
    /// Checks node `i` at `depth` and its subtree; returns the exact union of its primitives'
    /// boxes and the subtree's depth.
    fn node(&mut self, i: usize, depth: usize) -> (Aabb, usize) {
        let context = self.context;
        assert!(!std::mem::replace(&mut self.reached[i], true), "{context}: node {i} reached twice");
        let node = self.bvh.nodes[i];
        let (union, subtree_depth) = if node.is_leaf() {
            self.leaves += 1;
            assert!(node.count <= self.max_leaf_size, "{context}: leaf {i} holds {} > max", node.count);
            let range = node.offset as usize..(node.offset + node.count) as usize;
            assert!(range.end <= self.prims.len(), "{context}: leaf {i} range {range:?} out of bounds");
            let mut union = Aabb::EMPTY;
            for j in range {
                assert!(!std::mem::replace(&mut self.covered[j], true), "{context}: {j} in two leaves");
                let prim = self.prims[self.bvh.prim_order[j] as usize];
                assert!(contains(&node.bounds(), &prim), "{context}: leaf {i} misses primitive {j}");
                union = box_union(union, prim);
            }
            (union, depth)
        } else {
            let children = node.offset as usize;
            assert!(children > i, "{context}: node {i} has children {children} before it");
            assert_eq!(children, self.next_pair, "{context}: node {i}'s children are not depth first");
            self.next_pair += 2;
            assert!(children + 1 < self.bvh.nodes.len(), "{context}: node {i} children out of bounds");
            let mut union = Aabb::EMPTY;
            let mut deepest = 0;
            for c in [children, children + 1] {
                let (child, d) = self.node(c, depth + 1);
                let child_box = self.bvh.nodes[c].bounds();
                assert!(contains(&node.bounds(), &child_box), "{context}: node {i} misses child {c}");
                union = box_union(union, child);
                deepest = deepest.max(d);
            }
            (union, deepest)
        };
        let expected = if union.is_empty() { Aabb::EMPTY } else { union };
        assert_eq!(node.bounds(), expected, "{context}: node {i} box is not the union of its primitives");
        (union, subtree_depth)
    }
}

/// Builds with both builders and checks both results.
fn check_builds(prims: &[Aabb], params: &BuildParams, context: &str) {
    check_invariants(&build_binned_sah(prims, params), prims, params, &format!("binned, {context}"));
    check_invariants(&build_sweep_sah(prims, params), prims, params, &format!("sweep, {context}"));
}

/// A box of half extent `size` around `centre`.
fn cube(centre: Vec3, size: f32) -> Aabb {
    Aabb::new(centre - size, centre + size)
}

/// Named box distributions that stress the builders in different ways.
fn distributions() -> Vec<(&'static str, Vec<Aabb>)> {
    let mut rng = Rng::new(7);
    let mut d: Vec<(&'static str, Vec<Aabb>)> = Vec::new();
    d.push(("one", vec![cube(Vec3::ONE, 0.5)]));
    d.push(("two", vec![cube(Vec3::ZERO, 0.1), cube(Vec3::X, 0.1)]));
    d.push(("three", vec![cube(Vec3::ZERO, 1.0), cube(Vec3::X, 0.1), cube(Vec3::Y, 0.1)]));
    d.push(("uniform", (0..2000).map(|_| cube(rng.vec3(), 0.01 * rng.f32())).collect()));
    d.push(("same centroid, growing sizes", (1..=100).map(|i| cube(Vec3::splat(3.0), i as f32)).collect()));
    d.push(("identical boxes", vec![cube(Vec3::new(1.0, -2.0, 3.0), 0.25); 77]));
    d.push(("points", (0..500).map(|_| cube(rng.vec3(), 0.0)).collect()));
    d.push(("coincident points", vec![cube(Vec3::splat(-1.0), 0.0); 40]));
    d.push(("flat cluster and huge boxes", {
        let mut boxes: Vec<Aabb> = (0..3000)
            .map(|_| {
                let p = Vec3::new(1000.0 + rng.f32(), 1000.0 + rng.f32(), 0.0);
                Aabb::new(p, p + Vec3::new(1e-3, 1e-3, 0.0))
            })
            .collect();
        boxes.extend((0..6).map(|i| Aabb::new(Vec3::splat(-1e4), Vec3::new(1e4, 1e4, i as f32))));
        boxes
    }));
    d.push((
        "lines along x",
        (0..300).map(|i| Aabb::new(Vec3::new(0.0, i as f32, 0.0), Vec3::new(50.0, i as f32, 0.0))).collect(),
    ));
    d.push((
        "empty boxes mixed in",
        (0..400).map(|i| if i % 3 == 0 { Aabb::EMPTY } else { cube(rng.vec3(), 0.02) }).collect(),
    ));
    d.push(("only empty boxes", vec![Aabb::EMPTY; 20]));
    d.push((
        "exponential spacing",
        (0..120).map(|i| cube(Vec3::splat(1.3f32.powi(i)), 1.3f32.powi(i) * 0.1)).collect(),
    ));
    d.push(("huge coordinates", (0..300).map(|_| cube(1e30 * (rng.vec3() - 0.5), 1e28)).collect()));
    d
}

#[test]
fn empty_input_gives_an_empty_bvh() {
    let params = BuildParams::default();
    for bvh in [build_binned_sah(&[], &params), build_sweep_sah(&[], &params)] {
        assert!(bvh.nodes.is_empty());
        assert_eq!((bvh.nodes.len(), bvh.prim_order.len()), (0, 0));
        assert_eq!((bvh.depth(), bvh.leaf_count(), bvh.bytes()), (0, 0, 0));
        assert_eq!(bvh.sah_cost(&params), 0.0);
    }
}

#[test]
fn invariants_hold_on_all_distributions() {
    let params = [
        BuildParams::default(),
        BuildParams { max_leaf_size: 1, ..Default::default() },
        BuildParams { max_leaf_size: BuildParams::MAX_LEAF_SIZE, bins: 2, ..Default::default() },
        BuildParams { bins: BuildParams::MAX_BINS, traversal_cost: 0.0, ..Default::default() },
        BuildParams { max_leaf_size: 4, intersection_cost: 20.0, ..Default::default() },
    ];
    for (name, prims) in distributions() {
        for (k, p) in params.iter().enumerate() {
            check_builds(&prims, p, &format!("{name}, params #{k}"));
        }
    }
}

#[test]
fn invariants_hold_on_large_inputs() {
    // Large enough for parallel binning and parallel subtrees.
    let triangles = random_triangles(60_000, 11);
    let mut prims = triangle_bounds(&triangles);
    check_invariants(
        &build_binned_sah(&prims, &BuildParams::default()),
        &prims,
        &BuildParams::default(),
        "random 60k",
    );
    // A dense cluster inside a sparse scene, like the conference room's tiny detailed object.
    let mut rng = Rng::new(3);
    prims.extend((0..40_000).map(|_| cube(Vec3::splat(0.5) + 1e-4 * rng.vec3(), 1e-6)));
    check_invariants(
        &build_binned_sah(&prims, &BuildParams::default()),
        &prims,
        &BuildParams::default(),
        "cluster",
    );
}

/// The wide tree's invariants (`Bvh8`'s documentation): every primitive in exactly one leaf
/// and inside a box of the hull, each slot's box holding its primitives and, for an inner
/// slot, its node's slots; used slots first and unused ones inverted; children after their
/// parents; and a walk's stack bound.
fn check_wide(bvh: &Bvh, prims: &[Aabb], context: &str) {
    let wide = Bvh8::collapse(bvh);
    assert_eq!(wide.nodes.is_empty(), bvh.nodes.is_empty(), "{context}");
    let mut seen = vec![0u32; prims.len()];
    // (node, depth) pairs still to check, and the deepest level reached.
    let mut todo = if wide.nodes.is_empty() { vec![] } else { vec![(0usize, 1usize)] };
    let mut depth = 0;
    while let Some((n, d)) = todo.pop() {
        depth = depth.max(d);
        let node = &wide.nodes[n];
        let used = node.used();
        assert!(used >= 1, "{context}: node {n} is empty");
        for i in 0..8 {
            let (child, count, b) = (node.child[i], node.count[i], node.bounds(i));
            if i >= used {
                assert_eq!((child, count), (Bvh8Node::UNUSED, 0), "{context}: node {n} slot {i}");
                assert!(b.min.cmpgt(b.max).all(), "{context}: unused slot {i} of node {n} must be inverted");
                continue;
            }
            if count > 0 {
                for leaf_slot in child..child + count {
                    let p = bvh.prim_order[leaf_slot as usize] as usize;
                    seen[p] += 1;
                    assert!(prims[p].is_empty() || contains(&b, &prims[p]), "{context}: leaf box misses {p}");
                }
            } else {
                assert!(child as usize > n, "{context}: child {child} of node {n} comes before it");
                let inner = &wide.nodes[child as usize];
                for j in 0..inner.used() {
                    let ib = inner.bounds(j);
                    assert!(
                        ib.is_empty() || contains(&b, &ib),
                        "{context}: slot {j} of node {child} leaves its box"
                    );
                }
                todo.push((child as usize, d + 1));
            }
        }
    }
    assert!(seen.iter().all(|&k| k == 1), "{context}: every primitive must be in exactly one leaf");
    assert!(wide.hull.len() <= 8, "{context}: a hull of {} boxes", wide.hull.len());
    for (p, b) in prims.iter().enumerate() {
        assert!(b.is_empty() || wide.hull.iter().any(|h| contains(h, b)), "{context}: the hull misses {p}");
    }
    assert!(depth <= bvh.depth().max(1), "{context}: wide depth {depth} beyond the binary {}", bvh.depth());
}

#[test]
fn wide_trees_keep_their_invariants_on_all_distributions() {
    for (name, prims) in distributions() {
        for p in [BuildParams::default(), BuildParams { max_leaf_size: 1, ..Default::default() }] {
            check_wide(&build_binned_sah(&prims, &p), &prims, name);
        }
    }
}

#[test]
fn depth_stays_within_the_traversal_stack() {
    // Boxes at powers of two: SAH splits peel off the largest box, so unbounded this would be
    // a chain 240 levels deep.
    let prims: Vec<Aabb> =
        (0..240).map(|i| cube(Vec3::splat(2f32.powi(i - 120)), 2f32.powi(i - 122))).collect();
    let params = BuildParams { max_leaf_size: 1, ..Default::default() };
    for bvh in [build_binned_sah(&prims, &params), build_sweep_sah(&prims, &params)] {
        check_invariants(&bvh, &prims, &params, "powers of two");
        assert!(bvh.depth() > TRAVERSAL_STACK_SIZE - 8, "the input reaches the depth limit");
    }
}

#[test]
fn build_is_identical_at_any_thread_count() {
    let mut prims = triangle_bounds(&random_triangles(120_000, 5));
    prims.extend(vec![cube(Vec3::splat(0.25), 0.01); 5000]);
    let params = BuildParams::default();
    let build = |threads| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| build_binned_sah(&prims, &params))
    };
    let one = build(1);
    assert_eq!(one, build(2), "1 vs 2 threads");
    assert_eq!(one, build(3), "1 vs 3 threads");
}

#[test]
fn sah_cost_of_a_single_leaf_is_its_intersection_cost() {
    let prims = [cube(Vec3::ZERO, 1.0), cube(Vec3::ZERO, 0.9), cube(Vec3::ZERO, 0.8)];
    let params = BuildParams { intersection_cost: 1.5, ..Default::default() };
    let bvh = build_binned_sah(&prims, &params);
    assert_eq!(bvh.nodes.len(), 1);
    assert_eq!(bvh.sah_cost(&params), 4.5);
}

/// Asserts that the binned build's SAH cost is at most 5 % above the full sweep's.
fn assert_sah_close_to_sweep(prims: &[Aabb], context: &str) {
    let params = BuildParams::default();
    let binned = build_binned_sah(prims, &params).sah_cost(&params);
    let sweep = build_sweep_sah(prims, &params).sah_cost(&params);
    println!("{context}: SAH binned {binned:.3}, sweep {sweep:.3}, ratio {:.4}", binned / sweep);
    assert!(binned <= 1.05 * sweep, "{context}: binned SAH {binned} > 1.05 × sweep {sweep}");
}

#[test]
fn binned_sah_is_within_5_percent_of_the_sweep_on_random_soups() {
    for (n, seed) in [(1_000, 1), (20_000, 2), (50_000, 3)] {
        assert_sah_close_to_sweep(&triangle_bounds(&random_triangles(n, seed)), &format!("random {n}"));
    }
    // Triangles of very different sizes.
    let mut rng = Rng::new(4);
    let triangles: Vec<Triangle> = (0..20_000)
        .map(|_| {
            let (centre, size) = (rng.vec3(), 0.3 * rng.f32().powi(4));
            [0; 3].map(|_| centre + size * (rng.vec3() - 0.5))
        })
        .collect();
    assert_sah_close_to_sweep(&triangle_bounds(&triangles), "random sizes");
    // A small, dense object far from the origin: bins a fraction of a unit wide at 10⁴.
    let far: Vec<Triangle> =
        random_triangles(20_000, 5).iter().map(|t| t.map(|v| Vec3::splat(1e4) + 1e-2 * v)).collect();
    assert_sah_close_to_sweep(&triangle_bounds(&far), "small and far");
}

#[test]
fn binned_sah_is_within_5_percent_of_the_sweep_on_real_scenes() {
    for (name, path) in SCENES {
        if let Some(triangles) = load_scene(path) {
            assert_sah_close_to_sweep(&triangle_bounds(&triangles), name);
        }
    }
}

/// The exact union of each node's primitives over the BVH's topology, computed from scratch.
fn fresh_bounds(bvh: &Bvh, leaf_order_bounds: &[Aabb]) -> Vec<Aabb> {
    fn visit(bvh: &Bvh, prims: &[Aabb], i: usize, out: &mut [Aabb]) -> Aabb {
        let node = bvh.nodes[i];
        let union = if node.is_leaf() {
            prims[node.offset as usize..(node.offset + node.count) as usize]
                .iter()
                .fold(Aabb::EMPTY, |a, &b| box_union(a, b))
        } else {
            let left = visit(bvh, prims, node.offset as usize, out);
            box_union(left, visit(bvh, prims, node.offset as usize + 1, out))
        };
        out[i] = union;
        union
    }
    let mut out = vec![Aabb::EMPTY; bvh.nodes.len()];
    visit(bvh, leaf_order_bounds, 0, &mut out);
    out
}

#[test]
fn refit_recomputes_exact_boxes_for_moved_primitives() {
    let mut triangles = random_triangles(5_000, 9);
    let params = BuildParams::default();
    let mut bvh = build_binned_sah(&triangle_bounds(&triangles), &params);
    let built = bvh.clone();

    // Refitting unmoved primitives reproduces the build.
    let order = built.prim_order.clone();
    let leaf_order = |triangles: &[Triangle]| -> Vec<Aabb> {
        order.iter().map(|&p| Aabb::from_points(triangles[p as usize])).collect()
    };
    let unmoved = leaf_order(&triangles);
    bvh.refit(|i| unmoved[i as usize]);
    assert_eq!(bvh, built);

    // Move every triangle, some far away.
    let mut rng = Rng::new(10);
    for (k, t) in triangles.iter_mut().enumerate() {
        let shift = if k % 17 == 0 { 10.0 * rng.vec3() } else { 0.01 * rng.vec3() };
        for v in t.iter_mut() {
            *v += shift + 0.001 * rng.vec3();
        }
    }
    let mut moved = leaf_order(&triangles);
    bvh.refit(|i| moved[i as usize]);
    assert_eq!(bvh.prim_order, built.prim_order);
    let check = |bvh: &Bvh, leaf_order_bounds: &[Aabb], context: &str| {
        let fresh = fresh_bounds(bvh, leaf_order_bounds);
        for (i, node) in bvh.nodes.iter().enumerate() {
            let topology = (built.nodes[i].offset, built.nodes[i].count);
            assert_eq!((node.offset, node.count), topology, "{context}: topology of node {i}");
            let expected = if fresh[i].is_empty() { Aabb::EMPTY } else { fresh[i] };
            assert_eq!(node.bounds(), expected, "{context}: box of node {i}");
        }
        let mut input_order = vec![Aabb::EMPTY; leaf_order_bounds.len()];
        for (j, &p) in bvh.prim_order.iter().enumerate() {
            input_order[p as usize] = leaf_order_bounds[j];
        }
        check_invariants(bvh, &input_order, &params, context);
    };
    check(&bvh, &moved, "moved");

    // Primitives that vanish (empty boxes), including whole leaves.
    for (j, b) in moved.iter_mut().enumerate() {
        if j % 7 == 0 || j < 40 {
            *b = Aabb::EMPTY;
        }
    }
    bvh.refit(|i| moved[i as usize]);
    check(&bvh, &moved, "vanished");
}

#[test]
#[should_panic(expected = "max_leaf_size")]
fn leaves_larger_than_15_are_rejected() {
    build_binned_sah(&[], &BuildParams { max_leaf_size: 16, ..Default::default() });
}

#[test]
#[should_panic(expected = "bins")]
fn too_many_bins_are_rejected() {
    build_binned_sah(&[], &BuildParams { bins: BuildParams::MAX_BINS + 1, ..Default::default() });
}
