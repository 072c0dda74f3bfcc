//! General quadrics `F(p) = pᵀQp = 0`, optionally clipped by an axis-aligned box.
//!
//! # Coefficients
//!
//! The ten coefficients `[a, b, c, d, e, f, g, h, i, j]` stand for
//!
//! ```text
//! F(x, y, z) = a x² + b y² + c z² + 2d xy + 2e xz + 2f yz + 2g x + 2h y + 2i z + j
//! ```
//!
//! that is the symmetric matrix `Q = [[a d e g] [d b f h] [e f c i] [g h i j]]` applied
//! to `(x, y, z, 1)`. The solid is `F ≤ 0` (intersected with the clip box, if any) and
//! the outward normal is `∇F`.
//!
//! # Numerics
//!
//! Everything is computed in f64, which is what makes the intersector robust for f32
//! rays at any distance and scale:
//!
//! * the coefficients are stored about a local origin (the quadric's centre, or the
//!   least-squares centre for cylinders and paraboloids; the given point for the
//!   presets), so `F` near the surface does not cancel against the square of the
//!   quadric's distance from the world origin, and they are scaled by a power of two
//!   (exactly) so that the largest is in `[1, 2)`;
//! * the ray origin is moved along the ray to the point nearest the local origin (the
//!   clip box centre for clipped quadrics) before `F(o)` is formed, so a ray from far
//!   away does not lose its discriminant to cancellation (as [`super::Sphere`] and
//!   [`super::Cone`] do in f32);
//! * the roots come from the cancellation-free form `q = −(b + sign(b)√D)`, roots
//!   `q/a` and `c/q`, labelled entry or exit by the sign of `F'` there (as
//!   `quadratic_roots` does in f32); `a → 0` degenerates to the one linear root.
//!
//! Only the results (`t`, normals, points) are rounded to f32.

use super::{Intersect, Param, Primitive, Shape, ShapeError, ShapeHit, Span, Spans, SurfacePoint};
use crate::math::{Aabb, DVec3, Ray, Vec3, next_float_down, next_float_up};
use glam::{DAffine3, DMat3, DMat4};
use std::sync::Arc;

/// `n·u / (1 − n·u)` with `u = 2⁻⁵³`: the relative error bound of `n` f64 operations.
pub(super) const fn gamma64(n: u32) -> f64 {
    let nu = n as f64 * (f64::EPSILON * 0.5);
    nu / (1.0 - nu)
}

/// `v / |v|` rounded to f32, or `None` when `v` is zero or not finite.
pub(super) fn unit_f32(v: DVec3) -> Option<Vec3> {
    let len = v.length();
    if len > 0.0 && len.is_finite() {
        Some((v / len).as_vec3())
    } else {
        // Huge components overflow the length: scale down first.
        let m = v.abs().max_element();
        if m > 0.0 && m.is_finite() {
            let w = v / m;
            Some((w / w.length()).as_vec3())
        } else {
            None
        }
    }
}

/// The outward normal for a crossing whose gradient is `g`; where the gradient vanishes
/// (a cone's apex) the line's own direction stands in: against it at an entry, along it
/// at an exit.
pub(super) fn outward_or_dir(g: DVec3, dir: DVec3, exit: bool) -> Vec3 {
    unit_f32(g)
        .or_else(|| unit_f32(if exit { dir } else { -dir }))
        .unwrap_or(Vec3::Z)
}

/// The largest f32 not above `x` (round towards −∞).
pub(super) fn f32_down(x: f64) -> f32 {
    let y = x as f32;
    if y as f64 > x { next_float_down(y) } else { y }
}

/// The smallest f32 not below `x` (round towards +∞).
pub(super) fn f32_up(x: f64) -> f32 {
    let y = x as f32;
    if (y as f64) < x { next_float_up(y) } else { y }
}

/// The f32 box containing `[lo, hi]` (rounded outwards).
pub(super) fn aabb_out(lo: DVec3, hi: DVec3) -> Aabb {
    Aabb {
        min: Vec3::new(f32_down(lo.x), f32_down(lo.y), f32_down(lo.z)),
        max: Vec3::new(f32_up(hi.x), f32_up(hi.y), f32_up(hi.z)),
    }
}

/// Per-axis error bound of `p` rounded to f32 from an f64 value `δ` away from the true
/// point: half an ulp of every coordinate, doubled for safety, plus `δ`.
pub(super) fn rounding_err(p: Vec3, delta: f64) -> Vec3 {
    let ulp = p.abs() * f32::EPSILON + Vec3::splat(f32::MIN_POSITIVE);
    ulp + Vec3::splat(f32_up(delta))
}

/// The quadric constructors' checks of their input: finite coefficients, not all of
/// the second- and first-order ones zero, and a finite clip box with volume.
fn check_input(coeffs: &[f64; 10], clip: Option<Aabb>) -> Result<(), ShapeError> {
    if let Some(k) = coeffs.iter().position(|c| !c.is_finite()) {
        return Err(ShapeError::QuadricCoefficient {
            name: "abcdefghij".as_bytes()[k] as char,
            value: coeffs[k],
        });
    }
    if let Some(b) = clip {
        if !b.is_finite() {
            return Err(ShapeError::ClipNotFinite);
        }
        if !(b.min.cmplt(b.max).all()) {
            return Err(ShapeError::ClipEmpty {
                min: b.min,
                max: b.max,
            });
        }
    }
    if coeffs[..9].iter().all(|&c| c == 0.0) {
        return Err(ShapeError::QuadricNoTerms);
    }
    Ok(())
}

