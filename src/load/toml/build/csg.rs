//! Constructive solid geometry: `union`, `intersection` and `difference` of closed
//! solids, folded left over their children into a [`CsgTree`]. Operands may be
//! analytic solids, nested set operations and instances of defines (copied into the
//! tree); each may give its own material and transform.

use super::super::format::{ObjectDef, Spanned};
use super::objects::Sink;
use super::objects::split_translation;
use super::types::Ty;
use super::{Builder, R, article};
use crate::geometry::{Csg, CsgOp, CsgTree, Primitive, Shape};
use glam::{DAffine3, DMat3};
use std::sync::Arc;

impl<'a> Builder<'a, '_> {
    /// A set operation `op` placed under `x`: at the top level a transformed CSG is an
    /// instance; inside a define the transform goes into the tree.
    pub(super) fn csg(
        &mut self,
        node: &'a Spanned<ObjectDef>,
        op: CsgOp,
        x: DAffine3,
        material: u32,
        sink: &mut Sink,
    ) -> R<()> {
        let span = node.get_ref().ty.span();
        // A translation (the scene's frame, `translate` steps) goes into the leaves.
        let instanced = !sink.in_define() && x.matrix3 != DMat3::IDENTITY;
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

    /// The left fold of a CSG node's children (at least two) by `op`.
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
        self.non_empty(children, "children", ty, "at least 2 children")?;
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
                let (at, rest) = split_translation(&rel);
                let shape = self.analytic(node, t, at)?;
                self.refuse_spindle(node)?;
                self.csg_leaf(node, shape, rest, material)
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

    /// A leaf: the closed solid `shape` of `node` under `rel`, baked when that is exact.
    fn csg_leaf(
        &self,
        node: &Spanned<ObjectDef>,
        shape: Shape,
        rel: DAffine3,
        material: Option<u32>,
    ) -> R<CsgTree> {
        let span = node.get_ref().ty.span();
        if !shape.is_solid() {
            return Err(self.err(
                span,
                format!(
                    "{} is not a closed solid and cannot be a CSG operand",
                    article(shape.kind().singular())
                ),
            ));
        }
        let leaf = |shape| CsgTree::Leaf { shape, material };
        if rel == DAffine3::IDENTITY {
            Ok(leaf(shape))
        } else if let Some(baked) = shape.bake(&rel) {
            Ok(leaf(baked))
        } else {
            let xform = self.check_invertible(&rel, span)?;
            Ok(CsgTree::Transform {
                xform,
                child: Box::new(leaf(shape)),
            })
        }
    }
}
