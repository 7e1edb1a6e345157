//! What a frame cost: rays traced by kind and time spent per pipeline phase. Tiles report
//! their own figures and the frame sums them, so a render node can report the same numbers.

use std::ops::AddAssign;
use std::time::{Duration, Instant};

/// Rays traced, by kind.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct RayCounts {
    /// Camera rays (closest hit).
    pub primary: u64,
    /// Shadow rays toward VPLs and lights (any hit).
    pub shadow: u64,
    /// Mirror and glass rays from the camera path (closest hit).
    pub specular: u64,
    /// Short rays of the clamp's bias compensation (closest hit).
    pub compensation: u64,
}

impl RayCounts {
    /// All rays.
    pub fn total(&self) -> u64 {
        self.primary + self.shadow + self.specular + self.compensation
    }
}

impl AddAssign for RayCounts {
    fn add_assign(&mut self, o: Self) {
        self.primary += o.primary;
        self.shadow += o.shadow;
        self.specular += o.specular;
        self.compensation += o.compensation;
    }
}

/// The phases of a frame, in the order the pipeline runs them ([`crate::igi::tile_pipeline`];
/// ARCHITECTURE.md, "Data flow").
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Phase {
    /// Random walks from the lights.
    VplGeneration,
    /// Camera rays.
    Primary,
    /// Surface shading inputs of every hit (position, normals, albedo, material).
    Shading,
    /// Mirror and glass rays.
    Specular,
    /// Bias compensation of the VPL clamp (its rays, and folding the light they find into the
    /// camera paths' points after the shadow phase).
    Compensation,
    /// Shadow rays to the VPLs and accumulation of their contributions.
    Shadow,
    /// The discontinuity filter (with the lit points arranged by pixel for it) and the final
    /// multiply by the albedo.
    Filter,
    /// Luminance statistics and the mapping to display values.
    ToneMap,
}

impl Phase {
    /// Every phase, in pipeline order.
    pub const ALL: [Phase; 8] = [
        Phase::VplGeneration,
        Phase::Primary,
        Phase::Shading,
        Phase::Specular,
        Phase::Compensation,
        Phase::Shadow,
        Phase::Filter,
        Phase::ToneMap,
    ];

    /// Short name (used as a JSON key).
    pub fn name(self) -> &'static str {
        match self {
            Phase::VplGeneration => "vpl_generation",
            Phase::Primary => "primary",
            Phase::Shading => "shading",
            Phase::Shadow => "shadow",
            Phase::Specular => "specular",
            Phase::Compensation => "compensation",
            Phase::Filter => "filter",
            Phase::ToneMap => "tone_map",
        }
    }
}

/// Time spent in each phase (summed over threads for the tile phases).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct PhaseTimes([Duration; Phase::ALL.len()]);

impl PhaseTimes {
    /// Time of `phase`.
    pub fn get(&self, phase: Phase) -> Duration {
        self.0[phase as usize]
    }

    /// Adds `d` to `phase`.
    pub fn add(&mut self, phase: Phase, d: Duration) {
        self.0[phase as usize] += d;
    }

    /// Adds the time since `*since` to `phase` and restarts the clock.
    #[inline]
    pub fn lap(&mut self, phase: Phase, since: &mut Instant) {
        let now = Instant::now();
        self.0[phase as usize] += now - *since;
        *since = now;
    }

    /// Sum over all phases.
    pub fn total(&self) -> Duration {
        self.0.iter().sum()
    }
}

impl AddAssign for PhaseTimes {
    fn add_assign(&mut self, o: Self) {
        for (a, b) in self.0.iter_mut().zip(o.0) {
            *a += b;
        }
    }
}
