//! `emray explain`: one pixel's whole ray tree, traced by the renderer's own code with
//! the camera, samples and settings of `emray render`, as indented text or as JSON
//! (docs/explain.md).

use super::Error;
use super::args::LogArgs;
use super::error::{job_error, print};
use emray::job::{self, Job, JobError, Outputs, Product, RenderOptions, SceneSource, Task};
use emray::render::explain::{Explanation, text};
use serde::Serialize;
use std::path::{Path, PathBuf};

/// `emray explain`.
#[derive(clap::Args, Debug, Clone)]
pub struct Args {
    /// Scene file: NFF, TOML (`.toml`), OBJ (`.obj`), or `spd:NAME[?size=N]`.
    #[arg(value_name = "SCENE")]
    pub scene: PathBuf,
    /// Pixel column, from 0 at the left.
    #[arg(value_name = "X")]
    pub x: u32,
    /// Pixel row, from 0 at the top.
    #[arg(value_name = "Y")]
    pub y: u32,
    /// Print the tree as JSON (schema in docs/explain.md).
    #[arg(long)]
    pub json: bool,
    /// The render whose pixel it is, as `emray render` takes it.
    #[command(flatten)]
    pub options: RenderOptions,
    /// `-q` and `-v`.
    #[command(flatten)]
    pub log: LogArgs,
}

/// The JSON `--json` prints: the explanation with the scene and backend it is of.
#[derive(Serialize)]
struct Output<'a> {
    scene: String,
    backend: &'static str,
    #[serde(flatten)]
    explanation: &'a Explanation,
}

/// Explain the pixel and print the tree.
pub fn run(a: Args) -> Result<(), Error> {
    if a.json {
        let json = json(&a.scene, &a.options, a.x, a.y).map_err(job_error)?;
        return Ok(print(format_args!("{json}"))?);
    }
    let source = SceneSource::File(a.scene.clone());
    let (job, rendered) = explain(&a.scene, source, &a.options, a.x, a.y).map_err(job_error)?;
    let Product::Explanation(explanation) = &rendered.product else {
        unreachable!("an explain job explains");
    };
    print(format_args!(
        "scene {}, backend {}\n{}",
        job.name,
        rendered.resolved.backend.backend.name(),
        text::format(explanation)
    ))?;
    Ok(())
}

/// The tree of pixel `(x, y)` of `scene` rendered with `options`, as `--json` prints
/// it (a final newline included); `emray view` serves the same.
pub fn json(scene: &Path, options: &RenderOptions, x: u32, y: u32) -> Result<String, JobError> {
    let source = SceneSource::File(scene.to_path_buf());
    Ok(explained(scene, source, options, x, y)?.0)
}

/// [`json`] with the scene of file `scene` from `source` (which may hold it loaded
/// already), and the explanation itself beside its JSON.
pub fn explained(
    scene: &Path,
    source: SceneSource,
    options: &RenderOptions,
    x: u32,
    y: u32,
) -> Result<(String, Explanation), JobError> {
    let (job, rendered) = explain(scene, source, options, x, y)?;
    let Product::Explanation(explanation) = rendered.product else {
        unreachable!("an explain job explains");
    };
    let out = Output {
        scene: job.name,
        backend: rendered.resolved.backend.backend.name(),
        explanation: &explanation,
    };
    let json = serde_json::to_string_pretty(&out).expect("an explanation serialises");
    Ok((json + "\n", *explanation))
}

/// Check and run the job explaining pixel `(x, y)` of the file `scene`, had from
/// `source`.
fn explain(
    scene: &Path,
    source: SceneSource,
    options: &RenderOptions,
    x: u32,
    y: u32,
) -> Result<(Job, job::Rendered), JobError> {
    let job = Job {
        name: scene.display().to_string(),
        scene: source,
        options: options.clone(),
        task: Task::Explain { x, y },
        outputs: Outputs::default(),
    };
    job.check()?;
    let rendered = job::run(&job, &())?;
    Ok((job, rendered))
}
