//! Portable backend: each type is a plain array and every operation a loop over the lanes,
//! which the compiler vectorises where the target allows. Results equal the AVX2 backend's
//! bit for bit (including the NaN rules of `min`/`max` and the single rounding of `mul_add`).

use crate::Lanes;
use std::array::from_fn;
use std::ops::{Add, BitAnd, BitOr, BitXor, Div, Mul, Neg, Not, Sub};

/// Eight `f32` lanes.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
pub struct F32x8([f32; 8]);

/// Eight `i32` lanes.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
pub struct I32x8([i32; 8]);

/// Eight lane flags.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
pub struct M32x8([bool; 8]);

impl F32x8 {
    /// All lanes zero.
    pub const ZERO: Self = Self([0.0; 8]);

    /// All lanes `v`.
    #[inline(always)]
    pub fn splat(v: f32) -> Self {
        Self([v; 8])
    }

    /// Lanes from an array, lane 0 first.
    #[inline(always)]
    pub const fn from_array(a: [f32; 8]) -> Self {
        Self(a)
    }

    /// The lanes as an array, lane 0 first.
    #[inline(always)]
    pub fn to_array(self) -> [f32; 8] {
        self.0
    }

    /// Lane `i` (panics if `i >= 8`).
    #[inline(always)]
    pub fn lane(self, i: usize) -> f32 {
        self.0[i]
    }

    /// `self * b + c`, fused (one rounding, as `f32::mul_add`).
    #[inline(always)]
    pub fn mul_add(self, b: Self, c: Self) -> Self {
        Self(from_fn(|i| self.0[i].mul_add(b.0[i], c.0[i])))
    }

    /// Lane-wise minimum; if either lane is NaN the result is `o`'s lane (as `minps`).
    #[inline(always)]
    pub fn min(self, o: Self) -> Self {
        Self(from_fn(|i| if self.0[i] < o.0[i] { self.0[i] } else { o.0[i] }))
    }

    /// Lane-wise maximum; if either lane is NaN the result is `o`'s lane (as `maxps`).
    #[inline(always)]
    pub fn max(self, o: Self) -> Self {
        Self(from_fn(|i| if self.0[i] > o.0[i] { self.0[i] } else { o.0[i] }))
    }

    /// Lane-wise square root.
    #[inline(always)]
    pub fn sqrt(self) -> Self {
        Self(self.0.map(f32::sqrt))
    }

    /// Lane-wise absolute value.
    #[inline(always)]
    pub fn abs(self) -> Self {
        Self(self.0.map(f32::abs))
    }

    /// Lane-wise floor.
    #[inline(always)]
    pub fn floor(self) -> Self {
        Self(self.0.map(f32::floor))
    }

    /// `self` with the sign bit of each lane flipped where `sign`'s lane is negative.
    #[inline(always)]
    pub fn xor_sign(self, sign: Self) -> Self {
        Self(from_fn(|i| Lanes::xor_sign(self.0[i], sign.0[i])))
    }

    /// `self < o` per lane (false for NaN).
    #[inline(always)]
    pub fn lt(self, o: Self) -> M32x8 {
        M32x8(from_fn(|i| self.0[i] < o.0[i]))
    }

    /// `self <= o` per lane (false for NaN).
    #[inline(always)]
    pub fn le(self, o: Self) -> M32x8 {
        M32x8(from_fn(|i| self.0[i] <= o.0[i]))
    }

    /// `self > o` per lane (false for NaN).
    #[inline(always)]
    pub fn gt(self, o: Self) -> M32x8 {
        M32x8(from_fn(|i| self.0[i] > o.0[i]))
    }

    /// `self >= o` per lane (false for NaN).
    #[inline(always)]
    pub fn ge(self, o: Self) -> M32x8 {
        M32x8(from_fn(|i| self.0[i] >= o.0[i]))
    }

    /// `self == o` per lane (false for NaN).
    #[inline(always)]
    pub fn eq(self, o: Self) -> M32x8 {
        M32x8(from_fn(|i| self.0[i] == o.0[i]))
    }

