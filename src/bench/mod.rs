//! `emray bench`: the SPD suite rendered on both backends, with 1 and all threads, each
//! run in a child process of its own (so that its peak memory is its own), repeated and
//! interleaved (every backend and thread count of a scene side by side in each
//! repetition), with raw-casting runs for the renderer's overhead and Tachyon as a peer.

mod cpu;
mod peer;
pub(crate) mod raw;
mod report;

use crate::accel::{AccelError, Backend, WithAccel};
use crate::job::{
    Event, Job, JobError, OptionsError, RenderOptions, SceneError, SceneSource, load_scene,
};
use crate::output::OutputError;
use crate::render::RenderSettings;
use crate::scene::Scene;
use crate::spd::Database;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::{Arc, Mutex};
use std::time::Instant;

/// Why a benchmark (or one of its runs) failed.
#[derive(Debug, thiserror::Error)]
pub enum BenchError {
    /// A scene could not be generated, read or parsed.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// A scene file that is not there.
    #[error("{0}: no such scene file")]
    NoSuchScene(String),
    /// The worker threads could not be started.
    #[error("cannot start {threads} threads: {message}")]
    Threads {
        /// How many were asked for.
        threads: usize,
        /// Why they could not be.
        message: String,
    },
    /// The backend could not be built.
    #[error(transparent)]
    Accel(#[from] AccelError),
    /// The render options cannot be met.
    #[error(transparent)]
    Options(#[from] OptionsError),
    /// The render failed.
    #[error(transparent)]
    Job(#[from] JobError),
    /// The child process could not be started.
    #[error("cannot run {}: {message}", exe.display())]
    Spawn {
        /// The executable.
        exe: PathBuf,
        /// Why.
        message: String,
    },
    /// A run failed in its child process.
    #[error("{scene} on {backend} ({threads} threads, {mode:?}) failed ({status}): {stderr}")]
    RunFailed {
        /// The run's scene.
        scene: String,
        /// Its backend.
        backend: String,
        /// Its threads.
        threads: usize,
        /// What it measured.
        mode: Mode,
        /// The child's exit status.
        status: String,
        /// What the child printed on standard error.
        stderr: String,
    },
    /// A child's answer is not a run result.
    #[error("bad answer from a bench run ({message}): {line}")]
    BadAnswer {
        /// Why it does not parse.
        message: String,
        /// The answer.
        line: String,
    },
    /// A file or directory could not be read, written or created.
    #[error("{}: cannot {action}: {message}", path.display())]
    Io {
        /// The file or directory.
        path: PathBuf,
        /// `read`, `write` or `create`.
        action: &'static str,
        /// Why.
        message: String,
    },
    /// A `--baseline` file that is not what `emray bench --json` writes.
    #[error("{}:{line}:{column}: not an `emray bench --json` file: {message}", path.display())]
    NotSaved {
        /// The file.
        path: PathBuf,
        /// Where it stops making sense.
        line: usize,
        /// The column.
        column: usize,
        /// What is wrong.
        message: String,
    },
    /// Tachyon failed.
    #[error(transparent)]
    Peer(#[from] peer::PeerError),
    /// A report file could not be written.
    #[error(transparent)]
    Output(#[from] OutputError),
}

impl BenchError {
    fn io(path: impl Into<PathBuf>, action: &'static str, e: std::io::Error) -> Self {
        BenchError::Io {
            path: path.into(),
            action,
            message: e.to_string(),
        }
    }
}

/// What a run measures.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Mode {
    /// A full render.
    Render,
    /// The render's rays cast again with no shading.
    Raw,
}

/// One run, as passed to the child process.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunSpec {
    /// Scene: `spd:NAME[?size=N]` or a scene file.
    pub scene: String,
    /// Worker threads.
    pub threads: usize,
    /// What to measure.
    pub mode: Mode,
    /// Eye rays only: one ray per pixel centre (never SPD mode), the scene's lights
    /// removed and the ray tree cut at depth 1, so that a render casts its camera rays
    /// and nothing else, and render ÷ raw is the cost of
    /// emray's eye-ray pipeline (camera, packets, surfaces, shading, film) over casting
    /// the same rays.
    #[serde(default)]
    pub eye_only: bool,
    /// The render options, the backend among them ([`Config::options`]); a run saved
    /// by a version that described it otherwise reads as the defaults.
    #[serde(default)]
    pub options: RenderOptions,
}

impl RunSpec {
    /// The backend's name.
    pub fn backend(&self) -> &'static str {
        self.options.backend_options().backend.name()
    }

    /// The options the run renders with: its own, with depth 1 and no SPD mode for
    /// eye rays alone.
    fn render_options(&self) -> RenderOptions {
        let mut o = self.options.clone();
        if self.eye_only {
            o.max_depth = Some(1);
            // SPD mode's corner rays and fixed depth are not eye rays alone.
            o.spd = Some(false);
        }
        o
    }
}

/// Rays by type, as the render counted them.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Rays {
    /// Eye rays.
    pub eye: u64,
    /// Reflection rays.
    pub reflection: u64,
    /// Refraction rays.
    pub refraction: u64,
    /// Shadow rays.
    pub shadow: u64,
    /// Every ray.
    pub total: u64,
}

impl From<crate::render::RayCounts> for Rays {
    fn from(c: crate::render::RayCounts) -> Rays {
        Rays {
            eye: c.eye,
            reflection: c.reflection,
            refraction: c.refraction,
            shadow: c.shadow,
            total: c.total(),
        }
    }
}

/// What one child run measured.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunResult {
    /// Primitives in the scene.
    pub prims: usize,
    /// Load (generate and parse) time, ms.
    pub load_ms: f64,
    /// Acceleration-structure build time, ms.
    pub build_ms: f64,
    /// Render time (mode `render`) or raw casting time (mode `raw`), ms.
    pub ms: f64,
    /// Rays by type.
    pub rays: Rays,
    /// Peak resident memory of the process in KiB (`VmHWM`), when the system says.
    pub peak_kib: Option<u64>,
    /// The backend's description (Embree version and ISA, BVH nodes).
    pub accel: String,
    /// CPU time of the process's threads during the render (or the raw casting), ms.
    #[serde(default)]
    pub cpu_ms: Option<f64>,
    /// Time the machine's processors were stolen during it (all processors), ms.
    #[serde(default)]
    pub steal_ms: Option<f64>,
    /// Bytes of the backend's structure ([`AccelStats::bytes`](crate::accel::AccelStats::bytes);
    /// 0 when unknown).
    #[serde(default)]
    pub accel_bytes: usize,
}

