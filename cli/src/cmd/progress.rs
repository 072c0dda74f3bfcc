//! Progress bars on a terminal: the tiles of one render, and the jobs of a batch with
//! a bar per running job and a line per finished one. A render's bar spins, naming the
//! phase (loading, with the share loaded, building, rendering), while the scene loads
//! and the backend builds, counts the tiles from 0 once the render tells how many there
//! are, with the time left ([`eta`]), and names the file being written.

use super::error::error_line;
use super::eta;
use emray::batch::{JobPhase, JobRecord, JobStatus, Observer};
use emray::job::Job;
use emray::output::OutputError;
use indicatif::{MultiProgress, ProgressBar, ProgressStyle};
use std::collections::HashMap;
use std::io::IsTerminal;
use std::path::Path;
use std::sync::Once;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

/// Bars are drawn unless `quiet`, and only on a terminal.
fn shown(quiet: bool) -> bool {
    !quiet && std::io::stderr().is_terminal()
}

/// The shape of a bar: `template`, with the time left ([`eta`]) as `{time_left}`,
/// measured from `start` and shown once `min_done` of its steps are done.
fn style(template: &str, start: Instant, min_done: fn(u64) -> u64) -> ProgressStyle {
    ProgressStyle::with_template(template)
        .expect("static template")
        .with_key("time_left", eta::key(start, min_done))
        .progress_chars("=> ")
}

/// The shape of a spinner, with the time since its bar started.
fn spinner_style() -> ProgressStyle {
    ProgressStyle::with_template("{prefix}{spinner} {msg} {elapsed_precise}")
        .expect("static template")
}

/// A new bar in the spinner's shape saying `name`, its lines starting with `indent`:
/// the default shape, a full bar of 0 of 0, is never drawn.
fn spinner_bar(name: &str, indent: &'static str) -> ProgressBar {
    ProgressBar::new(0)
        .with_style(spinner_style())
        .with_prefix(indent)
        .with_message(name.to_string())
}

/// Make `b` a spinner saying `message`.
fn spin(b: &ProgressBar, message: String) {
    b.set_style(spinner_style());
    b.set_message(message);
    b.enable_steady_tick(Duration::from_millis(100));
}

/// One render's bar: a spinner while the scene loads and the backend builds, then the
/// tiles done of all of them with the time left, from 0 of the count the render tells
/// before its first tile, then a spinner naming the file being written.
struct Tiles {
    bar: ProgressBar,
    name: String,
    /// Switches to the tiles' bar, once.
    started: Once,
    /// The most tiles said done (the workers tell in any order).
    done: AtomicUsize,
}

impl Tiles {
    /// The bar `bar`, a [`spinner_bar`], of the render `name`.
    fn new(bar: ProgressBar, name: &str) -> Self {
        bar.enable_steady_tick(Duration::from_millis(100));
        Tiles {
            bar,
            name: name.to_string(),
            started: Once::new(),
            done: AtomicUsize::new(0),
        }
    }

    /// `done` of `total` tiles are rendered.
    fn set(&self, done: usize, total: usize) {
        self.started.call_once(|| {
            let template =
                "{prefix}{msg} [{bar:40}] {pos}/{len} tiles {elapsed_precise}{time_left}";
            self.bar.set_length(total as u64);
            self.bar
                .set_style(style(template, Instant::now(), eta::min_tiles));
            self.bar.set_message(self.name.clone());
        });
        let done = self.done.fetch_max(done, Ordering::Relaxed).max(done);
        self.bar.set_length(total as u64);
        self.bar.set_position(done as u64);
    }

    /// The job is in `phase` (loading, building): say so beside the name, until the
    /// tiles' bar takes over.
    fn phase(&self, phase: &str) {
        if !self.started.is_completed() {
            self.bar.set_message(format!("{}: {phase} …", self.name));
        }
    }

    /// `done` of `total` units of the scene are loaded: say what share, drawn at once
    /// (the load tells a few dozen times a second at most).
    fn loaded(&self, done: u64, total: u64) {
        if !self.started.is_completed() && total > 0 {
            let percent = done.min(total) * 100 / total;
            let name = &self.name;
            self.bar
                .set_message(format!("{name}: loading {percent}% …"));
            self.bar.force_draw();
        }
    }

