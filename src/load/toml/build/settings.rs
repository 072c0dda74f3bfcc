//! `[render]`: the background and ambient light, the environment map, and the
//! renderer's settings (`max_depth`, `spp`).

use super::super::SceneSettings;
use super::super::format::Spanned;
use super::{Builder, R};
use crate::math::Vec3;
use crate::scene::Environment;

/// Largest accepted `max_depth`.
const MAX_RAY_DEPTH: u32 = 64;
/// Largest accepted `spp`.
const MAX_SPP: u32 = 65_536;
/// Ambient light when `[render]` gives none.
const DEFAULT_AMBIENT: f32 = 0.1;

impl Builder<'_, '_> {
    /// The background, the ambient light and the renderer's settings; the environment
    /// map, if any, is read into the builder.
    pub(super) fn render(&mut self) -> R<(Vec3, Vec3, SceneSettings)> {
        let mut background = Vec3::ZERO;
        let mut ambient = Vec3::splat(DEFAULT_AMBIENT);
        let mut settings = SceneSettings::default();
        if let Some(r) = &self.file.render {
            let r = r.get_ref();
            if let Some(b) = &r.background {
                background = self.colour(b, "`background`")?;
            }
            if let Some(e) = &r.environment {
                self.environment = Some(self.environment_map(e)?);
            }
            if let Some(a) = &r.ambient {
                ambient = self.colour(a, "`ambient`")?;
            }
            if let Some(d) = &r.max_depth {
                settings.max_depth = Some(self.count_up_to(d, "max_depth", MAX_RAY_DEPTH)?);
            }
            if let Some(s) = &r.spp {
                settings.spp = Some(self.count_up_to(s, "spp", MAX_SPP)?);
            }
        }
        Ok((background, ambient, settings))
    }

    /// `environment`: an image file, relative to the scene file.
    fn environment_map(&self, file: &Spanned<String>) -> R<Environment> {
        let path = self.relative_path(file.get_ref());
        Environment::load(&path).map_err(|m| self.err(file.span(), m.to_string()))
    }

    /// The value of key `key`, which must be between 1 and `max`.
    fn count_up_to(&self, v: &Spanned<u32>, key: &str, max: u32) -> R<u32> {
        let n = *v.get_ref();
        if !(1..=max).contains(&n) {
            return Err(self.err(
                v.span(),
                format!("`{key}` must be between 1 and {max}, found {n}"),
            ));
        }
        Ok(n)
    }
}
