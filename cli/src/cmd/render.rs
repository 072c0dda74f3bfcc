//! `emray render` (and a bare `emray`): render scene files or generated SPD scenes to
//! PNG or EXR, whole or one part of an image for `emray merge`. The command plans the
//! jobs, checks them and their files before any work, and runs each
//! ([`emray::job::run`]) with a progress bar.

use super::args::LogArgs;
use super::error::{job_error, print};
use super::progress::TileBar;
use super::{Error, thread_pool};
use emray::job::{self, Event, Job, RenderOptions, Rendered, SceneSource};
use std::path::PathBuf;

/// `emray render`.
#[derive(clap::Args, Debug, Clone, Default)]
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
    /// Worker threads (default: all cores).
    #[arg(short, long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub threads: Option<u32>,
    /// Print primitives, timings, ray counts and Mrays/s.
    #[arg(long)]
    pub stats: bool,
    /// Append one JSON object per render to FILE.
    #[arg(long, value_name = "FILE")]
    pub stats_json: Option<PathBuf>,
    /// What to render and how.
    #[command(flatten)]
    pub options: RenderOptions,
    /// `-q` and `-v`.
    #[command(flatten)]
    pub log: LogArgs,
}

impl Args {
    /// The arguments for a bare `emray`: the default scene to `emray.png`.
    pub fn default_scene() -> Self {
        Args {
            output: Some("emray.png".into()),
            ..Args::default()
        }
    }
}

/// Render every scene; with several, a failing one is reported and the others go on.
pub fn run(args: Args) -> Result<(), Error> {
    let jobs = plan(&args).map_err(job_error)?;
    // An output that cannot be written is found before any scene is read (a missing
    // folder is created).
    for job in &jobs {
        job.prepare().map_err(job_error)?;
    }
    let pool = thread_pool(args.threads).map_err(Error::Failed)?;
    let mut failed = 0usize;
    for job in &jobs {
        if let Err(e) = pool.install(|| render_one(&args, job)) {
            if jobs.len() == 1 || e.is_closed_pipe() {
                return Err(e);
            }
            // Printed now; the others go on.
            let _ = e.report();
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

/// The jobs of the scenes (the default scene when there are none), checked: a usage
/// error found before any work is done.
fn plan(args: &Args) -> Result<Vec<Job>, job::JobError> {
    let sources = match args.scenes.as_slice() {
        [] => vec![SceneSource::Builtin],
        s => s.iter().cloned().map(SceneSource::File).collect(),
    };
    let o = &args.options;
    if (o.band.is_some() || o.crop.is_some()) && sources.len() != 1 {
        return Err(job::JobError::Outputs(
            "--band and --crop render one scene".into(),
        ));
    }
    let mut jobs = job::plan(sources, args.output.as_deref(), o)?;
    for job in &mut jobs {
        job.outputs.stats_json = args.stats_json.clone();
        job.check()?;
    }
    job::check_distinct(&jobs)?;
    Ok(jobs)
}

/// Load, render and write one scene, with a progress bar; print its statistics.
fn render_one(args: &Args, job: &Job) -> Result<(), Error> {
    // Cleared when dropped, on an error too.
    let bar = TileBar::new(&job.scene.name(), args.log.quiet);
    let observer = |e: Event<'_>| match e {
        Event::Loading => bar.phase("loading"),
        Event::Loaded { done, total } => bar.loaded(done, total),
        Event::Building => bar.phase("building"),
        Event::Rendering => bar.phase("rendering"),
        Event::Tiles { done, total } => bar.set(done, total),
        Event::Writing(path) => bar.writing(path),
        _ => {}
    };
    let rendered = job::run(job, &observer).map_err(job_error)?;
    bar.finish();
    if args.stats {
        print_stats(job, &rendered)?;
    }
    Ok(())
}

/// `--stats`: the report's summary and the file written.
fn print_stats(job: &Job, rendered: &Rendered) -> std::io::Result<()> {
    let out = job
        .outputs
        .image
        .as_ref()
        .map(|p| p.display().to_string())
        .unwrap_or_default();
    print(format_args!(
        "{}\noutput     {out}\n",
        rendered.report.summary()
    ))
}
