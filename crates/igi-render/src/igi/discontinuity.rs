//! The discontinuity buffer (paper 2.1, Keller & Heidrich 2001, Wald et al. 2002): each pixel
//! was lit by one of the n·m VPL sets only, so the light it receives carries that set's
//! structured noise. Averaging it over the n×m window around the pixel combines all sets, but
//! only across neighbours that see a similar surface: the same material, normals within a
//! cosine threshold and distances along the camera path within a relative threshold. Edges,
//! creases and depth steps stay sharp, and the filtered quantities are D = E/π and the glossy
//! terms G and S before the albedo and the glossy reflectance multiply them back in, so texture
//! detail stays sharp too.
//!
//! Shading points are matched by (sample index, camera path): sample j of a pixel is filtered
//! with sample j of its neighbours, and a point seen through a mirror or glass with the point
//! seen through the same chain of reflections and refractions. A point that stands for all
//! samples of its pixel (they saw one surface) counts as every sample's neighbour. A pixel
//! without a similar neighbour keeps its own value, so a constant irradiance stays constant.

use crate::frame::FilterSettings;
use crate::igi::interleave::{Interleave, Window};
use crate::image::pixel_rect::PixelRect;
use crate::image::tile::Tile;
use glam::Vec3;

/// A shading point as the filter sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FilterSample {
    /// Row-major pixel index in the region.
    pub pixel: u32,
    /// Anti-aliasing sample index within the pixel.
    pub sample: u32,
    /// The point stands for every sample of its pixel (they all saw one surface), so each
    /// sample's neighbours are filtered with it.
    pub whole_pixel: bool,
    /// Code of the specular chain that led to the point (1 for the camera ray's own hit).
    pub path: u32,
    /// Unit shading normal, on the side facing the camera path.
    pub normal: Vec3,
    /// Distance from the camera along the path.
    pub depth: f32,
    /// Material index.
    pub material: u32,
    /// D = E/π before filtering: the radiance a white Lambertian surface at the point
    /// reflects, so that ρ_d·D is the diffuse term (see [`crate::igi::vpl_lighting`]).
    pub diffuse_radiance: Vec3,
}

/// The filter's output: D, and G and S, per point.
#[derive(Clone, Debug, Default)]
pub struct Filtered {
    /// Filtered D = E/π per point (see [`FilterSample::diffuse_radiance`]).
    pub diffuse_radiance: Vec<Vec3>,
    /// Filtered G and S per point: the radiance a glossy lobe of unit reflectance at the point
    /// reflects, so that ρ_s·G is the glossy term, and a GGX lobe's Schlick radiance (see
    /// [`crate::igi::vpl_lighting`]; empty if the tile has no glossy point).
    pub glossy_radiance: Vec<[Vec3; 2]>,
}

/// What the filter reads of a shading point, stored in a pixel grid per camera path so that
/// the neighbours of a pixel lie next to each other in memory.
#[derive(Clone, Copy, Debug)]
struct Cell {
    normal: Vec3,
    depth: f32,
    diffuse_radiance: Vec3,
    /// Material index; [`EMPTY`] if the layer has no point at this pixel; for a pixel whose
    /// samples have points of their own, [`EDGE`] plus the slot of its N cells in
    /// [`DiscontinuityBuffer::edge_cells`].
    material: u32,
}

/// No shading point at this pixel in this layer.
const EMPTY: u32 = u32::MAX;

/// Marks a cell whose pixel has a point per sample (the low bits hold the slot of its cells).
const EDGE: u32 = 1 << 31;

const EMPTY_CELL: Cell =
    Cell { normal: Vec3::ZERO, depth: 0.0, diffuse_radiance: Vec3::ZERO, material: EMPTY };

