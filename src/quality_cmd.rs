//! `emray compare`: error metrics between two images, for people and for scripts;
//! `emray stress`: the numerical stress cases with their measured numbers.

use clap::Args;
#[cfg(feature = "quality")]
use emray::output::Encoding;
#[cfg(feature = "quality")]
use emray::quality::metrics::{self, Metrics};
use std::path::PathBuf;
use std::process::ExitCode;

/// `emray compare`.
#[derive(Args, Debug, Clone)]
pub struct CompareArgs {
    /// The image under test (.png or .exr).
    #[arg(value_name = "TEST")]
    pub test: PathBuf,
    /// The reference image (.png or .exr), same size.
    #[arg(value_name = "REFERENCE")]
    pub reference: PathBuf,
    /// Write a heat map of the per-pixel FLIP error (magma colours) to this PNG/EXR.
    #[arg(long, value_name = "OUT")]
    pub diff: Option<PathBuf>,
    /// Exit with status 1 if the RMSE exceeds X.
    #[arg(long, value_name = "X")]
    pub max_rmse: Option<f64>,
    /// Exit with status 1 if the mean FLIP error exceeds Y.
    #[arg(long, value_name = "Y")]
    pub max_flip: Option<f64>,
    /// How PNG values are decoded to linear (EXR is linear already).
    #[arg(long, value_enum, default_value_t = crate::cli::EncodingArg::Srgb)]
    pub encoding: crate::cli::EncodingArg,
    /// Print one JSON object instead of the table.
    #[arg(long)]
    pub json: bool,
}

/// The table `emray compare` prints.
#[cfg(feature = "quality")]
pub fn table(m: &Metrics) -> String {
    format!(
        "rmse       {:.6e}\n\
         psnr       {:.3} dB\n\
         rel_mse    {:.6e}\n\
         max_abs    {:.6e}\n\
         diff_8bit  {:.4}% of pixels\n\
         flip       {:.6} (LDR, 8-bit sRGB)",
        m.rmse,
        m.psnr,
        m.rel_mse,
        m.max_abs,
        m.diff_8bit * 100.0,
        m.flip
    )
}

/// Exit status: 0 within the thresholds, 1 a threshold exceeded, 2 a usage or I/O error.
#[cfg(not(feature = "quality"))]
pub fn compare(_: &CompareArgs) -> ExitCode {
    lacking("compare")
}

/// Exit status: 0 within the thresholds, 1 a threshold exceeded, 2 a usage or I/O error.
#[cfg(feature = "quality")]
pub fn compare(a: &CompareArgs) -> ExitCode {
    let run = || -> Result<bool, String> {
        for (name, v) in [("--max-rmse", a.max_rmse), ("--max-flip", a.max_flip)] {
            if v.is_some_and(|v| v.is_nan() || v < 0.0) {
                return Err(format!("{name} must be a number ≥ 0"));
            }
        }
        let enc: Encoding = a.encoding.into();
        let test = metrics::read_image(&a.test, enc).map_err(|e| e.to_string())?;
        let reference = metrics::read_image(&a.reference, enc).map_err(|e| e.to_string())?;
        metrics::check_sizes(&test, &a.test, &reference, &a.reference)
            .map_err(|e| e.to_string())?;
        let m = metrics::compare(&test, &reference);
        if a.json {
            println!("{}", serde_json::to_string(&m).expect("metrics serialise"));
        } else {
            println!("{}", table(&m));
        }
        if let Some(out) = &a.diff {
            let heat = metrics::heat_map(&test, &reference);
            emray::output::write_image(out, &heat, Encoding::Srgb).map_err(|e| e.to_string())?;
        }
        let mut pass = true;
        if let Some(x) = a.max_rmse {
            if m.rmse.is_nan() || m.rmse > x {
                eprintln!("emray: rmse {:.6e} exceeds --max-rmse {x}", m.rmse);
                pass = false;
            }
        }
        if let Some(y) = a.max_flip {
            if m.flip.is_nan() || m.flip > y {
                eprintln!("emray: flip {:.6} exceeds --max-flip {y}", m.flip);
                pass = false;
            }
        }
        Ok(pass)
    };
    match run() {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::from(1),
        Err(e) => {
            eprintln!("emray: error: {e}");
            ExitCode::from(2)
        }
    }
}

/// `emray stress`.
#[derive(Args, Debug, Clone)]
pub struct StressArgs {
    /// Random rays per far/tiny sphere case.
    #[arg(long, default_value_t = 1_000_000)]
    pub rays: u32,
}