    /// Per lane: `a` where `m` is set, else `b`.
    #[inline(always)]
    pub fn select(m: M32x8, a: Self, b: Self) -> Self {
        Self(from_fn(|i| if m.0[i] { a.0[i] } else { b.0[i] }))
    }

    /// Smallest lane (NaN lanes are ignored unless all are NaN).
    #[inline(always)]
    pub fn reduce_min(self) -> f32 {
        let a = self.0;
        let m4: [f32; 4] = from_fn(|i| if a[i] < a[i + 4] { a[i] } else { a[i + 4] });
        let m2: [f32; 2] = from_fn(|i| if m4[i] < m4[i + 2] { m4[i] } else { m4[i + 2] });
        if m2[0] < m2[1] { m2[0] } else { m2[1] }
    }

    /// Largest lane (NaN lanes are ignored unless all are NaN).
    #[inline(always)]
    pub fn reduce_max(self) -> f32 {
        let a = self.0;
        let m4: [f32; 4] = from_fn(|i| if a[i] > a[i + 4] { a[i] } else { a[i + 4] });
        let m2: [f32; 2] = from_fn(|i| if m4[i] > m4[i + 2] { m4[i] } else { m4[i + 2] });
        if m2[0] > m2[1] { m2[0] } else { m2[1] }
    }

    /// Lanes converted to `i32`, truncating toward zero (out of range: `i32::MIN`, as
    /// `cvttps2dq`).
    #[inline(always)]
    pub fn to_i32(self) -> I32x8 {
        I32x8(self.0.map(<f32 as Lanes>::to_i32))
    }

    /// The bits of each lane reinterpreted as `i32`.
    #[inline(always)]
    pub fn to_bits(self) -> I32x8 {
        I32x8(self.0.map(|v| v.to_bits() as i32))
    }

    /// The eight records `rows` as eight vectors of their fields: lane k of vector j is
    /// `rows[k][j]` (an 8×8 transpose).
    #[inline(always)]
    pub fn transpose(rows: [&[f32; 8]; 8]) -> [Self; 8] {
        from_fn(|j| Self(from_fn(|k| rows[k][j])))
    }

    /// Per lane `table[idx & 15]`.
    #[inline(always)]
    pub fn lookup16(table: &[f32; 16], idx: I32x8) -> Self {
        Self(idx.0.map(|i| <f32 as Lanes>::lookup16(table, i)))
    }
}

macro_rules! lanewise {
    ($t:ident, $tr:ident, $f:ident, $op:expr) => {
        impl $tr for $t {
            type Output = Self;
            #[inline(always)]
            fn $f(self, o: Self) -> Self {
                let op = $op;
                Self(from_fn(|i| op(self.0[i], o.0[i])))
            }
        }
    };
}
lanewise!(F32x8, Add, add, |a: f32, b: f32| a + b);
lanewise!(F32x8, Sub, sub, |a: f32, b: f32| a - b);
lanewise!(F32x8, Mul, mul, |a: f32, b: f32| a * b);
lanewise!(F32x8, Div, div, |a: f32, b: f32| a / b);
lanewise!(I32x8, Add, add, i32::wrapping_add);
lanewise!(I32x8, Sub, sub, i32::wrapping_sub);
lanewise!(I32x8, Mul, mul, i32::wrapping_mul);
lanewise!(I32x8, BitAnd, bitand, |a: i32, b: i32| a & b);
lanewise!(I32x8, BitOr, bitor, |a: i32, b: i32| a | b);
lanewise!(I32x8, BitXor, bitxor, |a: i32, b: i32| a ^ b);
lanewise!(M32x8, BitAnd, bitand, |a: bool, b: bool| a & b);
lanewise!(M32x8, BitOr, bitor, |a: bool, b: bool| a | b);
lanewise!(M32x8, BitXor, bitxor, |a: bool, b: bool| a ^ b);

impl Neg for F32x8 {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        Self(self.0.map(|v| -v))
    }
}

impl I32x8 {
    /// All lanes `v`.
    #[inline(always)]
    pub fn splat(v: i32) -> Self {
        Self([v; 8])
    }

    /// Lanes from an array, lane 0 first.
    #[inline(always)]
    pub const fn from_array(a: [i32; 8]) -> Self {
        Self(a)
    }

