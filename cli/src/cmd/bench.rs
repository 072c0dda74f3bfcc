//! `emray bench`: the benchmark suite, each run in a child process of its own (the
//! hidden `--child` option is that child's side).

use super::args::LogArgs;
use super::error::print;
use super::{Error, outputs};
use emray::accel::Backend;
use emray::bench::{self, RunSpec};
use emray::job::RenderOptions;
use emray::spd::Database;
use std::path::PathBuf;

/// `emray bench`.
#[derive(clap::Args, Debug, Clone)]
pub struct Args {
    /// Scenes (`spd:NAME[?size=N]` or NFF files) [default: the SPD suite: balls, gears,
    /// jacks, mount, rings, teapot, tetra, tree, plus balls at sizes 2, 3, 5 and jacks at
    /// 2, 3].
    #[arg(value_name = "SCENE")]
    pub scenes: Vec<String>,
    /// Thread counts [default: 1 and all cores].
    #[arg(short, long, value_delimiter = ',', value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub threads: Vec<u32>,
    /// Repetitions of every run (median and spread are reported).
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u32).range(1..=1000))]
    pub reps: u32,
    /// Render with one ray per pixel centre instead of SPD mode's corner rays.
    #[arg(long)]
    pub no_spd: bool,
    /// Eye rays only: one per pixel centre, lights removed, depth 1, so that render ÷ raw is the cost of the
    /// eye-ray pipeline over casting the same rays.
    #[arg(long)]
    pub eye_only: bool,
    /// Skip the raw-casting runs.
    #[arg(long)]
    pub no_raw: bool,
    /// Skip Tachyon.
    #[arg(long)]
    pub no_peer: bool,
    /// Write the rows as CSV to FILE.
    #[arg(long, value_name = "FILE")]
    pub csv: Option<PathBuf>,
    /// Write everything (machine, rows, summary, samples) as JSON to FILE.
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
    /// Compare with a JSON file of an earlier run: per-row ratios.
    #[arg(long, value_name = "FILE.json")]
    pub baseline: Option<PathBuf>,
    /// The render options of every run over the suite's rules (512x512 in SPD mode,
    /// depth 5, the full ray tree): `--backend` keeps one backend of the two, `--res`
    /// changes the size, and so on.
    #[command(flatten)]
    pub options: RenderOptions,
    /// Run one measurement in this process (used by the suite itself).
    #[arg(long, hide = true, value_name = "JSON")]
    pub child: Option<String>,
    /// `-q` and `-v`.
    #[command(flatten)]
    pub log: LogArgs,
}

/// Run the suite and print its markdown report (or, as a child, one run's JSON).
pub fn run(b: Args) -> Result<(), Error> {
    if let Some(json) = &b.child {
        return child(json);
    }
    let cfg = config(&b);
    for s in &cfg.scenes {
        Database::parse_spec(s).map_err(Error::usage)?;
    }
    outputs::prepare(b.csv.iter().chain(&b.json).map(PathBuf::as_path))?;
    let outs = bench::Outputs {
        csv: b.csv.clone(),
        json: b.json.clone(),
        baseline: b.baseline.clone(),
    };
    let exe = std::env::current_exe()
        .map_err(|e| Error::failed(format!("cannot find the emray executable: {e}")))?;
    let quiet = b.log.quiet;
    let mut log = |line: &str| {
        if !quiet {
            eprintln!("{line}");
        }
    };
    let md = bench::bench(&cfg, &outs, &exe, &mut log)?;
    print(format_args!("{md}"))?;
    Ok(())
}

/// One run in this process, its result as JSON on standard output.
fn child(json: &str) -> Result<(), Error> {
    let spec = serde_json::from_str::<RunSpec>(json)
        .map_err(|e| Error::failed(format!("bad run description: {e}")))?;
    let result = bench::run_child(&spec)?;
    let json = serde_json::to_string(&result).expect("result serialises");
    print(format_args!("{json}\n"))?;
    Ok(())
}

/// The suite the options ask for: both backends (or the BVH alone without Embree, or
/// the one `--backend` names) and 1 and all threads unless told otherwise.
fn config(b: &Args) -> bench::Config {
    let backends = match b.options.backend {
        Some(one) => vec![one],
        None if cfg!(feature = "embree") => vec![Backend::Embree, Backend::Bvh],
        None => vec![Backend::Bvh],
    };
    let mut threads: Vec<usize> = b.threads.iter().map(|&t| t as usize).collect();
    if threads.is_empty() {
        let all = std::thread::available_parallelism().map_or(1, |n| n.get());
        threads = if all > 1 { vec![1, all] } else { vec![1] };
    }
    let mut rules = bench::Config::rules();
    if b.no_spd {
        rules.spd = Some(false);
    }
    bench::Config {
        scenes: if b.scenes.is_empty() {
            bench::default_scenes()
        } else {
            b.scenes.clone()
        },
        backends,
        threads,
        reps: b.reps as usize,
        raw: !b.no_raw,
        peer: !b.no_peer,
        eye_only: b.eye_only,
        options: b.options.over(&rules),
    }
}
