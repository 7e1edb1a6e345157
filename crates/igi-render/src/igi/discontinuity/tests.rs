//! Tests of [`super`].

use super::*;

/// The discontinuity test: same material (an empty cell has none), normals and path
/// distances close enough.
fn similar(a: &FilterSample, b: &Cell, settings: &FilterSettings) -> bool {
    a.material == b.material()
        && a.normal.dot(Vec3::from_slice(&b.0[NORMAL..NORMAL + 3])) >= settings.min_normal_cos
        && (a.depth - b.0[DEPTH]).abs() <= settings.max_depth_ratio * a.depth
}

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

/// The filter from its definition, one point and one tap at a time: for each point of
/// the rectangle, the weighted mean over the level's taps inside the region, in row-major
/// order, of the point of the tap's pixel on the same camera path that stands for the
/// point's sample (its whole pixel's, or its own sample's), where it is similar or is the
/// point itself; the first level's results replace the values the second level reads.
fn reference(
    points: &[FilterSample],
    glossy: &[[Vec3; 2]],
    region: &PixelRect,
    tile: &Tile,
    il: &Interleave,
) -> (Vec<Vec3>, Vec<[Vec3; 2]>) {
    let settings = FilterSettings::default();
    let values: Vec<(Vec3, [Vec3; 2])> = (0..points.len())
        .map(|i| (points[i].diffuse_radiance, glossy.get(i).copied().unwrap_or_default()))
        .collect();
    let tap_point = |p: &FilterSample, x: u32, y: u32| {
        points.iter().position(|q| {
            q.path == p.path
                && q.pixel == region.index(x, y) as u32
                && (q.whole_pixel || q.sample == p.sample)
        })
    };
    let level =
        |values: &[(Vec3, [Vec3; 2])], rect: &PixelRect, window: Window, stride: (u32, u32), tent: bool| {
            let mut out = values.to_vec();
            let (([l, r], [u, d]), (sx, sy)) = (window, stride);
            for (i, p) in points.iter().enumerate() {
                let (x, y) = region.pixel(p.pixel);
                if !rect.contains(x, y) {
                    continue;
                }
                let (mut sum, mut count) = ((Vec3::ZERO, [Vec3::ZERO; 2]), 0.0f32);
                for ty in -(u as i64)..=d as i64 {
                    for tx in -(l as i64)..=r as i64 {
                        let (qx, qy) = (x as i64 + tx * sx as i64, y as i64 + ty * sy as i64);
                        if !region.contains(qx.max(0) as u32, qy.max(0) as u32) || qx < 0 || qy < 0 {
                            continue;
                        }
                        let Some(j) = tap_point(p, qx as u32, qy as u32) else { continue };
                        let q = &points[j];
                        let cell = Cell::new(q.normal, q.depth, q.diffuse_radiance, q.material);
                        if j == i || similar(p, &cell, &settings) {
                            let weight =
                                |t: i64| if tent { il.coarse_tent(t.unsigned_abs() as u32) } else { 1.0 };
                            let w = weight(tx) * weight(ty);
                            let (dq, [gq, sq]) = values[j];
                            sum = (sum.0 + w * dq, [sum.1[0] + w * gq, sum.1[1] + w * sq]);
                            count += w;
                        }
                    }
                }
                out[i] = (sum.0 / count, [sum.1[0] / count, sum.1[1] / count]);
            }
            out
        };
    let values = if il.coarse == 1 {
        level(&values, &tile.rect, il.window(), (1, 1), false)
    } else {
        let fine = level(&values, region, il.window(), (1, 1), false);
        level(&fine, &tile.rect, il.coarse_window(), (il.n, il.m), true)
    };
    (values.iter().map(|v| v.0).collect(), values.iter().map(|v| v.1).collect())
}

