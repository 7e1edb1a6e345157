//! AVX2 + FMA backend: each type wraps one 256-bit register.
//!
//! This module is only compiled when the target enables `avx2` and `fma` (see `lib.rs`), so the
//! intrinsics are always available and the `unsafe` blocks below only call them.

use std::arch::x86_64::*;
use std::ops::{Add, BitAnd, BitOr, BitXor, Div, Mul, Neg, Not, Sub};

/// Eight `f32` lanes.
#[derive(Clone, Copy, Debug)]
#[repr(transparent)]
pub struct F32x8(__m256);

/// Eight `i32` lanes.
#[derive(Clone, Copy, Debug)]
#[repr(transparent)]
pub struct I32x8(__m256i);

/// Eight lane flags, each lane all ones (true) or all zeros (false).
#[derive(Clone, Copy, Debug)]
#[repr(transparent)]
pub struct M32x8(__m256);

/// The constructors and accessors of `$t`, which wraps one register of eight `$e`.
macro_rules! lanes_of {
    ($t:ident, $e:ty, $set1:ident) => {
        impl $t {
            /// All lanes `v`.
            #[inline(always)]
            pub fn splat(v: $e) -> Self {
                unsafe { Self($set1(v)) }
            }

            /// Lanes from an array, lane 0 first.
            #[inline(always)]
            pub const fn from_array(a: [$e; 8]) -> Self {
                // SAFETY: the register and the array have the same size and every bit pattern
                // is valid.
                unsafe { std::mem::transmute::<[$e; 8], Self>(a) }
            }

            /// The lanes as an array, lane 0 first.
            #[inline(always)]
            pub fn to_array(self) -> [$e; 8] {
                // SAFETY: as in `from_array`.
                unsafe { std::mem::transmute::<Self, [$e; 8]>(self) }
            }

            /// Lane `i` (panics if `i >= 8`).
            #[inline(always)]
            pub fn lane(self, i: usize) -> $e {
                self.to_array()[i]
            }
        }
    };
}
lanes_of!(F32x8, f32, _mm256_set1_ps);
lanes_of!(I32x8, i32, _mm256_set1_epi32);

