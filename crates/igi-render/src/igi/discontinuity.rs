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
//!
//! The whole pixels are filtered eight neighbours of a row at a time (SIMD lanes: eight cells
//! of 32 bytes turned into vectors of their fields by one transpose), the points of pixels
//! with a point per sample eight samples of a pixel at a time; every lane adds the same taps
//! in the same order as the definition, so the values are its own bit for bit (tested against
//! it; ARCHITECTURE.md, "Eight whole pixels at a time in the discontinuity filter").

use crate::frame::FilterSettings;
use crate::igi::interleave::{Interleave, Window};
use crate::image::pixel_rect::PixelRect;
use crate::image::tile::Tile;
use glam::Vec3;
use igi_simd::{F32x8, I32x8, M32x8};

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
/// the neighbours of a pixel lie next to each other in memory: eight lanes, the unit normal,
/// the depth, D and the material index's bits, so that eight neighbouring cells turn into
/// eight vectors of one field each with one transpose ([`DiscontinuityBuffer::whole_pixels`]).
/// The material is [`EMPTY`] if the layer has no point at this pixel; for a pixel whose samples
/// have points of their own, [`EDGE`] plus the slot of its N cells in
/// [`DiscontinuityBuffer::edge_cells`].
#[derive(Clone, Copy, Debug)]
struct Cell([f32; 8]);

/// Lanes of a [`Cell`].
const NORMAL: usize = 0;
const DEPTH: usize = 3;
const DIFFUSE: usize = 4;
const MATERIAL: usize = 7;

impl Cell {
    fn new(normal: Vec3, depth: f32, diffuse_radiance: Vec3, material: u32) -> Self {
        let (n, d) = (normal, diffuse_radiance);
        Self([n.x, n.y, n.z, depth, d.x, d.y, d.z, f32::from_bits(material)])
    }

    fn set_diffuse_radiance(&mut self, d: Vec3) {
        d.write_to_slice(&mut self.0[DIFFUSE..DIFFUSE + 3]);
    }

    fn material(&self) -> u32 {
        self.0[MATERIAL].to_bits()
    }

    fn set_material(&mut self, material: u32) {
        self.0[MATERIAL] = f32::from_bits(material);
    }

    /// For a cell that marks a pixel with a point per sample, the index of the first of its N
    /// edge cells (the slot times N); none for a whole pixel's cell or an empty one.
    #[inline]
    fn edge_cells(&self, aa: usize) -> Option<usize> {
        let m = self.material();
        (m != EMPTY && m & EDGE != 0).then(|| (m & !EDGE) as usize * aa)
    }
}

/// The glossy terms G and S of a cell, in eight lanes (two unused) like [`Cell`].
#[derive(Clone, Copy, Debug)]
struct GlossyCell([f32; 8]);

impl GlossyCell {
    const ZERO: Self = Self([0.0; 8]);

    fn new([g, s]: [Vec3; 2]) -> Self {
        Self([g.x, g.y, g.z, s.x, s.y, s.z, 0.0, 0.0])
    }
}

/// No shading point at this pixel in this layer.
const EMPTY: u32 = u32::MAX;

/// Marks a cell whose pixel has a point per sample (the low bits hold the slot of its cells).
const EDGE: u32 = 1 << 31;

const EMPTY_CELL: Cell = Cell([0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, f32::from_bits(EMPTY)]);

/// A bit per pixel of a layer's grid (with a spare word, so any eight bits can be read).
#[derive(Clone, Debug, Default)]
struct EdgeBits(Vec<u64>);

impl EdgeBits {
    fn reset(&mut self, pixels: usize) {
        self.0.clear();
        self.0.resize(pixels / 64 + 2, 0);
    }

    fn set(&mut self, pixel: usize) {
        self.0[pixel / 64] |= 1 << (pixel % 64);
    }