/// Eight whole pixels at a time and the sample points one at a time give the definition's
/// values bit for bit: random surfaces with edges, two camera paths, pixels with a point
/// per sample among whole ones, glossy terms, a tile on the region's border (the image's).
#[test]
fn the_filter_is_its_definition() {
    let mut state = 0x2545_f491u32;
    let mut random = move || {
        state = crate::sampling::hash32(state.wrapping_add(0x9e37_79b9));
        state as f32 / u32::MAX as f32
    };
    for (aa, coarse) in [(1, 1), (4, 1), (1, 3), (4, 3), (12, 3)] {
        let il = Interleave { n: 3, m: 3, coarse, aa };
        let region = PixelRect { x0: 3, y0: 2, x1: 3 + 37, y1: 2 + 29 };
        let tile = Tile { index: 0, rect: PixelRect { x0: 3, y0: 2, x1: 30, y1: 23 } };
        let mut points = Vec::new();
        for path in [1, 2] {
            for pixel in 0..region.pixel_count() as u32 {
                let (x, y) = region.pixel(pixel);
                if path == 2 && (x + y) % 3 != 0 {
                    continue;
                }
                let whole = aa == 1 || random() < 0.8;
                for sample in 0..if whole { 1 } else { aa } {
                    let side = (x * 7 + y * 3) % 11 < 5;
                    let normal = Vec3::new(random() * 0.3, 1.0, random() * 0.3).normalize();
                    points.push(FilterSample {
                        pixel,
                        sample: if whole { (random() * aa as f32) as u32 % aa } else { sample },
                        whole_pixel: whole,
                        path,
                        normal: if side { normal } else { Vec3::new(normal.y, normal.x, normal.z) },
                        depth: 1.0 + random() * if random() < 0.1 { 1.0 } else { 0.01 },
                        material: u32::from(random() < 0.05),
                        diffuse_radiance: Vec3::new(random(), random(), random()) * 10.0,
                    });
                }
            }
        }
        let glossy: Vec<[Vec3; 2]> =
            points.iter().map(|_| [Vec3::new(random(), random(), random()), Vec3::splat(random())]).collect();
        for glossy in [&[][..], &glossy[..]] {
            let mut out = Filtered::default();
            DiscontinuityBuffer::default().filter(
                &region,
                &tile,
                &il,
                &FilterSettings::default(),
                (&points, glossy),
                &mut out,
            );
            let (d, g) = reference(&points, glossy, &region, &tile, &il);
            for (i, p) in points.iter().enumerate() {
                let (x, y) = region.pixel(p.pixel);
                if tile.rect.contains(x, y) {
                    let what = format!("aa {aa}, coarse {coarse}, glossy {}, point {i}", !glossy.is_empty());
                    assert_eq!(out.diffuse_radiance[i], d[i], "{what}");
                    if !glossy.is_empty() {
                        assert_eq!(out.glossy_radiance[i], g[i], "{what}");
                    }
                }
            }
        }
    }
}

#[test]
fn constant_irradiance_stays_constant() {
    let region = PixelRect { x0: 0, y0: 0, x1: 10, y1: 8 };
    let tile = Tile { index: 0, rect: region };
    let c = Vec3::new(0.3, 0.7, 1.9);
    let points = grid_points(&region, |x, _| (Vec3::Y, 1.0 + 0.01 * x as f32, c));
    // Equal up to the rounding of a sum of up to nine values divided by their count.
    assert!(
        run(&points, &region, &tile).iter().all(|&v| (v - c).abs().max_element() <= 1e-6 * c.max_element())
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
            largest_step = largest_step.max((v(x + 1, y) - v(x, y)).abs()).max((v(x, y + 1) - v(x, y)).abs());
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
        let i =
            points.iter().position(|p| p.pixel == region.index(x, y) as u32 && p.sample == sample).unwrap();
        out.diffuse_radiance[i].x
    };
    // Sample 0 at (1, 1): seven whole pixels, itself (10) and (2, 1)'s sample 0 (30).
    assert!((value(1, 1, 0) - (7.0 + 10.0 + 30.0) / 9.0).abs() < 1e-5);
    assert!((value(1, 1, 1) - (7.0 + 20.0 + 40.0) / 9.0).abs() < 1e-5);
    // A whole pixel is filtered as its own sample (0): (0, 0) sees (1, 1)'s sample 0.
    assert!((value(0, 0, 0) - (3.0 + 10.0) / 4.0).abs() < 1e-5);
}