    /// The render is done and `path` is being written.
    fn writing(&self, path: &Path) {
        spin(&self.bar, format!("writing {} …", path.display()));
    }
}

/// A bar is cleared when dropped, so that a failure's message is not printed beside
/// it.
impl Drop for Tiles {
    fn drop(&mut self) {
        self.bar.finish_and_clear();
    }
}

/// The tiles of one render, and the files it writes after them (writing a large EXR
/// takes seconds).
pub struct TileBar(Option<Tiles>);

impl TileBar {
    /// A bar named `name` (none when `quiet` or not on a terminal).
    pub fn new(name: &str, quiet: bool) -> Self {
        TileBar(shown(quiet).then(|| Tiles::new(spinner_bar(name, ""), name)))
    }

    /// `done` of `total` tiles are rendered.
    pub fn set(&self, done: usize, total: usize) {
        if let Some(t) = &self.0 {
            t.set(done, total);
        }
    }

    /// The job is in `phase` (`loading`, `building`, `rendering`): say so on the
    /// spinner, so that a long load or build is never a silent wait.
    pub fn phase(&self, phase: &str) {
        if let Some(t) = &self.0 {
            t.phase(phase);
        }
    }

    /// `done` of `total` units of the scene are loaded: show the percentage beside
    /// the phase.
    pub fn loaded(&self, done: u64, total: u64) {
        if let Some(t) = &self.0 {
            t.loaded(done, total);
        }
    }

    /// The render is done and `path` is being written: say so.
    pub fn writing(&self, path: &Path) {
        if let Some(t) = &self.0 {
            t.writing(path);
        }
    }

    /// Everything is written: clear the bar.
    pub fn finish(&self) {
        if let Some(t) = &self.0 {
            t.bar.finish_and_clear();
        }
    }
}

/// What the user sees while a batch runs: a bar of the jobs and one per running job
/// on a terminal, and a line per finished job (errors even when quiet).
pub struct BatchDisplay {
    bars: Option<(MultiProgress, ProgressBar)>,
    job_bars: HashMap<usize, Tiles>,
    quiet: bool,
    /// Why the report could not be written, the first time it could not.
    report_error: Option<String>,
}

impl BatchDisplay {
    /// The display of a batch of `total` jobs.
    pub fn new(total: usize, quiet: bool) -> Self {
        let bars = shown(quiet).then(|| {
            let m = MultiProgress::new();
            let template = "batch [{bar:30}] {pos}/{len} jobs {elapsed_precise}{time_left}";
            let style = style(template, Instant::now(), eta::min_jobs);
            let b = m.add(ProgressBar::new(total as u64).with_style(style));
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
            let b = m.add(spinner_bar(&job.name, "  "));
            self.job_bars.insert(index, Tiles::new(b, &job.name));
        }
    }

    fn phase(&mut self, index: usize, phase: JobPhase) {
        let Some(t) = self.job_bars.get(&index) else {
            return;
        };
        match phase {
            JobPhase::Loading { done, total } if total > 0 => t.loaded(done, total),
            JobPhase::Loading { .. } => t.phase("loading"),
            JobPhase::Building => t.phase("building"),
            JobPhase::Rendering => t.phase("rendering"),
        }
    }

    fn progress(&mut self, index: usize, done: usize, total: usize) {
        if let Some(t) = self.job_bars.get(&index) {
            t.set(done, total);
        }
    }

    fn writing(&mut self, index: usize, job: &Job) {
        if let Some(t) = self.job_bars.get(&index) {
            if let Some(image) = &job.outputs.image {
                t.writing(image);
            }
        }
    }

    fn finished(&mut self, record: &JobRecord, done: usize, total: usize, eta_s: Option<f64>) {
        if let Some(t) = self.job_bars.remove(&record.index) {
            t.bar.finish_and_clear();
            if let Some((m, _)) = &self.bars {
                m.remove(&t.bar);
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
