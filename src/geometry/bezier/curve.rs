//! Bézier curves of any degree.

use glam::DVec3;

/// `(1 − t)·a + t·b` in one coordinate: exactly `a` at `t = 0`, exactly `b` at `t = 1`,
/// and exactly `a` (as `+0` for a zero) wherever `a == b`, so that collapsed control
/// points stay collapsed. For a `t` whose complement `1 − t` is exact (every dyadic
/// parameter the tessellator uses), `lerp1(b, a, 1 − t)` is bitwise `lerp1(a, b, t)`.
#[inline]
fn lerp1(a: f64, b: f64, t: f64) -> f64 {
    if a == b {
        a + 0.0
    } else {
        (1.0 - t) * a + t * b
    }
}

/// Per-coordinate [`lerp1`]: the de Casteljau step.
#[inline]
pub(crate) fn lerp(a: DVec3, b: DVec3, t: f64) -> DVec3 {
    DVec3::new(lerp1(a.x, b.x, t), lerp1(a.y, b.y, t), lerp1(a.z, b.z, t))
}

/// Whether `a` sorts before `b` in the total order of their coordinates (x, then y,
/// then z, each by `f64::total_cmp`).
fn lex_less(a: &[DVec3], b: &[DVec3]) -> bool {
    for (p, q) in a.iter().zip(b) {
        for k in 0..3 {
            match p[k].total_cmp(&q[k]) {
                std::cmp::Ordering::Less => return true,
                std::cmp::Ordering::Greater => return false,
                std::cmp::Ordering::Equal => {}
            }
        }
    }
    false
}

/// The orientation of a control polygon that every reader agrees on: the point
/// sequence or its reverse, whichever sorts first, with any `−0` coordinate made `+0`.
/// Returns the polygon and whether it was reversed. Computations on the canonical
/// polygon give bitwise the same result whichever way round the caller's polygon was.
pub(crate) fn canonical<const N: usize>(p: [DVec3; N]) -> ([DVec3; N], bool) {
    let p = p.map(|q| q + DVec3::ZERO);
    let mut r = p;
    r.reverse();
    if lex_less(&r, &p) {
        (r, true)
    } else {
        (p, false)
    }
}

/// A Bézier curve of degree `n = points.len() − 1` in 3-D:
/// `C(t) = Σᵢ Bᵢⁿ(t)·pᵢ` with the Bernstein polynomials `Bᵢⁿ(t) = C(n, i) tⁱ (1 − t)ⁿ⁻ⁱ`,
/// `t ∈ [0, 1]`.
#[derive(Clone, Debug, PartialEq)]
pub struct BezierCurve {
    /// The control points, `p₀ … pₙ`; never empty.
    pub points: Vec<DVec3>,
}

impl BezierCurve {
    /// The curve with these control points.
    ///
    /// # Panics
    /// If `points` is empty.
    pub fn new(points: Vec<DVec3>) -> Self {
        assert!(!points.is_empty(), "a Bézier curve needs a control point");
        BezierCurve { points }
    }

    /// The degree `n` (one less than the number of control points).
    pub fn degree(&self) -> usize {
        self.points.len() - 1
    }

    /// The point at parameter `t`, by de Casteljau's algorithm (repeated linear
    /// interpolation of the control polygon, numerically stable for `t ∈ [0, 1]`).
    /// Exact at the ends: `eval(0) = p₀`, `eval(1) = pₙ`.
    pub fn eval(&self, t: f64) -> DVec3 {
        let mut w = self.points.clone();
        for level in (1..w.len()).rev() {
            for i in 0..level {
                w[i] = lerp(w[i], w[i + 1], t);
            }
        }
        w[0]
    }

    /// The hodograph `C′(t)`: the curve of degree `n − 1` with control points
    /// `n·(pᵢ₊₁ − pᵢ)`. A constant curve (degree 0) has the zero curve (one control
    /// point at the origin) as its derivative.
    pub fn derivative(&self) -> BezierCurve {
        let n = self.degree();
        if n == 0 {
            return BezierCurve::new(vec![DVec3::ZERO]);
        }
        let scale = n as f64;
        BezierCurve::new(
            self.points
                .windows(2)
                .map(|w| (w[1] - w[0]) * scale)
                .collect(),
        )
    }

