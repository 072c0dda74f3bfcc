//! The files a command will write, checked before any work goes into them: each can be
//! written (its folder made if missing), or the command fails at once naming it.

use super::Error;
use std::path::Path;

/// Check that every file of `files` can be written ([`emray::output::prepare`]).
pub fn prepare<'a>(files: impl IntoIterator<Item = &'a Path>) -> Result<(), Error> {
    for f in files {
        emray::output::prepare(f)?;
    }
    Ok(())
}
