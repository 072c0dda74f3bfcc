//! From the [`format`](super::format) structures to a [`Scene`]: names resolved,
//! defaults applied, transforms composed and applied, everything checked, every error at
//! the span of the value (or table) it is about.
//!
//! Placement rules (the scene has exactly one level of instancing):
//! - triangles (`triangle`, `polygon`, `mesh`, included files) are transformed into
//!   their final coordinates (baked);
//! - an analytic primitive under a similarity (rotation, uniform scale, translation,
//!   mirror) whose shape stays of its kind (spheres, NFF cones) is baked too;
//! - any other analytic primitive under a non-identity transform becomes, at the top
//!   level, an object of its own placed by an instance; inside a `define` (which is
//!   itself an object), a closed solid is wrapped in a one-leaf CSG with a
//!   [`CsgTree::Transform`], and an open surface is an error;
//! - a `define` placed by a top-level `instance` is compiled once into an object that
//!   every instance shares; an `instance` inside a `define` copies the other define's
//!   content in place (following the same rules), which is where cycles are caught.

use super::format::{
    LightDef, MaterialDef, ObjectDef, Real, Scale, SceneFile, Spanned, TextureDef, TransformList,
    TransformStep, V3,
};
use super::{MAX_SIDE, SceneSettings, Source, suggest};
use crate::geometry::bezier::{BezierPatch, teapot_patches, tessellate};
use crate::geometry::polygon::Triangulator;
use crate::geometry::{
    AaBox, CappedCone, Cone, Csg, CsgOp, CsgTree, OBox, Plane, Polyhedron, Primitive, QuadUv,
    Quadric, Shape, Sphere, Torus, Triangle,
};
use crate::load::{LoadError, nff, obj};
use crate::math::{Aabb, Vec3, Xform};
use crate::scene::texture::{Image, Wrap};
use crate::scene::{
    Camera, Environment, Geometry, GeometryMark, INHERIT, Instance, Light, LoadStats, Maps,
    Material, Scene, Spot, Texture, range,
};
use glam::{Affine3A, DAffine3, DMat3, DMat4, DQuat, DVec3, Quat};
use std::collections::HashMap;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::rc::Rc;
use std::sync::Arc;

type R<T> = Result<T, LoadError>;

/// Deepest nesting of objects (groups, CSG, instances copied into defines).
const MAX_NESTING: usize = 256;
/// Largest accepted `max_depth`.
const MAX_RAY_DEPTH: u32 = 64;
/// Largest accepted `spp`.
const MAX_SPP: u32 = 65_536;
/// Ambient light when `[render]` gives none.
const DEFAULT_AMBIENT: f32 = 0.1;
/// Image size when `[camera]` gives none.
const DEFAULT_RESOLUTION: [u32; 2] = [640, 480];
/// Field of view when `[camera]` gives none.
const DEFAULT_FOV: f64 = 45.0;
/// Phong exponent when a material gives none.
const DEFAULT_SHININESS: f64 = 32.0;
/// A bezier's default tessellation tolerance, relative to the diagonal of its control
/// points' bounding box.
const BEZIER_RELATIVE_TOLERANCE: f64 = 1e-3;
/// Spot cutoff half-angle when a light gives none.
const DEFAULT_CUTOFF: f64 = 45.0;

/// The object types.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Ty {
    Sphere,
    Cone,
    Cylinder,
    CappedCone,
    Box,
    OBox,
    Polyhedron,
    Quadric,
    Plane,
    Torus,
    Triangle,
    Polygon,
    Mesh,
    Bezier,
    Include,
    Group,
    Instance,
    Union,
    Intersection,
    Difference,
}

/// Each type's name and the keys it takes besides `type`, `material` and `transform`.
const TYPES: &[(&str, Ty, &[&str])] = &[
    ("sphere", Ty::Sphere, &["center", "radius"]),
    (
        "cone",
        Ty::Cone,
        &["base", "base_radius", "apex", "apex_radius"],
    ),
    (
        "cylinder",
        Ty::Cylinder,
        &["base", "axis", "height", "radius"],
    ),
    (
        "capped_cone",
        Ty::CappedCone,
        &["base", "axis", "height", "base_radius", "top_radius"],
    ),
    ("box", Ty::Box, &["min", "max"]),
    (
        "obox",
        Ty::OBox,
        &["center", "size", "half_size", "rotation", "axes"],
    ),
    (
        "polyhedron",
        Ty::Polyhedron,
        &["planes", "preset", "center", "radius", "sides", "height"],
    ),
    ("quadric", Ty::Quadric, &["coefficients", "clip"]),
    ("plane", Ty::Plane, &["point", "normal"]),
    (
        "torus",
        Ty::Torus,
        &["center", "axis", "major_radius", "minor_radius"],
    ),
    ("triangle", Ty::Triangle, &["vertices", "normals"]),
    ("polygon", Ty::Polygon, &["vertices", "normals"]),
    ("mesh", Ty::Mesh, &["vertices", "faces", "normals"]),
    ("bezier", Ty::Bezier, &["patches", "builtin", "tolerance"]),
    ("include", Ty::Include, &["file", "lights"]),
    ("group", Ty::Group, &["children"]),
    ("instance", Ty::Instance, &["of"]),
    ("union", Ty::Union, &["children"]),
    ("intersection", Ty::Intersection, &["children"]),
    ("difference", Ty::Difference, &["children"]),
];

impl Ty {
    fn name(self) -> &'static str {
        TYPES.iter().find(|t| t.1 == self).map_or("?", |t| t.0)
    }

    fn csg_op(self) -> Option<CsgOp> {
        match self {
            Ty::Union => Some(CsgOp::Union),
            Ty::Intersection => Some(CsgOp::Intersection),
            Ty::Difference => Some(CsgOp::Difference),
            _ => None,
        }
    }
}

/// Where primitives go: the scene's top level, or an object being compiled from a
/// `define`.
enum Sink<'g> {
    Top,
    Object(&'g mut Geometry),
}

impl Sink<'_> {
    fn in_define(&self) -> bool {
        matches!(self, Sink::Object(_))
    }
}

/// What a node passes down to its children.
#[derive(Clone, Copy, Debug)]
struct Ctx {
    /// The node's space to the space of the sink (world, or the define's object space).
    xform: DAffine3,
    /// The nearest material given above, if any.
    material: Option<u32>,
    /// Nesting depth.
    depth: usize,
}

impl Ctx {
    const ROOT: Ctx = Ctx {
        xform: DAffine3::IDENTITY,
        material: None,
        depth: 0,
    };
}

/// The formats an `include` reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Format {
    Nff,
    Obj,
}

/// A parsed included file, its materials already appended to the scene's.
struct Included {
    /// Its primitives, material indices local to the file.
    geometry: Geometry,
    /// Its lights (NFF).
    lights: Vec<Light>,
    /// Where its materials start in the scene's list.
    material_base: u32,
    format: Format,
}

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
    includes: HashMap<PathBuf, Rc<Included>>,
    stats: LoadStats,
    /// Position of the first dropped degenerate polygon.
    first_degenerate: Option<Range<usize>>,
    triangulator: Triangulator,
    pts: Vec<Vec3>,
    nrm: Vec<Vec3>,
    tris: Vec<[usize; 3]>,
}

