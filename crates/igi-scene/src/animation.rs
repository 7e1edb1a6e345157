//! Keyframe animation: how instances and lights move with the scene clock.
//!
//! An [`Animation`] is a forest of transform nodes ([`AnimationNode`]), each with optional
//! translation, rotation and scale [`Track`]s, the instances those nodes carry, and the lights
//! that are keyed directly or ride on a node. [`Animation::pose`] evaluates all of it at a
//! time in seconds; the renderer moves its instances and lights to the result every frame and
//! recomputes the whole illumination (paper section 1: nothing is cached between frames).
//!
//! Interpolation follows glTF 2.0 (section 3.11, Appendix C): `Step` holds a key's value,
//! `Linear` interpolates linearly (quaternions by slerp, the shorter way), `Cubic` is a
//! Hermite spline through the keys with given in- and out-tangents (glTF `CUBICSPLINE`;
//! quaternions are normalised afterwards). The scene file's `smooth` is `Cubic` with
//! Catmull-Rom tangents (Catmull & Rom 1974), computed for uneven key spacing, and zero
//! tangents at the first and last key, so a motion eases in and out there.

use crate::light::Light;
use glam::{Affine3A, EulerRot, Quat, Vec3};

/// How a track interpolates between two keys.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Interpolation {
    /// The earlier key's value, until the next key.
    Step,
    /// Linear (slerp for rotations).
    Linear,
    /// Cubic Hermite with the track's tangents.
    Cubic,
}

/// A value that tracks can interpolate.
pub trait Keyable: Copy + std::fmt::Debug + PartialEq {
    /// The value a fraction `s` ∈ [0, 1] of the way from `a` to `b`.
    fn lerp(a: Self, b: Self, s: f32) -> Self;
    /// `a·x + b·y` (the terms of a Hermite basis).
    fn combine(terms: [(f32, Self); 4]) -> Self;
    /// The value after a cubic combination (unit length for rotations).
    fn finish(self) -> Self {
        self
    }
    /// (b − a) / dt: a finite-difference slope.
    fn slope(a: Self, b: Self, dt: f32) -> Self;
    /// The zero slope.
    const ZERO: Self;
}

impl Keyable for f32 {
    fn lerp(a: Self, b: Self, s: f32) -> Self {
        a + (b - a) * s
    }
    fn combine(terms: [(f32, Self); 4]) -> Self {
        terms.iter().map(|(w, v)| w * v).sum()
    }
    fn slope(a: Self, b: Self, dt: f32) -> Self {
        (b - a) / dt
    }
    const ZERO: Self = 0.0;
}

impl Keyable for Vec3 {
    fn lerp(a: Self, b: Self, s: f32) -> Self {
        a + (b - a) * s
    }
    fn combine(terms: [(f32, Self); 4]) -> Self {
        terms.iter().map(|&(w, v)| w * v).sum()
    }
    fn slope(a: Self, b: Self, dt: f32) -> Self {
        (b - a) / dt
    }
    const ZERO: Self = Vec3::ZERO;
}

impl Keyable for Quat {
    fn lerp(a: Self, b: Self, s: f32) -> Self {
        a.slerp(b, s)
    }
    fn combine(terms: [(f32, Self); 4]) -> Self {
        let v = terms.iter().fold(glam::Vec4::ZERO, |acc, &(w, q)| acc + w * glam::Vec4::from(q));
        Quat::from_vec4(v)
    }
    /// A cubic blend of opposite keys can pass through zero; that pose has no rotation to
    /// normalise, and identity keeps it finite rather than NaN.
    fn finish(self) -> Self {
        glam::Vec4::from(self).try_normalize().map_or(Quat::IDENTITY, Quat::from_vec4)
    }
    fn slope(a: Self, b: Self, dt: f32) -> Self {
        Quat::from_vec4((glam::Vec4::from(b) - glam::Vec4::from(a)) / dt)
    }
    const ZERO: Self = Quat::from_xyzw(0.0, 0.0, 0.0, 0.0);
}

/// What is wrong with a track's keys.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum TrackError {
    /// No keys at all.
    #[error("a track needs at least one key")]
    Empty,
    /// A time that is negative, infinite or NaN.
    #[error("key time {0} is not a finite number ≥ 0")]
    BadTime(f32),
    /// Times that do not increase.
    #[error("key times must increase strictly ({0} follows {1})")]
    NotIncreasing(f32, f32),
    /// A value count that does not match the times.
    #[error("{values} values for {keys} keys")]
    Count {
        /// Keys (times).
        keys: usize,
        /// Values given.
        values: usize,
    },
    /// A value that is infinite or NaN.
    #[error("a key value is not finite")]
    NotFinite,
}

