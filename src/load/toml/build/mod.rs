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

mod bake;
mod camera;
mod lights;
mod materials;
mod settings;
mod shapes;
mod transforms;
mod types;
mod values;

use bake::bake;
use types::Ty;

use super::format::{ObjectDef, SceneFile, Spanned, V3};
use super::{SceneSettings, Source, suggest};
use crate::geometry::bezier::{BezierPatch, teapot_patches, tessellate};
use crate::geometry::polygon::Triangulator;
use crate::geometry::{Csg, CsgOp, CsgTree, Primitive, QuadUv, Shape, Triangle};
use crate::load::{LoadError, nff, obj};
use crate::math::{Aabb, Vec3};
use crate::scene::{
    Environment, Geometry, GeometryMark, Instance, Light, LoadStats, Material, Scene, Spot,
    Texture, range,
};
use glam::{DAffine3, DVec3};
use std::collections::HashMap;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::rc::Rc;
use std::sync::Arc;

type R<T> = Result<T, LoadError>;

/// A bezier's default tessellation tolerance, relative to the diagonal of its control
/// points' bounding box.
const BEZIER_RELATIVE_TOLERANCE: f64 = 1e-3;

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
    b.named_materials()?;
    b.file_lights()?;
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

    // ---- objects -----------------------------------------------------------------------

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
            Ty::Csg(op) => {
                let m = self.material_or_fallback(inherited, sink);
                self.csg(node, op, x, m, sink)
            }
            Ty::Include => self.include(node, x, explicit, sink),
            Ty::Triangle | Ty::Polygon | Ty::Mesh => {
                let m = self.material_or_fallback(inherited, sink);
                self.polygons(node, ty, &x, m, sink)
            }
            Ty::Bezier => {
                let m = self.material_or_fallback(inherited, sink);
                self.bezier(node, &x, m, sink)
            }
            Ty::Analytic(t) => {
                let m = self.material_or_fallback(inherited, sink);
                let shape = self.analytic(node, t)?;
                self.place_shape(shape, &x, m, node.get_ref().ty.span(), sink)
            }
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
            let material = self.material_or_fallback(inner.material, sink);
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
        op: CsgOp,
        x: DAffine3,
        material: u32,
        sink: &mut Sink,
    ) -> R<()> {
        let span = node.get_ref().ty.span();
        // At the top level a transformed CSG is an instance; inside a define the
        // transform goes into the tree.
        let instanced = !sink.in_define() && x != DAffine3::IDENTITY;
        let rel = if instanced { DAffine3::IDENTITY } else { x };
        let tree = self.csg_operands(node, op, rel, None, 0)?;
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
        op: CsgOp,
        rel: DAffine3,
        material: Option<u32>,
        depth: usize,
    ) -> R<CsgTree> {
        let ty = Ty::Csg(op);
        let children = self.need(&node.get_ref().children, "children", node, ty)?;
        let (first, rest) = match children.get_ref().split_first() {
            Some((first, rest)) if !rest.is_empty() => (first, rest),
            _ => {
                return Err(self.err(
                    children.span(),
                    format!(
                        "{} needs at least 2 children, found {}",
                        article(ty.name()),
                        children.get_ref().len()
                    ),
                ));
            }
        };
        let mut acc = self.csg_operand(first, rel, material, depth + 1)?;
        for c in rest {
            let t = self.csg_operand(c, rel, material, depth + 1)?;
            acc = CsgTree::op(op, acc, t);
        }
        Ok(acc)
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
            Ty::Csg(op) => self.csg_operands(node, op, rel, material, depth),
            Ty::Instance => {
                let of = self.need(&o.of, "of", node, ty)?;
                let (name, def) = self.lookup_define(of)?;
                self.enter_define(name, of)?;
                let t = self.csg_operand(def, rel, material, depth + 1);
                self.define_stack.pop();
                t
            }
            Ty::Analytic(t) => {
                let shape = self.analytic(node, t)?;
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
