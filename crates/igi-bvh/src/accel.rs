//! The two-level acceleration structure: one 8-wide BVH per mesh (bottom level, collapsed
//! from a binned-SAH binary tree) and one binary BVH over the placed instances (top level),
//! with the single-ray and 8-ray packet queries on top.
//!
//! Bottom-level BVHs are built once per mesh; the top level is rebuilt whenever instances move
//! ([`Accel::set_transforms`]), which costs microseconds for the few instances a scene has.
//! Triangles are stored in BVH leaf order, so a leaf's triangles are contiguous and a hit's
//! `prim` indexes the mesh directly; [`Accel::build`] returns the permutation so the caller can
//! reorder its own per-triangle data (materials) to match.
//!
//! Alpha cut-outs ([`Accel::set_cutouts`]): triangles flagged as possibly cut hand their hits
//! to a [`CutoutTest`], and a hit it calls cut is no hit, so a closest-hit query goes on to
//! what lies behind and an any-hit query passes. The flags are one bit per triangle, kept only
//! for meshes that have a flagged triangle; every other mesh is walked by a kernel without the
//! test (chosen once per instance visit), so opaque geometry pays nothing.

use crate::aabb::Aabb;
use crate::build::{BuildParams, build_binned_sah, build_binned_sah_tree_by};
use crate::bvh::{Bvh, sah_cost};
use crate::bvh8::{Boxes8, Bvh8, PacketBoxes, walk8, walk8_packet};
use crate::node::Node;
use crate::ray::{Hit, HitPacket8, INVALID_ID, Ray, RayPacket8};
use crate::traverse::{BoxRay1, BoxRay8, BoxTest, Query, walk};
use crate::triangle::{Shear, Shear8, ShearUniform, TriangleHit, intersect};
use glam::{Affine3A, Vec3};
use igi_simd::{F32x8, I32x8, LaneMask, Lanes, M32x8, Vec3x8};
use std::sync::Arc;

mod shadow_cache;
pub use shadow_cache::ShadowCache;

/// Decides whether a hit on a triangle that may be cut out is really there (alpha cut-outs:
/// glTF `alphaMode: MASK`, MTL `map_d`; the renderer reads the texels).
pub trait CutoutTest: Send + Sync + std::fmt::Debug {
    /// True if the surface is absent at barycentric weights (`u`, `v`) of the second and third
    /// corner of stored triangle `prim` of mesh `mesh`. Must be a function of its arguments
    /// alone: every query and every packet lane asks it the same question.
    fn is_cut(&self, mesh: u32, prim: u32, u: f32, v: f32) -> bool;
}

/// The cut-outs of a structure: which triangles may be cut, and what decides.
#[derive(Clone, Debug)]
struct Cutouts {
    /// Per mesh, one bit per stored triangle that may be cut; empty for a mesh with none.
    may_cut: Vec<Vec<u64>>,
    test: Arc<dyn CutoutTest>,
}

/// Triangle geometry as the acceleration structure stores it.
#[derive(Clone, Debug, Default)]
pub struct TriangleMesh {
    /// Vertex positions in object space.
    pub positions: Vec<Vec3>,
    /// Triangles as vertex indices (all in range).
    pub indices: Vec<[u32; 3]>,
}

impl TriangleMesh {
    /// The three corners of triangle `prim`.
    #[inline(always)]
    pub fn triangle(&self, prim: u32) -> [Vec3; 3] {
        let [a, b, c] = self.indices[prim as usize];
        [self.positions[a as usize], self.positions[b as usize], self.positions[c as usize]]
    }

    /// Bytes of vertex and index data.
    pub fn bytes(&self) -> usize {
        self.positions.len() * std::mem::size_of::<Vec3>()
            + self.indices.len() * std::mem::size_of::<[u32; 3]>()
    }
}

/// A placement of a mesh, as stored by the structure.
#[derive(Clone, Copy, Debug)]
struct Placement {
    mesh: u32,
    object_to_world: Affine3A,
    world_to_object: Affine3A,
    /// Rays need no transform (the common single-instance scene).
    identity: bool,
}

impl Placement {
    fn new(mesh: u32, object_to_world: Affine3A) -> Self {
        Self {
            mesh,
            object_to_world,
            world_to_object: object_to_world.inverse(),
            identity: object_to_world == Affine3A::IDENTITY,
        }
    }
}

