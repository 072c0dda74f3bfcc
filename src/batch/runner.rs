//! Running a batch: workers, progress, the JSON report, Ctrl-C.

use super::Job;
use crate::run::{Report, limits, load_scene};
use serde::Serialize;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Once, RwLock, mpsc};
use std::time::{Duration, Instant};

/// How to run a batch.
#[derive(Clone, Debug, Default)]
pub struct BatchOptions {
    /// Worker threads in all (default: every core).
    pub threads: Option<usize>,
    /// Jobs rendered at once, sharing the threads (at least 1).
    pub jobs: usize,
    /// Skip a job whose output exists and decodes as a whole image.
    pub skip_existing: bool,
    /// Where the JSON report goes, rewritten after every job.
    pub report: Option<PathBuf>,
    /// No progress, only errors.
    pub quiet: bool,
    /// Refuse a job whose estimated memory exceeds this many bytes.
    pub max_memory: u64,
    /// The shard `I/N` being run, for the report.
    pub shard: Option<(u32, u32)>,
}

/// What became of a job.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum JobStatus {
    /// Rendered and written.
    Ok,
    /// Failed to load, render or write; `error` says why.
    Failed,
    /// Its output was already there and whole (`--skip-existing`).
    Skipped,
    /// Running when the batch was interrupted; nothing was written.
    Interrupted,
    /// Not started.
    NotRun,
}

/// One job in the report.
#[derive(Clone, Debug, Serialize)]
pub struct JobRecord {
    /// Position in the batch (after shard selection).
    pub index: usize,
    /// The job's name.
    pub name: String,
    /// Scene.
    pub scene: String,
    /// Output file.
    pub output: String,
    /// Outcome.
    pub status: JobStatus,
    /// Wall time of the whole job in milliseconds (load, build, render, write).
    pub wall_ms: f64,
    /// The render's report (timings by phase, ray counts, primitives) when it ran.
    pub stats: Option<Report>,
    /// The error, `path:line:col: message` where it has a place.
    pub error: Option<String>,
}

/// The JSON report of a batch.
#[derive(Clone, Debug, Serialize)]
pub struct BatchReport {
    /// `I/N` when a shard was run.
    pub shard: Option<String>,
    /// Jobs in this run.
    pub total: usize,
    /// Jobs by outcome.
    pub ok: usize,
    /// Failed jobs.
    pub failed: usize,
    /// Skipped jobs.
    pub skipped: usize,
    /// Jobs not finished (interrupted or not started).
    pub unfinished: usize,
    /// Whether Ctrl-C stopped the batch.
    pub interrupted: bool,
    /// Wall time of the batch in milliseconds.
    pub wall_ms: f64,
    /// Every job.
    pub jobs: Vec<JobRecord>,
}

impl BatchReport {
    fn tally(&mut self) {
        let n = |s: JobStatus| self.jobs.iter().filter(|j| j.status == s).count();
        self.ok = n(JobStatus::Ok);
        self.failed = n(JobStatus::Failed);
        self.skipped = n(JobStatus::Skipped);
        self.unfinished = n(JobStatus::Interrupted) + n(JobStatus::NotRun);
    }

    /// The process exit status: 130 when interrupted, 1 when a job failed, else 0.
    pub fn exit_code(&self) -> u8 {
        if self.interrupted {
            130
        } else if self.failed > 0 {
            1
        } else {
            0
        }
    }
}

/// Set by Ctrl-C.
static STOP: AtomicBool = AtomicBool::new(false);

/// Workers hold it shared while they write an image (after checking [`STOP`]); on
/// Ctrl-C the batch takes it exclusively, so it returns with no image half-written and
/// no temporary file left, and every image in place is in the report.
static WRITE_GATE: RwLock<()> = RwLock::new(());

fn catch_ctrl_c() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        if let Err(e) = ctrlc::set_handler(|| STOP.store(true, Ordering::SeqCst)) {
            log::warn!("cannot catch Ctrl-C: {e}");
        }
    });
}

enum Msg {
    Started(usize),
    Progress(usize, usize, usize),
    Finished(Box<JobRecord>),
}

/// Load and render one job; the error is the report's `error`.
fn render_job(
    job: &Job,
    max_memory: u64,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<(crate::render::Film, Report), String> {
    let t0 = Instant::now();
    let scene = load_scene(&job.scene).map_err(|e| e.to_string())?;
    let load_ms = t0.elapsed().as_secs_f64() * 1e3;
    let name = job.scene.to_string_lossy();
    let settings = (job.settings.render)
        .settings(&scene)
        .map_err(|e| format!("{name}: {e}"))?;
    limits::check(&job.scene, &scene, &settings, max_memory).map_err(|e| e.to_string())?;
    let (film, report) = crate::run::render_scene(
        &name,
        &scene,
        job.settings.backend(),
        &settings,
        load_ms,
        Some(progress),
    )
    .map_err(|e| format!("{name}: {e}"))?;
    Ok((film, report))
}

fn panic_message(p: &(dyn std::any::Any + Send)) -> String {
    p.downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| p.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "unknown panic".into())
}

