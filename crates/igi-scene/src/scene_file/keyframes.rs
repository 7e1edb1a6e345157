//! Keyframes of scene-file entries: the checks of an `animation` table's keys, the track of
//! each keyed field, and the looping of an entry's tracks with one period.

use std::ops::Range;

use glam::Vec3;

use super::checker::Checker;
use super::schema::{AnimationSpec, InterpolationKind, KeySpec};
use crate::animation::{Finite, Keyable, Track};
use crate::error::SceneError;

impl Checker<'_> {
    /// Checks an `animation` table's keys: at least one, times finite and ≥ 0, and only the
    /// fields in `allowed` (`entry` names the kind of entry in the message).
    pub(super) fn keys(
        &self,
        span: &Range<usize>,
        path: &str,
        spec: &AnimationSpec,
        allowed: &[&str],
        entry: &str,
    ) -> Result<(), SceneError> {
        if spec.keys.is_empty() {
            return Err(self.error(span, format!("{path}keys"), "an animation needs at least one key"));
        }
        for (k, key) in spec.keys.iter().enumerate() {
            if !(key.time.is_finite() && key.time >= 0.0) {
                return Err(self.error(
                    span,
                    format!("{path}keys[{k}].time"),
                    "must be a finite number of seconds ≥ 0",
                ));
            }
            self.allowed_fields(
                span,
                &key.present(),
                allowed,
                |field| format!("{path}keys[{k}].{field}"),
                |field| format!("{entry} cannot animate `{field}` (it can: {})", allowed.join(", ")),
            )?;
        }
        Ok(())
    }

    /// The track of one field over the keys that set it (`None` if no key does); `value`
    /// reads and checks a key's value, given the field's path for messages.
    pub(super) fn track<T: Keyable + Finite>(
        &self,
        span: &Range<usize>,
        path: &str,
        spec: &AnimationSpec,
        field: &str,
        value: impl Fn(&KeySpec, String) -> Result<Option<T>, SceneError>,
    ) -> Result<Option<Track<T>>, SceneError> {
        let mut times = Vec::new();
        let mut values = Vec::new();
        for (k, key) in spec.keys.iter().enumerate() {
            if let Some(v) = value(key, format!("{path}keys[{k}].{field}"))? {
                times.push(key.time);
                values.push(v);
            }
        }
        if times.is_empty() {
            return Ok(None);
        }
        let track = match spec.interpolation.unwrap_or(InterpolationKind::Linear) {
            InterpolationKind::Step => Track::step(times, values),
            InterpolationKind::Linear => Track::linear(times, values),
            InterpolationKind::Smooth => Track::smooth(times, values),
        };
        track.map(Some).map_err(|e| self.error(span, format!("{path}keys"), format!("`{field}` keys: {e}")))
    }

    /// The track of a position or angles field (`translate`, `rotate`, `position`), read from
    /// each key by `value`: finite vectors.
    pub(super) fn vector_track(
        &self,
        span: &Range<usize>,
        path: &str,
        spec: &AnimationSpec,
        field: &str,
        value: impl Fn(&KeySpec) -> Option<[f32; 3]>,
    ) -> Result<Option<Track<Vec3>>, SceneError> {
        self.track(span, path, spec, field, |key, at| {
            value(key).map(|v| self.vector(span, at, v)).transpose()
        })
    }
}

/// Makes the tracks of one entry repeat with the entry's period (the last key time of any of
/// them), if the entry loops (`loop`, default true).
pub(super) fn looped<const N: usize>(
    tracks: [Option<Track<Vec3>>; N],
    spec: &AnimationSpec,
) -> [Option<Track<Vec3>>; N] {
    let period = tracks.iter().flatten().map(Track::end).fold(0.0, f32::max);
    tracks.map(|track| track.map(|t| if spec.looping.unwrap_or(true) { t.looping(period) } else { t }))
}
