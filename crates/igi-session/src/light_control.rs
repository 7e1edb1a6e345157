//! [`LightControl`]: one of the scene's light sources as a viewer edits it (intensity, colour,
//! and a move by dragging), turned into the frame's [`LightEdit`].

use glam::{Affine3A, Vec3};
use igi_render::{LightEdit, LightId, PreparedScene};
use igi_scene::Light;
use serde::Serialize;

/// Largest intensity factor of a light.
pub const MAX_INTENSITY: f32 = 1000.0;

/// How a drag moves a light source.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum LightKind {
    /// A point or spot light: moves in the view plane.
    Point,
    /// A directional light: turns.
    Sun,
    /// An emissive material: moves with the object that carries it (pick the object).
    Emissive,
}

/// A light source and the user's changes to it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LightControl {
    /// The source.
    pub id: LightId,
    /// Its name in the viewers' list.
    pub name: String,
    /// How a drag moves it.
    pub kind: LightKind,
    /// Factor on its power (1 as loaded).
    pub intensity: f32,
    /// Linear RGB tint of its power, each in [0, 1] (white as loaded).
    pub colour: [f32; 3],
    /// Extra world transform of a point, spot or directional light.
    #[serde(skip)]
    pub transform: Affine3A,
}

impl LightControl {
    /// The light sources of `scene`, unchanged.
    pub fn of(scene: &PreparedScene) -> Vec<Self> {
        scene
            .light_sources()
            .into_iter()
            .map(|(id, name)| {
                let kind = match id {
                    LightId::Emissive(_) => LightKind::Emissive,
                    LightId::Punctual(i) => match scene.lights().get(i as usize) {
                        Some(Light::Directional { .. }) => LightKind::Sun,
                        _ => LightKind::Point,
                    },
                };
                Self { id, name, kind, intensity: 1.0, colour: [1.0; 3], transform: Affine3A::IDENTITY }
            })
            .collect()
    }

    /// The frame's edit of this light, `None` while it is as loaded.
    pub fn edit(&self) -> Option<LightEdit> {
        let power = self.intensity * Vec3::from(self.colour);
        (power != Vec3::ONE || self.transform != Affine3A::IDENTITY).then_some(LightEdit {
            light: self.id,
            power,
            transform: self.transform,
        })
    }

    /// Sets intensity and colour if they are valid; else says what is wrong.
    pub fn set(&mut self, intensity: f32, colour: [f32; 3]) -> Result<(), String> {
        if !(intensity.is_finite() && (0.0..=MAX_INTENSITY).contains(&intensity)) {
            return Err(format!("intensity {intensity} is not between 0 and {MAX_INTENSITY}"));
        }
        if !colour.iter().all(|c| c.is_finite() && (0.0..=1.0).contains(c)) {
            return Err(format!("colour {colour:?} has a value outside [0, 1]"));
        }
        (self.intensity, self.colour) = (intensity, colour);
        Ok(())
    }

    /// Where the light is now in `scene` (posed), for a point or spot light.
    pub fn position(&self, scene: &PreparedScene) -> Option<Vec3> {
        let LightId::Punctual(i) = self.id else { return None };
        match scene.lights().get(i as usize)? {
            Light::Point { position, .. } | Light::Spot { position, .. } => Some(*position),
            Light::Directional { .. } => None,
        }
    }
}