/// Two-level BVH over instanced triangle meshes.
#[derive(Clone, Debug)]
pub struct Accel {
    meshes: Vec<TriangleMesh>,
    /// Per mesh, its 8-wide BVH (ARCHITECTURE.md, "The wide BVH").
    blas: Vec<Bvh8>,
    placements: Vec<Placement>,
    tlas: Bvh,
    params: BuildParams,
    /// SAH cost of the binary trees the meshes' wide trees were collapsed from, weighted by
    /// triangle count (a build quality figure for benchmarks).
    sah_cost: f32,
    cutouts: Option<Cutouts>,
}

/// A triangle's bounding box.
fn triangle_bounds(mesh: &TriangleMesh, prim: u32) -> Aabb {
    Aabb::from_points(mesh.triangle(prim))
}

/// World bounds of an instance of the mesh whose BVH is `bvh`, under `m`: the union of the
/// placed boxes of its hull ([`Bvh8::hull`]). Up to eight placed boxes hug a rotated mesh far
/// closer than its placed root box (16 boxes of the binary tree gave 27 % less surface on the
/// armadillos of issue 17) at a cost per instance that does not grow with the mesh, so moving
/// instances stay cheap.
fn instance_bounds(bvh: &Bvh8, m: &Affine3A) -> Aabb {
    bvh.hull.iter().map(|&b| placed_bounds(b, m)).fold(Aabb::EMPTY, |bounds, placed| {
        if placed.is_empty() { bounds } else { bounds.grow(placed.min).grow(placed.max) }
    })
}

/// World bounds of a box under an affine transform (its transformed corners).
fn placed_bounds(local: Aabb, m: &Affine3A) -> Aabb {
    if local.is_empty() {
        return local;
    }
    Aabb::from_points(local.corners().map(|c| m.transform_point3(c)))
}

impl Accel {
    /// Builds the bottom-level BVHs of `meshes` and the top level over `instances`
    /// (mesh index, object-to-world transform). Each mesh's triangles are reordered into leaf
    /// order; the returned vectors give, per mesh, the input index of each stored triangle.
    pub fn build(mut meshes: Vec<TriangleMesh>, instances: &[(u32, Affine3A)]) -> (Self, Vec<Vec<u32>>) {
        let params = BuildParams::default();
        let mut orders = Vec::with_capacity(meshes.len());
        let mut blas = Vec::with_capacity(meshes.len());
        let mut sah_sum = 0.0;
        for mesh in &mut meshes {
            // The binary tree is collapsed as the builder left it, never compacted.
            let Some((binary, prim_order)) =
                build_binned_sah_tree_by(mesh.indices.len(), |p| triangle_bounds(mesh, p as u32), &params)
            else {
                orders.push(Vec::new());
                blas.push(Bvh8::default());
                continue;
            };
            // The triangles themselves move into leaf order, so the bottom level needs no
            // permutation of its own; the caller gets it to reorder its per-triangle data.
            mesh.indices = prim_order.iter().map(|&p| mesh.indices[p as usize]).collect();
            orders.push(prim_order);
            sah_sum += sah_cost(&binary, &params) * mesh.indices.len() as f32;
            blas.push(Bvh8::collapse_tree(&binary));
        }
        let triangles: usize = meshes.iter().map(|m| m.indices.len()).sum();
        let placements = instances.iter().map(|&(mesh, m)| Placement::new(mesh, m)).collect();
        let mut accel = Self {
            meshes,
            blas,
            placements,
            tlas: Bvh { nodes: Vec::new(), prim_order: Vec::new() },
            params,
            sah_cost: if triangles == 0 { 0.0 } else { sah_sum / triangles as f32 },
            cutouts: None,
        };
        accel.build_tlas();
        (accel, orders)
    }

    /// Subjects the triangles flagged in `may_cut` (per mesh, per stored triangle; a missing or
    /// short list flags none) to `test`: a hit it calls cut is no hit for any query. Meshes
    /// without a flagged triangle keep the walk without the test.
    pub fn set_cutouts(&mut self, may_cut: &[Vec<bool>], test: Arc<dyn CutoutTest>) {
        let bits: Vec<Vec<u64>> = (0..self.meshes.len())
            .map(|mesh| {
                let flags = may_cut.get(mesh).map_or(&[][..], Vec::as_slice);
                if !flags.contains(&true) {
                    return Vec::new();
                }
                let mut bits = vec![0u64; flags.len().div_ceil(64)];
                for (prim, _) in flags.iter().enumerate().filter(|(_, f)| **f) {
                    bits[prim / 64] |= 1 << (prim % 64);
                }
                bits
            })
            .collect();
        self.cutouts = bits.iter().any(|b| !b.is_empty()).then_some(Cutouts { may_cut: bits, test });
    }

