//! The environment light as the renderer samples it: the radiance of a scene's
//! [`Environment`] along any direction, and directions importance-sampled from it.
//!
//! Directions map to the image by the equirectangular convention documented on
//! [`igi_scene::Environment`] ([`equirect_uv`], [`equirect_direction`]): +Y up, v = 0 the top
//! row (+Y), u = ½ the centre column (−Z), u = 0 the +Z seam; the map's rotation about +Y is
//! undone before the lookup.
//!
//! # Radiance
//!
//! Bilinear interpolation between texel centres, wrapping around horizontally (the seam is
//! continuous) and clamping vertically (the top and bottom rows are the poles).
//!
//! # Sampling
//!
//! The sphere is cut into one cell per texel: columns of equal azimuth, rows of equal polar
//! angle θ ∈ [π r/H, π (r+1)/H], a cell of solid angle Ω_r = (2π/W)(cos θ_r − cos θ_{r+1}).
//! A cell is chosen with probability proportional to Ω_r times the luminance of its *mean
//! radiance*, the average of the bilinear radiance over the cell's solid angle, i.e. to
//! ∫_cell luminance(L) dω exactly. That mean is a 3 × 3 filter of the texel and its
//! neighbours: ⅛, ¾, ⅛ across (azimuth is uniform over a cell), and down the weights of the
//! interpolation integrated against sin θ (computed per row). Using the filtered mean rather
//! than the texel itself matters: interpolation spreads a bright texel
//! into the neighbouring cells, and a cell whose own texel is black but whose radiance is not
//! must keep a non-zero probability, or light sampling alone (the VPL walk) would lose that
//! light. A row is chosen first (the marginal distribution over rows), then a column of it
//! (the conditional distribution of that row), each from one of the two numbers, which
//! [`Cdf::sample_remapped`] then reuses to place the direction uniformly in the cell's solid
//! angle (uniform azimuth, uniform cos θ). The density is therefore piecewise constant in solid
//! angle: p(ω) = P(cell) / Ω_r, proportional to luminance × sin θ in image coordinates, and
//! finite at the poles. A constant environment is sampled uniformly over the sphere
//! (p = 1/4π).

use std::f32::consts::{PI, TAU};

use glam::{Vec2, Vec3};
use igi_scene::{Environment, Image, Texture};

use crate::image::tonemap::luminance;
use crate::sampling::Cdf;

/// Texel channels are clamped to this, so that sums over the largest image (16k × 16k
/// texels) stay finite in f32; nothing physical comes near it.
const MAX_RADIANCE: f32 = 1e20;

/// The weights of columns c − 1, c, c + 1 in the mean of the bilinear radiance over a cell
/// of column c: over a texel width, interpolation gives its neighbours ⅛ each.
const COLUMN_MEAN: [f32; 3] = [0.125, 0.75, 0.125];

/// The weights of rows r − 1, r, r + 1 in the mean of the bilinear radiance over a cell of
/// row `row` (of `height`), per unit solid angle: the interpolation weights integrated against
/// sin θ over the cell, divided by ∫ sin θ. Unlike the columns these depend on the row, since
/// a cell's solid angle is not spread evenly over its rows of texels.
fn row_mean(row: usize, height: usize) -> [f32; 3] {
    use std::f64::consts::PI;
    let h = height as f64;
    // ∫ sin(πv) dv and ∫ v sin(πv) dv over [a, b].
    let i0 = |a: f64, b: f64| ((PI * a).cos() - (PI * b).cos()) / PI;
    let i1 = |a: f64, b: f64| {
        let f = |v: f64| -v * (PI * v).cos() / PI + (PI * v).sin() / (PI * PI);
        f(b) - f(a)
    };
    let r = row as f64;
    let (top, middle, bottom) = (r / h, (r + 0.5) / h, (r + 1.0) / h);
    // Upper half: lerp(texel r − 1, texel r, s) with s = v·h − r + ½; lower half:
    // lerp(texel r, texel r + 1, s) with s = v·h − r − ½.
    let upper_s = h * i1(top, middle) - (r - 0.5) * i0(top, middle);
    let lower_s = h * i1(middle, bottom) - (r + 0.5) * i0(middle, bottom);
    let above = i0(top, middle) - upper_s;
    let below = lower_s;
    let total = i0(top, bottom);
    [above / total, (total - above - below) / total, below / total].map(|w| w as f32)
}