/// What a child measured of its render or raw casting.
struct Measure {
    prims: usize,
    build_ms: f64,
    ms: f64,
    counts: crate::render::RayCounts,
    stats: crate::accel::AccelStats,
    cpu_ms: Option<f64>,
    steal_ms: Option<f64>,
}

/// The raw-casting work: record the render's queries, then cast them timed.
struct RawWork<'a> {
    scene: &'a Scene,
    settings: &'a RenderSettings,
}

impl WithAccel for RawWork<'_> {
    type Output = Measure;
    fn run<A: crate::accel::Accel>(self, accel: &A, build_ms: f64) -> Measure {
        let (queries, counts) = raw::record(self.scene, accel, self.settings);
        let mark = cpu::Mark::now();
        let cast = raw::cast(accel, &queries);
        let (cpu_ms, steal_ms) = mark.elapsed();
        Measure {
            prims: 0,
            build_ms,
            ms: cast.ms,
            counts,
            stats: accel.stats(),
            cpu_ms,
            steal_ms,
        }
    }
}

/// Do one run in this process (the child side of `emray bench`).
pub fn run_child(spec: &RunSpec) -> Result<RunResult, BenchError> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(spec.threads.max(1))
        .build()
        .map_err(|e| BenchError::Threads {
            threads: spec.threads,
            message: e.to_string(),
        })?;
    let t0 = Instant::now();
    let mut scene = load_scene(&spec.scene)?;
    if spec.eye_only {
        scene.lights.clear();
    }
    let load_ms = t0.elapsed().as_secs_f64() * 1e3;
    let options = spec.render_options();
    let m = pool.install(|| match spec.mode {
        Mode::Render => measure_render(&spec.scene, scene, options.clone()),
        Mode::Raw => measure_raw(&scene, &options),
    })?;
    let packet_width = options.backend_options().packet_width;
    let accel = match (spec.backend(), packet_width) {
        ("embree", 0) => format!("{}, eye rays one by one", m.stats.detail),
        ("embree", w) => format!("{}, eye rays in packets of {w}", m.stats.detail),
        _ => m.stats.detail.clone(),
    };
    Ok(RunResult {
        prims: m.prims,
        load_ms,
        build_ms: m.build_ms,
        ms: m.ms,
        rays: Rays::from(m.counts),
        peak_kib: crate::job::peak_resident_bytes().map(|b| b / 1024),
        accel,
        cpu_ms: m.cpu_ms,
        steal_ms: m.steal_ms,
        accel_bytes: m.stats.bytes,
    })
}

