//! Running a batch: workers, the JSON report, progress through an [`Observer`], and a
//! clean stop when the [`Cancel`] flag is set.

use crate::job::{Event, Job, Rendered, Report};
use crate::output::OutputError;
use serde::Serialize;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, RwLock, mpsc};
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

impl JobRecord {
    /// The record of job `index` before it runs.
    fn not_run(index: usize, job: &Job) -> Self {
        JobRecord {
            index,
            name: job.name.clone(),
            scene: job.scene.name(),
            output: job
                .outputs
                .image
                .as_ref()
                .map(|p| p.to_string_lossy().into_owned())
                .unwrap_or_default(),
            status: JobStatus::NotRun,
            wall_ms: 0.0,
            stats: None,
            error: None,
        }
    }
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
}

/// A flag that stops a batch (set it from a Ctrl-C handler, say); clones share it.
#[derive(Clone, Debug, Default)]
pub struct Cancel(Arc<AtomicBool>);

impl Cancel {
    /// Ask the batch to stop.
    pub fn cancel(&self) {
        self.0.store(true, Ordering::SeqCst);
    }

    /// Whether it was asked to.
    pub fn is_cancelled(&self) -> bool {
        self.0.load(Ordering::SeqCst)
    }
}

/// What a batch tells while it runs (the command draws progress bars from it). Every
/// method is called from the thread that called [`run`]; each does nothing by default.
pub trait Observer {
    /// Job `index` started.
    fn started(&mut self, index: usize, job: &Job) {
        let _ = (index, job);
    }

    /// Job `index` is in `phase` (told from the start of its load to its first tile).
    fn phase(&mut self, index: usize, phase: JobPhase) {
        let _ = (index, phase);
    }

    /// Job `index` has rendered `done` of its `total` tiles.
    fn progress(&mut self, index: usize, done: usize, total: usize) {
        let _ = (index, done, total);
    }

    /// Job `index` is rendered and its image is being written.
    fn writing(&mut self, index: usize, job: &Job) {
        let _ = (index, job);
    }

    /// A job finished (rendered, failed or skipped): `done` of `total` jobs are, and
    /// about `eta_s` seconds of rendering are left.
    fn finished(&mut self, record: &JobRecord, done: usize, total: usize, eta_s: Option<f64>) {
        let _ = (record, done, total, eta_s);
    }

    /// No job runs any more (all finished, or the batch was cancelled); the report is
    /// written next.
    fn stopped(&mut self) {}

    /// The JSON report could not be written (the batch goes on).
    fn report_not_written(&mut self, error: &OutputError) {
        let _ = error;
    }
}

/// Tells nothing.
impl Observer for () {}

/// What a job is doing before its first tile.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum JobPhase {
    /// Reading or generating its scene; `done` of `total` units loaded (bytes of an
    /// NFF or OBJ file, primitives of a generated database) once the load tells.
    Loading {
        /// Units done.
        done: u64,
        /// Units in all (0 until the load tells).
        total: u64,
    },
    /// Building its backend.
    Building,
    /// Rendering (solving the radiosity first, in two-pass mode).
    Rendering,
}

impl JobPhase {
    /// The phase a job event starts or advances, if any.
    fn of(event: &Event<'_>) -> Option<JobPhase> {
        match *event {
            Event::Loading => Some(JobPhase::Loading { done: 0, total: 0 }),
            Event::Loaded { done, total } => Some(JobPhase::Loading { done, total }),
            Event::Building => Some(JobPhase::Building),
            Event::Rendering => Some(JobPhase::Rendering),
            _ => None,
        }
    }
}

/// What the workers of one batch share.
struct Shared {
    jobs: Vec<Job>,
    /// The next job to take.
    next: AtomicUsize,
    cancel: Cancel,
    /// Workers hold it shared while they write an image (after checking `cancel`);
    /// once cancelled the batch takes it exclusively, so it returns with no image
    /// half-written and no temporary file left, and every image in place is in the
    /// report.
    write_gate: RwLock<()>,
    /// Worker threads per job.
    threads: usize,
    opts: BatchOptions,
}

enum Msg {
    Started(usize),
    Phase(usize, JobPhase),
    Progress(usize, usize, usize),
    Writing(usize),
    Finished(Box<JobRecord>),
}

/// Load and render one job, telling `tell` of its phases and tiles; the error is the
/// report's `error`.
fn render_job(job: &Job, tell: &(dyn Fn(Msg) + Sync), i: usize) -> Result<Rendered, String> {
    let observer = |e: Event<'_>| {
        if let Event::Tiles { done, total } = e {
            tell(Msg::Progress(i, done, total));
        } else if let Some(phase) = JobPhase::of(&e) {
            tell(Msg::Phase(i, phase));
        }
    };
    crate::job::render(job, &observer).map_err(|e| e.to_string())
}

