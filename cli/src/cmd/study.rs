//! `emray study`: error against time for every speed/accuracy knob, against the f64
//! reference, to CSV, SVG and PNG. Needs the `quality` feature (FLIP, plots).

use super::Error;
use super::args::LogArgs;
#[cfg(feature = "quality")]
use super::error::print;
use emray::job::Res;
use std::path::PathBuf;

/// `emray study`.
#[derive(clap::Args, Debug, Clone)]
pub struct Args {
    /// Scene file or `spd:NAME[?size=N]` (spheres, cones and triangles only: the f64
    /// reference refuses the rest).
    #[arg(value_name = "SCENE")]
    pub scene: PathBuf,
    /// Output directory for study.csv, study.svg and study.png.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Image size of every run.
    #[arg(long, value_name = "WxH", default_value = "128x128")]
    pub res: Res,
    /// Reference samples per pixel side (N×N).
    #[arg(long, default_value_t = 16, value_parser = clap::value_parser!(u32).range(1..=64))]
    pub reference_strata: u32,
    /// `-q` and `-v`.
    #[command(flatten)]
    pub log: LogArgs,
}

/// Run the study and print its CSV; a bad `spd:` spec is a usage error.
#[cfg(feature = "quality")]
pub fn run(a: Args) -> Result<(), Error> {
    use emray::job::{SceneError, load_scene};
    let files = emray::accuracy::study::FILES.map(|f| a.out.join(f));
    super::outputs::prepare(files.iter().map(PathBuf::as_path))?;
    let name = a.scene.display().to_string();
    let scene = match load_scene(&a.scene) {
        Err(SceneError::Spec(e)) => return Err(Error::usage(e)),
        Err(e) => return Err(Error::failed(format!("{name}: {e}"))),
        Ok(s) => s,
    };
    let mut backends = vec![emray::Backend::Bvh];
    if cfg!(feature = "embree") {
        backends.push(emray::Backend::Embree);
    }
    let (w, h) = (a.res.width, a.res.height);
    let rows =
        emray::accuracy::study::write(&scene, &name, &a.out, w, h, a.reference_strata, &backends)
            .map_err(|e| Error::failed(format!("{name}: {e}")))?;
    print(format_args!("{}", emray::accuracy::study::csv(&rows)))?;
    Ok(())
}

/// This build has no FLIP and no plots.
#[cfg(not(feature = "quality"))]
pub fn run(_: Args) -> Result<(), Error> {
    Err(super::error::lacks_feature("study", "quality"))
}