/// Keyframes of one animated quantity.
#[derive(Clone, Debug, PartialEq)]
pub struct Track<T: Keyable> {
    times: Vec<f32>,
    values: Vec<T>,
    /// Per key, the (incoming, outgoing) tangents, in value units per second (`Cubic` only).
    tangents: Vec<(T, T)>,
    interpolation: Interpolation,
    /// With `Some(p)`, the track repeats with period `p` ≥ its last key time.
    period: Option<f32>,
}

fn check_times(times: &[f32]) -> Result<(), TrackError> {
    if times.is_empty() {
        return Err(TrackError::Empty);
    }
    if let Some(&t) = times.iter().find(|t| !(t.is_finite() && **t >= 0.0)) {
        return Err(TrackError::BadTime(t));
    }
    if let Some(w) = times.windows(2).find(|w| w[1] <= w[0]) {
        return Err(TrackError::NotIncreasing(w[1], w[0]));
    }
    Ok(())
}

impl<T: Keyable> Track<T> {
    /// A track that holds each key's value until the next key.
    pub fn step(times: Vec<f32>, values: Vec<T>) -> Result<Self, TrackError>
    where
        T: Finite,
    {
        Self::keys(times, values, Interpolation::Step)
    }

    /// A track that interpolates linearly between keys (slerp for rotations).
    pub fn linear(times: Vec<f32>, values: Vec<T>) -> Result<Self, TrackError>
    where
        T: Finite,
    {
        Self::keys(times, values, Interpolation::Linear)
    }

    fn keys(times: Vec<f32>, values: Vec<T>, interpolation: Interpolation) -> Result<Self, TrackError>
    where
        T: Finite,
    {
        check_times(&times)?;
        if values.len() != times.len() {
            return Err(TrackError::Count { keys: times.len(), values: values.len() });
        }
        if !values.iter().all(Finite::is_finite) {
            return Err(TrackError::NotFinite);
        }
        Ok(Self { times, values, tangents: Vec::new(), interpolation, period: None })
    }

    /// A Hermite spline with explicit (incoming, outgoing) tangents per key, as glTF's
    /// `CUBICSPLINE` stores them.
    pub fn cubic(times: Vec<f32>, values: Vec<T>, tangents: Vec<(T, T)>) -> Result<Self, TrackError>
    where
        T: Finite,
    {
        let mut track = Self::linear(times, values)?;
        if tangents.len() != track.times.len() {
            return Err(TrackError::Count { keys: track.times.len(), values: tangents.len() });
        }
        if !tangents.iter().all(|(a, b)| a.is_finite() && b.is_finite()) {
            return Err(TrackError::NotFinite);
        }
        track.tangents = tangents;
        track.interpolation = Interpolation::Cubic;
        Ok(track)
    }

    /// A smooth curve through the keys: Catmull-Rom tangents (the slope between the two
    /// neighbouring keys, for uneven spacing), zero at the first and last key.
    pub fn smooth(times: Vec<f32>, values: Vec<T>) -> Result<Self, TrackError>
    where
        T: Finite,
    {
        let track = Self::linear(times, values)?;
        let n = track.times.len();
        let tangents = (0..n)
            .map(|k| {
                if k == 0 || k + 1 == n {
                    return (T::ZERO, T::ZERO);
                }
                let m = T::slope(
                    track.values[k - 1],
                    track.values[k + 1],
                    track.times[k + 1] - track.times[k - 1],
                );
                (m, m)
            })
            .collect();
        Self::cubic(track.times, track.values, tangents)
    }

    /// Makes the track repeat with `period` (at least its last key time; a shorter period is
    /// raised to it).
    pub fn looping(mut self, period: f32) -> Self {
        let last = *self.times.last().expect("a track has keys");
        self.period = Some(if period.is_finite() { period.max(last) } else { last });
        self
    }

    /// Time of the last key.
    pub fn end(&self) -> f32 {
        *self.times.last().expect("a track has keys")
    }