fn panic_message(p: &(dyn std::any::Any + Send)) -> String {
    p.downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| p.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "unknown panic".into())
}

/// Take jobs until none is left or the batch is cancelled, telling the batch of each.
fn worker(shared: Arc<Shared>, tx: mpsc::Sender<Msg>) {
    let pool = match rayon::ThreadPoolBuilder::new()
        .num_threads(shared.threads)
        .build()
    {
        Ok(p) => p,
        Err(e) => {
            log::error!("cannot start worker threads: {e}");
            return;
        }
    };
    loop {
        if shared.cancel.is_cancelled() {
            return;
        }
        let i = shared.next.fetch_add(1, Ordering::SeqCst);
        let Some(job) = shared.jobs.get(i) else {
            return;
        };
        if tx.send(Msg::Started(i)).is_err() {
            return;
        }
        let Some(record) = run_job(&shared, &pool, i, job, &tx) else {
            return;
        };
        if tx.send(Msg::Finished(Box::new(record))).is_err() {
            return;
        }
    }
}

/// Skip, or render and write, job `i`; `None` when the batch was cancelled before its
/// image was written.
fn run_job(
    shared: &Shared,
    pool: &rayon::ThreadPool,
    i: usize,
    job: &Job,
    tx: &mpsc::Sender<Msg>,
) -> Option<JobRecord> {
    let t0 = Instant::now();
    for file in job.files() {
        crate::output::remove_stale_temps(&file);
    }
    let mut record = JobRecord::not_run(i, job);
    record.status = JobStatus::Ok;
    let whole = |p: &PathBuf| crate::output::is_complete_image(p);
    if shared.opts.skip_existing && job.outputs.image.as_ref().is_some_and(whole) {
        record.status = JobStatus::Skipped;
        record.wall_ms = t0.elapsed().as_secs_f64() * 1e3;
        return Some(record);
    }
    // An output that cannot be written fails the job before it renders.
    if let Err(e) = job.prepare() {
        record.status = JobStatus::Failed;
        record.error = Some(e.to_string());
        record.wall_ms = t0.elapsed().as_secs_f64() * 1e3;
        return Some(record);
    }
    let txp = tx.clone();
    let tell = move |m: Msg| {
        let _ = txp.send(m);
    };
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        pool.install(|| render_job(job, &tell, i))
    }));
    // The image is written and the job reported with the gate held shared, and not at
    // all once the batch is cancelled (see `Shared::write_gate`).
    let _gate = shared.write_gate.read().unwrap_or_else(|e| e.into_inner());
    if shared.cancel.is_cancelled() {
        return None;
    }
    let result = result.map(|r| {
        r.and_then(|rendered| {
            let _ = tx.send(Msg::Writing(i));
            crate::job::write(job, &rendered, &())
                .map(|()| rendered.report)
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
                job.scene.name(),
                panic_message(&*p)
            ));
        }
    }
    record.wall_ms = t0.elapsed().as_secs_f64() * 1e3;
    Some(record)
}

fn write_report(path: &Path, report: &BatchReport, observer: &mut dyn Observer) {
    let text = serde_json::to_string_pretty(report).expect("report serialises") + "\n";
    if let Err(e) = crate::output::write_text(path, &text) {
        observer.report_not_written(&e);
    }
}

/// Run `jobs`, writing the report after each one; returns the final report. Setting
/// `cancel` stops the batch: the report of what finished is written and the call
/// returns at once with `interrupted` set (running jobs are abandoned before their
/// output is renamed into place, so no partial image is left under an output name).
pub fn run(
    jobs: Vec<Job>,
    opts: &BatchOptions,
    cancel: &Cancel,
    observer: &mut dyn Observer,
) -> BatchReport {
    let start = Instant::now();
    let total = jobs.len();
    let threads = opts.threads.unwrap_or_else(|| {
        std::thread::available_parallelism()
            .map(|n| n.get())
            .unwrap_or(1)
    });
    let workers = opts.jobs.clamp(1, total.max(1));
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
            .map(|(i, j)| JobRecord::not_run(i, j))
            .collect(),
    };
    let shared = Arc::new(Shared {
        jobs,
        next: AtomicUsize::new(0),
        cancel: cancel.clone(),
        write_gate: RwLock::new(()),
        threads: (threads / workers).max(1),
        opts: opts.clone(),
    });
    let (tx, rx) = mpsc::channel();
    for _ in 0..workers {
        let (shared, tx) = (shared.clone(), tx.clone());
        std::thread::spawn(move || worker(shared, tx));
    }
    drop(tx);
    collect(&shared, &rx, &mut report, workers, start, observer);
    observer.stopped();
    report.tally();
    report.wall_ms = start.elapsed().as_secs_f64() * 1e3;
    if let Some(p) = &opts.report {
        write_report(p, &report, observer);
    }
    report
}

