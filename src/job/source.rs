//! Where a job's scene comes from: a scene file (NFF, TOML, OBJ), a generated
//! `spd:NAME[?size=N]` database, or the built-in default scene; loading it, with an
//! environment map in place of its own when the options ask for one.

use super::template::scene_stem;
use crate::load::{self, LoadError, LoadProgress};
use crate::scene::{Environment, Scene};
use crate::spd::Database;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// The built-in default scene (`emray` with no command renders it).
const DEFAULT_SCENE: &str = include_str!("../../scenes/default.nff");
/// The name of the built-in default scene in reports and messages.
const DEFAULT_NAME: &str = "default";
/// The `{stem}` of the built-in default scene's outputs.
const DEFAULT_STEM: &str = "emray";

/// Why a scene could not be had.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// An `spd:` spec that names no database or a size it cannot generate.
    #[error(transparent)]
    Spec(#[from] crate::spd::SpecError),
    /// The file could not be read or does not parse (`path:line:col: message`).
    #[error(transparent)]
    Load(#[from] LoadError),
    /// The environment map could not be read.
    #[error("{0}")]
    Environment(String),
}

/// A job's scene.
#[derive(Clone, Debug, PartialEq)]
pub enum SceneSource {
    /// A scene file, or a generated `spd:NAME[?size=N]` database.
    File(PathBuf),
    /// The built-in default scene.
    Builtin,
    /// A scene already loaded (or built by a program), with its name.
    Loaded {
        /// Its name in reports and messages, and the path of its `{stem}`.
        name: String,
        /// The scene.
        scene: Arc<Scene>,
    },
}

impl SceneSource {
    /// The name reports and messages give it: the path as given, or `default`.
    pub fn name(&self) -> String {
        match self {
            SceneSource::File(p) => p.display().to_string(),
            SceneSource::Builtin => DEFAULT_NAME.into(),
            SceneSource::Loaded { name, .. } => name.clone(),
        }
    }

    /// The path `{stem}` and the output's hash are made of.
    pub fn path(&self) -> &Path {
        match self {
            SceneSource::File(p) => p,
            SceneSource::Builtin => Path::new(DEFAULT_STEM),
            SceneSource::Loaded { name, .. } => Path::new(name),
        }
    }

    /// The `{stem}` of its outputs.
    pub fn stem(&self) -> String {
        scene_stem(self.path())
    }

    /// Refuse, before any work, an `spd:` spec that names no database.
    pub fn check(&self) -> Result<(), SceneError> {
        if let SceneSource::File(p) = self {
            Database::parse_spec(&p.to_string_lossy())?;
        }
        Ok(())
    }

    /// The generated database and size this source names (`spd:NAME[?size=N]`), if it
    /// names one.
    pub fn database(&self) -> Option<(Database, u32)> {
        match self {
            SceneSource::File(p) => Database::parse_spec(&p.to_string_lossy()).ok().flatten(),
            _ => None,
        }
    }

    /// Load the scene, with the environment map `envmap` in place of its own (a loaded
    /// scene is shared, not copied, unless its environment is replaced).
    pub fn load(&self, envmap: Option<&Path>) -> Result<Arc<Scene>, SceneError> {
        self.load_with(envmap, &LoadProgress::silent())
    }

    /// [`SceneSource::load`], telling `progress` how far the load of a scene file or
    /// generated database has come.
    pub fn load_with(
        &self,
        envmap: Option<&Path>,
        progress: &LoadProgress<'_>,
    ) -> Result<Arc<Scene>, SceneError> {
        let mut scene = match self {
            SceneSource::File(p) => Arc::new(load_scene_with(p, progress)?),
            SceneSource::Builtin => Arc::new(load::nff::parse_str(
                DEFAULT_SCENE,
                Path::new("<default scene>"),
            )?),
            SceneSource::Loaded { scene, .. } => Arc::clone(scene),
        };
        if let Some(env) = envmap {
            let env = Environment::load(env).map_err(|e| SceneError::Environment(e.to_string()))?;
            Arc::make_mut(&mut scene).environment = Some(env);
        }
        Ok(scene)
    }
}

/// Load a scene file or generate an `spd:NAME[?size=N]` scene; errors name the file
/// (and line and column where there is one).
pub fn load_scene(spec: impl AsRef<Path>) -> Result<Scene, SceneError> {
    load_scene_with(spec, &LoadProgress::silent())
}

/// [`load_scene`], telling `progress` how many bytes of the file are read, or how many
/// primitives of the database are made, and that all are once the scene is there.
pub fn load_scene_with(
    spec: impl AsRef<Path>,
    progress: &LoadProgress<'_>,
) -> Result<Scene, SceneError> {
    let spec = spec.as_ref();
    let scene = match Database::parse_spec(&spec.to_string_lossy())? {
        Some((db, size)) => super::spd_scene::scene(db, size, spec, progress)?,
        None => load::load_path_with(spec, progress)?,
    };
    progress.finish();
    Ok(scene)
}