/// Texture coordinates of a direction in an unrotated equirectangular map (see the
/// [`igi_scene::Environment`] convention): u = atan2(−x, z)/2π in [0, 1), v = acos(y)/π.
/// `dir` must be of unit length.
pub fn equirect_uv(dir: Vec3) -> Vec2 {
    let mut u = (-dir.x).atan2(dir.z) / TAU;
    if u < 0.0 {
        u += 1.0;
    }
    // A tiny negative angle rounds to exactly 1 after the shift.
    if u >= 1.0 {
        u = 0.0;
    }
    Vec2::new(u, dir.y.clamp(-1.0, 1.0).acos() / PI)
}

/// The unit direction at texture coordinates `uv` of an unrotated equirectangular map: the
/// inverse of [`equirect_uv`].
pub fn equirect_direction(uv: Vec2) -> Vec3 {
    direction_at(uv.x, (PI * uv.y).cos())
}

/// The direction of azimuth 2πu and polar angle acos(`cos_theta`).
fn direction_at(u: f32, cos_theta: f32) -> Vec3 {
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    let (sin_phi, cos_phi) = (TAU * u).sin_cos();
    Vec3::new(-sin_phi * sin_theta, cos_theta, cos_phi * sin_theta)
}

/// A direction chosen by [`EnvironmentLight::sample`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EnvironmentSample {
    /// Unit direction toward the environment (world space).
    pub dir: Vec3,
    /// Radiance arriving from `dir`, `radiance(dir)`.
    pub radiance: Vec3,
    /// Probability density of `dir` per unit solid angle, `pdf(dir)`.
    pub pdf: f32,
}

/// A scene's environment, ready for lookups and importance sampling.
#[derive(Clone, Debug)]
pub struct EnvironmentLight {
    kind: Kind,
    /// Factor on every radiance (a viewer's sky strength, [`crate::ScenePose::sky`]).
    strength: f32,
}

#[derive(Clone, Debug)]
enum Kind {
    /// The same radiance from everywhere.
    Constant(Vec3),
    /// An equirectangular map.
    Map(Box<Map>),
}

#[derive(Clone, Debug)]
struct Map {
    width: usize,
    height: usize,
    /// Radiance per texel (intensity applied, non-finite and negative values zeroed), row 0 at
    /// the top.
    texels: Vec<Vec3>,
    /// Sine and cosine of the rotation about +Y.
    rotation: (f32, f32),
    /// cos θ at the top edge of each row, and 1 past the last: `height + 1` values from 1 to −1.
    cos_edges: Vec<f32>,
    /// Which row: weights Ω_r · Σ_c luminance(mean radiance of cell (r, c)).
    rows: Cdf,
    /// Which column of a row: weights luminance(mean radiance of the cell). Empty for rows
    /// that are never chosen.
    columns: Vec<Cdf>,
    /// ∫ L dω, as Σ over cells of mean radiance × Ω_r (exact for the bilinear radiance).
    integral: Vec3,
}

impl EnvironmentLight {
    /// The light of `environment`, whose image (if any) is one of `textures` (the scene's).
    /// An image that is not there, or has no texels, makes a black environment (with a
    /// warning): loaders never produce one, and a renderer should not fall over on it.
    pub fn new(environment: &Environment, textures: &[Texture]) -> Self {
        match *environment {
            Environment::Constant { radiance } => {
                Self { kind: Kind::Constant(sanitise(radiance)), strength: 1.0 }
            }
            Environment::Map { texture, intensity, rotation_deg } => {
                let image = textures.get(texture as usize).map(|t| &t.image).filter(|i| i.is_complete());
                match image {
                    Some(image) => Self {
                        kind: Kind::Map(Box::new(Map::new(image, intensity, rotation_deg))),
                        strength: 1.0,
                    },
                    None => {
                        tracing::warn!("environment texture {texture} is missing or empty; the sky is black");
                        Self { kind: Kind::Constant(Vec3::ZERO), strength: 1.0 }
                    }
                }
            }
        }
    }

