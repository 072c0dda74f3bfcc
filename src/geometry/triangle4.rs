//! Four triangles tested against one ray at once: the watertight test of
//! [`Triangle::intersect_wt`] run on glam's `Vec4` (one SSE register per quantity, one
//! triangle per lane), for the BVH's leaves.
//!
//! The vertices are stored structure-of-arrays (`p[vertex][axis]`, four lanes each), so
//! the ray's axis permutation picks whole registers and no lane is shuffled. Every lane
//! performs exactly the operations of the scalar test, in the same order and with the
//! same roundings, so a lane's hit is the scalar test's, bit for bit (the unit tests
//! check it): the BVH stays watertight and finds the same hits as before. The only
//! operations that are not lane-wise IEEE arithmetic are the `max` of the error bound,
//! which treats NaN differently from `f32::max`; a NaN can only reach it when the
//! distance itself is infinite or NaN, which the interval test rejects either way.

use super::triangle::{WatertightRay, distance_error, refine_in_f64};
use super::{ShapeHit, Triangle};
use glam::{BVec4A, Vec4};

/// Up to four triangles, structure-of-arrays. Unused lanes repeat the last triangle, so
/// they can only report its hit again, at the same distance and in a later lane.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Triangle4 {
    /// `p[vertex][axis]`: coordinate `axis` of vertex `vertex` of each lane's triangle.
    p: [[Vec4; 3]; 3],
}

/// A [`WatertightRay`] broadcast to four lanes: the permuted origin and shear, and the
/// interval.
#[derive(Clone, Copy, Debug)]
pub struct WatertightRay4 {
    /// The permutation (x, y, z) of the scalar ray.
    k: [usize; 3],
    /// The origin's coordinates along `k[0]`, `k[1]`, `k[2]`.
    org: [Vec4; 3],
    /// The shear (`d[kx]/d[kz]`, `d[ky]/d[kz]`, `1/d[kz]`).
    shear: [Vec4; 3],
    tmin: Vec4,
    tmax: Vec4,
    /// The scalar ray, for the f64 fallback of lanes whose f32 distance is uncertain.
    ray: WatertightRay,
}

impl WatertightRay4 {
    /// Broadcast `ray`.
    #[inline]
    pub fn new(ray: &WatertightRay) -> Self {
        let (org, k, shear, tmin, tmax) = ray.parts();
        WatertightRay4 {
            k,
            org: k.map(|a| Vec4::splat(org[a])),
            shear: [shear.x, shear.y, shear.z].map(Vec4::splat),
            tmin: Vec4::splat(tmin),
            tmax: Vec4::splat(tmax),
            ray: *ray,
        }
    }

    /// Narrow the far end of the interval (after a closer hit).
    #[inline]
    pub fn set_tmax(&mut self, tmax: f32) {
        self.tmax = Vec4::splat(tmax);
        self.ray.set_tmax(tmax);
    }
}

/// The lanes a [`Triangle4`] test accepted (bit `i` for lane `i`) with each lane's
/// distance and barycentric weights of vertices 1 and 2 (meaningful in accepted lanes).
#[derive(Clone, Copy, Debug)]
pub struct Hits4 {
    /// Accepted lanes.
    pub mask: u32,
    t: Vec4,
    u: Vec4,
    v: Vec4,
}

impl Hits4 {
    const NONE: Hits4 = Hits4 {
        mask: 0,
        t: Vec4::ZERO,
        u: Vec4::ZERO,
        v: Vec4::ZERO,
    };

    /// The accepted lane with the smallest distance, the lowest such lane on a tie (the
    /// one a scalar loop over the lanes in order would keep).
    #[inline]
    pub fn nearest(&self) -> Option<usize> {
        let mask = self.mask;
        if mask & mask.wrapping_sub(1) == 0 {
            // None or one lane: the common case.
            return (mask != 0).then(|| mask.trailing_zeros() as usize);
        }
        // Accepted distances are finite (inside the interval), so the minimum over
        // them, the others set to +∞, is one of theirs.
        let accepted = BVec4A::new(mask & 1 != 0, mask & 2 != 0, mask & 4 != 0, mask & 8 != 0);
        let t = Vec4::select(accepted, self.t, Vec4::INFINITY);
        let nearest = t.cmpeq(Vec4::splat(t.min_element())).bitmask() & mask;
        Some(nearest.trailing_zeros() as usize)
    }

