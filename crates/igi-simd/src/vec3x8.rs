//! Eight 3-vectors in structure-of-arrays form: the ray origins, directions and normals of an
//! 8-ray packet.

use crate::{F32x8, M32x8};
use std::ops::{Add, Mul, Neg, Sub};

/// Eight 3-vectors, one per lane, stored as three [`F32x8`]s.
#[derive(Clone, Copy, Debug)]
pub struct Vec3x8 {
    /// x components.
    pub x: F32x8,
    /// y components.
    pub y: F32x8,
    /// z components.
    pub z: F32x8,
}

impl Vec3x8 {
    /// From three component vectors.
    #[inline(always)]
    pub fn new(x: F32x8, y: F32x8, z: F32x8) -> Self {
        Self { x, y, z }
    }

    /// The same vector in every lane.
    #[inline(always)]
    pub fn splat(v: [f32; 3]) -> Self {
        Self::new(F32x8::splat(v[0]), F32x8::splat(v[1]), F32x8::splat(v[2]))
    }

    /// From eight vectors, lane 0 first.
    #[inline(always)]
    pub fn from_lanes(v: [[f32; 3]; 8]) -> Self {
        Self::new(
            F32x8::from_array(v.map(|p| p[0])),
            F32x8::from_array(v.map(|p| p[1])),
            F32x8::from_array(v.map(|p| p[2])),
        )
    }

    /// Lane `i` as an array.
    #[inline(always)]
    pub fn lane(&self, i: usize) -> [f32; 3] {
        [self.x.lane(i), self.y.lane(i), self.z.lane(i)]
    }

    /// All eight lanes as arrays, lane 0 first (one store per component, not per lane).
    #[inline(always)]
    pub fn to_lanes(&self) -> [[f32; 3]; 8] {
        let (x, y, z) = (self.x.to_array(), self.y.to_array(), self.z.to_array());
        std::array::from_fn(|i| [x[i], y[i], z[i]])
    }

    /// Dot products per lane.
    #[inline(always)]
    pub fn dot(self, o: Self) -> F32x8 {
        self.x * o.x + self.y * o.y + self.z * o.z
    }

    /// Cross products per lane.
    #[inline(always)]
    pub fn cross(self, o: Self) -> Self {
        Self::new(self.y * o.z - self.z * o.y, self.z * o.x - self.x * o.z, self.x * o.y - self.y * o.x)
    }

    /// Lengths per lane.
    #[inline(always)]
    pub fn length(self) -> F32x8 {
        self.dot(self).sqrt()
    }

    /// Unit vectors per lane (lanes of zero length become NaN).
    #[inline(always)]
    pub fn normalize(self) -> Self {
        self * (F32x8::splat(1.0) / self.length())
    }

    /// Per lane: `a` where `m` is set, else `b`.
    #[inline(always)]
    pub fn select(m: M32x8, a: Self, b: Self) -> Self {
        Self::new(F32x8::select(m, a.x, b.x), F32x8::select(m, a.y, b.y), F32x8::select(m, a.z, b.z))
    }
}

impl Add for Vec3x8 {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        Self::new(self.x + o.x, self.y + o.y, self.z + o.z)
    }
}

impl Sub for Vec3x8 {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        Self::new(self.x - o.x, self.y - o.y, self.z - o.z)
    }
}

impl Mul<F32x8> for Vec3x8 {
    type Output = Self;
    #[inline(always)]
    fn mul(self, s: F32x8) -> Self {
        Self::new(self.x * s, self.y * s, self.z * s)
    }
}

impl Neg for Vec3x8 {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        Self::new(-self.x, -self.y, -self.z)
    }
}

impl From<[F32x8; 3]> for Vec3x8 {
    /// The vector with components `[x, y, z]`.
    #[inline(always)]
    fn from([x, y, z]: [F32x8; 3]) -> Self {
        Self::new(x, y, z)
    }
}

impl From<Vec3x8> for [F32x8; 3] {
    /// The components `[x, y, z]`.
    #[inline(always)]
    fn from(v: Vec3x8) -> Self {
        [v.x, v.y, v.z]
    }
}
