//! [`Input`]: everything a viewer can ask of a session, as one serialisable message type.
//! The browser sends these as JSON text messages (`{"type": "key", "key": "w", "down": true}`);
//! the window builds them from its events.

use crate::settings::ViewerSettings;
use igi_render::frame::SettingsError;
use serde::{Deserialize, Serialize};

/// How drags and keys move the camera.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum CameraMode {
    /// WASD/QE move, a drag turns the view about the eye; scroll sets the speed.
    #[default]
    Fly,
    /// A drag turns the eye about the target; scroll sets the distance.
    Orbit,
}

/// The keys of the fly camera.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Key {
    /// Forward.
    W,
    /// Left.
    A,
    /// Backward.
    S,
    /// Right.
    D,
    /// Down (world −Y).
    Q,
    /// Up (world +Y).
    E,
}

/// The mouse button of a drag.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Button {
    /// Look around (fly) or orbit (orbit).
    Primary,
    /// Move the selected object in the view plane.
    Secondary,
}

/// One user action.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum Input {
    /// A fly-camera key went down or up.
    Key {
        /// The key.
        key: Key,
        /// True when pressed, false when released.
        down: bool,
    },
    /// The pointer moved by (dx, dy) pixels of the image with a button held (pixels of the
    /// rendered image, not of the screen: the viewers scale a drag over a scaled-up image
    /// down, so the view turns, and a dragged object moves, with the pointer at any
    /// resolution).
    Drag {
        /// Horizontal motion, pixels, to the right.
        dx: f32,
        /// Vertical motion, pixels, downwards.
        dy: f32,
        /// The button held.
        button: Button,
    },
    /// The wheel turned by `delta` notches (positive: away from the user): fly speed or orbit
    /// distance.
    Scroll {
        /// Notches.
        delta: f32,
    },
    /// Select the object under the image point (x, y), in pixels; nothing there clears the
    /// selection.
    Pick {
        /// Column.
        x: f32,
        /// Row.
        y: f32,
    },
    /// Switch between fly and orbit.
    Mode {
        /// The new mode.
        mode: CameraMode,
    },
    /// Replace the settings.
    Settings {
        /// The new settings (checked; invalid ones are refused with a message).
        settings: ViewerSettings,
    },
    /// Select the scene's light source `index` ([`crate::FrameStats::lights`]): a right-drag
    /// then moves (a sun: turns) it.
    SelectLight {
        /// Its index.
        index: usize,
    },
    /// Set the intensity (a factor on its power, 1 as loaded) and the linear RGB colour tint
    /// (white as loaded) of light source `index`.
    EditLight {
        /// Its index.
        index: usize,
        /// Factor on its power, 0 ..= [`crate::light_control::MAX_INTENSITY`].
        intensity: f32,
        /// Tint, each channel in [0, 1].
        colour: [f32; 3],
    },
    /// Back to the scene's own camera, no object moved and every light as loaded.
    Reset,
    /// Open the scene of this name from the viewer's list ([`crate::SceneCatalog`]) in place
    /// of the current one (its camera, lights and clock start anew; the settings stay).
    Open {
        /// The name as listed.
        name: String,
    },
    /// Look from the scene's view of this name ([`crate::FrameStats::views`]); objects stay
    /// where they were moved.
    View {
        /// The view's name.
        name: String,
    },
}

impl Input {
    /// True if this input's effect outlasts opening another scene ([`Input::Open`]): the
    /// settings and the camera mode stay, while the camera, the lights, the selection and
    /// moved objects start anew with the scene.
    pub fn outlasts_open(&self) -> bool {
        matches!(self, Self::Settings { .. } | Self::Mode { .. })
    }
}

/// Why a session refused an input; the refused input changes nothing.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum InputError {
    /// A setting outside its range ([`Input::Settings`]).
    #[error(transparent)]
    Settings(#[from] SettingsError),
    /// [`Input::View`] named a view the scene does not have (its name as
    /// [`crate::refusals::quote_name`] quotes it).
    #[error("view: the scene has no view {0}")]
    NoView(String),
    /// A light input named a light source the scene does not have (`index` counts from 0).
    #[error("light: the scene has {count} light sources, not {}", index + 1)]
    NoLight {
        /// The index asked for.
        index: usize,
        /// The scene's light sources.
        count: usize,
    },
    /// [`Input::EditLight`] asked for an intensity or colour out of range; the message says
    /// which.
    #[error("light: {0}")]
    Light(String),
    /// [`Input::Open`] could not open the scene; the message says why.
    #[error("open: {0}")]
    Open(String),
}

impl InputError {
    /// The error as the viewers' panels say it: a setting by its label there
    /// ([`ViewerSettings::panel_message`]), the rest as they are.
    pub fn panel_message(&self) -> String {
        match self {
            Self::Settings(e) => ViewerSettings::panel_message(e),
            other => other.to_string(),
        }
    }
}