    /// Subdivision at `t` (de Casteljau): the curves of the same degree that trace
    /// `C` on `[0, t]` and on `[t, 1]`, each reparametrised to `[0, 1]`:
    /// `left.eval(s) = C(s·t)`, `right.eval(s) = C(t + s·(1 − t))`. They share the
    /// point `C(t)` exactly.
    pub fn split(&self, t: f64) -> (BezierCurve, BezierCurve) {
        let n = self.points.len();
        let mut w = self.points.clone();
        let mut left = Vec::with_capacity(n);
        let mut right = Vec::with_capacity(n);
        left.push(w[0]);
        right.push(w[n - 1]);
        for level in (1..n).rev() {
            for i in 0..level {
                w[i] = lerp(w[i], w[i + 1], t);
            }
            left.push(w[0]);
            right.push(w[level - 1]);
        }
        right.reverse();
        (BezierCurve::new(left), BezierCurve::new(right))
    }

    /// Degree elevation: the same curve written with `n + 2` control points,
    /// `qᵢ = i/(n+1)·pᵢ₋₁ + (1 − i/(n+1))·pᵢ`. Each new point is a convex combination
    /// of two old neighbours, so the polygon moves towards the curve:
    /// [`flatness`](Self::flatness) and [`chord_error_bound`](Self::chord_error_bound)
    /// do not grow.
    pub fn elevate(&self) -> BezierCurve {
        let p = &self.points;
        let m = p.len(); // n + 1
        let mut q = Vec::with_capacity(m + 1);
        q.push(p[0]);
        for i in 1..m {
            let a = i as f64 / m as f64;
            q.push(p[i - 1] * a + p[i] * (1.0 - a));
        }
        q.push(p[m - 1]);
        BezierCurve::new(q)
    }

    /// The same curve traced backwards: control points in reverse order.
    pub fn reversed(&self) -> BezierCurve {
        let mut p = self.points.clone();
        p.reverse();
        BezierCurve::new(p)
    }

    /// Flatness of the control polygon: the largest distance of a control point from
    /// the chord, the segment `p₀pₙ` (from `p₀` when the ends coincide). The curve lies
    /// in the hull of its control points, so no point of it is farther from the chord.
    /// Zero exactly when all control points lie on the chord. Computed on the canonical
    /// orientation of the polygon, so reversing the points gives bitwise the same value.
    pub fn flatness(&self) -> f64 {
        let mut p = self.points.clone();
        let mut r = p.clone();
        r.reverse();
        if lex_less(&r, &p) {
            p = r;
        }
        let (a, b) = (p[0], p[p.len() - 1]);
        p.iter()
            .map(|&q| distance_to_segment(q, a, b))
            .fold(0.0, f64::max)
    }

    /// A bound on the distance between the curve and its chord at the same parameter,
    /// `|C(t) − ((1 − t)·p₀ + t·pₙ)|` for all `t ∈ [0, 1]`: `n(n − 1)/8 · maxᵢ |Δ²pᵢ|`,
    /// with `Δ²pᵢ = pᵢ − 2pᵢ₊₁ + pᵢ₊₂` the control polygon's second differences (the
    /// second derivative is the Bézier curve with control points `n(n−1)·Δ²pᵢ`, and
    /// linear interpolation errs by at most an eighth of its largest value). Exact for
    /// parabolas. Subdividing at `1/2` divides it by at least 4.
    pub fn chord_error_bound(&self) -> f64 {
        let n = self.degree();
        if n < 2 {
            return 0.0;
        }
        let max = self
            .points
            .windows(3)
            .map(|w| (w[0] - 2.0 * w[1] + w[2]).length())
            .fold(0.0, f64::max);
        (n * (n - 1)) as f64 / 8.0 * max
    }
}

/// Distance from `q` to the segment `ab` (to `a` when the segment is a point).
fn distance_to_segment(q: DVec3, a: DVec3, b: DVec3) -> f64 {
    let ab = b - a;
    let len2 = ab.length_squared();
    if len2 == 0.0 {
        return (q - a).length();
    }
    let t = ((q - a).dot(ab) / len2).clamp(0.0, 1.0);
    (q - (a + ab * t)).length()
}

// The cubic specialisations used by patches and the tessellator, on fixed arrays.

/// The point of the cubic with control points `p` at `t` (de Casteljau).
#[inline]
pub(crate) fn cubic_eval(p: &[DVec3; 4], t: f64) -> DVec3 {
    let a = lerp(p[0], p[1], t);
    let b = lerp(p[1], p[2], t);
    let c = lerp(p[2], p[3], t);
    let d = lerp(a, b, t);
    let e = lerp(b, c, t);
    lerp(d, e, t)
}