/// Build the scene described by `file`, read from `src`.
pub(super) fn build(file: &SceneFile, src: &Source) -> R<(Scene, SceneSettings)> {
    let mut b = Builder {
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
        includes: HashMap::new(),
        stats: LoadStats::default(),
        first_degenerate: None,
        triangulator: Triangulator::new(),
        pts: Vec::new(),
        nrm: Vec::new(),
        tris: Vec::new(),
    };
    let camera = b.camera()?;
    let (background, ambient, settings) = b.render()?;
    // Materials are numbered in file order (the map itself is sorted by name).
    let mut materials: Vec<_> = file.materials.iter().collect();
    materials.sort_by_key(|(_, d)| d.span().start);
    for (name, def) in materials {
        let mut m = b.material(def)?;
        m.maps = b.maps(def)?;
        b.material_names.insert(name, b.materials.len() as u32);
        b.materials.push(m);
    }
    for l in &file.lights {
        let light = b.light(l)?;
        b.lights.push(light);
    }
    for obj in &file.objects {
        b.walk(obj, Ctx::ROOT, &mut Sink::Top)?;
    }
    // Defines no instance placed are still checked, so that an error in one does not
    // wait until it is first used.
    let mut defines: Vec<_> = file.define.iter().collect();
    defines.sort_by_key(|(_, d)| d.span().start);
    for (name, def) in defines {
        if !b.compiled.contains_key(name.as_str()) {
            log::warn!(
                "{}: define `{name}` is never instanced",
                b.at(def.span()).display_prefix()
            );
            let mut scratch = Geometry::default();
            b.define_stack.push(name);
            b.walk(def, Ctx::ROOT, &mut Sink::Object(&mut scratch))?;
            b.define_stack.pop();
        }
    }
    if let Some(span) = &b.first_degenerate {
        log::warn!(
            "{}: dropped {} degenerate polygon(s) (fewer than 3 distinct vertices or zero \
             area), the first here",
            b.at(span.clone()).display_prefix(),
            b.stats.degenerate_dropped
        );
    }
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
        sources: Default::default(),
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

/// `m` in single precision.
fn affine_f32(m: &DAffine3) -> Affine3A {
    Affine3A::from_mat3_translation(m.matrix3.as_mat3(), m.translation.as_vec3())
}

/// The uniform scale factor of `m` if its linear part is a rotation (or mirror) times
/// that factor, to a relative 1e-6.
fn similarity_scale(m: &DAffine3) -> Option<f64> {
    let l = m.matrix3;
    let g = l.transpose() * l;
    let s2 = (g.x_axis.x + g.y_axis.y + g.z_axis.z) / 3.0;
    if !(s2 > 0.0 && s2.is_finite()) {
        return None;
    }
    let dev = g - DMat3::from_diagonal(DVec3::splat(s2));
    let worst = [dev.x_axis, dev.y_axis, dev.z_axis]
        .iter()
        .map(|c| c.abs().max_element())
        .fold(0.0f64, f64::max);
    (worst <= 1e-6 * s2).then(|| s2.sqrt())
}

/// `shape` under `m` as a shape of the same kind, when that is exact.
fn bake(shape: &Shape, m: &DAffine3) -> Option<Shape> {
    match shape {
        Shape::Sphere(s) => {
            let k = similarity_scale(m)?;
            let r = (s.radius as f64 * k) as f32;
            Some(Shape::Sphere(Sphere {
                center: f32v(m.transform_point3(s.center.as_dvec3())),
                radius: r,
                inside_only: s.inside_only,
            }))
        }
        Shape::Cone(c) => {
            let k = similarity_scale(m)?;
            let sign = if c.inside_only { -1.0 } else { 1.0 };
            Some(Shape::Cone(Cone::new(
                f32v(m.transform_point3(c.base.as_dvec3())),
                sign * (c.base_radius as f64 * k) as f32,
                f32v(m.transform_point3(c.apex.as_dvec3())),
                sign * (c.apex_radius as f64 * k) as f32,
            )))
        }
        Shape::Box(b) => {
            // Axis-aligned stays axis-aligned under a diagonal linear part.
            let l = m.matrix3;
            let diagonal = l.x_axis.y == 0.0
                && l.x_axis.z == 0.0
                && l.y_axis.x == 0.0
                && l.y_axis.z == 0.0
                && l.z_axis.x == 0.0
                && l.z_axis.y == 0.0;
            if !diagonal {
                return None;
            }
            let a = m.transform_point3(b.min().as_dvec3());
            let c = m.transform_point3(b.max().as_dvec3());
            AaBox::new(f32v(a.min(c)), f32v(a.max(c)))
                .ok()
                .map(Shape::Box)
        }
        Shape::OBox(b) => {
            let k = similarity_scale(m)?;
            let axes = b.axes().map(|a| f32v((m.matrix3 * a.as_dvec3()) / k));
            OBox::from_axes(
                f32v(m.transform_point3(b.center().as_dvec3())),
                f32v(b.half_extents().as_dvec3() * k),
                axes,
            )
            .ok()
            .map(|b| Shape::OBox(Arc::new(b)))
        }
        Shape::CappedCone(c) => {
            let k = similarity_scale(m)?;
            CappedCone::new(
                f32v(m.transform_point3(c.base().as_dvec3())),
                f32v(m.matrix3 * c.axis().as_dvec3()),
                (c.height() as f64 * k) as f32,
                (c.base_radius() as f64 * k) as f32,
                (c.top_radius() as f64 * k) as f32,
            )
            .ok()
            .map(|c| Shape::CappedCone(Arc::new(c)))
        }
        Shape::Polyhedron(p) => {
            // Half-spaces n·x ≤ d map to n'·y ≤ d + n'·t with n' = M⁻ᵀn.
            let inv_t = m.matrix3.inverse().transpose();
            let planes = p
                .world_planes()
                .into_iter()
                .map(|(n, d)| {
                    let n2 = inv_t * n;
                    (f32v(n2), (d + n2.dot(m.translation)) as f32)
                })
                .collect();
            Polyhedron::new(planes)
                .ok()
                .map(|p| Shape::Polyhedron(Arc::new(p)))
        }
        Shape::Quadric(q) if q.clip().is_none() => {
            // F(L⁻¹(y − t)) about the origin t: the coefficients through L⁻¹ alone.
            let [a, b, c, d, e, f, g, h, i, j] = q.coefficients();
            let qm = DMat4::from_cols_array_2d(&[
                [a, d, e, g],
                [d, b, f, h],
                [e, f, c, i],
                [g, h, i, j],
            ]);
            let inv = DMat4::from_mat3(m.matrix3.inverse());
            let r = inv.transpose() * qm * inv;
            let k = |x: usize, y: usize| 0.5 * (r.col(x)[y] + r.col(y)[x]);
            let coeffs = [
                k(0, 0),
                k(1, 1),
                k(2, 2),
                k(0, 1),
                k(0, 2),
                k(1, 2),
                k(0, 3),
                k(1, 3),
                k(2, 3),
                k(3, 3),
            ];
            let t = m.translation;
            if !t.is_finite() {
                return None;
            }
            Quadric::about(f32v(t), coeffs, None)
                .ok()
                .map(|q| Shape::Quadric(Arc::new(q)))
        }
        Shape::Plane(p) => {
            let n = p.normal().as_dvec3();
            let point = m.transform_point3(n * p.offset());
            let normal = m.matrix3.inverse().transpose() * n;
            Plane::from_point_normal(f32v(point), f32v(normal))
                .ok()
                .map(Shape::Plane)
        }
        Shape::Torus(t) => {
            let k = similarity_scale(m)?;
            Torus::new(
                f32v(m.transform_point3(t.center().as_dvec3())),
                f32v(m.matrix3 * t.axis().as_dvec3()),
                (t.major_radius() as f64 * k) as f32,
                (t.minor_radius() as f64 * k) as f32,
            )
            .ok()
            .map(|t| Shape::Torus(Arc::new(t)))
        }
        Shape::Csg(_) | Shape::Quadric(_) => None,
    }
}

/// A primitive constructor's message, prefixed with the object type unless it names
/// the primitive already.
fn from_constructor(ty: Ty, e: impl std::fmt::Display) -> String {
    let e = e.to_string();
    const NAMES: [&str; 9] = [
        "box",
        "oriented box",
        "capped cone",
        "cylinder",
        "polyhedron",
        "prism",
        "quadric",
        "plane",
        "torus",
    ];
    if NAMES.iter().any(|n| e.starts_with(n)) {
        e
    } else {
        format!("{}: {e}", ty.name())
    }
}

/// "a sphere", "an include".
fn article(name: &str) -> String {
    let vowel = name.starts_with(['a', 'e', 'i', 'o', 'u']);
    format!("{} {name}", if vowel { "an" } else { "a" })
}

fn did_you_mean<'c>(word: &str, candidates: impl IntoIterator<Item = &'c str>) -> String {
    match suggest(word, candidates) {
        Some(s) => format!(" (did you mean `{s}`?)"),
        None => String::new(),
    }
}

impl<'a, 's> Builder<'a, 's> {
    /// An error at the start of `span` in the scene file.
    fn at(&self, span: Range<usize>) -> LoadError {
        self.src.err(span, "")
    }

    fn err(&self, span: Range<usize>, message: impl Into<String>) -> LoadError {
        self.src.err(span, message)
    }

    // ---- numbers -------------------------------------------------------------------

    fn positive(&self, v: &Spanned<Real>, what: &str) -> R<f64> {
        let x = v.get_ref().0;
        if x > 0.0 {
            Ok(x)
        } else {
            Err(self.err(v.span(), format!("{what} must be positive, found {x}")))
        }
    }

    fn non_negative(&self, v: &Spanned<Real>, what: &str) -> R<f64> {
        let x = v.get_ref().0;
        if x >= 0.0 {
            Ok(x)
        } else {
            Err(self.err(v.span(), format!("{what} must not be negative, found {x}")))
        }
    }

    fn non_negative3(&self, v: &Spanned<V3>, what: &str) -> R<Vec3> {
        let x = v3(v.get_ref());
        if x.min_element() >= 0.0 {
            Ok(f32v(x))
        } else {
            Err(self.err(
                v.span(),
                format!("{what} must not have negative components, found {x}"),
            ))
        }
    }

    fn positive3(&self, v: &Spanned<V3>, what: &str) -> R<Vec3> {
        let x = v3(v.get_ref());
        if x.min_element() > 0.0 {
            Ok(f32v(x))
        } else {
            Err(self.err(
                v.span(),
                format!("{what} must have positive components, found {x}"),
            ))
        }
    }

    /// A non-zero vector, normalised.
    fn direction(&self, v: &Spanned<V3>, what: &str) -> R<DVec3> {
        let x = v3(v.get_ref());
        let scaled = x / x.abs().max_element();
        match scaled.try_normalize() {
            Some(u) if x != DVec3::ZERO => Ok(u),
            _ => Err(self.err(v.span(), format!("{what} must not be zero"))),
        }
    }

    // ---- camera, render, materials, lights ------------------------------------------

