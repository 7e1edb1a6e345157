//! [`TemporalHistory`]: the running mean of a view's frames carried across camera motion
//! (ARCHITECTURE.md, "Temporal reuse while the view moves").
//!
//! Each frame still recomputes all its light from fresh VPLs (the paper's immediate response);
//! the history only averages the frames' independent errors. For each pixel of the new frame,
//! the surface point its centre sees ([`SurfaceBuffer`]) is carried into the previous frame
//! (through its instance's motion, then the previous camera) and the history is read there,
//! bilinearly from the neighbours that saw the same instance at the expected distance
//! ([`DEPTH_TOLERANCE`]) and the same side of it with a similar normal ([`NORMAL_COS`]); a
//! pixel no neighbour matches was hidden (a disocclusion) or is seen from its other side, and
//! starts anew. At silhouettes the history is clamped into the new frame's neighbourhood
//! (each frame's jittered samples see either side there). Changes of the light are not
//! detected here: one frame's error at the scale of a block is 10-20 % (ARCHITECTURE.md, "The
//! coarse level's tent"), as large as many real changes, and a per-block test against it
//! restarted blocks on noise alone, which showed as squares. The caller refuses the whole
//! history when the light may have changed (a cut). The new value is the mean of the frame and
//! the history weighted as `n` frames, with `n` at most the caller's limit: short while the
//! view moves (the resampled history blurs and lags), unbounded while it stands still, where
//! the history is the plain mean of the frames (progressive refinement).
//!
//! Only a frame's [`DiffuseLayer`] is carried across a move: the rest of its radiance
//! (emission, glossy reflection, what mirrors and glass show) depends on the view or carries
//! no VPL noise, so it is taken from the new frame, and averaged in place only
//! while the view stands still. A glossy highlight thereby stays where the new view sees it,
//! and an emitter's radiance never bleeds into its neighbours through the resampling.
//!
//! Everything is per pixel or per block in a fixed order, so the image does not depend on
//! the thread count, tile size or node count that rendered the frames.

use crate::image::film::Film;
use crate::image::frame_image::DiffuseLayer;
use crate::temporal::surface_buffer::SurfaceBuffer;
use glam::{Affine3A, Vec3};
use igi_bvh::INVALID_ID;
use rayon::prelude::*;

/// A history sample is read from a neighbour only where that neighbour saw the same instance
/// at a distance within this share of the expected one, ...
pub const DEPTH_TOLERANCE: f32 = 0.03;

/// ... and the same side of a surface with a normal within this cosine (the filter's
/// threshold, `FilterSettings::min_normal_cos`).
pub const NORMAL_COS: f32 = 0.9;

/// Neighbouring pixels whose distances differ by more than this share lie across a silhouette.
pub const SILHOUETTE_DEPTH_RATIO: f32 = 0.1;

/// The history of a view: a linear image, the number of frames each pixel's value stands for,
/// and the surfaces of the last frame.
#[derive(Clone, Debug, Default)]
pub struct TemporalHistory {
    /// The mean of the frames' [`DiffuseLayer`]s (of their whole radiance for frames
    /// without one), per pixel.
    radiance: Vec<Vec3>,
    frames: Vec<f32>,
    /// The mean of the rest of the frames' radiance since the view last moved, and its frames.
    rest: Vec<Vec3>,
    rest_frames: f32,
    surfaces: Option<SurfaceBuffer>,
    /// Pixels of the last frame that kept history.
    kept: usize,
}

impl TemporalHistory {
    /// An empty history.
    pub fn new() -> Self {
        Self::default()
    }

    /// Forgets everything (a cut: another scene, view or lighting).
    pub fn clear(&mut self) {
        *self = Self::default();
    }

    /// The share of the last frame's pixels that kept history (0 after a cut).
    pub fn kept(&self) -> f64 {
        self.kept as f64 / self.radiance.len().max(1) as f64
    }

    /// The mean number of frames the pixels of the image stand for.
    pub fn mean_frames(&self) -> f64 {
        self.frames.iter().map(|&n| f64::from(n)).sum::<f64>() / self.frames.len().max(1) as f64
    }