/// The bounds of an ellipsoid `pᵀMp + 2lᵀp + j ≤ 0` about `origin`, given the
/// eigen-decomposition `lam`, `vecs` of `M` (eigenvalues below `tol` count as zero):
/// `None` unless `M` is positive definite and the solid is not empty.
fn ellipsoid_bounds(
    lam: &[f64; 3],
    vecs: &[DVec3; 3],
    l: DVec3,
    j: f64,
    origin: DVec3,
    tol: f64,
) -> Option<Aabb> {
    let lam_max = lam.iter().fold(0.0f64, |a, x| a.max(x.abs()));
    let lam_min = lam.iter().fold(f64::INFINITY, |a, &x| a.min(x));
    if lam_min <= tol {
        return None;
    }
    // The tangent planes x_k = const satisfy πᵀ adj(Q) π = 0 (the dual quadric), which
    // for F = (p − c)ᵀM(p − c) + k reduces to c_k ± √(−k·(M⁻¹)_kk). The diagonal of
    // M⁻¹ = Σᵢ vᵢvᵢᵀ/λᵢ is a sum of positive terms, so it is formed from the
    // eigen-decomposition instead of the adjugate: no cancellation, and an axis-aligned
    // ellipsoid gets its exact box.
    let mut diag = DVec3::ZERO;
    let mut c = DVec3::ZERO;
    for i in 0..3 {
        diag += vecs[i] * vecs[i] / lam[i];
        c -= vecs[i] * (vecs[i].dot(l) / lam[i]);
    }
    let k = j + l.dot(c);
    if !(k < 0.0 && diag.is_finite()) {
        return None;
    }
    let half = diag * -k;
    let half = DVec3::new(half.x.sqrt(), half.y.sqrt(), half.z.sqrt());
    // The eigenvalues' relative error (Jacobi on a definite matrix) is a small multiple
    // of ε, degrading at worst with the condition number.
    let rel = 1e-13 + 4.0 * f64::EPSILON * (lam_max / lam_min);
    let slack = (half + c.abs() + origin.abs()) * rel;
    let centre_w = origin + c;
    Some(aabb_out(centre_w - half - slack, centre_w + half + slack))
}

/// Checks that a vector is finite, for constructors.
pub(super) fn check_finite(what: &str, v: Vec3) -> Result<(), ShapeError> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(ShapeError::NotFinite {
            what: what.into(),
            value: v,
        })
    }
}

/// Checks that a size is finite and positive, for constructors.
pub(super) fn check_positive(what: &str, x: f32) -> Result<(), ShapeError> {
    if x.is_finite() && x > 0.0 {
        Ok(())
    } else {
        Err(ShapeError::NotPositive {
            what: what.into(),
            value: x,
        })
    }
}

/// A unit axis from a finite non-zero vector, normalised in f64.
pub(super) fn unit_axis(what: &str, axis: Vec3) -> Result<DVec3, ShapeError> {
    check_finite(what, axis)?;
    let a = axis.as_dvec3();
    let len = a.length();
    if len > 0.0 {
        Ok(a / len)
    } else {
        Err(ShapeError::Zero { what: what.into() })
    }
}

/// The parameters where the line `o + t·d` is inside the box, with the outward face
/// normals at both ends (computed in f64), or `None` when it misses the box.
pub(super) fn box_interval(b: &Aabb, o: DVec3, d: DVec3) -> Option<(f64, Vec3, f64, Vec3)> {
    let (mut lo, mut n_lo) = (f64::NEG_INFINITY, Vec3::ZERO);
    let (mut hi, mut n_hi) = (f64::INFINITY, Vec3::ZERO);
    for i in 0..3 {
        let (mn, mx) = (b.min[i] as f64, b.max[i] as f64);
        let mut e = Vec3::ZERO;
        e[i] = 1.0;
        if d[i] == 0.0 {
            if o[i] < mn || o[i] > mx {
                return None;
            }
            continue;
        }
        let ta = (mn - o[i]) / d[i];
        let tb = (mx - o[i]) / d[i];
        let (tn, nn, tf, nf) = if d[i] > 0.0 {
            (ta, -e, tb, e)
        } else {
            (tb, e, ta, -e)
        };
        if tn > lo {
            lo = tn;
            n_lo = nn;
        }
        if tf < hi {
            hi = tf;
            n_hi = nf;
        }
    }
    (lo <= hi).then_some((lo, n_lo, hi, n_hi))
}

/// Whether `p` (f64) lies in the box, boundary included.
pub(super) fn box_contains(b: &Aabb, p: DVec3) -> bool {
    p.cmpge(b.min.as_dvec3()).all() && p.cmple(b.max.as_dvec3()).all()
}

