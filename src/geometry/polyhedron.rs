//! Convex polyhedra: intersections of half-spaces `n·x ≤ d`.
//!
//! Intersection is Haines' algorithm (Graphics Gems II, "Fast ray–convex polyhedron
//! intersection"): the line enters at the latest crossing of a plane it crosses against
//! the normal and leaves at the earliest crossing of one it crosses along the normal; a
//! plane parallel to the line rejects it when the origin is outside. There are no faces
//! to test and so no gaps along edges.
//!
//! The planes are stored with offsets relative to the centre of the bounds (the solid is
//! `{x : n·(x − o) ≤ d}` with `o = bounds.centroid()`), so a small polyhedron far from the
//! world origin keeps offsets of its own size and a ray starting near it evaluates them
//! without cancellation.

use super::tessellate::{Lookup, Tessellation, oriented};
use super::{Intersect, Param, Primitive, Shape, ShapeError, ShapeHit, Span, Spans, SurfacePoint};
use crate::math::{Aabb, DVec3, Frame, Ray, Vec3, gamma, next_float_down, next_float_up};
use glam::DAffine3;
use std::sync::Arc;

/// The most planes a polyhedron may have (validation enumerates plane triples).
pub const MAX_PLANES: usize = 256;

/// Margin, in units of the point's error bound, by which `surface` keeps a point inside
/// the other faces' planes, so that a ray spawned from it is still seen inside them.
const EDGE_MARGIN: f64 = 4.0;

/// The farthest `surface` moves a point along its face off an edge, in units of its
/// error bound.
const MAX_SHIFT: f64 = 64.0;

/// One bounding plane: `n·(x − o) ≤ d`, `n` unit (to f32 rounding).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Plane {
    n: Vec3,
    d: f32,
}

/// A convex polyhedron: the bounded intersection, with a nonempty interior, of at least
/// four half-spaces. A closed solid. Hits have `u = v = 0`.
///
/// Named regular presets ([`Polyhedron::preset`], [`Polyhedron::PRESETS`]) and regular
/// prisms ([`Polyhedron::prism`]) are built from their face planes.
#[derive(Clone, Debug, PartialEq)]
pub struct Polyhedron {
    /// Heap-allocated so that the type stays small inside an enum of shapes.
    planes: Box<[Plane]>,
    /// Conservative bounds; their centre is the origin of the plane offsets.
    bounds: Aabb,
}

/// The golden ratio.
const PHI: f64 = 1.618_033_988_749_895;

/// Corners of `{x : n·x ≤ d}` (unit normals): the intersections of plane triples that
/// satisfy every plane to within `tol`.
fn corners(planes: &[(DVec3, f64)], tol: f64) -> Vec<DVec3> {
    let mut out = Vec::new();
    let m = planes.len();
    for i in 0..m {
        for j in i + 1..m {
            let (ni, di) = planes[i];
            let (nj, dj) = planes[j];
            let nij = ni.cross(nj);
            if nij.length_squared() < 1e-24 {
                continue;
            }
            for (k, &(nk, dk)) in planes.iter().enumerate().skip(j + 1) {
                let det = nk.dot(nij);
                if det.abs() < 1e-12 {
                    continue;
                }
                let x = (nj.cross(nk) * di + nk.cross(ni) * dj + nij * dk) / det;
                if !x.is_finite() {
                    continue;
                }
                let inside = planes
                    .iter()
                    .enumerate()
                    .all(|(l, &(n, d))| l == i || l == j || l == k || n.dot(x) <= d + tol);
                if inside {
                    out.push(x);
                }
            }
        }
    }
    out
}

/// A direction in which `{x : n·x ≤ d}` is unbounded, if any. With corners present the
/// recession cone `{v : n·v ≤ 0}` is pointed, so if it is not `{0}` it has an extreme
/// ray, along the intersection of two of the planes.
fn recession(planes: &[(DVec3, f64)]) -> Option<DVec3> {
    for (i, &(ni, _)) in planes.iter().enumerate() {
        for &(nj, _) in &planes[i + 1..] {
            let v = ni.cross(nj);
            let len = v.length();
            if len < 1e-12 {
                continue;
            }
            for v in [v / len, -v / len] {
                if planes.iter().all(|&(n, _)| n.dot(v) <= 1e-9) {
                    return Some(v);
                }
            }
        }
    }
    None
}