    /// Sets the factor on every radiance (1: as loaded). The sampling densities do not
    /// change: the same directions matter, only brighter or darker.
    pub fn set_strength(&mut self, strength: f32) {
        self.strength = if strength.is_finite() { strength.max(0.0) } else { 1.0 };
    }

    /// The factor on every radiance.
    pub fn strength(&self) -> f32 {
        self.strength
    }

    /// Radiance arriving from the unit direction `dir` (world space).
    pub fn radiance(&self, dir: Vec3) -> Vec3 {
        self.strength
            * match &self.kind {
                Kind::Constant(radiance) => *radiance,
                Kind::Map(map) => map.radiance(equirect_uv(map.to_map(dir))),
            }
    }

    /// A direction importance-sampled from the two numbers `u` in [0, 1) (see the module
    /// doc); `None` for a black environment.
    pub fn sample(&self, u: Vec2) -> Option<EnvironmentSample> {
        match &self.kind {
            Kind::Constant(radiance) => (luminance(*radiance) > 0.0).then(|| EnvironmentSample {
                dir: direction_at(u.x, 1.0 - 2.0 * u.y),
                radiance: self.strength * *radiance,
                pdf: 1.0 / (4.0 * PI),
            }),
            Kind::Map(map) => {
                if map.rows.is_empty() {
                    return None;
                }
                let (row, _, within_row) = map.rows.sample_remapped(u.y);
                let (column, _, within_column) = map.columns[row].sample_remapped(u.x);
                let cos_theta =
                    map.cos_edges[row] + within_row * (map.cos_edges[row + 1] - map.cos_edges[row]);
                let m = direction_at((column as f32 + within_column) / map.width as f32, cos_theta);
                let dir = map.to_world(m);
                // The density is looked up from the direction itself, so it always equals
                // `pdf(dir)`, even where rounding puts a direction on a cell's edge.
                let pdf = self.pdf(dir);
                (pdf > 0.0).then(|| EnvironmentSample {
                    dir,
                    radiance: self.strength * map.radiance(equirect_uv(m)),
                    pdf,
                })
            }
        }
    }

    /// The density per unit solid angle with which [`EnvironmentLight::sample`] picks the
    /// unit direction `dir`; 0 for a black environment.
    pub fn pdf(&self, dir: Vec3) -> f32 {
        match &self.kind {
            Kind::Constant(radiance) => {
                if luminance(*radiance) > 0.0 {
                    1.0 / (4.0 * PI)
                } else {
                    0.0
                }
            }
            Kind::Map(map) => map.pdf(dir),
        }
    }

    /// ∫ L dω over the whole sphere (per channel): the environment's weight when choosing
    /// among light sources. 4π L for a constant environment.
    pub fn integral(&self) -> Vec3 {
        self.strength
            * match &self.kind {
                Kind::Constant(radiance) => 4.0 * PI * *radiance,
                Kind::Map(map) => map.integral,
            }
    }
}

/// Radiance with non-finite and negative channels zeroed and huge ones clamped.
fn sanitise(radiance: Vec3) -> Vec3 {
    Vec3::from_array(
        radiance.to_array().map(|c| if c.is_finite() && c > 0.0 { c.min(MAX_RADIANCE) } else { 0.0 }),
    )
}

