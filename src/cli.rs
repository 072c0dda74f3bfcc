//! Command-line arguments and their conversion into library settings.

use clap::{Args, Parser, Subcommand, ValueEnum};
use emray::accel::{Backend, EmbreeQuality};
use emray::output::Encoding;
use std::path::PathBuf;

/// emray: a Whitted ray tracer for NFF scenes on Intel Embree or a pure-Rust BVH.
#[derive(Parser, Debug)]
#[command(name = "emray", version, about, long_about = None)]
pub struct Cli {
    /// What to do; with none, renders the built-in default scene to emray.png.
    #[command(subcommand)]
    pub command: Option<Command>,
}

/// Subcommands.
#[derive(Subcommand, Debug)]
pub enum Command {
    /// Render one or more scene files (or `spd:NAME[?size=N]` generated scenes).
    Render(RenderArgs),
    /// Write a Standard Procedural Database as NFF, as the SPD 3.14 programs do.
    Gen(GenArgs),
    /// Render many scenes: failures isolated, resumable, split into shards.
    Batch(BatchArgs),
    /// Stitch parts rendered with `render --tile` or `--crop` into the whole image.
    Merge(MergeArgs),
    /// Benchmark suite: SPD scenes on both backends, 1 and all threads, raw casting,
    /// Tachyon as a peer; markdown to standard output.
    Bench(BenchArgs),
    /// Error metrics of an image against a reference (RMSE, PSNR, FLIP, ...); exit
    /// status 0 within the thresholds, 1 beyond, 2 on a usage or I/O error.
    Compare(crate::quality_cmd::CompareArgs),
    /// Numerical stress cases (scale, translation, far/tiny spheres, watertightness)
    /// with their measured numbers; exit status 1 if a bound is broken.
    Stress(crate::quality_cmd::StressArgs),
    /// Error against time: the f64 reference once, then a sweep of spp, adaptive AA,
    /// bailout, depth and backends, to DIR/study.csv; the error-against-time plot to
    /// DIR/study.svg and DIR/study.png.
    Study(crate::quality_cmd::StudyArgs),
    /// Solve a scene's diffuse interreflection by radiosity and render a view of it.
    Radiosity(RadiosityArgs),
}

/// Radiosity solvers as named on the command line.
#[derive(Clone, Copy, Debug, ValueEnum, PartialEq, Eq)]
pub enum SolverArg {
    /// Progressive refinement (shoot the most unshot energy first).
    Progressive,
    /// Gauss–Seidel on the full form-factor matrix (small meshes only).
    GaussSeidel,
}

/// Form-factor methods as named on the command line.
#[derive(Clone, Copy, Debug, ValueEnum, PartialEq, Eq)]
pub enum FormFactorArg {
    /// Exact point-to-polygon form factors with ray-cast visibility (either backend).
    Raycast,
    /// Hemicube (Cohen & Greenberg 1985): item buffers on the five faces.
    Hemicube,
}

/// `emray radiosity`.
#[derive(Args, Debug, Clone)]
pub struct RadiosityArgs {
    /// Scene file (surfaces whose material has an `emission` are the lights).
    #[arg(value_name = "SCENE")]
    pub scene: PathBuf,
    /// Output image (.png or .exr).
    #[arg(short, long, value_name = "OUT", default_value = "radiosity.png")]
    pub output: PathBuf,
    /// Also write the solved mesh with vertex colours as PLY.
    #[arg(long, value_name = "FILE.ply")]
    pub ply: Option<PathBuf>,
    /// Meshing, form factors and solver.
    #[command(flatten)]
    pub solve: RadiositySolveArgs,
    /// Ray-query backend for visibility and viewing.
    #[arg(long, value_enum)]
    pub backend: Option<BackendArg>,
    /// Image size, overriding the scene's resolution.
    #[arg(long, value_name = "WxH", value_parser = parse_res)]
    pub res: Option<(u32, u32)>,
    /// Samples per pixel of the view, rounded down to a square (1, 4, 9, ...).
    #[arg(long, default_value_t = 4, value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub spp: u32,
    /// Worker threads (default: all cores).
    #[arg(short, long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub threads: Option<u32>,
    /// Print mesh size, iterations, residuals and timings.
    #[arg(long)]
    pub stats: bool,
    /// Append the statistics (with the residual curve) as one JSON object to FILE.
    #[arg(long, value_name = "FILE")]
    pub stats_json: Option<PathBuf>,
}

