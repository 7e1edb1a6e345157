//! Every operation against the scalar operation it stands for, lane by lane, on values that
//! include zeros, negative zero, infinities and NaN. The same tests run on both backends.

use crate::{F32x8, I32x8, LaneMask, Lanes, M32x8, Vec3x8};

const A: [f32; 8] = [1.5, -2.25, 0.0, -0.0, 1e30, -1e-30, f32::INFINITY, 7.0];
const B: [f32; 8] = [0.5, -2.25, 3.0, 0.0, -1e30, 2.0, 1.0, f32::NAN];

fn same(a: f32, b: f32) -> bool {
    a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
}

#[test]
fn arithmetic_equals_scalar() {
    let (a, b) = (F32x8::from_array(A), F32x8::from_array(B));
    for i in 0..8 {
        assert!(same((a + b).lane(i), A[i] + B[i]));
        assert!(same((a - b).lane(i), A[i] - B[i]));
        assert!(same((a * b).lane(i), A[i] * B[i]));
        assert!(same((a / b).lane(i), A[i] / B[i]));
        assert!(same((-a).lane(i), -A[i]));
        assert!(same(a.abs().lane(i), A[i].abs()));
        assert!(same(a.abs().sqrt().lane(i), A[i].abs().sqrt()));
        assert!(same(a.floor().lane(i), A[i].floor()));
    }
}

#[test]
fn mul_add_is_fused_like_scalar() {
    // (1 + 2^-12)^2 - (1 + 2^-11) is exactly 2^-24 when fused and 0 when the square is rounded
    // first.
    let e = 1.0 + 2f32.powi(-12);
    let x = F32x8::from_array([e, 2.0, 3.0, -4.0, 0.5, 0.25, 1e3, -1e-3]);
    let c = F32x8::from_array([-(1.0 + 2f32.powi(-11)), 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0]);
    let r = x.mul_add(x, c).to_array();
    for (i, v) in x.to_array().iter().enumerate() {
        assert!(same(r[i], v.mul_add(*v, c.lane(i))), "lane {i}");
    }
    assert_eq!(r[0], 2f32.powi(-24), "the first lane must show the single rounding");
}

#[test]
fn min_max_follow_minps_nan_rule() {
    let (a, b) = (F32x8::from_array(A), F32x8::from_array(B));
    for i in 0..8 {
        let lo = if A[i] < B[i] { A[i] } else { B[i] };
        let hi = if A[i] > B[i] { A[i] } else { B[i] };
        assert!(same(a.min(b).lane(i), lo), "min lane {i}");
        assert!(same(a.max(b).lane(i), hi), "max lane {i}");
    }
}

#[test]
fn comparisons_and_masks() {
    let (a, b) = (F32x8::from_array(A), F32x8::from_array(B));
    for i in 0..8 {
        assert_eq!(a.lt(b).lane(i), A[i] < B[i]);
        assert_eq!(a.le(b).lane(i), A[i] <= B[i]);
        assert_eq!(a.gt(b).lane(i), A[i] > B[i]);
        assert_eq!(a.ge(b).lane(i), A[i] >= B[i]);
        assert_eq!(a.eq(b).lane(i), A[i] == B[i]);
    }
    let m = a.lt(b);
    let bits = (0..8).fold(0, |acc, i| acc | ((A[i] < B[i]) as u32) << i);
    assert_eq!(m.bitmask(), bits);
    assert_eq!(M32x8::from_bitmask(bits).bitmask(), bits);
    assert!(M32x8::ALL.bitmask() == 0xff && M32x8::ALL.any() && M32x8::NONE.none());
    assert_eq!((m & !m).bitmask(), 0);
    assert_eq!((m | !m).bitmask(), 0xff);
    assert_eq!(m.and_not(m).bitmask(), 0);
    assert_eq!((m ^ M32x8::ALL).bitmask(), !bits & 0xff);
    let sel = F32x8::select(m, a, b);
    for i in 0..8 {
        assert!(same(sel.lane(i), if A[i] < B[i] { A[i] } else { B[i] }));
    }
}