fn worker(
    jobs: Arc<Vec<Job>>,
    next: Arc<AtomicUsize>,
    tx: mpsc::Sender<Msg>,
    threads: usize,
    opts: BatchOptions,
) {
    let pool = match rayon::ThreadPoolBuilder::new().num_threads(threads).build() {
        Ok(p) => p,
        Err(e) => {
            log::error!("cannot start worker threads: {e}");
            return;
        }
    };
    loop {
        if STOP.load(Ordering::SeqCst) {
            return;
        }
        let i = next.fetch_add(1, Ordering::SeqCst);
        let Some(job) = jobs.get(i) else { return };
        if tx.send(Msg::Started(i)).is_err() {
            return;
        }
        let t0 = Instant::now();
        crate::output::remove_stale_temps(&job.output);
        let mut record = JobRecord {
            index: i,
            name: job.name.clone(),
            scene: job.scene.to_string_lossy().into_owned(),
            output: job.output.to_string_lossy().into_owned(),
            status: JobStatus::Ok,
            wall_ms: 0.0,
            stats: None,
            error: None,
        };
        if opts.skip_existing && crate::output::is_complete_image(&job.output) {
            record.status = JobStatus::Skipped;
        } else {
            if let Some(dir) = job.output.parent().filter(|d| !d.as_os_str().is_empty()) {
                let _ = std::fs::create_dir_all(dir);
            }
            let txp = tx.clone();
            let progress = move |d: usize, t: usize| {
                let _ = txp.send(Msg::Progress(i, d, t));
            };
            let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                pool.install(|| render_job(job, opts.max_memory, &progress))
            }));
            // The image is written and the job reported with the gate held shared, and
            // not at all once the batch is interrupted (see WRITE_GATE).
            let _gate = WRITE_GATE.read().unwrap_or_else(|e| e.into_inner());
            if STOP.load(Ordering::SeqCst) {
                return;
            }
            let result = result.map(|r| {
                r.and_then(|(film, report)| {
                    crate::output::write_image(&job.output, &film, job.settings.encoding)
                        .map(|()| report)
                        .map_err(|e| e.to_string())
                })
            });
            match result {
                Ok(Ok(report)) => record.stats = Some(report),
                Ok(Err(e)) => {
                    record.status = JobStatus::Failed;
                    record.error = Some(e);
                }
                Err(p) => {
                    record.status = JobStatus::Failed;
                    record.error = Some(format!(
                        "{}: internal error: {}",
                        job.scene.display(),
                        panic_message(&*p)
                    ));
                }
            }
            record.wall_ms = t0.elapsed().as_secs_f64() * 1e3;
            if tx.send(Msg::Finished(Box::new(record))).is_err() {
                return;
            }
            continue;
        }
        record.wall_ms = t0.elapsed().as_secs_f64() * 1e3;
        if tx.send(Msg::Finished(Box::new(record))).is_err() {
            return;
        }
    }
}

/// What the user sees while a batch runs.
struct Display {
    bars: Option<(indicatif::MultiProgress, indicatif::ProgressBar)>,
    job_bars: std::collections::HashMap<usize, indicatif::ProgressBar>,
    quiet: bool,
}

impl Display {
    fn new(total: usize, quiet: bool) -> Self {
        let bars = (!quiet && std::io::stderr().is_terminal()).then(|| {
            let m = indicatif::MultiProgress::new();
            let b = m.add(indicatif::ProgressBar::new(total as u64));
            b.set_style(
                indicatif::ProgressStyle::with_template(
                    "batch [{bar:30}] {pos}/{len} jobs {elapsed_precise} eta {eta}",
                )
                .expect("static template")
                .progress_chars("=> "),
            );
            (m, b)
        });
        Display {
            bars,
            job_bars: Default::default(),
            quiet,
        }
    }

    fn started(&mut self, i: usize, job: &Job) {
        if let Some((m, _)) = &self.bars {
            let b = m.add(indicatif::ProgressBar::new(0));
            b.set_style(
                indicatif::ProgressStyle::with_template(
                    "  {msg} [{bar:30}] {pos}/{len} tiles eta {eta}",
                )
                .expect("static template")
                .progress_chars("=> "),
            );
            b.set_message(job.name.clone());
            self.job_bars.insert(i, b);
        }
    }

    fn progress(&self, i: usize, done: usize, total: usize) {
        if let Some(b) = self.job_bars.get(&i) {
            b.set_length(total as u64);
            b.set_position(done as u64);
        }
    }