/// The radiosity options `emray radiosity` and `emray render --gi radiosity` share.
#[derive(Args, Debug, Clone, PartialEq)]
#[command(next_help_heading = "Radiosity")]
pub struct RadiositySolveArgs {
    /// Longest element edge, in scene units [default: 1/12 of the scene's diagonal].
    #[arg(long, value_name = "SIZE")]
    pub patch_size: Option<f32>,
    /// Form-factor sample points per shooting element: 1, 4, 16 or 64.
    #[arg(long, default_value_t = 4, value_parser = parse_power_of_four)]
    pub ff_samples: u32,
    /// Visibility rays per pair of elements: 1, 4, 16 or 64.
    #[arg(long, default_value_t = 1, value_parser = parse_power_of_four)]
    pub vis_samples: u32,
    /// Solver.
    #[arg(long, value_enum, default_value_t = SolverArg::Progressive)]
    pub solver: SolverArg,
    /// Form-factor method.
    #[arg(long, value_enum, default_value_t = FormFactorArg::Raycast)]
    pub form_factors: FormFactorArg,
    /// Hemicube resolution: pixels across the top face (even).
    #[arg(long, default_value_t = 128, value_parser = clap::value_parser!(u32).range(2..=4096))]
    pub hemicube_res: u32,
    /// Adaptive subdivision: split elements whose radiosity differs from a neighbour's
    /// by more than this fraction of the largest reflected radiosity, then solve again.
    #[arg(long, value_name = "FRACTION")]
    pub subdiv_threshold: Option<f32>,
    /// Smallest element edge adaptive subdivision makes [default: patch size / 8].
    #[arg(long, value_name = "SIZE")]
    pub min_patch_size: Option<f32>,
    /// Most rounds of adaptive subdivision.
    #[arg(long, default_value_t = 3)]
    pub subdiv_passes: u32,
    /// Stop when the unshot power is below this fraction of the emitted power.
    #[arg(long, default_value_t = 1e-3)]
    pub epsilon: f64,
    /// Most shots (progressive) or sweeps (Gauss–Seidel).
    #[arg(long, default_value_t = 1_000_000)]
    pub max_iterations: usize,
}

impl Default for RadiositySolveArgs {
    /// The same values as the options' defaults.
    fn default() -> Self {
        RadiositySolveArgs {
            patch_size: None,
            ff_samples: 1,
            vis_samples: 0,
            solver: SolverArg::Progressive,
            form_factors: FormFactorArg::Raycast,
            hemicube_res: 128,
            subdiv_threshold: None,
            min_patch_size: None,
            subdiv_passes: 3,
            epsilon: 1e-3,
            max_iterations: 1_000_000,
        }
    }
}

impl RadiositySolveArgs {
    /// The library settings.
    pub fn settings(&self) -> emray::radiosity::RadiositySettings {
        use emray::radiosity::{FormFactorMethod, RadiositySettings, SolverKind};
        RadiositySettings {
            patch_size: self.patch_size,
            shooter_level: self.ff_samples,
            visibility_level: self.vis_samples,
            epsilon: self.epsilon,
            max_iterations: self.max_iterations,
            solver: match self.solver {
                SolverArg::Progressive => SolverKind::Progressive,
                SolverArg::GaussSeidel => SolverKind::GaussSeidel,
            },
            form_factors: match self.form_factors {
                FormFactorArg::Raycast => FormFactorMethod::RayCast,
                FormFactorArg::Hemicube => FormFactorMethod::Hemicube(self.hemicube_res),
            },
            subdiv_threshold: self.subdiv_threshold,
            min_patch_size: self.min_patch_size,
            subdiv_passes: self.subdiv_passes,
        }
    }
}

