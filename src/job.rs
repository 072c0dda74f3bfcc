//! One render from start to end, with the phases timed separately (the SPD rule:
//! preprocessing apart from ray tracing): load ([`load_scene`]), resolve the settings
//! ([`RenderRequest::settings`]), check the memory it needs ([`limits`]), build the
//! backend and render ([`render_scene`], [`render_two_pass`], [`render_reference`]);
//! the output file names of every render, from templates ([`template`]).

mod aov;
mod explain;
pub mod limits;
mod request;
pub mod template;

pub use aov::{AovRunError, render_aov};
pub use explain::{ExplainRunError, explain_pixel};
pub use request::{
    CropSpecError, DEFAULT_MAX_DEPTH, DEFAULT_SPP, IndexOfError, Part, RenderRequest,
    SPD_MAX_DEPTH, SPD_SIDE, SettingsError, parse_crop, parse_index_of, parse_tile,
};

use crate::accel::{self, Accel, AccelError, AccelStats, BackendOptions, WithAccel};
use crate::geometry::{Kind, Shape};
use crate::load::{self, LoadError};
use crate::radiosity::{RadiosityError, RadiositySettings};
use crate::render::{self, Film, Progress, RenderSettings, RenderStats};
use crate::scene::Scene;
use crate::spd::Database;
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::Path;
use std::time::Instant;

/// Why a scene named on the command line (a file or `spd:NAME[?size=N]`) could not
/// be had.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// An `spd:` spec that names no database or a size it cannot generate.
    #[error("{0}")]
    Spec(#[from] crate::spd::SpecError),
    /// The file could not be read or does not parse (`path:line:col: message`).
    #[error(transparent)]
    Load(#[from] LoadError),
}

/// Load a scene file or generate an `spd:NAME[?size=N]` scene; errors name the file
/// (and line and column where there is one).
pub fn load_scene(spec: impl AsRef<Path>) -> Result<Scene, SceneError> {
    let spec = spec.as_ref();
    match Database::parse_spec(&spec.to_string_lossy()).map_err(SceneError::Spec)? {
        Some((db, size)) => Ok(load::nff::parse_str(&db.generate(size), spec)?),
        None => Ok(load::load_path(spec)?),
    }
}

/// Wall times of the three phases in milliseconds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Timings {
    /// Reading and parsing the scene.
    pub load: f64,
    /// Building the acceleration structure.
    pub build: f64,
    /// Tracing the rays.
    pub render: f64,
}

/// Everything a render reports; serialises to the `--stats-json` record.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Report {
    /// Scene name (file path or `default`).
    pub scene: String,
    /// Backend name.
    pub backend: &'static str,
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Worker threads.
    pub threads: usize,
    /// Samples per pixel.
    pub spp: u32,
    /// SPD testing mode.
    pub spd: bool,
    /// Maximum ray depth.
    pub max_depth: u32,
    /// Antialiasing (`uniform` or `adaptive T D`).
    pub aa: String,
    /// `--bailout` weight (0 = full ray tree).
    pub bailout: f32,
    /// Primitives a ray can meet (instanced objects counted once per instance), by
    /// kind, with cylinders named apart (`triangles`, `spheres`, `cones`,
    /// `open_cylinders`, `cylinders`, ...).
    pub prims: BTreeMap<&'static str, usize>,
    /// Lights.
    pub lights: usize,
    /// Whether any material transmits (T > 0); without, no refraction work is done.
    pub transmitters: bool,
    /// Degenerate polygons dropped at load.
    pub degenerate_dropped: usize,
    /// Phase times.
    pub time_ms: Timings,
    /// Rays by type.
    pub rays: BTreeMap<&'static str, u64>,
    /// Millions of rays per second of render time.
    pub mrays_per_s: f64,
    /// Backend details.
    pub accel: String,
    /// Bytes of the backend's structure ([`AccelStats::bytes`], 0 when unknown).
    pub accel_bytes: usize,
    /// Primitives in the backend's structure ([`AccelStats::prims`]).
    pub accel_prims: usize,
    /// The primitive kinds the backend holds and dispatches to
    /// ([`AccelStats::kinds`]), e.g. `triangles, spheres`.
    pub kinds: String,
}

