//! `type = "torus"`: a torus from its `center`, the `axis` it turns about, and its
//! `major_radius` (centre to tube centre) and `minor_radius` (the tube's).
//!
//! A spindle torus, whose tube is wider than its centre circle, passes through its axis
//! and intersects itself: it is drawn (its outer surface) with a warning, and refused as
//! a CSG operand, where what is inside a solid must be clear.

use super::super::super::format::{ObjectDef, Spanned};
use super::super::types::Ty;
use super::super::{Builder, DisplayPrefix, LOG_TARGET, R, f32v};
use super::{AnalyticType, At, from_constructor};
use crate::geometry::{Shape, Torus};
use std::sync::Arc;

pub(super) const TYPE: AnalyticType = AnalyticType {
    name: "torus",
    keys: &["center", "axis", "major_radius", "minor_radius"],
    build,
    #[cfg(test)]
    example: "center = [0, 0, 0]\naxis = [0, 1, 0]\nmajor_radius = 2\nminor_radius = 0.5",
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

/// The radii (major, minor) of `o` when it is a spindle torus: a minor radius above the
/// major one (the transforms scale both alike).
fn spindle(o: &ObjectDef) -> Option<(f64, f64)> {
    if o.ty.get_ref() != TYPE.name {
        return None;
    }
    let major = o.major_radius.as_ref()?.get_ref().0;
    let minor = o.minor_radius.as_ref()?.get_ref().0;
    (minor > major).then_some((major, minor))
}

/// What is said of a spindle torus, before why it matters.
fn spindle_message(major: f64, minor: f64) -> String {
    format!(
        "a spindle torus (minor radius {minor} > major radius {major}) passes through its \
         axis and intersects itself"
    )
}

impl Builder<'_, '_> {
    /// A warning when `node` is a spindle torus: only its outer surface is drawn.
    pub(in super::super) fn warn_spindle(&self, node: &Spanned<ObjectDef>) {
        let o = node.get_ref();
        if let Some((major, minor)) = spindle(o) {
            log::warn!(
                target: LOG_TARGET,
                "{}: {}; only its outer surface is drawn",
                self.at(o.ty.span()).display_prefix(),
                spindle_message(major, minor)
            );
        }
    }

    /// An error when `node`, a CSG operand, is a spindle torus.
    pub(in super::super) fn refuse_spindle(&self, node: &Spanned<ObjectDef>) -> R<()> {
        match spindle(node.get_ref()) {
            Some((major, minor)) => Err(self.err(
                node.get_ref().ty.span(),
                format!(
                    "{}: it cannot be a CSG operand, as what is inside it is not clear",
                    spindle_message(major, minor)
                ),
            )),
            None => Ok(()),
        }
    }
}
