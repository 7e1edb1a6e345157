//! [`Packet8`]: up to eight rays of a stream gathered lane by lane and traced as one 8-ray
//! packet, as the tile pipeline traces its specular and bias-compensation rays (closest hit)
//! and the shadow rays the roulette leaves ([`crate::igi::vpl_lighting`], any hit; paper
//! 3.1.2: rays travel in packets of eight).

use glam::Vec3;
use igi_bvh::{Accel, Hit, HitPacket8, Ray, RayPacket8};
use igi_simd::M32x8;

/// Up to eight rays, one per lane; lanes without a ray are unoccupied.
#[derive(Clone, Copy, Debug)]
pub struct Packet8 {
    rays: [Ray; 8],
    bits: u32,
}

/// What a traced [`Packet8`] hit.
#[derive(Clone, Copy, Debug)]
pub struct PacketHits {
    /// The closest hit of each lane (a miss in unoccupied lanes).
    pub hits: [Hit; 8],
    /// The occupied lanes whose ray hit something.
    pub bits: u32,
}

impl Packet8 {
    /// A packet without rays.
    #[inline]
    pub fn new() -> Self {
        Self { rays: [Ray::new(Vec3::ZERO, Vec3::Z); 8], bits: 0 }
    }

    /// Puts `ray` into lane `lane` (0..8).
    #[inline]
    pub fn set(&mut self, lane: usize, ray: Ray) {
        self.rays[lane] = ray;
        self.bits |= 1 << lane;
    }

    /// The ray of lane `lane`.
    #[inline]
    pub fn ray(&self, lane: usize) -> &Ray {
        &self.rays[lane]
    }

    /// Number of rays.
    #[inline]
    pub fn len(&self) -> u32 {
        self.bits.count_ones()
    }

    /// The rays as one 8-ray packet, and its occupied lanes. Unoccupied lanes (a full packet,
    /// the common case, has none) repeat the first ray, so that every lane of the packet holds
    /// a valid ray: the packet kernels decide the traversal order from all lanes' signs.
    #[inline]
    pub fn packet(&mut self) -> (RayPacket8, M32x8) {
        if self.bits != 0 && self.bits != 0xff {
            let first = self.rays[self.bits.trailing_zeros() as usize];
            for lane in 0..8 {
                if self.bits & (1 << lane) == 0 {
                    self.rays[lane] = first;
                }
            }
        }
        (RayPacket8::from_rays(&self.rays), M32x8::from_bitmask(self.bits))
    }

    /// The closest hits of the rays (all misses for an empty packet).
    #[inline]
    pub fn intersect(&mut self, accel: &Accel) -> PacketHits {
        if self.bits == 0 {
            return PacketHits { hits: [Hit::miss(f32::INFINITY); 8], bits: 0 };
        }
        let (rays, active) = self.packet();
        let hits = accel.intersect8(&rays, active);
        PacketHits { hits: unpack_hits(&hits), bits: self.bits & hits.hit_mask().bitmask() }
    }
}

/// The hits of a packet as single records (one store per field instead of one per lane and
/// field).
pub(crate) fn unpack_hits(h: &HitPacket8) -> [Hit; 8] {
    let (t, u, v) = (h.t.to_array(), h.u.to_array(), h.v.to_array());
    let (instance, prim) = (h.instance.to_array(), h.prim.to_array());
    std::array::from_fn(|i| Hit {
        t: t[i],
        u: u[i],
        v: v[i],
        instance: instance[i] as u32,
        prim: prim[i] as u32,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Affine3A;
    use igi_bvh::TriangleMesh;

    /// A unit square at z = 0 (two triangles) seen from z = 1.
    fn square() -> Accel {
        let positions = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        ];
        let mesh = TriangleMesh { positions, indices: vec![[0, 1, 2], [0, 2, 3]] };
        Accel::build(vec![mesh], &[(0, Affine3A::IDENTITY)]).0
    }

    #[test]
    fn sparse_lanes_hit_what_single_rays_hit() {
        let accel = square();
        let ray = |x: f32, y: f32| Ray::new(Vec3::new(x, y, 1.0), Vec3::NEG_Z);
        // Lanes 1, 4 and 6 occupied; lane 4 misses the square.
        let rays = [(1, ray(0.2, 0.7)), (4, ray(1.5, 0.5)), (6, ray(0.9, 0.1))];
        let mut packet = Packet8::new();
        for &(lane, r) in &rays {
            packet.set(lane, r);
        }
        assert_eq!(packet.len(), 3);
        let traced = packet.intersect(&accel);
        assert_eq!(traced.bits, 0b100_0010, "occupied lanes that hit");
        for &(lane, r) in &rays {
            assert_eq!(traced.hits[lane], accel.intersect(&r), "lane {lane}");
        }
        for lane in [0, 2, 3, 5, 7] {
            assert!(!traced.hits[lane].is_hit(), "unoccupied lane {lane}");
        }
        assert_eq!(Packet8::new().intersect(&accel).bits, 0, "an empty packet hits nothing");
    }
}
