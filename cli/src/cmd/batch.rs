//! `emray batch`: many scenes (arguments, globs or a manifest) rendered as isolated,
//! resumable jobs, optionally one shard of them; Ctrl-C or SIGTERM stops it after
//! writing the report of what finished (a second one at once).

use super::args::LogArgs;
use super::error::print;
use super::interrupt::stop_flag;
use super::progress::BatchDisplay;
use super::{Error, outputs};
use emray::batch::{self, BatchOptions, BatchReport};
use emray::job::template;
use emray::job::{Band, Job, RenderOptions};
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
    /// Worker threads in all (default: all cores).
    #[arg(short, long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub threads: Option<u32>,
    /// Jobs rendered at once, sharing the threads.
    #[arg(short, long, value_name = "N", default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub jobs: u32,
    /// Run only shard I of N (I counts from 0: 0 ≤ I < N): the jobs whose name hashes
    /// (FNV-1a 64) to I modulo N.
    #[arg(long, value_name = "I/N", value_parser = emray::batch::parse_shard)]
    pub shard: Option<Band>,
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
    /// What every job renders and how, over the manifest's options.
    #[command(flatten)]
    pub options: RenderOptions,
    /// `-q` and `-v`.
    #[command(flatten)]
    pub log: LogArgs,
}

impl Args {
    /// What overrides every job's output and options.
    pub fn overrides(&self) -> emray::batch::manifest::Overrides {
        emray::batch::manifest::Overrides {
            output: self.output.clone(),
            options: self.options.clone(),
        }
    }
}

/// Plan the jobs, keep this shard's, and list or run them.
pub fn run(b: Args) -> Result<(), Error> {
    let jobs = jobs(&b)?;
    batch::check_jobs(&jobs).map_err(|e| Error::Usage(e.into()))?;
    let report = report_path(&b)?;
    let jobs: Vec<Job> = match b.shard {
        Some(Band { index, count }) => jobs
            .into_iter()
            .filter(|j| batch::shard_of(&j.name, count) == index)
            .collect(),
        None => jobs,
    };
    if b.list {
        for j in &jobs {
            print(format_args!(
                "{}\t{}\t{}\n",
                j.name,
                j.scene.name(),
                j.outputs
                    .image
                    .as_ref()
                    .map(|p| p.display().to_string())
                    .unwrap_or_default()
            ))?;
        }
        return Ok(());
    }
    let opts = BatchOptions {
        threads: b.threads.map(|t| t as usize),
        jobs: b.jobs as usize,
        skip_existing: b.skip_existing,
        report,
        shard: b.shard.map(|s| (s.index, s.count)),
    };
    outputs::prepare(opts.report.as_deref())?;
    let files: Vec<PathBuf> = jobs.iter().flat_map(Job::files).collect();
    outputs::prepare(files.iter().map(PathBuf::as_path))?;
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
    let shard = b.shard.map_or(0, |s| s.index).to_string();
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
    let jobs = if report.failed > 0 {
        Some(format!("{} of {} jobs failed", report.failed, report.total))
    } else {
        // Not interrupted, yet not every job ran: its workers could not start.
        (report.unfinished > 0 && !report.interrupted)
            .then(|| format!("{} of {} jobs did not run", report.unfinished, report.total))
    };
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
    let template = b.output.as_deref().unwrap_or("{stem}.png");
    batch::expand_scene_args(&b.scenes)
        .and_then(|s| batch::jobs_from_scenes(&s, template, &b.options))
        .map_err(|e| Error::Usage(e.into()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn report(ok: usize, failed: usize, unfinished: usize, interrupted: bool) -> BatchReport {
        BatchReport {
            shard: None,
            total: ok + failed + unfinished,
            ok,
            failed,
            skipped: 0,
            unfinished,
            interrupted,
            wall_ms: 0.0,
            jobs: Vec::new(),
        }
    }

    #[test]
    fn a_batch_fails_when_a_job_failed_or_did_not_run_unasked() {
        assert!(failure(&report(3, 0, 0, false), None).is_none());
        assert!(failure(&report(1, 0, 2, true), None).is_none());
        let e = failure(&report(1, 0, 2, false), None).unwrap();
        assert_eq!(e.to_string(), "2 of 3 jobs did not run");
        let e = failure(&report(1, 1, 1, false), Some("report not written")).unwrap();
        assert_eq!(e.to_string(), "1 of 3 jobs failed; report not written");
    }
}
