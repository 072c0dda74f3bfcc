//! `emray compare`: error metrics between two images, for people and for scripts.

use clap::Args;
use emray::metrics::{self, Metrics};
use emray::output::Encoding;
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
