use super::{ShapeHit, SurfacePoint};
use crate::math::{Aabb, Ray, Vec3, gamma};

/// A triangle. Its front side is the one from which the vertices appear
/// counterclockwise; the geometric normal `(p1 − p0) × (p2 − p0)` points to it.
/// Intersection is two-sided.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Triangle {
    /// The three vertices.
    pub p: [Vec3; 3],
}

/// A ray prepared for the watertight test (Woop, Benthin and Wald, JCGT 2013): the axis
/// of largest direction component becomes z and the other two are sheared away.
#[derive(Clone, Copy, Debug)]
pub struct WatertightRay {
    org: Vec3,
    k: [usize; 3],
    shear: Vec3,
    tmin: f32,
    tmax: f32,
}

impl WatertightRay {
    /// Precompute the permutation and shear for `ray`.
    #[inline]
    pub fn new(ray: &Ray) -> Self {
        // Arrays, not `Vec3` indexing (a match on the index in glam).
        let d = ray.dir.to_array();
        let a = ray.dir.abs();
        // The first axis of largest magnitude (as `Vec3::max_position` picks it).
        let (mut kz, mut largest) = (0, a.x);
        if a.y > largest {
            (kz, largest) = (1, a.y);
        }
        if a.z > largest {
            kz = 2;
        }
        let (mut kx, mut ky) = ([1, 2, 0][kz], [2, 0, 1][kz]);
        if d[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        let dz = d[kz];
        WatertightRay {
            org: ray.org,
            k: [kx, ky, kz],
            shear: Vec3::new(d[kx] / dz, d[ky] / dz, 1.0 / dz),
            tmin: ray.tmin,
            tmax: ray.tmax,
        }
    }

    /// Narrow the far end of the interval (after a closer hit).
    #[inline]
    pub fn set_tmax(&mut self, tmax: f32) {
        self.tmax = tmax;
    }

    /// Origin, axis permutation, shear and interval, for the 4-wide test
    /// ([`Triangle4`](super::Triangle4)).
    #[inline]
    pub(crate) fn parts(&self) -> (Vec3, [usize; 3], Vec3, f32, f32) {
        (self.org, self.k, self.shear, self.tmin, self.tmax)
    }
}

impl Triangle {
    /// Geometric normal `(p1 − p0) × (p2 − p0)`, not normalised.
    #[inline]
    pub fn normal(&self) -> Vec3 {
        (self.p[1] - self.p[0]).cross(self.p[2] - self.p[0])
    }

    /// Bounds.
    pub fn bounds(&self) -> Aabb {
        Aabb::from_points(self.p[0], self.p[1]).grow(self.p[2])
    }

    /// Area.
    pub fn area(&self) -> f32 {
        0.5 * self.normal().length()
    }