    /// The lanes as an array, lane 0 first.
    #[inline(always)]
    pub fn to_array(self) -> [i32; 8] {
        self.0
    }

    /// Lane `i` (panics if `i >= 8`).
    #[inline(always)]
    pub fn lane(self, i: usize) -> i32 {
        self.0[i]
    }

    /// `self == o` per lane.
    #[inline(always)]
    pub fn eq(self, o: Self) -> M32x8 {
        M32x8(from_fn(|i| self.0[i] == o.0[i]))
    }

    /// `self > o` per lane (signed).
    #[inline(always)]
    pub fn gt(self, o: Self) -> M32x8 {
        M32x8(from_fn(|i| self.0[i] > o.0[i]))
    }

    /// `self < o` per lane (signed).
    #[inline(always)]
    pub fn lt(self, o: Self) -> M32x8 {
        o.gt(self)
    }

    /// Per lane: `a` where `m` is set, else `b`.
    #[inline(always)]
    pub fn select(m: M32x8, a: Self, b: Self) -> Self {
        Self(from_fn(|i| if m.0[i] { a.0[i] } else { b.0[i] }))
    }

    /// Lanes converted to `f32`.
    #[inline(always)]
    pub fn to_f32(self) -> F32x8 {
        F32x8(self.0.map(|v| v as f32))
    }

    /// Each lane shifted left by `N` bits (`N` in 0..32), zeros shifted in.
    #[inline(always)]
    pub fn shl<const N: i32>(self) -> Self {
        const { assert!(N >= 0 && N < 32) };
        Self(self.0.map(|v| v << N))
    }

    /// Each lane shifted right by `N` bits (`N` in 0..32), copies of the sign bit shifted in
    /// (arithmetic shift: floor division by 2^N).
    #[inline(always)]
    pub fn shr<const N: i32>(self) -> Self {
        const { assert!(N >= 0 && N < 32) };
        Self(self.0.map(|v| v >> N))
    }

    /// Per lane `table[idx & (N - 1)]` (`N` a power of two).
    #[inline(always)]
    pub fn gather<const N: usize>(table: &[i32; N], idx: Self) -> Self {
        Self(idx.0.map(|i| <f32 as Lanes>::gather(table, i)))
    }

    /// The bits of each lane reinterpreted as `f32`.
    #[inline(always)]
    pub fn from_bits_to_f32(self) -> F32x8 {
        F32x8(self.0.map(|v| f32::from_bits(v as u32)))
    }
}

impl M32x8 {
    /// Every lane set.
    pub const ALL: Self = Self([true; 8]);
    /// No lane set.
    pub const NONE: Self = Self([false; 8]);

    /// Lanes from booleans, lane 0 first.
    #[inline(always)]
    pub const fn from_bools(b: [bool; 8]) -> Self {
        Self(b)
    }

    /// The mask whose lane `i` is bit `i` of `bits`.
    #[inline(always)]
    pub fn from_bitmask(bits: u32) -> Self {
        Self(from_fn(|i| bits >> i & 1 != 0))
    }

    /// Bit `i` of the result is lane `i`.
    #[inline(always)]
    pub fn bitmask(self) -> u32 {
        self.0.iter().enumerate().fold(0, |m, (i, &b)| m | (b as u32) << i)
    }

    /// True if any lane is set.
    #[inline(always)]
    pub fn any(self) -> bool {
        self.0.iter().any(|&b| b)
    }

    /// True if no lane is set.
    #[inline(always)]
    pub fn none(self) -> bool {
        !self.any()
    }

    /// Lane `i` (panics if `i >= 8`).
    #[inline(always)]
    pub fn lane(self, i: usize) -> bool {
        self.0[i]
    }

    /// `self & !o`.
    #[inline(always)]
    pub fn and_not(self, o: Self) -> Self {
        Self(from_fn(|i| self.0[i] & !o.0[i]))
    }
}

impl Not for M32x8 {
    type Output = Self;
    #[inline(always)]
    fn not(self) -> Self {
        Self(self.0.map(|b| !b))
    }
}