/// The render of a [`Job`] of the loaded `scene`, its CPU and stolen time measured
/// around the render phase alone.
fn measure_render(name: &str, scene: Scene, options: RenderOptions) -> Result<Measure, BenchError> {
    let prims = scene.prim_count_with_instances();
    let source = SceneSource::Loaded {
        name: name.to_string(),
        scene: Arc::new(scene),
    };
    let job = Job::render(source, options, None);
    let mark: Mutex<Option<cpu::Mark>> = Mutex::new(None);
    let times: Mutex<(Option<f64>, Option<f64>)> = Mutex::new((None, None));
    let observer = |e: Event<'_>| {
        let mut m = mark.lock().unwrap_or_else(|e| e.into_inner());
        match e {
            Event::Rendering => *m = Some(cpu::Mark::now()),
            Event::Rendered => {
                if let Some(start) = m.take() {
                    *times.lock().unwrap_or_else(|e| e.into_inner()) = start.elapsed();
                }
            }
            _ => {}
        }
    };
    let rendered = crate::job::render(&job, &observer)?;
    let (cpu_ms, steal_ms) = *times.lock().unwrap_or_else(|e| e.into_inner());
    let r = &rendered.report;
    Ok(Measure {
        prims,
        build_ms: r.time_ms.build,
        ms: r.time_ms.render,
        counts: rendered.rays,
        stats: rendered.accel.clone(),
        cpu_ms,
        steal_ms,
    })
}

/// The render's rays recorded, then cast again with no shading, timed.
fn measure_raw(scene: &Scene, options: &RenderOptions) -> Result<Measure, BenchError> {
    let resolved = options.resolve(scene)?;
    let work = RawWork {
        scene,
        settings: &resolved.settings,
    };
    let mut m = crate::accel::build(scene, &resolved.backend, work)?;
    m.prims = scene.prim_count_with_instances();
    Ok(m)
}

/// Run `spec` in a child process `exe bench --child JSON` and parse its answer.
pub fn run_in_child(exe: &Path, spec: &RunSpec) -> Result<RunResult, BenchError> {
    let json = serde_json::to_string(spec).expect("spec serialises");
    let out = Command::new(exe)
        .args(["bench", "--child", &json])
        .output()
        .map_err(|e| BenchError::Spawn {
            exe: exe.to_path_buf(),
            message: e.to_string(),
        })?;
    let stdout = String::from_utf8_lossy(&out.stdout);
    if !out.status.success() {
        return Err(BenchError::RunFailed {
            scene: spec.scene.clone(),
            backend: spec.backend().to_string(),
            threads: spec.threads,
            mode: spec.mode,
            status: out.status.to_string(),
            stderr: String::from_utf8_lossy(&out.stderr).trim().to_string(),
        });
    }
    // The answer is the last line (a library may print above it).
    let line = stdout.lines().last().unwrap_or("");
    serde_json::from_str(line).map_err(|e| BenchError::BadAnswer {
        message: e.to_string(),
        line: line.to_string(),
    })
}

