//! The `emray` command.

mod cli;
mod quality_cmd;

use anyhow::{Context, Result, bail};
use clap::Parser;
use cli::{Cli, Command, RenderArgs};
use emray::Scene;
use emray::accel::Backend;
use emray::load;
use emray::scene::Environment;
use emray::spd::Database;
use std::io::{IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

/// The built-in default scene.
const DEFAULT_SCENE: &str = include_str!("../scenes/default.nff");

fn main() -> ExitCode {
    let cli = Cli::parse();
    let args = match cli.command {
        Some(Command::Render(a)) => a,
        Some(Command::Gen(g)) => return generate(&g),
        Some(Command::Batch(b)) => return batch(&b),
        Some(Command::Merge(m)) => return merge(&m),
        Some(Command::Bench(b)) => return bench(&b),
        Some(Command::Compare(c)) => return quality_cmd::compare(&c),
        Some(Command::Stress(s)) => return quality_cmd::stress(&s),
        Some(Command::Radiosity(r)) => return radiosity(&r),
        Some(Command::Study(s)) => return quality_cmd::study(&s),
        None => RenderArgs::default_scene(),
    };
    init_log(args.quiet, args.verbose);
    let jobs = match plan(&args) {
        Ok(j) => j,
        Err(e) => {
            eprintln!("emray: error: {e}");
            return ExitCode::from(2);
        }
    };
    match render_all(&args, &jobs) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("emray: error: {e:#}");
            ExitCode::from(1)
        }
    }
}

fn init_log(quiet: bool, verbose: u8) {
    let level = match (quiet, verbose) {
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

/// `emray batch`: exit 2 on a usage error (nothing run), 1 when a job failed, 130 when
/// interrupted, else 0.
fn batch(b: &cli::BatchArgs) -> ExitCode {
    use emray::batch;
    init_log(b.quiet, 0);
    let usage = |e: String| {
        eprintln!("emray: error: {e}");
        ExitCode::from(2)
    };
    let jobs = match &b.manifest {
        Some(m) => match batch::manifest::load(m, &b.overrides()) {
            Ok(j) => j,
            Err(e) => {
                eprintln!("emray: error: {e}");
                return ExitCode::from(1);
            }
        },
        None if b.scenes.is_empty() => {
            return usage("give scene files, globs or --manifest FILE".into());
        }
        None => {
            let settings = batch::JobSettings {
                backend: b.backend.map(Backend::from),
                res: b.res,
                spp: b.spp,
                max_depth: b.max_depth,
                spd: b.spd,
                encoding: b.encoding.map(Into::into).unwrap_or_default(),
            };
            let template = b.output.as_deref().unwrap_or("{stem}.png");
            match batch::expand_scene_args(&b.scenes)
                .and_then(|s| batch::jobs_from_scenes(&s, template, &settings))
            {
                Ok(j) => j,
                Err(e) => return usage(e),
            }
        }
    };
    if let Err(e) = batch::check_jobs(&jobs) {
        return usage(e);
    }
    let jobs: Vec<batch::Job> = match b.shard {
        Some((i, n)) => jobs
            .into_iter()
            .filter(|j| batch::shard_of(&j.name, n) == i)
            .collect(),
        None => jobs,
    };
    if b.list {
        for j in &jobs {
            println!("{}\t{}\t{}", j.name, j.scene.display(), j.output.display());
        }
        return ExitCode::SUCCESS;
    }
    let shard_index = b.shard.map_or(0, |(i, _)| i);
    let opts = batch::BatchOptions {
        threads: b.threads.map(|t| t as usize),
        jobs: b.jobs as usize,
        skip_existing: b.skip_existing,
        report: b
            .report
            .as_ref()
            .map(|r| PathBuf::from(r.replace("{shard}", &shard_index.to_string()))),
        quiet: b.quiet,
        max_memory: b
            .max_memory
            .unwrap_or_else(batch::limits::default_max_memory),
        shard: b.shard,
    };
    let report = batch::run(jobs, &opts);
    if report.failed > 0 {
        eprintln!(
            "emray: error: {} of {} jobs failed",
            report.failed, report.total
        );
    }
    ExitCode::from(report.exit_code())
}

/// `emray merge`: exit 1 when the parts do not make one image or cannot be written.
fn merge(m: &cli::MergeArgs) -> ExitCode {
    let result = emray::output::Format::from_path(&m.output)
        .map_err(|e| e.to_string())
        .and_then(|_| emray::batch::merge::merge(&m.parts))
        .and_then(|film| {
            emray::output::write_image(&m.output, &film, m.encoding.into())
                .map_err(|e| e.to_string())
        });
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("emray: error: {e}");
            ExitCode::from(1)
        }
    }
}

