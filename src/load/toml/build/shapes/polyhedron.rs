//! `type = "polyhedron"`: a convex polyhedron given in one of three ways: the
//! half-spaces of its `planes`, a regular `preset` (with `center` and `radius`), or a
//! right prism of `sides` sides (with `center`, `radius` and `height`).

use super::super::super::format::{ObjectDef, Real, Spanned};
use super::super::types::Ty;
use super::super::{Builder, R, did_you_mean, f32v};
use super::{AnalyticType, At, from_constructor};
use crate::geometry::{Polyhedron, Shape};
use crate::math::Vec3;
use glam::DVec3;
use std::ops::Range;
use std::sync::Arc;

pub(super) const TYPE: AnalyticType = AnalyticType {
    name: "polyhedron",
    keys: &["planes", "preset", "center", "radius", "sides", "height"],
    build,
    #[cfg(test)]
    example: "preset = \"octahedron\"\nradius = 1",
};

fn build(b: &Builder<'_, '_>, node: &Spanned<ObjectDef>, ty: Ty, at: At) -> R<Shape> {
    let o = node.get_ref();
    let center = o
        .center
        .as_ref()
        .map_or(at.point(&[Real(0.0); 3]), |c| at.point(c.get_ref()));
    let p = match (&o.planes, &o.preset, &o.sides) {
        (Some(planes), None, None) => from_planes(b, o, planes, ty, at)?,
        (None, Some(name), None) => preset(b, node, name, center, ty)?,
        (None, None, Some(sides)) => prism(b, node, sides, center, ty)?,
        (None, None, None) => {
            return Err(b.err(
                node.span(),
                "missing key `planes`, `preset` or `sides` for a polyhedron",
            ));
        }
        _ => {
            return Err(b.err(
                second_way(node),
                "a polyhedron takes one of `planes`, `preset` or `sides`",
            ));
        }
    };
    Ok(Shape::Polyhedron(Arc::new(p)))
}

/// Where a polyhedron given in more than one way gives its second.
fn second_way(node: &Spanned<ObjectDef>) -> Range<usize> {
    let o = node.get_ref();
    [
        o.planes.as_ref().map(|v| v.span()),
        o.preset.as_ref().map(|v| v.span()),
        o.sides.as_ref().map(|v| v.span()),
    ]
    .into_iter()
    .flatten()
    .nth(1)
    .unwrap_or(node.span())
}

/// The intersection of the half-spaces a·x + b·y + c·z ≤ d of `planes`.
fn from_planes(
    b: &Builder<'_, '_>,
    o: &ObjectDef,
    planes: &Spanned<Vec<Spanned<[Real; 4]>>>,
    ty: Ty,
    at: At,
) -> R<Polyhedron> {
    if let Some((k, span)) = [
        ("center", o.center.as_ref().map(|v| v.span())),
        ("radius", o.radius.as_ref().map(|v| v.span())),
        ("height", o.height.as_ref().map(|v| v.span())),
    ]
    .into_iter()
    .find_map(|(k, s)| s.map(|s| (k, s)))
    {
        return Err(b.err(
            span,
            format!("`{k}` is for a preset or a prism, not a polyhedron given by `planes`"),
        ));
    }
    let mut list = Vec::with_capacity(planes.get_ref().len());
    for p in b.non_empty(planes, "planes", ty, "at least 4 planes")? {
        let [pa, pb, pc, d] = p.get_ref().map(|x| x.0);
        let n = DVec3::new(pa, pb, pc);
        if n == DVec3::ZERO {
            return Err(b.err(p.span(), "a plane's normal must not be zero"));
        }
        // n·(q + offset) ≤ d for the points q of the moved polyhedron.
        list.push((f32v(n), (d - n.dot(at.offset)) as f32));
    }
    Polyhedron::new(list).map_err(|e| b.err(planes.span(), from_constructor(ty, e)))
}

/// A regular polyhedron named `name` (any case) about `center`.
fn preset(
    b: &Builder<'_, '_>,
    node: &Spanned<ObjectDef>,
    name: &Spanned<String>,
    center: Vec3,
    ty: Ty,
) -> R<Polyhedron> {
    let o = node.get_ref();
    if let Some(h) = &o.height {
        return Err(b.err(h.span(), "`height` is for a prism (`sides`), not a preset"));
    }
    let n = name.get_ref().as_str();
    if !Polyhedron::PRESETS
        .iter()
        .any(|p| p.eq_ignore_ascii_case(n))
    {
        return Err(b.err(
            name.span(),
            format!(
                "unknown polyhedron preset `{n}`{}; presets: {}",
                did_you_mean(n, Polyhedron::PRESETS.iter().copied()),
                Polyhedron::PRESETS.join(", ")
            ),
        ));
    }
    let r = b.need(&o.radius, "radius", node, ty)?;
    let r = b.positive(r, "polyhedron `radius`")? as f32;
    Polyhedron::preset(n, center, r).map_err(|e| b.err(node.span(), from_constructor(ty, e)))
}

/// A right prism of `sides` sides about `center`.
fn prism(
    b: &Builder<'_, '_>,
    node: &Spanned<ObjectDef>,
    sides: &Spanned<u32>,
    center: Vec3,
    ty: Ty,
) -> R<Polyhedron> {
    let o = node.get_ref();
    let r = b.need(&o.radius, "radius", node, ty)?;
    let r = b.positive(r, "prism `radius`")? as f32;
    let h = b.need(&o.height, "height", node, ty)?;
    let h = b.positive(h, "prism `height`")? as f32;
    Polyhedron::prism(center, *sides.get_ref(), r, h)
        .map_err(|e| b.err(sides.span(), from_constructor(ty, e)))
}
