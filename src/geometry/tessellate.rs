//! Tessellation of analytic shapes, for the radiosity pass: what
//! [`Primitive::tessellate`](super::Primitive::tessellate) returns, and the tools each
//! kind builds it with in its own file.
//!
//! Spheres, open and capped cones and cylinders, axis-aligned and oriented boxes and
//! convex polyhedra become convex planar faces (counterclockwise seen from their front,
//! the outside, or the inside for an inside-only sphere or cone); the radiosity mesh
//! splits each face into a fan of source triangles and meshes those like any other
//! triangle. The curved surfaces use a grid whose cells are about one patch across:
//! latitude × longitude on a sphere (y up, as its texture parameterisation), angle ×
//! height on a cone (`revolution`). Their faces are inscribed in the true surface;
//! each face records how far it lies inside it at most ([`Tessellation::depth`]), and
//! the visibility rays of its elements start that far out, so that the true surface
//! does not shadow its own elements. CSG, quadrics, planes and tori are not tessellated:
//! they only occlude (ray casting) and are shaded by the Whitted renderer.
//!
//! The display maps a hit on the true surface back to its element: [`Lookup`] finds the
//! face from the hit point (grid cell, cap, or nearest plane), the face's fan triangle
//! that best contains the point's projection gives barycentric coordinates, and the
//! triangle's quadtree gives the element and the Gouraud-interpolated radiosity there.

use crate::math::{Frame, Vec3};
use std::f32::consts::{PI, TAU};

/// How a point on a shape finds its face.
#[derive(Clone, Debug, PartialEq)]
pub enum Lookup {
    /// A sphere's `nu × nv` latitude–longitude cells; face `j·nu + i`.
    Sphere {
        /// Centre.
        center: Vec3,
        /// Cells around the y axis.
        nu: u32,
        /// Cells from the −y pole to the +y pole.
        nv: u32,
    },
    /// `nu` angles × `nv` heights on a surface of revolution (face `j·nu + i`), then,
    /// with `caps`, the base and the top cap.
    Revolution {
        /// Centre of the base.
        base: Vec3,
        /// Unit axis.
        axis: Vec3,
        /// Length along the axis.
        height: f32,
        /// Cells around the axis.
        nu: u32,
        /// Cells along the axis.
        nv: u32,
        /// Whether the two caps follow the grid's faces.
        caps: bool,
    },
    /// Planar faces, unit normal and offset (`n·x = d`) each: the face whose plane is
    /// nearest the point.
    Planes(Vec<(Vec3, f32)>),
}

impl Lookup {
    /// The face of the point `p` with geometric normal `ng` (any length or sign).
    pub fn face(&self, p: Vec3, ng: Vec3) -> usize {
        match *self {
            Lookup::Sphere { center, nu, nv } => {
                let q = (p - center).normalize_or_zero();
                let u = wrap(q.x.atan2(q.z) / TAU);
                let v = 1.0 - q.y.clamp(-1.0, 1.0).acos() / PI;
                cell(v, nv) * nu as usize + cell(u, nu)
            }
            Lookup::Revolution {
                base,
                axis,
                height,
                nu,
                nv,
                caps,
            } => {
                let q = p - base;
                let h = q.dot(axis);
                let n = ng.normalize_or_zero();
                if caps && n.dot(axis).abs() > 0.999 {
                    let grid = (nu * nv) as usize;
                    if h < 1e-3 * height {
                        return grid;
                    }
                    if h > (1.0 - 1e-3) * height {
                        return grid + 1;
                    }
                }
                let f = Frame::from_z(axis);
                let u = wrap(q.dot(f.y).atan2(q.dot(f.x)) / TAU);
                cell(h / height, nv) * nu as usize + cell(u, nu)
            }
            Lookup::Planes(ref planes) => {
                let mut best = (f32::INFINITY, 0);
                for (k, &(n, d)) in planes.iter().enumerate() {
                    let dist = (n.dot(p) - d).abs();
                    if dist < best.0 {
                        best = (dist, k);
                    }
                }
                best.1
            }
        }
    }
}

/// `x` in `[0, 1)`, for an angle in turns from `atan2`.
fn wrap(x: f32) -> f32 {
    if x < 0.0 { x + 1.0 } else { x }
}

/// The cell of `x ∈ [0, 1]` among `n`.
fn cell(x: f32, n: u32) -> usize {
    ((x * n as f32).floor().max(0.0) as usize).min(n as usize - 1)
}