    /// Adds `frame` (with its [`DiffuseLayer`], if it has one) and returns the new image:
    /// each pixel the mean of the frame and its history weighted as at most `max_history`
    /// frames. With [`Motion::Still`] the history is read in place, else its layer part is
    /// reprojected from the surfaces of the last frame to those of this one and the rest
    /// starts anew.
    pub fn add(
        &mut self,
        frame: &Film,
        layer: Option<&DiffuseLayer>,
        motion: Motion,
        max_history: f32,
    ) -> Film {
        let (w, h) = (frame.width(), frame.height());
        let len = frame.pixels().len();
        let reusable = layer.map_or(frame.pixels(), |DiffuseLayer(layer)| layer.pixels());
        let fits = self.radiance.len() == len
            && self.surfaces.as_ref().is_some_and(|s| (s.camera.width, s.camera.height) == (w, h));
        let (mut history, mut frames) = match (&motion, &self.surfaces) {
            (Motion::Still, Some(_)) if fits => {
                (std::mem::take(&mut self.radiance), std::mem::take(&mut self.frames))
            }
            (Motion::Moved(current), Some(previous)) if fits => self.reproject(previous, current),
            _ => (vec![Vec3::ZERO; len], vec![0.0; len]),
        };
        if !(fits && matches!(motion, Motion::Still)) {
            (self.rest, self.rest_frames) = (vec![Vec3::ZERO; len], 0.0);
        }
        if let Motion::Moved(surfaces) = motion {
            clamp_at_silhouettes(reusable, &surfaces, &mut history);
            self.surfaces = Some(surfaces);
        } else if !fits {
            self.surfaces = None;
        }
        self.kept = frames.iter().filter(|&&n| n > 0.0).count();
        history.par_iter_mut().zip(frames.par_iter_mut()).zip(reusable).for_each(|((hist, n), &x)| {
            let k = n.min(max_history);
            *hist = (x + *hist * k) / (k + 1.0);
            *n = k + 1.0;
        });
        let k = self.rest_frames.min(max_history);
        // The rest's new mean, and the image: the layer's mean plus the rest's, in one pass.
        let out = (self.rest.par_iter_mut().zip(frame.pixels()).zip(reusable).zip(&history))
            .map(|(((rest, &x), &part), &mean)| {
                *rest = (x - part + *rest * k) / (k + 1.0);
                mean + *rest
            })
            .collect();
        self.rest_frames = k + 1.0;
        self.radiance = history;
        self.frames = frames;
        Film::from_pixels(w, h, out)
    }

    /// The history as seen from `current`'s pixels: per pixel the bilinear mean of the
    /// matching neighbours' radiance and frame counts (zero where none matches).
    fn reproject(&self, previous: &SurfaceBuffer, current: &SurfaceBuffer) -> (Vec<Vec3>, Vec<f32>) {
        let (w, h) = (current.camera.width, current.camera.height);
        // Each instance's motion since the last frame: current world → object → previous world.
        let motion: Vec<Affine3A> = current
            .transforms
            .iter()
            .enumerate()
            .map(|(i, now)| {
                previous.transforms.get(i).map_or(Affine3A::IDENTITY, |before| *before * now.inverse())
            })
            .collect();
        let mut radiance = vec![Vec3::ZERO; (w * h) as usize];
        let mut frames = vec![0.0f32; (w * h) as usize];
        radiance.par_chunks_mut(w as usize).zip(frames.par_chunks_mut(w as usize)).enumerate().for_each(
            |(y, (radiance, frames))| {
                for x in 0..w {
                    if let Some((r, n)) = self.reprojected(previous, current, &motion, x, y as u32) {
                        radiance[x as usize] = r;
                        frames[x as usize] = n;
                    }
                }
            },
        );
        (radiance, frames)
    }