/// `emray gen`: exit 2 on a bad database or size, 1 when the file cannot be written.
fn generate(g: &cli::GenArgs) -> ExitCode {
    let Some(db) = Database::from_name(&g.database) else {
        let names: Vec<&str> = Database::ALL.iter().map(|d| d.name()).collect();
        eprintln!(
            "emray: error: unknown database '{}' (one of {})",
            g.database,
            names.join(", ")
        );
        return ExitCode::from(2);
    };
    let size = g.size.unwrap_or_else(|| db.default_size());
    if let Err(e) = db.check_size(size) {
        eprintln!("emray: error: {e}");
        return ExitCode::from(2);
    }
    let text = db.generate(size);
    let result = match &g.output {
        None => std::io::stdout()
            .lock()
            .write_all(text.as_bytes())
            .context("cannot write to standard output"),
        Some(path) => emray::output::write_text(path, &text).map_err(anyhow::Error::from),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("emray: error: {e:#}");
            ExitCode::from(1)
        }
    }
}

/// `emray bench`: exit 2 on bad arguments, 1 when a run fails.
fn bench(b: &cli::BenchArgs) -> ExitCode {
    use emray::bench;
    if let Some(json) = &b.child {
        let answer = serde_json::from_str::<bench::RunSpec>(json)
            .map_err(|e| format!("bad run description: {e}"))
            .and_then(|spec| bench::run_child(&spec));
        return match answer {
            Ok(r) => {
                println!("{}", serde_json::to_string(&r).expect("result serialises"));
                ExitCode::SUCCESS
            }
            Err(e) => {
                eprintln!("emray: error: {e}");
                ExitCode::from(1)
            }
        };
    }
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
    let cfg = bench::Config {
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
    };
    for s in &cfg.scenes {
        if let Err(e) = Database::parse_spec(s) {
            eprintln!("emray: error: {e}");
            return ExitCode::from(2);
        }
    }
    let outs = bench::Outputs {
        csv: b.csv.clone(),
        json: b.json.clone(),
        baseline: b.baseline.clone(),
    };
    let exe = match std::env::current_exe() {
        Ok(e) => e,
        Err(e) => {
            eprintln!("emray: error: cannot find the emray executable: {e}");
            return ExitCode::from(1);
        }
    };
    let mut log = |line: &str| eprintln!("{line}");
    match bench::bench(&cfg, &outs, &exe, &mut log) {
        Ok(md) => {
            print!("{md}");
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("emray: error: {e}");
            ExitCode::from(1)
        }
    }
}

/// `emray radiosity`: exit 1 on any input, solve or output error.
fn radiosity(a: &cli::RadiosityArgs) -> ExitCode {
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn"))
        .format_timestamp(None)
        .init();
    match radiosity_run(a) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("emray: error: {e:#}");
            ExitCode::from(1)
        }
    }
}

fn radiosity_run(a: &cli::RadiosityArgs) -> Result<()> {
    emray::output::Format::from_path(&a.output)?;
    let mut builder = rayon::ThreadPoolBuilder::new();
    if let Some(t) = a.threads {
        builder = builder.num_threads(t as usize);
    }
    let pool = builder.build().context("cannot start the worker threads")?;
    let scene = load::load_path(&a.scene)?;
    let settings = a.solve.settings();
    let (w, h) = a.res.unwrap_or((scene.camera.width, scene.camera.height));
    let spp = (a.spp as f32).sqrt().floor().max(1.0) as u32;
    let backend: Backend = a
        .backend
        .map(Backend::from)
        .unwrap_or_else(Backend::default_available);
    let (sol, film, report) = pool
        .install(|| emray::radiosity::run(&scene, backend, &settings, (w, h, spp)))
        .with_context(|| a.scene.display().to_string())?;
    emray::output::write_image(&a.output, &film, emray::output::Encoding::Srgb)?;
    if let Some(p) = &a.ply {
        emray::output::write_text(p, &sol.to_ply(1.0))?;
    }
    if a.stats {
        println!("scene      {}\n{}", a.scene.display(), report.summary());
    }
    if let Some(path) = &a.stats_json {
        append_json_line(path, &report)?;
    }
    Ok(())
}