    fn camera(&self) -> R<Camera> {
        let cam = &self.file.camera;
        let c = cam.get_ref();
        let fov = match &c.fov {
            Some(f) => {
                let a = f.get_ref().0;
                if !(a > 0.0 && a < 180.0) {
                    return Err(self.err(
                        f.span(),
                        format!("`fov` must be between 0 and 180 degrees (exclusive), found {a}"),
                    ));
                }
                a
            }
            None => DEFAULT_FOV,
        };
        let hither = match &c.hither {
            Some(h) => self.non_negative(h, "`hither`")?,
            None => 0.0,
        };
        let [width, height] = match &c.resolution {
            Some(r) => {
                let [w, h] = *r.get_ref();
                for (n, name) in [(w, "width"), (h, "height")] {
                    if n == 0 || n > MAX_SIDE {
                        return Err(self.err(
                            r.span(),
                            format!("image {name} must be between 1 and {MAX_SIDE}, found {n}"),
                        ));
                    }
                }
                [w, h]
            }
            None => DEFAULT_RESOLUTION,
        };
        let (from, at, up, up_span) = match &c.matrix {
            Some(m) => {
                if let Some((k, span)) = [("from", &c.from), ("at", &c.at), ("up", &c.up)]
                    .into_iter()
                    .find_map(|(k, v)| v.as_ref().map(|v| (k, v.span())))
                {
                    return Err(self.err(
                        span,
                        format!("the camera has a `matrix`, so `{k}` cannot be given too"),
                    ));
                }
                let x = self.matrix(m)?;
                let from = x.translation;
                let forward = x.matrix3 * DVec3::NEG_Z;
                let up = x.matrix3 * DVec3::Y;
                (from, from + forward, up, m.span())
            }
            None => {
                let (Some(from), Some(at)) = (&c.from, &c.at) else {
                    return Err(self.err(
                        cam.span(),
                        "the camera needs `from` and `at` (or a `matrix`)",
                    ));
                };
                let up = c.up.as_ref().map_or(DVec3::Y, |u| v3(u.get_ref()));
                let up_span = c.up.as_ref().map_or(cam.span(), |u| u.span());
                let (f, a) = (v3(from.get_ref()), v3(at.get_ref()));
                if f == a {
                    return Err(self.err(at.span(), "camera `at` equals `from`"));
                }
                (f, a, up, up_span)
            }
        };
        let fwd = at - from;
        let fwd = (fwd / fwd.abs().max_element()).normalize();
        let upn = if up == DVec3::ZERO {
            up
        } else {
            up / up.abs().max_element()
        };
        if fwd.cross(upn).try_normalize().is_none() {
            return Err(self.err(
                up_span,
                "the camera's up vector is zero or parallel to the viewing direction",
            ));
        }
        let (from_span, at_span) = match (&c.matrix, &c.from, &c.at) {
            (Some(m), _, _) => (m.span(), m.span()),
            (None, Some(f), Some(a)) => (f.span(), a.span()),
            _ => (cam.span(), cam.span()),
        };
        range::check_point("the camera `from`", f32v(from))
            .map_err(|e| self.err(from_span, e.to_string()))?;
        range::check_point("the camera `at`", f32v(at))
            .map_err(|e| self.err(at_span, e.to_string()))?;
        Ok(Camera {
            from: f32v(from),
            at: f32v(at),
            up: f32v(up),
            angle_deg: fov as f32,
            hither: hither as f32,
            width,
            height,
        })
    }

    fn render(&mut self) -> R<(Vec3, Vec3, SceneSettings)> {
        let mut background = Vec3::ZERO;
        let mut ambient = Vec3::splat(DEFAULT_AMBIENT);
        let mut settings = SceneSettings::default();
        if let Some(r) = &self.file.render {
            let r = r.get_ref();
            if let Some(b) = &r.background {
                background = self.non_negative3(b, "`background`")?;
            }
            if let Some(e) = &r.environment {
                let path = self
                    .src
                    .path
                    .parent()
                    .unwrap_or(Path::new(""))
                    .join(e.get_ref());
                self.environment =
                    Some(Environment::load(&path).map_err(|m| self.err(e.span(), m.to_string()))?);
            }
            if let Some(a) = &r.ambient {
                ambient = self.non_negative3(a, "`ambient`")?;
            }
            if let Some(d) = &r.max_depth {
                let n = *d.get_ref();
                if !(1..=MAX_RAY_DEPTH).contains(&n) {
                    return Err(self.err(
                        d.span(),
                        format!("`max_depth` must be between 1 and {MAX_RAY_DEPTH}, found {n}"),
                    ));
                }
                settings.max_depth = Some(n);
            }
            if let Some(s) = &r.spp {
                let n = *s.get_ref();
                if !(1..=MAX_SPP).contains(&n) {
                    return Err(self.err(
                        s.span(),
                        format!("`spp` must be between 1 and {MAX_SPP}, found {n}"),
                    ));
                }
                settings.spp = Some(n);
            }
        }
        Ok((background, ambient, settings))
    }

    /// The texture maps of a material definition (images read now).
    fn maps(&mut self, def: &Spanned<MaterialDef>) -> R<Maps> {
        let d = def.get_ref();
        let mut maps = Maps::NONE;
        for (t, slot, srgb) in [
            (&d.texture, &mut maps.color, true),
            (&d.specular_map, &mut maps.specular, true),
            (&d.bump, &mut maps.bump, false),
            (&d.normal_map, &mut maps.normal, false),
        ] {
            if let Some(t) = t {
                let tex = self.texture(t, srgb)?;
                self.textures.push(tex);
                *slot = self.textures.len() as u32 - 1;
            }
        }
        if let Some(s) = &d.bump_scale {
            maps.bump_scale = s.get_ref().0 as f32;
        }
        if let Some(s) = &d.uv_scale {
            let [a, b] = s.get_ref();
            if !(a.0 != 0.0 && b.0 != 0.0) {
                return Err(self.err(s.span(), "`uv_scale` must not be zero"));
            }
            maps.uv_scale = [a.0 as f32, b.0 as f32];
        }
        Ok(maps)
    }

    fn texture(&self, def: &Spanned<TextureDef>, srgb: bool) -> R<Texture> {
        let t = def.get_ref();
        let colour = |v: &Option<Spanned<V3>>, default: Vec3| -> R<Vec3> {
            v.as_ref()
                .map_or(Ok(default), |c| self.non_negative3(c, "a texture colour"))
        };
        let ty = t.ty.as_ref().map(|s| (s.get_ref().as_str(), s.span()));
        match (ty, &t.file) {
            (None | Some(("image", _)), Some(file)) => {
                let path = self
                    .src
                    .path
                    .parent()
                    .unwrap_or(Path::new(""))
                    .join(file.get_ref());
                let mut img =
                    Image::load(&path, srgb).map_err(|e| self.err(file.span(), e.to_string()))?;
                img.wrap = match t.wrap.as_ref().map(|w| (w.get_ref().as_str(), w.span())) {
                    None | Some(("repeat", _)) => Wrap::Repeat,
                    Some(("clamp", _)) => Wrap::Clamp,
                    Some((w, span)) => {
                        return Err(self.err(
                            span,
                            format!("unknown wrap mode `{w}` (expected `repeat` or `clamp`)"),
                        ));
                    }
                };
                Ok(Texture::Image(Arc::new(img)))
            }
            (Some((kind @ ("checker" | "marble"), _)), None) => {
                let a = colour(&t.a, Vec3::ONE)?;
                let b = colour(&t.b, Vec3::ZERO)?;
                let default = if kind == "checker" { 8.0 } else { 4.0 };
                let scale = match &t.scale {
                    Some(s) => self.positive(s, "`scale`")? as f32,
                    None => default,
                };
                Ok(if kind == "checker" {
                    Texture::Checker { a, b, scale }
                } else {
                    Texture::Marble { a, b, scale }
                })
            }
            (None | Some(("image", _)), None) => {
                Err(self.err(def.span(), "an image texture needs a `file`"))
            }
            (Some((other, span)), _) if !matches!(other, "image" | "checker" | "marble") => {
                Err(self.err(
                    span,
                    format!(
                        "unknown texture type `{other}` (expected `image`, `checker` or `marble`)"
                    ),
                ))
            }
            (_, Some(file)) => Err(self.err(
                file.span(),
                "`file` is for image textures (remove `type` or set it to \"image\")",
            )),
            (Some((_, span)), None) => Err(self.err(span, "an image texture needs a `file`")),
        }
    }

    fn material(&self, def: &Spanned<MaterialDef>) -> R<Material> {
        let d = def.get_ref();
        let weight = |v: &Option<Spanned<Real>>, name: &str, default: f64| -> R<f32> {
            match v {
                Some(v) => Ok(self.non_negative(v, &format!("`{name}`"))? as f32),
                None => Ok(default as f32),
            }
        };
        let color = match &d.color {
            Some(c) => self.non_negative3(c, "`color`")?,
            None => Vec3::ONE,
        };
        let kd = weight(&d.diffuse, "diffuse", 1.0)?;
        let ior = match &d.ior {
            Some(v) => self.positive(v, "`ior`")? as f32,
            None => 1.0,
        };
        let t = weight(&d.transmittance, "transmittance", 0.0)?;
        if let Err(e) = range::check_ior(t, ior) {
            let at = d.ior.as_ref().map_or(def.span(), |v| v.span());
            return Err(self.err(at, e.to_string()));
        }
        Ok(Material {
            color,
            ka: weight(&d.ambient, "ambient", kd as f64)?,
            kd,
            ks: weight(&d.specular, "specular", 0.0)?,
            shine: weight(&d.shininess, "shininess", DEFAULT_SHININESS)?,
            kr: weight(&d.reflectance, "reflectance", 0.0)?,
            t,
            ior,
            filter: match &d.filter {
                Some(f) => self.non_negative3(f, "`filter`")?,
                None => Vec3::ONE,
            },
            priority: d.priority.as_ref().map_or(0, |p| *p.get_ref()),
            emission: match &d.emission {
                Some(e) => self.non_negative3(e, "`emission`")?,
                None => Vec3::ZERO,
            },
            ..Material::DEFAULT
        })
    }

