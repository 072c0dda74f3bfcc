//! `emray merge`: stitch the parts rendered with `render --band` or `--crop` into the
//! whole image, with the output variables they were rendered with (`--aov`).

use super::args::LogArgs;
use super::{Error, outputs};
use emray::batch::merge::{Merged, merge};
use emray::output::Encoding;
use std::path::PathBuf;

/// `emray merge`.
#[derive(clap::Args, Debug, Clone)]
pub struct Args {
    /// The parts (EXR files from `render --band` or `--crop`).
    #[arg(required = true, value_name = "PART.exr")]
    pub parts: Vec<PathBuf>,
    /// The whole image (.exr or .png).
    #[arg(short, long, value_name = "FULL")]
    pub output: PathBuf,
    /// PNG value encoding.
    #[arg(long, value_enum, default_value_t = Encoding::Srgb)]
    pub encoding: Encoding,
    /// `-q` and `-v`.
    #[command(flatten)]
    pub log: LogArgs,
}

/// Check that the parts make one image, and write it.
pub fn run(m: Args) -> Result<(), Error> {
    let files = Merged::files(&m.output)?;
    outputs::prepare(files.iter().map(PathBuf::as_path))?;
    merge(&m.parts)?.write(&m.output, m.encoding)?;
    Ok(())
}
