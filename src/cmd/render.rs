//! `emray render` (and a bare `emray`): render scene files or generated SPD scenes to
//! PNG or EXR, whole or one part of an image for `emray merge`.

use super::args::{
    BackendArg, EncodingArg, LogArgs, QualityArg, RadiositySolveArgs, packet_width, parse_res,
};
use super::error::{error_line, is_closed_pipe, print};
use super::insight;
use super::jobs::{self, Job};
use super::progress::TileBar;
use super::{Error, append_json_line, outputs, thread_pool};
use anyhow::{Result, anyhow, bail};
use clap::ValueEnum;
use emray::Scene;
use emray::accel::{Backend, BackendOptions};
use emray::job::{self, Part, RenderRequest, Report, limits};
use emray::load;
use emray::output::{self, Format, part};
use emray::render::aov::{AovFilm, AovSet};
use emray::render::{Aa, Film, RenderSettings};
use emray::scene::Environment;
use emray::spd::Database;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The built-in default scene.
const DEFAULT_SCENE: &str = include_str!("../../scenes/default.nff");

/// Antialiasing modes as named on the command line.
#[derive(Clone, Copy, Debug, ValueEnum, PartialEq, Eq)]
pub enum AaArg {
    /// `--spp` stratified samples per pixel.
    Uniform,
    /// Adaptive corner subdivision (`--aa-threshold`, `--aa-depth`).
    Adaptive,
}

/// `emray render`.
#[derive(clap::Args, Debug, Clone)]
pub struct Args {
    /// Scene files: NFF, TOML (`.toml`), OBJ (`.obj`), or `spd:NAME[?size=N]`.
    #[arg(required = true, value_name = "SCENE")]
    pub scenes: Vec<PathBuf>,
    /// Output file (.png or .exr), a template: `{stem}` (the scene file's stem),
    /// `{backend}`, `{index}` (the scene's position, from 0), `{spp}` (as `--spp`, 1
    /// without); several scenes need one. Default: `{stem}.png` in the current
    /// directory.
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
    /// Embree's fast traversal: without RTC_SCENE_FLAG_ROBUST, which emray sets on every
    /// scene by default so that no ray slips between triangles sharing an edge. Faster
    /// on triangle scenes, at the risk of pinholes in meshes.
    #[arg(long)]
    pub embree_fast: bool,
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
    /// Render only band I of N horizontal bands (I counts from 0: 0 ≤ I < N), to an EXR
    /// part for `emray merge`.
    #[arg(long, value_name = "I/N", value_parser = emray::job::parse_tile, conflicts_with = "crop")]
    pub tile: Option<(u32, u32)>,
    /// Render only columns x0..x1 and rows y0..y1 (half-open), to an EXR part.
    #[arg(long, value_name = "x0,x1,y0,y1", value_parser = emray::job::parse_crop)]
    pub crop: Option<emray::Region>,
    /// Refuse a render estimated to need more memory (e.g. 8G) [default: 3/4 of RAM].
    #[arg(long, value_name = "SIZE", value_parser = emray::job::limits::parse_size)]
    pub max_memory: Option<u64>,
    /// Environment map for rays that leave the scene (PNG/JPEG: 2:1 latitude-longitude
    /// or a 4:3 cube cross, or a directory of six cube faces px, nx, py, ny, pz, nz),
    /// replacing the scene's own.
    #[arg(long, value_name = "FILE|DIR")]
    pub envmap: Option<PathBuf>,
    /// `-q` and `-v`.
    #[command(flatten)]
    pub log: LogArgs,
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
    /// Output variables to write as EXR layers beside the colour, comma-separated:
    /// depth (Z), normal (N.X N.Y N.Z), albedo (albedo.R/G/B), position (P.X P.Y P.Z),
    /// id (with OUT.ids.json), rays, time; or all (docs/aov.md).
    #[arg(long, value_name = "LIST", value_parser = insight::parse_aov)]
    pub aov: Option<AovSet>,
    /// A heat map of a per-pixel cost: rays (cast), time (spent) or depth (of the
    /// deepest ray), to a PNG with a colour bar (a template, as `-o`); may be repeated.
    #[arg(long, num_args = 2, value_names = ["WHAT", "FILE.png"], action = clap::ArgAction::Append)]
    pub heatmap: Vec<String>,
}

/// Global-illumination methods.
#[derive(Clone, Copy, Debug, ValueEnum, PartialEq, Eq)]
pub enum GiArg {
    /// Two-pass: radiosity for the diffuse term, Whitted for the specular paths.
    Radiosity,
}