/// The primitives a ray can meet (each instance's copy of its object counted), by the
/// name a user knows them by: a kind's plural name, except that cones and capped cones
/// with equal radii are (open) cylinders.
fn prim_counts(scene: &Scene) -> BTreeMap<&'static str, usize> {
    let mut counts = BTreeMap::new();
    let mut add = |geometry: &crate::scene::Geometry, times: usize| {
        let tris = geometry.count(Kind::Triangle) * times;
        if tris > 0 {
            *counts.entry(Kind::Triangle.name()).or_insert(0) += tris;
        }
        for entry in geometry.shapes() {
            *counts.entry(prim_name(&entry.shape)).or_insert(0) += times;
        }
    };
    add(&scene.geometry, 1);
    let mut placed = vec![0usize; scene.objects.len()];
    for inst in &scene.instances {
        placed[inst.object as usize] += 1;
    }
    for (object, times) in scene.objects.iter().zip(placed) {
        if times > 0 {
            add(object, times);
        }
    }
    counts
}

/// What `--stats` calls `shape`.
fn prim_name(shape: &Shape) -> &'static str {
    match shape {
        Shape::Cone(c) if c.is_cylinder() => "open_cylinders",
        Shape::CappedCone(c) if c.is_cylinder() => "cylinders",
        other => other.kind().name(),
    }
}

impl Report {
    /// The report of a render of `scene` named `name`.
    pub fn new(
        name: &str,
        scene: &Scene,
        settings: &RenderSettings,
        accel: &AccelStats,
        time_ms: Timings,
        stats: &RenderStats,
    ) -> Self {
        let r = stats.rays;
        Report {
            scene: name.to_string(),
            backend: accel.backend,
            width: settings.width,
            height: settings.height,
            threads: rayon::current_num_threads(),
            spp: settings.spp,
            spd: settings.spd,
            max_depth: settings.max_depth,
            aa: match settings.aa {
                crate::render::Aa::Uniform => "uniform".into(),
                crate::render::Aa::Adaptive { threshold, depth } => {
                    format!("adaptive {threshold} {depth}")
                }
            },
            bailout: settings.bailout,
            prims: prim_counts(scene),
            lights: scene.lights.len(),
            transmitters: scene.materials.iter().any(|m| m.t > 0.0),
            degenerate_dropped: scene.load_stats.degenerate_dropped,
            time_ms,
            rays: BTreeMap::from([
                ("eye", r.eye),
                ("eye_hit", r.eye_hit),
                ("reflection", r.reflection),
                ("refraction", r.refraction),
                ("shadow", r.shadow),
                ("tir", r.tir),
                ("bailed", r.bailed),
                ("skipped_shadow", r.skipped_shadow),
                ("skipped_reflection", r.skipped_reflection),
                ("saturated", r.saturated),
                ("total", r.total()),
            ]),
            mrays_per_s: stats.mrays_per_s(),
            accel: if accel.detail.is_empty() {
                accel.backend.to_string()
            } else {
                format!("{}: {}", accel.backend, accel.detail)
            },
            kinds: crate::accel::kinds_summary(&accel.kinds),
            accel_bytes: accel.bytes,
            accel_prims: accel.prims,
        }
    }

    /// The backend's memory for `--stats`: bytes, and bytes per primitive.
    fn memory(&self) -> String {
        match (self.accel_bytes, self.accel_prims) {
            (0, _) => "unknown".to_string(),
            (b, 0) => format!("{b} bytes"),
            (b, n) => format!("{b} bytes, {:.1} per primitive", b as f64 / n as f64),
        }
    }

    /// A human-readable summary for `--stats`.
    pub fn summary(&self) -> String {
        let prims: Vec<String> = self
            .prims
            .iter()
            .filter(|&(_, &n)| n > 0)
            .map(|(k, n)| format!("{n} {k}"))
            .collect();
        let t = &self.time_ms;
        let r = &self.rays;
        format!(
            "scene      {}\n\
             backend    {} ({} threads)\n\
             image      {}x{}, {} spp, depth {}{}\n\
             prims      {} ({} lights{})\n\
             kinds      {} (only these are dispatched to)\n\
             memory     {}\n\
             time       load {:.1} ms, build {:.1} ms, render {:.1} ms\n\
             rays       eye {} (hit {}), reflection {}, refraction {}, shadow {}, total {}\n\
             tir        {}\n\
             skipped    shadow {}, reflection {}, bailout {} (aa {}, bailout {}){}\n\
             speed      {:.2} Mrays/s",
            self.scene,
            self.accel,
            self.threads,
            self.width,
            self.height,
            self.spp,
            self.max_depth,
            if self.spd { ", SPD mode" } else { "" },
            if prims.is_empty() {
                "none".to_string()
            } else {
                prims.join(", ")
            },
            self.lights,
            if self.degenerate_dropped > 0 {
                format!(", {} degenerate polygons dropped", self.degenerate_dropped)
            } else {
                String::new()
            },
            self.kinds,
            self.memory(),
            t.load,
            t.build,
            t.render,
            r["eye"],
            r["eye_hit"],
            r["reflection"],
            r["refraction"],
            r["shadow"],
            r["total"],
            r["tir"],
            r["skipped_shadow"],
            r["skipped_reflection"],
            r["bailed"],
            self.aa,
            self.bailout,
            if self.transmitters {
                ""
            } else {
                "; no transmitter: no refraction rays"
            },
            self.mrays_per_s,
        )
    }
}

