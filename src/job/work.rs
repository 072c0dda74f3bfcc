//! What a job does with its built backend ([`crate::accel::build`] hands the backend
//! over, so everything below is monomorphised per backend): solve the radiosity when
//! the task needs it, then render the image (with its output variables when the job
//! asks for some), explain one pixel, or view the radiosity solution. Also the f64
//! reference, which needs no backend.

use super::report::{Report, Timings};
use super::resolve::Resolved;
use super::{Event, JobError, Observer, Task};
use crate::accel::{Accel, AccelStats, WithAccel};
use crate::geometry::Kind;
use crate::radiosity::{self, RadiosityError, RadiosityReport, RadiositySettings, Solution};
use crate::render::aov::{self, AovFilm};
use crate::render::explain::{self, Explanation};
use crate::render::{self, Film, GlobalIllumination, RenderSettings, RenderStats};
use crate::scene::Scene;
use std::time::Instant;

/// What a job made.
#[derive(Debug)]
pub enum Product {
    /// An image, with the output variables it gathered.
    Image {
        /// The colour.
        film: Film,
        /// The output variables (`aov`, `heatmap`), when asked for.
        aov: Option<Box<AovFilm>>,
    },
    /// One pixel's ray tree.
    Explanation(Box<Explanation>),
    /// A view of a radiosity solution.
    Radiosity {
        /// The view.
        film: Film,
        /// The solution (its mesh is what `ply` writes).
        solution: Box<Solution>,
        /// What the solver reports.
        report: Box<RadiosityReport>,
    },
}

/// What a job made, with what it reports.
#[derive(Debug)]
pub(super) struct Made {
    pub product: Product,
    pub report: Report,
    pub accel: AccelStats,
    pub rays: crate::render::RayCounts,
}

impl Made {
    /// What a render of `scene` named `name` made.
    fn new(
        name: &str,
        scene: &Scene,
        settings: &RenderSettings,
        product: Product,
        accel: AccelStats,
        t: Timings,
        stats: &RenderStats,
    ) -> Made {
        Made {
            report: Report::new(name, scene, settings, &accel, t, stats),
            product,
            accel,
            rays: stats.rays,
        }
    }
}

/// The work done with the built backend.
pub(super) struct Work<'a> {
    pub name: &'a str,
    pub scene: &'a Scene,
    pub resolved: &'a Resolved,
    pub task: &'a Task,
    pub load_ms: f64,
    pub observer: &'a dyn Observer,
}

impl WithAccel for Work<'_> {
    type Output = Result<Made, JobError>;
    fn run<A: Accel>(self, accel: &A, build_ms: f64) -> Self::Output {
        let r = self.resolved;
        let cancelled = || JobError::Cancelled(self.name.to_string());
        if self.observer.cancelled() {
            return Err(cancelled());
        }
        self.observer.event(Event::Rendering);
        if let Task::RadiosityView = self.task {
            return self.radiosity_view(accel, build_ms);
        }
        let solution = match &r.radiosity {
            Some(rad) => Some(solve_logged(self.scene, accel, rad)?),
            None => None,
        };
        let gi = solution.as_ref().map(|s| s as &dyn GlobalIllumination);
        let progress = Watched(self.observer);
        let (product, stats) = match self.task {
            Task::Explain { x, y } => {
                let t0 = Instant::now();
                let e = explain::explain(self.scene, accel, &r.settings, gi, *x, *y)?;
                let stats = RenderStats {
                    rays: Default::default(),
                    render_ms: t0.elapsed().as_secs_f64() * 1e3,
                };
                (Product::Explanation(Box::new(e)), stats)
            }
            _ if r.wants_insight() => {
                let (film, mut aov, stats) = aov::render_aov(
                    self.scene,
                    accel,
                    &r.settings,
                    gi,
                    Some(&progress),
                    r.gathered(),
                )
                .map_err(|e| match e {
                    aov::AovError::Cancelled => cancelled(),
                    e => e.into(),
                })?;
                // The layers written are the ones asked for; the heat maps' are
                // gathered for them alone.
                aov.set = r.layers;
                (
                    Product::Image {
                        film,
                        aov: Some(Box::new(aov)),
                    },
                    stats,
                )
            }
            _ => {
                let (film, stats) =
                    render::render_with_gi(self.scene, accel, &r.settings, gi, Some(&progress));
                (Product::Image { film, aov: None }, stats)
            }
        };
        if self.observer.cancelled() {
            return Err(cancelled());
        }
        self.observer.event(Event::Rendered);
        let t = Timings {
            load: self.load_ms,
            // The view-independent solve is preprocessing, like the build.
            build: build_ms + solution.map_or(0.0, |s| s.solve.total_ms),
            render: stats.render_ms,
        };
        let stats_of_accel = accel.stats();
        Ok(Made::new(
            self.name,
            self.scene,
            &r.settings,
            product,
            stats_of_accel,
            t,
            &stats,
        ))
    }
}

/// A job's [`Observer`] as the renderer's [`render::Watch`]: tiles become events, and
/// the renderer stops when the observer asks.
struct Watched<'a>(&'a dyn Observer);

impl render::Watch for Watched<'_> {
    fn tiles(&self, done: usize, total: usize) {
        self.0.event(Event::Tiles { done, total })
    }

    fn tile(&self, tile: render::TileValues<'_>) {
        self.0.event(Event::Tile(tile))
    }

    fn cancelled(&self) -> bool {
        self.0.cancelled()
    }
}

