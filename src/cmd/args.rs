//! Argument types and parsers that several commands share: `-q` and `-v`, backends,
//! Embree build qualities, PNG encodings, image sizes, packet widths, and the radiosity
//! options of `emray radiosity` and `emray render --gi radiosity`.

use clap::{Args, ValueEnum};
use emray::accel::{Backend, EmbreeQuality};
use emray::output::Encoding;

/// Radiosity solvers as named on the command line.
#[derive(Clone, Copy, Debug, ValueEnum, PartialEq, Eq)]
pub enum SolverArg {
    /// Progressive refinement (shoot the most unshot energy first).
    Progressive,
    /// Gauss–Seidel on the full form-factor matrix (small meshes only).
    GaussSeidel,
}

/// Form-factor methods as named on the command line.
#[derive(Clone, Copy, Debug, ValueEnum, PartialEq, Eq)]
pub enum FormFactorArg {
    /// Exact point-to-polygon form factors with ray-cast visibility (either backend).
    Raycast,
    /// Hemicube (Cohen & Greenberg 1985): item buffers on the five faces.
    Hemicube,
}

/// `-q` and `-v`, which every command takes.
#[derive(Args, Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct LogArgs {
    /// No progress bars and no messages but errors.
    #[arg(short, long)]
    pub quiet: bool,
    /// More log output (repeat for more).
    #[arg(short, long, action = clap::ArgAction::Count)]
    pub verbose: u8,
}

/// The help heading of the radiosity options.
const RADIOSITY: &str = "Radiosity";

/// The radiosity options `emray radiosity` and `emray render --gi radiosity` share.
/// Each option sets its own heading: a heading set for the struct
/// (`next_help_heading`) would also head the options that follow it where it is
/// flattened.
#[derive(Args, Debug, Clone, PartialEq)]
pub struct RadiositySolveArgs {
    /// Longest element edge, in scene units [default: 1/12 of the scene's diagonal].
    #[arg(long, help_heading = RADIOSITY, value_name = "SIZE")]
    pub patch_size: Option<f32>,
    /// Form-factor sample points per shooting element: 1, 4, 16 or 64.
    #[arg(long, help_heading = RADIOSITY, default_value_t = 4, value_parser = parse_power_of_four)]
    pub ff_samples: u32,
    /// Visibility rays per pair of elements: 1, 4, 16 or 64.
    #[arg(long, help_heading = RADIOSITY, default_value_t = 1, value_parser = parse_power_of_four)]
    pub vis_samples: u32,
    /// Solver.
    #[arg(long, help_heading = RADIOSITY, value_enum, default_value_t = SolverArg::Progressive)]
    pub solver: SolverArg,
    /// Form-factor method.
    #[arg(long, help_heading = RADIOSITY, value_enum, default_value_t = FormFactorArg::Raycast)]
    pub form_factors: FormFactorArg,
    /// Hemicube resolution: pixels across the top face (even).
    #[arg(long, help_heading = RADIOSITY, default_value_t = 128, value_parser = clap::value_parser!(u32).range(2..=4096))]
    pub hemicube_res: u32,
    /// Adaptive subdivision: split elements whose radiosity differs from a neighbour's
    /// by more than this fraction of the largest reflected radiosity, then solve again.
    #[arg(long, help_heading = RADIOSITY, value_name = "FRACTION")]
    pub subdiv_threshold: Option<f32>,
    /// Smallest element edge adaptive subdivision makes [default: patch size / 8].
    #[arg(long, help_heading = RADIOSITY, value_name = "SIZE")]
    pub min_patch_size: Option<f32>,
    /// Most rounds of adaptive subdivision.
    #[arg(long, help_heading = RADIOSITY, default_value_t = 3)]
    pub subdiv_passes: u32,
    /// Stop when the unshot power is below this fraction of the emitted power.
    #[arg(long, help_heading = RADIOSITY, default_value_t = 1e-3)]
    pub epsilon: f64,
    /// Most shots (progressive) or sweeps (Gauss–Seidel).
    #[arg(long, help_heading = RADIOSITY, default_value_t = 1_000_000)]
    pub max_iterations: usize,
}

impl Default for RadiositySolveArgs {
    /// The same values as the options' defaults.
    fn default() -> Self {
        RadiositySolveArgs {
            patch_size: None,
            ff_samples: 1,
            vis_samples: 0,
            solver: SolverArg::Progressive,
            form_factors: FormFactorArg::Raycast,
            hemicube_res: 128,
            subdiv_threshold: None,
            min_patch_size: None,
            subdiv_passes: 3,
            epsilon: 1e-3,
            max_iterations: 1_000_000,
        }
    }
}

impl RadiositySolveArgs {
    /// The library settings.
    pub fn settings(&self) -> emray::radiosity::RadiositySettings {
        use emray::radiosity::{FormFactorMethod, RadiositySettings, SolverKind};
        RadiositySettings {
            patch_size: self.patch_size,
            shooter_level: self.ff_samples,
            visibility_level: self.vis_samples,
            epsilon: self.epsilon,
            max_iterations: self.max_iterations,
            solver: match self.solver {
                SolverArg::Progressive => SolverKind::Progressive,
                SolverArg::GaussSeidel => SolverKind::GaussSeidel,
            },
            form_factors: match self.form_factors {
                FormFactorArg::Raycast => FormFactorMethod::RayCast,
                FormFactorArg::Hemicube => FormFactorMethod::Hemicube(self.hemicube_res),
            },
            subdiv_threshold: self.subdiv_threshold,
            min_patch_size: self.min_patch_size,
            subdiv_passes: self.subdiv_passes,
        }
    }
}