/// `F32x8` comparisons, each one `vcmpps` with the predicate given.
macro_rules! f32_compare {
    ($($(#[$doc:meta])* $f:ident = $pred:ident;)*) => {
        impl F32x8 {
            $(
                $(#[$doc])*
                #[inline(always)]
                pub fn $f(self, o: Self) -> M32x8 {
                    unsafe { M32x8(_mm256_cmp_ps::<$pred>(self.0, o.0)) }
                }
            )*
        }
    };
}
f32_compare! {
    /// `self < o` per lane (false for NaN).
    lt = _CMP_LT_OQ;
    /// `self <= o` per lane (false for NaN).
    le = _CMP_LE_OQ;
    /// `self > o` per lane (false for NaN).
    gt = _CMP_GT_OQ;
    /// `self >= o` per lane (false for NaN).
    ge = _CMP_GE_OQ;
    /// `self == o` per lane (false for NaN).
    eq = _CMP_EQ_OQ;
}

impl F32x8 {
    /// All lanes zero.
    pub const ZERO: Self = Self::from_array([0.0; 8]);

    /// `self * b + c`, fused (one rounding).
    #[inline(always)]
    pub fn mul_add(self, b: Self, c: Self) -> Self {
        unsafe { Self(_mm256_fmadd_ps(self.0, b.0, c.0)) }
    }

    /// Lane-wise minimum; if either lane is NaN the result is `o`'s lane.
    #[inline(always)]
    pub fn min(self, o: Self) -> Self {
        unsafe { Self(_mm256_min_ps(self.0, o.0)) }
    }

    /// Lane-wise maximum; if either lane is NaN the result is `o`'s lane.
    #[inline(always)]
    pub fn max(self, o: Self) -> Self {
        unsafe { Self(_mm256_max_ps(self.0, o.0)) }
    }

    /// Lane-wise square root.
    #[inline(always)]
    pub fn sqrt(self) -> Self {
        unsafe { Self(_mm256_sqrt_ps(self.0)) }
    }

    /// Lane-wise absolute value.
    #[inline(always)]
    pub fn abs(self) -> Self {
        unsafe { Self(_mm256_andnot_ps(_mm256_set1_ps(-0.0), self.0)) }
    }

    /// Lane-wise floor.
    #[inline(always)]
    pub fn floor(self) -> Self {
        unsafe { Self(_mm256_floor_ps(self.0)) }
    }

    /// `self` with the sign bit of each lane flipped where `sign`'s lane is negative.
    #[inline(always)]
    pub fn xor_sign(self, sign: Self) -> Self {
        unsafe {
            let s = _mm256_and_ps(sign.0, _mm256_set1_ps(-0.0));
            Self(_mm256_xor_ps(self.0, s))
        }
    }

    /// Per lane: `a` where `m` is set, else `b`.
    #[inline(always)]
    pub fn select(m: M32x8, a: Self, b: Self) -> Self {
        unsafe { Self(_mm256_blendv_ps(b.0, a.0, m.0)) }
    }

    /// Smallest lane (NaN lanes are ignored unless all are NaN).
    #[inline(always)]
    pub fn reduce_min(self) -> f32 {
        reduce(self.0, |a, b| unsafe { _mm256_min_ps(a, b) })
    }

    /// Largest lane (NaN lanes are ignored unless all are NaN).
    #[inline(always)]
    pub fn reduce_max(self) -> f32 {
        reduce(self.0, |a, b| unsafe { _mm256_max_ps(a, b) })
    }

    /// Lanes converted to `i32`, truncating toward zero.
    #[inline(always)]
    pub fn to_i32(self) -> I32x8 {
        unsafe { I32x8(_mm256_cvttps_epi32(self.0)) }
    }

    /// The bits of each lane reinterpreted as `i32`.
    #[inline(always)]
    pub fn to_bits(self) -> I32x8 {
        unsafe { I32x8(_mm256_castps_si256(self.0)) }
    }

    /// The eight records `rows` as eight vectors of their fields: lane k of vector j is
    /// `rows[k][j]` (an 8×8 transpose). Each half of a record is loaded beside the same half of
    /// the record four lanes on, so two 4×4 transposes within the 128-bit halves do it: 16
    /// shuffles instead of the 24 of a transpose of whole registers.
    #[inline(always)]
    pub fn transpose(rows: [&[f32; 8]; 8]) -> [Self; 8] {
        // SAFETY: each load reads four floats of an eight-float array.
        unsafe {
            let half = |k: usize, at: usize| {
                _mm256_insertf128_ps::<1>(
                    _mm256_castps128_ps256(_mm_loadu_ps(rows[k].as_ptr().add(at))),
                    _mm_loadu_ps(rows[k + 4].as_ptr().add(at)),
                )
            };
            let transpose4 = |r: [__m256; 4]| {
                let (t0, t1) = (_mm256_unpacklo_ps(r[0], r[1]), _mm256_unpackhi_ps(r[0], r[1]));
                let (t2, t3) = (_mm256_unpacklo_ps(r[2], r[3]), _mm256_unpackhi_ps(r[2], r[3]));
                [
                    _mm256_shuffle_ps::<0x44>(t0, t2),
                    _mm256_shuffle_ps::<0xee>(t0, t2),
                    _mm256_shuffle_ps::<0x44>(t1, t3),
                    _mm256_shuffle_ps::<0xee>(t1, t3),
                ]
            };
            let low = transpose4([half(0, 0), half(1, 0), half(2, 0), half(3, 0)]);
            let high = transpose4([half(0, 4), half(1, 4), half(2, 4), half(3, 4)]);
            [low[0], low[1], low[2], low[3], high[0], high[1], high[2], high[3]].map(Self)
        }
    }

    /// Per lane `table[idx & 15]`: a lookup in a 16-entry table held in two registers (two
    /// `vpermps` and a blend on bit 3 of the index), far cheaper than a gather.
    #[inline(always)]
    pub fn lookup16(table: &[f32; 16], idx: I32x8) -> Self {
        unsafe {
            let lo = _mm256_permutevar8x32_ps(_mm256_loadu_ps(table.as_ptr()), idx.0);
            let hi = _mm256_permutevar8x32_ps(_mm256_loadu_ps(table.as_ptr().add(8)), idx.0);
            // Bit 3 of the index moved to the sign bit picks the upper half.
            Self(_mm256_blendv_ps(lo, hi, _mm256_castsi256_ps(_mm256_slli_epi32::<28>(idx.0))))
        }
    }
}

/// The eight lanes of `v` folded with `op` as a tree: the two halves, then pairs, then
/// neighbours.
#[inline(always)]
fn reduce(v: __m256, op: impl Fn(__m256, __m256) -> __m256) -> f32 {
    unsafe {
        let m = op(v, _mm256_permute2f128_ps::<1>(v, v));
        let m = op(m, _mm256_shuffle_ps::<0b01_00_11_10>(m, m));
        let m = op(m, _mm256_shuffle_ps::<0b10_11_00_01>(m, m));
        _mm256_cvtss_f32(m)
    }
}

/// The binary operators of `$t`: `impl $tr for $t` (method `$f`) as the intrinsic `$intr` on the
/// wrapped registers, for each operator listed.
macro_rules! ops {
    ($t:ident, $($tr:ident $f:ident $intr:ident),*) => {
        $(
            impl $tr for $t {
                type Output = Self;
                #[inline(always)]
                fn $f(self, o: Self) -> Self {
                    unsafe { Self($intr(self.0, o.0)) }
                }
            }
        )*
    };
}
ops!(F32x8, Add add _mm256_add_ps, Sub sub _mm256_sub_ps, Mul mul _mm256_mul_ps, Div div _mm256_div_ps);
ops!(I32x8, Add add _mm256_add_epi32, Sub sub _mm256_sub_epi32, Mul mul _mm256_mullo_epi32);
ops!(I32x8, BitAnd bitand _mm256_and_si256, BitOr bitor _mm256_or_si256, BitXor bitxor _mm256_xor_si256);
ops!(M32x8, BitAnd bitand _mm256_and_ps, BitOr bitor _mm256_or_ps, BitXor bitxor _mm256_xor_ps);

impl Neg for F32x8 {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        unsafe { Self(_mm256_xor_ps(self.0, _mm256_set1_ps(-0.0))) }
    }
}

impl I32x8 {
    /// `self == o` per lane.
    #[inline(always)]
    pub fn eq(self, o: Self) -> M32x8 {
        unsafe { M32x8(_mm256_castsi256_ps(_mm256_cmpeq_epi32(self.0, o.0))) }
    }

    /// `self > o` per lane (signed).
    #[inline(always)]
    pub fn gt(self, o: Self) -> M32x8 {
        unsafe { M32x8(_mm256_castsi256_ps(_mm256_cmpgt_epi32(self.0, o.0))) }
    }

    /// `self < o` per lane (signed).
    #[inline(always)]
    pub fn lt(self, o: Self) -> M32x8 {
        o.gt(self)
    }

    /// Per lane: `a` where `m` is set, else `b`.
    #[inline(always)]
    pub fn select(m: M32x8, a: Self, b: Self) -> Self {
        unsafe {
            Self(_mm256_castps_si256(_mm256_blendv_ps(
                _mm256_castsi256_ps(b.0),
                _mm256_castsi256_ps(a.0),
                m.0,
            )))
        }
    }

    /// Lanes converted to `f32`.
    #[inline(always)]
    pub fn to_f32(self) -> F32x8 {
        unsafe { F32x8(_mm256_cvtepi32_ps(self.0)) }
    }

    /// Each lane shifted left by `N` bits (`N` in 0..32), zeros shifted in.
    #[inline(always)]
    pub fn shl<const N: i32>(self) -> Self {
        const { assert!(N >= 0 && N < 32) };
        unsafe { Self(_mm256_slli_epi32::<N>(self.0)) }
    }

    /// Each lane shifted right by `N` bits (`N` in 0..32), copies of the sign bit shifted in
    /// (arithmetic shift: floor division by 2^N).
    #[inline(always)]
    pub fn shr<const N: i32>(self) -> Self {
        const { assert!(N >= 0 && N < 32) };
        unsafe { Self(_mm256_srai_epi32::<N>(self.0)) }
    }

    /// Per lane `table[idx & (N - 1)]` (`N` a power of two): a gather whose masked indices can
    /// never leave the table.
    #[inline(always)]
    pub fn gather<const N: usize>(table: &[i32; N], idx: Self) -> Self {
        const { assert!(N.is_power_of_two() && N <= 1 << 30) };
        let masked = idx & Self::splat((N - 1) as i32);
        // SAFETY: every index is masked into 0..N, inside `table`.
        unsafe { Self(_mm256_i32gather_epi32::<4>(table.as_ptr(), masked.0)) }
    }

    /// The bits of each lane reinterpreted as `f32`.
    #[inline(always)]
    pub fn from_bits_to_f32(self) -> F32x8 {
        unsafe { F32x8(_mm256_castsi256_ps(self.0)) }
    }
}

impl M32x8 {
    /// Every lane set.
    pub const ALL: Self = Self::from_bools([true; 8]);
    /// No lane set.
    pub const NONE: Self = Self::from_bools([false; 8]);

    /// Lanes from booleans, lane 0 first.
    #[inline(always)]
    pub const fn from_bools(b: [bool; 8]) -> Self {
        let mut a = [0i32; 8];
        let mut i = 0;
        while i < 8 {
            a[i] = if b[i] { -1 } else { 0 };
            i += 1;
        }
        // SAFETY: same size, every bit pattern valid.
        unsafe { std::mem::transmute::<[i32; 8], Self>(a) }
    }

    /// The mask whose lane `i` is bit `i` of `bits`.
    #[inline(always)]
    pub fn from_bitmask(bits: u32) -> Self {
        unsafe {
            let lane_bits = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
            let b = _mm256_and_si256(_mm256_set1_epi32(bits as i32), lane_bits);
            Self(_mm256_castsi256_ps(_mm256_cmpeq_epi32(b, lane_bits)))
        }
    }

    /// Bit `i` of the result is lane `i`.
    #[inline(always)]
    pub fn bitmask(self) -> u32 {
        unsafe { _mm256_movemask_ps(self.0) as u32 }
    }

    /// True if any lane is set.
    #[inline(always)]
    pub fn any(self) -> bool {
        unsafe { _mm256_testz_ps(self.0, self.0) == 0 }
    }

    /// True if no lane is set.
    #[inline(always)]
    pub fn none(self) -> bool {
        !self.any()
    }

    /// Lane `i` (panics if `i >= 8`).
    #[inline(always)]
    pub fn lane(self, i: usize) -> bool {
        assert!(i < 8);
        self.bitmask() >> i & 1 != 0
    }

    /// `self & !o`.
    #[inline(always)]
    pub fn and_not(self, o: Self) -> Self {
        unsafe { Self(_mm256_andnot_ps(o.0, self.0)) }
    }
}

impl Not for M32x8 {
    type Output = Self;
    #[inline(always)]
    fn not(self) -> Self {
        self ^ Self::ALL
    }
}
