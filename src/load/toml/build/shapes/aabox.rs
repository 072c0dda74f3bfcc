//! `type = "box"`: an axis-aligned box from its `min` and `max` corners.

use super::super::super::format::{ObjectDef, Spanned};
use super::super::types::Ty;
use super::super::{Builder, R};
use super::{AnalyticType, At, from_constructor};
use crate::geometry::{AaBox, Shape};

pub(super) const TYPE: AnalyticType = AnalyticType {
    name: "box",
    keys: &["min", "max"],
    build,
    #[cfg(test)]
    example: "min = [0, 0, 0]\nmax = [1, 1, 1]",
};

fn build(b: &Builder<'_, '_>, node: &Spanned<ObjectDef>, ty: Ty, at: At) -> R<Shape> {
    let o = node.get_ref();
    let min = b.need(&o.min, "min", node, ty)?;
    let max = b.need(&o.max, "max", node, ty)?;
    let aabox = AaBox::new(at.point(min.get_ref()), at.point(max.get_ref()))
        .map_err(|e| b.err(max.span(), from_constructor(ty, e)))?;
    Ok(Shape::Box(aabox))
}