    /// `(t, u, v)` of lane `i`, as [`ShapeHit`] reports them.
    #[inline]
    pub fn lane(&self, i: usize) -> (f32, f32, f32) {
        (
            self.t.to_array()[i],
            self.u.to_array()[i],
            self.v.to_array()[i],
        )
    }
}

impl Triangle4 {
    /// Pack one to four triangles; the unused lanes repeat the last one.
    ///
    /// # Panics
    /// If `tris` is empty or holds more than four triangles.
    pub fn new(tris: &[Triangle]) -> Triangle4 {
        assert!(
            (1..=4).contains(&tris.len()),
            "a Triangle4 packs 1 to 4 triangles"
        );
        let lane = |i: usize| &tris[i.min(tris.len() - 1)];
        let p = std::array::from_fn(|vertex| {
            std::array::from_fn(|axis| {
                Vec4::from_array(std::array::from_fn(|i| lane(i).p[vertex][axis]))
            })
        });
        Triangle4 { p }
    }

    /// The geometric normal of lane `i`'s triangle, [`Triangle::normal`] bit for bit
    /// (the same differences and cross product, lane-wise).
    #[inline]
    pub fn normal(&self, i: usize) -> glam::Vec3 {
        let [p0, p1, p2] = &self.p;
        let e1 = [0, 1, 2].map(|a| p1[a] - p0[a]);
        let e2 = [0, 1, 2].map(|a| p2[a] - p0[a]);
        // `Vec3::cross`: (y·z' − y'·z, z·x' − z'·x, x·y' − x'·y).
        let n = [
            e1[1] * e2[2] - e2[1] * e1[2],
            e1[2] * e2[0] - e2[2] * e1[0],
            e1[0] * e2[1] - e2[0] * e1[1],
        ];
        glam::Vec3::new(n[0].to_array()[i], n[1].to_array()[i], n[2].to_array()[i])
    }

    /// The triangle of lane `i`.
    #[inline]
    pub fn triangle(&self, i: usize) -> Triangle {
        Triangle {
            p: self.p.map(|v| {
                glam::Vec3::new(v[0].to_array()[i], v[1].to_array()[i], v[2].to_array()[i])
            }),
        }
    }

    /// The four watertight tests ([`Triangle::intersect_wt`], lane by lane).
    #[inline(always)]
    pub fn intersect(&self, r: &WatertightRay4) -> Hits4 {
        let [kx, ky, kz] = r.k;
        let [sx, sy, sz] = r.shear;
        // Vertex coordinates relative to the origin, along the permuted axes.
        let rel = |v: usize| {
            let p = &self.p[v];
            (p[kx] - r.org[0], p[ky] - r.org[1], p[kz] - r.org[2])
        };
        let (a_x, a_y, a_z) = rel(0);
        let (b_x, b_y, b_z) = rel(1);
        let (c_x, c_y, c_z) = rel(2);
        let ax = a_x - sx * a_z;
        let ay = a_y - sy * a_z;
        let bx = b_x - sx * b_z;
        let by = b_y - sy * b_z;
        let cx = c_x - sx * c_z;
        let cy = c_y - sy * c_z;
        let mut u = cx * by - cy * bx;
        let mut v = ax * cy - ay * cx;
        let mut w = bx * ay - by * ax;
        let zero = Vec4::ZERO;
        let on_edge = u.cmpeq(zero) | v.cmpeq(zero) | w.cmpeq(zero);
        if on_edge.any() {
            (u, v, w) = edges_in_f64(on_edge, [ax, ay, bx, by, cx, cy], [u, v, w]);
        }
        let negative = u.cmplt(zero) | v.cmplt(zero) | w.cmplt(zero);
        let positive = u.cmpgt(zero) | v.cmpgt(zero) | w.cmpgt(zero);
        let mut mask = !(negative & positive).bitmask() & 0xf;
        let det = u + v + w;
        mask &= !det.cmpeq(zero).bitmask();
        if mask == 0 {
            return Hits4::NONE;
        }
        let az = sz * a_z;
        let bz = sz * b_z;
        let cz = sz * c_z;
        let tt = u * az + v * bz + w * cz;
        let inv = det.recip();
        let t = tt * inv;
        mask &= t.cmplt(r.tmax).bitmask();
        if mask == 0 {
            return Hits4::NONE;
        }
        let delta_t = distance_error(
            [ax, ay, bx, by, cx, cy],
            [a_z, b_z, c_z],
            [az, bz, cz],
            [u, v, w],
            inv,
        );
        let sure = (t.cmpgt(delta_t) & t.cmpgt(r.tmin)).bitmask();
        let before = (t + delta_t).cmple(r.tmin.max(zero)).bitmask();
        let unsure = mask & !sure & !before;
        mask &= sure;
        let hits = Hits4 {
            mask,
            t,
            u: v * inv,
            v: w * inv,
        };
        if unsure == 0 {
            hits
        } else {
            self.refine_lanes(hits, unsure, &r.ray)
        }
    }

