//! Baking: an analytic primitive under a transform rewritten as a primitive of the same
//! kind in final coordinates, when that is exact (see the placement rules in the
//! [module notes](super)). Spheres, cones, oriented boxes, capped cones and tori bake
//! under similarities; axis-aligned boxes under diagonal linear parts; polyhedra,
//! unclipped quadrics and planes under any invertible transform; CSG solids never.

use super::f32v;
use super::transforms::similarity_scale;
use crate::geometry::{
    AaBox, CappedCone, Cone, OBox, Plane, Polyhedron, Quadric, Shape, Sphere, Torus,
};
use glam::{DAffine3, DMat4};
use std::sync::Arc;

/// `shape` under `m` as a shape of the same kind, when that is exact.
pub(super) fn bake(shape: &Shape, m: &DAffine3) -> Option<Shape> {
    match shape {
        Shape::Sphere(s) => sphere(s, m),
        Shape::Cone(c) => cone(c, m),
        Shape::Box(b) => aabox(b, m),
        Shape::OBox(b) => obox(b, m),
        Shape::CappedCone(c) => capped_cone(c, m),
        Shape::Polyhedron(p) => polyhedron(p, m),
        Shape::Quadric(q) => quadric(q, m),
        Shape::Plane(p) => plane(p, m),
        Shape::Torus(t) => torus(t, m),
        Shape::Csg(_) => None,
    }
}

fn sphere(s: &Sphere, m: &DAffine3) -> Option<Shape> {
    let k = similarity_scale(m)?;
    let r = (s.radius as f64 * k) as f32;
    Some(Shape::Sphere(Sphere {
        center: f32v(m.transform_point3(s.center.as_dvec3())),
        radius: r,
        inside_only: s.inside_only,
    }))
}

fn cone(c: &Cone, m: &DAffine3) -> Option<Shape> {
    let k = similarity_scale(m)?;
    let sign = if c.inside_only { -1.0 } else { 1.0 };
    Some(Shape::Cone(Cone::new(
        f32v(m.transform_point3(c.base.as_dvec3())),
        sign * (c.base_radius as f64 * k) as f32,
        f32v(m.transform_point3(c.apex.as_dvec3())),
        sign * (c.apex_radius as f64 * k) as f32,
    )))
}

/// Axis-aligned stays axis-aligned under a diagonal linear part.
fn aabox(b: &AaBox, m: &DAffine3) -> Option<Shape> {
    let l = m.matrix3;
    let diagonal = l.x_axis.y == 0.0
        && l.x_axis.z == 0.0
        && l.y_axis.x == 0.0
        && l.y_axis.z == 0.0
        && l.z_axis.x == 0.0
        && l.z_axis.y == 0.0;
    if !diagonal {
        return None;
    }
    let a = m.transform_point3(b.min().as_dvec3());
    let c = m.transform_point3(b.max().as_dvec3());
    AaBox::new(f32v(a.min(c)), f32v(a.max(c)))
        .ok()
        .map(Shape::Box)
}

fn obox(b: &OBox, m: &DAffine3) -> Option<Shape> {
    let k = similarity_scale(m)?;
    let axes = b.axes().map(|a| f32v((m.matrix3 * a.as_dvec3()) / k));
    OBox::from_axes(
        f32v(m.transform_point3(b.center().as_dvec3())),
        f32v(b.half_extents().as_dvec3() * k),
        axes,
    )
    .ok()
    .map(|b| Shape::OBox(Arc::new(b)))
}

fn capped_cone(c: &CappedCone, m: &DAffine3) -> Option<Shape> {
    let k = similarity_scale(m)?;
    CappedCone::new(
        f32v(m.transform_point3(c.base().as_dvec3())),
        f32v(m.matrix3 * c.axis().as_dvec3()),
        (c.height() as f64 * k) as f32,
        (c.base_radius() as f64 * k) as f32,
        (c.top_radius() as f64 * k) as f32,
    )
    .ok()
    .map(|c| Shape::CappedCone(Arc::new(c)))
}

/// Half-spaces n·x ≤ d map to n'·y ≤ d + n'·t with n' = M⁻ᵀn.
fn polyhedron(p: &Polyhedron, m: &DAffine3) -> Option<Shape> {
    let inv_t = m.matrix3.inverse().transpose();
    let planes = p
        .world_planes()
        .into_iter()
        .map(|(n, d)| {
            let n2 = inv_t * n;
            (f32v(n2), (d + n2.dot(m.translation)) as f32)
        })
        .collect();
    Polyhedron::new(planes)
        .ok()
        .map(|p| Shape::Polyhedron(Arc::new(p)))
}

/// F(L⁻¹(y − t)) about the origin t: the coefficients through L⁻¹ alone. A clipped
/// quadric does not bake (its clip box would not stay a box).
fn quadric(q: &Quadric, m: &DAffine3) -> Option<Shape> {
    if q.clip().is_some() {
        return None;
    }
    let [a, b, c, d, e, f, g, h, i, j] = q.coefficients();
    let qm = DMat4::from_cols_array_2d(&[[a, d, e, g], [d, b, f, h], [e, f, c, i], [g, h, i, j]]);
    let inv = DMat4::from_mat3(m.matrix3.inverse());
    let r = inv.transpose() * qm * inv;
    let k = |x: usize, y: usize| 0.5 * (r.col(x)[y] + r.col(y)[x]);
    let coeffs = [
        k(0, 0),
        k(1, 1),
        k(2, 2),
        k(0, 1),
        k(0, 2),
        k(1, 2),
        k(0, 3),
        k(1, 3),
        k(2, 3),
        k(3, 3),
    ];
    let t = m.translation;
    if !t.is_finite() {
        return None;
    }
    Quadric::about(f32v(t), coeffs, None)
        .ok()
        .map(|q| Shape::Quadric(Arc::new(q)))
}

fn plane(p: &Plane, m: &DAffine3) -> Option<Shape> {
    let n = p.normal().as_dvec3();
    let point = m.transform_point3(n * p.offset());
    let normal = m.matrix3.inverse().transpose() * n;
    Plane::from_point_normal(f32v(point), f32v(normal))
        .ok()
        .map(Shape::Plane)
}

fn torus(t: &Torus, m: &DAffine3) -> Option<Shape> {
    let k = similarity_scale(m)?;
    Torus::new(
        f32v(m.transform_point3(t.center().as_dvec3())),
        f32v(m.matrix3 * t.axis().as_dvec3()),
        (t.major_radius() as f64 * k) as f32,
        (t.minor_radius() as f64 * k) as f32,
    )
    .ok()
    .map(|t| Shape::Torus(Arc::new(t)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Vec3;
    use glam::DVec3;

    #[test]
    fn spheres_bake_under_similarities_only() {
        let s = Shape::Sphere(Sphere::new(Vec3::new(1.0, 0.0, 0.0), 2.0));
        let m = DAffine3::from_translation(DVec3::new(0.0, 5.0, 0.0))
            * DAffine3::from_scale(DVec3::splat(3.0))
            * DAffine3::from_axis_angle(DVec3::Z, std::f64::consts::FRAC_PI_2);
        let Some(Shape::Sphere(b)) = bake(&s, &m) else {
            panic!("not baked")
        };
        assert!(
            (b.center - Vec3::new(0.0, 8.0, 0.0)).length() < 1e-5,
            "{}",
            b.center
        );
        assert!((b.radius - 6.0).abs() < 1e-5);
        assert!(bake(&s, &DAffine3::from_scale(DVec3::new(1.0, 2.0, 3.0))).is_none());
    }
}