/// Scratch space of the filter, reused across tiles: one pixel grid per camera path (layer)
/// holding the whole pixels' points, and beside it the cells of the pixels that have a point
/// per sample, N per pixel.
#[derive(Clone, Debug, Default)]
pub struct DiscontinuityBuffer {
    /// Camera path of each layer.
    paths: Vec<u32>,
    grids: Vec<Vec<Cell>>,
    /// The glossy terms G and S per layer, beside the grids (filled only for tiles with a
    /// glossy point, which keeps the cells small for the rest).
    glossy_grids: Vec<Vec<[Vec3; 2]>>,
    /// The cells of pixels with a point per sample, N per slot, and their G and S.
    edge_cells: Vec<Cell>,
    edge_glossy: Vec<[Vec3; 2]>,
    /// Layer of each point.
    layers: Vec<u32>,
}

/// One level of the filter: the window of taps around a pixel, the distance between taps, and
/// how the taps are weighted.
#[derive(Clone, Copy, Debug)]
struct Level {
    window: Window,
    stride: (u32, u32),
    /// The coarse level's tent ([`Interleave::coarse_weight`]), else every tap weighs one.
    tent: Option<Interleave>,
}

impl DiscontinuityBuffer {
    /// Filters D, G and S of the points of `tile`: `out.diffuse_radiance[i]` becomes the filtered
    /// D of `points[i]` for points inside the tile (points in the apron get other values), and
    /// likewise `out.glossy_radiance[i]` the filtered G and S of `glossy_in[i]` (the same
    /// weights; `glossy_in` is empty where no point has a glossy lobe, and then so is
    /// `out.glossy_radiance`).
    ///
    /// With a coarse level ([`Interleave::coarse`] above 1) the first level filters every point
    /// the second level reads, the tile grown by the coarse window at stride (n, m); its results
    /// replace the points' values, and the second level averages them over the coarse window's
    /// taps with the same similarity test, weighted by the tent of
    /// [`Interleave::coarse_weight`], as the à-trous wavelet filter does one scale up
    /// (Dammertz et al. 2010).
    /// `points` must cover `region`, the tile plus the apron of [`Interleave::region`].
    pub fn filter(
        &mut self,
        region: &PixelRect,
        tile: &Tile,
        interleave: &Interleave,
        settings: &FilterSettings,
        (points, glossy_in): (&[FilterSample], &[[Vec3; 2]]),
        out: &mut Filtered,
    ) {
        self.index(region, interleave.aa as usize, points, glossy_in);
        out.diffuse_radiance.clear();
        out.diffuse_radiance.extend(points.iter().map(|p| p.diffuse_radiance));
        out.glossy_radiance.clear();
        out.glossy_radiance.extend_from_slice(glossy_in);
        let fine = Level { window: interleave.window(), stride: (1, 1), tent: None };
        if interleave.coarse == 1 {
            self.level(region, &tile.rect, fine, settings, points, interleave.aa, out);
            return;
        }
        let coarse = Level {
            window: interleave.coarse_window(),
            stride: (interleave.n, interleave.m),
            tent: Some(*interleave),
        };
        let ([l, r], [u, d]) = coarse.window;
        let read = PixelRect {
            x0: tile.rect.x0.saturating_sub(l * interleave.n).max(region.x0),
            y0: tile.rect.y0.saturating_sub(u * interleave.m).max(region.y0),
            x1: (tile.rect.x1 + r * interleave.n).min(region.x1),
            y1: (tile.rect.y1 + d * interleave.m).min(region.y1),
        };
        self.level(region, &read, fine, settings, points, interleave.aa, out);
        self.store(region, &read, interleave.aa as usize, points, out);
        self.level(region, &tile.rect, coarse, settings, points, interleave.aa, out);
    }

