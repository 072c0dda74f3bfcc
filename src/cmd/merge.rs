//! `emray merge`: stitch the parts rendered with `render --tile` or `--crop` into the
//! whole image.

use super::Error;
use super::args::EncodingArg;
use emray::output::{self, Format};
use std::path::PathBuf;

/// `emray merge`.
#[derive(clap::Args, Debug, Clone)]
pub struct Args {
    /// The parts (EXR files from `render --tile` or `--crop`).
    #[arg(required = true, value_name = "PART.exr")]
    pub parts: Vec<PathBuf>,
    /// The whole image (.exr or .png).
    #[arg(short, long, value_name = "FULL")]
    pub output: PathBuf,
    /// PNG value encoding.
    #[arg(long, value_enum, default_value_t = EncodingArg::Srgb)]
    pub encoding: EncodingArg,
}

/// Check that the parts make one image, and write it.
pub fn run(m: Args) -> Result<(), Error> {
    Format::from_path(&m.output)?;
    let film = emray::batch::merge::merge(&m.parts)?;
    output::write_image(&m.output, &film, m.encoding.into())?;
    Ok(())
}