impl Polyhedron {
    /// The names [`Polyhedron::preset`] knows ("box" is the cube).
    pub const PRESETS: &'static [&'static str] = &[
        "cube",
        "box",
        "tetrahedron",
        "octahedron",
        "dodecahedron",
        "icosahedron",
    ];

    /// The solid `{x : n·x ≤ d}` for the planes `(n, d)`; each `n` may have any nonzero
    /// length (the plane is normalised).
    ///
    /// # Errors
    /// With fewer than 4 or more than [`MAX_PLANES`] planes, a non-finite number or zero
    /// normal, or when the planes bound no volume (empty, flat or unbounded).
    pub fn new(planes: Vec<(Vec3, f32)>) -> Result<Self, ShapeError> {
        if planes.len() < 4 {
            return Err(ShapeError::TooFewPlanes(planes.len()));
        }
        let mut local = Vec::with_capacity(planes.len());
        for (i, &(n, d)) in planes.iter().enumerate() {
            if !n.is_finite() || !d.is_finite() {
                return Err(ShapeError::PlaneNotFinite {
                    index: i + 1,
                    normal: n,
                    offset: d,
                });
            }
            let nd = n.as_dvec3();
            let len = nd.length();
            if !(len.is_finite() && len > 0.0) {
                return Err(ShapeError::PlaneZeroNormal(i + 1));
            }
            local.push((nd / len, d as f64 / len));
        }
        Self::build(DVec3::ZERO, local)
    }

    /// The regular polyhedron `name` (one of [`Polyhedron::PRESETS`], any case) centred
    /// on `center` with circumradius `radius`.
    ///
    /// Orientations: the cube's faces are normal to the axes; the tetrahedron's vertices
    /// are at `(1,1,1)`, `(1,−1,−1)`, `(−1,1,−1)`, `(−1,−1,1)` (scaled); the octahedron's on
    /// the axes; the icosahedron's at the cyclic permutations of `(0, ±1, ±φ)` and the
    /// dodecahedron's faces are normal to those (its dual).
    ///
    /// # Errors
    /// For an unknown name, a non-finite centre or radius, or a radius that is not
    /// positive.
    pub fn preset(name: &str, center: Vec3, radius: f32) -> Result<Self, ShapeError> {
        if !center.is_finite() {
            return Err(ShapeError::parameter_not_finite(
                format!("polyhedron {name}"),
                "centre",
                center,
            ));
        }
        if !(radius > 0.0 && radius.is_finite()) {
            return Err(ShapeError::parameter_not_positive(
                format!("polyhedron {name}"),
                "radius",
                radius,
            ));
        }
        let r = radius as f64;
        let s3 = 3f64.sqrt();
        // Inradius over circumradius of the icosahedron and of its dual.
        let ico_ratio = ((5.0 + 2.0 * 5f64.sqrt()) / 15.0).sqrt();
        let signs = [-1.0, 1.0];
        // (x, y, z) and its two cyclic permutations.
        let cyclic = |v: DVec3| [v, DVec3::new(v.y, v.z, v.x), DVec3::new(v.z, v.x, v.y)];
        let all_signs = |v: DVec3| {
            let mut out = Vec::new();
            for sx in signs {
                for sy in signs {
                    for sz in signs {
                        let u = v * DVec3::new(sx, sy, sz);
                        if !out.contains(&u) {
                            out.push(u);
                        }
                    }
                }
            }
            out
        };
        let normals: Vec<DVec3>;
        let inradius: f64;
        match name.to_ascii_lowercase().as_str() {
            "cube" | "box" => {
                normals = vec![
                    DVec3::X,
                    -DVec3::X,
                    DVec3::Y,
                    -DVec3::Y,
                    DVec3::Z,
                    -DVec3::Z,
                ];
                inradius = r / s3;
            }
            "tetrahedron" => {
                // Each face is opposite a vertex, its normal pointing away from it.
                normals = [
                    (1.0, 1.0, 1.0),
                    (1.0, -1.0, -1.0),
                    (-1.0, 1.0, -1.0),
                    (-1.0, -1.0, 1.0),
                ]
                .map(|(x, y, z)| -DVec3::new(x, y, z))
                .to_vec();
                inradius = r / 3.0;
            }
            "octahedron" => {
                normals = all_signs(DVec3::ONE);
                inradius = r / s3;
            }
            "dodecahedron" => {
                // Face normals along the icosahedron's vertices.
                normals = cyclic(DVec3::new(0.0, 1.0, PHI))
                    .into_iter()
                    .flat_map(all_signs)
                    .collect();
                inradius = r * ico_ratio;
            }
            "icosahedron" => {
                // Face normals along the dodecahedron's vertices.
                normals = all_signs(DVec3::ONE)
                    .into_iter()
                    .chain(
                        cyclic(DVec3::new(0.0, PHI, 1.0 / PHI))
                            .into_iter()
                            .flat_map(all_signs),
                    )
                    .collect();
                inradius = r * ico_ratio;
            }
            _ => {
                return Err(ShapeError::UnknownPolyhedron {
                    name: name.to_string(),
                });
            }
        }
        let planes = normals
            .into_iter()
            .map(|n| (n.normalize(), inradius))
            .collect();
        Self::build(center.as_dvec3(), planes)
            .map_err(|e| e.within(format!("polyhedron {name} of radius {radius} at {center}")))
    }

    /// A right prism over a regular `sides`-gon of circumradius `radius`, with its axis
    /// along z and height `height`, centred on `center` (so it spans
    /// `center.z ± height/2`). One polygon vertex lies in the +x direction from the axis.
    ///
    /// # Errors
    /// With fewer than 3 sides (or more than [`MAX_PLANES`] − 2), a non-finite centre,
    /// or a radius or height that is not positive and finite.
    pub fn prism(center: Vec3, sides: u32, radius: f32, height: f32) -> Result<Self, ShapeError> {
        if sides < 3 || sides as usize > MAX_PLANES - 2 {
            return Err(ShapeError::PrismSides { sides });
        }
        if !center.is_finite() {
            return Err(ShapeError::parameter_not_finite("prism", "centre", center));
        }
        if !(radius > 0.0 && radius.is_finite()) {
            return Err(ShapeError::parameter_not_positive(
                "prism", "radius", radius,
            ));
        }
        if !(height > 0.0 && height.is_finite()) {
            return Err(ShapeError::parameter_not_positive(
                "prism", "height", height,
            ));
        }
        let n = sides as f64;
        let apothem = radius as f64 * (std::f64::consts::PI / n).cos();
        let mut planes: Vec<(DVec3, f64)> = (0..sides)
            .map(|k| {
                // Between the vertices at angles 2πk/n and 2π(k+1)/n.
                let a = std::f64::consts::TAU * (k as f64 + 0.5) / n;
                (DVec3::new(a.cos(), a.sin(), 0.0), apothem)
            })
            .collect();
        planes.push((DVec3::Z, 0.5 * height as f64));
        planes.push((-DVec3::Z, 0.5 * height as f64));
        Self::build(center.as_dvec3(), planes)
            .map_err(|e| e.within(format!("prism of {sides} sides at {center}")))
    }

    /// Validate the planes `n·(x − center) ≤ d` (unit normals, in f64), compute the
    /// bounds and store the planes relative to their centre.
    fn build(center: DVec3, planes: Vec<(DVec3, f64)>) -> Result<Self, ShapeError> {
        if planes.len() > MAX_PLANES {
            return Err(ShapeError::TooManyPlanes(planes.len()));
        }
        // The normals as they will be stored (in f32).
        let planes: Vec<(DVec3, f64)> = planes
            .into_iter()
            .map(|(n, d)| (n.as_vec3().as_dvec3(), d))
            .collect();
        let scale = planes.iter().fold(0.0f64, |m, &(_, d)| m.max(d.abs()));
        let verts = corners(&planes, 1e-6 * scale.max(f64::MIN_POSITIVE));
        if verts.is_empty() {
            return Err(ShapeError::NoCorner);
        }
        if let Some(v) = recession(&planes) {
            return Err(ShapeError::OpenPolyhedron {
                towards: v.as_vec3(),
            });
        }
        let (lo, hi) = verts.iter().fold(
            (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
            |(lo, hi), &v| (lo.min(v), hi.max(v)),
        );
        let size = (hi - lo).max_element();
        let mean = verts.iter().sum::<DVec3>() / verts.len() as f64;
        let depth = planes
            .iter()
            .fold(f64::INFINITY, |m, &(n, d)| m.min(d - n.dot(mean)));
        if size.is_nan() || size <= 0.0 || depth.is_nan() || depth <= 1e-5 * size {
            return Err(ShapeError::FlatPolyhedron);
        }
        // World bounds, widened for the corner tolerance and the rounding of the offsets.
        let (wlo, whi) = (center + lo, center + hi);
        let slack = DVec3::splat(1e-6 * size) + wlo.abs().max(whi.abs()) * gamma(4) as f64;
        let (wlo, whi) = ((wlo - slack).as_vec3(), (whi + slack).as_vec3());
        let bounds = Aabb {
            min: Vec3::new(
                next_float_down(wlo.x),
                next_float_down(wlo.y),
                next_float_down(wlo.z),
            ),
            max: Vec3::new(
                next_float_up(whi.x),
                next_float_up(whi.y),
                next_float_up(whi.z),
            ),
        };
        if !bounds.is_finite() {
            return Err(ShapeError::PolyhedronOverflow);
        }
        let shift = bounds.centroid().as_dvec3() - center;
        let planes: Box<[Plane]> = planes
            .iter()
            .map(|&(n, d)| Plane {
                n: n.as_vec3(),
                d: (d - n.dot(shift)) as f32,
            })
            .collect();
        Ok(Polyhedron { planes, bounds })
    }

    /// Number of planes (faces, if none is redundant).
    pub fn face_count(&self) -> usize {
        self.planes.len()
    }

    /// The point the plane offsets are relative to: the centre of the bounds.
    pub fn origin(&self) -> Vec3 {
        self.bounds.centroid()
    }

    /// The planes `(n, d)` as stored: the solid is `{x : n·(x − origin) ≤ d}`, `n` unit
    /// to f32 rounding.
    pub fn planes(&self) -> impl Iterator<Item = (Vec3, f32)> + '_ {
        self.planes.iter().map(|p| (p.n, p.d))
    }

    /// The planes in world space and double precision, `n·x ≤ d`, exactly as stored
    /// (for references and tests).
    pub fn world_planes(&self) -> Vec<(DVec3, f64)> {
        let o = self.origin().as_dvec3();
        self.planes
            .iter()
            .map(|p| {
                let n = p.n.as_dvec3();
                (n, p.d as f64 + n.dot(o))
            })
            .collect()
    }

    /// The vertices, in world space, each once (corners closer than 1e-6 of the size
    /// merged). Enumerates plane triples: `O(planes⁴)` at worst, for tools and tests.
    pub fn vertices(&self) -> Vec<DVec3> {
        let o = self.origin().as_dvec3();
        let planes: Vec<(DVec3, f64)> = self
            .planes
            .iter()
            .map(|p| {
                let n = p.n.as_dvec3();
                let len = n.length();
                (n / len, p.d as f64 / len)
            })
            .collect();
        let size = self.bounds.extent().max_element() as f64;
        let mut out: Vec<DVec3> = Vec::new();
        for v in corners(&planes, 1e-7 * size) {
            if !out.iter().any(|u| (*u - v).length() <= 1e-6 * size) {
                out.push(v);
            }
        }
        out.into_iter().map(|v| v + o).collect()
    }

    /// Plane `i` in f64 with its normal normalised.
    #[inline]
    fn plane64(&self, i: usize) -> (DVec3, f64) {
        let p = self.planes[i];
        let n = p.n.as_dvec3();
        let len = n.length();
        (n / len, p.d as f64 / len)
    }

    /// Haines' test over the whole line: `(t_in, plane, t_out, plane)` or `None`.
    #[inline]
    fn stretch(&self, ray: &Ray) -> Option<(f32, usize, f32, usize)> {
        if !ray.org.is_finite() || !ray.dir.is_finite() {
            return None;
        }
        let o = ray.org - self.bounds.centroid();
        let (mut t_in, mut t_out) = (f32::NEG_INFINITY, f32::INFINITY);
        let (mut i_in, mut i_out) = (usize::MAX, usize::MAX);
        for (i, p) in self.planes.iter().enumerate() {
            // Signed distance (times |n|) of the origin: positive outside.
            let dist = p.n.dot(o) - p.d;
            let vn = p.n.dot(ray.dir);
            if vn < 0.0 {
                // Crossed against the normal: entering.
                let t = -dist / vn;
                if t > t_in {
                    t_in = t;
                    i_in = i;
                }
            } else if vn > 0.0 {
                let t = -dist / vn;
                if t < t_out {
                    t_out = t;
                    i_out = i;
                }
            } else if dist > 0.0 {
                // Parallel and outside.
                return None;
            }
            if t_in > t_out {
                return None;
            }
        }
        (i_in != usize::MAX && i_out != usize::MAX).then_some((t_in, i_in, t_out, i_out))
    }
}