    /// `hits` with the lanes in `unsure` decided in f64, as the scalar test decides
    /// them when its f32 distance is within rounding of the interval's start
    /// ([`refine_in_f64`]).
    #[cold]
    #[inline(never)]
    fn refine_lanes(&self, hits: Hits4, unsure: u32, ray: &WatertightRay) -> Hits4 {
        let mut mask = hits.mask;
        let [mut t, mut u, mut v] = [hits.t, hits.u, hits.v].map(|x| x.to_array());
        for i in (0..4).filter(|i| unsure & (1 << i) != 0) {
            if let Some((ti, ui, vi)) = refine_in_f64(&self.triangle(i).p, ray) {
                mask |= 1 << i;
                (t[i], u[i], v[i]) = (ti, ui, vi);
            }
        }
        Hits4 {
            mask,
            t: Vec4::from_array(t),
            u: Vec4::from_array(u),
            v: Vec4::from_array(v),
        }
    }

    /// The nearest hit among the four, as `(lane, hit)`: the hit
    /// [`Triangle::intersect_wt`] reports for that lane's triangle.
    #[inline]
    pub fn nearest(&self, r: &WatertightRay4) -> Option<(usize, ShapeHit)> {
        let hits = self.intersect(r);
        let i = hits.nearest()?;
        let (t, u, v) = hits.lane(i);
        Some((
            i,
            ShapeHit {
                t,
                u,
                v,
                ng: self.normal(i),
            },
        ))
    }

    /// Whether any of the four is hit.
    #[inline]
    pub fn occluded(&self, r: &WatertightRay4) -> bool {
        self.intersect(r).mask != 0
    }
}