/// Eigen-decomposition of a symmetric 3×3 matrix by cyclic Jacobi rotations:
/// eigenvalues and the matching orthonormal eigenvectors.
fn eigen_sym3(m: DMat3) -> ([f64; 3], [DVec3; 3]) {
    let mut a = [
        [m.x_axis.x, m.y_axis.x, m.z_axis.x],
        [m.x_axis.y, m.y_axis.y, m.z_axis.y],
        [m.x_axis.z, m.y_axis.z, m.z_axis.z],
    ];
    let mut v = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    for _sweep in 0..64 {
        let off = a[0][1] * a[0][1] + a[0][2] * a[0][2] + a[1][2] * a[1][2];
        let diag = a[0][0] * a[0][0] + a[1][1] * a[1][1] + a[2][2] * a[2][2];
        if off == 0.0 || off <= diag * 1e-40 {
            break;
        }
        for (p, q) in [(0, 1), (0, 2), (1, 2)] {
            if a[p][q] == 0.0 {
                continue;
            }
            // Rotation annihilating a[p][q] (Numerical Recipes §11.1).
            let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
            let t = if theta.abs() > 1e150 {
                0.5 / theta
            } else {
                1.0f64.copysign(theta) / (theta.abs() + (theta * theta + 1.0).sqrt())
            };
            let c = 1.0 / (t * t + 1.0).sqrt();
            let s = t * c;
            for row in &mut a {
                let (x, y) = (row[p], row[q]);
                row[p] = c * x - s * y;
                row[q] = s * x + c * y;
            }
            let (row_p, row_q) = (a[p], a[q]);
            for (k, (&x, &y)) in row_p.iter().zip(&row_q).enumerate() {
                a[p][k] = c * x - s * y;
                a[q][k] = s * x + c * y;
            }
            for row in &mut v {
                let (x, y) = (row[p], row[q]);
                row[p] = c * x - s * y;
                row[q] = s * x + c * y;
            }
        }
    }
    let vec = |k: usize| DVec3::new(v[0][k], v[1][k], v[2][k]);
    ([a[0][0], a[1][1], a[2][2]], [vec(0), vec(1), vec(2)])
}

/// `2^e` for any `e` whose result is a normal f64.
fn pow2(e: i32) -> f64 {
    let half = e / 2;
    2f64.powi(half) * 2f64.powi(e - half)
}

/// A crossing of a line with a surface: the line parameter, relative to the re-based
/// origin, and whether the line leaves the solid there.
#[derive(Clone, Copy, Debug)]
pub(super) struct Crossing {
    /// Parameter relative to the re-based origin.
    pub r: f64,
    /// True where the line leaves the solid.
    pub exit: bool,
}

/// A ray line re-based near the quadric and its crossings with `F = 0`.
struct LineRoots {
    /// Re-based origin, local coordinates.
    o: DVec3,
    /// Direction.
    d: DVec3,
    /// Ray parameter of the re-based origin.
    t0: f64,
    /// Whether the line is inside `F ≤ 0` as `t → −∞`.
    inside_start: bool,
    /// Crossings, sorted by parameter.
    xs: [Crossing; 2],
    /// Number of crossings.
    n: usize,
}

impl LineRoots {
    fn crossings(&self) -> &[Crossing] {
        &self.xs[..self.n]
    }
}

/// A quadric surface `F(p) = 0` with its solid `F(p) ≤ 0`, optionally clipped by an
/// axis-aligned box (see the module documentation for the coefficient order and the
/// numerics).
///
/// The clip box keeps the part of the surface inside it (an open surface for
/// [`Intersect`]); the solid is `{F ≤ 0} ∩ box`, so [`Primitive::spans`] enters and leaves
/// through the box faces where the box bounds it. `u` and `v` of hits are 0.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quadric {
    /// Second-order part about the local origin (scaled).
    m: DMat3,
    /// Half the first-order part about the local origin (scaled).
    l: DVec3,
    /// Constant term about the local origin (scaled).
    j: f64,
    /// `|m|` elementwise, for error bounds.
    m_abs: DMat3,
    /// Frobenius norm of `m`, bounding its eigenvalues.
    m_norm: f64,
    /// Largest positive eigenvalue of `m` (0 if none).
    lam_pos: f64,
    /// Largest magnitude of a negative eigenvalue of `m` (0 if none).
    lam_neg: f64,
    /// Unit eigenvector of `lam_pos`.
    v_pos: DVec3,
    /// Unit eigenvector of `-lam_neg`.
    v_neg: DVec3,
    /// The local origin in world coordinates.
    origin: DVec3,
    /// The point, in local coordinates, rays are re-based to.
    rebase: DVec3,
    /// Clip box.
    clip: Option<Aabb>,
    /// Conservative bounds.
    bounds: Aabb,
    /// Whether the solid is bounded.
    bounded: bool,
}

impl Quadric {
    /// A quadric from its ten world-space coefficients `[a, b, c, d, e, f, g, h, i, j]`
    /// (see the module documentation), optionally clipped by `clip`.
    ///
    /// The coefficients are re-expressed about the quadric's centre (or least-squares
    /// centre) in f64. Errors: non-finite coefficients, no second- or first-order terms,
    /// a quadric with no real surface (`x² + y² + z² + 1`), one that fills all space or
    /// is a single point or line, an invalid clip box, or a clip box that misses an
    /// ellipsoid.
    pub fn new(coeffs: [f64; 10], clip: Option<Aabb>) -> Result<Self, ShapeError> {
        Self::build(DVec3::ZERO, coeffs, clip, true)
    }

    /// A quadric whose coefficients (same order as [`Quadric::new`]) describe
    /// `F(p − origin)`: the precise way to give a small quadric far from the world
    /// origin.
    pub fn about(origin: Vec3, coeffs: [f64; 10], clip: Option<Aabb>) -> Result<Self, ShapeError> {
        check_finite("quadric origin", origin)?;
        Self::build(origin.as_dvec3(), coeffs, clip, false)
    }

    /// The sphere `|p − center|² = radius²`.
    pub fn sphere(center: Vec3, radius: f32) -> Result<Self, ShapeError> {
        check_positive("sphere radius", radius)?;
        let r = radius as f64;
        Self::about(
            center,
            [1.0, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -r * r],
            None,
        )
    }