impl Intersect for Polyhedron {
    fn bounds(&self) -> Aabb {
        self.bounds
    }

    #[inline]
    fn intersect(&self, ray: &Ray) -> Option<ShapeHit> {
        let (t_in, i_in, t_out, i_out) = self.stretch(ray)?;
        let (t, i) = if t_in > ray.tmin && t_in < ray.tmax {
            (t_in, i_in)
        } else if t_out > ray.tmin && t_out < ray.tmax {
            (t_out, i_out)
        } else {
            return None;
        };
        Some(ShapeHit {
            t,
            u: 0.0,
            v: 0.0,
            ng: self.planes[i].n,
        })
    }

    #[inline]
    fn occluded(&self, ray: &Ray) -> bool {
        self.stretch(ray).is_some_and(|(t_in, _, t_out, _)| {
            (t_in > ray.tmin && t_in < ray.tmax) || (t_out > ray.tmin && t_out < ray.tmax)
        })
    }

    /// In double precision: the face is the plane whose normal is closest to `ng`; the
    /// point `o + t·d` is projected onto it and moved inside the other planes by a few
    /// error bounds (along the face, onto an edge or a corner), so a spawned ray is seen
    /// inside them.
    fn surface(&self, ray: &Ray, hit: &ShapeHit) -> SurfacePoint {
        let c = self.origin().as_dvec3();
        let i = (0..self.planes.len())
            .max_by(|&a, &b| {
                self.planes[a]
                    .n
                    .dot(hit.ng)
                    .total_cmp(&self.planes[b].n.dot(hit.ng))
            })
            .unwrap_or(0);
        let (ni, di) = self.plane64(i);
        let y0 = ray.at(hit.t).as_dvec3() - c;
        let mut y = y0 - ni * (ni.dot(y0) - di);
        // What the intersector's `n·(o − c) − d` can hide, and the final rounding.
        let e = gamma(8) as f64 * (y.abs().element_sum() + di.abs());
        let err_max = e + gamma(2) as f64 * (c + y).abs().max_element();
        let margin = |dj: f64| EDGE_MARGIN * err_max + gamma(8) as f64 * dj.abs();
        // Moving the point more than this along the face (to get off a knife edge, where
        // two faces meet at a few degrees) would move it visibly: it then stays.
        let max_shift = MAX_SHIFT * err_max;
        let y_face = y;
        let mut edge: Option<(DVec3, f64)> = None;
        for _ in 0..2 {
            // The most violated other plane (shrunk by the margin), not parallel to ni.
            let mut worst: Option<(f64, DVec3, f64)> = None;
            for j in 0..self.planes.len() {
                let (nj, dj) = self.plane64(j);
                if j == i || ni.dot(nj).abs() > 1.0 - 1e-12 {
                    continue;
                }
                let dj = dj - margin(dj);
                let viol = nj.dot(y) - dj;
                if viol > 0.0 && worst.is_none_or(|w| viol > w.0) {
                    worst = Some((viol, nj, dj));
                }
            }
            let Some((viol, nj, dj)) = worst else {
                break;
            };
            match edge {
                None => {
                    // Along the face, onto the edge line with plane j.
                    let u = nj - ni * ni.dot(nj);
                    let step = u * (viol / u.length_squared());
                    if step.length() > max_shift {
                        break;
                    }
                    y -= step;
                    edge = Some((nj, dj));
                }
                Some((nk, dk)) => {
                    // Onto the corner of the three planes.
                    let nkj = nk.cross(nj);
                    let det = ni.dot(nkj);
                    if det.abs() > 1e-12 {
                        let v = (nk.cross(nj) * di + nj.cross(ni) * dk + ni.cross(nk) * dj) / det;
                        if v.is_finite() && (v - y_face).length() <= max_shift {
                            y = v;
                        }
                    }
                    break;
                }
            }
        }
        let p = (c + y).as_vec3();
        SurfacePoint {
            p,
            err: Vec3::splat(e as f32) + p.abs() * gamma(2),
            ng: ni.as_vec3(),
        }
    }
}