/// What to benchmark.
#[derive(Clone, Debug, PartialEq)]
pub struct Config {
    /// Scenes, as on the command line.
    pub scenes: Vec<String>,
    /// Backends.
    pub backends: Vec<Backend>,
    /// Thread counts.
    pub threads: Vec<usize>,
    /// Repetitions of every run.
    pub reps: usize,
    /// Also measure raw casting.
    pub raw: bool,
    /// Also run the Tachyon peer when installed.
    pub peer: bool,
    /// Eye rays only (see [`RunSpec::eye_only`]).
    pub eye_only: bool,
    /// The render options of every run (the backend aside, which each run sets):
    /// what the command line asks for over the suite's own rules ([`Config::rules`]).
    pub options: RenderOptions,
}

impl Config {
    /// The suite's rules, under the options asked for: 512 × 512 in SPD mode, one
    /// sample per pixel, depth 5 and the full ray tree (no bailout) whatever the scene
    /// file says, so that runs of every version measure the same work.
    pub fn rules() -> RenderOptions {
        RenderOptions {
            res: Some(crate::job::Res {
                width: 512,
                height: 512,
            }),
            spd: Some(true),
            spp: Some(1),
            max_depth: Some(5),
            bailout: Some(0.0),
            ..RenderOptions::default()
        }
    }

    /// The image size of every run.
    pub fn res(&self) -> (u32, u32) {
        let r = self.options.res.unwrap_or(crate::job::Res {
            width: 512,
            height: 512,
        });
        (r.width, r.height)
    }

    /// The options of a run on `backend`.
    fn run_options(&self, backend: Backend) -> RenderOptions {
        RenderOptions {
            backend: Some(backend),
            ..self.options.clone()
        }
    }
}

/// The default suite: the eight SPD scenes at their default sizes, then balls and jacks
/// at other size factors to show how the cost grows.
pub fn default_scenes() -> Vec<String> {
    let mut v: Vec<String> = [
        "balls", "gears", "jacks", "mount", "rings", "teapot", "tetra", "tree",
    ]
    .iter()
    .map(|n| format!("spd:{n}"))
    .collect();
    for s in [2, 3, 5] {
        v.push(format!("spd:balls?size={s}"));
    }
    for s in [2, 3] {
        v.push(format!("spd:jacks?size={s}"));
    }
    v
}

/// One measured sample.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Sample {
    /// What was run.
    pub spec: RunSpec,
    /// Repetition index.
    pub rep: usize,
    /// What it measured.
    pub result: RunResult,
}

/// One Tachyon measurement.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PeerSample {
    /// Scene name.
    pub scene: String,
    /// Threads.
    pub threads: usize,
    /// Repetition index.
    pub rep: usize,
    /// Tachyon's ray-tracing time, ms.
    pub trace_ms: f64,
    /// emray's render time of the same file (pixel centres), ms.
    #[serde(default)]
    pub emray_ms: Option<f64>,
}

/// NFF files of the suite's scenes for Tachyon and emray's runs beside it (the angle set
/// to Tachyon's, see [`peer`]), in a private directory removed on drop.
struct PeerFiles {
    dir: std::path::PathBuf,
    files: std::collections::BTreeMap<String, (std::path::PathBuf, String)>,
}

