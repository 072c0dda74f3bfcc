//! The texture maps of the materials: images read once each and set on the materials,
//! reflection maps made the scene's environment, and the warnings and stand-ins for
//! files that cannot be read.

use super::MISSING_TEXTURE;
use super::located::show;
use super::material::Materials;
use super::texmap::{CUBE_TYPES, MapKind, TexStmt};
use crate::scene::texture::{Image, Wrap};
use crate::scene::{Environment, Texture};
use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::Arc;

/// Images read so far: (file, sRGB, clamped) → texture index.
type Cache = HashMap<(PathBuf, bool, bool), u32>;

impl Materials {
    /// Load the texture maps of the materials (each image once) and set the materials'
    /// maps; a file that cannot be read is a warning and gets the documented default.
    pub fn load_maps(&mut self, maps: &[TexStmt], warnings: &mut Vec<String>) {
        let mut cache = Cache::new();
        let mut missing: Option<u32> = None;
        let mut cube: [Option<&TexStmt>; 6] = [None; 6];
        for m in maps {
            let Some(&i) = self.by_name.get(m.material.as_str()) else {
                continue;
            };
            if let Some(face) = m.cube {
                if let Some(slot) = cube.get_mut(face) {
                    slot.get_or_insert(m);
                }
                continue;
            }
            if m.kind == MapKind::Reflection {
                self.load_reflection(m, warnings);
                continue;
            }
            if let Some(t) = self.image_texture(m, &mut cache, &mut missing, warnings) {
                self.set_map(i, m, t);
            }
        }
        self.load_cube(&cube, warnings);
    }

    /// The environment from a single-image `refl`, unless one was loaded already.
    fn load_reflection(&mut self, m: &TexStmt, warnings: &mut Vec<String>) {
        if self.environment.is_some() {
            return;
        }
        match Environment::load(&m.file) {
            Ok(env) => self.environment = Some(env),
            Err(e) => warnings.push(format!(
                "{}: reflection map '{}' not used: {e}; the background stays",
                m.at, m.name
            )),
        }
    }

    /// The texture of map `m`: its image (read once), the missing-texture checkerboard
    /// for a colour map that cannot be read, or `None` for another map that cannot.
    fn image_texture(
        &mut self,
        m: &TexStmt,
        cache: &mut Cache,
        missing: &mut Option<u32>,
        warnings: &mut Vec<String>,
    ) -> Option<u32> {
        let srgb = matches!(m.kind, MapKind::Color | MapKind::Specular);
        let key = (m.file.clone(), srgb, m.clamp);
        if let Some(&t) = cache.get(&key) {
            return Some(t);
        }
        match Image::load(&m.file, srgb) {
            Ok(mut img) => {
                if m.clamp {
                    img.wrap = Wrap::Clamp;
                }
                let t = self.add_texture(Texture::Image(Arc::new(img)));
                cache.insert(key, t);
                Some(t)
            }
            Err(e) => {
                let what = if m.kind == MapKind::Color {
                    "the colour becomes a magenta and black checkerboard"
                } else {
                    "the map is left out"
                };
                warnings.push(format!(
                    "{}: texture '{}' of material {} not found or unreadable ({e}); {what}",
                    m.at,
                    m.name,
                    show(&m.material)
                ));
                (m.kind == MapKind::Color)
                    .then(|| *missing.get_or_insert_with(|| self.add_texture(MISSING_TEXTURE)))
            }
        }
    }

    fn add_texture(&mut self, t: Texture) -> u32 {
        self.textures.push(t);
        self.textures.len() as u32 - 1
    }

    /// Set texture `t` as map `m` of material `i`.
    fn set_map(&mut self, i: u32, m: &TexStmt, t: u32) {
        let Some(material) = self.list.get_mut(i as usize) else {
            return;
        };
        let maps = &mut material.maps;
        if m.scale != [1.0, 1.0] {
            maps.uv_scale = m.scale;
        }
        match m.kind {
            MapKind::Color => maps.color = t,
            MapKind::Specular => maps.specular = t,
            MapKind::Bump => {
                maps.bump = t;
                maps.bump_scale = m.bump_scale;
            }
            MapKind::Normal => maps.normal = t,
            MapKind::Reflection => {}
        }
    }

    /// The environment from the six `refl -type cube_*` faces, unless a single-image
    /// reflection map already gave one; a missing or unreadable face is a warning.
    fn load_cube(&mut self, cube: &[Option<&TexStmt>; 6], warnings: &mut Vec<String>) {
        let Some(first) = cube.iter().flatten().next() else {
            return;
        };
        if self.environment.is_some() {
            return;
        }
        let missing: Vec<&str> = cube
            .iter()
            .zip(CUBE_TYPES)
            .filter(|(m, _)| m.is_none())
            .map(|(_, t)| t)
            .collect();
        if !missing.is_empty() {
            warnings.push(format!(
                "{}: cube reflection map incomplete, missing {}; the background stays",
                first.at,
                missing.join(", ")
            ));
            return;
        }
        let files = cube.map(|m| m.map(|m| m.file.clone()).unwrap_or_default());
        match Environment::load_faces(&files) {
            Ok(env) => self.environment = Some(env),
            Err(e) => warnings.push(format!(
                "{}: cube reflection map not used: {e}; the background stays",
                first.at
            )),
        }
    }
}
