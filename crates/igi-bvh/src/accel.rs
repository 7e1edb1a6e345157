//! The two-level acceleration structure: one BVH per mesh (bottom level) and one BVH over the
//! placed instances (top level), with the single-ray and 8-ray packet queries on top.
//!
//! Bottom-level BVHs are built once per mesh; the top level is rebuilt whenever instances move
//! ([`Accel::set_transforms`]), which costs microseconds for the few instances a scene has.
//! Triangles are stored in BVH leaf order, so a leaf's triangles are contiguous and a hit's
//! `prim` indexes the mesh directly; [`Accel::build`] returns the permutation so the caller can
//! reorder its own per-triangle data (materials) to match.

use crate::aabb::Aabb;
use crate::build::{BuildParams, build_binned_sah};
use crate::bvh::Bvh;
use crate::node::Node;
use crate::ray::{Hit, HitPacket8, INVALID_ID, Ray, RayPacket8};
use crate::traverse::{BoxRay1, BoxRay8, Boxes8, Query1, Query8, walk1, walk8};
use crate::triangle::{Shear, Shear8, ShearScalar, intersect};
use glam::{Affine3A, Vec3};
use igi_simd::{F32x8, I32x8, M32x8, Vec3x8};

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
    blas: Vec<Bvh>,
    placements: Vec<Placement>,
    tlas: Bvh,
    params: BuildParams,
}

/// A triangle's bounding box.
fn triangle_bounds(mesh: &TriangleMesh, prim: u32) -> Aabb {
    Aabb::from_points(mesh.triangle(prim))
}

