//! `type = "torus"`: a torus from its `center`, the `axis` it turns about, and its
//! `major_radius` (centre to tube centre) and `minor_radius` (the tube's).

use super::super::super::format::{ObjectDef, Spanned};
use super::super::types::Ty;
use super::super::{Builder, R, f32v};
use super::{AnalyticType, At, from_constructor};
use crate::geometry::{Shape, Torus};
use std::sync::Arc;

pub(super) const TYPE: AnalyticType = AnalyticType {
    name: "torus",
    keys: &["center", "axis", "major_radius", "minor_radius"],
    build,
};

fn build(b: &Builder<'_, '_>, node: &Spanned<ObjectDef>, ty: Ty, at: At) -> R<Shape> {
    let o = node.get_ref();
    let c = b.need(&o.center, "center", node, ty)?;
    let axis = b.direction(b.need(&o.axis, "axis", node, ty)?, "torus `axis`")?;
    let major = b.positive(
        b.need(&o.major_radius, "major_radius", node, ty)?,
        "`major_radius`",
    )?;
    let minor = b.positive(
        b.need(&o.minor_radius, "minor_radius", node, ty)?,
        "`minor_radius`",
    )?;
    let t = Torus::new(
        at.point(c.get_ref()),
        f32v(axis),
        major as f32,
        minor as f32,
    )
    .map_err(|e| b.err(node.span(), from_constructor(ty, e)))?;
    Ok(Shape::Torus(Arc::new(t)))
}
