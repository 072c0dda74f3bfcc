//! Scene loaders. They build a [`crate::scene::Scene`] and never render.

pub mod nff;
pub mod obj;
pub mod progress;
mod read;
pub(crate) mod text;
pub mod toml;

pub use progress::LoadProgress;
use std::fmt;
use std::path::{Path, PathBuf};

/// A load failure, displayed as `path:line:col: message` (or `path: message` when it
/// concerns the whole file).
#[derive(Debug, Clone, PartialEq)]
pub struct LoadError {
    /// The file (or a label such as `<string>`).
    pub path: PathBuf,
    /// 1-based line, 0 when not applicable.
    pub line: usize,
    /// 1-based column, 0 when not applicable.
    pub col: usize,
    /// What is wrong.
    pub message: String,
}

impl fmt::Display for LoadError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.line == 0 {
            write!(f, "{}: {}", self.path.display(), self.message)
        } else {
            write!(
                f,
                "{}:{}:{}: {}",
                self.path.display(),
                self.line,
                self.col,
                self.message
            )
        }
    }
}

impl std::error::Error for LoadError {}

/// Warn when `scene`, read from the file at `path`, has no object at all: it renders,
/// but its image is the background alone, which is seldom what was meant.
pub(crate) fn warn_if_empty(scene: &crate::scene::Scene, path: &Path) {
    if scene.prim_count_with_instances() == 0 {
        log::warn!(
            "{}: scene has no objects: the image will be the background only",
            path.display()
        );
    }
}

/// Load a scene file, choosing the format by extension (any case): `.toml` is the
/// scene format ([`toml`]), `.obj` a Wavefront OBJ model framed by an automatic camera
/// and light ([`obj::load`]); anything else is read as NFF (`.nff`, and the classic
/// benchmark files have no fixed extension).
pub fn load_path(path: &Path) -> Result<crate::scene::Scene, LoadError> {
    load_path_with(path, &LoadProgress::silent())
}

/// [`load_path`], telling `progress` how many bytes of an NFF or OBJ file are read,
/// and that all are once the scene is loaded (a TOML scene tells nothing).
pub fn load_path_with(
    path: &Path,
    progress: &LoadProgress<'_>,
) -> Result<crate::scene::Scene, LoadError> {
    let ext = |e: &str| path.extension().is_some_and(|x| x.eq_ignore_ascii_case(e));
    let scene = if ext("toml") {
        self::toml::load(path)
    } else if ext("obj") {
        obj::load_with(path, progress)
    } else {
        nff::load_with(path, progress)
    }?;
    progress.finish();
    Ok(scene)
}