    /// The axis-aligned ellipsoid `Σ ((p − center)ᵢ / radiiᵢ)² = 1`.
    pub fn ellipsoid(center: Vec3, radii: Vec3) -> Result<Self, ShapeError> {
        for (k, r) in radii.to_array().into_iter().enumerate() {
            check_positive(&format!("ellipsoid radius {}", ["x", "y", "z"][k]), r)?;
        }
        let r = radii.as_dvec3();
        let inv = DVec3::ONE / (r * r);
        Self::about(
            center,
            [inv.x, inv.y, inv.z, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0],
            None,
        )
    }

    /// The infinite cylinder of `radius` around the line through `point` along `axis`.
    pub fn cylinder(point: Vec3, axis: Vec3, radius: f32) -> Result<Self, ShapeError> {
        check_positive("cylinder radius", radius)?;
        let w = unit_axis("cylinder axis", axis)?;
        let r = radius as f64;
        Self::about(point, axial(w, 1.0, 0.0, 0.0, -r * r), None)
    }

    /// The infinite double cone with its apex at `apex`, around `axis`, whose radius
    /// grows by `slope` per unit of height (`slope = tan` of the half-angle).
    pub fn cone(apex: Vec3, axis: Vec3, slope: f32) -> Result<Self, ShapeError> {
        check_positive("cone slope", slope)?;
        let w = unit_axis("cone axis", axis)?;
        let k = slope as f64;
        Self::about(apex, axial(w, 1.0, -k * k, 0.0, 0.0), None)
    }

    /// The paraboloid of revolution with its vertex at `vertex`, opening along `axis`,
    /// with focal length `focal`: `|p⊥|² = 4·focal·h` (`h` the height along the axis).
    pub fn paraboloid(vertex: Vec3, axis: Vec3, focal: f32) -> Result<Self, ShapeError> {
        check_positive("paraboloid focal length", focal)?;
        let w = unit_axis("paraboloid axis", axis)?;
        Self::about(vertex, axial(w, 1.0, 0.0, -2.0 * focal as f64, 0.0), None)
    }

    /// The hyperboloid of one sheet around `axis` through `center`:
    /// `|p⊥|² − slope²·h² = waist²` (`waist` the radius at the centre, `slope` that of
    /// the asymptotic cone). The solid is the region around the axis.
    pub fn hyperboloid_one_sheet(
        center: Vec3,
        axis: Vec3,
        waist: f32,
        slope: f32,
    ) -> Result<Self, ShapeError> {
        check_positive("hyperboloid waist radius", waist)?;
        check_positive("hyperboloid slope", slope)?;
        let w = unit_axis("hyperboloid axis", axis)?;
        let (r, k) = (waist as f64, slope as f64);
        Self::about(center, axial(w, 1.0, -k * k, 0.0, -r * r), None)
    }

    /// The hyperboloid of two sheets around `axis` through `center`, with its vertices at
    /// `±vertex` along the axis: `slope²·h² − |p⊥|² = slope²·vertex²`. The solid is the
    /// inside of the two bowls.
    pub fn hyperboloid_two_sheets(
        center: Vec3,
        axis: Vec3,
        vertex: f32,
        slope: f32,
    ) -> Result<Self, ShapeError> {
        check_positive("hyperboloid vertex distance", vertex)?;
        check_positive("hyperboloid slope", slope)?;
        let w = unit_axis("hyperboloid axis", axis)?;
        let (a, k) = (vertex as f64, slope as f64);
        Self::about(center, axial(w, 1.0, -k * k, 0.0, k * k * a * a), None)
    }

    /// The same quadric clipped by `clip` (replacing any previous clip box).
    pub fn with_clip(self, clip: Aabb) -> Result<Self, ShapeError> {
        let c = self.local_coefficients();
        Self::build(self.origin, c, Some(clip), false)
    }

    /// The clip box, if any.
    pub fn clip(&self) -> Option<Aabb> {
        self.clip
    }

    /// Whether the solid is bounded (an ellipsoid, or clipped): then [`Quadric::bounds`]
    /// is finite, otherwise it is [`Aabb::INFINITE`].
    pub fn is_bounded(&self) -> bool {
        self.bounded
    }

    /// The world-space coefficients `[a, b, c, d, e, f, g, h, i, j]`, up to the positive
    /// factor the constructor scaled them by.
    pub fn coefficients(&self) -> [f64; 10] {
        let o = self.origin;
        let l = self.l - self.m * o;
        let j = o.dot(self.m * o) - 2.0 * self.l.dot(o) + self.j;
        pack(self.m, l, j)
    }

    /// `F(p)` in world coordinates, up to the constructor's positive factor: negative
    /// inside, positive outside.
    pub fn value(&self, p: DVec3) -> f64 {
        self.f_local(p - self.origin)
    }

    /// The coefficients about the local origin.
    fn local_coefficients(&self) -> [f64; 10] {
        pack(self.m, self.l, self.j)
    }

