//! The rays a render casts, counted by type: what `--stats` prints and the SPD's
//! published statistics are checked against.

/// Rays cast, by type.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RayCounts {
    /// Eye (primary) rays.
    pub eye: u64,
    /// Eye rays that hit something.
    pub eye_hit: u64,
    /// Reflection rays.
    pub reflection: u64,
    /// Refraction (transmission) rays.
    pub refraction: u64,
    /// Shadow rays.
    pub shadow: u64,
    /// Total internal reflection events (no refraction ray was cast).
    pub tir: u64,
    /// Reflection or refraction rays not spawned because their accumulated weight was
    /// below the `--bailout` threshold.
    pub bailed: u64,
    /// Shadow rays not cast: the light is behind the shading normal or sends nothing.
    pub skipped_shadow: u64,
    /// Reflection rays not cast at hits on non-reflective (`Ks = 0`) surfaces below
    /// the depth limit.
    pub skipped_reflection: u64,
    /// Rays whose radiance overflowed f32 and was saturated (an infinite channel
    /// clamped to ±`f32::MAX`, a NaN one set to 0): the scene's colours, intensities
    /// or weights are too large. 0 for sane scenes.
    pub saturated: u64,
}

impl RayCounts {
    /// All rays cast.
    pub fn total(&self) -> u64 {
        self.eye + self.reflection + self.refraction + self.shadow
    }
}

impl std::ops::AddAssign for RayCounts {
    fn add_assign(&mut self, o: Self) {
        self.eye += o.eye;
        self.eye_hit += o.eye_hit;
        self.reflection += o.reflection;
        self.refraction += o.refraction;
        self.shadow += o.shadow;
        self.tir += o.tir;
        self.bailed += o.bailed;
        self.skipped_shadow += o.skipped_shadow;
        self.skipped_reflection += o.skipped_reflection;
        self.saturated += o.saturated;
    }
}
