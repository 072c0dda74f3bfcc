//! A render that also gathers output variables (`--aov`, `--heatmap`): the backend
//! built, the radiosity solved in two-pass mode, then the render with its variables
//! ([`crate::render::aov`]) and the report of a plain render.

use super::{Report, Timings, solve_logged};
use crate::accel::{self, Accel, AccelError, BackendOptions, WithAccel};
use crate::radiosity::{RadiosityError, RadiositySettings};
use crate::render::aov::{self, AovError, AovFilm, AovSet};
use crate::render::{Film, GlobalIllumination, Progress, RenderSettings};
use crate::scene::Scene;

/// Why a render with output variables failed.
#[derive(Debug, thiserror::Error)]
pub enum AovRunError {
    /// The backend could not be built.
    #[error(transparent)]
    Accel(#[from] AccelError),
    /// The radiosity pass failed.
    #[error(transparent)]
    Radiosity(#[from] RadiosityError),
    /// The variables cannot be gathered with these settings.
    #[error(transparent)]
    Aov(#[from] AovError),
}

/// The work done with the built backend.
struct AovWork<'a> {
    name: &'a str,
    scene: &'a Scene,
    settings: &'a RenderSettings,
    radiosity: Option<&'a RadiositySettings>,
    set: AovSet,
    load_ms: f64,
    progress: Option<Progress<'a>>,
}

impl WithAccel for AovWork<'_> {
    type Output = Result<(Film, AovFilm, Report), AovRunError>;
    fn run<A: Accel>(self, accel: &A, build_ms: f64) -> Self::Output {
        let solution = match self.radiosity {
            Some(rad) => Some(solve_logged(self.scene, accel, rad)?),
            None => None,
        };
        let gi = solution.as_ref().map(|s| s as &dyn GlobalIllumination);
        let (film, aov, stats) = aov::render_aov(
            self.scene,
            accel,
            self.settings,
            gi,
            self.progress,
            self.set,
        )?;
        let t = Timings {
            load: self.load_ms,
            // The view-independent solve is preprocessing, like the build.
            build: build_ms + solution.map_or(0.0, |s| s.solve.total_ms),
            render: stats.render_ms,
        };
        let report = Report::new(
            self.name,
            self.scene,
            self.settings,
            &accel.stats(),
            t,
            &stats,
        );
        Ok((film, aov, report))
    }
}

/// Build the backend over `scene` and render it with the output variables `set`,
/// two-pass with the radiosity `radiosity` when given: the film of
/// [`super::render_scene`] (or [`super::render_two_pass`]) and the variables.
#[allow(clippy::too_many_arguments)]
pub fn render_aov(
    name: &str,
    scene: &Scene,
    backend: impl Into<BackendOptions>,
    settings: &RenderSettings,
    radiosity: Option<&RadiositySettings>,
    set: AovSet,
    load_ms: f64,
    progress: Option<Progress<'_>>,
) -> Result<(Film, AovFilm, Report), AovRunError> {
    let work = AovWork {
        name,
        scene,
        settings,
        radiosity,
        set,
        load_ms,
        progress,
    };
    accel::build(scene, &backend.into(), work)?
}