impl Args {
    /// The arguments for a bare `emray`: the default scene to `emray.png`.
    pub fn default_scene() -> Self {
        Args {
            scenes: Vec::new(),
            output: Some("emray.png".into()),
            backend: None,
            res: None,
            spp: None,
            max_depth: None,
            threads: None,
            spd: false,
            embree_quality: QualityArg::Medium,
            embree_fast: false,
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
            log: LogArgs::default(),
            gi: None,
            radiosity: RadiositySolveArgs::default(),
            area_samples: 16,
            aov: None,
            heatmap: Vec::new(),
        }
    }
}

/// Render every scene; with several, a failing one is reported and the others go on.
pub fn run(args: Args) -> Result<(), Error> {
    let jobs = plan(&args).map_err(Error::Usage)?;
    // An output that cannot be written is found before any scene is read (a missing
    // folder is created).
    for job in &jobs {
        outputs::prepare(job.files(&args).iter().map(PathBuf::as_path))?;
    }
    outputs::prepare_log(args.stats_json.as_deref())?;
    let pool = thread_pool(args.threads).map_err(Error::Failed)?;
    let mut failed = 0usize;
    for job in &jobs {
        if let Err(e) = pool.install(|| render_one(&args, job)) {
            if jobs.len() == 1 || is_closed_pipe(&e) {
                return Err(Error::Failed(e));
            }
            eprintln!("{}", error_line(&e));
            failed += 1;
        }
    }
    if failed > 0 {
        return Err(Error::failed(format!(
            "{failed} of {} scenes failed",
            jobs.len()
        )));
    }
    Ok(())
}

/// The jobs, or a usage error found before any work is done.
fn plan(args: &Args) -> Result<Vec<Job>> {
    check_options(args)?;
    let maps = insight::heatmaps(&args.heatmap)?;
    let jobs = jobs::plan(args, &maps, backend_options(args).backend)?;
    if args.tile.is_some() || args.crop.is_some() {
        check_part(args, &jobs)?;
    }
    for job in &jobs {
        Format::from_path(&job.out)?;
        insight::check_aov_output(&args.aov.unwrap_or_default(), &job.out)?;
        if let Some(s) = &job.scene {
            Database::parse_spec(&s.to_string_lossy()).map_err(anyhow::Error::msg)?;
        }
    }
    jobs::check_distinct(args, &jobs)?;
    Ok(jobs)
}

/// Options that cannot go together, and numbers out of range.
fn check_options(args: &Args) -> Result<()> {
    if args.reference && (args.spd || args.aa != AaArg::Uniform) {
        bail!(
            "--reference samples N×N stratified: it cannot be combined with --spd or --aa adaptive"
        );
    }
    if insight_wanted(args) && (args.reference || (args.aa != AaArg::Uniform && !args.spd)) {
        bail!(
            "--aov and --heatmap look inside the Whitted renderer's uniform samples: not with \
             --reference or --aa adaptive"
        );
    }
    for (name, v) in [
        ("--bailout", args.bailout.unwrap_or(0.0)),
        ("--aa-threshold", args.aa_threshold),
    ] {
        if !v.is_finite() || v < 0.0 {
            bail!("{name} must be a finite number >= 0, not {v}");
        }
    }
    Ok(())
}

/// Whether the render gathers output variables (`--aov` or `--heatmap`).
fn insight_wanted(args: &Args) -> bool {
    args.aov.is_some_and(|s| s.any()) || !args.heatmap.is_empty()
}

/// `--tile` and `--crop` render one scene, whole-image modes aside, to an EXR part.
fn check_part(args: &Args, jobs: &[Job]) -> Result<()> {
    if args.reference {
        bail!("--reference renders whole images: not with --tile or --crop");
    }
    if args.gi.is_some() {
        // Each part would solve the radiosity on its own; the hash does not cover it.
        bail!("--gi renders whole images: not with --tile or --crop");
    }
    if jobs.len() != 1 {
        bail!("--tile and --crop render one scene");
    }
    if !matches!(Format::from_path(&jobs[0].out), Ok(Format::Exr)) {
        bail!(
            "--tile and --crop write an EXR part (for emray merge), not '{}'",
            jobs[0].out.display()
        );
    }
    Ok(())
}

/// What the options ask of the render besides the scene.
fn request(args: &Args) -> RenderRequest {
    RenderRequest {
        res: args.res,
        spp: args.spp,
        max_depth: args.max_depth,
        spd: args.spd,
        bailout: args.bailout,
        aa: (args.aa == AaArg::Adaptive).then_some(Aa::Adaptive {
            threshold: args.aa_threshold,
            depth: args.aa_depth,
        }),
        cast_skippable: args.no_skip,
        area_samples: Some(args.area_samples),
        part: match (args.tile, args.crop) {
            (Some((index, count)), _) => Some(Part::Tile { index, count }),
            (None, crop) => crop.map(Part::Crop),
        },
    }
}

