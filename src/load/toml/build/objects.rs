//! The tree of objects: walking `[[objects]]` (and the content of defines) node by
//! node, passing transforms and materials down, dispatching on each node's type,
//! placing groups and analytic primitives (by the placement rules of the
//! [module notes](super)), and refusing what lands outside the range emray traces.

use super::super::format::{ObjectDef, Spanned};
use super::shapes::At;
use super::types::Ty;
use super::{Builder, R, article};
use crate::geometry::{Csg, CsgTree, Primitive, Shape};
use crate::math::{Aabb, Vec3, Xform};
use crate::scene::{Geometry, GeometryMark, Instance, range};
use glam::{DAffine3, DMat3, DVec3};
use std::ops::Range;
use std::sync::Arc;

/// Where primitives go: the scene's top level, or an object being compiled from a
/// `define`.
pub(super) enum Sink<'g> {
    Top,
    Object(&'g mut Geometry),
}

impl Sink<'_> {
    pub(super) fn in_define(&self) -> bool {
        matches!(self, Sink::Object(_))
    }
}

/// What a node passes down to its children.
#[derive(Clone, Copy, Debug)]
pub(super) struct Ctx {
    /// The node's space to the space of the sink (world, or the define's object space).
    pub(super) xform: DAffine3,
    /// The nearest material given above, if any.
    pub(super) material: Option<u32>,
    /// Nesting depth.
    pub(super) depth: usize,
}

impl Ctx {
    /// A define's root: its object's own space.
    pub(super) const ROOT: Ctx = Ctx {
        xform: DAffine3::IDENTITY,
        material: None,
        depth: 0,
    };

    /// The scene's root: world coordinates moved into the frame whose origin is the
    /// world point `origin` (see [`crate::scene::Scene::origin`]).
    pub(super) fn frame(origin: DVec3) -> Ctx {
        Ctx {
            xform: DAffine3::from_translation(-origin),
            ..Ctx::ROOT
        }
    }
}

/// `x` as a translation that a primitive can be built in place with (see [`At`]) and
/// the rest: `(x's translation, identity)` when `x` is a translation, else
/// `(nothing, x)`.
pub(super) fn split_translation(x: &DAffine3) -> (At, DAffine3) {
    if x.matrix3 == DMat3::IDENTITY {
        (
            At {
                offset: x.translation,
            },
            DAffine3::IDENTITY,
        )
    } else {
        (At::LOCAL, *x)
    }
}

impl<'a> Builder<'a, '_> {
    /// The geometry `sink` adds to: the scene's (`top`) or the define's.
    pub(super) fn geometry<'g>(top: &'g mut Geometry, sink: &'g mut Sink<'_>) -> &'g mut Geometry {
        match sink {
            Sink::Top => top,
            Sink::Object(g) => g,
        }
    }

    /// Place one node (and everything under it) into `sink`.
    pub(super) fn walk(
        &mut self,
        node: &'a Spanned<ObjectDef>,
        ctx: Ctx,
        sink: &mut Sink,
    ) -> R<()> {
        let o = node.get_ref();
        let ty = self.ty(node, ctx.depth)?;
        let x = ctx.xform * self.local_xform(o)?;
        let explicit = o
            .material
            .as_ref()
            .map(|m| self.material_ref(m))
            .transpose()?;
        let inner = Ctx {
            xform: x,
            material: explicit.or(ctx.material),
            depth: ctx.depth + 1,
        };
        let (mark, first_instance) = (self.geometry.mark(), self.instances.len());
        let before = self.placed(sink);
        self.place(node, ty, explicit, inner, sink)?;
        self.record_at(sink, &before, node.span());
        // A group's children were checked one by one; inside a define, coordinates are
        // the object's own, checked where an instance places it.
        if ty != Ty::Group && !sink.in_define() {
            self.check_placed(mark, first_instance, ty, node.get_ref().ty.span())?;
        }
        Ok(())
    }

    /// The body of [`Builder::walk`]: place node `node` of type `ty`, whose own material
    /// is `explicit`, in the context `inner` it passes to its children (its transform
    /// and the material it inherits or gives).
    fn place(
        &mut self,
        node: &'a Spanned<ObjectDef>,
        ty: Ty,
        explicit: Option<u32>,
        inner: Ctx,
        sink: &mut Sink,
    ) -> R<()> {
        let x = inner.xform;
        match ty {
            Ty::Group => self.group(node, inner, sink),
            Ty::Instance => self.instance(node, inner, sink),
            Ty::Csg(op) => {
                let m = self.material_or_fallback(inner.material, sink);
                self.csg(node, op, x, m, sink)
            }
            Ty::Include => self.include(node, x, explicit, sink),
            Ty::Triangle | Ty::Polygon => {
                let m = self.material_or_fallback(inner.material, sink);
                self.polygon(node, ty, &x, m, sink)
            }
            Ty::Mesh => {
                let m = self.material_or_fallback(inner.material, sink);
                self.mesh(node, &x, m, sink)
            }
            Ty::Bezier => {
                let m = self.material_or_fallback(inner.material, sink);
                self.bezier(node, &x, m, sink)
            }
            Ty::Analytic(t) => {
                let m = self.material_or_fallback(inner.material, sink);
                let (at, rest) = split_translation(&x);
                let shape = self.analytic(node, t, at)?;
                self.warn_spindle(node);
                self.place_shape(shape, &rest, m, node.get_ref().ty.span(), sink)
            }
        }
    }

    /// `group`: its children, each placed in turn.
    fn group(&mut self, node: &'a Spanned<ObjectDef>, inner: Ctx, sink: &mut Sink) -> R<()> {
        let children = self.need(&node.get_ref().children, "children", node, Ty::Group)?;
        for c in self.non_empty(children, "children", Ty::Group, "at least one child")? {
            self.walk(c, inner, sink)?;
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
        // The range is the world's: the frame's bounds moved back by its origin.
        let o = self.origin;
        let check = |b: &Aabb| {
            let world = |p: Vec3| (p.as_dvec3() + o).as_vec3();
            let b = if b.is_finite() {
                Aabb::from_points(world(b.min), world(b.max))
            } else {
                *b
            };
            range::check_bounds(&what, &b).map_err(|e| self.err(span.clone(), e.to_string()))
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

    /// Add an analytic primitive under transform `x` (see the module notes).
    pub(super) fn place_shape(
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
        if let Some(baked) = shape.bake(x) {
            Self::geometry(&mut self.geometry, sink).add_shape(baked, material);
            return Ok(());
        }
        let xform = self.check_invertible(x, span.clone())?;
        match sink {
            Sink::Top => {
                self.instance_shape(shape, xform, material);
                Ok(())
            }
            Sink::Object(g) => {
                let csg = self.transformed_solid(shape, xform, span)?;
                g.add_shape(csg, material);
                Ok(())
            }
        }
    }

    /// At the top level: `shape` as an object of its own, placed by an instance.
    fn instance_shape(&mut self, shape: Shape, xform: Xform, material: u32) {
        let mut object = Geometry::default();
        object.add_shape(shape, material);
        self.objects.push(object);
        self.instances.push(Instance {
            object: self.objects.len() as u32 - 1,
            xform,
            material,
        });
    }

    /// Inside a define: the closed solid `shape` under `xform` as a one-leaf CSG (an
    /// open surface is refused).
    fn transformed_solid(&self, shape: Shape, xform: Xform, span: Range<usize>) -> R<Shape> {
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
        Ok(Shape::Csg(Arc::new(csg)))
    }
}