    fn build(
        origin: DVec3,
        coeffs: [f64; 10],
        clip: Option<Aabb>,
        recentre: bool,
    ) -> Result<Self, ShapeError> {
        check_input(&coeffs, clip)?;
        // Scale exactly by a power of two so the largest coefficient is in [1, 2).
        let big = coeffs.iter().fold(0.0f64, |a, c| a.max(c.abs()));
        let s = pow2(-(big.log2().floor() as i32));
        let c = coeffs.map(|x| x * s);
        let m = DMat3::from_cols(
            DVec3::new(c[0], c[3], c[4]),
            DVec3::new(c[3], c[1], c[5]),
            DVec3::new(c[4], c[5], c[2]),
        );
        let l = DVec3::new(c[6], c[7], c[8]);
        let j = c[9];

        let (lam, vecs) = eigen_sym3(m);
        let lam_max = lam.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        // Eigenvalues below this are treated as zero (cylinders, paraboloids, planes).
        let tol = 1e-10 * lam_max;
        // Least-squares centre: −M⁺l over the non-null eigenvectors.
        let mut centre = DVec3::ZERO;
        let mut residual = DVec3::ZERO;
        for k in 0..3 {
            let lv = vecs[k].dot(l);
            if lam[k].abs() > tol {
                centre -= vecs[k] * (lv / lam[k]);
            } else {
                residual += vecs[k] * lv;
            }
        }
        let f_centre = centre.dot(m * centre) + 2.0 * l.dot(centre) + j;
        let nonzero: Vec<f64> = lam.iter().copied().filter(|x| x.abs() > tol).collect();
        let linear_part = residual.length() > 1e-12 * (l.length() + lam_max * centre.length());
        if !linear_part {
            if nonzero.is_empty() {
                return Err(ShapeError::QuadricConstant);
            }
            if nonzero.iter().all(|&x| x > 0.0) && f_centre >= 0.0 {
                return Err(if f_centre > 0.0 {
                    ShapeError::QuadricNoPoints
                } else {
                    ShapeError::QuadricDegenerate
                });
            }
            if nonzero.iter().all(|&x| x < 0.0) && f_centre <= 0.0 {
                return Err(ShapeError::QuadricFillsSpace);
            }
        }

        let (origin, l, j) = if recentre {
            (origin + centre, m * centre + l, f_centre)
        } else {
            (origin, l, j)
        };

        let ellipsoid = ellipsoid_bounds(&lam, &vecs, l, j, origin, tol);
        let mut bounded = ellipsoid.is_some();
        let mut bounds = ellipsoid.unwrap_or(Aabb::INFINITE);
        if let Some(b) = clip {
            bounds = Aabb {
                min: bounds.min.max(b.min),
                max: bounds.max.min(b.max),
            };
            bounded = true;
            if bounds.is_empty() {
                return Err(ShapeError::ClipMisses);
            }
        }
        let rebase = clip.map_or(DVec3::ZERO, |b| {
            (b.min.as_dvec3() + b.max.as_dvec3()) * 0.5 - origin
        });
        let m_abs = DMat3::from_cols(m.x_axis.abs(), m.y_axis.abs(), m.z_axis.abs());
        let m_norm =
            (m.x_axis.length_squared() + m.y_axis.length_squared() + m.z_axis.length_squared())
                .sqrt();
        let (mut lam_pos, mut lam_neg) = (0.0f64, 0.0f64);
        let (mut v_pos, mut v_neg) = (DVec3::ZERO, DVec3::ZERO);
        for k in 0..3 {
            if lam[k] > lam_pos {
                (lam_pos, v_pos) = (lam[k], vecs[k]);
            }
            if -lam[k] > lam_neg {
                (lam_neg, v_neg) = (-lam[k], vecs[k]);
            }
        }
        Ok(Quadric {
            m,
            l,
            j,
            m_abs,
            m_norm,
            lam_pos,
            lam_neg,
            v_pos,
            v_neg,
            origin,
            rebase,
            clip,
            bounds,
            bounded,
        })
    }

    /// `F` at a local point.
    #[inline]
    fn f_local(&self, p: DVec3) -> f64 {
        p.dot(self.m * p) + 2.0 * self.l.dot(p) + self.j
    }

    /// Half the gradient of `F` at a local point.
    #[inline]
    fn half_grad(&self, p: DVec3) -> DVec3 {
        self.m * p + self.l
    }

    /// Bound on the rounding error of [`Quadric::f_local`] at `p`.
    #[inline]
    fn f_err(&self, p: DVec3) -> f64 {
        let a = p.abs();
        gamma64(8) * (a.dot(self.m_abs * a) + 2.0 * self.l.abs().dot(a) + self.j.abs())
    }

    /// The line of `ray`, re-based, and its crossings with `F = 0`, or `None` for
    /// non-finite or zero-direction rays.
    #[inline]
    fn roots(&self, ray: &Ray) -> Option<LineRoots> {
        if !(ray.org.is_finite() && ray.dir.is_finite()) {
            return None;
        }
        let d = ray.dir.as_dvec3();
        let dd = d.length_squared();
        if dd == 0.0 {
            return None;
        }
        let q = ray.org.as_dvec3() - self.origin;
        let t0 = (self.rebase - q).dot(d) / dd;
        let o = q + d * t0;
        let md = self.m * d;
        let a = d.dot(md);
        let b = md.dot(o) + self.l.dot(d);
        let c = self.f_local(o);
        if !(a.is_finite() && b.is_finite() && c.is_finite()) {
            return None;
        }
        let none = Crossing {
            r: 0.0,
            exit: false,
        };
        let mut out = LineRoots {
            o,
            d,
            t0,
            inside_start: false,
            xs: [none; 2],
            n: 0,
        };
        if a == 0.0 {
            if b == 0.0 {
                // F is constant along the line.
                out.inside_start = c < 0.0;
            } else {
                // Linear: F grows through the root when b > 0, so the line leaves there.
                out.inside_start = b > 0.0;
                out.xs[0] = Crossing {
                    r: -c / (2.0 * b),
                    exit: b > 0.0,
                };
                out.n = 1;
            }
            return Some(out);
        }
        // D = b² − a·c with one rounding (Kahan).
        let ac = a * c;
        let disc = b.mul_add(b, -ac) + (-a).mul_add(c, ac);
        out.inside_start = a < 0.0;
        if !disc.is_finite() || disc < 0.0 {
            return Some(out);
        }
        let qq = -(b + disc.sqrt().copysign(b));
        let r_qa = qq / a;
        // qq = 0 only when b = D = 0, then c = 0 too: a double root at 0.
        let r_cq = if qq != 0.0 { c / qq } else { 0.0 };
        // The exit root is where a·r + b = +√D: q/a when b < 0.
        let (entry, exit) = if b.is_sign_negative() {
            (r_cq, r_qa)
        } else {
            (r_qa, r_cq)
        };
        // Near a tangent the two formulas can round past each other: then both are the
        // double root.
        let (entry, exit) = if (a > 0.0) == (entry <= exit) {
            (entry, exit)
        } else {
            let mid = 0.5 * (entry + exit);
            (mid, mid)
        };
        let (en, ex) = (
            Crossing {
                r: entry,
                exit: false,
            },
            Crossing {
                r: exit,
                exit: true,
            },
        );
        out.xs = if a > 0.0 { [en, ex] } else { [ex, en] };
        out.n = 2;
        Some(out)
    }

