//! The commands of the `emray` binary, one module each with its own arguments and a
//! `run(args) -> Result<(), Error>`; [`args`] holds the argument types several share,
//! [`error`] how a failure becomes a message and an exit status, [`progress`] and
//! [`interrupt`] the terminal's progress bars and the handler of Ctrl-C and SIGTERM
//! (neither of which the library has).

mod args;
mod batch;
mod bench;
mod compare;
#[cfg(test)]
mod docs_commands;
#[cfg(test)]
mod docs_scan;
mod error;
mod eta;
mod explain;
mod generate;
mod interrupt;
mod merge;
mod outputs;
mod progress;
mod radiosity;
mod render;
mod stress;
mod study;
mod view;

pub use error::Error;

use args::LogArgs;

use anyhow::Context;
use clap::{Parser, Subcommand};

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
    Render(render::Args),
    /// Write a Standard Procedural Database as NFF, as the SPD 3.14 programs do.
    Gen(generate::Args),
    /// Render many scenes: failures isolated, resumable, split into shards.
    Batch(batch::Args),
    /// Stitch parts rendered with `render --band` or `--crop` into the whole image.
    Merge(merge::Args),
    /// Benchmark suite: SPD scenes on both backends, 1 and all threads, raw casting,
    /// Tachyon as a peer; markdown to standard output.
    Bench(bench::Args),
    /// Error metrics of an image against a reference (RMSE, PSNR, FLIP, ...); exit
    /// status 0 within the thresholds, 1 beyond, 2 on a usage or I/O error.
    Compare(compare::Args),
    /// Numerical stress cases (scale, translation, far/tiny spheres, watertightness)
    /// with their measured numbers; exit status 1 if a bound is broken.
    Stress(stress::Args),
    /// Error against time: the f64 reference once, then a sweep of spp, adaptive AA,
    /// bailout, depth and backends, to DIR/study.csv; the error-against-time plot to
    /// DIR/study.svg and DIR/study.png.
    Study(study::Args),
    /// Solve a scene's diffuse interreflection by radiosity and render a view of it.
    Radiosity(radiosity::Args),
    /// One pixel's whole ray tree: each ray, what it hit and where that was defined,
    /// the light at each hit term by term, and what each ray brings back.
    Explain(explain::Args),
    /// Serve a page on this machine that shows the render as it progresses, re-renders
    /// with the options changed or the scene saved, and explains the pixel clicked.
    View(view::Args),
}

/// Run the command line's command (a bare `emray` renders the default scene), Ctrl-C
/// and SIGTERM caught for it ([`interrupt`]).
pub fn run(cli: Cli) -> Result<(), Error> {
    init_log(
        cli.command
            .as_ref()
            .map_or_else(LogArgs::default, Command::log),
    );
    interrupt::install();
    match cli.command {
        None => render::run(render::Args::default_scene()),
        Some(Command::Render(a)) => render::run(a),
        Some(Command::Gen(a)) => generate::run(a),
        Some(Command::Batch(a)) => batch::run(a),
        Some(Command::Merge(a)) => merge::run(a),
        Some(Command::Bench(a)) => bench::run(a),
        Some(Command::Compare(a)) => compare::run(a),
        Some(Command::Stress(a)) => stress::run(a),
        Some(Command::Study(a)) => study::run(a),
        Some(Command::Radiosity(a)) => radiosity::run(a),
        Some(Command::Explain(a)) => explain::run(a),
        Some(Command::View(a)) => view::run(a),
    }
}

impl Command {
    /// The command's `-q` and `-v`.
    fn log(&self) -> LogArgs {
        match self {
            Command::Render(a) => a.log,
            Command::Gen(a) => a.log,
            Command::Batch(a) => a.log,
            Command::Merge(a) => a.log,
            Command::Bench(a) => a.log,
            Command::Compare(a) => a.log,
            Command::Stress(a) => a.log,
            Command::Study(a) => a.log,
            Command::Radiosity(a) => a.log,
            Command::Explain(a) => a.log,
            Command::View(a) => a.log,
        }
    }
}

/// Log to standard error: errors only with `-q`, else warnings and more with each
/// `-v` (`RUST_LOG` wins).
fn init_log(log: LogArgs) {
    let level = match (log.quiet, log.verbose) {
        (true, _) => "error",
        (false, 0) => "warn",
        (false, 1) => "info",
        (false, 2) => "debug",
        _ => "trace",
    };
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or(level))
        .format_timestamp(None)
        .init();
}

/// The worker threads: `threads` of them, or one per core.
fn thread_pool(threads: Option<u32>) -> anyhow::Result<rayon::ThreadPool> {
    let mut builder = rayon::ThreadPoolBuilder::new();
    if let Some(t) = threads {
        builder = builder.num_threads(t as usize);
    }
    builder.build().context("cannot start the worker threads")
}