/// The level `l` of a count `4^l` in 1..=64.
fn parse_power_of_four(s: &str) -> Result<u32, String> {
    match s.trim() {
        "1" => Ok(0),
        "4" => Ok(1),
        "16" => Ok(2),
        "64" => Ok(3),
        _ => Err(format!("'{s}' is not one of 1, 4, 16, 64")),
    }
}

/// `emray bench`.
#[derive(Args, Debug, Clone)]
pub struct BenchArgs {
    /// Scenes (`spd:NAME[?size=N]` or NFF files) [default: the SPD suite: balls, gears,
    /// jacks, mount, rings, teapot, tetra, tree, plus balls at sizes 2, 3, 5 and jacks at
    /// 2, 3].
    #[arg(value_name = "SCENE")]
    pub scenes: Vec<String>,
    /// Backends to compare [default: both, or the BVH alone without Embree].
    #[arg(long, value_enum, value_delimiter = ',')]
    pub backend: Vec<BackendArg>,
    /// Thread counts [default: 1 and all cores].
    #[arg(short, long, value_delimiter = ',', value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub threads: Vec<u32>,
    /// Repetitions of every run (median and spread are reported).
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u32).range(1..=1000))]
    pub reps: u32,
    /// Image size.
    #[arg(long, value_name = "WxH", value_parser = parse_res, default_value = "512x512")]
    pub res: (u32, u32),
    /// Render with one ray per pixel centre instead of SPD mode's corner rays.
    #[arg(long)]
    pub no_spd: bool,
    /// Embree build quality (RTC_BUILD_QUALITY_*).
    #[arg(long, value_enum, default_value_t = QualityArg::Medium)]
    pub embree_quality: QualityArg,
    /// Eye rays per Embree packet (0, 4, 8 or 16; 0 casts them one by one).
    #[arg(long, value_name = "N", default_value_t = 8, value_parser = packet_width)]
    pub packet_width: u32,
    /// Skip the raw-casting runs.
    #[arg(long)]
    pub no_raw: bool,
    /// Skip Tachyon.
    #[arg(long)]
    pub no_peer: bool,
    /// Write the rows as CSV to FILE.
    #[arg(long, value_name = "FILE")]
    pub csv: Option<PathBuf>,
    /// Write everything (machine, rows, summary, samples) as JSON to FILE.
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
    /// Compare with a JSON file of an earlier run: per-row ratios.
    #[arg(long, value_name = "FILE.json")]
    pub baseline: Option<PathBuf>,
    /// Run one measurement in this process (used by the suite itself).
    #[arg(long, hide = true, value_name = "JSON")]
    pub child: Option<String>,
}