    /// The first accepted crossing: inside the ray interval and the clip box.
    #[inline]
    fn first(&self, ray: &Ray) -> Option<(f32, DVec3, DVec3, bool)> {
        let lr = self.roots(ray)?;
        for x in lr.crossings() {
            let t = (lr.t0 + x.r) as f32;
            if !(t > ray.tmin && t < ray.tmax) {
                continue;
            }
            let p = lr.o + lr.d * x.r;
            if let Some(b) = &self.clip {
                if !box_contains(b, self.origin + p) {
                    continue;
                }
            }
            return Some((t, p, lr.d, x.exit));
        }
        None
    }

    /// The surface point for a span end on a face of the clip box: `ng` is that face's
    /// normal (exactly `±x`, `±y` or `±z`, as [`Quadric::spans`] reports it) and the
    /// point `o + t·d` is within the rounding of `t` of the face's plane.
    fn cap_point(&self, ray: &Ray, t: f32, ng: Vec3) -> Option<SurfacePoint> {
        let b = self.clip?;
        let axis = (0..3).find(|&i| ng[i].abs() == 1.0)?;
        if ng.length_squared() != 1.0 {
            return None;
        }
        let face = if ng[axis] > 0.0 {
            b.max[axis]
        } else {
            b.min[axis]
        };
        let pw = ray.org.as_dvec3() + ray.dir.as_dvec3() * t as f64;
        let slack = (t.abs() * f32::EPSILON) as f64 * (ray.dir[axis] as f64).abs()
            + gamma64(4) * (pw.abs().max_element() + ray.org.abs().max_element() as f64);
        if !pw.is_finite() || (pw[axis] - face as f64).abs() > slack {
            return None;
        }
        // On the face's plane exactly (its coordinate is an f32); the other coordinates
        // are rounded once, and along the face that is all the error there is.
        let mut p32 = pw.as_vec3();
        p32[axis] = face;
        Some(SurfacePoint {
            p: p32,
            err: rounding_err(p32, gamma64(4) * pw.abs().max_element()),
            ng,
        })
    }
}

/// The coefficients of `α|p⊥|² + β(p·w)² + 2γ(p·w) + δ` (`p⊥` the part of `p`
/// perpendicular to the unit axis `w`), i.e. `M = α(I − wwᵀ) + βwwᵀ`, `l = γw`.
fn axial(w: DVec3, alpha: f64, beta: f64, gamma: f64, delta: f64) -> [f64; 10] {
    let k = beta - alpha;
    let m = DMat3::from_diagonal(DVec3::splat(alpha))
        + DMat3::from_cols(w * (k * w.x), w * (k * w.y), w * (k * w.z));
    pack(m, w * gamma, delta)
}

/// `[a, b, c, d, e, f, g, h, i, j]` from `M`, `l` and `j`.
fn pack(m: DMat3, l: DVec3, j: f64) -> [f64; 10] {
    [
        m.x_axis.x, m.y_axis.y, m.z_axis.z, m.y_axis.x, m.z_axis.x, m.z_axis.y, l.x, l.y, l.z, j,
    ]
}

impl Intersect for Quadric {
    /// Conservative bounds: the clip box, intersected with the ellipsoid's exact box
    /// (rounded outwards) for ellipsoids; [`Aabb::INFINITE`] when unbounded.
    fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// The nearest hit in `(ray.tmin, ray.tmax)`, from either side; `ng` is the unit
    /// gradient of `F` (outwards).
    fn intersect(&self, ray: &Ray) -> Option<ShapeHit> {
        let (t, p, d, exit) = self.first(ray)?;
        Some(ShapeHit {
            t,
            u: 0.0,
            v: 0.0,
            ng: outward_or_dir(self.half_grad(p), d, exit),
        })
    }

    /// Whether a hit lies in `(ray.tmin, ray.tmax)`.
    fn occluded(&self, ray: &Ray) -> bool {
        self.first(ray).is_some()
    }

