//! Transforms: the steps of a `transform` list (`translate`, `rotate`, `scale`,
//! `mirror`, `matrix`) composed into one affine map, checked to be invertible in the single
//! precision the renderer uses.

use super::super::format::{
    MirrorDef, ObjectDef, Real, Scale, Spanned, TransformList, TransformStep,
};
use super::{Builder, R, v3};
use crate::math::Xform;
use glam::{Affine3A, DAffine3, DMat3, DVec3};
use std::ops::Range;

/// `m` in single precision.
fn affine_f32(m: &DAffine3) -> Affine3A {
    Affine3A::from_mat3_translation(m.matrix3.as_mat3(), m.translation.as_vec3())
}

impl Builder<'_, '_> {
    /// An affine matrix given as 4 rows of 4.
    pub(super) fn matrix(&self, m: &Spanned<[[Real; 4]; 4]>) -> R<DAffine3> {
        let r = m.get_ref().map(|row| row.map(|x| x.0));
        if r[3] != [0.0, 0.0, 0.0, 1.0] {
            let [a, b, c, d] = r[3];
            return Err(self.err(
                m.span(),
                format!(
                    "the last row of a matrix must be [0, 0, 0, 1] (only affine transforms), \
                     found [{a}, {b}, {c}, {d}]"
                ),
            ));
        }
        let col = |i: usize| DVec3::new(r[0][i], r[1][i], r[2][i]);
        let x = DAffine3::from_mat3_translation(DMat3::from_cols(col(0), col(1), col(2)), col(3));
        self.check_invertible(&x, m.span())?;
        Ok(x)
    }

    /// `m` as the renderer's transform, refused (at `span`) unless invertible.
    pub(super) fn check_invertible(&self, m: &DAffine3, span: Range<usize>) -> R<Xform> {
        Xform::new(affine_f32(m)).map_err(|e| self.err(span, format!("bad transform: {e}")))
    }

    /// One step of a transform list, which gives exactly one operation.
    fn step(&self, st: &Spanned<TransformStep>) -> R<DAffine3> {
        let t = st.get_ref();
        self.check_one_operation(st)?;
        if let (Some(a), None) = (&t.angle, &t.rotate) {
            return Err(self.err(a.span(), "`angle` goes with `rotate`"));
        }
        if let Some(v) = &t.translate {
            return Ok(DAffine3::from_translation(v3(v.get_ref())));
        }
        if let Some(axis) = &t.rotate {
            let u = self.direction(axis, "the rotation axis")?;
            let Some(angle) = &t.angle else {
                return Err(self.err(st.span(), "`rotate` needs `angle` (degrees)"));
            };
            return Ok(DAffine3::from_axis_angle(u, angle.get_ref().0.to_radians()));
        }
        if let Some(s) = &t.scale {
            return self.scale(s);
        }
        if let Some(m) = &t.mirror {
            return self.mirror(m.get_ref());
        }
        match &t.matrix {
            Some(m) => self.matrix(m),
            None => unreachable!("one operation is present"),
        }
    }

    /// Refuse a step with no operation or more than one.
    fn check_one_operation(&self, st: &Spanned<TransformStep>) -> R<()> {
        let t = st.get_ref();
        let ops: Vec<&str> = [
            ("translate", t.translate.is_some()),
            ("rotate", t.rotate.is_some()),
            ("scale", t.scale.is_some()),
            ("mirror", t.mirror.is_some()),
            ("matrix", t.matrix.is_some()),
        ]
        .into_iter()
        .filter_map(|(k, p)| p.then_some(k))
        .collect();
        if ops.len() == 1 {
            return Ok(());
        }
        let found = if ops.is_empty() {
            "none".to_string()
        } else {
            ops.join(", ")
        };
        Err(self.err(
            st.span(),
            format!(
                "a transform step takes exactly one of `translate`, `rotate` (with \
                 `angle`), `scale`, `mirror` or `matrix`; found {found}"
            ),
        ))
    }

    /// A `mirror` step: the reflection `p ↦ p − 2((p − q)·n) n` about the plane through
    /// `q` with unit normal `n`.
    fn mirror(&self, m: &MirrorDef) -> R<DAffine3> {
        let n = self.direction(&m.normal, "the mirror's normal")?;
        let q = m.point.as_ref().map_or(DVec3::ZERO, |p| v3(p.get_ref()));
        let linear = DMat3::IDENTITY - 2.0 * DMat3::from_cols(n * n.x, n * n.y, n * n.z);
        Ok(DAffine3::from_mat3_translation(linear, 2.0 * q.dot(n) * n))
    }

    /// A `scale` step: one factor for all axes or one per axis, none zero.
    fn scale(&self, s: &Spanned<Scale>) -> R<DAffine3> {
        let k = match s.get_ref() {
            Scale::Uniform(k) => DVec3::splat(k.0),
            Scale::Axes(v) => v3(v),
        };
        if k.min_element() * k.max_element() == 0.0 || k.abs().min_element() == 0.0 {
            return Err(self.err(
                s.span(),
                format!("scale factors must not be zero, found {k}"),
            ));
        }
        let x = DAffine3::from_scale(k);
        self.check_invertible(&x, s.span())?;
        Ok(x)
    }

    /// The composition of a transform list: the first step applied first.
    pub(super) fn transform_list(&self, list: &Spanned<TransformList>) -> R<DAffine3> {
        let mut m = DAffine3::IDENTITY;
        for st in list.get_ref() {
            m = self.step(st)? * m;
        }
        self.check_invertible(&m, list.span())?;
        Ok(m)
    }

    /// An object's own transform (the identity when it has none).
    pub(super) fn local_xform(&self, o: &ObjectDef) -> R<DAffine3> {
        match &o.transform {
            Some(t) => self.transform_list(t),
            None => Ok(DAffine3::IDENTITY),
        }
    }
}