/// Run every stress case at full counts and print what was measured; exit 1 if a
/// bound of `tests/stability.rs` is broken.
pub fn stress(a: &StressArgs) -> ExitCode {
    use emray::Backend;
    use emray::accel::bvh::Bvh;
    use emray::quality::stress::*;
    let mut ok = true;
    let mut check = |cond: bool, what: String| {
        println!("{} {what}", if cond { "ok  " } else { "FAIL" });
        ok &= cond;
    };
    let mut backends = vec![Backend::Bvh];
    if cfg!(feature = "embree") {
        backends.push(Backend::Embree);
    }
    for &b in &backends {
        let want = render(&floor_scene(1.0, 256), b);
        for e in -4..=4 {
            if e == 0 {
                continue;
            }
            let share = differing_share(&render(&floor_scene(10f64.powi(e), 256), b), &want);
            check(
                share <= 1e-3,
                format!(
                    "scale 1e{e} ({b:?}, 256x256): {:.4}% pixels differ (bound 0.1%)",
                    share * 100.0
                ),
            );
        }
    }
    for e in -4..=4 {
        let c = convex_scene(10f64.powi(e), 0.0, 256);
        let (lit, bad) = acne(&c, &Bvh::build(&c));
        check(
            bad == 0,
            format!("scale 1e{e}: acne {bad} of {lit} lit points"),
        );
    }
    let base = render(&convex_scene(1.0, 0.0, 256), Backend::Bvh);
    for e in 3..=6 {
        let s = convex_scene(1.0, 10f64.powi(e), 256);
        let (lit, bad) = acne(&s, &Bvh::build(&s));
        let share = differing_share(&render(&s, Backend::Bvh), &base);
        check(
            e > 5 || bad == 0,
            format!(
                "offset 1e{e}: acne {bad} of {lit} lit points, {:.3}% pixels differ",
                share * 100.0
            ),
        );
    }
    for (dist, radius) in [(1e4f32, 1.0f32), (1e2, 1e-4), (1e6, 1e3), (1e5, 1e-2)] {
        let (worst, miss, extra) = far_sphere(dist, radius, a.rays, 7);
        check(
            worst < 1e-5,
            format!(
                "sphere r={radius:e} at {dist:e}: worst relative t error {worst:.3e} over {} rays; \
                 silhouette: {miss} f32 misses, {extra} f32 extra hits",
                a.rays
            ),
        );
    }
    for (name, case) in quadric_root_cases() {
        let st = case(a.rays);
        check(
            st.nan == 0 && st.disagree == 0 && st.worst_dist < ROOT_DIST_BOUND,
            format!(
                "{name}: {} rays ({} hit in f64): {} NaN, {} hit/miss disagreements \
                 outside the band ({} rays in it), worst |dt|/max(t,1) {:.3e}, \
                 worst f32 hit point distance from the surface {:.3e}",
                st.rays, st.hits, st.nan, st.disagree, st.in_band, st.worst_t, st.worst_dist
            ),
        );
    }
    for (name, case, n) in watertight_cases() {
        let touching = |st: &WatertightStats| {
            format!(
                "{} misses of {} rays (and {} of {} rays that may only touch an apex or ridge)",
                st.misses, st.rays, st.touching_misses, st.touching
            )
        };
        let st = case.run(&Bvh::build(&case.scene), n, 3.0);
        check(
            st.misses == 0,
            format!("watertight ({name}, bvh): {}", touching(&st)),
        );
        #[cfg(feature = "embree")]
        for robust in [false, true] {
            let flag = if robust { "robust" } else { "default flags" };
            match emray::accel::embree::EmbreeAccel::build_with(
                &case.scene,
                "",
                Default::default(),
                robust,
            ) {
                Ok(e) => {
                    let st = case.run(&e, n, 3.0);
                    println!("info watertight ({name}, embree {flag}): {}", touching(&st));
                }
                Err(e) => println!("info embree unavailable: {e}"),
            }
        }
    }
    if ok {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    }
}

/// `emray study`.
#[derive(Args, Debug, Clone)]
pub struct StudyArgs {
    /// Scene file or `spd:NAME[?size=N]` (spheres, cones and triangles only: the f64
    /// reference refuses the rest).
    #[arg(value_name = "SCENE")]
    pub scene: PathBuf,
    /// Output directory for study.csv, study.svg and study.png.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Image size of every run.
    #[arg(long, value_name = "WxH", default_value = "128x128", value_parser = crate::cli::parse_res)]
    pub res: (u32, u32),
    /// Reference samples per pixel side (N×N).
    #[arg(long, default_value_t = 16, value_parser = clap::value_parser!(u32).range(1..=64))]
    pub reference_strata: u32,
}

/// Exit status: 0 done, 1 a scene or render error, 2 a usage error.
#[cfg(not(feature = "quality"))]
pub fn study(_: &StudyArgs) -> ExitCode {
    lacking("study")
}

/// Exit status: 0 done, 1 a scene or render error, 2 a usage error.
#[cfg(feature = "quality")]
pub fn study(a: &StudyArgs) -> ExitCode {
    let name = a.scene.display().to_string();
    let scene = match emray::spd::Database::parse_spec(&name) {
        Err(e) => {
            eprintln!("emray: error: {e}");
            return ExitCode::from(2);
        }
        Ok(Some((db, size))) => {
            emray::load::nff::parse_str(&db.generate(size), &a.scene).map_err(|e| e.to_string())
        }
        Ok(None) => emray::load::load_path(&a.scene).map_err(|e| e.to_string()),
    };
    let mut backends = vec![emray::Backend::Bvh];
    if cfg!(feature = "embree") {
        backends.push(emray::Backend::Embree);
    }
    let (w, h) = a.res;
    let result = scene.and_then(|s| {
        emray::quality::study::write(&s, &name, &a.out, w, h, a.reference_strata, &backends)
    });
    match result {
        Ok(rows) => {
            print!("{}", emray::quality::study::csv(&rows));
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("emray: error: {name}: {e}");
            ExitCode::from(1)
        }
    }
}

/// A build without the `quality` feature has no FLIP and no plots.
#[cfg(not(feature = "quality"))]
fn lacking(command: &str) -> ExitCode {
    eprintln!(
        "emray: error: this emray was built without the `quality` feature, which `{command}` \
         needs (build with the default features or `--features quality`)"
    );
    ExitCode::from(2)
}