/// The edge functions of the lanes in `redo` recomputed in f64 from the sheared
/// coordinates, as the scalar test does for a ray exactly on an edge in f32 (rare: off
/// the fast path).
#[cold]
#[inline(never)]
fn edges_in_f64(redo: BVec4A, c: [Vec4; 6], uvw: [Vec4; 3]) -> (Vec4, Vec4, Vec4) {
    let [ax, ay, bx, by, cx, cy] = c.map(|v| v.to_array());
    let mut out = uvw.map(|v| v.to_array());
    let redo = redo.bitmask();
    for i in (0..4).filter(|i| redo & (1 << i) != 0) {
        let (ax, ay, bx, by, cx, cy) = (
            f64::from(ax[i]),
            f64::from(ay[i]),
            f64::from(bx[i]),
            f64::from(by[i]),
            f64::from(cx[i]),
            f64::from(cy[i]),
        );
        out[0][i] = (cx * by - cy * bx) as f32;
        out[1][i] = (ax * cy - ay * cx) as f32;
        out[2][i] = (bx * ay - by * ax) as f32;
    }
    let [u, v, w] = out.map(Vec4::from_array);
    (u, v, w)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{Ray, Rng, Vec3};

    /// Random triangles, some sharing edges and vertices, and random rays, some aimed
    /// exactly at shared vertices and edge midpoints.
    #[test]
    fn lanes_equal_the_scalar_test_bit_for_bit() {
        let mut rng = Rng::new(11);
        let mut exact_edges = 0;
        for case in 0..20_000 {
            let n = 1 + rng.below(4) as usize;
            // Half the cases on a grid of integers, where rays through vertices and
            // edge midpoints are exact and edge functions often exactly zero.
            let grid = case % 2 == 0;
            let mut point = |s: f32| {
                let p = rng.vec3_in(-s, s);
                if grid { p.round() } else { p }
            };
            let c = point(1.0);
            let shared = [c, c + point(1.0)];
            let tris: Vec<Triangle> = (0..n)
                .map(|_| Triangle {
                    p: [shared[0], shared[1], c + point(1.0)],
                })
                .collect();
            let org = point(4.0);
            let target = match case % 3 {
                0 => shared[0],
                1 => (shared[0] + shared[1]) * 0.5,
                _ => c + rng.vec3_in(-0.5, 0.5),
            };
            let scale = if grid { 1.0 } else { rng.range(0.1, 10.0) };
            let mut ray = Ray::new(org, (target - org) * scale);
            if case % 5 == 0 {
                ray.tmax = rng.range(0.0, 2.0);
            }
            let wt = WatertightRay::new(&ray);
            let pack = Triangle4::new(&tris);
            let hits = pack.intersect(&WatertightRay4::new(&wt));
            for (i, tri) in tris.iter().enumerate() {
                let want = tri.intersect_wt(&wt);
                assert_eq!(
                    hits.mask & (1 << i) != 0,
                    want.is_some(),
                    "case {case} lane {i}"
                );
                if let Some(w) = want {
                    let (t, u, v) = hits.lane(i);
                    assert_eq!(
                        (t.to_bits(), u.to_bits(), v.to_bits()),
                        (w.t.to_bits(), w.u.to_bits(), w.v.to_bits())
                    );
                    exact_edges += usize::from(u == 0.0 || v == 0.0);
                }
            }
            let want_nearest =
                tris.iter()
                    .enumerate()
                    .fold(None::<(usize, ShapeHit)>, |best, (i, tri)| {
                        match (best, tri.intersect_wt(&wt)) {
                            (Some(b), Some(h)) if h.t < b.1.t => Some((i, h)),
                            (None, Some(h)) => Some((i, h)),
                            (b, _) => b,
                        }
                    });
            assert_eq!(pack.nearest(&WatertightRay4::new(&wt)), want_nearest);
        }
        assert!(exact_edges > 100, "rays on edges: {exact_edges}");
    }

    /// Lanes whose f32 distance is within rounding of zero (huge, sliver and grazing
    /// triangles, origins near the plane) are decided in f64, and still equal the
    /// scalar test bit for bit.
    #[test]
    fn lanes_decided_in_f64_equal_the_scalar_test() {
        use crate::accuracy::hard_triangles::{hard_cases, known_cases};
        let mut cases = known_cases(64);
        cases.extend(hard_cases(200, 16, 5));
        let mut compared = 0;
        for pair in cases.chunks(4) {
            let tris: Vec<Triangle> = pair.iter().map(|c| c.triangle).collect();
            let pack = Triangle4::new(&tris);
            for ray in pair.iter().flat_map(|c| &c.rays) {
                let wt = WatertightRay::new(ray);
                let hits = pack.intersect(&WatertightRay4::new(&wt));
                for (i, tri) in tris.iter().enumerate() {
                    let want = tri.intersect_wt(&wt);
                    assert_eq!(hits.mask & (1 << i) != 0, want.is_some(), "lane {i}");
                    if let Some(w) = want {
                        let (t, u, v) = hits.lane(i);
                        assert_eq!(
                            (t.to_bits(), u.to_bits(), v.to_bits()),
                            (w.t.to_bits(), w.u.to_bits(), w.v.to_bits())
                        );
                        compared += 1;
                    }
                }
            }
        }
        assert!(compared > 2000, "{compared} hits compared");
    }

    #[test]
    fn unused_lanes_repeat_the_last_triangle() {
        let t = Triangle {
            p: [Vec3::ZERO, Vec3::X, Vec3::Y],
        };
        let pack = Triangle4::new(&[t]);
        for i in 0..4 {
            assert_eq!(pack.triangle(i), t);
        }
        let ray = Ray::new(Vec3::new(0.2, 0.2, 1.0), -Vec3::Z);
        let hit = pack.nearest(&WatertightRay4::new(&WatertightRay::new(&ray)));
        assert_eq!(hit.map(|(i, h)| (i, h.t)), Some((0, 1.0)));
    }
}
