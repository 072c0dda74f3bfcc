//! Progress bars on a terminal: the tiles of one render, and the jobs of a batch with
//! a bar per running job and a line per finished one; each says when its image is
//! being written.

use super::error::error_line;
use emray::batch::{Job, JobRecord, JobStatus, Observer};
use emray::output::OutputError;
use indicatif::{MultiProgress, ProgressBar, ProgressStyle};
use std::collections::HashMap;
use std::io::IsTerminal;
use std::path::Path;
use std::time::Duration;

/// Bars are drawn unless `quiet`, and only on a terminal.
fn shown(quiet: bool) -> bool {
    !quiet && std::io::stderr().is_terminal()
}

/// A bar in `template`'s shape.
fn bar(len: u64, template: &str) -> ProgressBar {
    let b = ProgressBar::new(len);
    b.set_style(
        ProgressStyle::with_template(template)
            .expect("static template")
            .progress_chars("=> "),
    );
    b
}

/// Turn `b` into a spinner saying that `path` is being written.
fn writing(b: &ProgressBar, path: &Path) {
    b.set_style(
        ProgressStyle::with_template("{spinner} {msg} {elapsed_precise}").expect("static template"),
    );
    b.set_message(format!("writing {} …", path.display()));
    b.enable_steady_tick(Duration::from_millis(100));
}

/// The tiles of one render.
pub struct TileBar(Option<ProgressBar>);

impl TileBar {
    /// A bar named `name` (none when `quiet` or not on a terminal).
    pub fn new(name: &str, quiet: bool) -> Self {
        TileBar(shown(quiet).then(|| {
            let b = bar(
                0,
                "{msg} [{bar:40}] {pos}/{len} tiles {elapsed_precise} eta {eta}",
            );
            b.set_message(name.to_string());
            b
        }))
    }

    /// `done` of `total` tiles are rendered.
    pub fn set(&self, done: usize, total: usize) {
        if let Some(b) = &self.0 {
            b.set_length(total as u64);
            b.set_position(done as u64);
        }
    }

    /// The render is done and `path` is being written: say so (writing a large EXR
    /// takes seconds).
    pub fn writing(&self, path: &Path) {
        if let Some(b) = &self.0 {
            writing(b, path);
        }
    }

    /// Everything is written: clear the bar.
    pub fn finish(&self) {
        if let Some(b) = &self.0 {
            b.finish_and_clear();
        }
    }
}

/// What the user sees while a batch runs: a bar of the jobs and one per running job
/// on a terminal, and a line per finished job (errors even when quiet).
pub struct BatchDisplay {
    bars: Option<(MultiProgress, ProgressBar)>,
    job_bars: HashMap<usize, ProgressBar>,
    quiet: bool,
    /// Why the report could not be written, the first time it could not.
    report_error: Option<String>,
}

impl BatchDisplay {
    /// The display of a batch of `total` jobs.
    pub fn new(total: usize, quiet: bool) -> Self {
        let bars = shown(quiet).then(|| {
            let m = MultiProgress::new();
            let b = m.add(bar(
                total as u64,
                "batch [{bar:30}] {pos}/{len} jobs {elapsed_precise} eta {eta}",
            ));
            (m, b)
        });
        BatchDisplay {
            bars,
            job_bars: HashMap::new(),
            quiet,
            report_error: None,
        }
    }

    /// Why the report could not be written, if it could not (the command fails with
    /// it once the batch is done, rather than after each job).
    pub fn report_error(&self) -> Option<&str> {
        self.report_error.as_deref()
    }

    /// The line of a finished job, or none (a job that went well, when quiet).
    fn line(&self, r: &JobRecord, done: usize, total: usize, eta: Option<f64>) -> Option<String> {
        match (&r.status, &r.error) {
            (JobStatus::Failed, Some(e)) => Some(error_line(format_args!("job '{}': {e}", r.name))),
            _ if self.quiet => None,
            (s, _) => Some(format!(
                "emray: [{done}/{total}] {} {} ({:.2} s{})",
                match s {
                    JobStatus::Skipped => "skipped",
                    _ => "ok",
                },
                r.output,
                r.wall_ms / 1e3,
                eta.map(|e| format!(", eta {e:.0} s")).unwrap_or_default()
            )),
        }
    }
}

impl Observer for BatchDisplay {
    fn started(&mut self, index: usize, job: &Job) {
        if let Some((m, _)) = &self.bars {
            let b = m.add(bar(0, "  {msg} [{bar:30}] {pos}/{len} tiles eta {eta}"));
            b.set_message(job.name.clone());
            self.job_bars.insert(index, b);
        }
    }

    fn progress(&mut self, index: usize, done: usize, total: usize) {
        if let Some(b) = self.job_bars.get(&index) {
            b.set_length(total as u64);
            b.set_position(done as u64);
        }
    }

    fn writing(&mut self, index: usize, job: &Job) {
        if let Some(b) = self.job_bars.get(&index) {
            writing(b, &job.output);
        }
    }

    fn finished(&mut self, record: &JobRecord, done: usize, total: usize, eta_s: Option<f64>) {
        if let Some(b) = self.job_bars.remove(&record.index) {
            b.finish_and_clear();
            if let Some((m, _)) = &self.bars {
                m.remove(&b);
            }
        }
        let Some(line) = self.line(record, done, total, eta_s) else {
            return;
        };
        match &self.bars {
            Some((m, b)) => {
                b.inc(1);
                let _ = m.println(line);
            }
            None => eprintln!("{line}"),
        }
    }

    fn stopped(&mut self) {
        if let Some((_, b)) = &self.bars {
            b.finish_and_clear();
        }
    }

    fn report_not_written(&mut self, error: &OutputError) {
        self.report_error.get_or_insert_with(|| error.to_string());
    }
}