impl Map {
    fn new(image: &Image, intensity: f32, rotation_deg: f32) -> Self {
        let (width, height) = (image.width as usize, image.height as usize);
        let intensity = if intensity.is_finite() { intensity.max(0.0) } else { 0.0 };
        let texels: Vec<Vec3> = (0..image.texels.len())
            .map(|i| {
                let [r, g, b, _] = image.texels.linear(i);
                sanitise(Vec3::new(r, g, b) * intensity)
            })
            .collect();
        let rotation =
            if rotation_deg.is_finite() { rotation_deg.to_radians().sin_cos() } else { (0.0, 1.0) };
        let cos_edges: Vec<f32> = (0..=height)
            .map(|r| match r {
                // Exact poles, so that the first and last rows reach ±Y.
                0 => 1.0,
                r if r == height => -1.0,
                r => (PI * r as f32 / height as f32).cos(),
            })
            .collect();
        let mut map = Self {
            width,
            height,
            texels,
            rotation,
            cos_edges,
            rows: Cdf::default(),
            columns: Vec::with_capacity(height),
            integral: Vec3::ZERO,
        };
        let mut row_weights = Vec::with_capacity(height);
        let mut integral = glam::DVec3::ZERO;
        for row in 0..height {
            let solid_angle = map.cell_solid_angle(row);
            let filter = row_mean(row, height);
            let means: Vec<Vec3> = (0..width).map(|column| map.cell_mean(row, column, filter)).collect();
            let columns = Cdf::new(means.iter().map(|&m| luminance(m)));
            row_weights.push(solid_angle * columns.total() as f32);
            let row_sum: glam::DVec3 = means.iter().map(|m| m.as_dvec3()).sum();
            integral += row_sum * f64::from(solid_angle);
            map.columns.push(columns);
        }
        map.rows = Cdf::new(row_weights);
        map.integral = integral.as_vec3();
        map
    }

    /// Ω_r: the solid angle of one cell of row `row`.
    fn cell_solid_angle(&self, row: usize) -> f32 {
        TAU / self.width as f32 * (self.cos_edges[row] - self.cos_edges[row + 1])
    }

    /// The texel at column `x` (wrapped) and row `y` (clamped).
    fn texel(&self, x: i64, y: i64) -> Vec3 {
        let x = x.rem_euclid(self.width as i64) as usize;
        let y = y.clamp(0, self.height as i64 - 1) as usize;
        self.texels[y * self.width + x]
    }

    /// The mean of the bilinear radiance over the solid angle of cell (`row`, `column`), with
    /// `filter` = [`row_mean`] of the row.
    fn cell_mean(&self, row: usize, column: usize, filter: [f32; 3]) -> Vec3 {
        let (row, column) = (row as i64, column as i64);
        let mut sum = Vec3::ZERO;
        for (dy, wy) in (-1..=1).zip(filter) {
            for (dx, wx) in (-1..=1).zip(COLUMN_MEAN) {
                sum += wy * wx * self.texel(column + dx, row + dy);
            }
        }
        sum
    }

    /// Bilinear radiance at image coordinates `uv` (texel centres at half-integer texels).
    fn radiance(&self, uv: Vec2) -> Vec3 {
        let x = uv.x * self.width as f32 - 0.5;
        let y = uv.y * self.height as f32 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (x0, y0) = (x0 as i64, y0 as i64);
        let top = self.texel(x0, y0).lerp(self.texel(x0 + 1, y0), fx);
        let bottom = self.texel(x0, y0 + 1).lerp(self.texel(x0 + 1, y0 + 1), fx);
        top.lerp(bottom, fy)
    }

    fn pdf(&self, dir: Vec3) -> f32 {
        if self.rows.is_empty() {
            return 0.0;
        }
        let uv = equirect_uv(self.to_map(dir));
        let column = ((uv.x * self.width as f32) as usize).min(self.width - 1);
        let row = ((uv.y * self.height as f32) as usize).min(self.height - 1);
        let p_row = self.rows.pmf(row);
        if p_row <= 0.0 {
            return 0.0;
        }
        p_row * self.columns[row].pmf(column) / self.cell_solid_angle(row)
    }

    /// World direction → direction in the unrotated map: R_y(−rotation).
    fn to_map(&self, d: Vec3) -> Vec3 {
        let (s, c) = self.rotation;
        Vec3::new(d.x * c - d.z * s, d.y, d.x * s + d.z * c)
    }