    /// The value at time `t` (seconds). Before the first key the first value holds, after the
    /// last the last value (within each period of a looping track).
    pub fn sample(&self, t: f32) -> T {
        let t = match self.period {
            Some(p) if p > 0.0 && t.is_finite() => t.rem_euclid(p),
            _ => t,
        };
        let times = &self.times;
        // The first key later than t; NaN compares false and lands on the first key.
        let next = times.partition_point(|&k| k <= t);
        if next == 0 {
            return self.values[0];
        }
        if next == times.len() {
            return self.values[next - 1];
        }
        let (k, dt) = (next - 1, times[next] - times[next - 1]);
        let s = ((t - times[k]) / dt).clamp(0.0, 1.0);
        let (a, b) = (self.values[k], self.values[next]);
        match self.interpolation {
            Interpolation::Step => a,
            Interpolation::Linear => T::lerp(a, b, s),
            Interpolation::Cubic => {
                let (s2, s3) = (s * s, s * s * s);
                let h00 = 2.0 * s3 - 3.0 * s2 + 1.0;
                let h10 = s3 - 2.0 * s2 + s;
                let h01 = -2.0 * s3 + 3.0 * s2;
                let h11 = s3 - s2;
                let m0 = self.tangents[k].1;
                let m1 = self.tangents[next].0;
                T::combine([(h00, a), (h10 * dt, m0), (h01, b), (h11 * dt, m1)]).finish()
            }
        }
    }
}

/// Values whose components can be checked for finiteness.
pub trait Finite {
    /// True if every component is finite.
    fn is_finite(&self) -> bool;
}

impl Finite for f32 {
    fn is_finite(&self) -> bool {
        f32::is_finite(*self)
    }
}

impl Finite for Vec3 {
    fn is_finite(&self) -> bool {
        Vec3::is_finite(*self)
    }
}

impl Finite for Quat {
    fn is_finite(&self) -> bool {
        Quat::is_finite(*self)
    }
}

/// A rotation track: quaternions (glTF), or Euler angles in degrees (scene files), which can
/// turn by more than half a revolution between two keys.
#[derive(Clone, Debug, PartialEq)]
pub enum RotationTrack {
    /// Unit quaternions.
    Quaternion(Track<Quat>),
    /// Degrees about X, Y and Z, applied as R = Rz·Ry·Rx (the scene file's convention).
    EulerDegrees(Track<Vec3>),
}

impl RotationTrack {
    /// The rotation at time `t`.
    pub fn sample(&self, t: f32) -> Quat {
        match self {
            Self::Quaternion(track) => track.sample(t),
            Self::EulerDegrees(track) => euler_degrees(track.sample(t)),
        }
    }

    fn end(&self) -> f32 {
        match self {
            Self::Quaternion(track) => track.end(),
            Self::EulerDegrees(track) => track.end(),
        }
    }
}

/// The rotation R = Rz·Ry·Rx for angles in degrees about X, Y and Z.
pub fn euler_degrees(degrees: Vec3) -> Quat {
    let r = degrees * (std::f32::consts::PI / 180.0);
    Quat::from_euler(EulerRot::ZYX, r.z, r.y, r.x)
}

/// A transform node: its local transform relative to its parent, from tracks where it has
/// them and from `rest` elsewhere.
#[derive(Clone, Debug, PartialEq)]
pub struct AnimationNode {
    /// The parent node (an index lower than this node's), or `None` for a root.
    pub parent: Option<u32>,
    /// The local transform without animation. With any track, it is decomposed into
    /// translation, rotation and scale and the tracks replace their parts.
    pub rest: Affine3A,
    /// Translation keys.
    pub translation: Option<Track<Vec3>>,
    /// Rotation keys.
    pub rotation: Option<RotationTrack>,
    /// Scale keys.
    pub scale: Option<Track<Vec3>>,
}

impl AnimationNode {
    /// A node that does not move relative to its parent.
    pub fn fixed(parent: Option<u32>, rest: Affine3A) -> Self {
        Self { parent, rest, translation: None, rotation: None, scale: None }
    }

    /// True if the node has a track.
    pub fn is_animated(&self) -> bool {
        self.translation.is_some() || self.rotation.is_some() || self.scale.is_some()
    }

    /// The local transform T·R·S at time `t`.
    pub fn local(&self, t: f32) -> Affine3A {
        if !self.is_animated() {
            return self.rest;
        }
        let (scale, rotation, translation) = self.rest.to_scale_rotation_translation();
        Affine3A::from_scale_rotation_translation(
            self.scale.as_ref().map_or(scale, |track| track.sample(t)),
            self.rotation.as_ref().map_or(rotation, |track| track.sample(t)),
            self.translation.as_ref().map_or(translation, |track| track.sample(t)),
        )
    }

