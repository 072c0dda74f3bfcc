//! One render from start to end, with the phases timed separately (the SPD rule:
//! preprocessing apart from ray tracing): load ([`load_scene`]), resolve the settings
//! ([`RenderRequest::settings`]), check the memory it needs ([`limits`]), build the
//! backend and render ([`render_scene`], [`render_two_pass`], [`render_reference`]).

pub mod limits;
mod request;

pub use request::{
    CropSpecError, DEFAULT_MAX_DEPTH, DEFAULT_SPP, IndexOfError, Part, RenderRequest,
    SPD_MAX_DEPTH, SPD_SIDE, SettingsError, parse_crop, parse_index_of, parse_tile,
};

use crate::accel::{self, Accel, AccelError, AccelStats, BackendOptions, WithAccel};
use crate::geometry::Kind;
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
    /// Primitives by kind (`triangles`, `spheres`, `cones`).
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
    /// ([`AccelStats::kinds`]), e.g. `spheres×8, triangles×1`.
    pub kinds: String,
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
            prims: Kind::ALL
                .iter()
                .map(|&k| (k.name(), scene.count_with_instances(k)))
                .collect(),
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
        let sol = crate::radiosity::solve(self.scene, accel, self.rad)?;
        log::info!(
            "radiosity: {} elements, {} shots, residual {:.2e}, form factors {:.0} ms, solve {:.0} ms",
            sol.mesh.elements.len(),
            sol.solve.iterations,
            sol.solve.residuals.last().copied().unwrap_or(0.0),
            sol.solve.form_factor_ms,
            sol.solve.total_ms
        );
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
