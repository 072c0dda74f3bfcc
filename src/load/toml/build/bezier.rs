//! `bezier`: bicubic Bézier patches (given, or the built-in teapot), transformed (a
//! patch's control points transform with it) and then tessellated, so that the
//! tolerance is in final units.

use super::super::format::{ObjectDef, Spanned};
use super::objects::Sink;
use super::types::Ty;
use super::{Builder, R, did_you_mean, v3};
use crate::geometry::bezier::{BezierPatch, teapot_patches, tessellate};
use glam::DAffine3;

/// A bezier's default tessellation tolerance, relative to the diagonal of its control
/// points' bounding box.
const BEZIER_RELATIVE_TOLERANCE: f64 = 1e-3;

impl Builder<'_, '_> {
    pub(super) fn bezier(
        &mut self,
        node: &Spanned<ObjectDef>,
        x: &DAffine3,
        material: u32,
        sink: &mut Sink,
    ) -> R<()> {
        let o = node.get_ref();
        let mut patches = self.patches(node)?;
        transform_patches(&mut patches, x);
        // Points that overflowed would make the tolerance and the tessellation
        // meaningless; what they would have built lies outside the traceable range.
        if !all_finite(&patches) {
            return Err(self.err(
                o.ty.span(),
                "this bezier's control points are not finite under its transforms (they \
                 overflow)",
            ));
        }
        let tolerance = match &o.tolerance {
            Some(t) => self.positive(t, "bezier `tolerance`")?,
            None => default_tolerance(&patches)
                .ok_or_else(|| self.err(node.span(), "a bezier needs at least one patch"))?,
        };
        let mesh = tessellate(&patches, tolerance);
        let g = Self::geometry(&mut self.geometry, sink);
        for (i, tri) in mesh.triangles.iter().enumerate() {
            let n = tri.map(|k| mesh.normals[k as usize]);
            g.add_smooth_triangle(mesh.triangle(i), n, material);
        }
        Ok(())
    }

    /// The patches: `patches` (16 control points each) or a `builtin` set.
    fn patches(&self, node: &Spanned<ObjectDef>) -> R<Vec<BezierPatch>> {
        let o = node.get_ref();
        match (&o.patches, &o.builtin) {
            (Some(p), None) => Ok(self
                .non_empty(p, "patches", Ty::Bezier, "at least one patch")?
                .iter()
                .map(|q| {
                    let q = q.get_ref();
                    // Row by row: point 4·j + i is p[i][j], i along u.
                    BezierPatch::new(std::array::from_fn(|i| {
                        std::array::from_fn(|j| v3(&q[4 * j + i]))
                    }))
                })
                .collect()),
            (None, Some(b)) => match b.get_ref().as_str() {
                "teapot" => Ok(teapot_patches()),
                other => Err(self.err(
                    b.span(),
                    format!(
                        "unknown built-in patch set `{other}`{}; built-ins: teapot",
                        did_you_mean(other, ["teapot"])
                    ),
                )),
            },
            (Some(_), Some(b)) => {
                Err(self.err(b.span(), "a bezier takes `patches` or `builtin`, not both"))
            }
            (None, None) => Err(self.err(
                node.span(),
                "missing key `patches` (or `builtin`) for a bezier",
            )),
        }
    }
}

/// The patches' control points under `x`. A mirror turns a patch inside out; swapping
/// u and v turns it back.
fn transform_patches(patches: &mut [BezierPatch], x: &DAffine3) {
    let mirror = x.matrix3.determinant() < 0.0;
    for p in patches {
        let mut q = *p;
        for row in &mut q.p {
            for c in row.iter_mut() {
                *c = x.transform_point3(*c);
            }
        }
        *p = if mirror { q.transposed() } else { q };
    }
}

/// Whether every control point of `patches` is finite.
fn all_finite(patches: &[BezierPatch]) -> bool {
    patches
        .iter()
        .all(|p| p.p.iter().flatten().all(|c| c.is_finite()))
}

/// The default tolerance, relative to the diagonal of the control points' bounding box
/// (1 when the points coincide), always positive and finite; `None` without control
/// points, which have no extent to be relative to.
fn default_tolerance(patches: &[BezierPatch]) -> Option<f64> {
    let mut points = patches.iter().flat_map(|p| p.p.iter().flatten().copied());
    let first = points.next()?;
    let (lo, hi) = points.fold((first, first), |(lo, hi), c| (lo.min(c), hi.max(c)));
    let size = (hi - lo).length();
    Some(if size > 0.0 {
        (size * BEZIER_RELATIVE_TOLERANCE).min(f64::MAX)
    } else {
        1.0
    })
}