    fn end(&self) -> f32 {
        let ends = [
            self.translation.as_ref().map(Track::end),
            self.rotation.as_ref().map(RotationTrack::end),
            self.scale.as_ref().map(Track::end),
        ];
        ends.into_iter().flatten().fold(0.0, f32::max)
    }
}

/// An instance carried by a node: its transform is the node's world transform times `local`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AnimatedInstance {
    /// Index into [`Scene::instances`](crate::Scene::instances).
    pub instance: u32,
    /// The node carrying it.
    pub node: u32,
    /// Transform from the mesh to the node.
    pub local: Affine3A,
}

/// A light that moves or changes: keyed position, direction and power, and optionally carried
/// by a node (a glTF light on an animated node, a lamp fixed to a swinging arm).
#[derive(Clone, Debug, PartialEq)]
pub struct AnimatedLight {
    /// Index into [`Scene::lights`](crate::Scene::lights).
    pub light: u32,
    /// The light in the space of its node (or in world space without a node), before tracks.
    pub rest: Light,
    /// The node carrying the light.
    pub node: Option<u32>,
    /// Position keys (point and spot lights), in the node's space.
    pub position: Option<Track<Vec3>>,
    /// Direction keys (spot and directional lights), normalised after interpolation.
    pub direction: Option<Track<Vec3>>,
    /// Keys of the light's RGB power: intensity (W/sr) of point and spot lights, irradiance
    /// (W/m²) of directional lights.
    pub power: Option<Track<Vec3>>,
}

impl AnimatedLight {
    fn end(&self) -> f32 {
        let ends =
            [self.position.as_ref(), self.direction.as_ref(), self.power.as_ref()].map(|t| t.map(Track::end));
        ends.into_iter().flatten().fold(0.0, f32::max)
    }

    /// The light at time `t`, given its node's world transform.
    fn at(&self, t: f32, node: Option<&Affine3A>) -> Light {
        let mut light = self.rest.clone();
        let position = self.position.as_ref().map(|track| track.sample(t));
        let direction = self.direction.as_ref().map(|track| track.sample(t));
        let power = self.power.as_ref().map(|track| track.sample(t).max(Vec3::ZERO));
        let place = |p: Vec3| node.map_or(p, |m| m.transform_point3(p));
        let turn = |d: Vec3| {
            let d = node.map_or(d, |m| m.transform_vector3(d));
            d.try_normalize().unwrap_or(Vec3::NEG_Y)
        };
        match &mut light {
            Light::Point { position: p, intensity } => {
                *p = place(position.unwrap_or(*p));
                *intensity = power.unwrap_or(*intensity);
            }
            Light::Spot { position: p, direction: d, intensity, .. } => {
                *p = place(position.unwrap_or(*p));
                *d = turn(direction.unwrap_or(*d));
                *intensity = power.unwrap_or(*intensity);
            }
            Light::Directional { direction: d, irradiance } => {
                *d = turn(direction.unwrap_or(*d));
                *irradiance = power.unwrap_or(*irradiance);
            }
        }
        light
    }
}

/// Everything in a scene that moves with the clock.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Animation {
    /// Transform nodes; a parent comes before its children.
    pub nodes: Vec<AnimationNode>,
    /// Instances placed by nodes (instances not listed stand still).
    pub instances: Vec<AnimatedInstance>,
    /// Lights that move or change (lights not listed stand still).
    pub lights: Vec<AnimatedLight>,
}

/// The instances and lights of an [`Animation`] at one time.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Pose {
    /// (instance index, object-to-world transform) of every animated instance.
    pub instances: Vec<(u32, Affine3A)>,
    /// (light index, light) of every animated light.
    pub lights: Vec<(u32, Light)>,
}

impl Animation {
    /// True if nothing is animated.
    pub fn is_empty(&self) -> bool {
        self.instances.is_empty() && self.lights.is_empty()
    }

    /// The time of the last key of any track (one cycle of the longest animation).
    pub fn duration(&self) -> f32 {
        let nodes = self.nodes.iter().map(AnimationNode::end);
        let lights = self.lights.iter().map(AnimatedLight::end);
        nodes.chain(lights).fold(0.0, f32::max)
    }

    /// Every node's world transform at time `t`.
    pub fn node_transforms(&self, t: f32) -> Vec<Affine3A> {
        let mut world: Vec<Affine3A> = Vec::with_capacity(self.nodes.len());
        for node in &self.nodes {
            let local = node.local(t);
            // Parents precede children (checked by `validate`), so the parent is done.
            let m = match node.parent.and_then(|p| world.get(p as usize)) {
                Some(parent) => *parent * local,
                None => local,
            };
            world.push(m);
        }
        world
    }

