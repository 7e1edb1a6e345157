//! Transcendental functions on [`F32x8`]: `exp2`, `log2` and `powf`, for the glossy lobe's
//! cosⁿ and for procedural shaders.
//!
//! They are written once, on top of the backend operations (add, multiply, fused multiply-add,
//! floor, compare, select, integer shifts), so both backends give bit-identical results. The
//! polynomials are truncated Taylor series on ranges small enough that the truncation error is
//! below f32 rounding (bounds below); the result is then within a few ulp of the exact value.

use crate::{F32x8, I32x8};

/// Taylor coefficients (ln 2)^k / k! of 2^f = e^(f ln 2), k = 7 down to 0. On |f| ≤ 1/2 the
/// first omitted term is (ln 2 / 2)^8 / 8! < 5.3e-9, relative to 2^f ≥ 0.707: < 7.4e-9.
const EXP2_TAYLOR: [f32; 8] = [
    1.525_273_4e-5,
    1.540_353e-4,
    1.333_355_8e-3,
    9.618_129e-3,
    5.550_411e-2,
    0.240_226_5,
    std::f32::consts::LN_2,
    1.0,
];

/// Coefficients 2 / (ln 2 · (2k + 1)), k = 4 down to 0, of log2(m) = s · Σ c_k s^(2k) with
/// s = (m − 1)/(m + 1) (the series of 2·atanh s). For m in [√½, √2), |s| ≤ 0.1716 and the first
/// omitted term is below 2.1e-9 relative.
const LOG2_ATANH: [f32; 5] = [0.320_598_9, 0.412_198_57, 0.577_078_04, 0.961_796_7, 2.885_39];

impl F32x8 {
    /// 2^x per lane. Relative error below 1e-6 (a few ulp); 2^x overflows to +∞ for x ≥ 128,
    /// goes subnormal below −126 and is 0 for x ≤ −150 (so `exp2(−∞) = 0`); NaN stays NaN.
    #[inline(always)]
    pub fn exp2(self) -> Self {
        // Clamp so that 2^k below is built from two in-range exponents; `max`/`min` return their
        // argument's lane for NaN, so a NaN input survives.
        let x = Self::splat(128.0).min(Self::splat(-150.0).max(self));
        // k = round(x), f = x − k in [−½, ½] (exact: k is an integer within ½ of x).
        let k = (x + Self::splat(0.5)).floor();
        let f = x - k;
        let mut p = Self::splat(EXP2_TAYLOR[0]);
        for &c in &EXP2_TAYLOR[1..] {
            p = p.mul_add(f, Self::splat(c));
        }
        // 2^k as 2^(k/2) · 2^(k − k/2): both halves lie in [−75, 64], normal floats, so the only
        // rounding is the last product (which also rounds correctly into the subnormals).
        let ki = k.to_i32();
        let k1 = ki.shr::<1>();
        let k2 = ki - k1;
        let bias = I32x8::splat(127);
        let s1 = (k1 + bias).shl::<23>().from_bits_to_f32();
        let s2 = (k2 + bias).shl::<23>().from_bits_to_f32();
        p * s1 * s2
    }

    /// log2(x) per lane. Absolute error below 1e-7 · max(1, |log2 x|) and relative error below
    /// 1e-6 (also near x = 1, where the result is small); subnormals are handled; log2(0) = −∞,
    /// log2(+∞) = +∞, negative or NaN lanes give NaN.
    #[inline(always)]
    pub fn log2(self) -> Self {
        // Scale subnormals up by 2^23 so their exponent field is meaningful.
        let subnormal = self.lt(Self::splat(f32::MIN_POSITIVE));
        let x = Self::select(subnormal, self * Self::splat(8_388_608.0), self);
        // x = 2^n · m with m in [√½, √2): subtract the bits of √½ so that the exponent field
        // carries n, then put m back into [√½, √2) by removing n from the exponent.
        let bits = x.to_bits();
        let n = (bits - I32x8::splat(0x3f35_04f3)).shr::<23>();
        let m = (bits - n.shl::<23>()).from_bits_to_f32();
        let n = n.to_f32() - Self::select(subnormal, Self::splat(23.0), Self::ZERO);
        // m − 1 is exact (Sterbenz), so s keeps full relative accuracy as m → 1.
        let s = (m - Self::splat(1.0)) / (m + Self::splat(1.0));
        let z = s * s;
        let mut q = Self::splat(LOG2_ATANH[0]);
        for &c in &LOG2_ATANH[1..] {
            q = q.mul_add(z, Self::splat(c));
        }
        let r = s.mul_add(q, n);
        // Zero, infinity, negative and NaN lanes.
        let regular = self.gt(Self::ZERO) & self.lt(Self::splat(f32::INFINITY));
        let special = Self::select(
            self.eq(Self::ZERO),
            Self::splat(f32::NEG_INFINITY),
            Self::select(self.eq(Self::splat(f32::INFINITY)), self, Self::splat(f32::NAN)),
        );
        Self::select(regular, r, special)
    }

    /// x^e per lane for x ≥ 0, as 2^(e · log2 x): `powf(x, 0) = 1` (also for x = 0), and
    /// `powf(0, e > 0) = 0`. The relative error is about 1e-6 plus the f32 rounding of
    /// y = e · log2 x amplified by ln 2 · |y| · 2^−24, i.e. below 2e-6 for results in
    /// [2^−16, 2^16] (|y| ≤ 16), which covers every Phong lobe value that matters; for larger |y|
    /// it grows as 4.2e-8 · |y|. Negative x gives NaN.
    #[inline(always)]
    pub fn powf(self, e: Self) -> Self {
        let r = (e * self.log2()).exp2();
        Self::select(e.eq(Self::ZERO), Self::splat(1.0), r)
    }
}