    /// The bits of pixels `first .. first + 8`.
    fn eight(&self, first: usize) -> u32 {
        let (word, shift) = (first / 64, first % 64);
        let bits = match shift {
            0 => self.0[word],
            _ => self.0[word] >> shift | self.0[word + 1] << (64 - shift),
        };
        (bits & 0xff) as u32
    }
}

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
    glossy_grids: Vec<Vec<GlossyCell>>,
    /// Per layer and pixel, the index of the whole pixel's point (where the cell holds one).
    whole_points: Vec<Vec<u32>>,
    /// Per layer, a bit per pixel: the cell marks a pixel with a point per sample ([`EDGE`]),
    /// so eight neighbouring cells say at once whether one of them must be looked up
    /// elsewhere.
    edge_bits: Vec<EdgeBits>,
    /// The cells of pixels with a point per sample, N per slot, their G and S, and the index
    /// of each cell's point.
    edge_cells: Vec<Cell>,
    edge_glossy: Vec<GlossyCell>,
    edge_points: Vec<u32>,
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

impl Level {
    /// The level's taps, their weights looked up: computing the tent per tap (two divisions,
    /// and two more for the tap numbers) was a fifth of the filter's time. The product of a
    /// row's and a column's weight is `coarse_weight`'s, so the bits are the same.
    fn taps(&self) -> Taps {
        let axis = |before: u32, after: u32, stride: u32| -> Vec<(i64, f32)> {
            (0..=before + after)
                .map(|t| {
                    let offset = (i64::from(t) - i64::from(before)) * i64::from(stride);
                    (offset, self.tent.map_or(1.0, |il| il.coarse_tent(before.abs_diff(t))))
                })
                .collect()
        };
        let (([left, right], [up, down]), (sx, sy)) = (self.window, self.stride);
        let (columns, rows) = (axis(left, right, sx), axis(up, down, sy));
        let taps = rows
            .iter()
            .flat_map(|&(dy, w_y)| columns.iter().map(move |&(dx, w_x)| Tap { dx, dy, weight: w_x * w_y }))
            .collect();
        Taps { all: taps, reach: ([left * sx, right * sx], [up * sy, down * sy]) }
    }
}

/// A level's window of taps around a pixel, row by row from the top, each row from the left:
/// the order in which the filter adds them.
struct Taps {
    all: Vec<Tap>,
    /// How far the taps reach from the pixel, in pixels: ([left, right], [up, down]).
    reach: Window,
}

/// One tap around a pixel: its offset in pixels and its weight.
#[derive(Clone, Copy)]
struct Tap {
    dx: i64,
    dy: i64,
    weight: f32,
}

impl Taps {
    /// Whether every tap of the eight pixels from (x, y) on lies in `region`: their taps need
    /// no test of the region's borders.
    fn all_inside(&self, x: u32, y: u32, region: &PixelRect) -> bool {
        let ([left, right], [up, down]) = self.reach;
        x >= region.x0 + left && x + 7 + right < region.x1 && y >= region.y0 + up && y + down < region.y1
    }
}