/// Take in the workers' messages until every job finished or the batch is cancelled.
fn collect(
    shared: &Shared,
    rx: &mpsc::Receiver<Msg>,
    report: &mut BatchReport,
    workers: usize,
    start: Instant,
    observer: &mut dyn Observer,
) {
    let total = report.total;
    let mut done = 0;
    let mut rendered_ms = 0.0;
    let mut rendered = 0usize;
    while done < total {
        if shared.cancel.is_cancelled() {
            report.interrupted = true;
            // Wait for images being written; then take in what finished meanwhile.
            // Running jobs are abandoned.
            let _gate = shared.write_gate.write().unwrap_or_else(|e| e.into_inner());
            while let Ok(m) = rx.try_recv() {
                if let Msg::Finished(r) = m {
                    let i = r.index;
                    report.jobs[i] = *r;
                }
            }
            return;
        }
        match rx.recv_timeout(Duration::from_millis(100)) {
            Ok(Msg::Started(i)) => {
                report.jobs[i].status = JobStatus::Interrupted;
                observer.started(i, &shared.jobs[i]);
            }
            Ok(Msg::Phase(i, phase)) => observer.phase(i, phase),
            Ok(Msg::Progress(i, d, t)) => observer.progress(i, d, t),
            Ok(Msg::Writing(i)) => observer.writing(i, &shared.jobs[i]),
            Ok(Msg::Finished(r)) => {
                done += 1;
                if r.status != JobStatus::Skipped {
                    rendered_ms += r.wall_ms;
                    rendered += 1;
                }
                let eta = (rendered > 0 && done < total).then(|| {
                    rendered_ms / rendered as f64 * (total - done) as f64 / workers as f64 / 1e3
                });
                observer.finished(&r, done, total, eta);
                let i = r.index;
                report.jobs[i] = *r;
                report.tally();
                report.wall_ms = start.elapsed().as_secs_f64() * 1e3;
                if let Some(p) = &shared.opts.report {
                    write_report(p, report, observer);
                }
            }
            Err(mpsc::RecvTimeoutError::Timeout) => {}
            // Every worker stopped: a worker that saw the signal before this loop did
            // stops without a word, so the batch was interrupted if the signal came.
            Err(mpsc::RecvTimeoutError::Disconnected) => {
                report.interrupted = shared.cancel.is_cancelled();
                return;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::job::{RenderOptions, Res, SceneSource};

    /// Everything a batch tells, in order.
    #[derive(Default)]
    struct Told(Vec<String>);

    impl Observer for Told {
        fn started(&mut self, index: usize, _: &Job) {
            self.0.push(format!("started {index}"));
        }
        fn phase(&mut self, index: usize, phase: JobPhase) {
            self.0.push(format!("{index} {phase:?}"));
        }
        fn progress(&mut self, index: usize, done: usize, total: usize) {
            self.0.push(format!("{index} tiles {done}/{total}"));
        }
        fn finished(&mut self, r: &JobRecord, _: usize, _: usize, _: Option<f64>) {
            self.0.push(format!("finished {} {:?}", r.index, r.status));
        }
    }

    #[test]
    fn a_job_tells_its_phases_before_its_tiles() {
        let dir = tempfile::tempdir().unwrap();
        let options = RenderOptions {
            res: Some(Res {
                width: 16,
                height: 16,
            }),
            ..RenderOptions::default()
        };
        let scene = SceneSource::File("spd:balls?size=1".into());
        let job = Job::render(scene, options, Some(dir.path().join("b.png")));
        let mut told = Told::default();
        let opts = BatchOptions {
            threads: Some(1),
            jobs: 1,
            skip_existing: false,
            report: None,
            shard: None,
        };
        let report = run(vec![job], &opts, &Cancel::default(), &mut told);
        assert_eq!(report.ok, 1, "{:?}", told.0);
        let at = |what: &str| told.0.iter().position(|t| t.starts_with(what));
        let loading = at("0 Loading { done: 0, total: 0 }").expect("loading told");
        let loaded = told.0.iter().position(|t| {
            t.starts_with("0 Loading { done: ")
                && t.contains("total: ")
                && !t.contains("total: 0 }")
        });
        let building = at("0 Building").expect("building told");
        let rendering = at("0 Rendering").expect("rendering told");
        let first_tile = at("0 tiles").expect("tiles told");
        assert!(at("started 0") < Some(loading));
        assert!(
            loaded.is_some_and(|l| loading < l && l < building),
            "{:?}",
            told.0
        );
        assert!(
            building < rendering && rendering < first_tile,
            "{:?}",
            told.0
        );
        assert_eq!(told.0.last().map(String::as_str), Some("finished 0 Ok"));
    }
}