    /// Moves the instances (same count and meshes as at build time) and rebuilds the top level.
    pub fn set_transforms(&mut self, object_to_world: &[Affine3A]) {
        assert_eq!(object_to_world.len(), self.placements.len(), "one transform per instance");
        for (p, m) in self.placements.iter_mut().zip(object_to_world) {
            *p = Placement::new(p.mesh, *m);
        }
        self.build_tlas();
    }

    /// The top level over the instances' world bounds, one instance per leaf: entering an
    /// instance costs a ray transform and a walk of its own BVH, far more than one more
    /// top-level node, so leaves of several instances made rays enter instances they miss
    /// (1.8 instances per ray against 1.4 in the armadillo field of issue 17).
    fn build_tlas(&mut self) {
        let bounds: Vec<Aabb> = self
            .placements
            .iter()
            .map(|p| instance_bounds(&self.blas[p.mesh as usize], &p.object_to_world))
            .collect();
        self.tlas = build_binned_sah(&bounds, &BuildParams { max_leaf_size: 1, ..self.params });
    }

    /// The stored (leaf-ordered) meshes.
    pub fn meshes(&self) -> &[TriangleMesh] {
        &self.meshes
    }

    /// Number of instances.
    pub fn instance_count(&self) -> usize {
        self.placements.len()
    }

    /// Mesh index of instance `i`.
    pub fn instance_mesh(&self, i: u32) -> u32 {
        self.placements[i as usize].mesh
    }

    /// Object-to-world transform of instance `i`.
    pub fn instance_transform(&self, i: u32) -> Affine3A {
        self.placements[i as usize].object_to_world
    }

    /// Object-space bounds of mesh `mesh` (the union of its hull's boxes).
    pub fn mesh_bounds(&self, mesh: u32) -> Aabb {
        instance_bounds(&self.blas[mesh as usize], &Affine3A::IDENTITY)
    }

    /// World bounds of the scene.
    pub fn bounds(&self) -> Aabb {
        self.tlas.nodes.first().map_or(Aabb::EMPTY, Node::bounds)
    }

    /// Bytes of triangle data plus all BVH nodes and the top level.
    pub fn bytes(&self) -> usize {
        self.triangle_bytes() + self.bvh_bytes()
    }

    /// Bytes of the meshes' vertices and index triples.
    pub fn triangle_bytes(&self) -> usize {
        self.meshes.iter().map(TriangleMesh::bytes).sum()
    }

    /// Bytes of the BVHs: every mesh's nodes and triangle order, the top level and the
    /// instance placements.
    pub fn bvh_bytes(&self) -> usize {
        self.blas.iter().map(Bvh8::bytes).sum::<usize>()
            + self.tlas.bytes()
            + self.placements.len() * std::mem::size_of::<Placement>()
    }

    /// SAH cost of the binary BVHs the meshes' wide BVHs were collapsed from, weighted by
    /// triangle count (a quality figure for benchmarks, comparable with other binary builders).
    pub fn sah_cost(&self) -> f32 {
        self.sah_cost
    }

    /// Unit geometric normal of a hit in world space, following the triangle's winding
    /// (p1 - p0) × (p2 - p0).
    pub fn geometric_normal(&self, instance: u32, prim: u32) -> Vec3 {
        let p = &self.placements[instance as usize];
        let [a, b, c] = self.meshes[p.mesh as usize].triangle(prim);
        let n = (b - a).cross(c - a);
        // Normals transform with the inverse transpose of the object-to-world matrix.
        p.world_to_object.matrix3.transpose().mul_vec3a(n.into()).normalize().into()
    }

    /// World-space position of `hit`, interpolated from its triangle's corners (exact to the
    /// rounding of the interpolation, which origin + t·direction is not).
    pub fn hit_position(&self, hit: &Hit) -> Vec3 {
        let p = &self.placements[hit.instance as usize];
        let [a, b, c] = self.meshes[p.mesh as usize].triangle(hit.prim);
        let local = a + hit.u * (b - a) + hit.v * (c - a);
        if p.identity { local } else { p.object_to_world.transform_point3(local) }
    }

