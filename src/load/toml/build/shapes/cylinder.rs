//! `type = "cylinder"`: a closed cylinder (a capped cone of equal radii) from its
//! `base` point, `axis`, `height` and `radius`.

use super::super::super::format::{ObjectDef, Spanned};
use super::super::types::Ty;
use super::super::{Builder, R};
use super::capped_cone::{frame, shape};
use super::{AnalyticType, At};
use crate::geometry::{CappedCone, Shape};

pub(super) const TYPE: AnalyticType = AnalyticType {
    name: "cylinder",
    keys: &["base", "axis", "height", "radius"],
    build,
    #[cfg(test)]
    example: "base = [0, 0, 0]\naxis = [0, 1, 0]\nheight = 1\nradius = 1",
};

fn build(b: &Builder<'_, '_>, node: &Spanned<ObjectDef>, ty: Ty, at: At) -> R<Shape> {
    let o = node.get_ref();
    let (base, axis, height) = frame(b, node, ty, at)?;
    let r = b.need(&o.radius, "radius", node, ty)?;
    let r = b.positive(r, "cylinder `radius`")? as f32;
    shape(b, node, ty, CappedCone::cylinder(base, axis, height, r))
}