/// What one level reads and writes: the region's grids, the filter's settings, the points and
/// their values.
struct LevelInput<'a> {
    region: &'a PixelRect,
    settings: &'a FilterSettings,
    points: &'a [FilterSample],
    aa: usize,
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
        let aa = interleave.aa as usize;
        self.index(region, aa, points, glossy_in);
        out.diffuse_radiance.clear();
        out.diffuse_radiance.extend(points.iter().map(|p| p.diffuse_radiance));
        out.glossy_radiance.clear();
        out.glossy_radiance.extend_from_slice(glossy_in);
        let input = LevelInput { region, settings, points, aa };
        let fine = Level { window: interleave.window(), stride: (1, 1), tent: None };
        if interleave.coarse == 1 {
            self.level(&input, &tile.rect, fine, out);
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
        self.level(&input, &read, fine, out);
        self.store(region, &read, aa, points, out);
        self.level(&input, &tile.rect, coarse, out);
    }

    /// One filter level: for each point inside `rect`, the weighted mean of the values in the
    /// cells of `level`'s taps around its pixel (inside the region) whose points are
    /// [`similar`] to it. The whole pixels go eight at a time, the other points one by one;
    /// both sum the same taps in the same order, so a point's value does not depend on which.
    fn level(&self, input: &LevelInput, rect: &PixelRect, level: Level, out: &mut Filtered) {
        if out.glossy_radiance.is_empty() {
            self.whole_pixels::<false>(input, rect, level, out);
            self.sample_points::<false>(input, rect, level, out);
        } else {
            self.whole_pixels::<true>(input, rect, level, out);
            self.sample_points::<true>(input, rect, level, out);
        }
    }

    /// [`DiscontinuityBuffer::level`] for the points that stand for their whole pixel, eight
    /// neighbouring pixels of a row of a layer at a time: a tap of the eight is eight
    /// neighbouring cells, turned into vectors of their fields by one transpose, so the
    /// similarity tests and the sums run on eight points at once (with G and S if `GLOSSY`).
    fn whole_pixels<const GLOSSY: bool>(
        &self,
        input: &LevelInput,
        rect: &PixelRect,
        level: Level,
        out: &mut Filtered,
    ) {
        let LevelInput { region, settings, points, aa } = *input;
        let taps = level.taps();
        let width = region.width() as i64;
        let lane_offsets = I32x8::from_array(std::array::from_fn(|k| k as i32));
        for layer in 0..self.paths.len() {
            let (grid, glossy_grid) = (&self.grids[layer], &self.glossy_grids[layer]);
            let (whole, edge_map) = (&self.whole_points[layer], &self.edge_bits[layer]);
            for y in rect.y0..rect.y1 {
                for x in (rect.x0..rect.x1).step_by(8) {
                    // The centres: the row's whole pixels from x on, inside `rect`.
                    let centre = region.index(x, y);
                    let lanes = (rect.x1 - x).min(8) as usize;
                    let mut active = 0u32;
                    for k in 0..lanes {
                        let m = grid[centre + k].material();
                        active |= u32::from(m & EDGE == 0) << k;
                    }
                    if active == 0 {
                        continue;
                    }
                    let c =
                        F32x8::transpose(std::array::from_fn(|k| &grid[(centre + k).min(grid.len() - 1)].0));
                    let centres = Centres::new(&c, active, settings);
                    let mut sums = TapSums::<GLOSSY>::ZERO;
                    let xs = I32x8::splat(x as i32) + lane_offsets;
                    // Away from the region's borders every tap is eight neighbouring cells of
                    // the grid, at a fixed distance from the centres'.
                    let interior = taps.all_inside(x, y, region);
                    let last = grid.len() as i64 - 8;
                    for &Tap { dx, dy, weight } in &taps.all {
                        // The tap's first cell, and the lanes whose tap lies in the region's
                        // columns (the others take no part, and read some cell of the grid).
                        let (first, inside) = if interior {
                            (centre as i64 + dy * width + dx, M32x8::from_bitmask(0xff))
                        } else {
                            let row = i64::from(y) + dy;
                            if !(i64::from(region.y0)..i64::from(region.y1)).contains(&row) {
                                continue;
                            }
                            let tap_x0 = i64::from(x) + dx;
                            let first =
                                (row - i64::from(region.y0)) * width + (tap_x0 - i64::from(region.x0));
                            let inside =
                                if tap_x0 >= i64::from(region.x0) && tap_x0 + 7 < i64::from(region.x1) {
                                    M32x8::from_bitmask(0xff)
                                } else {
                                    let tap_x = xs + I32x8::splat(dx as i32);
                                    tap_x.gt(I32x8::splat(region.x0 as i32 - 1))
                                        & tap_x.lt(I32x8::splat(region.x1 as i32))
                                };
                            (first, inside)
                        };
                        // An interior block's taps lie in the grid by construction.
                        let in_grid = interior || (first >= 0 && first <= last);
                        let block =
                            if in_grid { first as usize } else { first.clamp(0, last.max(0)) as usize };
                        let at = |k: usize| match in_grid {
                            true => block + k,
                            false => (first + k as i64).clamp(0, grid.len() as i64 - 1) as usize,
                        };
                        // A neighbour with a point per sample shows each centre's sample.
                        let edge_bits = match in_grid {
                            true => edge_map.eight(block) & inside.bitmask() & active,
                            false => {
                                (0..8)
                                    .filter(|&k| grid[at(k)].edge_cells(aa).is_some())
                                    .fold(0, |bits, k| bits | 1 << k)
                                    & inside.bitmask()
                                    & active
                            }
                        };
                        let edge_slot = |k: usize| {
                            let first_cell = grid[at(k)]
                                .edge_cells(aa)
                                .expect("an edge pixel's cell names its edge cells");
                            first_cell + points[whole[centre + k] as usize].sample as usize
                        };
                        let contiguous = in_grid && edge_bits == 0;
                        let q = if contiguous {
                            let cells = &grid[block..block + 8];
                            F32x8::transpose(std::array::from_fn(|k| &cells[k].0))
                        } else {
                            let rows: [&[f32; 8]; 8] = std::array::from_fn(|k| match edge_bits >> k & 1 {
                                1 => &self.edge_cells[edge_slot(k)].0,
                                _ => &grid[at(k)].0,
                            });
                            F32x8::transpose(rows)
                        };
                        let similar = match dx == 0 && dy == 0 {
                            true => centres.active,
                            false => centres.similar(&q) & inside,
                        };
                        sums.add(similar, weight, &q, || {
                            if contiguous {
                                let cells = &glossy_grid[block..block + 8];
                                F32x8::transpose(std::array::from_fn(|k| &cells[k].0))
                            } else {
                                F32x8::transpose(std::array::from_fn(|k| match edge_bits >> k & 1 {
                                    1 => &self.edge_glossy[edge_slot(k)].0,
                                    _ => &glossy_grid[at(k)].0,
                                }))
                            }
                        });
                    }
                    sums.write(active, |k| whole[centre + k] as usize, out);
                }
            }
        }
    }

    /// [`DiscontinuityBuffer::level`] for the points of pixels whose samples have points of
    /// their own, eight samples of a pixel at a time: a tap of them is one whole pixel's cell,
    /// the same for all, or the tap pixel's cells of the same eight samples, side by side.
    fn sample_points<const GLOSSY: bool>(
        &self,
        input: &LevelInput,
        rect: &PixelRect,
        level: Level,
        out: &mut Filtered,
    ) {
        let LevelInput { region, settings, aa, .. } = *input;
        let taps = level.taps();
        let width = region.width() as i64;
        for layer in 0..self.paths.len() {
            let (grid, glossy_grid) = (&self.grids[layer], &self.glossy_grids[layer]);
            for y in rect.y0..rect.y1 {
                for x in rect.x0..rect.x1 {
                    let Some(own) = grid[region.index(x, y)].edge_cells(aa) else { continue };
                    for first_sample in (0..aa).step_by(8) {
                        // Lanes past the last sample repeat it and take no part.
                        let lanes = (aa - first_sample).min(8);
                        let sample = |k: usize| first_sample + k.min(lanes - 1);
                        let c =
                            F32x8::transpose(std::array::from_fn(|k| &self.edge_cells[own + sample(k)].0));
                        let with_point = !c[MATERIAL].to_bits().eq(I32x8::splat(EMPTY as i32));
                        let active = with_point.bitmask() & ((1 << lanes) - 1);
                        if active == 0 {
                            continue;
                        }
                        let centres = Centres::new(&c, active, settings);
                        let mut sums = TapSums::<GLOSSY>::ZERO;
                        for &Tap { dx, dy, weight } in &taps.all {
                            let row = i64::from(y) + dy;
                            if !(i64::from(region.y0)..i64::from(region.y1)).contains(&row) {
                                continue;
                            }
                            let column = i64::from(x) + dx;
                            if column < i64::from(region.x0) || column >= i64::from(region.x1) {
                                continue;
                            }
                            let index = ((row - i64::from(region.y0)) * width
                                + (column - i64::from(region.x0)))
                                as usize;
                            let tap = &grid[index];
                            let edge = tap.edge_cells(aa);
                            let q = match edge {
                                Some(slot) => F32x8::transpose(std::array::from_fn(|k| {
                                    &self.edge_cells[slot + sample(k)].0
                                })),
                                None => tap.0.map(F32x8::splat),
                            };
                            let similar = match dx == 0 && dy == 0 {
                                true => centres.active,
                                false => centres.similar(&q),
                            };
                            sums.add(similar, weight, &q, || match edge {
                                Some(slot) => F32x8::transpose(std::array::from_fn(|k| {
                                    &self.edge_glossy[slot + sample(k)].0
                                })),
                                None => glossy_grid[index].0.map(F32x8::splat),
                            });
                        }
                        sums.write(active, |k| self.edge_points[own + first_sample + k] as usize, out);
                    }
                }
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
                self.grids[layer][p.pixel as usize].set_diffuse_radiance(d);
                if glossy {
                    self.glossy_grids[layer][p.pixel as usize] = GlossyCell::new(values.glossy_radiance[i]);
                }
            } else {
                // The pixel's slot of N cells ([`DiscontinuityBuffer::index`]).
                let first_cell = self.grids[layer][p.pixel as usize]
                    .edge_cells(aa)
                    .expect("an edge pixel's cell names its edge cells");
                let at = first_cell + p.sample as usize;
                self.edge_cells[at].set_diffuse_radiance(d);
                if glossy {
                    self.edge_glossy[at] = GlossyCell::new(values.glossy_radiance[i]);
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
        self.edge_points.clear();
        let mut last: Option<(u32, u32)> = None;
        for (i, p) in points.iter().enumerate() {
            // Points come in runs of one path: look it up only when it changes.
            let layer = match last {
                Some((path, layer)) if path == p.path => layer,
                _ => self.layer(p.path, region, !glossy.is_empty()),
            };
            last = Some((p.path, layer));
            self.layers.push(layer);
            let cell = Cell::new(p.normal, p.depth, p.diffuse_radiance, p.material);
            let g = glossy.get(i).copied().map(GlossyCell::new);
            let slot = &mut self.grids[layer as usize][p.pixel as usize];
            if p.whole_pixel {
                *slot = cell;
                self.whole_points[layer as usize][p.pixel as usize] = i as u32;
                if let Some(g) = g {
                    self.glossy_grids[layer as usize][p.pixel as usize] = g;
                }
                continue;
            }
            if slot.edge_cells(aa).is_none() {
                // The pixel's first sample point in this layer opens its slot.
                slot.set_material(EDGE | (self.edge_cells.len() / aa) as u32);
                self.edge_bits[layer as usize].set(p.pixel as usize);
                self.edge_cells.resize(self.edge_cells.len() + aa, EMPTY_CELL);
                self.edge_glossy.resize(self.edge_glossy.len() + aa, GlossyCell::ZERO);
                self.edge_points.resize(self.edge_points.len() + aa, u32::MAX);
            }
            let at =
                slot.edge_cells(aa).expect("an edge pixel's cell names its edge cells") + p.sample as usize;
            self.edge_cells[at] = cell;
            self.edge_points[at] = i as u32;
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
            self.whole_points.push(Vec::new());
            self.edge_bits.push(EdgeBits::default());
        }
        let layer = self.paths.len() - 1;
        let grid = &mut self.grids[layer];
        grid.clear();
        grid.resize(region.pixel_count(), EMPTY_CELL);
        self.whole_points[layer].resize(region.pixel_count(), 0);
        self.edge_bits[layer].reset(region.pixel_count());
        let glossy_grid = &mut self.glossy_grids[layer];
        glossy_grid.clear();
        if glossy {
            glossy_grid.resize(region.pixel_count(), GlossyCell::ZERO);
        }
        layer as u32
    }
}

/// Eight points being filtered, as vectors of their fields, and which lanes hold one.
struct Centres {
    normal: [F32x8; 3],
    depth: F32x8,
    material: I32x8,
    /// The largest depth difference of a similar point: the depth ratio times the depth.
    max_step: F32x8,
    min_cos: F32x8,
    active: M32x8,
}

impl Centres {
    /// The centres from their cells' fields `c` (a transpose of eight [`Cell`]s); `active`
    /// has a bit per lane that holds a point.
    #[inline(always)]
    fn new(c: &[F32x8; 8], active: u32, settings: &FilterSettings) -> Self {
        Self {
            normal: [c[NORMAL], c[NORMAL + 1], c[NORMAL + 2]],
            depth: c[DEPTH],
            material: c[MATERIAL].to_bits(),
            max_step: F32x8::splat(settings.max_depth_ratio) * c[DEPTH],
            min_cos: F32x8::splat(settings.min_normal_cos),
            active: M32x8::from_bitmask(active),
        }
    }

    /// The discontinuity test per lane against the cell fields `q`: same material (an empty
    /// cell has none), normals and path distances close enough; the operations of the
    /// definition in its order (a·b = a.x·b.x + a.y·b.y + a.z·b.z), so the bits are its own.
    #[inline(always)]
    fn similar(&self, q: &[F32x8; 8]) -> M32x8 {
        let n = &self.normal;
        let dot = n[0] * q[NORMAL] + n[1] * q[NORMAL + 1] + n[2] * q[NORMAL + 2];
        q[MATERIAL].to_bits().eq(self.material)
            & dot.ge(self.min_cos)
            & (self.depth - q[DEPTH]).abs().le(self.max_step)
            & self.active
    }
}

/// The weighted sums of eight points' similar taps: D, with G and S if `GLOSSY`, and the
/// weights. Each lane adds its taps in the order they come, as the definition does.
struct TapSums<const GLOSSY: bool> {
    diffuse: [F32x8; 3],
    glossy: [F32x8; 6],
    count: F32x8,
}

impl<const GLOSSY: bool> TapSums<GLOSSY> {
    const ZERO: Self = Self { diffuse: [F32x8::ZERO; 3], glossy: [F32x8::ZERO; 6], count: F32x8::ZERO };

    /// Adds the tap with cell fields `q` and weight `w` to the `similar` lanes, and its glossy
    /// cells' fields (from `glossy`, read only if some lane is similar).
    #[inline(always)]
    fn add(&mut self, similar: M32x8, w: f32, q: &[F32x8; 8], glossy: impl FnOnce() -> [F32x8; 8]) {
        if similar.none() {
            return;
        }
        let w = F32x8::splat(w);
        for (axis, s) in self.diffuse.iter_mut().enumerate() {
            *s = F32x8::select(similar, *s + w * q[DIFFUSE + axis], *s);
        }
        self.count = F32x8::select(similar, self.count + w, self.count);
        if GLOSSY {
            let g = glossy();
            for (axis, s) in self.glossy.iter_mut().enumerate() {
                *s = F32x8::select(similar, *s + w * g[axis], *s);
            }
        }
    }

    /// Writes the means of the lanes in `active` to their points, lane k's point `point(k)`
    /// (every active lane counted its centre, so its weights are above zero).
    fn write(self, active: u32, point: impl Fn(usize) -> usize, out: &mut Filtered) {
        let d = self.diffuse.map(|s| (s / self.count).to_array());
        let g = self.glossy.map(|s| (s / self.count).to_array());
        for k in (0..8).filter(|k| active >> k & 1 != 0) {
            let i = point(k);
            out.diffuse_radiance[i] = Vec3::new(d[0][k], d[1][k], d[2][k]);
            if GLOSSY {
                out.glossy_radiance[i] =
                    [Vec3::new(g[0][k], g[1][k], g[2][k]), Vec3::new(g[3][k], g[4][k], g[5][k])];
            }
        }
    }
}

#[cfg(test)]
mod tests;