/// World bounds of a mesh under an affine transform (the transformed corners of its box).
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
        for mesh in &mut meshes {
            let bounds: Vec<Aabb> =
                (0..mesh.indices.len() as u32).map(|p| triangle_bounds(mesh, p)).collect();
            let Bvh { nodes, prim_order } = build_binned_sah(&bounds, &params);
            // The triangles themselves move into leaf order, so the bottom level needs no
            // permutation of its own; the caller gets it to reorder its per-triangle data.
            mesh.indices = prim_order.iter().map(|&p| mesh.indices[p as usize]).collect();
            orders.push(prim_order);
            blas.push(Bvh { nodes, prim_order: Vec::new() });
        }
        let placements = instances.iter().map(|&(mesh, m)| Placement::new(mesh, m)).collect();
        let mut accel = Self {
            meshes,
            blas,
            placements,
            tlas: Bvh { nodes: Vec::new(), prim_order: Vec::new() },
            params,
        };
        accel.build_tlas();
        (accel, orders)
    }

    /// Moves the instances (same count and meshes as at build time) and rebuilds the top level.
    pub fn set_transforms(&mut self, object_to_world: &[Affine3A]) {
        assert_eq!(object_to_world.len(), self.placements.len(), "one transform per instance");
        for (p, m) in self.placements.iter_mut().zip(object_to_world) {
            *p = Placement::new(p.mesh, *m);
        }
        self.build_tlas();
    }

    fn build_tlas(&mut self) {
        let bounds: Vec<Aabb> = self
            .placements
            .iter()
            .map(|p| {
                let root = self.blas[p.mesh as usize].nodes.first().map_or(Aabb::EMPTY, Node::bounds);
                placed_bounds(root, &p.object_to_world)
            })
            .collect();
        self.tlas = build_binned_sah(&bounds, &self.params);
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

    /// World bounds of the scene.
    pub fn bounds(&self) -> Aabb {
        self.tlas.nodes.first().map_or(Aabb::EMPTY, Node::bounds)
    }

    /// The bottom-level BVH of mesh `i`.
    pub fn mesh_bvh(&self, i: usize) -> &Bvh {
        &self.blas[i]
    }

    /// Bytes of triangle data plus all BVH nodes and the top level.
    pub fn bytes(&self) -> usize {
        self.meshes.iter().map(TriangleMesh::bytes).sum::<usize>()
            + self.blas.iter().map(Bvh::bytes).sum::<usize>()
            + self.tlas.bytes()
            + self.placements.len() * std::mem::size_of::<Placement>()
    }

    /// SAH cost of the bottom-level BVHs, weighted by triangle count (a quality figure for
    /// benchmarks).
    pub fn sah_cost(&self) -> f32 {
        let n: usize = self.meshes.iter().map(|m| m.indices.len()).sum();
        if n == 0 {
            return 0.0;
        }
        self.blas
            .iter()
            .zip(&self.meshes)
            .map(|(b, m)| b.sah_cost(&self.params) * m.indices.len() as f32)
            .sum::<f32>()
            / n as f32
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

    /// The closest hit of `ray` within `[tnear, tfar]` (ties in distance go to the lowest
    /// instance, then triangle, index, so the answer does not depend on traversal order).
    pub fn intersect(&self, ray: &Ray) -> Hit {
        let mut q = Closest1 { hit: Hit::miss(ray.tfar) };
        self.trace1(ray, &mut q);
        q.hit
    }

    /// True if anything lies on `ray` within `[tnear, tfar]` (shadow rays).
    pub fn occluded(&self, ray: &Ray) -> bool {
        let mut q = Any1 { tfar: ray.tfar, hit: false };
        self.trace1(ray, &mut q);
        q.hit
    }

    /// The closest hits of the active lanes of `rays` (same rules as [`Accel::intersect`], lane
    /// for lane; inactive lanes report a miss).
    pub fn intersect8(&self, rays: &RayPacket8, active: M32x8) -> HitPacket8 {
        let mut q = Closest8 {
            t: rays.tfar,
            u: F32x8::ZERO,
            v: F32x8::ZERO,
            instance: I32x8::splat(INVALID_ID as i32),
            prim: I32x8::splat(INVALID_ID as i32),
            active,
        };
        self.trace8(rays, active, &mut q);
        HitPacket8 { t: q.t, u: q.u, v: q.v, instance: q.instance, prim: q.prim }
    }

    /// Lanes of `rays` (among `active`) that are blocked within `[tnear, tfar]`.
    pub fn occluded8(&self, rays: &RayPacket8, active: M32x8) -> M32x8 {
        let mut q = Any8 { tfar: rays.tfar, active };
        self.trace8(rays, active, &mut q);
        active.and_not(q.active)
    }

    /// One ray through both levels: the top level finds instances, each instance's BVH is
    /// walked in its object space, and the query handles the triangles of its leaves.
    fn trace1<Q: Leaf1>(&self, ray: &Ray, q: &mut Q) {
        let world = Local1::new(ray.origin, ray.dir, ray.tnear);
        walk1(&self.tlas.nodes, &world.boxes, q, |q, leaf| {
            for &inst in self.tlas_leaf(leaf) {
                let p = &self.placements[inst as usize];
                let local = if p.identity { world } else { world.transformed(ray, &p.world_to_object) };
                let mesh = &self.meshes[p.mesh as usize];
                walk1(&self.blas[p.mesh as usize].nodes, &local.boxes, q, |q, leaf| {
                    q.triangles(mesh, &local, leaf, inst)
                });
                if q.done() {
                    return;
                }
            }
        });
    }

    /// Eight rays through both levels, as [`Accel::trace1`]; each instance's walk is
    /// monomorphised for the packet's kind of shear and box test.
    fn trace8<Q: Leaf8>(&self, rays: &RayPacket8, active: M32x8, q: &mut Q) {
        let world = Local8::new(rays.origin, rays.dir, rays.tnear, active);
        let tlas = |q: &mut Q, leaf: &Node| {
            for &inst in self.tlas_leaf(leaf) {
                let p = &self.placements[inst as usize];
                let local =
                    if p.identity { world } else { world.transformed(rays, &p.world_to_object, q.active()) };
                let (mesh, nodes) = (&self.meshes[p.mesh as usize], &self.blas[p.mesh as usize].nodes);
                match (&local.shear, &local.boxes) {
                    (Shear8::Uniform(s), BoxRay8::Octant(b)) => blas8(nodes, mesh, &local, s, b, inst, q),
                    (Shear8::Uniform(s), BoxRay8::Mixed(b)) => blas8(nodes, mesh, &local, s, b, inst, q),
                    (Shear8::Mixed(s), BoxRay8::Octant(b)) => blas8(nodes, mesh, &local, s, b, inst, q),
                    (Shear8::Mixed(s), BoxRay8::Mixed(b)) => blas8(nodes, mesh, &local, s, b, inst, q),
                }
                if q.active().none() {
                    return;
                }
            }
        };
        match &world.boxes {
            BoxRay8::Octant(b) => walk8(&self.tlas.nodes, b, q, tlas),
            BoxRay8::Mixed(b) => walk8(&self.tlas.nodes, b, q, tlas),
        }
    }

    /// Instances referenced by a top-level leaf.
    #[inline(always)]
    fn tlas_leaf(&self, leaf: &Node) -> &[u32] {
        &self.tlas.prim_order[leaf.offset as usize..(leaf.offset + leaf.count) as usize]
    }
}

/// The tie rule that makes closest hits independent of traversal order.
#[inline(always)]
fn closer(t: f32, inst: u32, prim: u32, best: &Hit) -> bool {
    t < best.t || (t == best.t && (inst, prim) < (best.instance, best.prim))
}

/// A single ray in one instance's object space, ready for box and triangle tests.
#[derive(Clone, Copy)]
struct Local1 {
    org: [f32; 3],
    shear: ShearScalar,
    boxes: BoxRay1,
}

impl Local1 {
    fn new(org: Vec3, dir: Vec3, tnear: f32) -> Self {
        Self { org: org.to_array(), shear: ShearScalar::new(dir), boxes: BoxRay1::new(org, dir, tnear) }
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

struct Closest1 {
    hit: Hit,
}

impl Query1 for Closest1 {
    const SHRINKS: bool = true;
    #[inline(always)]
    fn tfar(&self) -> f32 {
        self.hit.t
    }
    #[inline(always)]
    fn done(&self) -> bool {
        false
    }
}

struct Any1 {
    tfar: f32,
    hit: bool,
}

impl Query1 for Any1 {
    const SHRINKS: bool = false;
    #[inline(always)]
    fn tfar(&self) -> f32 {
        self.tfar
    }
    #[inline(always)]
    fn done(&self) -> bool {
        self.hit
    }
}

/// A single-ray query's handling of one leaf's triangles.
trait Leaf1: Query1 {
    fn triangles(&mut self, mesh: &TriangleMesh, local: &Local1, leaf: &Node, inst: u32);
}

impl Leaf1 for Closest1 {
    #[inline(always)]
    fn triangles(&mut self, mesh: &TriangleMesh, local: &Local1, leaf: &Node, inst: u32) {
        for prim in leaf.offset..leaf.offset + leaf.count {
            let [a, b, c] = mesh.triangle(prim);
            let h = intersect(local.org, &local.shear, a, b, c, local.boxes.tnear, self.hit.t);
            if h.mask && closer(h.t, inst, prim, &self.hit) {
                self.hit = Hit { t: h.t, u: h.u, v: h.v, instance: inst, prim };
            }
        }
    }
}

impl Leaf1 for Any1 {
    #[inline(always)]
    fn triangles(&mut self, mesh: &TriangleMesh, local: &Local1, leaf: &Node, _inst: u32) {
        for prim in leaf.offset..leaf.offset + leaf.count {
            let [a, b, c] = mesh.triangle(prim);
            if intersect(local.org, &local.shear, a, b, c, local.boxes.tnear, self.tfar).mask {
                self.hit = true;
                return;
            }
        }
    }
}

/// Eight rays in one instance's object space.
#[derive(Clone, Copy)]
struct Local8 {
    org: [F32x8; 3],
    tnear: F32x8,
    shear: Shear8,
    boxes: BoxRay8,
}

impl Local8 {
    fn new(org: Vec3x8, dir: Vec3x8, tnear: F32x8, active: M32x8) -> Self {
        Self {
            org: [org.x, org.y, org.z],
            tnear,
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

struct Closest8 {
    t: F32x8,
    u: F32x8,
    v: F32x8,
    instance: I32x8,
    prim: I32x8,
    active: M32x8,
}

impl Query8 for Closest8 {
    const SHRINKS: bool = true;
    #[inline(always)]
    fn tfar(&self) -> F32x8 {
        self.t
    }
    #[inline(always)]
    fn active(&self) -> M32x8 {
        self.active
    }
}

struct Any8 {
    tfar: F32x8,
    active: M32x8,
}

impl Query8 for Any8 {
    const SHRINKS: bool = false;
    #[inline(always)]
    fn tfar(&self) -> F32x8 {
        self.tfar
    }
    #[inline(always)]
    fn active(&self) -> M32x8 {
        self.active
    }
}

/// A packet query's handling of one leaf's triangles.
trait Leaf8: Query8 {
    fn triangles<S: Shear<F32x8>>(
        &mut self,
        mesh: &TriangleMesh,
        local: &Local8,
        shear: &S,
        leaf: &Node,
        inst: u32,
    );
}

/// Walks one bottom-level BVH with a packet.
#[inline(always)]
fn blas8<Q: Leaf8, S: Shear<F32x8>, B: Boxes8>(
    nodes: &[Node],
    mesh: &TriangleMesh,
    local: &Local8,
    shear: &S,
    boxes: &B,
    inst: u32,
    q: &mut Q,
) {
    walk8(nodes, boxes, q, |q, leaf| q.triangles(mesh, local, shear, leaf, inst));
}

impl Leaf8 for Closest8 {
    #[inline(always)]
    fn triangles<S: Shear<F32x8>>(
        &mut self,
        mesh: &TriangleMesh,
        local: &Local8,
        shear: &S,
        leaf: &Node,
        inst: u32,
    ) {
        let inst_v = I32x8::splat(inst as i32);
        for prim in leaf.offset..leaf.offset + leaf.count {
            let [a, b, c] = mesh.triangle(prim);
            let h = intersect(local.org, shear, a, b, c, local.tnear, self.t);
            let prim_v = I32x8::splat(prim as i32);
            // The tie rule of `closer`, lane by lane: ids compare as unsigned, and INVALID_ID
            // (-1 as i32) is the largest.
            let tie = h.t.eq(self.t)
                & (lt_u32(inst_v, self.instance) | (inst_v.eq(self.instance) & lt_u32(prim_v, self.prim)));
            let take = h.mask & self.active & (h.t.lt(self.t) | tie);
            if take.any() {
                self.t = F32x8::select(take, h.t, self.t);
                self.u = F32x8::select(take, h.u, self.u);
                self.v = F32x8::select(take, h.v, self.v);
                self.instance = I32x8::select(take, inst_v, self.instance);
                self.prim = I32x8::select(take, prim_v, self.prim);
            }
        }
    }
}

impl Leaf8 for Any8 {
    #[inline(always)]
    fn triangles<S: Shear<F32x8>>(
        &mut self,
        mesh: &TriangleMesh,
        local: &Local8,
        shear: &S,
        leaf: &Node,
        _inst: u32,
    ) {
        for prim in leaf.offset..leaf.offset + leaf.count {
            let [a, b, c] = mesh.triangle(prim);
            let h = intersect(local.org, shear, a, b, c, local.tnear, self.tfar);
            self.active = self.active.and_not(h.mask);
            if self.active.none() {
                return;
            }
        }
    }
}

/// Unsigned `a < b` per lane.
#[inline(always)]
fn lt_u32(a: I32x8, b: I32x8) -> M32x8 {
    let flip = I32x8::splat(i32::MIN);
    (a ^ flip).lt(b ^ flip)
}
