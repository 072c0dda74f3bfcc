//! `emray compare`: error metrics of an image against a reference, for people (a
//! table) and scripts (JSON, and the exit status against thresholds). Needs the
//! `quality` feature (FLIP).

use super::Error;
use super::args::LogArgs;
#[cfg(feature = "quality")]
use super::error::print;
use emray::output::Encoding;
use std::path::PathBuf;

/// `emray compare`.
#[derive(clap::Args, Debug, Clone)]
pub struct Args {
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
    #[arg(long, value_enum, default_value_t = Encoding::Srgb)]
    pub encoding: Encoding,
    /// Print one JSON object instead of the table.
    #[arg(long)]
    pub json: bool,
    /// `-q` and `-v`.
    #[command(flatten)]
    pub log: LogArgs,
}

/// The table `emray compare` prints.
#[cfg(feature = "quality")]
fn table(m: &emray::accuracy::metrics::Metrics) -> String {
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

/// Compare the images; exceeding a threshold is [`Error::CheckFailed`], and an image
/// that cannot be read (or of another size) is a usage error.
#[cfg(feature = "quality")]
pub fn run(a: Args) -> Result<(), Error> {
    use emray::accuracy::metrics;
    use emray::output::Encoding;
    for (name, v) in [("--max-rmse", a.max_rmse), ("--max-flip", a.max_flip)] {
        if v.is_some_and(|v| v.is_nan() || v < 0.0) {
            return Err(Error::usage(format!("{name} must be a number ≥ 0")));
        }
    }
    if let Some(out) = &a.diff {
        emray::output::prepare(out).map_err(|e| Error::Usage(e.into()))?;
    }
    let usage = |e: metrics::MetricsError| Error::Usage(e.into());
    let enc = a.encoding;
    let test = metrics::read_image(&a.test, enc).map_err(usage)?;
    let reference = metrics::read_image(&a.reference, enc).map_err(usage)?;
    metrics::check_sizes(&test, &a.test, &reference, &a.reference).map_err(usage)?;
    let m = metrics::compare(&test, &reference);
    if a.json {
        let json = serde_json::to_string(&m).expect("metrics serialise");
        print(format_args!("{json}\n"))?;
    } else {
        print(format_args!("{}\n", table(&m)))?;
    }
    if let Some(out) = &a.diff {
        let heat = metrics::heat_map(&test, &reference);
        emray::output::write_image(out, &heat, Encoding::Srgb)
            .map_err(|e| Error::Usage(e.into()))?;
    }
    if within_thresholds(&a, &m) {
        Ok(())
    } else {
        Err(Error::CheckFailed)
    }
}

/// Whether `m` is within `--max-rmse` and `--max-flip`, saying which is not.
#[cfg(feature = "quality")]
fn within_thresholds(a: &Args, m: &emray::accuracy::metrics::Metrics) -> bool {
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
    pass
}

/// This build has no FLIP.
#[cfg(not(feature = "quality"))]
pub fn run(_: Args) -> Result<(), Error> {
    Err(super::error::lacks_feature("compare", "quality"))
}
