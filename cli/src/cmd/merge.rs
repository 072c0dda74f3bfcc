//! `emray merge`: stitch the parts rendered with `render --tile` or `--crop` into the
//! whole image, with the output variables they were rendered with (`--aov`).

use super::args::LogArgs;
use super::{Error, outputs};
use emray::output::Encoding;
use emray::output::aov::{ids_path, write_ids};
use emray::output::channels::write_exr_channels;
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
    #[arg(long, value_enum, default_value_t = Encoding::Srgb)]
    pub encoding: Encoding,
    /// `-q` and `-v`.
    #[command(flatten)]
    pub log: LogArgs,
}

/// Check that the parts make one image, and write it: every channel of the parts to
/// an EXR (with the `.ids.json` of an `id` channel), the colour alone to a PNG.
pub fn run(m: Args) -> Result<(), Error> {
    let format = Format::from_path(&m.output)?;
    // The ids file of parts with an `id` channel goes beside an EXR.
    let ids = (format == Format::Exr).then(|| ids_path(&m.output));
    outputs::prepare([m.output.as_path()].into_iter().chain(ids.as_deref()))?;
    let merged = emray::batch::merge::merge(&m.parts)?;
    if merged.channels.is_empty() || format == Format::Png {
        if !merged.channels.is_empty() {
            log::warn!(
                "{}: a PNG holds the colour alone; the parts' other channels are left out",
                m.output.display()
            );
        }
        output::write_image(&m.output, &merged.film, m.encoding)?;
        return Ok(());
    }
    write_exr_channels(&m.output, &merged.film, &merged.channels, None)?;
    if let Some(ids) = &merged.ids {
        write_ids(&m.output, ids)?;
    }
    Ok(())
}