impl PeerFiles {
    fn new(scenes: &[String]) -> Result<PeerFiles, BenchError> {
        let dir = std::env::temp_dir().join(format!("emray-bench-{}", std::process::id()));
        std::fs::create_dir_all(&dir).map_err(|e| BenchError::io(&dir, "create", e))?;
        let mut files = std::collections::BTreeMap::new();
        for (k, name) in scenes.iter().enumerate() {
            let spec = Database::parse_spec(name).map_err(SceneError::Spec)?;
            let text = match spec {
                Some((db, size)) => db.generate(size),
                // Tachyon reads NFF only.
                None if name.ends_with(".nff") => {
                    crate::load::text::read_lossy(Path::new(name)).map_err(SceneError::Load)?
                }
                None => continue,
            };
            let path = dir.join(format!("scene{k}.nff"));
            let text = peer::with_angle(&text, peer::TACHYON_ANGLE_DEG);
            std::fs::write(&path, &text).map_err(|e| BenchError::io(&path, "write", e))?;
            let scene = load_scene(name)?;
            files.insert(name.clone(), (path, peer::differences(&scene)));
        }
        Ok(PeerFiles { dir, files })
    }
}

impl Drop for PeerFiles {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

/// Everything a suite run measured.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Measured {
    /// emray runs.
    pub samples: Vec<Sample>,
    /// Tachyon runs.
    pub peers: Vec<PeerSample>,
    /// Scene → how Tachyon's picture differs.
    pub peer_notes: std::collections::BTreeMap<String, String>,
    /// Scene → share of pixels Tachyon and emray frame alike (`peer::framing`).
    pub peer_framing: std::collections::BTreeMap<String, f64>,
    /// Why there are no Tachyon runs, if there are none.
    pub peer_missing: String,
}

/// Run the suite: for every repetition, every scene, every thread count, every backend
/// and then Tachyon (interleaved, so that load changes on the machine hit every row
/// alike). `log` is told of every finished run.
pub fn run_suite(
    cfg: &Config,
    exe: &Path,
    log: &mut dyn FnMut(&str),
) -> Result<Measured, BenchError> {
    for s in &cfg.scenes {
        let spec = Database::parse_spec(s).map_err(SceneError::Spec)?;
        if spec.is_none() && !Path::new(s).is_file() {
            return Err(BenchError::NoSuchScene(s.clone()));
        }
    }
    let mut m = Measured::default();
    let peer_files = if !cfg.peer {
        m.peer_missing = "Tachyon not run (--no-peer).".into();
        None
    } else if !peer::available() {
        m.peer_missing =
            "Tachyon skipped: `tachyon` is not installed (Debian: apt-get install tachyon).".into();
        None
    } else {
        Some(PeerFiles::new(&cfg.scenes)?)
    };
    let modes: &[Mode] = if cfg.raw {
        &[Mode::Render, Mode::Raw]
    } else {
        &[Mode::Render]
    };
    for rep in 0..cfg.reps {
        for scene in &cfg.scenes {
            for &threads in &cfg.threads {
                for &backend in &cfg.backends {
                    for &mode in modes {
                        let spec = RunSpec {
                            scene: scene.clone(),
                            threads,
                            mode,
                            eye_only: cfg.eye_only,
                            options: cfg.run_options(backend),
                        };
                        let result = run_in_child(exe, &spec)?;
                        log(&format!(
                            "rep {} {scene} {} {threads}t {mode:?}: {:.1} ms",
                            rep + 1,
                            spec.backend(),
                            result.ms
                        ));
                        m.samples.push(Sample { spec, rep, result });
                    }
                }
                let Some((nff, note)) = peer_files.as_ref().and_then(|p| p.files.get(scene)) else {
                    continue;
                };
                let image = nff.with_extension("ppm");
                let (width, height) = cfg.res();
                let t = peer::run(nff, &image, width, height, threads)?;
                let emray_ms = run_peer_emray(cfg, exe, nff, threads)?;
                log(&format!(
                    "rep {} {scene} tachyon {threads}t: {:.1} ms (emray on its file {:.1} ms)",
                    rep + 1,
                    t.trace_ms,
                    emray_ms
                ));
                if !m.peer_framing.contains_key(scene) {
                    let framing = peer_framing(nff, &image, cfg)?;
                    m.peer_framing.insert(scene.clone(), framing);
                }
                m.peer_notes.insert(scene.clone(), note.clone());
                m.peers.push(PeerSample {
                    scene: scene.clone(),
                    threads,
                    rep,
                    trace_ms: t.trace_ms,
                    emray_ms: Some(emray_ms),
                });
            }
        }
    }
    Ok(m)
}