/// `emray batch`.
#[derive(Args, Debug, Clone)]
pub struct BatchArgs {
    /// Scene files, globs (quoted, e.g. 'scenes/*.nff') or `spd:NAME[?size=N]` specs.
    #[arg(value_name = "SCENE")]
    pub scenes: Vec<PathBuf>,
    /// A TOML manifest of jobs (README "Batch rendering"), instead of scene arguments.
    #[arg(short, long, value_name = "FILE.toml", conflicts_with = "scenes")]
    pub manifest: Option<PathBuf>,
    /// Output template: `{stem}`, `{backend}`, `{index}`, `{spp}` [default: `{stem}.png`,
    /// or the manifest's].
    #[arg(short, long, value_name = "TEMPLATE")]
    pub output: Option<String>,
    /// Ray-query backend (overrides the manifest).
    #[arg(long, value_enum)]
    pub backend: Option<BackendArg>,
    /// Image size, overriding the scenes' (and the manifest's).
    #[arg(long, value_name = "WxH", value_parser = parse_res)]
    pub res: Option<(u32, u32)>,
    /// Samples per pixel (overrides the manifest).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=65536))]
    pub spp: Option<u32>,
    /// Maximum ray-tree depth (overrides the manifest).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=64))]
    pub max_depth: Option<u32>,
    /// SPD testing mode for every job.
    #[arg(long)]
    pub spd: bool,
    /// PNG value encoding (overrides the manifest).
    #[arg(long, value_enum)]
    pub encoding: Option<EncodingArg>,
    /// Worker threads in all (default: all cores).
    #[arg(short, long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub threads: Option<u32>,
    /// Jobs rendered at once, sharing the threads.
    #[arg(short, long, value_name = "N", default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub jobs: u32,
    /// Run only shard I of N: the jobs whose name hashes (FNV-1a 64) to I modulo N.
    #[arg(long, value_name = "I/N", value_parser = emray::batch::parse_shard)]
    pub shard: Option<(u32, u32)>,
    /// Skip jobs whose output exists and decodes as a whole image (resume).
    #[arg(long)]
    pub skip_existing: bool,
    /// Write a JSON report of every job to FILE (rewritten after each job); `{shard}`
    /// in the name becomes the shard index.
    #[arg(long, value_name = "FILE")]
    pub report: Option<String>,
    /// Print this shard's jobs (name, scene, output) and exit without rendering.
    #[arg(long)]
    pub list: bool,
    /// Refuse jobs estimated to need more memory (e.g. 8G) [default: 3/4 of RAM].
    #[arg(long, value_name = "SIZE", value_parser = emray::batch::limits::parse_size)]
    pub max_memory: Option<u64>,
    /// No progress, only errors.
    #[arg(short, long)]
    pub quiet: bool,
}

/// `emray merge`.
#[derive(Args, Debug, Clone)]
pub struct MergeArgs {
    /// The parts (EXR files from `render --tile` or `--crop`).
    #[arg(required = true, value_name = "PART.exr")]
    pub parts: Vec<PathBuf>,
    /// The whole image (.exr or .png).
    #[arg(short, long, value_name = "FULL")]
    pub output: PathBuf,
    /// PNG value encoding.
    #[arg(long, value_enum, default_value_t = EncodingArg::Srgb)]
    pub encoding: EncodingArg,
}

/// `emray gen`.
#[derive(Args, Debug, Clone)]
pub struct GenArgs {
    /// Database: balls, gears, jacks, lattice, mount, rings, shells, sombrero, teapot,
    /// tetra, tree.
    #[arg(value_name = "DATABASE")]
    pub database: String,
    /// Size factor (default: the SPD program's default for the database).
    #[arg(short, long)]
    pub size: Option<u32>,
    /// Output file (default: standard output).
    #[arg(short, long, value_name = "FILE.nff")]
    pub output: Option<std::path::PathBuf>,
}

/// The backends as named on the command line.
#[derive(Clone, Copy, Debug, ValueEnum, PartialEq, Eq)]
pub enum BackendArg {
    /// Intel Embree (default when built with the `embree` feature).
    Embree,
    /// The pure-Rust BVH.
    Bvh,
}

impl From<BackendArg> for Backend {
    fn from(b: BackendArg) -> Self {
        match b {
            BackendArg::Embree => Backend::Embree,
            BackendArg::Bvh => Backend::Bvh,
        }
    }
}

/// Embree build qualities as named on the command line.
#[derive(Clone, Copy, Debug, ValueEnum, PartialEq, Eq)]
pub enum QualityArg {
    /// Morton-code build: fastest to build.
    Low,
    /// Binned SAH (Embree's default).
    Medium,
    /// SAH with spatial splits: slowest to build, fastest to trace.
    High,
}

impl From<QualityArg> for EmbreeQuality {
    fn from(q: QualityArg) -> Self {
        match q {
            QualityArg::Low => EmbreeQuality::Low,
            QualityArg::Medium => EmbreeQuality::Medium,
            QualityArg::High => EmbreeQuality::High,
        }
    }
}

/// PNG value encodings.
#[derive(Clone, Copy, Debug, ValueEnum, PartialEq, Eq)]
pub enum EncodingArg {
    /// sRGB transfer curve (default).
    Srgb,
    /// Values written as they are.
    Linear,
}