/// The level `l` of a count `4^l` in 1..=64.
pub fn parse_power_of_four(s: &str) -> Result<u32, String> {
    match s.trim() {
        "1" => Ok(0),
        "4" => Ok(1),
        "16" => Ok(2),
        "64" => Ok(3),
        _ => Err(format!("'{s}' is not one of 1, 4, 16, 64")),
    }
}

/// The backends as named on the command line.
#[derive(Clone, Copy, Debug, ValueEnum, PartialEq, Eq)]
pub enum BackendArg {
    /// Intel Embree (default when built with the `embree` feature).
    Embree,
    /// The pure-Rust BVH.
    Bvh,
}

impl From<BackendArg> for Backend {
    fn from(b: BackendArg) -> Self {
        match b {
            BackendArg::Embree => Backend::Embree,
            BackendArg::Bvh => Backend::Bvh,
        }
    }
}

/// Embree build qualities as named on the command line.
#[derive(Clone, Copy, Debug, ValueEnum, PartialEq, Eq)]
pub enum QualityArg {
    /// Morton-code build: fastest to build.
    Low,
    /// Binned SAH (Embree's default).
    Medium,
    /// SAH with spatial splits: slowest to build, fastest to trace.
    High,
}

impl From<QualityArg> for EmbreeQuality {
    fn from(q: QualityArg) -> Self {
        match q {
            QualityArg::Low => EmbreeQuality::Low,
            QualityArg::Medium => EmbreeQuality::Medium,
            QualityArg::High => EmbreeQuality::High,
        }
    }
}

/// PNG value encodings.
#[derive(Clone, Copy, Debug, ValueEnum, PartialEq, Eq)]
pub enum EncodingArg {
    /// sRGB transfer curve (default).
    Srgb,
    /// Values written as they are.
    Linear,
}

impl From<EncodingArg> for Encoding {
    fn from(e: EncodingArg) -> Self {
        match e {
            EncodingArg::Srgb => Encoding::Srgb,
            EncodingArg::Linear => Encoding::Linear,
        }
    }
}

/// Largest accepted image side; larger sizes are refused before any allocation.
pub const MAX_SIDE: u32 = 65536;
/// Largest accepted pixel count (2^28, 268 megapixels).
pub const MAX_PIXELS: u64 = 1 << 28;

/// Parse `WxH` (`--res`).
pub fn parse_res(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("'{s}' is not WxH (e.g. 640x480)"))?;
    let w: u32 = w
        .trim()
        .parse()
        .map_err(|_| format!("bad width in '{s}'"))?;
    let h: u32 = h
        .trim()
        .parse()
        .map_err(|_| format!("bad height in '{s}'"))?;
    if w == 0 || h == 0 {
        return Err(format!("'{s}': width and height must be at least 1"));
    }
    if w > MAX_SIDE || h > MAX_SIDE || w as u64 * h as u64 > MAX_PIXELS {
        return Err(format!(
            "'{s}' is too large (at most {MAX_SIDE} per side and {MAX_PIXELS} pixels)"
        ));
    }
    Ok((w, h))
}

/// `--packet-width`: 0, 4, 8 or 16.
pub fn packet_width(s: &str) -> Result<u32, String> {
    match s.parse::<u32>() {
        Ok(n @ (0 | 4 | 8 | 16)) => Ok(n),
        _ => Err(format!("expected 0, 4, 8 or 16, got {s:?}")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cmd::{Cli, Command};
    use clap::Parser;

    #[test]
    fn res_parses_and_refuses() {
        assert_eq!(parse_res("640x480"), Ok((640, 480)));
        assert!(parse_res("0x10").is_err());
        assert!(parse_res("abc").is_err());
        assert!(parse_res("100000x10").is_err());
        assert!(parse_res("60000x60000").is_err());
    }

    fn radiosity_options(cmd: &[&str]) -> RadiositySolveArgs {
        match Cli::try_parse_from(cmd).unwrap().command {
            Some(Command::Radiosity(a)) => a.solve,
            Some(Command::Render(a)) => a.radiosity,
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn render_and_radiosity_share_the_radiosity_options() {
        let opts = [
            "--patch-size",
            "0.5",
            "--form-factors",
            "hemicube",
            "--hemicube-res",
            "64",
            "--subdiv-threshold",
            "0.1",
            "--min-patch-size",
            "0.05",
            "--subdiv-passes",
            "2",
            "--ff-samples",
            "16",
            "--epsilon",
            "1e-4",
        ];
        let rad = radiosity_options(&[&["emray", "radiosity", "s.toml"], &opts[..]].concat());
        let gi = ["emray", "render", "s.toml", "--gi", "radiosity"];
        let render = radiosity_options(&[&gi[..], &opts[..]].concat());
        assert_eq!(rad, render);
        let s = rad.settings();
        assert_eq!(
            s.form_factors,
            emray::radiosity::FormFactorMethod::Hemicube(64)
        );
        assert_eq!((s.subdiv_threshold, s.subdiv_passes), (Some(0.1), 2));
        assert_eq!((s.patch_size, s.shooter_level), (Some(0.5), 2));
        // Without options: the defaults, which are the library's.
        let none = radiosity_options(&["emray", "radiosity", "s.toml"]);
        assert_eq!(none, RadiositySolveArgs::default());
        assert_eq!(radiosity_options(&gi), none);
        assert_eq!(
            none.settings(),
            emray::radiosity::RadiositySettings::default()
        );
    }

    #[test]
    fn packet_width_is_one_of_the_embree_widths() {
        for n in [0, 4, 8, 16] {
            assert_eq!(packet_width(&n.to_string()), Ok(n));
        }
        for bad in ["3", "32", "-8", "eight"] {
            let e = packet_width(bad).unwrap_err();
            assert!(e.contains("0, 4, 8 or 16") && e.contains(bad), "{e}");
        }
    }
}