    /// Map direction → world direction: R_y(rotation).
    fn to_world(&self, m: Vec3) -> Vec3 {
        let (s, c) = self.rotation;
        Vec3::new(m.x * c + m.z * s, m.y, -m.x * s + m.z * c)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::hash32;

    /// 8 × 4 texels: a dim, slightly varying sky and one bright texel at column 2, row 1.
    const W: u32 = 8;
    const H: u32 = 4;
    const BRIGHT: (usize, usize) = (2, 1);

    fn sky() -> Texture {
        let texels = (0..H * W)
            .map(|i| {
                let (x, y) = ((i % W) as usize, (i / W) as usize);
                if (x, y) == BRIGHT {
                    [40.0, 30.0, 20.0, 1.0]
                } else {
                    [0.2 + 0.02 * x as f32, 0.3, 0.5 + 0.1 * y as f32, 1.0]
                }
            })
            .collect();
        Texture::from_linear("sky", W, H, texels)
    }

    fn light(intensity: f32, rotation_deg: f32) -> EnvironmentLight {
        EnvironmentLight::new(&Environment::Map { texture: 0, intensity, rotation_deg }, &[sky()])
    }

    /// The loader charges a sky image [`igi_scene::SKY_BYTES_PER_TEXEL`] per texel to the
    /// texture budget for what the map builds (its radiance and sampling tables), so the map
    /// holds no more than that.
    #[test]
    fn a_sky_map_holds_what_the_texture_budget_charged() {
        let Kind::Map(map) = light(1.0, 0.0).kind else { panic!("a map") };
        let radiance = map.texels.len() * size_of::<Vec3>();
        let tables: usize = map.columns.iter().map(|c| c.len() * 2 * size_of::<f32>()).sum();
        assert_eq!((radiance + tables) as u64, u64::from(W * H) * igi_scene::SKY_BYTES_PER_TEXEL);
    }

    /// The i-th of a fixed sequence of points in [0, 1)².
    fn random(i: u32) -> Vec2 {
        let a = hash32(2 * i) >> 8;
        let b = hash32(2 * i + 1) >> 8;
        Vec2::new(a as f32, b as f32) / (1u32 << 24) as f32
    }

    fn rotate_y(degrees: f32, m: Vec3) -> Vec3 {
        glam::Quat::from_rotation_y(degrees.to_radians()) * m
    }

    /// ∫ f(ω) dω by the midpoint rule on an n × n/2 grid in (azimuth, cos θ).
    fn integrate(n: usize, f: impl Fn(Vec3) -> f64) -> f64 {
        let (nu, nz) = (n, n / 2);
        let cell = 4.0 * std::f64::consts::PI / (nu * nz) as f64;
        let mut sum = 0.0;
        for j in 0..nz {
            let z = 1.0 - 2.0 * (j as f32 + 0.5) / nz as f32;
            for i in 0..nu {
                sum += f(direction_at((i as f32 + 0.5) / nu as f32, z));
            }
        }
        sum * cell
    }

    #[test]
    fn the_equirect_convention() {
        let close = |a: Vec2, b: Vec2| (a - b).length() < 1e-6;
        assert!(close(equirect_uv(Vec3::NEG_Z), Vec2::new(0.5, 0.5)), "centre: straight ahead");
        assert!(close(equirect_uv(Vec3::X), Vec2::new(0.75, 0.5)), "right of centre: +X");
        assert!(close(equirect_uv(Vec3::NEG_X), Vec2::new(0.25, 0.5)));
        assert!(close(equirect_uv(Vec3::Z), Vec2::new(0.0, 0.5)), "the seam");
        assert_eq!(equirect_uv(Vec3::Y).y, 0.0, "top row: up");
        assert_eq!(equirect_uv(Vec3::NEG_Y).y, 1.0);
        for i in 0..1000 {
            let uv = random(i);
            let back = equirect_uv(equirect_direction(uv));
            let du = (back.x - uv.x).abs();
            assert!(du.min(1.0 - du) < 1e-4 && (back.y - uv.y).abs() < 1e-4, "{uv} -> {back}");
        }
    }

    #[test]
    fn radiance_at_texel_centres_is_the_texel() {
        let texture = sky();
        for rotation in [0.0, 90.0, -33.0] {
            let env = light(2.0, rotation);
            for y in 0..H as usize {
                for x in 0..W as usize {
                    let centre = Vec2::new((x as f32 + 0.5) / W as f32, (y as f32 + 0.5) / H as f32);
                    let dir = rotate_y(rotation, equirect_direction(centre));
                    let [r, g, b, _] = texture.image.texels.linear(y * W as usize + x);
                    let expected = 2.0 * Vec3::new(r, g, b);
                    let got = env.radiance(dir);
                    assert!((got - expected).abs().max_element() < 1e-3 * expected.max_element(), "{got}");
                }
            }
        }
        // +90° turns the map's +Z seam to +X: the radiance there is the unrotated one at +Z.
        assert_eq!(light(1.0, 90.0).radiance(Vec3::X), light(1.0, 0.0).radiance(Vec3::Z));
        // Between texel centres the radiance interpolates; across the seam it wraps.
        let between = equirect_direction(Vec2::new(0.0, 0.5 / H as f32));
        let (first, last) = (texture.image.texels.linear(0), texture.image.texels.linear(W as usize - 1));
        let expected = 0.5 * (first[0] + last[0]);
        assert!((light(1.0, 0.0).radiance(between).x - expected).abs() < 1e-5);
    }

    #[test]
    fn pdf_integrates_to_one_and_sample_agrees_with_it() {
        for rotation in [0.0, 37.0] {
            let env = light(1.0, rotation);
            let total = integrate(1024, |d| f64::from(env.pdf(d)));
            assert!((total - 1.0).abs() < 2e-3, "∫ pdf dω = {total}");
            for i in 0..10_000 {
                let s = env.sample(random(i)).expect("a sample");
                assert!((s.dir.length() - 1.0).abs() < 1e-5);
                assert_eq!(s.pdf, env.pdf(s.dir));
                assert!(
                    (s.radiance - env.radiance(s.dir)).abs().max_element() < 1e-3 * s.radiance.max_element()
                );
            }
        }
    }

    #[test]
    fn samples_follow_the_pdf() {
        // Chi-square over 16 × 8 bins of the world (u, v), expected counts from the pdf by
        // quadrature. The bins do not line up with the (rotated) texels.
        let env = light(1.0, 37.0);
        let (bu, bv) = (16usize, 8usize);
        let bin = |d: Vec3| {
            let uv = equirect_uv(d);
            let u = ((uv.x * bu as f32) as usize).min(bu - 1);
            let v = ((uv.y * bv as f32) as usize).min(bv - 1);
            v * bu + u
        };
        let mut expected = vec![0.0f64; bu * bv];
        let (nu, nz) = (2048usize, 1024usize);
        let cell = 4.0 * std::f64::consts::PI / (nu * nz) as f64;
        for j in 0..nz {
            let z = 1.0 - 2.0 * (j as f32 + 0.5) / nz as f32;
            for i in 0..nu {
                let d = direction_at((i as f32 + 0.5) / nu as f32, z);
                expected[bin(d)] += f64::from(env.pdf(d)) * cell;
            }
        }
        let n = 200_000u32;
        let mut observed = vec![0u32; bu * bv];
        for i in 0..n {
            observed[bin(env.sample(random(i)).unwrap().dir)] += 1;
        }
        let chi2: f64 = observed
            .iter()
            .zip(&expected)
            .map(|(&o, &p)| {
                let e = p * f64::from(n);
                assert!(e > 5.0, "every bin is expected to be visited: {e}");
                (f64::from(o) - e).powi(2) / e
            })
            .sum();
        // 127 degrees of freedom: the 0.1 % critical value is about 181.
        assert!(chi2 < 181.0, "chi² = {chi2}");
    }

    #[test]
    fn the_bright_texel_is_sampled_by_its_share_of_the_luminance() {
        let env = light(1.0, 0.0);
        let in_bright = |d: Vec3| {
            let uv = equirect_uv(d);
            ((uv.x * W as f32) as usize, (uv.y * H as f32) as usize) == BRIGHT
        };
        let lum = |d: Vec3| f64::from(luminance(env.radiance(d)));
        let share = integrate(2048, |d| if in_bright(d) { lum(d) } else { 0.0 }) / integrate(2048, lum);
        let n = 100_000u32;
        let hits = (0..n).filter(|&i| in_bright(env.sample(random(i)).unwrap().dir)).count();
        let fraction = hits as f64 / f64::from(n);
        assert!(share > 0.3, "the bright texel dominates: {share}");
        assert!((fraction - share).abs() < 0.01 * share, "sampled {fraction}, share of ∫ luminance {share}");
    }

    #[test]
    fn row_filters_are_weights_of_the_interpolation_against_sin_theta() {
        for height in [1, 2, 4, 7, 64] {
            for row in 0..height {
                let w = row_mean(row, height);
                assert!((w.iter().sum::<f32>() - 1.0).abs() < 1e-5, "{w:?}");
                assert!(w.iter().all(|&x| x > 0.0), "{w:?}");
            }
        }
        // Near the equator of a fine map sin θ is flat over a cell: the plain ⅛, ¾, ⅛.
        let w = row_mean(500, 1000);
        assert!(w.iter().zip(COLUMN_MEAN).all(|(a, b)| (a - b).abs() < 1e-4), "{w:?}");
        // In the top row the row below holds more of the solid angle than the pole side.
        let w = row_mean(0, 4);
        assert!(w[2] > w[0], "{w:?}");
    }

    #[test]
    fn integral_over_the_sphere() {
        let c = Vec3::new(0.3, 0.5, 1.2);
        let constant = EnvironmentLight::new(&Environment::Constant { radiance: c }, &[]);
        assert!((constant.integral() - 4.0 * PI * c).abs().max_element() < 1e-6);
        assert_eq!(constant.pdf(Vec3::Y), 1.0 / (4.0 * PI));
        let s = constant.sample(Vec2::new(0.3, 0.8)).unwrap();
        assert_eq!((s.radiance, s.pdf), (c, 1.0 / (4.0 * PI)));
        assert!((s.dir.length() - 1.0).abs() < 1e-6);
        // A uniform image integrates exactly like a constant sky.
        let uniform = Texture::from_linear("grey", 5, 3, vec![[0.3, 0.5, 1.2, 1.0]; 15]);
        let map = EnvironmentLight::new(
            &Environment::Map { texture: 0, intensity: 1.0, rotation_deg: 10.0 },
            &[uniform],
        );
        assert!((map.integral() - 4.0 * PI * c).abs().max_element() < 1e-5);
        // The sky's integral matches quadrature of its radiance.
        let env = light(1.0, 0.0);
        for channel in 0..3 {
            let quadrature = integrate(2048, |d| f64::from(env.radiance(d)[channel]));
            let got = f64::from(env.integral()[channel]);
            assert!((got - quadrature).abs() < 1e-3 * quadrature, "channel {channel}: {got} vs {quadrature}");
        }
    }

    #[test]
    fn black_and_broken_environments_are_never_sampled() {
        let black = [
            EnvironmentLight::new(&Environment::Constant { radiance: Vec3::ZERO }, &[]),
            EnvironmentLight::new(
                &Environment::Map { texture: 0, intensity: 0.0, rotation_deg: 0.0 },
                &[sky()],
            ),
            EnvironmentLight::new(
                &Environment::Map { texture: 3, intensity: 1.0, rotation_deg: 0.0 },
                &[sky()],
            ),
            EnvironmentLight::new(
                &Environment::Constant { radiance: Vec3::new(f32::NAN, -1.0, f32::INFINITY) },
                &[],
            ),
        ];
        for env in black {
            assert_eq!(env.sample(Vec2::new(0.5, 0.5)), None);
            assert_eq!(env.pdf(Vec3::Y), 0.0);
            assert_eq!(env.integral(), Vec3::ZERO);
            assert_eq!(env.radiance(Vec3::X), Vec3::ZERO);
        }
    }
}