/// emray's render time of the peer's file `nff`: the renderer's default backend (Embree
/// when built with it), one ray per pixel centre, as Tachyon casts them.
fn run_peer_emray(cfg: &Config, exe: &Path, nff: &Path, threads: usize) -> Result<f64, BenchError> {
    let backend = if cfg.backends.contains(&Backend::Embree) {
        Backend::Embree
    } else {
        Backend::Bvh
    };
    let spec = RunSpec {
        scene: nff.to_string_lossy().into_owned(),
        threads,
        mode: Mode::Render,
        eye_only: false,
        options: RenderOptions {
            spd: Some(false),
            ..cfg.run_options(backend)
        },
    };
    Ok(run_in_child(exe, &spec)?.ms)
}

/// How alike Tachyon's picture `image` of `nff` and emray's frame the scene.
fn peer_framing(nff: &Path, image: &Path, cfg: &Config) -> Result<f64, BenchError> {
    let scene = load_scene(nff)?;
    let bytes = std::fs::read(image).map_err(|e| BenchError::io(image, "read", e))?;
    let (w, h, rgb) = peer::read_ppm(&bytes).ok_or_else(|| BenchError::Io {
        path: image.to_path_buf(),
        action: "read",
        message: "not a binary 8-bit PPM".into(),
    })?;
    if (w, h) != cfg.res() {
        return Ok(0.0);
    }
    Ok(peer::framing(&scene, w, h, &rgb))
}

/// Where the report goes besides standard output.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Outputs {
    /// CSV file of the rows.
    pub csv: Option<std::path::PathBuf>,
    /// JSON file of everything (machine, rows, summary, peers, samples).
    pub json: Option<std::path::PathBuf>,
    /// A JSON file of an earlier run to compare with.
    pub baseline: Option<std::path::PathBuf>,
}

/// Read a JSON file written by `emray bench --json`.
pub fn read_saved(path: &Path) -> Result<report::Saved, BenchError> {
    let text = std::fs::read_to_string(path).map_err(|e| BenchError::io(path, "read", e))?;
    serde_json::from_str(&text).map_err(|e| BenchError::NotSaved {
        path: path.to_path_buf(),
        line: e.line(),
        column: e.column(),
        message: e.to_string(),
    })
}

/// Run the suite and return the markdown report, writing the files of `outs`.
pub fn bench(
    cfg: &Config,
    outs: &Outputs,
    exe: &Path,
    log: &mut dyn FnMut(&str),
) -> Result<String, BenchError> {
    let base = outs.baseline.as_deref().map(read_saved).transpose()?;
    let mut machine = Machine::probe();
    let m = run_suite(cfg, exe, log)?;
    machine.load_after = load_average();
    let rows = report::rows(&m.samples);
    let summary = report::summary(&rows);
    let peers = report::peer_rows(&m);
    let mut md = report::markdown(&machine, &rows, &summary, &peers, &m.peer_missing);
    if let Some(b) = base {
        md.push_str("\n## Against the baseline\n\n");
        md.push_str(&report::compare(&rows, &b.rows));
    }
    if let Some(p) = &outs.csv {
        crate::output::write_text(p, &report::csv(&rows))?;
    }
    if let Some(p) = &outs.json {
        let saved = report::Saved {
            machine,
            rows,
            summary,
            peers,
            samples: m.samples,
        };
        let text = serde_json::to_string_pretty(&saved).expect("report serialises");
        crate::output::write_text(p, &text)?;
    }
    Ok(md)
}

