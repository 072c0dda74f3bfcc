//! `type = "sphere"`: a `center` and a `radius`.

use super::super::super::format::{ObjectDef, Spanned};
use super::super::types::Ty;
use super::super::{Builder, R};
use super::{AnalyticType, At};
use crate::geometry::{Shape, Sphere};

pub(super) const TYPE: AnalyticType = AnalyticType {
    name: "sphere",
    keys: &["center", "radius"],
    build,
    #[cfg(test)]
    example: "center = [0, 0, 0]\nradius = 1",
};

fn build(b: &Builder<'_, '_>, node: &Spanned<ObjectDef>, ty: Ty, at: At) -> R<Shape> {
    let o = node.get_ref();
    let c = at.point(b.need(&o.center, "center", node, ty)?.get_ref());
    let r = b.positive(b.need(&o.radius, "radius", node, ty)?, "sphere `radius`")?;
    Ok(Shape::Sphere(Sphere::new(c, r as f32)))
}
