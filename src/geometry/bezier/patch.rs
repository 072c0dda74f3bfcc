//! Bicubic tensor-product Bézier patches.

use super::curve::{cubic_derivatives, cubic_eval, cubic_split};
use glam::DVec3;

/// A bicubic Bézier patch `P(u, v) = Σᵢ Σⱼ Bᵢ³(u) Bⱼ³(v) p[i][j]`, `(u, v) ∈ [0, 1]²`.
///
/// The first index runs along `u`, the second along `v`: `p[i][0]` (`i = 0‥3`) is the
/// control polygon of the boundary curve `v = 0`, `p[0][j]` that of `u = 0`. The
/// front side, towards which [`normal`](Self::normal) points, is the one from which
/// the `u` direction turns counterclockwise into the `v` direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BezierPatch {
    /// The 16 control points, `p[i][j]` with `i` along `u` and `j` along `v`.
    pub p: [[DVec3; 4]; 4],
}

/// `p[i][j]` for `j` fixed: the control polygon along `u`.
#[inline]
fn column(p: &[[DVec3; 4]; 4], j: usize) -> [DVec3; 4] {
    [p[0][j], p[1][j], p[2][j], p[3][j]]
}

impl BezierPatch {
    /// The patch with these control points (`p[i][j]`, `i` along `u`).
    pub fn new(p: [[DVec3; 4]; 4]) -> Self {
        BezierPatch { p }
    }

    /// The same surface with `u` and `v` swapped (which flips the normal).
    pub fn transposed(&self) -> Self {
        let mut q = self.p;
        for (i, row) in q.iter_mut().enumerate() {
            for (j, x) in row.iter_mut().enumerate() {
                *x = self.p[j][i];
            }
        }
        BezierPatch { p: q }
    }

    /// The points `cⱼ(u)` of the four `u` curves at `u`: the control polygon along
    /// `v` of the isoparametric curve at that `u`.
    #[inline]
    fn at_u(&self, u: f64) -> [DVec3; 4] {
        std::array::from_fn(|j| cubic_eval(&column(&self.p, j), u))
    }

    /// The surface point at `(u, v)` (tensor-product de Casteljau: along `u`, then `v`).
    /// Exact at the corners: `eval(0, 0) = p[0][0]`, `eval(1, 0) = p[3][0]`, and so on.
    pub fn eval(&self, u: f64, v: f64) -> DVec3 {
        cubic_eval(&self.at_u(u), v)
    }

    /// The partial derivative `∂P/∂u` at `(u, v)`.
    pub fn du(&self, u: f64, v: f64) -> DVec3 {
        let d: [DVec3; 4] = std::array::from_fn(|j| cubic_derivatives(&column(&self.p, j), u)[1]);
        cubic_eval(&d, v)
    }

    /// The partial derivative `∂P/∂v` at `(u, v)`.
    pub fn dv(&self, u: f64, v: f64) -> DVec3 {
        cubic_derivatives(&self.at_u(u), v)[1]
    }

    /// All mixed partial derivatives `∂ᵃ_u ∂ᵇ_v P(u, v)` for `a, b ∈ 0‥3` as
    /// `[a][b]` (higher orders vanish); `[0][0]` is the point itself.
    pub fn partials(&self, u: f64, v: f64) -> [[DVec3; 4]; 4] {
        // du[j][a]: the a-th u derivative of the j-th u curve.
        let du: [[DVec3; 4]; 4] =
            std::array::from_fn(|j| cubic_derivatives(&column(&self.p, j), u));
        std::array::from_fn(|a| cubic_derivatives(&[du[0][a], du[1][a], du[2][a], du[3][a]], v))
    }

    /// The unit normal `(∂P/∂u × ∂P/∂v) / |∂P/∂u × ∂P/∂v|`.
    ///
    /// Where the cross product vanishes (a boundary edge collapsed to a point, as at
    /// the teapot's lid knob and bottom, or parallel derivatives) the normal is its
    /// limit as `(u, v)` is approached from inside the patch, along the line from the
    /// patch centre: the cross product along that line is a polynomial in the distance
    /// `h`, `Σₖ hᵏ nₖ`, whose coefficients come from the exact mixed partials, and its
    /// first coefficient that is not negligible gives the direction. The result agrees
    /// with the normals at neighbouring parameters and is never NaN. Only a patch
    /// without a tangent plane anywhere along every such line (a patch collapsed to a
    /// curve or a point) gives `DVec3::ZERO`.
    pub fn normal(&self, u: f64, v: f64) -> DVec3 {
        let du = self.du(u, v);
        let dv = self.dv(u, v);
        let n = du.cross(dv);
        let tiny = 1e-9 * self.derivative_scale().powi(2);
        if n.length() > tiny {
            return n.normalize();
        }
        if !tiny.is_normal() {
            return DVec3::ZERO;
        }
        let partials = self.partials(u, v);
        let to_centre = (0.5 - u, 0.5 - v);
        let directions = [
            to_centre,
            (1.0, 1.0),
            (-1.0, 1.0),
            (1.0, -1.0),
            (-1.0, -1.0),
        ];
        for (du_dir, dv_dir) in directions {
            let len = du_dir.abs().max(dv_dir.abs());
            if len == 0.0 {
                continue;
            }
            if let Some(n) = limit_normal(&partials, du_dir / len, dv_dir / len, tiny) {
                return n;
            }
        }
        DVec3::ZERO
    }