/// The cubic's value and its first three derivatives at `t`.
#[inline]
pub(crate) fn cubic_derivatives(p: &[DVec3; 4], t: f64) -> [DVec3; 4] {
    let d1 = [p[1] - p[0], p[2] - p[1], p[3] - p[2]];
    let d2 = [d1[1] - d1[0], d1[2] - d1[1]];
    let d3 = d2[1] - d2[0];
    let q = lerp(lerp(d1[0], d1[1], t), lerp(d1[1], d1[2], t), t);
    [
        cubic_eval(p, t),
        3.0 * q,
        6.0 * lerp(d2[0], d2[1], t),
        6.0 * d3,
    ]
}

/// The cubic split at `t` into the pieces on `[0, t]` and `[t, 1]`.
#[inline]
pub(crate) fn cubic_split(p: &[DVec3; 4], t: f64) -> ([DVec3; 4], [DVec3; 4]) {
    let a = lerp(p[0], p[1], t);
    let b = lerp(p[1], p[2], t);
    let c = lerp(p[2], p[3], t);
    let d = lerp(a, b, t);
    let e = lerp(b, c, t);
    let m = lerp(d, e, t);
    ([p[0], a, d, m], [m, e, c, p[3]])
}

/// [`BezierCurve::chord_error_bound`] of a cubic: `3/4 · max |Δ²pᵢ|`.
#[inline]
pub(crate) fn cubic_chord_error_bound(p: &[DVec3; 4]) -> f64 {
    let a = (p[0] - 2.0 * p[1] + p[2]).length();
    let b = (p[1] - 2.0 * p[2] + p[3]).length();
    0.75 * a.max(b)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample_curve() -> [DVec3; 4] {
        [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 2.0, -1.0),
            DVec3::new(3.0, -1.0, 0.5),
            DVec3::new(4.0, 0.5, 2.0),
        ]
    }

    #[test]
    fn lerp_is_exact_at_the_ends_and_for_equal_coordinates() {
        let a = DVec3::new(0.1, -0.0, 3.0);
        let b = DVec3::new(0.7, 0.0, 3.0);
        assert_eq!(lerp(a, b, 0.0), a + 0.0);
        assert_eq!(lerp(a, b, 1.0), b);
        for t in [0.1, 1.0 / 3.0, 0.5, 0.9] {
            let m = lerp(a, b, t);
            assert_eq!(m.z, 3.0);
            // Equal coordinates of different sign of zero give +0 either way round.
            assert_eq!(m.y.to_bits(), 0.0f64.to_bits());
        }
    }

    #[test]
    fn dyadic_evaluation_is_bitwise_symmetric_under_reversal() {
        let p = sample_curve();
        let mut r = p;
        r.reverse();
        for k in 0..=64 {
            let t = f64::from(k) / 64.0;
            assert_eq!(
                cubic_eval(&p, t).to_array().map(f64::to_bits),
                cubic_eval(&r, 1.0 - t).to_array().map(f64::to_bits),
                "t = {t}"
            );
        }
    }

    #[test]
    fn canonical_orientation_is_shared_by_both_directions() {
        let p = sample_curve();
        let mut r = p;
        r.reverse();
        let (cp, rev_p) = canonical(p);
        let (cr, rev_r) = canonical(r);
        assert_eq!(cp, cr);
        assert_ne!(rev_p, rev_r);
        // A palindrome is its own canonical form, not reversed.
        let pal = [p[0], p[1], p[1], p[0]];
        assert_eq!(canonical(pal), (pal, false));
    }

    #[test]
    fn cubic_helpers_agree_with_the_general_curve() {
        let p = sample_curve();
        let c = BezierCurve::new(p.to_vec());
        let d1 = c.derivative();
        let d2 = d1.derivative();
        let d3 = d2.derivative();
        for t in [0.0, 0.2, 0.5, 0.8, 1.0] {
            let d = cubic_derivatives(&p, t);
            assert!((d[0] - c.eval(t)).length() < 1e-14);
            assert!((d[1] - d1.eval(t)).length() < 1e-13);
            assert!((d[2] - d2.eval(t)).length() < 1e-13);
            assert!((d[3] - d3.eval(t)).length() < 1e-13);
            let (l, r) = cubic_split(&p, t);
            let (gl, gr) = c.split(t);
            assert_eq!(l.to_vec(), gl.points);
            assert_eq!(r.to_vec(), gr.points);
        }
        assert_eq!(cubic_chord_error_bound(&p), c.chord_error_bound());
    }
}