impl From<EncodingArg> for Encoding {
    fn from(e: EncodingArg) -> Self {
        match e {
            EncodingArg::Srgb => Encoding::Srgb,
            EncodingArg::Linear => Encoding::Linear,
        }
    }
}

/// Antialiasing modes as named on the command line.
#[derive(Clone, Copy, Debug, ValueEnum, PartialEq, Eq)]
pub enum AaArg {
    /// `--spp` stratified samples per pixel.
    Uniform,
    /// Adaptive corner subdivision (`--aa-threshold`, `--aa-depth`).
    Adaptive,
}

/// `emray render`.
#[derive(Args, Debug, Clone)]
pub struct RenderArgs {
    /// Scene files (NFF), or generated SPD scenes as `spd:NAME` / `spd:NAME?size=N`.
    #[arg(required = true, value_name = "SCENE")]
    pub scenes: Vec<PathBuf>,
    /// Output file (.png or .exr), or a template with `{stem}` for several scenes.
    /// Default: `{stem}.png` in the current directory.
    #[arg(short, long, value_name = "OUT")]
    pub output: Option<String>,
    /// Ray-query backend.
    #[arg(long, value_enum)]
    pub backend: Option<BackendArg>,
    /// Image size, overriding the scene's resolution.
    #[arg(long, value_name = "WxH", value_parser = parse_res)]
    pub res: Option<(u32, u32)>,
    /// Samples per pixel (stratified; 1 = pixel centre) [default: the scene file's
    /// `[render] spp`, else 1].
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=65536))]
    pub spp: Option<u32>,
    /// Maximum ray-tree depth, the eye ray being depth 1 [default: the scene file's
    /// `[render] max_depth`, else 5].
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=64))]
    pub max_depth: Option<u32>,
    /// Worker threads (default: all cores).
    #[arg(short, long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub threads: Option<u32>,
    /// SPD testing mode: 513x513 corner rays for 512x512, depth 5, ray statistics.
    #[arg(long)]
    pub spd: bool,
    /// Embree build quality (RTC_BUILD_QUALITY_*).
    #[arg(long, value_enum, default_value_t = QualityArg::Medium)]
    pub embree_quality: QualityArg,
    /// Embree robust traversal (RTC_SCENE_FLAG_ROBUST) on every scene: no ray slips
    /// between triangles sharing an edge, at some cost in speed.
    #[arg(long)]
    pub embree_robust: bool,
    /// Cast each tile's primary rays together, as Embree packets of this many rays
    /// (`rtcIntersect4/8/16`); 0 casts them one by one. Used with one sample per pixel
    /// (SPD mode included). Analytic shapes give the same hits either way; Embree's
    /// packet triangle test may round a ray through a shared edge to the other triangle.
    #[arg(long, value_name = "N", default_value_t = 8, value_parser = packet_width)]
    pub packet_width: u32,
    /// Antialiasing: `uniform` (`--spp` stratified samples) or `adaptive` (corner rays
    /// shared by neighbouring pixels, subdivided where the corners differ).
    #[arg(long, value_enum, default_value_t = AaArg::Uniform)]
    pub aa: AaArg,
    /// Adaptive AA: largest corner difference (linear, any channel) left unsplit.
    #[arg(long, value_name = "T", default_value_t = emray::render::DEFAULT_AA_THRESHOLD)]
    pub aa_threshold: f32,
    /// Adaptive AA: most subdivision levels per pixel (0 = the four corners only).
    #[arg(long, value_name = "D", default_value_t = emray::render::DEFAULT_AA_DEPTH,
          value_parser = clap::value_parser!(u32).range(0..=8))]
    pub aa_depth: u32,
    /// No reflected/refracted ray whose accumulated weight (product of Ks, T and filter
    /// colours from the eye) is below W; 0 = the full ray tree [default: 0.001, 0 with
    /// --spd].
    #[arg(long, value_name = "W")]
    pub bailout: Option<f32>,
    /// Render the f64 reference instead: everything in double precision, brute-force
    /// traversal, N×N stratified samples per pixel with N = floor(sqrt(--spp))
    /// [default --spp 256: 16×16]. Spheres, cones and triangles only; other scenes are
    /// refused.
    #[arg(long)]
    pub reference: bool,
    /// Cast the rays that cannot change the image too (shadow rays to lights behind the
    /// surface, reflection rays off Ks = 0): only to measure what skipping them saves.
    #[arg(long)]
    pub no_skip: bool,
    /// Print primitives, timings, ray counts and Mrays/s.
    #[arg(long)]
    pub stats: bool,
    /// Append one JSON object per render to FILE.
    #[arg(long, value_name = "FILE")]
    pub stats_json: Option<PathBuf>,
    /// PNG value encoding.
    #[arg(long, value_enum, default_value_t = EncodingArg::Srgb)]
    pub encoding: EncodingArg,
    /// Render only band I of N horizontal bands, to an EXR part for `emray merge`.
    #[arg(long, value_name = "I/N", value_parser = emray::batch::parse_shard, conflicts_with = "crop")]
    pub tile: Option<(u32, u32)>,
    /// Render only columns x0..x1 and rows y0..y1 (half-open), to an EXR part.
    #[arg(long, value_name = "x0,x1,y0,y1", value_parser = emray::batch::parse_crop)]
    pub crop: Option<emray::Region>,
    /// Refuse a render estimated to need more memory (e.g. 8G) [default: 3/4 of RAM].
    #[arg(long, value_name = "SIZE", value_parser = emray::batch::limits::parse_size)]
    pub max_memory: Option<u64>,
    /// Environment map for rays that leave the scene (PNG/JPEG: 2:1 latitude-longitude
    /// or a 4:3 cube cross, or a directory of six cube faces px, nx, py, ny, pz, nz),
    /// replacing the scene's own.
    #[arg(long, value_name = "FILE|DIR")]
    pub envmap: Option<PathBuf>,
    /// No progress bar and no messages but errors.
    #[arg(short, long)]
    pub quiet: bool,
    /// More log output (repeat for more).
    #[arg(short, long, action = clap::ArgAction::Count)]
    pub verbose: u8,
    /// Global illumination: `radiosity` solves the diffuse interreflection first and
    /// takes the diffuse term of polygons and meshes from it (two-pass).
    #[arg(long, value_enum)]
    pub gi: Option<GiArg>,
    /// The radiosity pass of `--gi radiosity` (the same options as `emray radiosity`).
    #[command(flatten)]
    pub radiosity: RadiositySolveArgs,
    /// Shadow rays per emitting triangle (area light), a square number: 16 = 4×4
    /// strata.
    #[arg(long, default_value_t = 16, value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub area_samples: u32,
}