    /// Watertight intersection: no ray passes between two triangles sharing an edge.
    /// Always inlined: it is the inner loop of the BVH's leaves and of every hit's
    /// exact recomputation ([`crate::scene::Geometry::exact_hit`]), whose cost should not
    /// depend on what else the caller inlines.
    #[inline(always)]
    pub fn intersect_wt(&self, r: &WatertightRay) -> Option<ShapeHit> {
        let [kx, ky, kz] = r.k;
        let a = (self.p[0] - r.org).to_array();
        let b = (self.p[1] - r.org).to_array();
        let c = (self.p[2] - r.org).to_array();
        let s = r.shear;
        let ax = a[kx] - s.x * a[kz];
        let ay = a[ky] - s.y * a[kz];
        let bx = b[kx] - s.x * b[kz];
        let by = b[ky] - s.y * b[kz];
        let cx = c[kx] - s.x * c[kz];
        let cy = c[ky] - s.y * c[kz];
        let mut u = cx * by - cy * bx;
        let mut v = ax * cy - ay * cx;
        let mut w = bx * ay - by * ax;
        if u == 0.0 || v == 0.0 || w == 0.0 {
            // Exactly on an edge in f32: decide it in f64, as the paper prescribes.
            let (ax, ay, bx, by, cx, cy) = (
                ax as f64, ay as f64, bx as f64, by as f64, cx as f64, cy as f64,
            );
            u = (cx * by - cy * bx) as f32;
            v = (ax * cy - ay * cx) as f32;
            w = (bx * ay - by * ax) as f32;
        }
        if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
            return None;
        }
        let det = u + v + w;
        if det == 0.0 {
            return None;
        }
        let az = s.z * a[kz];
        let bz = s.z * b[kz];
        let cz = s.z * c[kz];
        let tt = u * az + v * bz + w * cz;
        let inv = 1.0 / det;
        let t = tt * inv;
        if !(t > r.tmin && t < r.tmax) {
            return None;
        }
        // Reject t within its own rounding error of zero (pbrt §6.8.7), so that a ray
        // leaving the surface from a robustly offset origin cannot re-hit it. The sheared
        // x and y are lengths, with an error relative to |x| + |z| before z is divided
        // by the direction's z (|Sx·z| ≤ |z| as |d[kx]| ≤ |d[kz]|); pbrt adds the divided
        // z there, which makes the bound depend on the direction's length: a shadow ray
        // towards a light (an unnormalised direction) in a scene 10⁻⁴ units across then
        // found its blocker "within rounding of 0" and passed through it.
        let max_zt = az.abs().max(bz.abs()).max(cz.abs());
        let max_z = a[kz].abs().max(b[kz].abs()).max(c[kz].abs());
        let max_xt = ax.abs().max(bx.abs()).max(cx.abs());
        let max_yt = ay.abs().max(by.abs()).max(cy.abs());
        let delta_z = gamma(3) * max_zt;
        let delta_x = gamma(5) * (max_xt + max_z);
        let delta_y = gamma(5) * (max_yt + max_z);
        let delta_e = 2.0 * (gamma(2) * max_xt * max_yt + delta_y * max_xt + delta_x * max_yt);
        let max_e = u.abs().max(v.abs()).max(w.abs());
        let delta_t =
            3.0 * (gamma(3) * max_e * max_zt + delta_e * max_zt + delta_z * max_e) * inv.abs();
        if t <= delta_t {
            return None;
        }
        Some(ShapeHit {
            t,
            u: v * inv,
            v: w * inv,
            ng: self.normal(),
        })
    }

    /// The nearest hit in `(ray.tmin, ray.tmax)`.
    #[inline]
    pub fn intersect(&self, ray: &Ray) -> Option<ShapeHit> {
        self.intersect_wt(&WatertightRay::new(ray))
    }

    /// The point with barycentrics `(1 − u − v, u, v)` and its error bound.
    ///
    /// pbrt's bound γ₇ Σ|bᵢ pᵢ| (§6.8.4) covers the interpolation, but it is zero along an
    /// axis where all three vertices share a coordinate, and a ray starting exactly on
    /// the plane may then re-hit it at a rounding-level `t` (the plane distance is
    /// computed from edges as large as the triangle). So the bound also has a term
    /// relative to the largest vertex coordinate: still no fixed epsilon, it scales with
    /// the scene.
    pub fn surface(&self, u: f32, v: f32) -> SurfacePoint {
        let b0 = 1.0 - u - v;
        let p = self.p[0] * b0 + self.p[1] * u + self.p[2] * v;
        let magnitude = self.p[0].abs().max(self.p[1].abs()).max(self.p[2].abs());
        let err = ((self.p[0] * b0).abs() + (self.p[1] * u).abs() + (self.p[2] * v).abs())
            * gamma(7)
            + Vec3::splat(magnitude.max_element() * gamma(8));
        SurfacePoint {
            p,
            err,
            ng: self.normal().normalize_or_zero(),
        }
    }
}
