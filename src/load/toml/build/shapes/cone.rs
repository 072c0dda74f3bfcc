//! `type = "cone"`: an open cone (NFF's `c`) from its `base` and `apex` points and
//! their radii; the `apex_radius` defaults to 0 (a point).

use super::super::super::format::{ObjectDef, Spanned};
use super::super::types::Ty;
use super::super::{Builder, R};
use super::{AnalyticType, At};
use crate::geometry::{Cone, Shape};

pub(super) const TYPE: AnalyticType = AnalyticType {
    name: "cone",
    keys: &["base", "base_radius", "apex", "apex_radius"],
    build,
    #[cfg(test)]
    example: "base = [0, 0, 0]\nbase_radius = 1\napex = [0, 1, 0]",
};

fn build(b: &Builder<'_, '_>, node: &Spanned<ObjectDef>, ty: Ty, at: At) -> R<Shape> {
    let o = node.get_ref();
    let base = b.need(&o.base, "base", node, ty)?;
    let rb = b.need(&o.base_radius, "base_radius", node, ty)?;
    let apex = b.need(&o.apex, "apex", node, ty)?;
    let rb_v = b.non_negative(rb, "cone `base_radius`")?;
    let ra_v = match &o.apex_radius {
        Some(ra) => b.non_negative(ra, "cone `apex_radius`")?,
        None => 0.0,
    };
    if rb_v == 0.0 && ra_v == 0.0 {
        return Err(b.err(rb.span(), "cone radii must not both be zero"));
    }
    let (base, apex_at) = (at.point(base.get_ref()), at.point(apex.get_ref()));
    if base == apex_at {
        return Err(b.err(apex.span(), "cone `apex` equals its `base`"));
    }
    Ok(Shape::Cone(Cone::new(
        base,
        rb_v as f32,
        apex_at,
        ra_v as f32,
    )))
}