    /// The animated instances and lights at time `t` (seconds on the scene clock).
    pub fn pose(&self, t: f32) -> Pose {
        let world = self.node_transforms(t);
        let instances = self
            .instances
            .iter()
            .map(|a| (a.instance, world.get(a.node as usize).map_or(a.local, |m| *m * a.local)))
            .collect();
        let lights = self
            .lights
            .iter()
            .map(|a| (a.light, a.at(t, a.node.and_then(|n| world.get(n as usize)))))
            .collect();
        Pose { instances, lights }
    }

    /// Checks the references: parents before children, nodes, instances and lights in range.
    pub fn validate(&self, instances: usize, lights: usize) -> Result<(), String> {
        for (i, node) in self.nodes.iter().enumerate() {
            if node.parent.is_some_and(|p| p as usize >= i) {
                return Err(format!("animation node {i} comes before its parent"));
            }
        }
        let node_ok = |n: u32| (n as usize) < self.nodes.len();
        for a in &self.instances {
            if a.instance as usize >= instances || !node_ok(a.node) {
                return Err(format!("animated instance {} (node {}) is out of range", a.instance, a.node));
            }
        }
        for a in &self.lights {
            if a.light as usize >= lights || a.node.is_some_and(|n| !node_ok(n)) {
                return Err(format!("animated light {} is out of range", a.light));
            }
        }
        Ok(())
    }

    /// Appends `other`, whose instance and light indices start at the given offsets in the
    /// combined scene; its root nodes become children of `root`.
    pub fn append(&mut self, other: &Animation, instance_base: u32, light_base: u32, root: Option<u32>) {
        let node_base = self.nodes.len() as u32;
        self.nodes.extend(
            other
                .nodes
                .iter()
                .map(|n| AnimationNode { parent: n.parent.map(|p| p + node_base).or(root), ..n.clone() }),
        );
        self.instances.extend(other.instances.iter().map(|a| AnimatedInstance {
            instance: a.instance + instance_base,
            node: a.node + node_base,
            local: a.local,
        }));
        self.lights.extend(other.lights.iter().map(|a| AnimatedLight {
            light: a.light + light_base,
            node: a.node.map(|n| n + node_base).or(root),
            ..a.clone()
        }));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f32, b: f32) -> bool {
        (a - b).abs() < 1e-5
    }

    #[test]
    fn linear_and_step_values_by_hand() {
        let times = vec![1.0, 3.0, 4.0];
        let values = vec![10.0, 20.0, 0.0];
        let linear = Track::linear(times.clone(), values.clone()).unwrap();
        let step = Track::step(times, values).unwrap();
        for (t, l, s) in
            [(0.0, 10.0, 10.0), (1.0, 10.0, 10.0), (2.0, 15.0, 10.0), (3.5, 10.0, 20.0), (9.0, 0.0, 0.0)]
        {
            assert!(close(linear.sample(t), l), "linear at {t}: {}", linear.sample(t));
            assert!(close(step.sample(t), s), "step at {t}: {}", step.sample(t));
        }
    }

    #[test]
    fn smooth_passes_through_keys_and_eases_at_the_ends() {
        let track = Track::smooth(vec![0.0, 1.0, 3.0], vec![0.0, 2.0, 2.0]).unwrap();
        assert!(
            close(track.sample(0.0), 0.0) && close(track.sample(1.0), 2.0) && close(track.sample(3.0), 2.0)
        );
        // Middle tangent (2 - 0) / 3; first segment h10 = 0, h11 = s³ − s² at s = 1/2 is -1/8:
        // 0·h00 + 2·h01(1/2) + dt·m1·h11 = 1 − 1/12.
        assert!(close(track.sample(0.5), 1.0 - 1.0 / 12.0), "{}", track.sample(0.5));
        // Zero slope at the first key: the value barely moves at first.
        assert!(track.sample(0.01) < 0.001);
    }

    #[test]
    fn cubic_uses_the_given_tangents() {
        // p(s) with p0 = 0, p1 = 0, m0 = 1, m1 = 0 over dt = 2: 2·h10(s).
        let track = Track::cubic(vec![0.0, 2.0], vec![0.0, 0.0], vec![(0.0, 1.0), (0.0, 0.0)]).unwrap();
        let s: f32 = 0.25;
        assert!(close(track.sample(0.5), 2.0 * (s.powi(3) - 2.0 * s * s + s)));
    }