/// The machine: CPU model, logical CPUs, load average.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Machine {
    /// CPU model name.
    pub cpu: String,
    /// Logical CPUs.
    pub cpus: usize,
    /// The ISA-relevant CPU flags (the best of sse4_2, avx, avx2, avx512f present).
    pub isa: String,
    /// `/proc/loadavg` when the suite started.
    pub load_before: String,
    /// `/proc/loadavg` when it ended.
    pub load_after: String,
}

impl Machine {
    /// What the system says about itself now (`load_after` left empty).
    pub fn probe() -> Machine {
        let info = std::fs::read_to_string("/proc/cpuinfo").unwrap_or_default();
        let field = |k: &str| {
            info.lines()
                .find(|l| l.starts_with(k))
                .and_then(|l| l.split_once(':'))
                .map(|(_, v)| v.trim().to_string())
                .unwrap_or_default()
        };
        let flags = field("flags");
        let has = |f: &str| flags.split_whitespace().any(|x| x == f);
        let isa = ["avx512f", "avx2", "avx", "sse4_2"]
            .into_iter()
            .find(|f| has(f))
            .unwrap_or("unknown")
            .to_string();
        Machine {
            cpu: if info.is_empty() {
                "unknown".into()
            } else {
                field("model name")
            },
            cpus: std::thread::available_parallelism().map_or(1, |n| n.get()),
            isa,
            load_before: load_average(),
            load_after: String::new(),
        }
    }
}

/// The first three fields of `/proc/loadavg`, or `unknown`.
pub fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .ok()
        .map(|s| s.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .unwrap_or_else(|| "unknown".into())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_suite_names_parse() {
        for s in default_scenes() {
            assert!(Database::parse_spec(&s).unwrap().is_some(), "{s}");
        }
    }

    #[test]
    fn child_run_measures_and_counts() {
        let spec = RunSpec {
            scene: "spd:balls?size=1".into(),
            threads: 1,
            mode: Mode::Render,
            eye_only: false,
            options: RenderOptions {
                backend: Some(Backend::Bvh),
                res: Some("16x16".parse().unwrap()),
                ..Config::rules()
            },
        };
        let r = run_child(&spec).unwrap();
        assert_eq!(r.rays.eye, 17 * 17);
        assert_eq!(
            r.rays.total,
            r.rays.eye + r.rays.reflection + r.rays.refraction + r.rays.shadow
        );
        assert!(r.rays.reflection > 0 && r.rays.shadow > 0);
        assert_eq!(
            r.prims,
            crate::job::load_scene("spd:balls?size=1")
                .unwrap()
                .prim_count_with_instances()
        );
        let raw = run_child(&RunSpec {
            mode: Mode::Raw,
            ..spec.clone()
        })
        .unwrap();
        assert_eq!(raw.rays, r.rays, "the raw run casts the render's rays");
        assert!(r.accel_bytes > 30 * r.prims, "{} bytes", r.accel_bytes);
        // Eye rays only: the same eye rays, nothing else, and raw casting casts them.
        let eye = RunSpec {
            eye_only: true,
            ..spec.clone()
        };
        let e = run_child(&eye).unwrap();
        assert_eq!(e.rays.eye, 16 * 16, "pixel centres");
        assert_eq!(e.rays.total, e.rays.eye, "{:?}", e.rays);
        let raw = run_child(&RunSpec {
            mode: Mode::Raw,
            ..eye
        })
        .unwrap();
        assert_eq!(raw.rays, e.rays);
        assert!(
            run_child(&RunSpec {
                scene: "spd:nope".into(),
                ..spec
            })
            .is_err()
        );
    }
}
