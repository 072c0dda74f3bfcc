//! From the [`format`](super::format) structures to a [`Scene`]: names resolved,
//! defaults applied, transforms composed and applied, everything checked, every error at
//! the span of the value (or table) it is about.
//!
//! Placement rules (the scene has exactly one level of instancing):
//! - triangles (`triangle`, `polygon`, `mesh`, included files) are transformed into
//!   their final coordinates (baked);
//! - an analytic primitive under a transform that its kind can absorb exactly is baked
//!   too, rewritten as a primitive of its kind in final coordinates
//!   ([`Primitive::bake`](crate::geometry::Primitive::bake)): spheres, cones, oriented
//!   boxes, capped cones and tori under similarities (rotation, uniform scale,
//!   translation, mirror), axis-aligned boxes under diagonal linear parts, polyhedra,
//!   unclipped quadrics and planes under any invertible transform, CSG solids never;
//! - any other analytic primitive under a non-identity transform becomes, at the top
//!   level, an object of its own placed by an instance; inside a `define` (which is
//!   itself an object), a closed solid is wrapped in a one-leaf CSG with a
//!   [`CsgTree::Transform`](crate::geometry::CsgTree::Transform), and an open surface
//!   is an error;
//! - a `define` placed by a top-level `instance` is compiled once into an object that
//!   every instance shares; an `instance` inside a `define` copies the other define's
//!   content in place (following the same rules), which is where cycles are caught.
//!
//! This file holds the [`Builder`] and the order of the steps; each other file of the
//! folder builds one part of the scene (its own notes say which), and `shapes/` has one
//! file per analytic object type.

mod bezier;
mod camera;
mod csg;
mod defines;
mod include;
mod lights;
mod materials;
mod mesh;
mod objects;
mod settings;
mod shapes;
mod sources;
mod transforms;
mod types;
mod values;

use super::format::{SceneFile, V3};
use super::{SceneSettings, Source, suggest};
use crate::geometry::polygon::Triangulator;
use crate::load::LoadError;
use crate::math::Vec3;
use crate::scene::{
    Environment, Geometry, Instance, Light, LoadStats, Material, Scene, SceneSources, Texture,
};
use glam::DVec3;
use include::Included;
use objects::{Ctx, Sink};
use std::collections::{HashMap, HashSet};
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::rc::Rc;
use std::sync::Arc;

type R<T> = Result<T, LoadError>;

/// The target of the builder's warnings, one for all its files: the module's path,
/// which the log lines show and `RUST_LOG` filters on.
const LOG_TARGET: &str = module_path!();

/// The scene being built, and what building it needs to remember.
struct Builder<'a, 's> {
    file: &'a SceneFile,
    src: &'s Source<'s>,
    materials: Vec<Material>,
    /// Textures the materials' maps index (the scene's and included OBJ files').
    textures: Vec<Texture>,
    /// Environment map (`[render] environment`, else an included OBJ's `refl`).
    environment: Option<Environment>,
    material_names: HashMap<&'a str, u32>,
    default_material: Option<u32>,
    lights: Vec<Light>,
    geometry: Geometry,
    objects: Vec<Geometry>,
    instances: Vec<Instance>,
    /// Compiled defines: their object, or `None` when they hold no primitive.
    compiled: HashMap<&'a str, Option<u32>>,
    /// Defines being expanded, outermost first, for cycle detection.
    define_stack: Vec<&'a str>,
    /// Defines expanded at least once (compiled, copied into another define, or taken
    /// as a CSG operand), and so checked.
    expanded: HashSet<&'a str>,
    includes: HashMap<PathBuf, Rc<Included>>,
    stats: LoadStats,
    /// Position of the first dropped degenerate polygon.
    first_degenerate: Option<Range<usize>>,
    triangulator: Triangulator,
    pts: Vec<Vec3>,
    nrm: Vec<Vec3>,
    tris: Vec<[usize; 3]>,
    /// The world point that is the scene's zero: the camera's eye (see
    /// [`Scene::origin`]).
    origin: DVec3,
    /// The scene file, as the origins of what it defines name it.
    origin_file: Arc<str>,
    /// Where the materials, lights and instances were defined.
    sources: SceneSources,
}

