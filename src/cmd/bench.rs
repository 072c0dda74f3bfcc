//! `emray bench`: the benchmark suite, each run in a child process of its own (the
//! hidden `--child` option is that child's side).

use super::args::{BackendArg, LogArgs, QualityArg, packet_width, parse_res};
use super::error::print;
use super::{Error, outputs};
use emray::accel::Backend;
use emray::bench::{self, RunSpec};
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
    /// Backends to compare [default: both, or the BVH alone without Embree].
    #[arg(long, value_enum, value_delimiter = ',')]
    pub backend: Vec<BackendArg>,
    /// Thread counts [default: 1 and all cores].
    #[arg(short, long, value_delimiter = ',', value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub threads: Vec<u32>,
    /// Repetitions of every run (median and spread are reported).
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u32).range(1..=1000))]
    pub reps: u32,
    /// Image size.
    #[arg(long, value_name = "WxH", value_parser = parse_res, default_value = "512x512")]
    pub res: (u32, u32),
    /// Render with one ray per pixel centre instead of SPD mode's corner rays.
    #[arg(long)]
    pub no_spd: bool,
    /// Embree build quality (RTC_BUILD_QUALITY_*).
    #[arg(long, value_enum, default_value_t = QualityArg::Medium)]
    pub embree_quality: QualityArg,
    /// Eye rays per Embree packet (0, 4, 8 or 16; 0 casts them one by one).
    #[arg(long, value_name = "N", default_value_t = 8, value_parser = packet_width)]
    pub packet_width: u32,
    /// Embree's fast traversal, without RTC_SCENE_FLAG_ROBUST (as `render --embree-fast`).
    #[arg(long)]
    pub embree_fast: bool,
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

/// The suite the options ask for: both backends (or the BVH alone without Embree)
/// and 1 and all threads unless told otherwise.
fn config(b: &Args) -> bench::Config {
    let mut backends: Vec<Backend> = b.backend.iter().map(|&x| Backend::from(x)).collect();
    if backends.is_empty() {
        backends = if cfg!(feature = "embree") {
            vec![Backend::Embree, Backend::Bvh]
        } else {
            vec![Backend::Bvh]
        };
    }
    let mut threads: Vec<usize> = b.threads.iter().map(|&t| t as usize).collect();
    if threads.is_empty() {
        let all = std::thread::available_parallelism().map_or(1, |n| n.get());
        threads = if all > 1 { vec![1, all] } else { vec![1] };
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
        width: b.res.0,
        height: b.res.1,
        spd: !b.no_spd,
        raw: !b.no_raw,
        peer: !b.no_peer,
        embree_quality: b.embree_quality.into(),
        packet_width: b.packet_width,
        embree_fast: b.embree_fast,
        eye_only: b.eye_only,
    }
}
