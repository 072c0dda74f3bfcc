//! The `emray` command.

mod cli;
mod quality_cmd;

use anyhow::{bail, Context, Result};
use clap::Parser;
use cli::{Cli, Command, RenderArgs};
use emray::accel::Backend;
use emray::gen::Database;
use emray::load;
use emray::render::RenderSettings;
use emray::scene::Environment;
use emray::Scene;
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
        Some(Command::Gen(g)) => return gen(&g),
        Some(Command::Bench(b)) => return bench(&b),
        Some(Command::Compare(c)) => return quality_cmd::compare(&c),
        Some(Command::Stress(s)) => return quality_cmd::stress(&s),
        Some(Command::Radiosity(r)) => return radiosity(&r),
        Some(Command::Study(s)) => return quality_cmd::study(&s),
        None => RenderArgs::default_scene(),
    };
    let level = match (args.quiet, args.verbose) {
        (true, _) => "error",
        (false, 0) => "warn",
        (false, 1) => "info",
        (false, 2) => "debug",
        _ => "trace",
    };
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or(level))
        .format_timestamp(None)
        .init();
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

/// `emray gen`: exit 2 on a bad database or size, 1 when the file cannot be written.
fn gen(g: &cli::GenArgs) -> ExitCode {
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
    use emray::radiosity::{RadiositySettings, SolverKind};
    emray::output::Format::from_path(&a.output)?;
    let mut builder = rayon::ThreadPoolBuilder::new();
    if let Some(t) = a.threads {
        builder = builder.num_threads(t as usize);
    }
    let pool = builder.build().context("cannot start the worker threads")?;
    let scene = load::load_path(&a.scene)?;
    let settings = RadiositySettings {
        patch_size: a.patch_size,
        shooter_level: a.ff_samples,
        visibility_level: a.vis_samples,
        epsilon: a.epsilon,
        max_iterations: a.max_iterations,
        solver: match a.solver {
            cli::SolverArg::Progressive => SolverKind::Progressive,
            cli::SolverArg::GaussSeidel => SolverKind::GaussSeidel,
        },
    };
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
        let line = serde_json::to_string(&report).expect("report serialises");
        let mut f = std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(path)
            .with_context(|| format!("{}: cannot open for writing", path.display()))?;
        writeln!(f, "{line}").with_context(|| format!("{}: cannot write", path.display()))?;
    }
    Ok(())
}

/// The file-name stem of a scene: the file's, or `NAME_sN` for a generated one.
fn scene_stem(scene: &Path) -> String {
    if let Ok(Some((db, size))) = Database::parse_spec(&scene.to_string_lossy()) {
        return format!("{}_s{size}", db.name());
    }
    scene
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "emray".into())
}

/// Where scene `scene` goes.
fn output_for(args: &RenderArgs, scene: &Path) -> PathBuf {
    let stem = scene_stem(scene);
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
        Some(p) => {
            let name = p.display().to_string();
            match Database::parse_spec(&name).map_err(anyhow::Error::msg)? {
                Some((db, size)) => {
                    let text = db.generate(size);
                    (name.clone(), load::nff::parse_str(&text, p)?)
                }
                None => (name, load::load_path(p)?),
            }
        }
        None => (
            "default".into(),
            load::nff::parse_str(DEFAULT_SCENE, Path::new("<default scene>"))?,
        ),
    };
    if let Some(env) = &args.envmap {
        scene.environment = Some(Environment::load(env).map_err(anyhow::Error::msg)?);
    }
    let load_ms = t0.elapsed().as_secs_f64() * 1e3;
    let mut settings = RenderSettings::for_scene(&scene);
    if let Some((w, h)) = args.res {
        settings.width = w;
        settings.height = h;
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
    settings.embree_quality = args.embree_quality.into();
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
    let backend: Backend = args
        .backend
        .map(Backend::from)
        .unwrap_or_else(Backend::default_available);

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
        let rad = emray::radiosity::RadiositySettings {
            patch_size: args.patch_size,
            ..Default::default()
        };
        emray::run::render_two_pass(
            &name,
            &scene,
            backend,
            &settings,
            &rad,
            load_ms,
            Some(&progress),
        )?
    } else {
        emray::run::render_scene(&name, &scene, backend, &settings, load_ms, Some(&progress))?
    };
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    emray::output::write_image(out, &film, args.encoding.into())?;
    if args.stats {
        println!("{}\noutput     {}", report.summary(), out.display());
    } else if !args.quiet {
        log::info!("wrote {}", out.display());
    }
    if let Some(path) = &args.stats_json {
        let line = serde_json::to_string(&report).expect("report serialises");
        let mut f = std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(path)
            .with_context(|| format!("{}: cannot open for writing", path.display()))?;
        writeln!(f, "{line}").with_context(|| format!("{}: cannot write", path.display()))?;
    }
    Ok(())
}
