//! `type = "plane"`: an infinite plane through a `point`, facing its `normal`.

use super::super::super::format::{ObjectDef, Spanned};
use super::super::types::Ty;
use super::super::{Builder, R, f32v};
use super::{AnalyticType, At, from_constructor};
use crate::geometry::{Plane, Shape};

pub(super) const TYPE: AnalyticType = AnalyticType {
    name: "plane",
    keys: &["point", "normal"],
    build,
    #[cfg(test)]
    example: "point = [0, 0, 0]\nnormal = [0, 1, 0]",
};

fn build(b: &Builder<'_, '_>, node: &Spanned<ObjectDef>, ty: Ty, at: At) -> R<Shape> {
    let o = node.get_ref();
    let p = b.need(&o.point, "point", node, ty)?;
    let n = b.need(&o.normal, "normal", node, ty)?;
    let n = b.direction(n, "plane `normal`")?;
    let plane = Plane::from_point_normal(at.point(p.get_ref()), f32v(n))
        .map_err(|e| b.err(node.span(), from_constructor(ty, e)))?;
    Ok(Shape::Plane(plane))
}