#[test]
fn reductions() {
    let v = F32x8::from_array([3.0, -1.0, 8.0, 2.0, -7.5, 0.0, 4.0, 1.0]);
    assert_eq!(v.reduce_min(), -7.5);
    assert_eq!(v.reduce_max(), 8.0);
    let with_nan = F32x8::from_array([f32::NAN, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0]);
    assert!(with_nan.reduce_min().is_finite() || with_nan.reduce_min().is_nan());
}

#[test]
fn integers() {
    let a = I32x8::from_array([1, -2, 3, i32::MAX, 0, 5, -7, 8]);
    let b = I32x8::splat(3);
    let (sa, sb) = (a.to_array(), b.to_array());
    for i in 0..8 {
        assert_eq!((a + b).lane(i), sa[i].wrapping_add(sb[i]));
        assert_eq!((a - b).lane(i), sa[i].wrapping_sub(sb[i]));
        assert_eq!((a * b).lane(i), sa[i].wrapping_mul(sb[i]));
        assert_eq!((a & b).lane(i), sa[i] & sb[i]);
        assert_eq!((a | b).lane(i), sa[i] | sb[i]);
        assert_eq!((a ^ b).lane(i), sa[i] ^ sb[i]);
        assert_eq!(a.eq(b).lane(i), sa[i] == sb[i]);
        assert_eq!(a.gt(b).lane(i), sa[i] > sb[i]);
        assert_eq!(a.lt(b).lane(i), sa[i] < sb[i]);
        assert_eq!(a.to_f32().lane(i), sa[i] as f32);
    }
    let f = F32x8::from_array([1.9, -1.9, 0.5, 1e10, -3.0, 2.5, 7.99, 0.0]);
    assert_eq!(f.to_i32().to_array(), [1, -1, 0, i32::MIN, -3, 2, 7, 0]);
    assert_eq!(f.to_bits().from_bits_to_f32().to_array(), f.to_array());
    let m = a.gt(b);
    assert_eq!(I32x8::select(m, a, b).to_array()[3], i32::MAX);
}

#[test]
fn xor_sign_flips_where_negative() {
    let v = F32x8::splat(2.0).xor_sign(F32x8::from_array(A));
    for (i, s) in A.iter().enumerate() {
        assert_eq!(v.lane(i), if s.is_sign_negative() { -2.0 } else { 2.0 });
    }
}

#[test]
fn vec3_ops() {
    let a = Vec3x8::splat([1.0, 2.0, 3.0]);
    let b = Vec3x8::from_lanes([[0.0, 1.0, 0.0]; 8]);
    assert_eq!(a.dot(b).to_array(), [2.0; 8]);
    assert_eq!(a.cross(b).lane(5), [-3.0, 0.0, 1.0]);
    let n = Vec3x8::splat([3.0, 0.0, 4.0]).normalize();
    assert_eq!(n.lane(0), [0.6, 0.0, 0.8]);
    assert_eq!((a - b + a).lane(2), [2.0, 3.0, 6.0]);
    assert_eq!((a * F32x8::splat(2.0)).lane(7), [2.0, 4.0, 6.0]);
}

#[test]
fn shifts_gather_and_lookup() {
    let a = I32x8::from_array([1, -2, 3, i32::MAX, 0, -1, i32::MIN, 8]);
    for (i, v) in a.to_array().iter().enumerate() {
        assert_eq!(a.shl::<3>().lane(i), v << 3);
        assert_eq!(a.shr::<3>().lane(i), v >> 3, "arithmetic shift");
    }
    let table: [i32; 16] = std::array::from_fn(|i| (i * i) as i32 - 7);
    let idx = I32x8::from_array([0, 15, 16, 17, -1, -16, 255, 7]);
    let g = I32x8::gather(&table, idx);
    for (i, v) in idx.to_array().iter().enumerate() {
        assert_eq!(g.lane(i), table[(v & 15) as usize]);
    }
    let ftable: [f32; 16] = std::array::from_fn(|i| i as f32 * 1.5 - 4.0);
    let l = F32x8::lookup16(&ftable, idx);
    for (i, v) in idx.to_array().iter().enumerate() {
        assert_eq!(l.lane(i), ftable[(v & 15) as usize]);
    }
}

