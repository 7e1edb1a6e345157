//! In-place reordering of a node's primitives for the binned builder. A node's primitives are
//! a range of two parallel arrays, boxes and input indices, which move in lockstep.

use std::cmp::Ordering;

use super::bins::BinMapping;
use super::box3a::Box3A;
use super::prim_box::PrimBox;

/// Moves the primitives in a bin below `bin` on `axis` to the front. Returns their number and
/// the centroid bounds of both sides.
pub(crate) fn partition_at_plane(
    boxes: &mut [PrimBox],
    ids: &mut [u32],
    mapping: &BinMapping,
    axis: usize,
    bin: usize,
) -> (usize, Box3A, Box3A) {
    // One instance per axis, so that picking the axis's bin is not a run-time index.
    match axis {
        0 => partition(boxes, ids, |b| mapping.bin_of::<0>(b) < bin),
        1 => partition(boxes, ids, |b| mapping.bin_of::<1>(b) < bin),
        2 => partition(boxes, ids, |b| mapping.bin_of::<2>(b) < bin),
        _ => partition(boxes, ids, |b| mapping.bin_of::<3>(b) < bin),
    }
}

/// Moves the primitives for which `goes_left` holds to the front (Hoare's scheme: swap pairs
/// that are on the wrong sides). Returns their number and the centroid bounds of both sides.
#[inline(always)]
fn partition(
    boxes: &mut [PrimBox],
    ids: &mut [u32],
    goes_left: impl Fn(&PrimBox) -> bool,
) -> (usize, Box3A, Box3A) {
    let (mut left_centroids, mut right_centroids) = (Box3A::EMPTY, Box3A::EMPTY);
    let (mut i, mut j) = (0, boxes.len());
    loop {
        while i < j && goes_left(&boxes[i]) {
            left_centroids = left_centroids.grow(boxes[i].centroid());
            i += 1;
        }
        while i < j && !goes_left(&boxes[j - 1]) {
            right_centroids = right_centroids.grow(boxes[j - 1].centroid());
            j -= 1;
        }
        if i == j {
            return (i, left_centroids, right_centroids);
        }
        boxes.swap(i, j - 1);
        ids.swap(i, j - 1);
    }
}

/// Reorders the primitives so that the `len / 2` with the smallest centroids on `axis` come
/// first (quickselect with a median-of-three pivot and three-way partitioning, so that equal
/// centroids cost one pass). Returns `len / 2`.
pub(crate) fn partition_at_median(boxes: &mut [PrimBox], ids: &mut [u32], axis: usize) -> usize {
    let key = |b: &PrimBox| b.centroid()[axis];
    let median = boxes.len() / 2;
    let (mut lo, mut hi) = (0, boxes.len());
    while hi - lo > 1 {
        let pivot = {
            let (a, b, c) = (key(&boxes[lo]), key(&boxes[lo + (hi - lo) / 2]), key(&boxes[hi - 1]));
            let (lower, upper) = if a.total_cmp(&b).is_le() { (a, b) } else { (b, a) };
            if c.total_cmp(&lower).is_le() {
                lower
            } else if c.total_cmp(&upper).is_ge() {
                upper
            } else {
                c
            }
        };
        // Dutch national flag: [lo, less) < pivot, [less, i) == pivot, [greater, hi) > pivot.
        let (mut less, mut i, mut greater) = (lo, lo, hi);
        while i < greater {
            match key(&boxes[i]).total_cmp(&pivot) {
                Ordering::Less => {
                    boxes.swap(less, i);
                    ids.swap(less, i);
                    less += 1;
                    i += 1;
                }
                Ordering::Equal => i += 1,
                Ordering::Greater => {
                    greater -= 1;
                    boxes.swap(i, greater);
                    ids.swap(i, greater);
                }
            }
        }
        if median < less {
            hi = less;
        } else if median >= greater {
            lo = greater;
        } else {
            break;
        }
    }
    median
}
