//! `type = "capped_cone"`: a closed cone frustum from its `base` point, `axis`,
//! `height` and the radii at its base and top; and the frame it shares with
//! `cylinder`.

use super::super::super::format::{ObjectDef, Spanned};
use super::super::types::Ty;
use super::super::{Builder, R, f32v};
use super::{AnalyticType, At, from_constructor};
use crate::geometry::{CappedCone, Shape, ShapeError};
use crate::math::Vec3;
use std::sync::Arc;

pub(super) const TYPE: AnalyticType = AnalyticType {
    name: "capped_cone",
    keys: &["base", "axis", "height", "base_radius", "top_radius"],
    build,
    #[cfg(test)]
    example: "base = [0, 0, 0]\naxis = [0, 1, 0]\nheight = 1\nbase_radius = 1\ntop_radius = 0.5",
};

fn build(b: &Builder<'_, '_>, node: &Spanned<ObjectDef>, ty: Ty, at: At) -> R<Shape> {
    let o = node.get_ref();
    let (base, axis, height) = frame(b, node, ty, at)?;
    let rb = b.need(&o.base_radius, "base_radius", node, ty)?;
    let rt = b.need(&o.top_radius, "top_radius", node, ty)?;
    let (rb_v, rt_v) = (
        b.non_negative(rb, "`base_radius`")? as f32,
        b.non_negative(rt, "`top_radius`")? as f32,
    );
    if rb_v == 0.0 && rt_v == 0.0 {
        return Err(b.err(rt.span(), "capped cone radii must not both be zero"));
    }
    shape(b, node, ty, CappedCone::new(base, axis, height, rb_v, rt_v))
}

/// The `base` point, unit `axis` and `height` of a capped cone or cylinder.
pub(super) fn frame(
    b: &Builder<'_, '_>,
    node: &Spanned<ObjectDef>,
    ty: Ty,
    at: At,
) -> R<(Vec3, Vec3, f32)> {
    let o = node.get_ref();
    let base = at.point(b.need(&o.base, "base", node, ty)?.get_ref());
    let axis = f32v(b.direction(b.need(&o.axis, "axis", node, ty)?, "`axis`")?);
    let height = b.positive(b.need(&o.height, "height", node, ty)?, "`height`")? as f32;
    Ok((base, axis, height))
}

/// The shape of a capped cone or cylinder, or the constructor's error at the object.
pub(super) fn shape(
    b: &Builder<'_, '_>,
    node: &Spanned<ObjectDef>,
    ty: Ty,
    c: Result<CappedCone, ShapeError>,
) -> R<Shape> {
    let c = c.map_err(|e| b.err(node.span(), from_constructor(ty, e)))?;
    Ok(Shape::CappedCone(Arc::new(c)))
}
