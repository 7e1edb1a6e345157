//! Lane-generic arithmetic: the [`Lanes`] trait, implemented by `f32` (one lane) and [`F32x8`]
//! (eight lanes), and [`LaneMask`], its per-lane flags (`bool` and [`M32x8`]).
//!
//! A kernel written once over [`Lanes`] runs as scalar code and as SIMD code with the same
//! floating-point operations in the same order, so both forms give the same bits, lane for lane
//! (every [`F32x8`] operation equals the scalar one, see the crate documentation). The
//! watertight triangle test and the BVH walk (igi-bvh), improved noise and the GGX lobe
//! (igi-shade) are written this way, and their tests compare the two forms bit for bit.

use crate::{F32x8, I32x8, M32x8};
use std::ops::{Add, BitAnd, BitOr, Div, Mul, Not, Sub};

/// One flag per lane: `bool` for one lane, [`M32x8`] for eight.
pub trait LaneMask: Copy + BitAnd<Output = Self> + BitOr<Output = Self> + Not<Output = Self> {
    /// Every lane set.
    const ALL: Self;
    /// True if any lane is set.
    fn any(self) -> bool;
    /// Number of lanes set.
    fn count(self) -> u32;
}

/// The operations of one `f32` or of eight lanes ([`F32x8`]), with equal results lane for lane.
pub trait Lanes:
    Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + Div<Output = Self>
{
    /// One flag per lane.
    type Mask: LaneMask;
    /// Integer lanes: `i32` or [`I32x8`].
    type Int: Copy + Add<Output = Self::Int>;

    /// All lanes `v`.
    fn splat(v: f32) -> Self;
    /// `self * b + c` with one rounding.
    fn mul_add(self, b: Self, c: Self) -> Self;
    /// Largest integer ≤ `self`, per lane.
    fn floor(self) -> Self;
    /// Square root, per lane (correctly rounded in both forms, so the bits agree).
    fn sqrt(self) -> Self;
    /// `self` with its sign flipped where `sign` is negative.
    fn xor_sign(self, sign: Self) -> Self;
    /// `self < o` per lane (false for NaN).
    fn lt(self, o: Self) -> Self::Mask;
    /// `self > o` per lane (false for NaN).
    fn gt(self, o: Self) -> Self::Mask;
    /// `self <= o` per lane (false for NaN).
    fn le(self, o: Self) -> Self::Mask;
    /// `self >= o` per lane (false for NaN).
    fn ge(self, o: Self) -> Self::Mask;
    /// `self == o` per lane (false for NaN).
    fn eq(self, o: Self) -> Self::Mask;
    /// Per lane: `a` where `m` is set, else `b`.
    fn select(m: Self::Mask, a: Self, b: Self) -> Self;
    /// Smallest lane (NaN lanes are ignored unless all are NaN).
    fn reduce_min(self) -> f32;
    /// Largest lane (NaN lanes are ignored unless all are NaN).
    fn reduce_max(self) -> f32;
    /// `values`, except that in each lane where `m` is set they become `f` of that lane of
    /// `args`: the scalar fallback of a kernel for the rare lanes its fast path cannot settle
    /// (for eight lanes, one call kept out of line).
    fn recompute<const K: usize, const R: usize>(
        m: Self::Mask,
        values: [Self; R],
        args: [Self; K],
        f: impl Fn([f32; K]) -> [f32; R],
    ) -> [Self; R];
    /// Lanes converted to `i32`, truncating toward zero (out of range: `i32::MIN`, as
    /// `cvttps2dq`).
    fn to_i32(self) -> Self::Int;
    /// All integer lanes `v`.
    fn splat_i32(v: i32) -> Self::Int;
    /// Per lane `table[idx & (N - 1)]` (`N` a power of two).
    fn gather<const N: usize>(table: &[i32; N], idx: Self::Int) -> Self::Int;
    /// Per lane `table[idx & 15]`.
    fn lookup16(table: &[f32; 16], idx: Self::Int) -> Self;
}

impl LaneMask for bool {
    const ALL: Self = true;
    #[inline(always)]
    fn any(self) -> bool {
        self
    }
    #[inline(always)]
    fn count(self) -> u32 {
        self as u32
    }
}

impl LaneMask for M32x8 {
    const ALL: Self = M32x8::ALL;
    #[inline(always)]
    fn any(self) -> bool {
        M32x8::any(self)
    }
    #[inline(always)]
    fn count(self) -> u32 {
        self.bitmask().count_ones()
    }
}