    /// The closest hit of `ray` within `[tnear, tfar]` (ties in distance go to the lowest
    /// instance, then triangle, index, so the answer does not depend on traversal order).
    pub fn intersect(&self, ray: &Ray) -> Hit {
        let mut hit = Hit::miss(ray.tfar);
        self.trace1(ray, &mut hit);
        hit
    }

    /// True if anything lies on `ray` within `[tnear, tfar]` (shadow rays).
    pub fn occluded(&self, ray: &Ray) -> bool {
        let mut q = Any { tfar: ray.tfar, active: true };
        self.trace1(ray, &mut q);
        !q.active
    }

    /// The closest hits of the active lanes of `rays` (same rules as [`Accel::intersect`], lane
    /// for lane; inactive lanes report a miss).
    pub fn intersect8(&self, rays: &RayPacket8, active: M32x8) -> HitPacket8 {
        let miss = I32x8::splat(INVALID_ID as i32);
        let hit = HitPacket8 { t: rays.tfar, u: F32x8::ZERO, v: F32x8::ZERO, instance: miss, prim: miss };
        let mut q = Closest8 { hit, active };
        self.trace8(rays, active, &mut q);
        q.hit
    }

    /// Lanes of `rays` (among `active`) that are blocked within `[tnear, tfar]`.
    pub fn occluded8(&self, rays: &RayPacket8, active: M32x8) -> M32x8 {
        let mut q = Any { tfar: rays.tfar, active };
        self.trace8(rays, active, &mut q);
        active.and_not(q.active)
    }

    /// One ray through both levels: the top level finds instances, each instance's BVH is
    /// walked in its object space, and the query handles the triangles of its leaves.
    fn trace1<Q: TriangleQuery<f32>>(&self, ray: &Ray, q: &mut Q) {
        let world = Local1::new(ray.origin, ray.dir, ray.tnear);
        self.walk_instances(&world.boxes, q, |q, inst, p| {
            let local = if p.identity { world } else { world.transformed(ray, &p.world_to_object) };
            self.walk_mesh(p.mesh, inst, &local.start, &local.shear, &Boxes8::of(&local.boxes), q);
        });
    }

    /// Eight rays through both levels, as [`Accel::trace1`]; each instance's walk is
    /// monomorphised for the packet's kind of shear and box test.
    fn trace8<Q: TriangleQuery<F32x8>>(&self, rays: &RayPacket8, active: M32x8, q: &mut Q) {
        self.trace8_from(&Local8::new(rays.origin, rays.dir, rays.tnear, active), rays, q);
    }

    /// [`Accel::trace8`] of `rays` prepared in world space as `world`.
    fn trace8_from<Q: TriangleQuery<F32x8>>(&self, world: &Local8, rays: &RayPacket8, q: &mut Q) {
        let instance = |q: &mut Q, inst: u32, p: &Placement| {
            // By reference: the prepared packet is about a kilobyte, and a copy was a `memcpy`
            // call per packet and instance.
            let transformed;
            let local = if p.identity {
                world
            } else {
                transformed = world.transformed(rays, &p.world_to_object, q.active());
                &transformed
            };
            let start = &local.start;
            match (&local.shear, &local.boxes) {
                (Shear8::Uniform(s), BoxRay8::Octant(b)) => self.walk_mesh(p.mesh, inst, start, s, b, q),
                (Shear8::Uniform(s), BoxRay8::Mixed(b)) => self.walk_mesh(p.mesh, inst, start, s, b, q),
                (Shear8::Mixed(s), BoxRay8::Octant(b)) => self.walk_mesh(p.mesh, inst, start, s, b, q),
                (Shear8::Mixed(s), BoxRay8::Mixed(b)) => self.walk_mesh(p.mesh, inst, start, s, b, q),
            }
        };
        match &world.boxes {
            BoxRay8::Octant(b) => self.walk_instances(b, q, instance),
            BoxRay8::Mixed(b) => self.walk_instances(b, q, instance),
        }
    }

