//! NFF loader (placeholder until the full parser lands).
use super::LoadError;
use std::path::Path;

/// Load an NFF file.
pub fn load(path: &Path) -> Result<crate::Scene, LoadError> {
    Err(LoadError {
        path: path.to_path_buf(),
        line: 0,
        col: 0,
        message: "NFF parser not yet built".into(),
    })
}