    /// The hit point put back onto the surface in f64 (re-solved along the ray within
    /// the rounding of `t`, then projected along the gradient line, where `F` is an
    /// exact quadratic), rounded to f32, with the bound of that rounding plus the f64
    /// point's proven distance from the surface.
    ///
    /// For a clipped quadric's span end on a box face (normal `±x`, `±y` or `±z`, as
    /// [`Quadric::spans`] reports them, and the point within the rounding of `t` of that
    /// face) the point is put on the face exactly instead.
    fn surface(&self, ray: &Ray, hit: &ShapeHit) -> SurfacePoint {
        if let Some(sp) = self.cap_point(ray, hit.t, hit.ng) {
            return sp;
        }
        let d = ray.dir.as_dvec3();
        let mut p = ray.org.as_dvec3() - self.origin + d * hit.t as f64;
        let p0 = p;
        // First back onto the ray's own crossing: the root of F(p + s·d̂) nearest 0, if
        // it is within the rounding of t (then it is the f64 root intersect() found).
        let dl = d.length();
        if dl > 0.0 {
            let u = d / dl;
            let (a, b, c) = (u.dot(self.m * u), self.half_grad(p).dot(u), self.f_local(p));
            let disc = b * b - a * c;
            let s = if a == 0.0 || disc >= 0.0 {
                let qq = -(b + disc.max(0.0).sqrt().copysign(b));
                c / qq
            } else {
                f64::NAN
            };
            let t_ulp = (hit.t.abs() * f32::EPSILON) as f64 * dl;
            if s.abs() <= 4.0 * t_ulp {
                p += u * s;
            }
        }
        // Then along the normal (usually nothing is left to do): one step, more only when
        // t was far off (a ray from millions of sizes away, whose f32 t is coarse) and the
        // gradient turns along the way. more only when t was far off (a ray from millions of sizes
        // away, whose f32 t is coarse) and the gradient turns along the way.
        for _ in 0..16 {
            let g = self.half_grad(p);
            let f = self.f_local(p);
            if f == 0.0 || !f.is_finite() || !g.is_finite() {
                break;
            }
            // Along a unit direction u, F(p + s·u) = f + 2(g·u)·s + (uᵀMu)·s² exactly:
            // step to its root nearest 0. The gradient's direction first; where that line
            // misses the surface (near a cone's apex), an eigenvector whose eigenvalue has
            // the sign opposite to f, along which a root always exists.
            let gl = g.length();
            let gh = g / gl;
            let kappa = gh.dot(self.m * gh);
            let disc = gl * gl - kappa * f;
            let (u, b, a, disc) = if gl > 0.0 && disc >= 0.0 {
                (gh, gl, kappa, disc)
            } else {
                let (u, mu) = if f > 0.0 {
                    (self.v_neg, -self.lam_neg)
                } else {
                    (self.v_pos, self.lam_pos)
                };
                let b = g.dot(u);
                (u, b, mu, b * b - mu * f)
            };
            if disc.is_nan() || disc < 0.0 || (a == 0.0 && b == 0.0) {
                break;
            }
            let qq = -(b + disc.sqrt().copysign(b));
            let s = f / qq;
            if !s.is_finite() {
                break;
            }
            p += u * s;
            if s.abs() <= 1e-17 * p.abs().max_element() {
                break;
            }
        }
        if !p.is_finite() {
            p = p0;
        }
        // Proven distance from p to the surface, with φ ≥ |F(p)| (rounding included):
        // * 2φ/|∇F| along the gradient when |∇F|² ≥ 8λφ (λ ≥ |eigenvalues|): the
        //   exact quadratic F(p + s·u) = F + s∇F·u + s²uᵀMu changes sign on that segment;
        // * √(φ/|μ|) along an eigenvector whose eigenvalue μ has the opposite sign to F
        //   (the bound that survives at a cone's apex, where ∇F vanishes).
        let f = self.f_local(p);
        let phi = f.abs() + self.f_err(p);
        let grad = 2.0 * self.half_grad(p).length();
        let lam = 2.0 * self.m_norm;
        let along_grad = if grad * grad >= 8.0 * lam * phi {
            2.0 * phi / grad
        } else {
            f64::INFINITY
        };
        let mu = if f > 0.0 { self.lam_neg } else { self.lam_pos };
        let along_eigen = if mu > 0.0 {
            (phi / (0.99 * mu)).sqrt()
        } else {
            f64::INFINITY
        };
        let mut delta = along_grad.min(along_eigen);
        if !delta.is_finite() {
            // Not near the surface at all (a t this quadric never reported).
            delta = 1e-6 * (d.length() * (hit.t as f64).abs() + p.length());
        }
        let pw = self.origin + p;
        let delta = delta + gamma64(4) * (pw.abs().max_element() + p.abs().max_element());
        let p32 = pw.as_vec3();
        let ng = unit_f32(self.half_grad(p))
            .or_else(|| hit.ng.try_normalize())
            .or_else(|| (-ray.dir).try_normalize())
            .unwrap_or(Vec3::Z);
        SurfacePoint {
            p: p32,
            err: rounding_err(p32, delta),
            ng,
        }
    }
}

impl Primitive for Quadric {
    /// A solid where `{F ≤ 0}` is bounded (clipped, or an ellipsoid).
    fn is_solid(&self) -> bool {
        self.is_bounded()
    }