/// Every lane-wise [`Lanes`] operation, written once over the trait: float results and integer
/// results.
fn lanes_kernel<L: Lanes>(a: L, b: L, idx: L::Int) -> ([L; 9], [L::Int; 2]) {
    let perm: [i32; 256] = std::array::from_fn(|k| (k * 97 % 256) as i32);
    let grad: [f32; 16] = std::array::from_fn(|k| k as f32 * 1.5 - 4.0);
    let floats = [
        a.mul_add(b, a),
        a.floor(),
        a.xor_sign(b),
        L::select(a.lt(b) | a.eq(b), a, b),
        L::select(a.gt(b) & !a.ge(b), a, L::splat(2.0)),
        L::select(a.le(b), b, L::splat(-0.0)),
        L::recompute(a.lt(b), [a], [a, b], |[x, y]| [x * 4.0 - y])[0],
        L::recompute(a.gt(b), [a, b], [b, a], |[x, y]| [x - y, x * y])[1],
        L::lookup16(&grad, idx),
    ];
    (floats, [a.to_i32(), L::gather(&perm, idx + L::splat_i32(3))])
}

#[test]
fn lanes_of_f32x8_equal_lanes_of_f32() {
    let idx = [0, 15, 16, 17, -1, -16, 255, 7];
    let c = [1.9, -1.9, 0.5, 1e10, -3.0, 2.5, 7.99, 0.0];
    for (a, b) in [(A, B), (B, A), (c, A)] {
        let (floats, ints) = lanes_kernel(F32x8::from_array(a), F32x8::from_array(b), I32x8::from_array(idx));
        for l in 0..8 {
            let (f, n) = lanes_kernel(a[l], b[l], idx[l]);
            for k in 0..f.len() {
                assert!(same(floats[k].lane(l), f[k]), "operation {k}, lane {l}: {a:?} {b:?}");
            }
            for k in 0..n.len() {
                assert_eq!(ints[k].lane(l), n[k], "integer operation {k}, lane {l}: {a:?}");
            }
        }
    }
    let m = F32x8::from_array(A).lt(F32x8::from_array(B));
    assert_eq!((LaneMask::any(m), m.count()), (true, m.bitmask().count_ones()));
    assert_eq!((LaneMask::any(M32x8::NONE), M32x8::NONE.count()), (false, 0));
    assert_eq!((true.any(), true.count(), false.any(), false.count()), (true, 1, false, 0));
    assert_eq!((<M32x8 as LaneMask>::ALL.count(), <bool as LaneMask>::ALL.count()), (8, 1));
    let v = F32x8::from_array(c);
    assert_eq!((Lanes::reduce_min(v), Lanes::reduce_max(v)), (-3.0, 1e10));
    assert_eq!((Lanes::reduce_min(2.5f32), Lanes::reduce_max(2.5f32)), (2.5, 2.5));
}

/// Relative error of `got` against the f64 reference `want`.
fn rel(got: f32, want: f64) -> f64 {
    if want == 0.0 { got.abs() as f64 } else { ((got as f64 - want) / want).abs() }
}