    /// An upper bound on `|∂P/∂u|` and `|∂P/∂v|` over the patch, from the control net
    /// (3 × the longest control-polygon leg), used to tell a vanishing normal from a
    /// small one.
    fn derivative_scale(&self) -> f64 {
        let mut m: f64 = 0.0;
        for i in 0..4 {
            for j in 0..4 {
                if i < 3 {
                    m = m.max((self.p[i + 1][j] - self.p[i][j]).length());
                }
                if j < 3 {
                    m = m.max((self.p[i][j + 1] - self.p[i][j]).length());
                }
            }
        }
        3.0 * m
    }

    /// De Casteljau subdivision at `u = t`: the patches over `[0, t] × [0, 1]` and
    /// `[t, 1] × [0, 1]`, each reparametrised to `[0, 1]²`.
    pub fn split_u(&self, t: f64) -> (BezierPatch, BezierPatch) {
        let mut left = self.p;
        let mut right = self.p;
        for j in 0..4 {
            let (l, r) = cubic_split(&column(&self.p, j), t);
            for i in 0..4 {
                left[i][j] = l[i];
                right[i][j] = r[i];
            }
        }
        (BezierPatch { p: left }, BezierPatch { p: right })
    }

    /// De Casteljau subdivision at `v = t`: the patches over `[0, 1] × [0, t]` and
    /// `[0, 1] × [t, 1]`, each reparametrised to `[0, 1]²`.
    pub fn split_v(&self, t: f64) -> (BezierPatch, BezierPatch) {
        let mut left = self.p;
        let mut right = self.p;
        for i in 0..4 {
            let (l, r) = cubic_split(&self.p[i], t);
            left[i] = l;
            right[i] = r;
        }
        (BezierPatch { p: left }, BezierPatch { p: right })
    }

    /// A bound on the distance between the patch and any triangle whose vertices are
    /// surface points, at the same parameters: `|P(x) − T(x)| ≤ ¾·(D_uu + D_vv) +
    /// 9/4·D_uv` for every `x` in the triangle, with `D_uu`, `D_vv`, `D_uv` the largest
    /// second differences of the control net along `u`, along `v` and mixed
    /// (`|p[i][j] − 2p[i+1][j] + p[i+2][j]|`, …, `|p[i+1][j+1] − p[i+1][j] − p[i][j+1] +
    /// p[i][j]|`).
    ///
    /// Why: with `T` the linear interpolant of `P` at the vertices `xₖ` (weights `λₖ`),
    /// Taylor's theorem gives `T(x) − P(x) = Σ λₖ Rₖ` with
    /// `|Rₖ| ≤ ½(M_uu Δu² + 2M_uv|Δu Δv| + M_vv Δv²)`, `M` bounding the second partials
    /// (`|P_uu| ≤ 6 D_uu`, `|P_vv| ≤ 6 D_vv`, `|P_uv| ≤ 9 D_uv` over the patch), and the
    /// weighted means of `Δu²`, `Δv²` and `|Δu Δv|` over the vertices are at most ¼ of
    /// the squared (product of the) parameter ranges, at most 1. Tight for a cylinder
    /// bent along one parameter and for a hyperbolic paraboloid. Subdivision shrinks it:
    /// halving in `u` divides `D_uu` by at least 4 and `D_uv` by at least 2.
    pub fn triangle_error_bound(&self) -> f64 {
        let (uu, vv, uv) = self.second_differences();
        0.75 * (uu + vv) + 2.25 * uv
    }

    /// The largest second differences of the control net: along `u`, along `v`, mixed.
    pub(crate) fn second_differences(&self) -> (f64, f64, f64) {
        let p = &self.p;
        let (mut uu, mut vv, mut uv) = (0.0f64, 0.0f64, 0.0f64);
        for i in 0..4 {
            for j in 0..4 {
                if i < 2 {
                    uu = uu.max((p[i][j] - 2.0 * p[i + 1][j] + p[i + 2][j]).length());
                }
                if j < 2 {
                    vv = vv.max((p[i][j] - 2.0 * p[i][j + 1] + p[i][j + 2]).length());
                }
                if i < 3 && j < 3 {
                    uv = uv.max((p[i + 1][j + 1] - p[i + 1][j] - p[i][j + 1] + p[i][j]).length());
                }
            }
        }
        (uu, vv, uv)
    }
}