/// A full render with its report.
struct RenderWork<'a> {
    name: &'a str,
    scene: &'a Scene,
    settings: &'a RenderSettings,
    load_ms: f64,
    progress: Option<Progress<'a>>,
}

impl WithAccel for RenderWork<'_> {
    type Output = (Film, Report);
    fn run<A: Accel>(self, accel: &A, build_ms: f64) -> (Film, Report) {
        let (film, stats) = render::render(self.scene, accel, self.settings, self.progress);
        let t = Timings {
            load: self.load_ms,
            build: build_ms,
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
        (film, report)
    }
}

/// Build the backend (a [`Backend`] with the default options, or [`BackendOptions`])
/// over `scene` and render it on the current rayon pool.
pub fn render_scene(
    name: &str,
    scene: &Scene,
    backend: impl Into<BackendOptions>,
    settings: &RenderSettings,
    load_ms: f64,
    progress: Option<Progress<'_>>,
) -> Result<(Film, Report), AccelError> {
    accel::build(
        scene,
        &backend.into(),
        RenderWork {
            name,
            scene,
            settings,
            load_ms,
            progress,
        },
    )
}

/// The two-pass render with its report.
struct TwoPassWork<'a> {
    name: &'a str,
    scene: &'a Scene,
    settings: &'a RenderSettings,
    rad: &'a RadiositySettings,
    load_ms: f64,
    progress: Option<Progress<'a>>,
}

impl WithAccel for TwoPassWork<'_> {
    type Output = Result<(Film, Report), RadiosityError>;
    fn run<A: Accel>(self, accel: &A, build_ms: f64) -> Self::Output {
        let sol = solve_logged(self.scene, accel, self.rad)?;
        let (film, stats) =
            render::render_with_gi(self.scene, accel, self.settings, Some(&sol), self.progress);
        let t = Timings {
            load: self.load_ms,
            // The view-independent solve is preprocessing, like the build.
            build: build_ms + sol.solve.total_ms,
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
        Ok((film, report))
    }
}

/// Solve the radiosity of `scene` with `accel`'s visibility, and log what it took.
fn solve_logged<A: Accel>(
    scene: &Scene,
    accel: &A,
    rad: &RadiositySettings,
) -> Result<crate::radiosity::Solution, RadiosityError> {
    let sol = crate::radiosity::solve(scene, accel, rad)?;
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

/// Two-pass rendering: build the backend over `scene`, solve its radiosity with the
/// backend's visibility, then render with the diffuse term of meshed surfaces from
/// the solution and the specular paths from the Whitted recursion. The solve counts
/// as build (preprocessing) time.
pub fn render_two_pass(
    name: &str,
    scene: &Scene,
    backend: impl Into<BackendOptions>,
    settings: &RenderSettings,
    rad: &RadiositySettings,
    load_ms: f64,
    progress: Option<Progress<'_>>,
) -> Result<(Film, Report), RadiosityError> {
    let work = TwoPassWork {
        name,
        scene,
        settings,
        rad,
        load_ms,
        progress,
    };
    accel::build(scene, &backend.into(), work)?
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
pub fn render_reference(
    name: &str,
    scene: &Scene,
    settings: &RenderSettings,
    strata: u32,
    load_ms: f64,
) -> Result<(Film, Report), render::reference::Unsupported> {
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
    Ok((film, Report::new(name, scene, &st, &accel, t, &stats)))
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
            load::nff::parse_str(&src, Path::new("<estimate>")).unwrap()
        };
        let (few, many) = (scene(8), scene(400));
        let est = |s: &Scene| render::reference::estimate_ms(s, 256, 256, 2, 1, 1);
        let (a, b) = (est(&few), est(&many));
        assert!(a.is_finite() && a > 0.0 && b > 10.0 * a, "{a} {b}");
    }
}
