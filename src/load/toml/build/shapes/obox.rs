//! `type = "obox"`: an oriented box from its `center`, its `size` (or `half_size`)
//! and its orientation, a `rotation` (a transform list of rotations) or three `axes`.

use super::super::super::format::{ObjectDef, Spanned, TransformList};
use super::super::types::Ty;
use super::super::{Builder, R, f32v, v3};
use super::{AnalyticType, At, from_constructor};
use crate::geometry::{OBox, Shape};
use crate::math::{Vec3, similarity_scale};
use glam::{DQuat, DVec3, Quat};
use std::sync::Arc;

pub(super) const TYPE: AnalyticType = AnalyticType {
    name: "obox",
    keys: &["center", "size", "half_size", "rotation", "axes"],
    build,
    #[cfg(test)]
    example: "center = [0, 0, 0]\nsize = [1, 2, 3]",
};

fn build(b: &Builder<'_, '_>, node: &Spanned<ObjectDef>, ty: Ty, at: At) -> R<Shape> {
    let o = node.get_ref();
    let center = at.point(b.need(&o.center, "center", node, ty)?.get_ref());
    let half = half_size(b, node)?;
    let obox = match (&o.rotation, &o.axes) {
        (Some(r), None) => OBox::new(center, half, rotation(b, r)?)
            .map_err(|e| b.err(r.span(), from_constructor(ty, e)))?,
        (None, Some(a)) => {
            let axes = a.get_ref().map(|v| f32v(v3(&v)));
            OBox::from_axes(center, half, axes)
                .map_err(|e| b.err(a.span(), from_constructor(ty, e)))?
        }
        (None, None) => OBox::new(center, half, Quat::IDENTITY)
            .map_err(|e| b.err(node.span(), from_constructor(ty, e)))?,
        (Some(_), Some(a)) => {
            return Err(b.err(a.span(), "an obox takes `rotation` or `axes`, not both"));
        }
    };
    Ok(Shape::OBox(Arc::new(obox)))
}

/// The half extents, from `size` or `half_size`.
fn half_size(b: &Builder<'_, '_>, node: &Spanned<ObjectDef>) -> R<Vec3> {
    let o = node.get_ref();
    match (&o.size, &o.half_size) {
        (Some(s), None) => Ok(b.positive3(s, "obox `size`")? * 0.5),
        (None, Some(h)) => b.positive3(h, "obox `half_size`"),
        (Some(_), Some(h)) => Err(b.err(h.span(), "an obox takes `size` or `half_size`, not both")),
        (None, None) => Err(b.err(
            node.span(),
            "missing key `size` (or `half_size`) for an obox",
        )),
    }
}

/// The orientation given by `rotation`, which must be a proper rotation.
fn rotation(b: &Builder<'_, '_>, r: &Spanned<TransformList>) -> R<Quat> {
    let m = b.transform_list(r)?;
    let det = m.matrix3.determinant();
    if m.translation != DVec3::ZERO
        || !similarity_scale(&m).is_some_and(|s| (s - 1.0).abs() <= 1e-6)
        || det < 0.0
    {
        return Err(b.err(
            r.span(),
            "an obox `rotation` must be made of rotations only",
        ));
    }
    Ok(DQuat::from_mat3(&m.matrix3).as_quat())
}