    /// The history of pixel `(x, y)` of `current` and the frames it stands for, if a
    /// neighbour of where its point was in `previous` saw it.
    fn reprojected(
        &self,
        previous: &SurfaceBuffer,
        current: &SurfaceBuffer,
        motion: &[Affine3A],
        x: u32,
        y: u32,
    ) -> Option<(Vec3, f32)> {
        let w = current.camera.width;
        let h = current.camera.height;
        let i = (y * w + x) as usize;
        let instance = current.instance[i];
        // Where the point was a frame ago, how far from the previous eye, and its normal turned
        // toward the previous eye if that eye saw the same side.
        let (at, expected) = match current.point(x, y) {
            Some(p) => {
                let m = motion[instance as usize];
                let (before, normal) =
                    (m.transform_point3(p), m.transform_vector3(current.normal[i]).normalize());
                if normal.dot(previous.camera.origin - before) <= 0.0 {
                    return None;
                }
                (previous.camera.project(before)?, Some(((before - previous.camera.origin).length(), normal)))
            }
            // The sky: only the direction counts.
            None => (previous.camera.project(previous.camera.origin + current.camera.direction(x, y))?, None),
        };
        // Pixel centres lie at +0.5.
        let (fx, fy) = (at.x - 0.5, at.y - 0.5);
        if !(fx > -1.0 && fy > -1.0 && fx < w as f32 && fy < h as f32) {
            return None;
        }
        let (x0, y0) = (fx.floor(), fy.floor());
        let (ax, ay) = (fx - x0, fy - y0);
        let (mut sum, mut count, mut weight) = (Vec3::ZERO, 0.0, 0.0);
        let taps = [
            (0, 0, (1.0 - ax) * (1.0 - ay)),
            (1, 0, ax * (1.0 - ay)),
            (0, 1, (1.0 - ax) * ay),
            (1, 1, ax * ay),
        ];
        for (dx, dy, wt) in taps {
            let (qx, qy) = (x0 as i64 + dx, y0 as i64 + dy);
            if wt <= 0.0 || qx < 0 || qy < 0 || qx >= i64::from(w) || qy >= i64::from(h) {
                continue;
            }
            let q = (qy as u32 * w + qx as u32) as usize;
            let matches = previous.instance[q] == instance
                && match expected {
                    Some((d, n)) => {
                        (previous.distance[q] - d).abs() <= DEPTH_TOLERANCE * d
                            && previous.normal[q].dot(n) >= NORMAL_COS
                    }
                    None => instance == INVALID_ID,
                };
            if matches && self.frames[q] > 0.0 {
                sum += self.radiance[q] * wt;
                count += self.frames[q] * wt;
                weight += wt;
            }
        }
        (weight > 0.0).then(|| (sum / weight, count / weight))
    }
}

/// How the view changed since the last frame.
#[derive(Clone, Debug)]
pub enum Motion {
    /// Not at all: the same camera and scene pose.
    Still,
    /// The camera or objects moved: the surfaces the new frame's pixel centres see.
    Moved(SurfaceBuffer),
}

/// At silhouettes (pixels whose 3×3 neighbourhood sees another instance or a depth step),
/// clamps the history into the range of the new frame's 3×3 neighbourhood (of `pixels`, the
/// part of the frame the history holds), as temporal
/// anti-aliasing does everywhere (Karis 2014): there each frame's jittered sample sees one side
/// or the other, and reprojecting through the pixel centre's surface would drag the other
/// side's colour along.
fn clamp_at_silhouettes(pixels: &[Vec3], surfaces: &SurfaceBuffer, history: &mut [Vec3]) {
    let (w, h) = (i64::from(surfaces.camera.width), i64::from(surfaces.camera.height));
    history.par_chunks_mut(w as usize).enumerate().for_each(|(y, row)| {
        let y = y as i64;
        for x in 0..w {
            let i = (y * w + x) as usize;
            let (instance, depth, normal) = (surfaces.instance[i], surfaces.distance[i], surfaces.normal[i]);
            let (mut lo, mut hi, mut edge) =
                (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY), false);
            for qy in (y - 1).max(0)..=(y + 1).min(h - 1) {
                for qx in (x - 1).max(0)..=(x + 1).min(w - 1) {
                    let q = (qy * w + qx) as usize;
                    let d = surfaces.distance[q];
                    // A step between neighbouring pixels, larger than a surface seen at a
                    // grazing angle makes (the filter's default depth ratio).
                    edge |= surfaces.instance[q] != instance
                        || (d.is_finite() != depth.is_finite())
                        || (depth.is_finite() && (d - depth).abs() > SILHOUETTE_DEPTH_RATIO * depth)
                        || surfaces.normal[q].dot(normal) < NORMAL_COS;
                    (lo, hi) = (lo.min(pixels[q]), hi.max(pixels[q]));
                }
            }
            if edge {
                row[x as usize] = row[x as usize].clamp(lo, hi);
            }
        }
    });
}
