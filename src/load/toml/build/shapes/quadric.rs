//! `type = "quadric"`: the surface F(x, y, z) = 0 of a general quadric given by its
//! ten `coefficients`, optionally clipped to a box (`clip`).

use super::super::super::format::{BoxDef, ObjectDef, Spanned};
use super::super::types::Ty;
use super::super::{Builder, R, f32v, v3};
use super::{AnalyticType, from_constructor};
use crate::geometry::{Quadric, Shape};
use crate::math::Aabb;
use std::sync::Arc;

pub(super) const TYPE: AnalyticType = AnalyticType {
    name: "quadric",
    keys: &["coefficients", "clip"],
    build,
};

fn build(b: &Builder<'_, '_>, node: &Spanned<ObjectDef>, ty: Ty) -> R<Shape> {
    let o = node.get_ref();
    let c = b.need(&o.coefficients, "coefficients", node, ty)?;
    let coeffs = c.get_ref().map(|x| x.0);
    let clip = match &o.clip {
        Some(bx) => Some(clip_box(b, bx)?),
        None => None,
    };
    let q = Quadric::new(coeffs, clip).map_err(|e| b.err(c.span(), from_constructor(ty, e)))?;
    Ok(Shape::Quadric(Arc::new(q)))
}

/// The clip box, whose `min` must be below its `max` on every axis.
fn clip_box(b: &Builder<'_, '_>, bx: &Spanned<BoxDef>) -> R<Aabb> {
    let (lo, hi) = (
        v3(bx.get_ref().min.get_ref()),
        v3(bx.get_ref().max.get_ref()),
    );
    if !lo.cmplt(hi).all() {
        return Err(b.err(
            bx.span(),
            format!("the clip box's `min` {lo} must be below its `max` {hi} on every axis"),
        ));
    }
    Ok(Aabb::from_points(f32v(lo), f32v(hi)))
}