    /// Walks the top level and hands each instance of every leaf reached to `instance`, with
    /// its placement, until no ray is left active.
    #[inline(always)]
    fn walk_instances<L: Lanes, Q: Query<L>, B: BoxTest<L>>(
        &self,
        boxes: &B,
        q: &mut Q,
        mut instance: impl FnMut(&mut Q, u32, &Placement),
    ) {
        walk(&self.tlas.nodes, boxes, q, |q, leaf| {
            for &inst in &self.tlas.prim_order[leaf.offset as usize..(leaf.offset + leaf.count) as usize] {
                instance(q, inst, &self.placements[inst as usize]);
                if !q.active().any() {
                    return;
                }
            }
        });
    }

    /// Walks the bottom-level BVH of `mesh`, placed as instance `inst`, with rays in its object
    /// space, and tests the triangles of every leaf reached until the query has its answer;
    /// with the cut-out test only if the mesh has a triangle that may be cut.
    #[inline(always)]
    fn walk_mesh<L: Lanes, Q: TriangleQuery<L>, S: Shear<L>, B: MeshWalk<L>>(
        &self,
        mesh: u32,
        inst: u32,
        start: &RayStart<L>,
        shear: &S,
        boxes: &B,
        q: &mut Q,
    ) where
        for<'a> MayCut<'a>: Cut<L>,
    {
        match self.may_cut(mesh) {
            None => self.walk_triangles(mesh, inst, start, shear, boxes, q, Opaque),
            Some(cut) => self.walk_triangles(mesh, inst, start, shear, boxes, q, cut),
        }
    }

    /// The cut-out test of `mesh`, if it has a triangle that may be cut.
    #[inline(always)]
    fn may_cut(&self, mesh: u32) -> Option<MayCut<'_>> {
        self.cutouts.as_ref().and_then(|c| {
            let bits = &c.may_cut[mesh as usize];
            (!bits.is_empty()).then_some(MayCut { bits, test: c.test.as_ref(), mesh })
        })
    }

    /// [`Accel::walk_mesh`] with the hits of each triangle test passed through `cut`.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn walk_triangles<L: Lanes, Q: TriangleQuery<L>, S: Shear<L>, B: MeshWalk<L>, C: Cut<L>>(
        &self,
        mesh: u32,
        inst: u32,
        start: &RayStart<L>,
        shear: &S,
        boxes: &B,
        q: &mut Q,
        cut: C,
    ) {
        let triangles = &self.meshes[mesh as usize];
        boxes.walk_leaves(&self.blas[mesh as usize], q, |q, first, count| {
            for prim in first..first + count {
                let [a, b, c] = triangles.triangle(prim);
                let hit = cut.keep(prim, intersect(start.org, shear, a, b, c, start.tnear, q.tfar()));
                if !q.take(hit, inst, prim) {
                    return;
                }
            }
        });
    }
}

/// How a ray or a packet, prepared for box tests, walks a mesh's wide BVH: calls
/// `leaf(q, first, count)` for the leaves it reaches until the query has its answer.
trait MeshWalk<L: Lanes> {
    fn walk_leaves<Q: Query<L>>(&self, bvh: &Bvh8, q: &mut Q, leaf: impl FnMut(&mut Q, u32, u32));
}

impl MeshWalk<f32> for Boxes8 {
    #[inline(always)]
    fn walk_leaves<Q: Query<f32>>(&self, bvh: &Bvh8, q: &mut Q, leaf: impl FnMut(&mut Q, u32, u32)) {
        walk8(&bvh.nodes, self, q, leaf);
    }
}

impl<B: PacketBoxes> MeshWalk<F32x8> for B {
    #[inline(always)]
    fn walk_leaves<Q: Query<F32x8>>(&self, bvh: &Bvh8, q: &mut Q, leaf: impl FnMut(&mut Q, u32, u32)) {
        walk8_packet(&bvh.nodes, self, q, leaf);
    }
}

/// What becomes of a triangle test's hits in a mesh's walk: kept as they are ([`Opaque`]), or
/// tested against the cut-outs ([`MayCut`]).
trait Cut<L: Lanes>: Copy {
    /// The hits of triangle `prim` that are there.
    fn keep(&self, prim: u32, h: TriangleHit<L>) -> TriangleHit<L>;
}

/// A mesh without cut-outs: every hit counts, at no cost.
#[derive(Clone, Copy)]
struct Opaque;

