//! `emray explain`: one pixel's whole ray tree, traced by the renderer's own code with
//! the camera, samples and settings of `emray render`, as indented text or as JSON
//! (docs/explain.md).

use super::Error;
use super::args::{BackendArg, LogArgs, QualityArg, RadiositySolveArgs, packet_width, parse_res};
use super::error::print;
use super::render::GiArg;
use anyhow::anyhow;
use emray::accel::{Backend, BackendOptions};
use emray::job::{self, ExplainRunError, RenderRequest};
use emray::render::explain::{ExplainError, Explanation, text};
use emray::scene::Environment;
use serde::Serialize;
use std::path::PathBuf;

/// `emray explain`.
#[derive(clap::Args, Debug, Clone)]
pub struct Args {
    /// Scene file: NFF, TOML (`.toml`), OBJ (`.obj`), or `spd:NAME[?size=N]`.
    #[arg(value_name = "SCENE")]
    pub scene: PathBuf,
    /// Pixel column, from 0 at the left.
    #[arg(value_name = "X")]
    pub x: u32,
    /// Pixel row, from 0 at the top.
    #[arg(value_name = "Y")]
    pub y: u32,
    /// Print the tree as JSON (schema in docs/explain.md).
    #[arg(long)]
    pub json: bool,
    /// Ray-query backend.
    #[arg(long, value_enum)]
    pub backend: Option<BackendArg>,
    /// Image size, overriding the scene's resolution.
    #[arg(long, value_name = "WxH", value_parser = parse_res)]
    pub res: Option<(u32, u32)>,
    /// Samples per pixel [default: the scene file's `[render] spp`, else 1].
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=65536))]
    pub spp: Option<u32>,
    /// Maximum ray-tree depth, the eye ray being depth 1 [default: the scene file's
    /// `[render] max_depth`, else 5].
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=64))]
    pub max_depth: Option<u32>,
    /// SPD testing mode: the pixel is the mean of its four corner rays.
    #[arg(long)]
    pub spd: bool,
    /// No reflected/refracted ray whose accumulated weight is below W [default: 0.001,
    /// 0 with --spd].
    #[arg(long, value_name = "W")]
    pub bailout: Option<f32>,
    /// Cast the rays that cannot change the image too.
    #[arg(long)]
    pub no_skip: bool,
    /// Shadow rays per emitting triangle (area light), a square number.
    #[arg(long, default_value_t = 16, value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub area_samples: u32,
    /// Environment map for rays that leave the scene, replacing the scene's own.
    #[arg(long, value_name = "FILE|DIR")]
    pub envmap: Option<PathBuf>,
    /// Global illumination: `radiosity` for the two-pass mode of `emray render`.
    #[arg(long, value_enum)]
    pub gi: Option<GiArg>,
    /// The radiosity pass of `--gi radiosity`.
    #[command(flatten)]
    pub radiosity: RadiositySolveArgs,
    /// Embree build quality.
    #[arg(long, value_enum, default_value_t = QualityArg::Medium)]
    pub embree_quality: QualityArg,
    /// Embree's fast (not robust) traversal, as `emray render --embree-fast`.
    #[arg(long)]
    pub embree_fast: bool,
    /// Eye rays per Embree packet, as `emray render --packet-width`.
    #[arg(long, value_name = "N", default_value_t = 8, value_parser = packet_width)]
    pub packet_width: u32,
    /// `-q` and `-v`.
    #[command(flatten)]
    pub log: LogArgs,
}

/// The JSON `--json` prints: the explanation with the scene and backend it is of.
#[derive(Serialize)]
struct Output<'a> {
    scene: String,
    backend: &'static str,
    #[serde(flatten)]
    explanation: &'a Explanation,
}

/// Explain the pixel and print the tree.
pub fn run(a: Args) -> Result<(), Error> {
    if let Some(b) = a.bailout {
        if !b.is_finite() || b < 0.0 {
            return Err(Error::usage(format!(
                "--bailout must be a finite number >= 0, not {b}"
            )));
        }
    }
    let name = a.scene.display().to_string();
    let mut scene = job::load_scene(&a.scene)?;
    if let Some(env) = &a.envmap {
        scene.environment = Some(Environment::load(env).map_err(Error::failed)?);
    }
    let request = RenderRequest {
        res: a.res,
        spp: a.spp,
        max_depth: a.max_depth,
        spd: a.spd,
        bailout: a.bailout,
        cast_skippable: a.no_skip,
        area_samples: Some(a.area_samples),
        ..RenderRequest::default()
    };
    let settings = request
        .settings(&scene)
        .map_err(|e| Error::Usage(anyhow!("{name}: {e}")))?;
    let backend = a
        .backend
        .map(Backend::from)
        .unwrap_or_else(Backend::default_available);
    let options = BackendOptions {
        backend,
        embree_quality: a.embree_quality.into(),
        embree_robust: !a.embree_fast,
        packet_width: a.packet_width,
    };
    let radiosity = a.gi.map(|GiArg::Radiosity| a.radiosity.settings());
    let explanation = job::explain_pixel(&scene, options, &settings, radiosity.as_ref(), a.x, a.y)
        .map_err(|e| match e {
            ExplainRunError::Explain(e @ ExplainError::Outside { .. }) => {
                Error::Usage(anyhow!("{name}: {e}"))
            }
            e => Error::Failed(anyhow!("{name}: {e}")),
        })?;
    if a.json {
        let out = Output {
            scene: name,
            backend: backend.name(),
            explanation: &explanation,
        };
        let json = serde_json::to_string_pretty(&out).expect("an explanation serialises");
        print(format_args!("{json}\n"))?;
    } else {
        print(format_args!(
            "scene {name}, backend {}\n{}",
            backend.name(),
            text::format(&explanation)
        ))?;
    }
    Ok(())
}
