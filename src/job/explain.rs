//! `emray explain`'s work: build the backend over the scene (and, in two-pass mode,
//! solve its radiosity with it, as a render does), then record the ray tree of one
//! pixel ([`crate::render::explain`]).

use crate::accel::{self, Accel, AccelError, BackendOptions, WithAccel};
use crate::radiosity::{RadiosityError, RadiositySettings};
use crate::render::RenderSettings;
use crate::render::explain::{ExplainError, Explanation, explain};
use crate::scene::Scene;

/// Why a pixel could not be explained.
#[derive(Debug, thiserror::Error)]
pub enum ExplainRunError {
    /// The backend could not be built.
    #[error(transparent)]
    Accel(#[from] AccelError),
    /// The radiosity pass failed.
    #[error(transparent)]
    Radiosity(#[from] RadiosityError),
    /// The pixel cannot be explained with these settings.
    #[error(transparent)]
    Explain(#[from] ExplainError),
}

/// The work done with the built backend.
struct ExplainWork<'a> {
    scene: &'a Scene,
    settings: &'a RenderSettings,
    radiosity: Option<&'a RadiositySettings>,
    pixel: (u32, u32),
}

impl WithAccel for ExplainWork<'_> {
    type Output = Result<Explanation, ExplainRunError>;
    fn run<A: Accel>(self, accel: &A, _build_ms: f64) -> Self::Output {
        let (x, y) = self.pixel;
        let solution = match self.radiosity {
            Some(rad) => Some(crate::radiosity::solve(self.scene, accel, rad)?),
            None => None,
        };
        let gi = solution
            .as_ref()
            .map(|s| s as &dyn crate::render::GlobalIllumination);
        Ok(explain(self.scene, accel, self.settings, gi, x, y)?)
    }
}

/// Explain pixel `(x, y)` of `scene` rendered with `settings` on the backend
/// `backend`, two-pass with the radiosity `radiosity` when given.
pub fn explain_pixel(
    scene: &Scene,
    backend: impl Into<BackendOptions>,
    settings: &RenderSettings,
    radiosity: Option<&RadiositySettings>,
    x: u32,
    y: u32,
) -> Result<Explanation, ExplainRunError> {
    let work = ExplainWork {
        scene,
        settings,
        radiosity,
        pixel: (x, y),
    };
    accel::build(scene, &backend.into(), work)?
}