impl<L: Lanes> Cut<L> for Opaque {
    #[inline(always)]
    fn keep(&self, _prim: u32, h: TriangleHit<L>) -> TriangleHit<L> {
        h
    }
}

/// A mesh with cut-outs: the hits on a flagged triangle go through its test.
#[derive(Clone, Copy)]
struct MayCut<'a> {
    bits: &'a [u64],
    test: &'a dyn CutoutTest,
    mesh: u32,
}

impl MayCut<'_> {
    #[inline(always)]
    fn flagged(&self, prim: u32) -> bool {
        (self.bits[prim as usize / 64] >> (prim % 64)) & 1 != 0
    }
}

impl Cut<f32> for MayCut<'_> {
    #[inline(always)]
    fn keep(&self, prim: u32, mut h: TriangleHit<f32>) -> TriangleHit<f32> {
        if h.mask && self.flagged(prim) && self.test.is_cut(self.mesh, prim, h.u, h.v) {
            h.mask = false;
        }
        h
    }
}

impl Cut<F32x8> for MayCut<'_> {
    #[inline(always)]
    fn keep(&self, prim: u32, mut h: TriangleHit<F32x8>) -> TriangleHit<F32x8> {
        let hits = h.mask.bitmask();
        if hits != 0 && self.flagged(prim) {
            // Lane by lane, the question a single ray asks: packets stay equal to single rays.
            let (u, v) = (h.u.to_array(), h.v.to_array());
            let cut = (0..8)
                .filter(|&i| hits & (1 << i) != 0 && self.test.is_cut(self.mesh, prim, u[i], v[i]))
                .fold(0, |bits, i| bits | (1 << i));
            h.mask = h.mask.and_not(M32x8::from_bitmask(cut));
        }
        h
    }
}

/// The tie rule that makes closest hits independent of traversal order.
#[inline(always)]
fn closer(t: f32, inst: u32, prim: u32, best: &Hit) -> bool {
    t < best.t || (t == best.t && (inst, prim) < (best.instance, best.prim))
}

/// Where rays start in one instance's object space, as the triangle test takes them: the
/// origins and the smallest accepted distance.
#[derive(Clone, Copy)]
struct RayStart<L> {
    org: [L; 3],
    tnear: L,
}

/// A single ray in one instance's object space, ready for box and triangle tests.
#[derive(Clone, Copy)]
struct Local1 {
    start: RayStart<f32>,
    shear: ShearUniform<f32>,
    /// For the top level's binary tree, and in every lane for the meshes' wide trees
    /// ([`Boxes8::of`]).
    boxes: BoxRay1,
}

impl Local1 {
    fn new(org: Vec3, dir: Vec3, tnear: f32) -> Self {
        Self {
            start: RayStart { org: org.to_array(), tnear },
            shear: ShearUniform::new(dir),
            boxes: BoxRay1::new(org, dir, tnear),
        }
    }

    /// The ray in the space of `world_to_object`. Directions are not renormalised, so
    /// distances `t` mean the same in both spaces.
    fn transformed(&self, ray: &Ray, world_to_object: &Affine3A) -> Self {
        Self::new(
            world_to_object.transform_point3(ray.origin),
            world_to_object.transform_vector3(ray.dir),
            ray.tnear,
        )
    }
}

/// Eight rays in one instance's object space.
#[derive(Clone, Copy)]
struct Local8 {
    start: RayStart<F32x8>,
    shear: Shear8,
    boxes: BoxRay8,
}

impl Local8 {
    fn new(org: Vec3x8, dir: Vec3x8, tnear: F32x8, active: M32x8) -> Self {
        Self {
            start: RayStart { org: org.into(), tnear },
            shear: Shear8::new(&dir, active),
            boxes: BoxRay8::new(&org, &dir, tnear, active),
        }
    }

    fn transformed(&self, rays: &RayPacket8, m: &Affine3A, active: M32x8) -> Self {
        let c = |v: glam::Vec3A| [F32x8::splat(v.x), F32x8::splat(v.y), F32x8::splat(v.z)];
        let (cx, cy, cz, t) =
            (c(m.matrix3.x_axis), c(m.matrix3.y_axis), c(m.matrix3.z_axis), c(m.translation));
        let apply = |v: &Vec3x8, w: [F32x8; 3]| {
            Vec3x8::new(
                v.x * cx[0] + v.y * cy[0] + v.z * cz[0] + w[0],
                v.x * cx[1] + v.y * cy[1] + v.z * cz[1] + w[1],
                v.x * cx[2] + v.y * cy[2] + v.z * cz[2] + w[2],
            )
        };
        let org = apply(&rays.origin, t);
        let dir = apply(&rays.dir, [F32x8::ZERO; 3]);
        Self::new(org, dir, rays.tnear, active)
    }
}

