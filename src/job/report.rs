//! What a render reports ([`Report`]): the scene, the settings, the primitives, the
//! backend, the time of each phase (the SPD rule: preprocessing apart from ray
//! tracing) and the rays by type; `--stats` prints its summary and `--stats-json`
//! appends it as one JSON line.

use crate::accel::AccelStats;
use crate::geometry::{Kind, Shape};
use crate::render::{RenderSettings, RenderStats};
use crate::scene::Scene;
use serde::Serialize;
use std::collections::BTreeMap;

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
    /// The process's peak resident memory in bytes when the render ended (`VmHWM`:
    /// the load, the build and the render's buffers at their largest; in a batch, the
    /// largest of its jobs so far); `None` where the system does not tell it.
    pub peak_resident_bytes: Option<u64>,
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
            peak_resident_bytes: super::peak_resident_bytes(),
        }
    }

    /// The memory line of `--stats`: the backend's bytes and the process's peak
    /// resident bytes, each with its bytes per primitive.
    fn memory(&self) -> String {
        let per_prim = |b: u64| match self.accel_prims {
            0 => format!("{b} bytes"),
            n => format!("{b} bytes, {:.1} per primitive", b as f64 / n as f64),
        };
        let backend = match self.accel_bytes {
            0 => "unknown".to_string(),
            b => per_prim(b as u64),
        };
        match self.peak_resident_bytes {
            Some(peak) => format!("backend {backend}; peak resident {}", per_prim(peak)),
            None => format!("backend {backend}"),
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