    fn finished(&mut self, r: &JobRecord, done: usize, total: usize, eta: Option<f64>) {
        if let Some(b) = self.job_bars.remove(&r.index) {
            b.finish_and_clear();
            if let Some((m, _)) = &self.bars {
                m.remove(&b);
            }
        }
        let line = match (&r.status, &r.error) {
            (JobStatus::Failed, Some(e)) => format!("emray: error: job '{}': {e}", r.name),
            _ if self.quiet => return,
            (s, _) => format!(
                "emray: [{done}/{total}] {} {} ({:.2} s{})",
                match s {
                    JobStatus::Skipped => "skipped",
                    _ => "ok",
                },
                r.output,
                r.wall_ms / 1e3,
                eta.map(|e| format!(", eta {e:.0} s")).unwrap_or_default()
            ),
        };
        match &self.bars {
            Some((m, b)) => {
                b.inc(1);
                let _ = m.println(line);
            }
            None => eprintln!("{line}"),
        }
    }

    fn finish(&self) {
        if let Some((_, b)) = &self.bars {
            b.finish_and_clear();
        }
    }
}

fn write_report(path: &Path, report: &BatchReport) {
    let text = serde_json::to_string_pretty(report).expect("report serialises") + "\n";
    if let Err(e) = crate::output::write_text(path, &text) {
        eprintln!("emray: error: {e}");
    }
}

/// Run `jobs`, writing the report after each one; returns the final report. Ctrl-C
/// stops the batch: the report of what finished is written and the call returns at
/// once with `interrupted` set (running jobs are abandoned before their output is
/// renamed into place, so no partial image is left under an output name).
pub fn run(jobs: Vec<Job>, opts: &BatchOptions) -> BatchReport {
    catch_ctrl_c();
    let start = Instant::now();
    let total = jobs.len();
    let threads = opts.threads.unwrap_or_else(|| {
        std::thread::available_parallelism()
            .map(|n| n.get())
            .unwrap_or(1)
    });
    let workers = opts.jobs.clamp(1, total.max(1));
    let per_worker = (threads / workers).max(1);
    let mut report = BatchReport {
        shard: opts.shard.map(|(i, n)| format!("{i}/{n}")),
        total,
        ok: 0,
        failed: 0,
        skipped: 0,
        unfinished: total,
        interrupted: false,
        wall_ms: 0.0,
        jobs: jobs
            .iter()
            .enumerate()
            .map(|(i, j)| JobRecord {
                index: i,
                name: j.name.clone(),
                scene: j.scene.to_string_lossy().into_owned(),
                output: j.output.to_string_lossy().into_owned(),
                status: JobStatus::NotRun,
                wall_ms: 0.0,
                stats: None,
                error: None,
            })
            .collect(),
    };
    let jobs = Arc::new(jobs);
    let next = Arc::new(AtomicUsize::new(0));
    let (tx, rx) = mpsc::channel();
    for _ in 0..workers {
        let (jobs, next, tx, opts) = (jobs.clone(), next.clone(), tx.clone(), opts.clone());
        std::thread::spawn(move || worker(jobs, next, tx, per_worker, opts));
    }
    drop(tx);
    let mut display = Display::new(total, opts.quiet);
    let mut done = 0;
    let mut rendered_ms = 0.0;
    let mut rendered = 0usize;
    while done < total {
        if STOP.load(Ordering::SeqCst) {
            report.interrupted = true;
            // Wait for images being written; then take in what finished meanwhile.
            // Running jobs are abandoned.
            let _gate = WRITE_GATE.write().unwrap_or_else(|e| e.into_inner());
            while let Ok(m) = rx.try_recv() {
                if let Msg::Finished(r) = m {
                    let i = r.index;
                    report.jobs[i] = *r;
                }
            }
            break;
        }
        match rx.recv_timeout(Duration::from_millis(100)) {
            Ok(Msg::Started(i)) => {
                report.jobs[i].status = JobStatus::Interrupted;
                display.started(i, &jobs[i]);
            }
            Ok(Msg::Progress(i, d, t)) => display.progress(i, d, t),
            Ok(Msg::Finished(r)) => {
                done += 1;
                if r.status != JobStatus::Skipped {
                    rendered_ms += r.wall_ms;
                    rendered += 1;
                }
                let eta = (rendered > 0 && done < total).then(|| {
                    rendered_ms / rendered as f64 * (total - done) as f64 / workers as f64 / 1e3
                });
                display.finished(&r, done, total, eta);
                let i = r.index;
                report.jobs[i] = *r;
                report.tally();
                report.wall_ms = start.elapsed().as_secs_f64() * 1e3;
                if let Some(p) = &opts.report {
                    write_report(p, &report);
                }
            }
            Err(mpsc::RecvTimeoutError::Timeout) => {}
            Err(mpsc::RecvTimeoutError::Disconnected) => break,
        }
    }
    display.finish();
    report.tally();
    report.wall_ms = start.elapsed().as_secs_f64() * 1e3;
    if let Some(p) = &opts.report {
        write_report(p, &report);
    }
    if report.interrupted && !opts.quiet {
        eprintln!(
            "emray: interrupted: {} of {} jobs finished",
            report.ok + report.failed + report.skipped,
            total
        );
    }
    report
}