    /// One filter level: for each point inside `rect`, the weighted mean of the values in the
    /// cells of `level`'s taps around its pixel (inside `region`) whose points are [`similar`]
    /// to it.
    #[allow(clippy::too_many_arguments)]
    fn level(
        &self,
        region: &PixelRect,
        rect: &PixelRect,
        level: Level,
        settings: &FilterSettings,
        points: &[FilterSample],
        aa: u32,
        out: &mut Filtered,
    ) {
        let glossy = !out.glossy_radiance.is_empty();
        let aa = aa as usize;
        let (([left, right], [up, down]), (sx, sy)) = (level.window, level.stride);
        // The weights of the taps along each axis, from the first tap before the centre to the
        // last after it, looked up: computing the tent per tap (two divisions, and two more for
        // the tap numbers) was a fifth of the filter's time. Their product is `coarse_weight`'s,
        // so the bits are the same.
        let weights = |before: u32, after: u32| -> Vec<f32> {
            (0..=before + after)
                .map(|t| level.tent.map_or(1.0, |il| il.coarse_tent(before.abs_diff(t))))
                .collect()
        };
        let (wx, wy) = (weights(left, right), weights(up, down));
        let width = region.width() as usize;
        let (sx, sy) = (sx as usize, sy as usize);
        for (i, p) in points.iter().enumerate() {
            let (x, y) = region.pixel(p.pixel);
            if !rect.contains(x, y) {
                continue;
            }
            let grid = &self.grids[self.layers[i] as usize];
            let glossy_grid = &self.glossy_grids[self.layers[i] as usize];
            // The taps at stride (sx, sy) that lie in the region, as tap numbers from the centre.
            let (tx0, tx1) =
                (left.min((x - region.x0) / sx as u32), right.min((region.x1 - 1 - x) / sx as u32));
            let (ty0, ty1) = (up.min((y - region.y0) / sy as u32), down.min((region.y1 - 1 - y) / sy as u32));
            let centre = p.pixel as usize;
            let first = centre - ty0 as usize * sy * width - tx0 as usize * sx;
            let (wx, wy) = (&wx[(left - tx0) as usize..], &wy[(up - ty0) as usize..]);
            let mut sum = [Vec3::ZERO; 3];
            let mut count = 0.0f32;
            for (ty, &w_y) in wy.iter().enumerate().take((ty0 + ty1 + 1) as usize) {
                let row = first + ty * sy * width;
                for (tx, &w_x) in wx.iter().enumerate().take((tx0 + tx1 + 1) as usize) {
                    let w = w_x * w_y;
                    let index = row + tx * sx;
                    let cell = &grid[index];
                    // A neighbour with a point per sample shows this point's sample.
                    let (q, edge) = match cell.material {
                        m if m != EMPTY && m & EDGE != 0 => {
                            let at = (m & !EDGE) as usize * aa + p.sample as usize;
                            (&self.edge_cells[at], Some(at))
                        }
                        _ => (cell, None),
                    };
                    // The centre always counts (a normal's dot product with itself can round
                    // below a threshold of 1), so count > 0.
                    if index == centre || similar(p, q, settings) {
                        sum[0] += w * q.diffuse_radiance;
                        if glossy {
                            let [g, s] = edge.map_or(glossy_grid[index], |at| self.edge_glossy[at]);
                            sum[1] += w * g;
                            sum[2] += w * s;
                        }
                        count += w;
                    }
                }
            }
            out.diffuse_radiance[i] = sum[0] / count;
            if glossy {
                out.glossy_radiance[i] = [sum[1] / count, sum[2] / count];
            }
        }
    }