    #[test]
    fn looping_wraps_time_and_holds_past_the_last_key() {
        let track = Track::linear(vec![0.0, 2.0], vec![0.0, 4.0]).unwrap().looping(3.0);
        assert!(close(track.sample(1.0), 2.0));
        assert!(close(track.sample(2.5), 4.0));
        assert!(close(track.sample(4.0), 2.0));
        assert!(close(track.sample(-2.0), 2.0));
    }

    #[test]
    fn quaternions_slerp_the_short_way() {
        let a = Quat::IDENTITY;
        let b = -Quat::from_rotation_y(std::f32::consts::FRAC_PI_2); // same rotation, sign flipped
        let track = Track::linear(vec![0.0, 1.0], vec![a, b]).unwrap();
        let mid = track.sample(0.5);
        let expected = Quat::from_rotation_y(std::f32::consts::FRAC_PI_4);
        assert!(mid.dot(expected).abs() > 1.0 - 1e-5, "{mid:?}");
    }

    #[test]
    fn a_cubic_through_the_zero_quaternion_poses_as_identity() {
        // Keys q and -q with zero tangents: the Hermite blend at s = 1/2 is exactly zero.
        let q = Quat::from_rotation_x(1.0);
        let zero = Quat::from_xyzw(0.0, 0.0, 0.0, 0.0);
        let track = Track::cubic(vec![0.0, 1.0], vec![q, -q], vec![(zero, zero), (zero, zero)]).unwrap();
        assert_eq!(track.sample(0.5), Quat::IDENTITY);
        assert!(track.sample(0.25).is_normalized());
    }

    #[test]
    fn euler_tracks_turn_a_full_revolution() {
        let track = Track::linear(vec![0.0, 4.0], vec![Vec3::ZERO, Vec3::new(0.0, 360.0, 0.0)]).unwrap();
        let rotation = RotationTrack::EulerDegrees(track);
        let half = rotation.sample(2.0) * Vec3::X;
        assert!((half - Vec3::NEG_X).length() < 1e-5, "{half}");
    }

    #[test]
    fn bad_keys_are_rejected() {
        assert_eq!(Track::<f32>::linear(vec![], vec![]), Err(TrackError::Empty));
        assert_eq!(Track::linear(vec![1.0, 1.0], vec![0.0, 0.0]), Err(TrackError::NotIncreasing(1.0, 1.0)));
        assert_eq!(Track::linear(vec![-1.0], vec![0.0]), Err(TrackError::BadTime(-1.0)));
        assert_eq!(Track::linear(vec![0.0], vec![f32::NAN]), Err(TrackError::NotFinite));
        assert_eq!(Track::linear(vec![0.0], vec![0.0, 1.0]), Err(TrackError::Count { keys: 1, values: 2 }));
    }

    #[test]
    fn nodes_compose_parent_first_and_carry_lights() {
        let spin = Track::linear(
            vec![0.0, 1.0],
            vec![Quat::IDENTITY, Quat::from_rotation_y(std::f32::consts::FRAC_PI_2)],
        )
        .unwrap();
        let animation = Animation {
            nodes: vec![
                AnimationNode {
                    rotation: Some(RotationTrack::Quaternion(spin)),
                    ..AnimationNode::fixed(None, Affine3A::IDENTITY)
                },
                AnimationNode::fixed(Some(0), Affine3A::from_translation(Vec3::X)),
            ],
            instances: vec![AnimatedInstance { instance: 0, node: 1, local: Affine3A::IDENTITY }],
            lights: vec![AnimatedLight {
                light: 0,
                rest: Light::Point { position: Vec3::ZERO, intensity: Vec3::ONE },
                node: Some(1),
                position: None,
                direction: None,
                power: Some(Track::linear(vec![0.0, 1.0], vec![Vec3::ZERO, Vec3::splat(2.0)]).unwrap()),
            }],
        };
        animation.validate(1, 1).unwrap();
        let pose = animation.pose(1.0);
        // The child sits at +X of the parent, which has turned 90° about Y: +X goes to −Z.
        let moved = pose.instances[0].1.transform_point3(Vec3::ZERO);
        assert!((moved - Vec3::NEG_Z).length() < 1e-5, "{moved}");
        match pose.lights[0].1 {
            Light::Point { position, intensity } => {
                assert!((position - Vec3::NEG_Z).length() < 1e-5);
                assert_eq!(intensity, Vec3::splat(2.0));
            }
            ref other => panic!("{other:?}"),
        }
        assert_eq!(animation.duration(), 1.0);
    }
}