    fn light(&self, def: &Spanned<LightDef>) -> R<Light> {
        let l = def.get_ref();
        let spot = match &l.ty {
            None => false,
            Some(t) => match t.get_ref().as_str() {
                "point" => false,
                "spot" => true,
                other => {
                    return Err(self.err(
                        t.span(),
                        format!(
                            "unknown light type `{other}`{}; light types: point, spot",
                            did_you_mean(other, ["point", "spot"])
                        ),
                    ));
                }
            },
        };
        if !spot {
            for (k, v) in [
                ("direction", l.direction.as_ref().map(|v| v.span())),
                ("target", l.target.as_ref().map(|v| v.span())),
                ("cutoff", l.cutoff.as_ref().map(|v| v.span())),
                ("exponent", l.exponent.as_ref().map(|v| v.span())),
            ] {
                if let Some(span) = v {
                    return Err(self.err(
                        span,
                        format!("`{k}` is for spot lights (add `type = \"spot\"`)"),
                    ));
                }
            }
        }
        let pos = v3(l.position.get_ref());
        range::check_point("the light `position`", f32v(pos))
            .map_err(|e| self.err(l.position.span(), e.to_string()))?;
        let color = match &l.color {
            Some(c) => self.non_negative3(c, "light `color`")?,
            None => Vec3::ONE,
        };
        let intensity = match &l.intensity {
            Some(i) => self.non_negative(i, "light `intensity`")? as f32,
            None => 1.0,
        };
        let attenuation = match &l.attenuation {
            Some(a) => {
                let v = self.non_negative3(a, "`attenuation`")?;
                if v == Vec3::ZERO {
                    return Err(self.err(a.span(), "`attenuation` must not be all zero"));
                }
                v
            }
            None => Vec3::X,
        };
        let spot = if spot {
            let dir = match (&l.direction, &l.target) {
                (Some(d), None) => self.direction(d, "spot `direction`")?,
                (None, Some(t)) => {
                    let d = v3(t.get_ref()) - pos;
                    if d == DVec3::ZERO {
                        return Err(self.err(t.span(), "spot `target` equals its `position`"));
                    }
                    (d / d.abs().max_element()).normalize()
                }
                (Some(_), Some(t)) => {
                    return Err(self.err(
                        t.span(),
                        "a spot light takes `direction` or `target`, not both",
                    ));
                }
                (None, None) => {
                    return Err(self.err(def.span(), "a spot light needs `direction` or `target`"));
                }
            };
            let cutoff = match &l.cutoff {
                Some(c) => {
                    let a = c.get_ref().0;
                    if !(a > 0.0 && a < 180.0) {
                        return Err(self.err(
                            c.span(),
                            format!(
                                "`cutoff` must be between 0 and 180 degrees (exclusive), found {a}"
                            ),
                        ));
                    }
                    a
                }
                None => DEFAULT_CUTOFF,
            };
            let exponent = match &l.exponent {
                Some(e) => self.non_negative(e, "`exponent`")?,
                None => 0.0,
            };
            Some(Spot {
                dir: f32v(dir),
                cos_cutoff: cutoff.to_radians().cos() as f32,
                exponent: exponent as f32,
            })
        } else {
            None
        };
        Ok(Light {
            pos: f32v(pos),
            color: color * intensity,
            spot,
            attenuation,
        })
    }

    fn material_ref(&self, name: &Spanned<String>) -> R<u32> {
        let n = name.get_ref().as_str();
        self.material_names.get(n).copied().ok_or_else(|| {
            let hint = if self.material_names.is_empty() {
                " (the file defines no `[materials.NAME]`)".to_string()
            } else {
                did_you_mean(n, self.file.materials.keys().map(String::as_str))
            };
            self.err(name.span(), format!("unknown material `{n}`{hint}"))
        })
    }

    /// The material of primitives given none: inherited inside a define, else the
    /// default material (added on first use).
    fn fallback_material(&mut self, sink: &Sink) -> u32 {
        if sink.in_define() {
            return INHERIT;
        }
        match self.default_material {
            Some(m) => m,
            None => {
                let m = self.materials.len() as u32;
                let def = Spanned::new(0..0, MaterialDef::default());
                let mat = self.material(&def).expect("the default material is valid");
                self.materials.push(mat);
                self.default_material = Some(m);
                m
            }
        }
    }

    // ---- transforms ------------------------------------------------------------------

    /// An affine matrix given as 4 rows of 4.
    fn matrix(&self, m: &Spanned<[[Real; 4]; 4]>) -> R<DAffine3> {
        let r = m.get_ref().map(|row| row.map(|x| x.0));
        if r[3] != [0.0, 0.0, 0.0, 1.0] {
            return Err(self.err(
                m.span(),
                format!(
                    "the last row of a matrix must be [0, 0, 0, 1] (only affine transforms), \
                     found {:?}",
                    r[3]
                ),
            ));
        }
        let col = |i: usize| DVec3::new(r[0][i], r[1][i], r[2][i]);
        let x = DAffine3::from_mat3_translation(DMat3::from_cols(col(0), col(1), col(2)), col(3));
        self.check_invertible(&x, m.span())?;
        Ok(x)
    }

    fn check_invertible(&self, m: &DAffine3, span: Range<usize>) -> R<Xform> {
        Xform::new(affine_f32(m)).map_err(|e| self.err(span, format!("bad transform: {e}")))
    }

    fn step(&self, st: &Spanned<TransformStep>) -> R<DAffine3> {
        let t = st.get_ref();
        let ops: Vec<&str> = [
            ("translate", t.translate.is_some()),
            ("rotate", t.rotate.is_some()),
            ("scale", t.scale.is_some()),
            ("matrix", t.matrix.is_some()),
        ]
        .into_iter()
        .filter_map(|(k, p)| p.then_some(k))
        .collect();
        if ops.len() != 1 {
            let found = if ops.is_empty() {
                "none".to_string()
            } else {
                ops.join(", ")
            };
            return Err(self.err(
                st.span(),
                format!(
                    "a transform step takes exactly one of `translate`, `rotate` (with \
                     `angle`), `scale` or `matrix`; found {found}"
                ),
            ));
        }
        if let (Some(a), None) = (&t.angle, &t.rotate) {
            return Err(self.err(a.span(), "`angle` goes with `rotate`"));
        }
        if let Some(v) = &t.translate {
            return Ok(DAffine3::from_translation(v3(v.get_ref())));
        }
        if let Some(axis) = &t.rotate {
            let u = self.direction(axis, "the rotation axis")?;
            let Some(angle) = &t.angle else {
                return Err(self.err(st.span(), "`rotate` needs `angle` (degrees)"));
            };
            return Ok(DAffine3::from_axis_angle(u, angle.get_ref().0.to_radians()));
        }
        if let Some(s) = &t.scale {
            let k = match s.get_ref() {
                Scale::Uniform(k) => DVec3::splat(k.0),
                Scale::Axes(v) => v3(v),
            };
            if k.min_element() * k.max_element() == 0.0 || k.abs().min_element() == 0.0 {
                return Err(self.err(
                    s.span(),
                    format!("scale factors must not be zero, found {k}"),
                ));
            }
            let x = DAffine3::from_scale(k);
            self.check_invertible(&x, s.span())?;
            return Ok(x);
        }
        match &t.matrix {
            Some(m) => self.matrix(m),
            None => unreachable!("one operation is present"),
        }
    }

    /// The composition of a transform list: the first step applied first.
    fn transform_list(&self, list: &Spanned<TransformList>) -> R<DAffine3> {
        let mut m = DAffine3::IDENTITY;
        for st in list.get_ref() {
            m = self.step(st)? * m;
        }
        self.check_invertible(&m, list.span())?;
        Ok(m)
    }

    fn local_xform(&self, o: &ObjectDef) -> R<DAffine3> {
        match &o.transform {
            Some(t) => self.transform_list(t),
            None => Ok(DAffine3::IDENTITY),
        }
    }

    // ---- objects -----------------------------------------------------------------------

    /// The node's type, after checking that it takes every key it has.
    fn ty(&self, node: &Spanned<ObjectDef>, depth: usize) -> R<Ty> {
        let o = node.get_ref();
        if depth > MAX_NESTING {
            return Err(self.err(
                node.span(),
                format!("objects nested deeper than {MAX_NESTING} levels"),
            ));
        }
        let name = o.ty.get_ref().as_str();
        let Some(&(_, ty, keys)) = TYPES.iter().find(|t| t.0 == name) else {
            let all: Vec<&str> = TYPES.iter().map(|t| t.0).collect();
            return Err(self.err(
                o.ty.span(),
                format!(
                    "unknown object type `{name}`{}; types: {}",
                    did_you_mean(name, all.iter().copied()),
                    all.join(", ")
                ),
            ));
        };
        for (key, span) in o.keys() {
            if key != "material" && key != "transform" && !keys.contains(&key) {
                return Err(self.err(
                    span,
                    format!(
                        "`{key}` does not apply to {} (its keys: {}material, transform)",
                        article(name),
                        keys.iter().map(|k| format!("{k}, ")).collect::<String>()
                    ),
                ));
            }
        }
        Ok(ty)
    }