/// Global-illumination methods.
#[derive(Clone, Copy, Debug, ValueEnum, PartialEq, Eq)]
pub enum GiArg {
    /// Two-pass: radiosity for the diffuse term, Whitted for the specular paths.
    Radiosity,
}

impl RenderArgs {
    /// The arguments for a bare `emray`: the default scene to `emray.png`.
    pub fn default_scene() -> Self {
        RenderArgs {
            scenes: Vec::new(),
            output: Some("emray.png".into()),
            backend: None,
            res: None,
            spp: None,
            max_depth: None,
            threads: None,
            spd: false,
            embree_quality: QualityArg::Medium,
            embree_robust: false,
            packet_width: 8,
            aa: AaArg::Uniform,
            aa_threshold: emray::render::DEFAULT_AA_THRESHOLD,
            aa_depth: emray::render::DEFAULT_AA_DEPTH,
            bailout: None,
            no_skip: false,
            reference: false,
            stats: false,
            stats_json: None,
            encoding: EncodingArg::Srgb,
            tile: None,
            crop: None,
            max_memory: None,
            envmap: None,
            quiet: false,
            verbose: 0,
            gi: None,
            radiosity: RadiositySolveArgs::default(),
            area_samples: 16,
        }
    }
}

impl BatchArgs {
    /// The settings that override every job's.
    pub fn overrides(&self) -> emray::batch::manifest::Overrides {
        emray::batch::manifest::Overrides {
            output: self.output.clone(),
            backend: self.backend.map(Backend::from),
            res: self.res,
            spp: self.spp,
            max_depth: self.max_depth,
            spd: self.spd,
            encoding: self.encoding.map(Encoding::from),
        }
    }
}