/// Appends `value` as one JSON line to `path` (the `--stats-json` log: one record per run).
fn append_json_line(path: &Path, value: &impl serde::Serialize) -> Result<()> {
    let line = serde_json::to_string(value).expect("report serialises");
    let mut f = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(path)
        .with_context(|| format!("{}: cannot open for writing", path.display()))?;
    writeln!(f, "{line}").with_context(|| format!("{}: cannot write", path.display()))
}

/// Where scene `scene` goes.
fn output_for(args: &RenderArgs, scene: &Path) -> PathBuf {
    let stem = emray::batch::scene_stem(scene);
    PathBuf::from(match &args.output {
        Some(t) if t.contains("{stem}") => t.replace("{stem}", &stem),
        Some(t) => t.clone(),
        None => format!("{stem}.png"),
    })
}

/// One render: the scene (`None` = the built-in default) and its output file.
type Job = (Option<PathBuf>, PathBuf);

/// The jobs, or a usage error (exit status 2) found before any work is done.
fn plan(args: &RenderArgs) -> Result<Vec<Job>, String> {
    if args.reference && (args.spd || args.aa != cli::AaArg::Uniform) {
        return Err(
            "--reference samples N×N stratified: it cannot be combined with --spd or --aa adaptive"
                .into(),
        );
    }
    for (name, v) in [
        ("--bailout", args.bailout.unwrap_or(0.0)),
        ("--aa-threshold", args.aa_threshold),
    ] {
        if !v.is_finite() || v < 0.0 {
            return Err(format!("{name} must be a finite number >= 0, not {v}"));
        }
    }
    if args.scenes.len() > 1 {
        if let Some(o) = &args.output {
            if !o.contains("{stem}") {
                return Err(format!(
                    "{} scenes but one output file '{o}': use a template such as '{{stem}}.png'",
                    args.scenes.len()
                ));
            }
        }
    }
    let jobs: Vec<Job> = if args.scenes.is_empty() {
        vec![(None, output_for(args, Path::new("emray")))]
    } else {
        args.scenes
            .iter()
            .map(|s| (Some(s.clone()), output_for(args, s)))
            .collect()
    };
    if args.tile.is_some() || args.crop.is_some() {
        if args.reference {
            return Err("--reference renders whole images: not with --tile or --crop".into());
        }
        if args.gi.is_some() {
            // Each part would solve the radiosity on its own; the hash does not cover it.
            return Err("--gi renders whole images: not with --tile or --crop".into());
        }
        if jobs.len() != 1 {
            return Err("--tile and --crop render one scene".into());
        }
        if !matches!(
            emray::output::Format::from_path(&jobs[0].1),
            Ok(emray::output::Format::Exr)
        ) {
            return Err(format!(
                "--tile and --crop write an EXR part (for emray merge), not '{}'",
                jobs[0].1.display()
            ));
        }
    }
    for (scene, out) in &jobs {
        emray::output::Format::from_path(out).map_err(|e| e.to_string())?;
        if let Some(s) = scene {
            Database::parse_spec(&s.to_string_lossy())?;
        }
    }
    Ok(jobs)
}

fn render_all(args: &RenderArgs, jobs: &[Job]) -> Result<()> {
    let mut builder = rayon::ThreadPoolBuilder::new();
    if let Some(t) = args.threads {
        builder = builder.num_threads(t as usize);
    }
    let pool = builder.build().context("cannot start the worker threads")?;
    let mut failed = 0usize;
    for (scene, out) in jobs {
        let result = pool.install(|| render_one(args, scene.as_deref(), out));
        if let Err(e) = result {
            if jobs.len() == 1 {
                return Err(e);
            }
            eprintln!("emray: error: {e:#}");
            failed += 1;
        }
    }
    if failed > 0 {
        bail!("{failed} of {} scenes failed", jobs.len());
    }
    Ok(())
}