/// The backend and its build options.
fn backend_options(args: &Args) -> BackendOptions {
    BackendOptions {
        backend: args
            .backend
            .map(Backend::from)
            .unwrap_or_else(Backend::default_available),
        embree_quality: args.embree_quality.into(),
        embree_robust: !args.embree_fast,
        packet_width: args.packet_width,
    }
}

/// The scene's name: its path, or `default`.
fn scene_name(path: Option<&Path>) -> String {
    path.map_or_else(|| "default".into(), |p| p.display().to_string())
}

/// The scene, with `--envmap` in place of its own.
fn load_scene(args: &Args, path: Option<&Path>) -> Result<Scene> {
    let mut scene = match path {
        Some(p) => job::load_scene(p)?,
        None => load::nff::parse_str(DEFAULT_SCENE, Path::new("<default scene>"))?,
    };
    if let Some(env) = &args.envmap {
        scene.environment = Some(Environment::load(env).map_err(anyhow::Error::msg)?);
    }
    Ok(scene)
}

/// Load, render and write one scene.
fn render_one(args: &Args, job: &Job) -> Result<()> {
    let out = job.out.as_path();
    let name = scene_name(job.scene.as_deref());
    // Cleared when dropped, on an error too.
    let bar = TileBar::new(&name, args.log.quiet);
    let t0 = Instant::now();
    let scene = load_scene(args, job.scene.as_deref())?;
    let load_ms = t0.elapsed().as_secs_f64() * 1e3;
    let settings = request(args)
        .settings(&scene)
        .map_err(|e| anyhow!("{name}: {e}"))?;
    let max_memory = args.max_memory.unwrap_or_else(limits::default_max_memory);
    let extra = if insight_wanted(args) {
        limits::aov_bytes(&settings)
    } else {
        0
    };
    limits::check_with(Path::new(&name), &scene, &settings, extra, max_memory)?;
    let options = backend_options(args);
    let (film, aov, report) = trace(args, &name, &scene, &settings, options, load_ms, &bar)?;
    bar.writing(out);
    let part = settings.region.map(|region| part::PartInfo {
        full: (settings.width, settings.height),
        region,
        hash: Some(emray::batch::merge::render_hash(
            &scene,
            &settings,
            options.backend,
        )),
    });
    match (&aov, &part) {
        (Some(aov), _) if aov.set.any() => {
            emray::output::aov::write_exr_aov(out, &film, aov, part.as_ref())?
        }
        (_, Some(info)) => part::write_exr(out, &film, Some(info))?,
        (_, None) => output::write_image(out, &film, args.encoding.into())?,
    }
    if let Some(aov) = &aov {
        insight::write_heatmaps(aov, &job.heatmaps, &bar)?;
    }
    bar.finish();
    if args.stats {
        print(format_args!(
            "{}\noutput     {}\n",
            report.summary(),
            out.display()
        ))?;
    } else if !args.log.quiet {
        log::info!("wrote {}", out.display());
    }
    if let Some(path) = &args.stats_json {
        append_json_line(path, &report)?;
    }
    Ok(())
}

/// Build the backend and render: the f64 reference, two-pass, or Whitted alone; with
/// the output variables when `--aov` or `--heatmap` asks for them.
fn trace(
    args: &Args,
    name: &str,
    scene: &Scene,
    settings: &RenderSettings,
    options: BackendOptions,
    load_ms: f64,
    bar: &TileBar,
) -> Result<(Film, Option<AovFilm>, Report)> {
    let progress = |done: usize, total: usize| bar.set(done, total);
    if args.reference {
        let strata = (args.spp.unwrap_or(256) as f64).sqrt().floor() as u32;
        let (film, report) = job::render_reference(name, scene, settings, strata, load_ms)
            .map_err(|why| anyhow!("{name}: {why}"))?;
        return Ok((film, None, report));
    }
    let radiosity = args.gi.map(|GiArg::Radiosity| args.radiosity.settings());
    if insight_wanted(args) {
        let maps = insight::heatmaps(&args.heatmap)?;
        let set = insight::gathered(args.aov.unwrap_or_default(), &maps);
        let (film, mut aov, report) = job::render_aov(
            name,
            scene,
            options,
            settings,
            radiosity.as_ref(),
            set,
            load_ms,
            Some(&progress),
        )?;
        // The layers written are the ones --aov asks for; the heat maps' are gathered
        // for them alone.
        aov.set = args.aov.unwrap_or_default();
        return Ok((film, Some(aov), report));
    }
    let (film, report) = match &radiosity {
        Some(rad) => job::render_two_pass(
            name,
            scene,
            options,
            settings,
            rad,
            load_ms,
            Some(&progress),
        )?,
        None => job::render_scene(name, scene, options, settings, load_ms, Some(&progress))?,
    };
    Ok((film, None, report))
}