    /// Replaces the values in the cells of the points inside `rect` by `values` (the first
    /// level's results, which the second level reads).
    fn store(
        &mut self,
        region: &PixelRect,
        rect: &PixelRect,
        aa: usize,
        points: &[FilterSample],
        values: &Filtered,
    ) {
        let glossy = !values.glossy_radiance.is_empty();
        for (i, p) in points.iter().enumerate() {
            let (x, y) = region.pixel(p.pixel);
            if !rect.contains(x, y) {
                continue;
            }
            let layer = self.layers[i] as usize;
            let d = values.diffuse_radiance[i];
            if p.whole_pixel {
                self.grids[layer][p.pixel as usize].diffuse_radiance = d;
                if glossy {
                    self.glossy_grids[layer][p.pixel as usize] = values.glossy_radiance[i];
                }
            } else {
                // The pixel's slot of N cells ([`DiscontinuityBuffer::index`]).
                let slot = self.grids[layer][p.pixel as usize].material & !EDGE;
                let at = slot as usize * aa + p.sample as usize;
                self.edge_cells[at].diffuse_radiance = d;
                if glossy {
                    self.edge_glossy[at] = values.glossy_radiance[i];
                }
            }
        }
    }

    /// Builds one pixel grid per camera path holding the points: a whole pixel's point in its
    /// cell, a sample's own point in its pixel's slot of N edge cells.
    fn index(&mut self, region: &PixelRect, aa: usize, points: &[FilterSample], glossy: &[[Vec3; 2]]) {
        self.paths.clear();
        self.layers.clear();
        self.edge_cells.clear();
        self.edge_glossy.clear();
        let mut last: Option<(u32, u32)> = None;
        for (i, p) in points.iter().enumerate() {
            // Points come in runs of one path: look it up only when it changes.
            let layer = match last {
                Some((path, layer)) if path == p.path => layer,
                _ => self.layer(p.path, region, !glossy.is_empty()),
            };
            last = Some((p.path, layer));
            self.layers.push(layer);
            let cell = Cell {
                normal: p.normal,
                depth: p.depth,
                diffuse_radiance: p.diffuse_radiance,
                material: p.material,
            };
            let g = glossy.get(i).copied();
            let slot = &mut self.grids[layer as usize][p.pixel as usize];
            if p.whole_pixel {
                *slot = cell;
                if let Some(g) = g {
                    self.glossy_grids[layer as usize][p.pixel as usize] = g;
                }
                continue;
            }
            if slot.material == EMPTY || slot.material & EDGE == 0 {
                // The pixel's first sample point in this layer opens its slot.
                slot.material = EDGE | (self.edge_cells.len() / aa) as u32;
                self.edge_cells.resize(self.edge_cells.len() + aa, EMPTY_CELL);
                self.edge_glossy.resize(self.edge_glossy.len() + aa, [Vec3::ZERO; 2]);
            }
            let at = (slot.material & !EDGE) as usize * aa + p.sample as usize;
            self.edge_cells[at] = cell;
            if let Some(g) = g {
                self.edge_glossy[at] = g;
            }
        }
    }

    /// The layer of camera path `path`, a fresh empty one the first time it is seen in a tile.
    fn layer(&mut self, path: u32, region: &PixelRect, glossy: bool) -> u32 {
        if let Some(layer) = self.paths.iter().position(|&k| k == path) {
            return layer as u32;
        }
        self.paths.push(path);
        if self.grids.len() < self.paths.len() {
            self.grids.push(Vec::new());
            self.glossy_grids.push(Vec::new());
        }
        let grid = &mut self.grids[self.paths.len() - 1];
        grid.clear();
        grid.resize(region.pixel_count(), EMPTY_CELL);
        let glossy_grid = &mut self.glossy_grids[self.paths.len() - 1];
        glossy_grid.clear();
        if glossy {
            glossy_grid.resize(region.pixel_count(), [Vec3::ZERO; 2]);
        }
        (self.paths.len() - 1) as u32
    }
}