/// A query's use of triangle tests, for one ray (`L = f32`) or a packet (`L = F32x8`).
trait TriangleQuery<L: Lanes>: Query<L> {
    /// Takes the test of the rays against triangle `prim` of instance `inst`; false once the
    /// query has its answer.
    fn take(&mut self, h: TriangleHit<L>, inst: u32, prim: u32) -> bool;
}

/// The any-hit query (shadow rays): the rays not yet blocked.
struct Any<L: Lanes> {
    tfar: L,
    active: L::Mask,
}

impl<L: Lanes> Query<L> for Any<L> {
    const SHRINKS: bool = false;
    #[inline(always)]
    fn tfar(&self) -> L {
        self.tfar
    }
    #[inline(always)]
    fn active(&self) -> L::Mask {
        self.active
    }
}

// The two widths take hits differently: one ray is answered by its first hit, so it branches on
// it; whether any lane of a packet hits a triangle is hard to predict, and that branch cost about
// 7 % of the shadow-packet throughput on the Cornell box, so a packet clears its hit lanes
// without one.

impl TriangleQuery<f32> for Any<f32> {
    #[inline(always)]
    fn take(&mut self, h: TriangleHit<f32>, _inst: u32, _prim: u32) -> bool {
        if h.mask {
            self.active = false;
        }
        self.active
    }
}

impl TriangleQuery<F32x8> for Any<F32x8> {
    #[inline(always)]
    fn take(&mut self, h: TriangleHit<F32x8>, _inst: u32, _prim: u32) -> bool {
        self.active = self.active.and_not(h.mask);
        self.active.any()
    }
}

/// The closest-hit query of one ray is its best hit so far.
impl Query<f32> for Hit {
    const SHRINKS: bool = true;
    #[inline(always)]
    fn tfar(&self) -> f32 {
        self.t
    }
}

impl TriangleQuery<f32> for Hit {
    #[inline(always)]
    fn take(&mut self, h: TriangleHit<f32>, inst: u32, prim: u32) -> bool {
        if h.mask && closer(h.t, inst, prim, self) {
            *self = Hit { t: h.t, u: h.u, v: h.v, instance: inst, prim };
        }
        true
    }
}

/// The closest-hit query of a packet: the best hits so far of the `active` lanes.
struct Closest8 {
    hit: HitPacket8,
    active: M32x8,
}

impl Query<F32x8> for Closest8 {
    const SHRINKS: bool = true;
    #[inline(always)]
    fn tfar(&self) -> F32x8 {
        self.hit.t
    }
    #[inline(always)]
    fn active(&self) -> M32x8 {
        self.active
    }
}

impl TriangleQuery<F32x8> for Closest8 {
    #[inline(always)]
    fn take(&mut self, h: TriangleHit<F32x8>, inst: u32, prim: u32) -> bool {
        let best = &mut self.hit;
        let (inst, prim) = (I32x8::splat(inst as i32), I32x8::splat(prim as i32));
        // The tie rule of `closer`, lane by lane: ids compare as unsigned, and INVALID_ID
        // (-1 as i32) is the largest.
        let tie = h.t.eq(best.t)
            & (lt_u32(inst, best.instance) | (inst.eq(best.instance) & lt_u32(prim, best.prim)));
        let take = h.mask & self.active & (h.t.lt(best.t) | tie);
        if take.any() {
            best.t = F32x8::select(take, h.t, best.t);
            best.u = F32x8::select(take, h.u, best.u);
            best.v = F32x8::select(take, h.v, best.v);
            best.instance = I32x8::select(take, inst, best.instance);
            best.prim = I32x8::select(take, prim, best.prim);
        }
        true
    }
}

/// Unsigned `a < b` per lane.
#[inline(always)]
fn lt_u32(a: I32x8, b: I32x8) -> M32x8 {
    let flip = I32x8::splat(i32::MIN);
    (a ^ flip).lt(b ^ flip)
}