/// The direction of `∂P/∂u × ∂P/∂v` at `x + h·d` as `h → 0⁺`, from the partials at
/// `x`: with `∂P/∂u(x + h d) = Σₖ hᵏ αₖ` and `∂P/∂v(x + h d) = Σₖ hᵏ βₖ`, the cross
/// product is `Σₖ hᵏ nₖ`, `nₖ = Σᵢ₊ⱼ₌ₖ αᵢ × βⱼ`; the first `nₖ` longer than `tiny`
/// dominates for small `h > 0`. `None` if every coefficient is negligible.
fn limit_normal(partials: &[[DVec3; 4]; 4], du: f64, dv: f64, tiny: f64) -> Option<DVec3> {
    // Taylor coefficients along the line, up to degree 5 (each of ∂P/∂u and ∂P/∂v has
    // total degree at most 5).
    let mut alpha = [DVec3::ZERO; 6];
    let mut beta = [DVec3::ZERO; 6];
    let fact = [1.0, 1.0, 2.0, 6.0];
    for a in 0..4 {
        for b in 0..4 {
            let w = du.powi(a as i32) * dv.powi(b as i32) / (fact[a] * fact[b]);
            if a < 3 {
                alpha[a + b] += w * partials[a + 1][b];
            }
            if b < 3 {
                beta[a + b] += w * partials[a][b + 1];
            }
        }
    }
    for k in 0..=10 {
        let mut n = DVec3::ZERO;
        for i in 0..=k.min(5) {
            if k - i <= 5 {
                n += alpha[i].cross(beta[k - i]);
            }
        }
        if n.length() > tiny {
            return Some(n.normalize());
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bump() -> BezierPatch {
        BezierPatch::new(std::array::from_fn(|i| {
            std::array::from_fn(|j| {
                let z = if (1..3).contains(&i) && (1..3).contains(&j) {
                    1.0
                } else {
                    0.0
                };
                DVec3::new(i as f64, j as f64 + 0.3 * i as f64, z)
            })
        }))
    }

    #[test]
    fn partials_agree_with_du_dv_and_each_other() {
        let p = bump();
        for (u, v) in [(0.0, 0.0), (0.3, 0.7), (1.0, 0.5)] {
            let d = p.partials(u, v);
            assert!((d[0][0] - p.eval(u, v)).length() < 1e-14);
            assert!((d[1][0] - p.du(u, v)).length() < 1e-13);
            assert!((d[0][1] - p.dv(u, v)).length() < 1e-13);
            // ∂uv from the transposed patch is ∂vu.
            let t = p.transposed().partials(v, u);
            for a in 0..4 {
                for b in 0..4 {
                    assert!((d[a][b] - t[b][a]).length() < 1e-12, "{a} {b}");
                }
            }
        }
    }

    #[test]
    fn collapsed_edge_normal_is_the_limit_from_inside() {
        // A cone-like patch: the v = 0 edge collapsed to the apex (0, 0, 1) of a
        // surface of revolution; at the apex the normal is the limit of the interior
        // normals, not NaN.
        let apex = DVec3::new(0.0, 0.0, 1.0);
        let p = BezierPatch::new(std::array::from_fn(|i| {
            std::array::from_fn(|j| {
                if j == 0 {
                    apex
                } else {
                    let r = j as f64 / 3.0;
                    let a = i as f64 * 0.4;
                    DVec3::new(r * a.cos(), r * a.sin(), 1.0 - 0.5 * r * r)
                }
            })
        }));
        for u in [0.0, 0.25, 0.5, 1.0] {
            let n = p.normal(u, 0.0);
            assert!((n.length() - 1.0).abs() < 1e-12, "{n}");
            let near = p.normal(u + (0.5 - u) * 1e-4, 1e-4);
            assert!(n.dot(near) > (1.0f64).to_radians().cos(), "{n} vs {near}");
        }
        // A patch collapsed to a point has no normal.
        let point = BezierPatch::new([[apex; 4]; 4]);
        assert_eq!(point.normal(0.5, 0.5), DVec3::ZERO);
    }

    #[test]
    fn error_bound_is_tight_for_a_hyperbolic_paraboloid() {
        // P(u, v) = (u, v, u v): the two triangles of the unit square err by 1/4 at
        // the centre, and the bound says exactly that.
        let p = BezierPatch::new(std::array::from_fn(|i| {
            std::array::from_fn(|j| {
                let (u, v) = (i as f64 / 3.0, j as f64 / 3.0);
                DVec3::new(u, v, u * v)
            })
        }));
        assert!((p.triangle_error_bound() - 0.25).abs() < 1e-15);
        let mid = 0.5 * (p.eval(0.0, 0.0) + p.eval(1.0, 1.0));
        assert!(((p.eval(0.5, 0.5) - mid).length() - 0.25).abs() < 1e-15);
    }
}