fn render_one(args: &RenderArgs, scene_path: Option<&Path>, out: &Path) -> Result<()> {
    let t0 = Instant::now();
    let (name, mut scene): (String, Scene) = match scene_path {
        Some(p) => (
            p.display().to_string(),
            emray::batch::load_scene(p).map_err(anyhow::Error::msg)?,
        ),
        None => (
            "default".into(),
            load::nff::parse_str(DEFAULT_SCENE, Path::new("<default scene>"))?,
        ),
    };
    if let Some(env) = &args.envmap {
        scene.environment = Some(Environment::load(env).map_err(anyhow::Error::msg)?);
    }
    let load_ms = t0.elapsed().as_secs_f64() * 1e3;
    let job = emray::batch::JobSettings {
        backend: args.backend.map(Backend::from),
        res: args.res,
        spp: args.spp,
        max_depth: args.max_depth,
        spd: args.spd,
        encoding: args.encoding.into(),
    };
    let mut settings = job.apply(&scene);
    if let Some(b) = args.bailout {
        settings.bailout = b;
    }
    settings.spp = args.spp.or(scene.render.spp).unwrap_or(1);
    settings.max_depth = args.max_depth.or(scene.render.max_depth).unwrap_or(5);
    if args.spd {
        // SPD testing mode: 512x512 from a 513x513 corner grid, depth 5, one sample.
        if args.res.is_none() {
            settings.width = 512;
            settings.height = 512;
        }
        settings.spd = true;
        settings.spp = 1;
        settings.max_depth = 5;
    }
    settings.bailout = args.bailout.unwrap_or(if args.spd {
        0.0
    } else {
        emray::render::DEFAULT_BAILOUT
    });
    if args.aa == cli::AaArg::Adaptive {
        settings.aa = emray::render::Aa::Adaptive {
            threshold: args.aa_threshold,
            depth: args.aa_depth,
        };
    }
    settings.skip = !args.no_skip;
    let backend = job.backend();
    let options = emray::accel::BackendOptions {
        backend,
        embree_quality: args.embree_quality.into(),
        embree_robust: args.embree_robust,
        packet_width: args.packet_width,
    };
    let (w, h) = (settings.width, settings.height);
    settings.region = match (args.tile, args.crop) {
        (Some((i, n)), _) => Some(emray::Region::band(i, n, w, h)),
        (None, Some(c)) if !c.fits(w, h) => bail!(
            "{name}: crop {},{},{},{} is not inside the {w}x{h} image",
            c.x0,
            c.x1,
            c.y0,
            c.y1
        ),
        (None, c) => c,
    };
    if settings.region.is_some_and(|r| r.height() == 0) {
        bail!("{name}: --tile leaves no rows for this part of a {h}-row image (use fewer tiles)");
    }
    let max_memory = args
        .max_memory
        .unwrap_or_else(emray::batch::limits::default_max_memory);
    emray::batch::limits::check(Path::new(&name), &scene, &settings, max_memory)
        .map_err(anyhow::Error::msg)?;

    let show_bar = !args.quiet && std::io::stderr().is_terminal();
    let bar = show_bar.then(|| {
        let b = indicatif::ProgressBar::new(0);
        b.set_style(
            indicatif::ProgressStyle::with_template(
                "{msg} [{bar:40}] {pos}/{len} tiles {elapsed_precise} eta {eta}",
            )
            .expect("static template")
            .progress_chars("=> "),
        );
        b.set_message(name.clone());
        b
    });
    let progress = |done: usize, total: usize| {
        if let Some(b) = &bar {
            b.set_length(total as u64);
            b.set_position(done as u64);
        }
    };
    settings.area_samples = (args.area_samples as f32).sqrt().floor().max(1.0) as u32;
    let (film, report) = if args.reference {
        let strata = (args.spp.unwrap_or(256) as f64).sqrt().floor() as u32;
        emray::run::render_reference(&name, &scene, &settings, strata, load_ms)
            .map_err(|why| anyhow::anyhow!("{name}: {why}"))?
    } else if let Some(cli::GiArg::Radiosity) = args.gi {
        let rad = args.radiosity.settings();
        emray::run::render_two_pass(
            &name,
            &scene,
            options,
            &settings,
            &rad,
            load_ms,
            Some(&progress),
        )?
    } else {
        emray::run::render_scene(&name, &scene, options, &settings, load_ms, Some(&progress))?
    };
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    match settings.region {
        Some(region) => {
            let info = emray::output::part::PartInfo {
                full: (w, h),
                region,
                hash: Some(emray::batch::merge::render_hash(&scene, &settings, backend)),
            };
            emray::output::part::write_exr(out, &film, Some(&info))?
        }
        None => emray::output::write_image(out, &film, args.encoding.into())?,
    }
    if args.stats {
        println!("{}\noutput     {}", report.summary(), out.display());
    } else if !args.quiet {
        log::info!("wrote {}", out.display());
    }
    if let Some(path) = &args.stats_json {
        append_json_line(path, &report)?;
    }
    Ok(())
}