impl Work<'_> {
    /// Solve the radiosity and render a view of the solution itself.
    fn radiosity_view<A: Accel>(&self, accel: &A, build_ms: f64) -> Result<Made, JobError> {
        let r = self.resolved;
        let settings = r.radiosity.clone().unwrap_or_default();
        let s = &r.settings;
        let view = (
            s.width,
            s.height,
            (s.spp as f32).sqrt().floor().max(1.0) as u32,
        );
        let (solution, film, report) =
            radiosity::solve_and_view(self.scene, accel, &settings, view, build_ms)?;
        self.observer.event(Event::Rendered);
        let t = Timings {
            load: self.load_ms,
            build: build_ms + report.form_factor_ms + report.solve_ms,
            render: report.view_ms,
        };
        let stats = RenderStats {
            rays: Default::default(),
            render_ms: report.view_ms,
        };
        let product = Product::Radiosity {
            film,
            solution: Box::new(solution),
            report: Box::new(report),
        };
        Ok(Made::new(
            self.name,
            self.scene,
            s,
            product,
            accel.stats(),
            t,
            &stats,
        ))
    }
}

/// Solve the radiosity of `scene` with `accel`'s visibility, and log what it took.
fn solve_logged<A: Accel>(
    scene: &Scene,
    accel: &A,
    rad: &RadiositySettings,
) -> Result<Solution, RadiosityError> {
    let sol = radiosity::solve(scene, accel, rad)?;
    log::info!(
        "radiosity: {} elements, {} shots, residual {:.2e}, form factors {:.0} ms, solve {:.0} ms",
        sol.mesh.elements.len(),
        sol.solve.iterations,
        sol.solve.residuals.last().copied().unwrap_or(0.0),
        sol.solve.form_factor_ms,
        sol.solve.total_ms
    );
    Ok(sol)
}

/// Runs of the reference longer than this are announced with their estimated time.
const LONG_REFERENCE_MS: f64 = 60_000.0;

/// Say how long the reference render will take when that is more than a minute, so
/// that a user can stop it (or lower `--res` or `--spp`) before waiting.
fn warn_if_long(scene: &Scene, settings: &RenderSettings, strata: u32) {
    let (w, h) = (settings.width, settings.height);
    let threads = rayon::current_num_threads();
    let ms = render::reference::estimate_ms(scene, w, h, strata, settings.max_depth, threads);
    if ms > LONG_REFERENCE_MS {
        log::warn!(
            "the f64 reference renders every primitive for every ray: this {w}x{h} render \
             with {} samples per pixel will take about {} on {threads} threads",
            strata * strata,
            format_duration(ms)
        );
    }
}

/// A duration for people: seconds, minutes or hours.
fn format_duration(ms: f64) -> String {
    let s = ms / 1e3;
    if s < 120.0 {
        format!("{s:.0} s")
    } else if s < 7200.0 {
        format!("{:.0} min", s / 60.0)
    } else {
        format!("{:.1} h", s / 3600.0)
    }
}

/// Render `scene` with the f64 reference renderer ([`render::reference`]) using
/// `strata × strata` samples per pixel; `Err` names what the reference does not model.
pub(super) fn reference(
    name: &str,
    scene: &Scene,
    settings: &RenderSettings,
    strata: u32,
    load_ms: f64,
) -> Result<Made, render::reference::Unsupported> {
    if let Some(why) = render::reference::unsupported(scene) {
        return Err(why);
    }
    warn_if_long(scene, settings, strata);
    let t0 = Instant::now();
    let (film, rays) = render::reference::render(
        scene,
        settings.width,
        settings.height,
        strata,
        settings.max_depth,
    );
    let stats = RenderStats {
        rays,
        render_ms: t0.elapsed().as_secs_f64() * 1e3,
    };
    let accel = AccelStats {
        backend: "reference",
        prims: scene.prim_count_with_instances(),
        nodes: 0,
        bytes: 0,
        detail: format!("f64, brute force, {strata}x{strata} stratified samples"),
        kinds: Kind::ALL
            .into_iter()
            .map(|k| (k, scene.count_with_instances(k)))
            .filter(|&(_, n)| n > 0)
            .collect(),
    };
    let mut st = settings.clone();
    st.spp = strata * strata;
    // The reference casts the full ray tree with uniform stratified samples.
    st.bailout = 0.0;
    st.aa = render::Aa::Uniform;
    let t = Timings {
        load: load_ms,
        build: 0.0,
        render: stats.render_ms,
    };
    let product = Product::Image { film, aov: None };
    Ok(Made::new(name, scene, &st, product, accel, t, &stats))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn durations_read_as_seconds_minutes_or_hours() {
        assert_eq!(format_duration(61_000.0), "61 s");
        assert_eq!(format_duration(600_000.0), "10 min");
        assert_eq!(format_duration(9_000_000.0), "2.5 h");
    }

    /// The estimate traces real pixels: a scene with 50× more spheres for every ray is
    /// estimated as much slower (timing noise cannot bridge a factor of 50).
    #[test]
    fn the_reference_estimate_grows_with_the_work() {
        let scene = |n: usize| {
            let mut src = String::from(
                "v\nfrom 0 -8 0\nat 0 0 0\nup 0 0 1\nangle 40\nhither 0\nresolution 16 16\n\
                 f 0.8 0.8 0.8 1 0 0 0 1\n",
            );
            for k in 0..n {
                src += &format!(
                    "s {} 0 {} 0.1\n",
                    (k % 20) as f32 * 0.2 - 2.0,
                    (k / 20) as f32 * 0.2 - 2.0
                );
            }
            crate::load::nff::parse_str(&src, std::path::Path::new("<estimate>")).unwrap()
        };
        let (few, many) = (scene(8), scene(400));
        let est = |s: &Scene| render::reference::estimate_ms(s, 256, 256, 2, 1, 1);
        let (a, b) = (est(&few), est(&many));
        assert!(a.is_finite() && a > 0.0 && b > 10.0 * a, "{a} {b}");
    }
}
