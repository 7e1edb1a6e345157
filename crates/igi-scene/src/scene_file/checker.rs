//! [`Checker`]: the checks of values a scene file gives (finite, in range, non-zero), with
//! errors that point at the field's own line; and `toml`'s errors pointed at a line and field
//! the same way.

use std::ops::Range;
use std::path::Path;

use glam::{Affine3A, Vec3};

use super::field_spans;
use super::schema::Scale;
use crate::animation::euler_degrees;
use crate::error::{Location, SceneError};

/// Turns semantic problems into errors that point at a field of the file.
pub(super) struct Checker<'a> {
    pub(super) file: &'a Path,
    pub(super) text: &'a str,
}

impl Checker<'_> {
    /// An error about the field at `path`, at the line of its value, or else (a default
    /// that is not in the file) of `span`, its table's.
    pub(super) fn error(&self, span: &Range<usize>, path: String, message: impl Into<String>) -> SceneError {
        let at = field_spans::value_span(self.text, &path).map_or(span.start, |value| value.start);
        SceneError::invalid(self.file, Location::Field { line: Some(line_of(self.text, at)), path }, message)
    }

    /// Refuses the first field of `present` that is set but not `allowed`: the error is at
    /// `path(field)` and says `message(field)`.
    pub(super) fn allowed_fields(
        &self,
        span: &Range<usize>,
        present: &[(&str, bool)],
        allowed: &[&str],
        path: impl Fn(&str) -> String,
        message: impl Fn(&str) -> String,
    ) -> Result<(), SceneError> {
        match present.iter().find(|&&(field, is_present)| is_present && !allowed.contains(&field)) {
            Some(&(field, _)) => Err(self.error(span, path(field), message(field))),
            None => Ok(()),
        }
    }

    pub(super) fn vector(&self, span: &Range<usize>, path: String, v: [f32; 3]) -> Result<Vec3, SceneError> {
        self.vector_at(span, || path, v)
    }

    /// [`Checker::vector`] with the path formatted only for a message.
    fn vector_at(
        &self,
        span: &Range<usize>,
        path: impl FnOnce() -> String,
        v: [f32; 3],
    ) -> Result<Vec3, SceneError> {
        let v = Vec3::from(v);
        if v.is_finite() { Ok(v) } else { Err(self.error(span, path(), "values must be finite")) }
    }

    pub(super) fn colour(&self, span: &Range<usize>, path: String, v: [f32; 3]) -> Result<Vec3, SceneError> {
        let c = self.vector(span, path.clone(), v)?;
        if c.min_element() < 0.0 {
            return Err(self.error(span, path, "values must not be negative"));
        }
        Ok(c)
    }

    /// A reflectance: finite and in [0, 1].
    pub(super) fn reflectance(
        &self,
        span: &Range<usize>,
        path: String,
        v: [f32; 3],
    ) -> Result<Vec3, SceneError> {
        let c = self.colour(span, path.clone(), v)?;
        if c.max_element() > 1.0 {
            return Err(self.error(span, path, "reflectance must be in [0, 1]"));
        }
        Ok(c)
    }

    /// A finite number that is positive (`zero_ok` false) or not negative (`zero_ok` true).
    pub(super) fn amount(
        &self,
        span: &Range<usize>,
        path: String,
        value: f32,
        zero_ok: bool,
    ) -> Result<f32, SceneError> {
        let ok = value.is_finite() && if zero_ok { value >= 0.0 } else { value > 0.0 };
        if ok {
            Ok(value)
        } else if zero_ok {
            Err(self.error(span, path, "must be finite and not negative"))
        } else {
            Err(self.error(span, path, "must be finite and positive"))
        }
    }

    pub(super) fn direction(
        &self,
        span: &Range<usize>,
        path: String,
        v: [f32; 3],
    ) -> Result<Vec3, SceneError> {
        self.vector(span, path.clone(), v)?
            .try_normalize()
            .ok_or_else(|| self.error(span, path, "direction must not be zero"))
    }

    /// The placement of `translate`, `rotate` (degrees) and `scale`; `path` is the prefix of
    /// their field paths, formatted only for a message (instance lists are long).
    pub(super) fn transform(
        &self,
        span: &Range<usize>,
        path: impl Fn() -> String,
        translate: Option<[f32; 3]>,
        rotate: Option<[f32; 3]>,
        scale: Option<Scale>,
    ) -> Result<Affine3A, SceneError> {
        let translation =
            self.vector_at(span, || format!("{}translate", path()), translate.unwrap_or_default())?;
        let degrees = self.vector_at(span, || format!("{}rotate", path()), rotate.unwrap_or_default())?;
        let scale = self.scale(span, || format!("{}scale", path()), scale.unwrap_or(Scale::Uniform(1.0)))?;
        Ok(Affine3A::from_scale_rotation_translation(scale, euler_degrees(degrees), translation))
    }

    pub(super) fn scale(
        &self,
        span: &Range<usize>,
        path: impl FnOnce() -> String,
        scale: Scale,
    ) -> Result<Vec3, SceneError> {
        let scale = match scale {
            Scale::Uniform(s) => Vec3::splat(s),
            Scale::Axes(axes) => Vec3::from(axes),
        };
        if !scale.is_finite() || scale.cmpeq(Vec3::ZERO).any() {
            return Err(self.error(span, path(), "scale must be finite and non-zero"));
        }
        Ok(scale)
    }
}

/// The 1-based line of a byte offset.
pub(super) fn line_of(text: &str, offset: usize) -> usize {
    text.as_bytes()[..offset.min(text.len())].iter().filter(|&&b| b == b'\n').count() + 1
}

/// A `toml` error as a [`SceneError`] pointing at the line and, where it can be told, the
/// field (`mesh[1].scale`).
pub(super) fn toml_error(error: &toml::de::Error, text: &str, file: &Path) -> SceneError {
    let message = error.message().trim().to_owned();
    let Some(span) = error.span() else {
        return SceneError::parse(file, Location::File, message);
    };
    let line = line_of(text, span.start);
    let location = match field_spans::path_at(text, span.start) {
        Some(path) => Location::Field { line: Some(line), path },
        None => Location::Line(line),
    };
    SceneError::parse(file, location, message)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotation_order_is_x_then_y_then_z() {
        let check = Checker { file: Path::new("s.toml"), text: "" };
        let t = check.transform(&(0..0), String::new, None, Some([90.0, 90.0, 0.0]), None).unwrap();
        // X first takes +Y to +Z, then Y takes +Z to +X.
        assert!((t.transform_vector3(Vec3::Y) - Vec3::X).length() < 1e-6);
        let t = check
            .transform(
                &(0..0),
                String::new,
                Some([1.0, 2.0, 3.0]),
                Some([0.0, 0.0, 90.0]),
                Some(Scale::Axes([2.0, 1.0, 1.0])),
            )
            .unwrap();
        // Scale, then rotate, then translate: +X → (2,0,0) → (0,2,0) → (1,4,3).
        assert!((t.transform_point3(Vec3::X) - Vec3::new(1.0, 4.0, 3.0)).length() < 1e-5);
    }
}
