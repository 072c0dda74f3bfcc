//! `emray radiosity`: solve a scene's diffuse interreflection and render a view of
//! the solution (a job of its own task, [`Task::RadiosityView`]).

use super::args::LogArgs;
use super::error::{job_error, print};
use super::{Error, thread_pool};
use emray::job::{self, Job, Outputs, Product, RenderOptions, SceneSource, Task};
use std::path::PathBuf;

/// `emray radiosity`.
#[derive(clap::Args, Debug, Clone)]
pub struct Args {
    /// Scene file (surfaces whose material has an `emission` are the lights).
    #[arg(value_name = "SCENE")]
    pub scene: PathBuf,
    /// Output image (.png or .exr).
    #[arg(short, long, value_name = "OUT", default_value = "radiosity.png")]
    pub output: PathBuf,
    /// Also write the solved mesh with vertex colours as PLY.
    #[arg(long, value_name = "FILE.ply")]
    pub ply: Option<PathBuf>,
    /// Worker threads (default: all cores).
    #[arg(short, long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub threads: Option<u32>,
    /// Print mesh size, iterations, residuals and timings.
    #[arg(long)]
    pub stats: bool,
    /// Append the statistics (with the residual curve) as one JSON object to FILE.
    #[arg(long, value_name = "FILE")]
    pub stats_json: Option<PathBuf>,
    /// The view (`--spp`, rounded down to a square, defaults to 4 here) and the
    /// radiosity pass.
    #[command(flatten)]
    pub options: RenderOptions,
    /// `-q` and `-v`.
    #[command(flatten)]
    pub log: LogArgs,
}

/// Solve, render the view, write the image (and the PLY and statistics asked for).
pub fn run(a: Args) -> Result<(), Error> {
    let job = Job {
        name: a.scene.display().to_string(),
        scene: SceneSource::File(a.scene.clone()),
        options: a.options.clone(),
        task: Task::RadiosityView,
        outputs: Outputs {
            image: Some(a.output.clone()),
            ply: a.ply.clone(),
            stats_json: a.stats_json.clone(),
            ..Outputs::default()
        },
    };
    job.check().map_err(job_error)?;
    job.prepare().map_err(job_error)?;
    let pool = thread_pool(a.threads).map_err(Error::Failed)?;
    let rendered = pool.install(|| job::run(&job, &())).map_err(job_error)?;
    if let (true, Product::Radiosity { report, .. }) = (a.stats, &rendered.product) {
        print(format_args!(
            "scene      {}\n{}\n",
            a.scene.display(),
            report.summary()
        ))?;
    }
    Ok(())
}