/// Largest accepted image side; larger sizes are refused before any allocation.
pub const MAX_SIDE: u32 = 65536;
/// Largest accepted pixel count (2^28, 268 megapixels).
pub const MAX_PIXELS: u64 = 1 << 28;

pub fn parse_res(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("'{s}' is not WxH (e.g. 640x480)"))?;
    let w: u32 = w
        .trim()
        .parse()
        .map_err(|_| format!("bad width in '{s}'"))?;
    let h: u32 = h
        .trim()
        .parse()
        .map_err(|_| format!("bad height in '{s}'"))?;
    if w == 0 || h == 0 {
        return Err(format!("'{s}': width and height must be at least 1"));
    }
    if w > MAX_SIDE || h > MAX_SIDE || w as u64 * h as u64 > MAX_PIXELS {
        return Err(format!(
            "'{s}' is too large (at most {MAX_SIDE} per side and {MAX_PIXELS} pixels)"
        ));
    }
    Ok((w, h))
}

/// `--packet-width`: 0, 4, 8 or 16.
fn packet_width(s: &str) -> Result<u32, String> {
    match s.parse::<u32>() {
        Ok(n @ (0 | 4 | 8 | 16)) => Ok(n),
        _ => Err(format!("expected 0, 4, 8 or 16, got {s:?}")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn res_parses_and_refuses() {
        assert_eq!(parse_res("640x480"), Ok((640, 480)));
        assert!(parse_res("0x10").is_err());
        assert!(parse_res("abc").is_err());
        assert!(parse_res("100000x10").is_err());
        assert!(parse_res("60000x60000").is_err());
    }

    fn radiosity_options(cmd: &[&str]) -> RadiositySolveArgs {
        match Cli::try_parse_from(cmd).unwrap().command {
            Some(Command::Radiosity(a)) => a.solve,
            Some(Command::Render(a)) => a.radiosity,
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn render_and_radiosity_share_the_radiosity_options() {
        let opts = [
            "--patch-size",
            "0.5",
            "--form-factors",
            "hemicube",
            "--hemicube-res",
            "64",
            "--subdiv-threshold",
            "0.1",
            "--min-patch-size",
            "0.05",
            "--subdiv-passes",
            "2",
            "--ff-samples",
            "16",
            "--epsilon",
            "1e-4",
        ];
        let rad = radiosity_options(&[&["emray", "radiosity", "s.toml"], &opts[..]].concat());
        let gi = ["emray", "render", "s.toml", "--gi", "radiosity"];
        let render = radiosity_options(&[&gi[..], &opts[..]].concat());
        assert_eq!(rad, render);
        let s = rad.settings();
        assert_eq!(
            s.form_factors,
            emray::radiosity::FormFactorMethod::Hemicube(64)
        );
        assert_eq!((s.subdiv_threshold, s.subdiv_passes), (Some(0.1), 2));
        assert_eq!((s.patch_size, s.shooter_level), (Some(0.5), 2));
        // Without options: the defaults, which are the library's.
        let none = radiosity_options(&["emray", "radiosity", "s.toml"]);
        assert_eq!(none, RadiositySolveArgs::default());
        assert_eq!(radiosity_options(&gi), none);
        assert_eq!(
            none.settings(),
            emray::radiosity::RadiositySettings::default()
        );
    }

    #[test]
    fn packet_width_is_one_of_the_embree_widths() {
        for n in [0, 4, 8, 16] {
            assert_eq!(packet_width(&n.to_string()), Ok(n));
        }
        for bad in ["3", "32", "-8", "eight"] {
            let e = packet_width(bad).unwrap_err();
            assert!(e.contains("0, 4, 8 or 16") && e.contains(bad), "{e}");
        }
    }
}