    /// The solid's spans along the whole line of `ray`.
    fn spans(&self, ray: &Ray, out: &mut Spans) {
        let Some(lr) = self.roots(ray) else {
            return;
        };
        let mut f_spans: smallvec::SmallVec<[(f64, Vec3, f64, Vec3); 2]> = Default::default();
        let mut start = lr.inside_start.then_some((f64::NEG_INFINITY, Vec3::ZERO));
        for x in lr.crossings() {
            let t = lr.t0 + x.r;
            let n = outward_or_dir(self.half_grad(lr.o + lr.d * x.r), lr.d, x.exit);
            if x.exit {
                if let Some((ts, ns)) = start.take() {
                    f_spans.push((ts, ns, t, n));
                }
            } else {
                start = Some((t, n));
            }
        }
        if let Some((ts, ns)) = start {
            f_spans.push((ts, ns, f64::INFINITY, Vec3::ZERO));
        }
        let window = match &self.clip {
            Some(b) => match box_interval(b, ray.org.as_dvec3(), lr.d) {
                Some(w) => w,
                None => return,
            },
            None => (f64::NEG_INFINITY, Vec3::ZERO, f64::INFINITY, Vec3::ZERO),
        };
        for (t_in, n_in, t_out, n_out) in f_spans {
            let (t_in, n_in) = if window.0 > t_in {
                (window.0, window.1)
            } else {
                (t_in, n_in)
            };
            let (t_out, n_out) = if window.2 < t_out {
                (window.2, window.3)
            } else {
                (t_out, n_out)
            };
            if t_in <= t_out {
                out.push(Span {
                    t_in: t_in as f32,
                    n_in,
                    t_out: t_out as f32,
                    n_out,
                });
            }
        }
    }

    /// Whether `p` is inside the solid (`F(p) ≤ 0` and in the clip box).
    fn contains(&self, p: Vec3) -> bool {
        let pd = p.as_dvec3();
        let in_box = match &self.clip {
            Some(b) => box_contains(b, pd),
            None => true,
        };
        in_box && self.value(pd) <= 0.0
    }

    /// The planar parameterisation about the normal ([`Param::planar`]).
    fn param(&self, p: Vec3, ng: Vec3) -> Param {
        Param::planar(p, ng)
    }

    /// Unclipped, under any invertible map: F(L⁻¹(y − t)) about the origin t, the
    /// coefficients through L⁻¹ alone. A clipped quadric does not bake (its clip box
    /// would not stay a box).
    fn bake(&self, m: &DAffine3) -> Option<Shape> {
        if self.clip().is_some() {
            return None;
        }
        let [a, b, c, d, e, f, g, h, i, j] = self.coefficients();
        let qm =
            DMat4::from_cols_array_2d(&[[a, d, e, g], [d, b, f, h], [e, f, c, i], [g, h, i, j]]);
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
        Quadric::about(t.as_vec3(), coeffs, None)
            .ok()
            .map(|q| Arc::new(q).into())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn jacobi_reconstructs_the_matrix() {
        let m = DMat3::from_cols(
            DVec3::new(2.0, -1.0, 0.5),
            DVec3::new(-1.0, 3.0, 0.25),
            DVec3::new(0.5, 0.25, -4.0),
        );
        let (lam, v) = eigen_sym3(m);
        let mut r = DMat3::ZERO;
        for k in 0..3 {
            assert!((v[k].length() - 1.0).abs() < 1e-14);
            r += DMat3::from_cols(v[k] * v[k].x, v[k] * v[k].y, v[k] * v[k].z) * lam[k];
        }
        for (a, b) in r.to_cols_array().iter().zip(m.to_cols_array()) {
            assert!((a - b).abs() < 1e-13, "{r} vs {m}");
        }
    }

    #[test]
    fn rejects_bad_input() {
        let nan = [f64::NAN, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0];
        assert!(
            Quadric::new(nan, None)
                .unwrap_err()
                .to_string()
                .contains("not finite")
        );
        let empty = [1.0, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0];
        assert!(
            Quadric::new(empty, None)
                .unwrap_err()
                .to_string()
                .contains("no real points")
        );
        let point = [1.0, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
        assert!(
            Quadric::new(point, None)
                .unwrap_err()
                .to_string()
                .contains("degenerate")
        );
        let all = [-1.0, -1.0, -1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0];
        assert!(
            Quadric::new(all, None)
                .unwrap_err()
                .to_string()
                .contains("all space")
        );
        let constant = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0];
        assert!(Quadric::new(constant, None).is_err());
        // An imaginary cylinder x² + y² + 1 = 0.
        let cyl = [1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0];
        assert!(Quadric::new(cyl, None).is_err());
        // A real one is fine, and so is a plane written as a quadric.
        let cyl = [1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0];
        assert!(!Quadric::new(cyl, None).unwrap().is_bounded());
        let plane = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, -1.0];
        assert!(Quadric::new(plane, None).is_ok());
        let flat = Aabb {
            min: Vec3::ZERO,
            max: Vec3::new(1.0, 0.0, 1.0),
        };
        assert!(
            Quadric::new(cyl, Some(flat))
                .unwrap_err()
                .to_string()
                .contains("clip box")
        );
        assert!(Quadric::sphere(Vec3::ZERO, 0.0).is_err());
        assert!(Quadric::sphere(Vec3::ZERO, -1.0).is_err());
        assert!(Quadric::sphere(Vec3::splat(f32::INFINITY), 1.0).is_err());
        assert!(Quadric::cylinder(Vec3::ZERO, Vec3::ZERO, 1.0).is_err());
        let far = Aabb {
            min: Vec3::splat(5.0),
            max: Vec3::splat(6.0),
        };
        assert!(
            Quadric::sphere(Vec3::ZERO, 1.0)
                .unwrap()
                .with_clip(far)
                .is_err()
        );
    }

    #[test]
    fn world_coefficients_round_trip() {
        let c = [1.0, 2.0, 3.0, 0.1, 0.2, 0.3, -1.0, 2.0, -3.0, -40.0];
        let q = Quadric::new(c, None).unwrap();
        let w = q.coefficients();
        let s = w[0] / c[0];
        for k in 0..10 {
            assert!(
                (w[k] - s * c[k]).abs() < 1e-12 * s * 40.0,
                "{k}: {w:?} vs {c:?}"
            );
        }
    }
}
