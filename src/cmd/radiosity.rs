//! `emray radiosity`: solve a scene's diffuse interreflection and render a view of
//! the solution.

use super::args::{BackendArg, LogArgs, RadiositySolveArgs, parse_res};
use super::error::print;
use super::{Error, append_json_line, outputs, thread_pool};
use anyhow::{Context, Result};
use emray::accel::Backend;
use emray::job::RenderRequest;
use emray::output::{self, Encoding, Format};
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
    /// `-q` and `-v`.
    #[command(flatten)]
    pub log: LogArgs,
}

/// Solve, render the view, write the image (and the PLY and statistics asked for).
pub fn run(a: Args) -> Result<(), Error> {
    Format::from_path(&a.output)?;
    outputs::prepare([a.output.as_path()].into_iter().chain(a.ply.as_deref()))?;
    outputs::prepare_log(a.stats_json.as_deref())?;
    solve_and_write(&a).map_err(Error::Failed)
}

fn solve_and_write(a: &Args) -> Result<()> {
    let pool = thread_pool(a.threads)?;
    let scene = emray::load::load_path(&a.scene)?;
    let settings = a.solve.settings();
    let view = RenderRequest {
        res: a.res,
        ..RenderRequest::default()
    }
    .settings(&scene)?;
    let spp = (a.spp as f32).sqrt().floor().max(1.0) as u32;
    let backend: Backend = a
        .backend
        .map(Backend::from)
        .unwrap_or_else(Backend::default_available);
    let (sol, film, report) = pool
        .install(|| {
            emray::radiosity::run(&scene, backend, &settings, (view.width, view.height, spp))
        })
        .with_context(|| a.scene.display().to_string())?;
    output::write_image(&a.output, &film, Encoding::Srgb)?;
    if let Some(p) = &a.ply {
        output::write_text(p, &sol.to_ply(1.0, scene.origin))?;
    }
    if a.stats {
        print(format_args!(
            "scene      {}\n{}\n",
            a.scene.display(),
            report.summary()
        ))?;
    }
    if let Some(path) = &a.stats_json {
        append_json_line(path, &report)?;
    }
    Ok(())
}
