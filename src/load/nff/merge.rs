//! Joining the [`Part`]s of a file, in file order, into its [`Scene`]: materials and
//! lights are numbered on, the material in effect carries from one part to the next,
//! the warnings are logged in order, and the last viewpoint and background win.

use super::LOG_TARGET;
use super::part::{INHERITED, Note, Part};
use crate::load::LoadError;
use crate::math::{DVec3, Vec3};
use crate::scene::{Camera, Material, Scene, default_light_intensity, range};
use std::path::Path;

/// Stands in until the `v` is read (the scene is built while parsing, and `v` may come
/// anywhere in the file).
const PLACEHOLDER_CAMERA: Camera = Camera {
    from: Vec3::ZERO,
    at: Vec3::NEG_Z,
    up: Vec3::Y,
    angle_deg: 45.0,
    hither: 0.0,
    width: 1,
    height: 1,
};

/// The scene of the parts joined so far.
pub(crate) struct Merger<'p> {
    path: &'p Path,
    origin: DVec3,
    scene: Scene,
    camera: Option<Camera>,
    /// Whether each light had its own colour.
    light_has_color: Vec<bool>,
    /// The material in effect after the last part.
    current: Option<u32>,
    /// Line and column of the first degenerate polygon.
    first_degenerate: Option<(usize, usize)>,
}

impl<'p> Merger<'p> {
    /// No parts yet, of the file `path` read in the frame whose origin is `origin`.
    pub fn new(path: &'p Path, origin: DVec3) -> Self {
        Merger {
            path,
            origin,
            scene: Scene::new(PLACEHOLDER_CAMERA),
            camera: None,
            light_has_color: Vec::new(),
            current: None,
            first_degenerate: None,
        }
    }

    /// Join the next part.
    pub fn add(&mut self, part: Part) {
        self.notes(&part.notes);
        let inherited = part.inherits.then(|| self.current_material());
        let base = self.scene.materials.len() as u32;
        for (k, (material, line)) in part.materials.iter().enumerate() {
            let index = base as usize + k;
            self.scene
                .sources
                .materials
                .add(index, 1, &part.file, *line);
            self.scene.materials.push(*material);
        }
        if !part.materials.is_empty() {
            self.current = Some(base + part.materials.len() as u32 - 1);
        }
        let first_light = self.scene.lights.len();
        for (k, (light, has_color, line)) in part.lights.iter().enumerate() {
            let sources = &mut self.scene.sources.lights;
            sources.add(first_light + k, 1, &part.file, *line);
            self.scene.lights.push(*light);
            self.light_has_color.push(*has_color);
        }
        if let Some(b) = part.background {
            self.scene.background = b;
        }
        let stats = &mut self.scene.load_stats;
        stats.polygons += part.polygons;
        stats.degenerate_dropped += part.degenerate_dropped;
        self.first_degenerate = self.first_degenerate.or(part.first_degenerate);
        let material = |m: u32| match m {
            INHERITED => inherited.unwrap_or(m),
            m => base + m,
        };
        self.scene.geometry.append(part.geometry, material);
    }

    /// The material in effect, the default one (added now) before any `f`.
    fn current_material(&mut self) -> u32 {
        *self.current.get_or_insert_with(|| {
            self.scene.materials.push(Material::default());
            self.scene.materials.len() as u32 - 1
        })
    }

    /// Log a part's warnings and take its viewpoints, in order.
    pub fn notes(&mut self, notes: &[Note]) {
        for note in notes {
            match note {
                Note::Warning(w) => log::warn!(target: LOG_TARGET, "{w}"),
                Note::Viewpoint { line, col } => self.second_viewpoint(*line, *col),
                Note::Camera(c) => self.camera = Some(*c),
            }
        }
    }

    /// Warn that the `v` at `line:col` replaces an earlier one, if there is one.
    fn second_viewpoint(&self, line: usize, col: usize) {
        if let Some(old) = self.camera {
            // The first eye in the file's coordinates, as it wrote them.
            let from = (old.from.as_dvec3() + self.origin).as_vec3();
            log::warn!(
                target: LOG_TARGET,
                "{}:{line}:{col}: a second viewpoint ('v') replaces the first (from {} {} {})",
                self.path.display(),
                range::number(from.x),
                range::number(from.y),
                range::number(from.z)
            );
        }
    }

    /// The scene, once every part is in.
    ///
    /// # Errors
    /// `path: no viewpoint ('v') in file` when no part had a complete viewpoint.
    pub fn finish(self) -> Result<Scene, LoadError> {
        let Some(camera) = self.camera else {
            return Err(LoadError {
                path: self.path.to_path_buf(),
                line: 0,
                col: 0,
                message: "no viewpoint ('v') in file".into(),
            });
        };
        let mut scene = self.scene;
        if let Some((line, col)) = self.first_degenerate {
            log::warn!(
                target: LOG_TARGET,
                "{}: dropped {} degenerate polygon(s) (fewer than 3 distinct vertices or \
                 zero area), the first at {line}:{col}",
                self.path.display(),
                scene.load_stats.degenerate_dropped
            );
        }
        let default = default_light_intensity(scene.lights.len());
        for (l, &has) in scene.lights.iter_mut().zip(&self.light_has_color) {
            if !has {
                l.color = Vec3::splat(default);
            }
        }
        scene.camera = camera;
        scene.ambient = Vec3::splat(default);
        scene.origin = self.origin;
        Ok(scene)
    }
}
