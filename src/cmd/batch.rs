//! `emray batch`: many scenes (arguments, globs or a manifest) rendered as isolated,
//! resumable jobs, optionally one shard of them; Ctrl-C or SIGTERM stops it after
//! writing the report of what finished (a second one at once).

use super::args::{BackendArg, EncodingArg, LogArgs, parse_res};
use super::error::print;
use super::interrupt::stop_flag;
use super::progress::BatchDisplay;
use super::{Error, outputs};
use emray::accel::Backend;
use emray::batch::{self, BatchOptions, BatchReport, Job, JobSettings};
use emray::job::RenderRequest;
use emray::job::template;
use emray::output::Encoding;
use std::path::PathBuf;

/// `emray batch`.
#[derive(clap::Args, Debug, Clone)]
pub struct Args {
    /// Scene files, globs (quoted, e.g. 'scenes/*.nff') or `spd:NAME[?size=N]` specs.
    #[arg(value_name = "SCENE")]
    pub scenes: Vec<PathBuf>,
    /// A TOML manifest of jobs (README "Batch rendering"), instead of scene arguments.
    #[arg(short, long, value_name = "FILE.toml", conflicts_with = "scenes")]
    pub manifest: Option<PathBuf>,
    /// Output template, as `render -o`: `{stem}`, `{backend}`, `{index}`, `{spp}`
    /// [default: `{stem}.png`, or the manifest's].
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
    /// Run only shard I of N (I counts from 0: 0 ≤ I < N): the jobs whose name hashes
    /// (FNV-1a 64) to I modulo N.
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
    #[arg(long, value_name = "SIZE", value_parser = emray::job::limits::parse_size)]
    pub max_memory: Option<u64>,
    /// `-q` and `-v`.
    #[command(flatten)]
    pub log: LogArgs,
}

impl Args {
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

/// Plan the jobs, keep this shard's, and list or run them.
pub fn run(b: Args) -> Result<(), Error> {
    let jobs = jobs(&b)?;
    batch::check_jobs(&jobs).map_err(|e| Error::Usage(e.into()))?;
    let report = report_path(&b)?;
    let jobs: Vec<Job> = match b.shard {
        Some((i, n)) => jobs
            .into_iter()
            .filter(|j| batch::shard_of(&j.name, n) == i)
            .collect(),
        None => jobs,
    };
    if b.list {
        for j in &jobs {
            print(format_args!(
                "{}\t{}\t{}\n",
                j.name,
                j.scene.display(),
                j.output.display()
            ))?;
        }
        return Ok(());
    }
    let opts = BatchOptions {
        threads: b.threads.map(|t| t as usize),
        jobs: b.jobs as usize,
        skip_existing: b.skip_existing,
        report,
        max_memory: b
            .max_memory
            .unwrap_or_else(emray::job::limits::default_max_memory),
        shard: b.shard,
    };
    let images = jobs.iter().map(|j| j.output.as_path());
    outputs::prepare(opts.report.as_deref().into_iter().chain(images))?;
    let cancel = stop_flag();
    let mut display = BatchDisplay::new(jobs.len(), b.log.quiet);
    let report = batch::run(jobs, &opts, &cancel, &mut display);
    if report.interrupted && !b.log.quiet {
        eprintln!(
            "emray: interrupted: {} of {} jobs finished",
            report.ok + report.failed + report.skipped,
            report.total
        );
    }
    let failed = failure(&report, display.report_error());
    match (report.interrupted, failed) {
        (true, failed) => Err(Error::Interrupted(failed)),
        (false, Some(failed)) => Err(Error::Failed(failed)),
        (false, None) => Ok(()),
    }
}

/// The `--report` file, its `{shard}` the shard's index (0 without `--shard`); another
/// placeholder is a usage error.
fn report_path(b: &Args) -> Result<Option<PathBuf>, Error> {
    let shard = b.shard.map_or(0, |(i, _)| i).to_string();
    b.report
        .as_deref()
        .map(|r| template::expand("report name", r, &["shard"], |_| shard.clone()))
        .transpose()
        .map(|r| r.map(PathBuf::from))
        .map_err(|e| Error::Usage(e.into()))
}

/// What went wrong in a batch that ran: failed jobs, a report that could not be
/// written.
fn failure(report: &BatchReport, report_error: Option<&str>) -> Option<anyhow::Error> {
    let jobs =
        (report.failed > 0).then(|| format!("{} of {} jobs failed", report.failed, report.total));
    match (jobs, report_error) {
        (Some(jobs), Some(r)) => Some(anyhow::anyhow!("{jobs}; {r}")),
        (jobs, r) => jobs.as_deref().or(r).map(|e| anyhow::anyhow!("{e}")),
    }
}

/// The jobs of the manifest (an unreadable one is an input error) or of the scene
/// arguments (a bad glob or template is a usage error).
fn jobs(b: &Args) -> Result<Vec<Job>, Error> {
    if let Some(m) = &b.manifest {
        return Ok(batch::manifest::load(m, &b.overrides())?);
    }
    if b.scenes.is_empty() {
        return Err(Error::usage("give scene files, globs or --manifest FILE"));
    }
    let settings = JobSettings {
        backend: b.backend.map(Backend::from),
        render: RenderRequest {
            res: b.res,
            spp: b.spp,
            max_depth: b.max_depth,
            spd: b.spd,
            ..RenderRequest::default()
        },
        encoding: b.encoding.map(Into::into).unwrap_or_default(),
    };
    let template = b.output.as_deref().unwrap_or("{stem}.png");
    batch::expand_scene_args(&b.scenes)
        .and_then(|s| batch::jobs_from_scenes(&s, template, &settings))
        .map_err(|e| Error::Usage(e.into()))
}