/// Build the scene described by `file`, read from `src`, in the frame whose origin is
/// the world point `origin` (by default the camera's eye; see [`Scene::origin`]).
pub(super) fn build(
    file: &SceneFile,
    src: &Source,
    origin: Option<DVec3>,
) -> R<(Scene, SceneSettings)> {
    let mut b = Builder::new(file, src);
    let (camera, origin) = b.camera(origin)?;
    b.origin = origin;
    let (background, ambient, settings) = b.render()?;
    b.named_materials()?;
    b.file_lights()?;
    for obj in &file.objects {
        b.walk(obj, Ctx::frame(origin), &mut Sink::Top)?;
    }
    b.check_unused_defines()?;
    b.warn_degenerate();
    let scene = Scene {
        camera,
        background,
        lights: b.lights,
        ambient,
        materials: b.materials,
        geometry: b.geometry,
        objects: b.objects,
        instances: b.instances,
        render: settings,
        load_stats: b.stats,
        textures: b.textures,
        environment: b.environment,
        origin,
        sources: b.sources,
    };
    Ok((scene, settings))
}

/// `path:line:col` of an error, for log messages.
trait DisplayPrefix {
    fn display_prefix(&self) -> String;
}

impl DisplayPrefix for LoadError {
    fn display_prefix(&self) -> String {
        format!("{}:{}:{}", self.path.display(), self.line, self.col)
    }
}

fn v3(v: &V3) -> DVec3 {
    DVec3::new(v[0].0, v[1].0, v[2].0)
}

fn f32v(v: DVec3) -> Vec3 {
    v.as_vec3()
}

/// "a sphere", "an include", "a union".
fn article(name: &str) -> String {
    // A "u" that sounds "you" takes "a".
    let vowel = name.starts_with(['a', 'e', 'i', 'o', 'u']) && !name.starts_with("uni");
    format!("{} {name}", if vowel { "an" } else { "a" })
}

fn did_you_mean<'c>(word: &str, candidates: impl IntoIterator<Item = &'c str>) -> String {
    match suggest(word, candidates) {
        Some(s) => format!(" (did you mean `{s}`?)"),
        None => String::new(),
    }
}

impl<'a, 's> Builder<'a, 's> {
    fn new(file: &'a SceneFile, src: &'s Source<'s>) -> Self {
        Builder {
            file,
            src,
            materials: Vec::new(),
            textures: Vec::new(),
            environment: None,
            material_names: HashMap::new(),
            default_material: None,
            lights: Vec::new(),
            geometry: Geometry::default(),
            objects: Vec::new(),
            instances: Vec::new(),
            compiled: HashMap::new(),
            define_stack: Vec::new(),
            expanded: HashSet::new(),
            includes: HashMap::new(),
            stats: LoadStats::default(),
            first_degenerate: None,
            triangulator: Triangulator::new(),
            pts: Vec::new(),
            nrm: Vec::new(),
            tris: Vec::new(),
            origin: DVec3::ZERO,
            origin_file: Arc::from(src.path.display().to_string()),
            sources: SceneSources::default(),
        }
    }

    /// The path of `name`, a file named in the scene file, relative to its folder.
    fn relative_path(&self, name: &str) -> PathBuf {
        self.src.path.parent().unwrap_or(Path::new("")).join(name)
    }

    /// An error at the start of `span` in the scene file.
    fn at(&self, span: Range<usize>) -> LoadError {
        self.src.err(span, "")
    }

    fn err(&self, span: Range<usize>, message: impl Into<String>) -> LoadError {
        self.src.err(span, message)
    }

    /// One warning for the degenerate polygons dropped, at the first.
    fn warn_degenerate(&self) {
        if let Some(span) = &self.first_degenerate {
            log::warn!(
                target: LOG_TARGET,
                "{}: dropped {} degenerate polygon(s) (fewer than 3 distinct vertices or zero \
                 area), the first here",
                self.at(span.clone()).display_prefix(),
                self.stats.degenerate_dropped
            );
        }
    }
}