impl Primitive for Polyhedron {
    fn is_solid(&self) -> bool {
        true
    }

    fn spans(&self, ray: &Ray, out: &mut Spans) {
        if let Some((t_in, i_in, t_out, i_out)) = self.stretch(ray) {
            out.push(Span {
                t_in,
                n_in: self.planes[i_in].n,
                t_out,
                n_out: self.planes[i_out].n,
            });
        }
    }

    fn contains(&self, p: Vec3) -> bool {
        let o = p - self.origin();
        self.planes.iter().all(|pl| pl.n.dot(o) <= pl.d)
    }

    /// The planar parameterisation about the normal ([`Param::planar`]).
    fn param(&self, p: Vec3, ng: Vec3) -> Param {
        Param::planar(p, ng)
    }

    /// Under any invertible map: the half-spaces n·x ≤ d map to n'·y ≤ d + n'·t with
    /// n' = M⁻ᵀn.
    fn bake(&self, m: &DAffine3) -> Option<Shape> {
        let inv_t = m.matrix3.inverse().transpose();
        let planes = self
            .world_planes()
            .into_iter()
            .map(|(n, d)| {
                let n2 = inv_t * n;
                (n2.as_vec3(), (d + n2.dot(m.translation)) as f32)
            })
            .collect();
        Polyhedron::new(planes).ok().map(|p| Arc::new(p).into())
    }