/// A shape as convex planar faces.
#[derive(Clone, Debug, PartialEq)]
pub struct Tessellation {
    /// Convex planar polygons, counterclockwise seen from the front; a face may be
    /// empty (a cap of radius 0) so that face indices follow [`Lookup`].
    pub faces: Vec<Vec<Vec3>>,
    /// Per face: the largest distance between the face and the true surface in front
    /// of it (0 for exact planar faces).
    pub depth: Vec<f32>,
    /// Face lookup for the display.
    pub lookup: Lookup,
    /// Whether the faces approximate one smooth surface (their shared corners are one
    /// vertex for the display) rather than meeting at creases.
    pub smooth: bool,
    /// Whether the shape is an open surface seen from both sides (an open cone): only
    /// its front side is meshed.
    pub open: bool,
}

/// Cells along a length `len` for patches of `patch`, at least `min` (for the shape's
/// geometric accuracy) and at most `max`.
pub(super) fn cells(len: f32, patch: f32, min: u32, max: u32) -> u32 {
    let n = (len / patch).ceil();
    if n.is_finite() {
        (n as u32).clamp(min, max)
    } else {
        max
    }
}

/// Orient `poly` counterclockwise about `front` and drop repeated corners (poles and
/// apices); empty when fewer than three corners remain.
pub(super) fn oriented(mut poly: Vec<Vec3>, front: Vec3) -> Vec<Vec3> {
    poly.dedup();
    while poly.len() > 1 && poly.first() == poly.last() {
        poly.pop();
    }
    if poly.len() < 3 {
        return Vec::new();
    }
    if newell(&poly).dot(front) < 0.0 {
        poly.reverse();
    }
    poly
}

/// The Newell normal of a polygon (twice its area along its normal).
pub fn newell(poly: &[Vec3]) -> Vec3 {
    let mut n = Vec3::ZERO;
    for (k, &a) in poly.iter().enumerate() {
        let b = poly[(k + 1) % poly.len()];
        n += (a - poly[0]).cross(b - poly[0]);
    }
    n
}

/// Reverse every face when the inside is the front.
pub(super) fn flip(faces: &mut [Vec<Vec3>], inside: bool) {
    if inside {
        for f in faces {
            f.reverse();
        }
    }
}

/// How far a face inscribed in the sphere of centre `c` and radius `r` lies inside it
/// at most.
pub(super) fn inscribed_depth(face: &[Vec3], c: Vec3, r: f32) -> f32 {
    if face.len() < 3 {
        return 0.0;
    }
    let n = newell(face).normalize_or_zero();
    (r - n.dot(face[0] - c).abs()).max(0.0) * 1.01
}

/// A surface of revolution: base centre, unit axis, height, end radii; cells about
/// `patch` across (at least 16 around), with the two caps when `caps`.
pub(super) fn revolution(
    base: Vec3,
    axis: Vec3,
    height: f32,
    radii: (f32, f32),
    patch: f32,
    caps: bool,
) -> Tessellation {
    let (r0, r1) = radii;
    let rmax = r0.max(r1);
    let nu = cells(TAU * rmax, patch, 16, 256);
    let slant = height.hypot(r1 - r0);
    let nv = cells(slant, patch, 1, 256);
    let f = Frame::from_z(axis);
    let point = |i: u32, j: u32| -> Vec3 {
        let t = j as f32 / nv as f32;
        let r = if j == nv { r1 } else { r0 + (r1 - r0) * t };
        let c = base + axis * (height * t);
        if r == 0.0 {
            return c;
        }
        let phi = TAU * (i % nu) as f32 / nu as f32;
        let (sp, cp) = phi.sin_cos();
        c + (f.x * cp + f.y * sp) * r
    };
    // The sagitta of a chord over one cell's angle.
    let sag = rmax * (1.0 - (PI / nu as f32).cos()) * 1.01;
    let mut faces = Vec::new();
    for j in 0..nv {
        for i in 0..nu {
            let poly = vec![
                point(i, j),
                point(i + 1, j),
                point(i + 1, j + 1),
                point(i, j + 1),
            ];
            let mid = poly.iter().copied().sum::<Vec3>() / 4.0 - base;
            faces.push(oriented(poly, mid - axis * mid.dot(axis)));
        }
    }
    let mut depth = vec![sag; faces.len()];
    if caps {
        faces.push(oriented((0..nu).map(|i| point(i, 0)).collect(), -axis));
        faces.push(oriented((0..nu).map(|i| point(i, nv)).collect(), axis));
        depth.extend([0.0, 0.0]);
    }
    Tessellation {
        faces,
        depth,
        lookup: Lookup::Revolution {
            base,
            axis,
            height,
            nu,
            nv,
            caps,
        },
        smooth: true,
        open: !caps,
    }
}