    fn need<'o, T>(
        &self,
        field: &'o Option<Spanned<T>>,
        key: &str,
        node: &Spanned<ObjectDef>,
        ty: Ty,
    ) -> R<&'o Spanned<T>> {
        field.as_ref().ok_or_else(|| {
            self.err(
                node.span(),
                format!("missing key `{key}` for {}", article(ty.name())),
            )
        })
    }

    fn geometry<'g>(top: &'g mut Geometry, sink: &'g mut Sink<'_>) -> &'g mut Geometry {
        match sink {
            Sink::Top => top,
            Sink::Object(g) => g,
        }
    }

    /// Place one node (and everything under it) into `sink`.
    fn walk(&mut self, node: &'a Spanned<ObjectDef>, ctx: Ctx, sink: &mut Sink) -> R<()> {
        let o = node.get_ref();
        let ty = self.ty(node, ctx.depth)?;
        let x = ctx.xform * self.local_xform(o)?;
        let explicit = o
            .material
            .as_ref()
            .map(|m| self.material_ref(m))
            .transpose()?;
        let inherited = explicit.or(ctx.material);
        let inner = Ctx {
            xform: x,
            material: inherited,
            depth: ctx.depth + 1,
        };
        let (mark, first_instance) = (self.geometry.mark(), self.instances.len());
        self.place(node, ty, x, explicit, inherited, inner, sink)?;
        // A group's children were checked one by one; inside a define, coordinates are
        // the object's own, checked where an instance places it.
        if ty != Ty::Group && !sink.in_define() {
            self.check_placed(mark, first_instance, ty, node.get_ref().ty.span())?;
        }
        Ok(())
    }

    /// Refuse what [`Builder::walk`] just placed at the top level (primitives added since
    /// `mark`, instances from `first_instance` on) when it reaches outside the range
    /// emray traces ([`range::MAX_COORDINATE`]).
    fn check_placed(
        &self,
        mark: GeometryMark,
        first_instance: usize,
        ty: Ty,
        span: Range<usize>,
    ) -> R<()> {
        let what = format!("this {}", ty.name());
        let check = |b: &Aabb| {
            range::check_bounds(&what, b).map_err(|e| self.err(span.clone(), e.to_string()))
        };
        for b in self.geometry.bounds_since(mark) {
            check(&b)?;
        }
        for inst in &self.instances[first_instance..] {
            let object = &self.objects[inst.object as usize];
            let bounded = object
                .bounds_since(GeometryMark::default())
                .filter(Aabb::is_finite)
                .fold(Aabb::EMPTY, |a, b| a.union(&b));
            check(&inst.xform.bounds_to_world(&bounded))?;
        }
        Ok(())
    }

    /// The body of [`Builder::walk`]: place node `node` of type `ty` under `x`.
    #[allow(clippy::too_many_arguments)]
    fn place(
        &mut self,
        node: &'a Spanned<ObjectDef>,
        ty: Ty,
        x: DAffine3,
        explicit: Option<u32>,
        inherited: Option<u32>,
        inner: Ctx,
        sink: &mut Sink,
    ) -> R<()> {
        let o = node.get_ref();
        match ty {
            Ty::Group => {
                let children = self.need(&o.children, "children", node, ty)?;
                for c in children.get_ref() {
                    self.walk(c, inner, sink)?;
                }
                Ok(())
            }
            Ty::Instance => self.instance(node, inner, sink),
            Ty::Union | Ty::Intersection | Ty::Difference => {
                let m = match inherited {
                    Some(m) => m,
                    None => self.fallback_material(sink),
                };
                self.csg(node, ty, x, m, sink)
            }
            Ty::Include => self.include(node, x, explicit, sink),
            Ty::Triangle | Ty::Polygon | Ty::Mesh => {
                let m = match inherited {
                    Some(m) => m,
                    None => self.fallback_material(sink),
                };
                self.polygons(node, ty, &x, m, sink)
            }
            Ty::Bezier => {
                let m = match inherited {
                    Some(m) => m,
                    None => self.fallback_material(sink),
                };
                self.bezier(node, &x, m, sink)
            }
            Ty::Sphere
            | Ty::Cone
            | Ty::Cylinder
            | Ty::CappedCone
            | Ty::Box
            | Ty::OBox
            | Ty::Polyhedron
            | Ty::Quadric
            | Ty::Plane
            | Ty::Torus => {
                let m = match inherited {
                    Some(m) => m,
                    None => self.fallback_material(sink),
                };
                let shape = self.analytic(node, ty)?;
                self.place_shape(shape, &x, m, node.get_ref().ty.span(), sink)
            }
        }
    }

    /// An analytic primitive in its own coordinates (before its transform).
    fn analytic(&self, node: &Spanned<ObjectDef>, ty: Ty) -> R<Shape> {
        let o = node.get_ref();
        match ty {
            Ty::Sphere => {
                let c = v3(self.need(&o.center, "center", node, ty)?.get_ref());
                let r =
                    self.positive(self.need(&o.radius, "radius", node, ty)?, "sphere `radius`")?;
                Ok(Shape::Sphere(Sphere::new(f32v(c), r as f32)))
            }
            Ty::Cone => {
                let base = self.need(&o.base, "base", node, ty)?;
                let rb = self.need(&o.base_radius, "base_radius", node, ty)?;
                let apex = self.need(&o.apex, "apex", node, ty)?;
                let rb_v = self.non_negative(rb, "cone `base_radius`")?;
                let ra_v = match &o.apex_radius {
                    Some(ra) => self.non_negative(ra, "cone `apex_radius`")?,
                    None => 0.0,
                };
                if rb_v == 0.0 && ra_v == 0.0 {
                    return Err(self.err(rb.span(), "cone radii must not both be zero"));
                }
                let (b, a) = (v3(base.get_ref()), v3(apex.get_ref()));
                if f32v(b) == f32v(a) {
                    return Err(self.err(apex.span(), "cone `apex` equals its `base`"));
                }
                Ok(Shape::Cone(Cone::new(
                    f32v(b),
                    rb_v as f32,
                    f32v(a),
                    ra_v as f32,
                )))
            }
            Ty::Box => {
                let min = self.need(&o.min, "min", node, ty)?;
                let max = self.need(&o.max, "max", node, ty)?;
                let b = AaBox::new(f32v(v3(min.get_ref())), f32v(v3(max.get_ref())))
                    .map_err(|e| self.err(max.span(), from_constructor(ty, e)))?;
                Ok(Shape::Box(b))
            }
            Ty::OBox => {
                let center = f32v(v3(self.need(&o.center, "center", node, ty)?.get_ref()));
                let half = match (&o.size, &o.half_size) {
                    (Some(s), None) => self.positive3(s, "obox `size`")? * 0.5,
                    (None, Some(h)) => self.positive3(h, "obox `half_size`")?,
                    (Some(_), Some(h)) => {
                        return Err(
                            self.err(h.span(), "an obox takes `size` or `half_size`, not both")
                        );
                    }
                    (None, None) => {
                        return Err(self.err(
                            node.span(),
                            "missing key `size` (or `half_size`) for an obox",
                        ));
                    }
                };
                let b = match (&o.rotation, &o.axes) {
                    (Some(r), None) => {
                        let m = self.transform_list(r)?;
                        let det = m.matrix3.determinant();
                        if m.translation != DVec3::ZERO
                            || !similarity_scale(&m).is_some_and(|s| (s - 1.0).abs() <= 1e-6)
                            || det < 0.0
                        {
                            return Err(self.err(
                                r.span(),
                                "an obox `rotation` must be made of rotations only",
                            ));
                        }
                        let q = DQuat::from_mat3(&m.matrix3).as_quat();
                        OBox::new(center, half, q)
                            .map_err(|e| self.err(r.span(), from_constructor(ty, e)))?
                    }
                    (None, Some(a)) => {
                        let axes = a.get_ref().map(|v| f32v(v3(&v)));
                        OBox::from_axes(center, half, axes)
                            .map_err(|e| self.err(a.span(), from_constructor(ty, e)))?
                    }
                    (None, None) => OBox::new(center, half, Quat::IDENTITY)
                        .map_err(|e| self.err(node.span(), from_constructor(ty, e)))?,
                    (Some(_), Some(a)) => {
                        return Err(
                            self.err(a.span(), "an obox takes `rotation` or `axes`, not both")
                        );
                    }
                };
                Ok(Shape::OBox(Arc::new(b)))
            }
            Ty::Cylinder | Ty::CappedCone => {
                let base = f32v(v3(self.need(&o.base, "base", node, ty)?.get_ref()));
                let axis = f32v(self.direction(self.need(&o.axis, "axis", node, ty)?, "`axis`")?);
                let height =
                    self.positive(self.need(&o.height, "height", node, ty)?, "`height`")? as f32;
                let c = if ty == Ty::Cylinder {
                    let r = self.need(&o.radius, "radius", node, ty)?;
                    let r = self.positive(r, "cylinder `radius`")? as f32;
                    CappedCone::cylinder(base, axis, height, r)
                } else {
                    let rb = self.need(&o.base_radius, "base_radius", node, ty)?;
                    let rt = self.need(&o.top_radius, "top_radius", node, ty)?;
                    let (b, t) = (
                        self.non_negative(rb, "`base_radius`")? as f32,
                        self.non_negative(rt, "`top_radius`")? as f32,
                    );
                    if b == 0.0 && t == 0.0 {
                        return Err(self.err(rt.span(), "capped cone radii must not both be zero"));
                    }
                    CappedCone::new(base, axis, height, b, t)
                };
                Ok(Shape::CappedCone(Arc::new(c.map_err(|e| {
                    self.err(node.span(), from_constructor(ty, e))
                })?)))
            }
            Ty::Polyhedron => {
                let center = o
                    .center
                    .as_ref()
                    .map_or(Vec3::ZERO, |c| f32v(v3(c.get_ref())));
                let p = match (&o.planes, &o.preset, &o.sides) {
                    (Some(planes), None, None) => {
                        if let Some((k, span)) = [
                            ("center", o.center.as_ref().map(|v| v.span())),
                            ("radius", o.radius.as_ref().map(|v| v.span())),
                            ("height", o.height.as_ref().map(|v| v.span())),
                        ]
                        .into_iter()
                        .find_map(|(k, s)| s.map(|s| (k, s)))
                        {
                            return Err(self.err(span, format!("`{k}` is for a preset or a prism, not a polyhedron given by `planes`")));
                        }
                        let mut list = Vec::with_capacity(planes.get_ref().len());
                        for p in planes.get_ref() {
                            let [a, b, c, d] = p.get_ref().map(|x| x.0);
                            let n = DVec3::new(a, b, c);
                            if n == DVec3::ZERO {
                                return Err(self.err(p.span(), "a plane's normal must not be zero"));
                            }
                            list.push((f32v(n), d as f32));
                        }
                        Polyhedron::new(list)
                            .map_err(|e| self.err(planes.span(), from_constructor(ty, e)))?
                    }
                    (None, Some(name), None) => {
                        if let Some(h) = &o.height {
                            return Err(self
                                .err(h.span(), "`height` is for a prism (`sides`), not a preset"));
                        }
                        let n = name.get_ref().as_str();
                        if !Polyhedron::PRESETS
                            .iter()
                            .any(|p| p.eq_ignore_ascii_case(n))
                        {
                            return Err(self.err(
                                name.span(),
                                format!(
                                    "unknown polyhedron preset `{n}`{}; presets: {}",
                                    did_you_mean(n, Polyhedron::PRESETS.iter().copied()),
                                    Polyhedron::PRESETS.join(", ")
                                ),
                            ));
                        }
                        let r = self.need(&o.radius, "radius", node, ty)?;
                        let r = self.positive(r, "polyhedron `radius`")? as f32;
                        Polyhedron::preset(n, center, r)
                            .map_err(|e| self.err(node.span(), from_constructor(ty, e)))?
                    }
                    (None, None, Some(sides)) => {
                        let r = self.need(&o.radius, "radius", node, ty)?;
                        let r = self.positive(r, "prism `radius`")? as f32;
                        let h = self.need(&o.height, "height", node, ty)?;
                        let h = self.positive(h, "prism `height`")? as f32;
                        Polyhedron::prism(center, *sides.get_ref(), r, h)
                            .map_err(|e| self.err(sides.span(), from_constructor(ty, e)))?
                    }
                    (None, None, None) => {
                        return Err(self.err(
                            node.span(),
                            "missing key `planes`, `preset` or `sides` for a polyhedron",
                        ));
                    }
                    _ => {
                        let second = [
                            o.planes.as_ref().map(|v| v.span()),
                            o.preset.as_ref().map(|v| v.span()),
                            o.sides.as_ref().map(|v| v.span()),
                        ]
                        .into_iter()
                        .flatten()
                        .nth(1)
                        .unwrap_or(node.span());
                        return Err(self.err(
                            second,
                            "a polyhedron takes one of `planes`, `preset` or `sides`",
                        ));
                    }
                };
                Ok(Shape::Polyhedron(Arc::new(p)))
            }
            Ty::Quadric => {
                let c = self.need(&o.coefficients, "coefficients", node, ty)?;
                let coeffs = c.get_ref().map(|x| x.0);
                let clip = match &o.clip {
                    Some(b) => {
                        let (lo, hi) =
                            (v3(b.get_ref().min.get_ref()), v3(b.get_ref().max.get_ref()));
                        if !lo.cmplt(hi).all() {
                            return Err(self.err(
                                b.span(),
                                format!("the clip box's `min` {lo} must be below its `max` {hi} on every axis"),
                            ));
                        }
                        Some(Aabb::from_points(f32v(lo), f32v(hi)))
                    }
                    None => None,
                };
                let q = Quadric::new(coeffs, clip)
                    .map_err(|e| self.err(c.span(), from_constructor(ty, e)))?;
                Ok(Shape::Quadric(Arc::new(q)))
            }
            Ty::Plane => {
                let p = self.need(&o.point, "point", node, ty)?;
                let n = self.need(&o.normal, "normal", node, ty)?;
                let n = self.direction(n, "plane `normal`")?;
                let plane = Plane::from_point_normal(f32v(v3(p.get_ref())), f32v(n))
                    .map_err(|e| self.err(node.span(), from_constructor(ty, e)))?;
                Ok(Shape::Plane(plane))
            }
            Ty::Torus => {
                let c = self.need(&o.center, "center", node, ty)?;
                let axis = self.direction(self.need(&o.axis, "axis", node, ty)?, "torus `axis`")?;
                let major = self.positive(
                    self.need(&o.major_radius, "major_radius", node, ty)?,
                    "`major_radius`",
                )?;
                let minor = self.positive(
                    self.need(&o.minor_radius, "minor_radius", node, ty)?,
                    "`minor_radius`",
                )?;
                let t = Torus::new(
                    f32v(v3(c.get_ref())),
                    f32v(axis),
                    major as f32,
                    minor as f32,
                )
                .map_err(|e| self.err(node.span(), from_constructor(ty, e)))?;
                Ok(Shape::Torus(Arc::new(t)))
            }
            _ => unreachable!("{ty:?} is not an analytic primitive"),
        }
    }

    /// Add an analytic primitive under transform `x` (see the module notes).
    fn place_shape(
        &mut self,
        shape: Shape,
        x: &DAffine3,
        material: u32,
        span: Range<usize>,
        sink: &mut Sink,
    ) -> R<()> {
        if *x == DAffine3::IDENTITY {
            Self::geometry(&mut self.geometry, sink).add_shape(shape, material);
            return Ok(());
        }
        if let Some(baked) = bake(&shape, x) {
            Self::geometry(&mut self.geometry, sink).add_shape(baked, material);
            return Ok(());
        }
        let xform = self.check_invertible(x, span.clone())?;
        match sink {
            Sink::Top => {
                let mut object = Geometry::default();
                object.add_shape(shape, material);
                self.objects.push(object);
                self.instances.push(Instance {
                    object: self.objects.len() as u32 - 1,
                    xform,
                    material,
                });
                Ok(())
            }
            Sink::Object(g) => {
                if !shape.is_solid() {
                    return Err(self.err(
                        span,
                        format!(
                            "{} under a transform other than rotation, uniform scale and \
                             translation cannot go inside a define: a define is already \
                             an instanced object (emray has one instancing level) and an \
                             open surface cannot be wrapped in CSG; give it its final \
                             coordinates, or place it outside the define",
                            article(shape.kind().singular())
                        ),
                    ));
                }
                let tree = CsgTree::Transform {
                    xform,
                    child: Box::new(CsgTree::leaf(shape)),
                };
                let csg = Csg::new(&tree).map_err(|e| self.err(span, e.to_string()))?;
                g.add_shape(Shape::Csg(Arc::new(csg)), material);
                Ok(())
            }
        }
    }

    fn lookup_define(&self, of: &Spanned<String>) -> R<(&'a str, &'a Spanned<ObjectDef>)> {
        let name = of.get_ref().as_str();
        match self.file.define.get_key_value(name) {
            Some((k, v)) => Ok((k.as_str(), v)),
            None => {
                let hint = if self.file.define.is_empty() {
                    " (the file has no `[define.NAME]`)".to_string()
                } else {
                    did_you_mean(name, self.file.define.keys().map(String::as_str))
                };
                Err(self.err(of.span(), format!("unknown define `{name}`{hint}")))
            }
        }
    }

    fn enter_define(&mut self, name: &'a str, of: &Spanned<String>) -> R<()> {
        if self.define_stack.contains(&name) {
            let mut chain: Vec<&str> = self.define_stack.clone();
            chain.push(name);
            return Err(self.err(
                of.span(),
                format!(
                    "define `{name}` contains an instance of itself: {}",
                    chain.join(" → ")
                ),
            ));
        }
        self.define_stack.push(name);
        Ok(())
    }

    /// `instance`: at the top level, the define's shared object placed under the
    /// instance's transform; inside a define, the define's content copied in place.
    fn instance(&mut self, node: &'a Spanned<ObjectDef>, inner: Ctx, sink: &mut Sink) -> R<()> {
        let of = self.need(&node.get_ref().of, "of", node, Ty::Instance)?;
        let (name, def) = self.lookup_define(of)?;
        if sink.in_define() {
            self.enter_define(name, of)?;
            self.walk(def, inner, sink)?;
            self.define_stack.pop();
            return Ok(());
        }
        let object = match self.compiled.get(name) {
            Some(&o) => o,
            None => {
                self.enter_define(name, of)?;
                let mut g = Geometry::default();
                self.walk(def, Ctx::ROOT, &mut Sink::Object(&mut g))?;
                self.define_stack.pop();
                let o = if g.prim_count() == 0 {
                    log::warn!(
                        "{}: define `{name}` holds no primitive; its instances are left out",
                        self.at(def.span()).display_prefix()
                    );
                    None
                } else {
                    self.objects.push(g);
                    Some(self.objects.len() as u32 - 1)
                };
                self.compiled.insert(name, o);
                o
            }
        };
        if let Some(object) = object {
            let xform = self.check_invertible(&inner.xform, node.get_ref().ty.span())?;
            let material = match inner.material {
                Some(m) => m,
                None => self.fallback_material(sink),
            };
            self.instances.push(Instance {
                object,
                xform,
                material,
            });
        }
        Ok(())
    }

    // ---- CSG -------------------------------------------------------------------------

    fn csg(
        &mut self,
        node: &'a Spanned<ObjectDef>,
        ty: Ty,
        x: DAffine3,
        material: u32,
        sink: &mut Sink,
    ) -> R<()> {
        let span = node.get_ref().ty.span();
        // At the top level a transformed CSG is an instance; inside a define the
        // transform goes into the tree.
        let instanced = !sink.in_define() && x != DAffine3::IDENTITY;
        let rel = if instanced { DAffine3::IDENTITY } else { x };
        let op = ty.csg_op().expect("a CSG type");
        let tree = self.csg_operands(node, ty, op, rel, None, 0)?;
        let csg = Csg::new(&tree).map_err(|e| self.err(span.clone(), e.to_string()))?;
        let shape = Shape::Csg(Arc::new(csg));
        if instanced {
            self.place_shape(shape, &x, material, span, sink)
        } else {
            Self::geometry(&mut self.geometry, sink).add_shape(shape, material);
            Ok(())
        }
    }

    /// The left fold of a CSG node's children by `op`.
    fn csg_operands(
        &mut self,
        node: &'a Spanned<ObjectDef>,
        ty: Ty,
        op: CsgOp,
        rel: DAffine3,
        material: Option<u32>,
        depth: usize,
    ) -> R<CsgTree> {
        let children = self.need(&node.get_ref().children, "children", node, ty)?;
        if children.get_ref().len() < 2 {
            return Err(self.err(
                children.span(),
                format!(
                    "{} needs at least 2 children, found {}",
                    article(ty.name()),
                    children.get_ref().len()
                ),
            ));
        }
        let mut acc: Option<CsgTree> = None;
        for c in children.get_ref() {
            let t = self.csg_operand(c, rel, material, depth + 1)?;
            acc = Some(match acc {
                None => t,
                Some(a) => CsgTree::op(op, a, t),
            });
        }
        Ok(acc.expect("at least two children"))
    }

    /// One CSG operand. `rel` maps the parent's space to the CSG root's; `material` is
    /// the nearest material given inside the CSG (the root's own is the primitive's).
    fn csg_operand(
        &mut self,
        node: &'a Spanned<ObjectDef>,
        parent: DAffine3,
        material: Option<u32>,
        depth: usize,
    ) -> R<CsgTree> {
        let o = node.get_ref();
        let ty = self.ty(node, depth)?;
        let rel = parent * self.local_xform(o)?;
        let material = match &o.material {
            Some(m) => Some(self.material_ref(m)?),
            None => material,
        };
        match ty {
            Ty::Union | Ty::Intersection | Ty::Difference => {
                let op = ty.csg_op().expect("a CSG type");
                self.csg_operands(node, ty, op, rel, material, depth)
            }
            Ty::Instance => {
                let of = self.need(&o.of, "of", node, ty)?;
                let (name, def) = self.lookup_define(of)?;
                self.enter_define(name, of)?;
                let t = self.csg_operand(def, rel, material, depth + 1);
                self.define_stack.pop();
                t
            }
            Ty::Sphere
            | Ty::Cone
            | Ty::Cylinder
            | Ty::CappedCone
            | Ty::Box
            | Ty::OBox
            | Ty::Polyhedron
            | Ty::Quadric
            | Ty::Plane
            | Ty::Torus => {
                let shape = self.analytic(node, ty)?;
                if !shape.is_solid() {
                    return Err(self.err(
                        o.ty.span(),
                        format!(
                            "{} is not a closed solid and cannot be a CSG operand",
                            article(shape.kind().singular())
                        ),
                    ));
                }
                let leaf = |shape| CsgTree::Leaf { shape, material };
                if rel == DAffine3::IDENTITY {
                    Ok(leaf(shape))
                } else if let Some(baked) = bake(&shape, &rel) {
                    Ok(leaf(baked))
                } else {
                    let xform = self.check_invertible(&rel, o.ty.span())?;
                    Ok(CsgTree::Transform {
                        xform,
                        child: Box::new(leaf(shape)),
                    })
                }
            }
            Ty::Group => Err(self.err(
                o.ty.span(),
                "a group is not a solid and cannot be a CSG operand (combine solids with \
                 `union`)",
            )),
            Ty::Triangle | Ty::Polygon | Ty::Mesh | Ty::Bezier | Ty::Include => Err(self.err(
                o.ty.span(),
                format!(
                    "{} is not a closed solid and cannot be a CSG operand",
                    article(ty.name())
                ),
            )),
        }
    }

    // ---- triangles -----------------------------------------------------------------------

    /// `triangle`, `polygon` and `mesh`.
    fn polygons(
        &mut self,
        node: &Spanned<ObjectDef>,
        ty: Ty,
        x: &DAffine3,
        material: u32,
        sink: &mut Sink,
    ) -> R<()> {
        let o = node.get_ref();
        let vertices = self.need(&o.vertices, "vertices", node, ty)?;
        let vs = vertices.get_ref();
        let normals = match &o.normals {
            Some(n) => {
                if n.get_ref().len() != vs.len() {
                    return Err(self.err(
                        n.span(),
                        format!(
                            "`normals` must have one normal per vertex: {} vertices, {} normals",
                            vs.len(),
                            n.get_ref().len()
                        ),
                    ));
                }
                let mut out = Vec::with_capacity(vs.len());
                for v in n.get_ref() {
                    out.push(self.direction(v, "a vertex normal")?);
                }
                Some(out)
            }
            None => None,
        };
        let need_count = |ok: bool, what: &str| -> R<()> {
            if ok {
                Ok(())
            } else {
                Err(self.err(
                    vertices.span(),
                    format!("{} needs {what}, found {}", article(ty.name()), vs.len()),
                ))
            }
        };
        let pts: Vec<DVec3> = vs.iter().map(|v| v3(v.get_ref())).collect();
        match ty {
            Ty::Triangle => {
                need_count(vs.len() == 3, "exactly 3 vertices")?;
                self.emit_polygon(
                    &pts,
                    normals.as_deref(),
                    None,
                    x,
                    material,
                    node.span(),
                    sink,
                );
            }
            Ty::Polygon => {
                need_count(vs.len() >= 3, "at least 3 vertices")?;
                self.emit_polygon(
                    &pts,
                    normals.as_deref(),
                    None,
                    x,
                    material,
                    node.span(),
                    sink,
                );
            }
            Ty::Mesh => {
                let faces = self.need(&o.faces, "faces", node, ty)?;
                for f in faces.get_ref() {
                    let idx = f.get_ref();
                    if idx.len() < 3 {
                        return Err(self.err(
                            f.span(),
                            format!(
                                "a face needs at least 3 vertex indices, found {}",
                                idx.len()
                            ),
                        ));
                    }
                    if let Some(&bad) = idx.iter().find(|&&i| i as usize >= pts.len()) {
                        return Err(self.err(
                            f.span(),
                            format!(
                                "vertex index {bad} is out of range: the mesh has {} vertices \
                                 (indices start at 0)",
                                pts.len()
                            ),
                        ));
                    }
                    self.emit_polygon(
                        &pts,
                        normals.as_deref(),
                        Some(idx),
                        x,
                        material,
                        f.span(),
                        sink,
                    );
                }
            }
            _ => unreachable!("{ty:?} is not made of polygons"),
        }
        Ok(())
    }

    /// Transform a polygon (the points `pts[indices[i]]`, or all of `pts`) and its
    /// vertex normals by `x`, triangulate it and add the triangles. Under a mirroring
    /// transform the vertex order is reversed so that the front side stays the front.
    #[allow(clippy::too_many_arguments)]
    fn emit_polygon(
        &mut self,
        pts: &[DVec3],
        normals: Option<&[DVec3]>,
        indices: Option<&[u32]>,
        x: &DAffine3,
        material: u32,
        span: Range<usize>,
        sink: &mut Sink,
    ) {
        let normal_matrix = x.matrix3.inverse().transpose();
        let mirror = x.matrix3.determinant() < 0.0;
        self.pts.clear();
        self.nrm.clear();
        let n = indices.map_or(pts.len(), <[u32]>::len);
        for k in 0..n {
            let k = if mirror { n - 1 - k } else { k };
            let i = indices.map_or(k, |ix| ix[k] as usize);
            self.pts.push(f32v(x.transform_point3(pts[i])));
            if let Some(ns) = normals {
                self.nrm.push(f32v((normal_matrix * ns[i]).normalize()));
            }
        }
        self.stats.polygons += 1;
        if self
            .triangulator
            .triangulate(&self.pts, &mut self.tris)
            .is_err()
        {
            self.stats.degenerate_dropped += 1;
            if self.first_degenerate.is_none() {
                self.first_degenerate = Some(span);
            }
            return;
        }
        let g = Self::geometry(&mut self.geometry, sink);
        for &[a, b, c] in &self.tris {
            let tri = Triangle {
                p: [self.pts[a], self.pts[b], self.pts[c]],
            };
            if normals.is_some() {
                g.add_smooth_triangle(tri, [self.nrm[a], self.nrm[b], self.nrm[c]], material);
            } else {
                g.add_triangle(tri, material);
            }
        }
    }

    /// `bezier`: bicubic patches, transformed (a Bézier patch's control points
    /// transform with it) and then tessellated, so the tolerance is in final units.
    fn bezier(
        &mut self,
        node: &Spanned<ObjectDef>,
        x: &DAffine3,
        material: u32,
        sink: &mut Sink,
    ) -> R<()> {
        let o = node.get_ref();
        let mut patches = match (&o.patches, &o.builtin) {
            (Some(p), None) => p
                .get_ref()
                .iter()
                .map(|q| {
                    let q = q.get_ref();
                    // Row by row: point 4·j + i is p[i][j], i along u.
                    BezierPatch::new(std::array::from_fn(|i| {
                        std::array::from_fn(|j| v3(&q[4 * j + i]))
                    }))
                })
                .collect::<Vec<_>>(),
            (None, Some(b)) => match b.get_ref().as_str() {
                "teapot" => teapot_patches(),
                other => {
                    return Err(self.err(
                        b.span(),
                        format!(
                            "unknown built-in patch set `{other}`{}; built-ins: teapot",
                            did_you_mean(other, ["teapot"])
                        ),
                    ));
                }
            },
            (Some(_), Some(b)) => {
                return Err(self.err(b.span(), "a bezier takes `patches` or `builtin`, not both"));
            }
            (None, None) => {
                return Err(self.err(
                    node.span(),
                    "missing key `patches` (or `builtin`) for a bezier",
                ));
            }
        };
        let mirror = x.matrix3.determinant() < 0.0;
        for p in &mut patches {
            let mut q = *p;
            for row in &mut q.p {
                for c in row.iter_mut() {
                    *c = x.transform_point3(*c);
                }
            }
            // A mirror turns the patch inside out; swapping u and v turns it back.
            *p = if mirror { q.transposed() } else { q };
        }
        let tolerance = match &o.tolerance {
            Some(t) => self.positive(t, "bezier `tolerance`")?,
            None => {
                let (lo, hi) = patches.iter().flat_map(|p| p.p.iter().flatten()).fold(
                    (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
                    |(lo, hi), &c| (lo.min(c), hi.max(c)),
                );
                let size = (hi - lo).length();
                if size > 0.0 {
                    size * BEZIER_RELATIVE_TOLERANCE
                } else {
                    1.0
                }
            }
        };
        let mesh = tessellate(&patches, tolerance);
        let g = Self::geometry(&mut self.geometry, sink);
        for (i, tri) in mesh.triangles.iter().enumerate() {
            let n = tri.map(|k| mesh.normals[k as usize]);
            g.add_smooth_triangle(mesh.triangle(i), n, material);
        }
        Ok(())
    }

    // ---- includes ------------------------------------------------------------------------

    /// The included file `file`, read once however often it is placed.
    fn included(&mut self, file: &Spanned<String>) -> R<Rc<Included>> {
        let rel = Path::new(file.get_ref());
        let dir = self.src.path.parent().unwrap_or(Path::new(""));
        let path = dir.join(rel);
        if let Some(inc) = self.includes.get(&path) {
            return Ok(inc.clone());
        }
        let is = |e: &str| rel.extension().is_some_and(|x| x.eq_ignore_ascii_case(e));
        if is("toml") {
            return Err(self.err(
                file.span(),
                format!(
                    "cannot include `{}`: only NFF and OBJ files can be included",
                    rel.display()
                ),
            ));
        }
        let unreadable = |e: std::io::Error| {
            self.err(
                file.span(),
                format!("cannot read included file `{}`: {e}", path.display()),
            )
        };
        let (line, col) = self.src.position(file.span().start);
        let located = |mut e: LoadError| {
            e.message = format!(
                "{} (included from {}:{line}:{col})",
                e.message,
                self.src.path.display()
            );
            e
        };
        let (geometry, materials, lights, stats, format) = if is("obj") {
            std::fs::File::open(&path).map_err(unreadable)?;
            let data = obj::load_geometry(&path).map_err(located)?;
            for w in &data.warnings {
                log::warn!(
                    "{w} (included from {}:{line}:{col})",
                    self.src.path.display()
                );
            }
            // The model's maps index its own textures: move them past the scene's.
            let base = self.textures.len() as u32;
            self.textures.extend(data.textures);
            if self.environment.is_none() {
                self.environment = data.environment;
            }
            let materials = data
                .materials
                .into_iter()
                .map(|m| Material {
                    maps: m.maps.offset(base),
                    ..m
                })
                .collect();
            (
                data.geometry,
                materials,
                Vec::new(),
                data.stats,
                Format::Obj,
            )
        } else {
            let bytes = std::fs::read(&path).map_err(unreadable)?;
            let scene = nff::parse_str(&String::from_utf8_lossy(&bytes), &path).map_err(located)?;
            (
                scene.geometry,
                scene.materials,
                scene.lights,
                scene.load_stats,
                Format::Nff,
            )
        };
        let material_base = self.materials.len() as u32;
        self.materials.extend_from_slice(&materials);
        self.stats.polygons += stats.polygons;
        self.stats.degenerate_dropped += stats.degenerate_dropped;
        let inc = Rc::new(Included {
            geometry,
            lights,
            material_base,
            format,
        });
        self.includes.insert(path, inc.clone());
        Ok(inc)
    }

    /// `include`: an NFF or OBJ file's primitives (and optionally lights) under the node's
    /// transform; its materials, unless the node gives one for all of them.
    fn include(
        &mut self,
        node: &Spanned<ObjectDef>,
        x: DAffine3,
        material: Option<u32>,
        sink: &mut Sink,
    ) -> R<()> {
        let o = node.get_ref();
        let file = self.need(&o.file, "file", node, Ty::Include)?;
        let inc = self.included(file)?;
        let s = &inc.geometry;
        let mat = |m: u32| material.unwrap_or(inc.material_base + m);
        if let Some(l) = &o.lights {
            if *l.get_ref() {
                if inc.format == Format::Obj {
                    return Err(self.err(
                        l.span(),
                        "`lights` is for NFF includes (an OBJ file has no lights)",
                    ));
                }
                if sink.in_define() {
                    return Err(self.err(
                        l.span(),
                        "an include inside a define cannot bring lights (a define is an \
                         object placed by instances; lights are not instanced)",
                    ));
                }
                for light in &inc.lights {
                    self.lights.push(Light {
                        pos: f32v(x.transform_point3(light.pos.as_dvec3())),
                        spot: light.spot.map(|sp| Spot {
                            dir: f32v((x.matrix3 * sp.dir.as_dvec3()).normalize()),
                            ..sp
                        }),
                        ..*light
                    });
                }
            }
        }
        let normal_matrix = x.matrix3.inverse().transpose();
        let mirror = x.matrix3.determinant() < 0.0;
        let identity = x == DAffine3::IDENTITY;
        {
            let g = Self::geometry(&mut self.geometry, sink);
            let to_world = |v: Vec3| f32v(x.transform_point3(v.as_dvec3()));
            // The included quads, placed once each when a triangle first needs them.
            let mut quads = vec![u32::MAX; s.quads.len()];
            for (i, tri) in s.triangles.items.iter().enumerate() {
                let m = mat(s.triangles.material[i]);
                let mut p = tri.p;
                if !identity {
                    p = p.map(to_world);
                }
                let normals = match s.triangle_normals[i] {
                    u32::MAX => None,
                    k => {
                        let mut n = s.vertex_normals[k as usize];
                        if !identity {
                            n = n.map(|v| f32v((normal_matrix * v.as_dvec3()).normalize()));
                        }
                        Some(n)
                    }
                };
                let (p, normals) = if mirror {
                    ([p[0], p[2], p[1]], normals.map(|n| [n[0], n[2], n[1]]))
                } else {
                    (p, normals)
                };
                match normals {
                    Some(n) => g.add_smooth_triangle(Triangle { p }, n, m),
                    None => g.add_triangle(Triangle { p }, m),
                }
                let placed = g.triangles.len() - 1;
                if let Some(&k) = s.triangle_uvs.get(i).filter(|&&k| k != u32::MAX) {
                    let t = s.vertex_uvs[k as usize];
                    let t = if mirror { [t[0], t[2], t[1]] } else { t };
                    g.set_triangle_uvs(placed, t);
                }
                if let Some(&k) = s.triangle_quads.get(i).filter(|&&k| k != u32::MAX) {
                    if quads[k as usize] == u32::MAX {
                        let q = s.quads[k as usize];
                        quads[k as usize] = g.add_quad(QuadUv {
                            p: if identity { q.p } else { q.p.map(to_world) },
                            ..q
                        });
                    }
                    g.set_triangle_quad(placed, quads[k as usize]);
                }
            }
        }
        let span = o.ty.span();
        for entry in s.shapes() {
            let m = mat(entry.material);
            self.place_shape(entry.shape, &x, m, span.clone(), sink)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeSet;

    #[test]
    fn similarity_detection() {
        let r = DAffine3::from_axis_angle(DVec3::new(1.0, 2.0, 3.0).normalize(), 0.7);
        assert_eq!(similarity_scale(&r).map(|s| (s * 1e9).round()), Some(1e9));
        let s = DAffine3::from_translation(DVec3::X) * DAffine3::from_scale(DVec3::splat(-2.5)) * r;
        assert!((similarity_scale(&s).unwrap() - 2.5).abs() < 1e-12);
        let ns = DAffine3::from_scale(DVec3::new(1.0, 2.0, 1.0)) * r;
        assert_eq!(similarity_scale(&ns), None);
        let shear = DAffine3::from_mat3(DMat3::from_cols(
            DVec3::X,
            DVec3::new(0.1, 1.0, 0.0),
            DVec3::Z,
        ));
        assert_eq!(similarity_scale(&shear), None);
    }

    #[test]
    fn spheres_bake_under_similarities_only() {
        let s = Shape::Sphere(Sphere::new(Vec3::new(1.0, 0.0, 0.0), 2.0));
        let m = DAffine3::from_translation(DVec3::new(0.0, 5.0, 0.0))
            * DAffine3::from_scale(DVec3::splat(3.0))
            * DAffine3::from_axis_angle(DVec3::Z, std::f64::consts::FRAC_PI_2);
        let Some(Shape::Sphere(b)) = bake(&s, &m) else {
            panic!("not baked")
        };
        assert!(
            (b.center - Vec3::new(0.0, 8.0, 0.0)).length() < 1e-5,
            "{}",
            b.center
        );
        assert!((b.radius - 6.0).abs() < 1e-5);
        assert!(bake(&s, &DAffine3::from_scale(DVec3::new(1.0, 2.0, 3.0))).is_none());
    }

    #[test]
    fn every_type_has_distinct_keys() {
        for (name, _, keys) in TYPES {
            let set: BTreeSet<_> = keys.iter().collect();
            assert_eq!(set.len(), keys.len(), "{name}");
            for k in *keys {
                assert!(super::super::format::OBJECT_KEYS.contains(k), "{name}.{k}");
            }
        }
        let names: BTreeSet<_> = TYPES.iter().map(|t| t.0).collect();
        assert_eq!(names.len(), TYPES.len());
    }
}
