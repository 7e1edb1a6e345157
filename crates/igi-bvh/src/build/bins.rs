//! Centroid binning and the binned SAH split search of Wald 2007, "On fast Construction of
//! SAH-based Bounding Volume Hierarchies", section 3.
//!
//! A node's primitives are sorted by centroid into K equally wide bins per axis over the node's
//! centroid bounds; each bin keeps the union of its primitives' boxes and their number. The K - 1
//! planes between bins are the split candidates, evaluated in two sweeps over the bins.
//! Bins merge exactly (min, max and integer sums are associative and commutative), so binning
//! chunks of a node in parallel gives the same bins, bit for bit, as binning it in one go.

use glam::Vec3A;

use super::box3a::Box3A;

/// The largest supported number of bins per axis.
pub(crate) const MAX_BINS: usize = 32;

/// Maps a centroid to its bin on each axis (Wald 2007, section 3.1):
/// `bin = ⌊K (1 - ε) (c - c_min) / (c_max - c_min)⌋` over the node's centroid bounds.
#[derive(Clone, Copy, Debug)]
pub(crate) struct BinMapping {
    origin: Vec3A,
    scale: Vec3A,
    count: usize,
}

impl BinMapping {
    /// The mapping of `count` bins (2 ..= [`MAX_BINS`]) over `centroid_bounds`. An axis on which
    /// all centroids coincide maps everything to bin 0, so it offers no split.
    pub fn new(centroid_bounds: &Box3A, count: usize) -> Self {
        debug_assert!((2..=MAX_BINS).contains(&count));
        let extent = centroid_bounds.max - centroid_bounds.min;
        // The factor 1 - ε keeps the largest centroid in bin K - 1 rather than K.
        let k = count as f32 * (1.0 - 1e-6);
        let scale = Vec3A::select(extent.cmpgt(Vec3A::ZERO), k / extent, Vec3A::ZERO);
        Self { origin: centroid_bounds.min, scale, count }
    }

    /// Number of bins per axis.
    #[inline(always)]
    pub fn count(&self) -> usize {
        self.count
    }

    /// The bin of centroid `c` on each axis. Binning and partitioning both go through this one
    /// computation, so they agree exactly on which side of a split plane a primitive lies.
    #[inline(always)]
    pub fn bins_of(&self, c: Vec3A) -> [usize; 3] {
        let b = (c - self.origin) * self.scale;
        let last = self.count - 1;
        // `as` saturates: NaN (0 · ∞ on a degenerate axis) becomes 0, +∞ becomes usize::MAX.
        [(b.x as usize).min(last), (b.y as usize).min(last), (b.z as usize).min(last)]
    }

    /// The bin of centroid `c` on one axis; the same value as `bins_of(c)[axis]`.
    #[inline(always)]
    pub fn bin_of(&self, c: Vec3A, axis: usize) -> usize {
        let b = (c - self.origin) * self.scale;
        (b[axis] as usize).min(self.count - 1)
    }
}

/// The best split plane found by [`Bins::best_split`].
#[derive(Clone, Copy, Debug)]
pub(crate) struct BinSplit {
    /// Split axis (0 = x, 1 = y, 2 = z).
    pub axis: usize,
    /// First bin of the right side: primitives in bins `< bin` go left.
    pub bin: usize,
    /// `A(L) N(L) + A(R) N(R)` with half areas, the variable part of the split's SAH cost.
    pub area_count_sum: f32,
    /// Bounds of the left side's primitives.
    pub left: Box3A,
    /// Bounds of the right side's primitives.
    pub right: Box3A,
    /// Number of primitives going left.
    pub left_count: usize,
}

/// Per-axis bins: the union of the boxes and the number of the primitives in each bin.
#[derive(Clone, Debug)]
pub(crate) struct Bins {
    boxes: [[Box3A; MAX_BINS]; 3],
    counts: [[u32; MAX_BINS]; 3],
}

impl Bins {
    /// Empty bins.
    pub fn new() -> Self {
        Self { boxes: [[Box3A::EMPTY; MAX_BINS]; 3], counts: [[0; MAX_BINS]; 3] }
    }

    /// Adds primitives, given by their boxes, to the bins of their centroids.
    pub fn add(&mut self, prims: &[Box3A], mapping: &BinMapping) {
        for p in prims {
            let bins = mapping.bins_of(p.centroid());
            for (axis, &bin) in bins.iter().enumerate() {
                self.boxes[axis][bin] = self.boxes[axis][bin].union(*p);
                self.counts[axis][bin] += 1;
            }
        }
    }

    /// The bins of two disjoint sets of primitives combined.
    pub fn merge(mut self, other: &Self) -> Self {
        for axis in 0..3 {
            for bin in 0..MAX_BINS {
                self.boxes[axis][bin] = self.boxes[axis][bin].union(other.boxes[axis][bin]);
                self.counts[axis][bin] += other.counts[axis][bin];
            }
        }
        self
    }

    /// The split plane between bins with the lowest `A(L) N(L) + A(R) N(R)` over all axes, or
    /// `None` if every axis has all primitives in one bin (then all centroids coincide).
    /// Ties go to the lowest axis, then the leftmost plane.
    pub fn best_split(&self, bin_count: usize) -> Option<BinSplit> {
        let mut best: Option<BinSplit> = None;
        for axis in 0..3 {
            let boxes = &self.boxes[axis][..bin_count];
            let counts = &self.counts[axis][..bin_count];
            let total: u32 = counts.iter().sum();

            // Sweep right to left: area times count of the bins [i, K) for every plane i.
            let mut right_cost = [0.0f32; MAX_BINS];
            let (mut right, mut right_count) = (Box3A::EMPTY, 0u32);
            for i in (1..bin_count).rev() {
                right = right.union(boxes[i]);
                right_count += counts[i];
                if right_count > 0 {
                    right_cost[i] = right.half_area() * right_count as f32;
                }
            }

            // Sweep left to right, completing the cost of each plane with both sides non-empty.
            let (mut left, mut left_count) = (Box3A::EMPTY, 0u32);
            for i in 1..bin_count {
                left = left.union(boxes[i - 1]);
                left_count += counts[i - 1];
                if left_count == 0 {
                    continue;
                }
                if left_count == total {
                    break;
                }
                let cost = left.half_area() * left_count as f32 + right_cost[i];
                if best.is_none_or(|b| cost < b.area_count_sum) {
                    best = Some(BinSplit {
                        axis,
                        bin: i,
                        area_count_sum: cost,
                        left: Box3A::EMPTY,
                        right: Box3A::EMPTY,
                        left_count: left_count as usize,
                    });
                }
            }
        }
        best.map(|mut split| {
            let (l, r) = self.boxes[split.axis][..bin_count].split_at(split.bin);
            split.left = Box3A::union_of(l);
            split.right = Box3A::union_of(r);
            split
        })
    }
}