    /// One face per plane that has at least three corners on it, exact.
    fn tessellate(&self, _patch: f32) -> Option<Tessellation> {
        let corners = self.vertices();
        let size = corners
            .iter()
            .fold(0.0f64, |m, v| m.max((*v - corners[0]).length()));
        let mut faces = Vec::new();
        let mut planes = Vec::new();
        for (n, d) in self.world_planes() {
            let len = n.length();
            let (n, d) = (n / len, d / len);
            let on: Vec<_> = corners
                .iter()
                .filter(|v| (n.dot(**v) - d).abs() <= 1e-5 * size)
                .collect();
            if on.len() < 3 {
                continue;
            }
            let centre = on.iter().copied().sum::<glam::DVec3>() / on.len() as f64;
            let nf = Frame::from_z(n.as_vec3());
            let (fx, fy) = (nf.x.as_dvec3(), nf.y.as_dvec3());
            let mut ring: Vec<(f64, Vec3)> = on
                .iter()
                .map(|v| {
                    let q = **v - centre;
                    (q.dot(fy).atan2(q.dot(fx)), v.as_vec3())
                })
                .collect();
            ring.sort_by(|a, b| a.0.total_cmp(&b.0));
            let face = oriented(ring.into_iter().map(|x| x.1).collect(), n.as_vec3());
            if face.is_empty() {
                continue;
            }
            planes.push((n.as_vec3(), d as f32));
            faces.push(face);
        }
        Some(Tessellation {
            depth: vec![0.0; faces.len()],
            faces,
            lookup: Lookup::Planes(planes),
            smooth: false,
            open: false,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cube() -> Vec<(DVec3, f64)> {
        [
            DVec3::X,
            -DVec3::X,
            DVec3::Y,
            -DVec3::Y,
            DVec3::Z,
            -DVec3::Z,
        ]
        .map(|n| (n, 1.0))
        .to_vec()
    }

    #[test]
    fn corners_of_a_cube() {
        let c = corners(&cube(), 1e-9);
        assert_eq!(c.len(), 8);
        assert!(c.iter().all(|v| v.abs() == DVec3::ONE));
        assert!(recession(&cube()).is_none());
    }

    #[test]
    fn recession_finds_the_open_side() {
        let mut open = cube();
        open.retain(|(n, _)| *n != -DVec3::Z);
        let v = recession(&open).expect("open towards −z");
        assert!(v.dot(-DVec3::Z) > 1.0 - 1e-12, "{v}");
    }

    #[test]
    fn offsets_are_relative_to_the_centre_of_the_bounds() {
        let far = Vec3::new(1e5, -2e5, 3e4);
        let p = Polyhedron::preset("cube", far, 3f32.sqrt()).unwrap();
        assert!((p.origin() - far).abs().max_element() <= 0.03);
        // Offsets of the cube's own size, not of its distance from the world origin.
        assert!(
            p.planes().all(|(_, d)| (d - 1.0).abs() < 0.05),
            "{:?}",
            p.planes
        );
    }
}