/// The discontinuity test: same material (an empty cell has none), normals and path
/// distances close enough.
#[inline]
fn similar(a: &FilterSample, b: &Cell, settings: &FilterSettings) -> bool {
    a.material == b.material
        && a.normal.dot(b.normal) >= settings.min_normal_cos
        && (a.depth - b.depth).abs() <= settings.max_depth_ratio * a.depth
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid_points(region: &PixelRect, f: impl Fn(u32, u32) -> (Vec3, f32, Vec3)) -> Vec<FilterSample> {
        let mut points = Vec::new();
        for y in region.y0..region.y1 {
            for x in region.x0..region.x1 {
                let (normal, depth, diffuse_radiance) = f(x, y);
                points.push(FilterSample {
                    pixel: region.index(x, y) as u32,
                    sample: 0,
                    whole_pixel: true,
                    path: 1,
                    normal,
                    depth,
                    material: 0,
                    diffuse_radiance,
                });
            }
        }
        points
    }

    /// The filter's output for `points` covering `region`, filtered for `tile` with `il`.
    fn filter(points: &[FilterSample], region: &PixelRect, tile: &Tile, il: &Interleave) -> Filtered {
        let mut out = Filtered::default();
        DiscontinuityBuffer::default().filter(
            region,
            tile,
            il,
            &FilterSettings::default(),
            (points, &[]),
            &mut out,
        );
        out
    }

    fn run(points: &[FilterSample], region: &PixelRect, tile: &Tile) -> Vec<Vec3> {
        filter(points, region, tile, &Interleave { n: 3, m: 3, coarse: 1, aa: 1 }).diffuse_radiance
    }

    #[test]
    fn constant_irradiance_stays_constant() {
        let region = PixelRect { x0: 0, y0: 0, x1: 10, y1: 8 };
        let tile = Tile { index: 0, rect: region };
        let c = Vec3::new(0.3, 0.7, 1.9);
        let points = grid_points(&region, |x, _| (Vec3::Y, 1.0 + 0.01 * x as f32, c));
        // Equal up to the rounding of a sum of up to nine values divided by their count.
        assert!(
            run(&points, &region, &tile)
                .iter()
                .all(|&v| (v - c).abs().max_element() <= 1e-6 * c.max_element())
        );
    }

    #[test]
    fn averages_the_window_and_never_across_an_edge() {
        let region = PixelRect { x0: 0, y0: 0, x1: 9, y1: 9 };
        let tile = Tile { index: 0, rect: region };
        // Left half: a floor at depth 1; right half (x ≥ 5): a wall at depth 1 with another
        // normal. Irradiance alternates to show the averaging.
        let points = grid_points(&region, |x, y| {
            let value = Vec3::splat(((x + y) % 2) as f32);
            if x < 5 { (Vec3::Y, 1.0, value) } else { (Vec3::X, 1.0, value + Vec3::splat(10.0)) }
        });
        let out = run(&points, &region, &tile);
        // Interior of the floor at (2, 2), value 0: its 4 edge neighbours are 1, the centre and
        // the 4 diagonal ones 0.
        let v = out[region.index(2, 2)].x;
        assert!((v - 4.0 / 9.0).abs() < 1e-6, "{v}");
        // Next to the edge: only floor pixels count, never the wall's +10.
        for y in 0..9 {
            assert!(out[region.index(4, y)].x <= 1.0);
            assert!(out[region.index(5, y)].x >= 10.0);
        }
    }

    /// One set's error at one pixel (a close VPL) spreads as the coarse level's tent, in
    /// steps of a third of its height, not as a 9×9 plateau with edges (the squares a box of
    /// K×K taps made of every set's error).
    #[test]
    fn one_sets_error_spreads_as_a_tent_not_a_square() {
        let region = PixelRect { x0: 0, y0: 0, x1: 45, y1: 45 };
        let tile = Tile { index: 0, rect: region };
        let points = grid_points(&region, |x, y| {
            (Vec3::Y, 1.0, if (x, y) == (22, 22) { Vec3::splat(81.0) } else { Vec3::ZERO })
        });
        let out = filter(&points, &region, &tile, &Interleave { n: 3, m: 3, coarse: 3, aa: 1 });
        let v = |x: u32, y: u32| out.diffuse_radiance[region.index(x, y)].x;
        assert!((v(22, 22) - 1.0).abs() < 1e-5, "the peak: {}", v(22, 22));
        let mut largest_step = 0.0f32;
        for y in 8..37 {
            for x in 8..37 {
                largest_step =
                    largest_step.max((v(x + 1, y) - v(x, y)).abs()).max((v(x, y + 1) - v(x, y)).abs());
            }
        }
        assert!(largest_step <= 1.0 / 3.0 + 1e-5, "a step of {largest_step} of the peak");
        // It reaches 8 pixels out (fine window 1 + two taps of 3 at weights 2/3, 1/3), no further.
        assert!(v(22 + 7, 22) > 0.0 && v(22 + 8, 22) == 0.0 && v(22, 22 - 8) == 0.0);
        // The light is kept: its weights around it sum to the spike over the sets.
        let total: f32 = out.diffuse_radiance.iter().map(|d| d.x).sum();
        assert!((total - 81.0).abs() < 1e-3, "{total}");
    }

    #[test]
    fn depth_steps_separate() {
        let region = PixelRect { x0: 0, y0: 0, x1: 6, y1: 6 };
        let tile = Tile { index: 0, rect: region };
        let points = grid_points(&region, |x, _| {
            if x < 3 { (Vec3::Z, 1.0, Vec3::ONE) } else { (Vec3::Z, 2.0, Vec3::splat(5.0)) }
        });
        let out = run(&points, &region, &tile);
        assert_eq!(out[region.index(2, 3)], Vec3::ONE);
        assert_eq!(out[region.index(3, 3)], Vec3::splat(5.0));
    }

    /// With two samples per pixel, a pixel across an edge has a point per sample: sample j
    /// averages its whole neighbours and their sample-j points, never another sample's; a
    /// whole pixel counts for every sample.
    #[test]
    fn a_sample_is_filtered_with_whole_pixels_and_the_same_sample_of_edge_pixels() {
        let region = PixelRect { x0: 0, y0: 0, x1: 3, y1: 3 };
        let tile = Tile { index: 0, rect: region };
        let il = Interleave { n: 3, m: 3, coarse: 1, aa: 2 };
        let point = |x: u32, y: u32, sample: u32, whole_pixel: bool, d: f32| FilterSample {
            pixel: region.index(x, y) as u32,
            sample,
            whole_pixel,
            path: 1,
            normal: Vec3::Y,
            depth: 1.0,
            material: 0,
            diffuse_radiance: Vec3::splat(d),
        };
        // Whole pixels of value 1 everywhere but (1, 1) and (2, 1), which have samples 0 and 1
        // of values 10, 20 and 30, 40.
        let mut points: Vec<FilterSample> = (0..9)
            .map(|i| (i % 3, i / 3))
            .filter(|&(x, y)| y != 1 || x == 0)
            .map(|(x, y)| point(x, y, 0, true, 1.0))
            .collect();
        points.extend([point(1, 1, 0, false, 10.0), point(1, 1, 1, false, 20.0)]);
        points.extend([point(2, 1, 0, false, 30.0), point(2, 1, 1, false, 40.0)]);
        let out = filter(&points, &region, &tile, &il);
        let value = |x: u32, y: u32, sample: u32| {
            let i = points
                .iter()
                .position(|p| p.pixel == region.index(x, y) as u32 && p.sample == sample)
                .unwrap();
            out.diffuse_radiance[i].x
        };
        // Sample 0 at (1, 1): seven whole pixels, itself (10) and (2, 1)'s sample 0 (30).
        assert!((value(1, 1, 0) - (7.0 + 10.0 + 30.0) / 9.0).abs() < 1e-5);
        assert!((value(1, 1, 1) - (7.0 + 20.0 + 40.0) / 9.0).abs() < 1e-5);
        // A whole pixel is filtered as its own sample (0): (0, 0) sees (1, 1)'s sample 0.
        assert!((value(0, 0, 0) - (3.0 + 10.0) / 4.0).abs() < 1e-5);
    }
}