impl Lanes for f32 {
    type Mask = bool;
    type Int = i32;
    #[inline(always)]
    fn splat(v: f32) -> Self {
        v
    }
    #[inline(always)]
    fn mul_add(self, b: Self, c: Self) -> Self {
        f32::mul_add(self, b, c)
    }
    #[inline(always)]
    fn floor(self) -> Self {
        f32::floor(self)
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        f32::sqrt(self)
    }
    #[inline(always)]
    fn xor_sign(self, sign: Self) -> Self {
        f32::from_bits(self.to_bits() ^ (sign.to_bits() & 0x8000_0000))
    }
    #[inline(always)]
    fn lt(self, o: Self) -> bool {
        self < o
    }
    #[inline(always)]
    fn gt(self, o: Self) -> bool {
        self > o
    }
    #[inline(always)]
    fn le(self, o: Self) -> bool {
        self <= o
    }
    #[inline(always)]
    fn ge(self, o: Self) -> bool {
        self >= o
    }
    #[inline(always)]
    fn eq(self, o: Self) -> bool {
        self == o
    }
    #[inline(always)]
    fn select(m: bool, a: Self, b: Self) -> Self {
        if m { a } else { b }
    }
    #[inline(always)]
    fn reduce_min(self) -> f32 {
        self
    }
    #[inline(always)]
    fn reduce_max(self) -> f32 {
        self
    }
    #[inline(always)]
    fn recompute<const K: usize, const R: usize>(
        m: bool,
        values: [Self; R],
        args: [Self; K],
        f: impl Fn([f32; K]) -> [f32; R],
    ) -> [Self; R] {
        if m { f(args) } else { values }
    }
    #[inline(always)]
    fn to_i32(self) -> i32 {
        if (-2_147_483_648.0..2_147_483_648.0).contains(&self) { self as i32 } else { i32::MIN }
    }
    #[inline(always)]
    fn splat_i32(v: i32) -> i32 {
        v
    }
    #[inline(always)]
    fn gather<const N: usize>(table: &[i32; N], idx: i32) -> i32 {
        const { assert!(N.is_power_of_two() && N <= 1 << 30) };
        table[(idx & (N - 1) as i32) as usize]
    }
    #[inline(always)]
    fn lookup16(table: &[f32; 16], idx: i32) -> Self {
        table[(idx & 15) as usize]
    }
}

/// Trait methods that call the inherent [`F32x8`] method of the same name and signature.
macro_rules! inherent {
    ($(fn $f:ident($($arg:ident: $t:ty),*) -> $r:ty;)*) => {
        $(
            #[inline(always)]
            fn $f($($arg: $t),*) -> $r {
                F32x8::$f($($arg),*)
            }
        )*
    };
}

impl Lanes for F32x8 {
    type Mask = M32x8;
    type Int = I32x8;
    inherent! {
        fn splat(v: f32) -> Self;
        fn mul_add(self: Self, b: Self, c: Self) -> Self;
        fn floor(self: Self) -> Self;
        fn sqrt(self: Self) -> Self;
        fn xor_sign(self: Self, sign: Self) -> Self;
        fn lt(self: Self, o: Self) -> M32x8;
        fn gt(self: Self, o: Self) -> M32x8;
        fn le(self: Self, o: Self) -> M32x8;
        fn ge(self: Self, o: Self) -> M32x8;
        fn eq(self: Self, o: Self) -> M32x8;
        fn select(m: M32x8, a: Self, b: Self) -> Self;
        fn reduce_min(self: Self) -> f32;
        fn reduce_max(self: Self) -> f32;
        fn to_i32(self: Self) -> I32x8;
        fn lookup16(table: &[f32; 16], idx: I32x8) -> Self;
    }
    #[cold]
    fn recompute<const K: usize, const R: usize>(
        m: M32x8,
        values: [Self; R],
        args: [Self; K],
        f: impl Fn([f32; K]) -> [f32; R],
    ) -> [Self; R] {
        let (mut r, args) = (values.map(F32x8::to_array), args.map(F32x8::to_array));
        for i in (0..8).filter(|&i| m.lane(i)) {
            let lane = f(std::array::from_fn(|k| args[k][i]));
            for (r, v) in r.iter_mut().zip(lane) {
                r[i] = v;
            }
        }
        r.map(F32x8::from_array)
    }
    #[inline(always)]
    fn splat_i32(v: i32) -> I32x8 {
        I32x8::splat(v)
    }
    #[inline(always)]
    fn gather<const N: usize>(table: &[i32; N], idx: I32x8) -> I32x8 {
        I32x8::gather(table, idx)
    }
}