#[test]
fn exp2_accuracy_sweep() {
    let mut worst: f64 = 0.0;
    for i in 0..=200_000 {
        let x = -126.0 + 253.9 * i as f32 / 200_000.0;
        let got = F32x8::splat(x).exp2().lane(0);
        worst = worst.max(rel(got, (x as f64).exp2()));
    }
    assert!(worst < 1e-6, "exp2 relative error {worst}");
    let special = F32x8::from_array([0.0, 1.0, -1.0, 10.0, 128.0, f32::NEG_INFINITY, -149.0, f32::NAN]);
    let r = special.exp2().to_array();
    assert_eq!(&r[..4], &[1.0, 2.0, 0.5, 1024.0]);
    assert_eq!(r[4], f32::INFINITY);
    assert_eq!(r[5], 0.0);
    assert_eq!(r[6], f32::from_bits(1), "2^-149 is the smallest subnormal");
    assert!(r[7].is_nan());
}

#[test]
fn log2_accuracy_sweep() {
    let mut worst: f64 = 0.0;
    // Geometric sweep over all normal floats, plus a dense sweep around 1 where log2 → 0.
    let mut x = f32::MIN_POSITIVE;
    while x < f32::MAX / 1.001 {
        let got = F32x8::splat(x).log2().lane(0);
        worst = worst.max(rel(got, (x as f64).log2()));
        x *= 1.000_37;
    }
    for i in 1..100_000 {
        let x = 0.9 + 0.2 * i as f32 / 100_000.0;
        if x != 1.0 {
            worst = worst.max(rel(F32x8::splat(x).log2().lane(0), (x as f64).log2()));
        }
    }
    assert!(worst < 1e-6, "log2 relative error {worst}");
    let special = F32x8::from_array([1.0, 2.0, 0.5, 0.0, f32::INFINITY, -1.0, f32::NAN, 1e-40]);
    let r = special.log2().to_array();
    assert_eq!(&r[..3], &[0.0, 1.0, -1.0]);
    assert_eq!(r[3], f32::NEG_INFINITY);
    assert_eq!(r[4], f32::INFINITY);
    assert!(r[5].is_nan() && r[6].is_nan());
    assert!(rel(r[7], (1e-40f32 as f64).log2()) < 1e-6, "subnormal");
}

#[test]
fn powf_accuracy_sweep() {
    let mut worst: f64 = 0.0;
    for i in 1..=2000 {
        let x = i as f32 / 2000.0 * 1.5;
        for e in [0.5f32, 1.0, 2.0, 3.7, 10.0, 60.0, 250.0, 1000.0, 5000.0] {
            let want = (x as f64).powf(e as f64);
            // The documented range: results in [2^-16, 2^16].
            if !(2f64.powi(-16)..=2f64.powi(16)).contains(&want) {
                continue;
            }
            let got = F32x8::splat(x).powf(F32x8::splat(e)).lane(0);
            worst = worst.max(rel(got, want));
            assert!(rel(got, x.powf(e) as f64) < 3e-6, "{x}^{e}");
        }
    }
    assert!(worst < 2e-6, "powf relative error {worst}");
    let x = F32x8::from_array([0.0, 0.0, 0.3, 1.0, 0.0, 2.0, 0.7, 4.0]);
    let e = F32x8::from_array([2.0, 0.0, 0.0, 7.0, 1e-3, 10.0, 1.0, 0.5]);
    let r = x.powf(e).to_array();
    assert_eq!(&r[..4], &[0.0, 1.0, 1.0, 1.0]);
    assert_eq!(r[4], 0.0);
    assert!(rel(r[5], 1024.0) < 1e-6 && rel(r[6], 0.7) < 1e-6 && rel(r[7], 2.0) < 1e-6);
}

#[test]
fn transpose_turns_records_into_fields() {
    let records: [[f32; 8]; 8] = std::array::from_fn(|k| std::array::from_fn(|j| (10 * k + j) as f32));
    let fields = F32x8::transpose(std::array::from_fn(|k| &records[k]));
    for (j, field) in fields.iter().enumerate() {
        assert_eq!(field.to_array(), std::array::from_fn(|k| records[k][j]), "field {j}");
    }
}