/// A box with centre `c`, half extents `half` along the unit axes `axes`.
pub(super) fn boxed(c: Vec3, half: Vec3, axes: [Vec3; 3]) -> Tessellation {
    let mut faces = Vec::new();
    let mut planes = Vec::new();
    for k in 0..3 {
        let (a, b) = ((k + 1) % 3, (k + 2) % 3);
        for s in [-1.0f32, 1.0] {
            let n = axes[k] * s;
            let centre = c + n * half[k];
            let (ea, eb) = (axes[a] * half[a], axes[b] * half[b]);
            let poly = vec![
                centre - ea - eb,
                centre + ea - eb,
                centre + ea + eb,
                centre - ea + eb,
            ];
            planes.push((n, n.dot(centre)));
            faces.push(oriented(poly, n));
        }
    }
    Tessellation {
        depth: vec![0.0; faces.len()],
        faces,
        lookup: Lookup::Planes(planes),
        smooth: false,
        open: false,
    }
}

/// Barycentric coordinates `(u, v)` (weights of corners 1 and 2) of the projection of
/// `p` onto the plane of triangle `t`.
pub fn barycentric(t: &[Vec3; 3], p: Vec3) -> (f32, f32) {
    let (e1, e2, q) = (t[1] - t[0], t[2] - t[0], p - t[0]);
    let (d11, d12, d22) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
    let (q1, q2) = (q.dot(e1), q.dot(e2));
    let det = d11 * d22 - d12 * d12;
    if det <= 0.0 {
        return (0.0, 0.0);
    }
    ((d22 * q1 - d12 * q2) / det, (d11 * q2 - d12 * q1) / det)
}

/// `(u, v)` moved to the nearest point of the triangle's parameter domain (in the
/// barycentric sense: negative weights clamped, the rest renormalised).
pub fn clamp_barycentric(u: f32, v: f32) -> (f32, f32) {
    let w = (1.0 - u - v).max(0.0);
    let (u, v) = (u.max(0.0), v.max(0.0));
    let s = u + v + w;
    if s > 0.0 {
        (u / s, v / s)
    } else {
        (1.0 / 3.0, 1.0 / 3.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{AaBox, CappedCone, Polyhedron, Primitive, Sphere};

    fn check_closed(t: &Tessellation, inside: impl Fn(Vec3) -> Vec3) {
        // Every face is planar, convex-ordered and faces away from the inside point.
        let mut area = Vec3::ZERO;
        for f in &t.faces {
            if f.is_empty() {
                continue;
            }
            let n = newell(f);
            assert!(n.length() > 0.0);
            let c = f.iter().copied().sum::<Vec3>() / f.len() as f32;
            assert!(n.dot(c - inside(c)) > 0.0, "face {f:?} faces inwards");
            area += n;
        }
        // A closed surface's oriented area sums to zero.
        assert!(area.length() < 1e-3, "not closed: {area}");
    }

    #[test]
    fn closed_shapes_are_closed_and_face_out() {
        let s = Sphere::new(Vec3::new(1.0, 2.0, 3.0), 0.5);
        check_closed(&s.tessellate(0.1).unwrap(), |_| s.center);
        let c = CappedCone::new(Vec3::ZERO, Vec3::new(0.0, 1.0, 1.0), 2.0, 0.5, 0.2).unwrap();
        check_closed(&c.tessellate(0.3).unwrap(), |p| {
            c.base() + c.axis() * (p - c.base()).dot(c.axis())
        });
        let b = AaBox::new(Vec3::ZERO, Vec3::new(1.0, 2.0, 3.0)).unwrap();
        check_closed(&b.tessellate(1.0).unwrap(), |_| Vec3::new(0.5, 1.0, 1.5));
        let p = Polyhedron::preset("icosahedron", Vec3::ONE, 1.0).unwrap();
        let t = p.tessellate(1.0).unwrap();
        assert_eq!(t.faces.len(), 20);
        check_closed(&t, |_| Vec3::ONE);
    }

    #[test]
    fn lookup_finds_the_face_under_a_surface_point() {
        let s = Sphere::new(Vec3::ZERO, 2.0);
        let t = s.tessellate(0.3).unwrap();
        for k in 0..50 {
            let (a, b) = (k as f32 * 0.37, k as f32 * 0.11 - 2.5);
            let dir = Vec3::new(a.cos() * b.cos(), b.sin(), a.sin() * b.cos());
            let p = dir * 2.0;
            let f = &t.faces[t.lookup.face(p, dir)];
            // The ray from the centre through p crosses that face.
            let n = newell(f).normalize();
            let x = dir * (n.dot(f[0]) / n.dot(dir));
            let inside = (0..f.len()).all(|i| {
                let (a, b) = (f[i], f[(i + 1) % f.len()]);
                (b - a).cross(x - a).dot(n) >= -1e-4
            });
            assert!(inside, "point {p} not under its face");
        }
        // The depth bound holds at the face's centre.
        for (f, &d) in t.faces.iter().zip(&t.depth) {
            let c = f.iter().copied().sum::<Vec3>() / f.len() as f32;
            assert!(c.length() + d >= 2.0 - 1e-5);
        }
    }
}
