//! `type = "quadric"`: the surface F(x, y, z) = 0 of a general quadric given by its
//! ten `coefficients`, optionally clipped to a box (`clip`).

use super::super::super::format::{BoxDef, ObjectDef, Spanned};
use super::super::types::Ty;
use super::super::{Builder, R, f32v, v3};
use super::{AnalyticType, At, from_constructor};
use crate::geometry::{Quadric, Shape};
use crate::math::Aabb;
use std::sync::Arc;

pub(super) const TYPE: AnalyticType = AnalyticType {
    name: "quadric",
    keys: &["coefficients", "clip"],
    build,
    #[cfg(test)]
    example: "coefficients = [1, 1, 1, 0, 0, 0, 0, 0, 0, -1]",
};

fn build(b: &Builder<'_, '_>, node: &Spanned<ObjectDef>, ty: Ty, at: At) -> R<Shape> {
    let o = node.get_ref();
    let c = b.need(&o.coefficients, "coefficients", node, ty)?;
    let coeffs = c.get_ref().map(|x| x.0);
    let clip = match &o.clip {
        Some(bx) => Some(clip_box(b, bx, at)?),
        None => None,
    };
    let coeffs = translated(coeffs, at.offset);
    let q = Quadric::new(coeffs, clip).map_err(|e| b.err(c.span(), from_constructor(ty, e)))?;
    Ok(Shape::Quadric(Arc::new(q)))
}

/// The clip box, whose `min` must be below its `max` on every axis.
fn clip_box(b: &Builder<'_, '_>, bx: &Spanned<BoxDef>, at: At) -> R<Aabb> {
    let (lo, hi) = (
        v3(bx.get_ref().min.get_ref()),
        v3(bx.get_ref().max.get_ref()),
    );
    if !lo.cmplt(hi).all() {
        return Err(b.err(
            bx.span(),
            format!("the clip box's `min` {lo} must be below its `max` {hi} on every axis"),
        ));
    }
    Ok(Aabb::from_points(
        f32v(lo + at.offset),
        f32v(hi + at.offset),
    ))
}

/// The coefficients of `F(q − by)`, for the quadric `F` of `c` (the layout of
/// [`Quadric::new`]): the same surface with its points moved by `by`, in double
/// precision so that a quadric far from the origin keeps its shape.
fn translated(c: [f64; 10], by: glam::DVec3) -> [f64; 10] {
    if by == glam::DVec3::ZERO {
        return c;
    }
    let [a, b, cc, d, e, f, g, h, i, j] = c;
    let (x, y, z) = (-by.x, -by.y, -by.z);
    // ∇F/2 at the offset gives the new linear terms, F(offset) the new constant.
    let gx = a * x + d * y + e * z + g;
    let gy = d * x + b * y + f * z + h;
    let gz = e * x + f * y + cc * z + i;
    let value = x * (gx + g) + y * (gy + h) + z * (gz + i) + j;
    [a, b, cc, d, e, f, gx, gy, gz, value]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The moved quadric at q is the original at q − by.
    #[test]
    fn translated_coefficients_describe_the_moved_quadric() {
        let c = [1.0, 2.0, -0.5, 0.3, -0.2, 0.1, 0.7, -1.1, 0.4, -2.0];
        let f = |c: &[f64; 10], p: glam::DVec3| {
            let [a, b, cc, d, e, f, g, h, i, j] = *c;
            let (x, y, z) = (p.x, p.y, p.z);
            a * x * x
                + b * y * y
                + cc * z * z
                + 2.0 * (d * x * y + e * x * z + f * y * z)
                + 2.0 * (g * x + h * y + i * z)
                + j
        };
        let by = glam::DVec3::new(3.0, -1.5, 0.25);
        let t = translated(c, by);
        for q in [
            glam::DVec3::ZERO,
            glam::DVec3::new(1.0, 2.0, -3.0),
            glam::DVec3::splat(0.5),
        ] {
            assert!((f(&t, q) - f(&c, q - by)).abs() < 1e-12, "{q}");
        }
    }
}
