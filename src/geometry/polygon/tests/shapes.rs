//! Test polygons: regular polygons, the SPD's gear outline, combs, spirals, stars and
//! large convex lattice polygons. The `exact_` shapes lie in the plane z = 0 on a
//! dyadic grid that `f32` holds exactly, so that `cover` can check them in integers.

use crate::math::Vec3;
use std::f32::consts::TAU;

/// Round to a multiple of 2⁻ᵇⁱᵗˢ: exact in `f32` below 2²⁴⁻ᵇⁱᵗˢ in magnitude.
fn snap(v: f64, bits: i32) -> f32 {
    let s = 2f64.powi(bits);
    ((v * s).round() / s) as f32
}

pub fn regular(n: usize, r: f32) -> Vec<Vec3> {
    (0..n)
        .map(|i| {
            let a = TAU * i as f32 / n as f32;
            Vec3::new(r * a.cos(), r * a.sin(), 0.0)
        })
        .collect()
}

/// A gear outline like the SPD's: `teeth` teeth, 4 vertices per tooth, the tooth
/// tips wider in angle than their roots gaps.
pub fn gear(teeth: usize, inner: f32, outer: f32) -> Vec<Vec3> {
    let mut v = Vec::new();
    for t in 0..teeth {
        let a0 = TAU * t as f32 / teeth as f32;
        let step = TAU / teeth as f32;
        for (da, r) in [(0.0, inner), (0.2, outer), (0.5, outer), (0.7, inner)] {
            let a = a0 + da * step;
            v.push(Vec3::new(r * a.cos(), r * a.sin(), 1.0));
        }
    }
    v
}

/// Rotate and translate a polygon into an arbitrary plane.
pub fn transform(points: &[Vec3]) -> Vec<Vec3> {
    let q = glam::Quat::from_euler(glam::EulerRot::XYZ, 0.7, -1.1, 2.3);
    points
        .iter()
        .map(|&p| q * p + Vec3::new(3.0, -7.0, 11.0))
        .collect()
}

/// A comb: a bar with `teeth` teeth. The corners of the bar see the teeth's roots
/// inside their triangles, so clipping a convex corner blindly goes wrong. The roots
/// all lie on one line, so cuts leave collinear vertices behind.
pub fn comb(teeth: usize) -> Vec<Vec3> {
    let w = 2.0 * teeth as f32 - 1.0;
    let mut v = vec![Vec3::new(0.0, 0.0, 0.0), Vec3::new(w, 0.0, 0.0)];
    for t in (0..teeth).rev() {
        let x = 2.0 * t as f32;
        v.push(Vec3::new(x + 1.0, 3.0, 0.0));
        v.push(Vec3::new(x, 3.0, 0.0));
        if t > 0 {
            v.push(Vec3::new(x, 1.0, 0.0));
            v.push(Vec3::new(x - 1.0, 1.0, 0.0));
        }
    }
    v
}

/// A square spiral corridor of width 1 along a centre line with legs 2, 4, 6, …
/// (4 apart), `turns` times round: walls offset ±½ with mitred corners.
pub fn spiral(turns: usize) -> Vec<Vec3> {
    let dirs = [(1.0f32, 0.0f32), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0)];
    let legs = 4 * turns;
    let mut centre = vec![(0.0f32, 0.0f32)];
    for k in 0..legs {
        let (dx, dy) = dirs[k % 4];
        let (x, y) = centre[k];
        let len = 2.0 * (k + 1) as f32;
        centre.push((x + dx * len, y + dy * len));
    }
    // Left normal of leg k, and the offset at centre-line vertex i.
    let normal = |k: usize| {
        let (dx, dy) = dirs[k % 4];
        (-dy, dx)
    };
    let offset = |i: usize| {
        let (a, b) = if i == 0 {
            (normal(0), (0.0, 0.0))
        } else if i == legs {
            (normal(legs - 1), (0.0, 0.0))
        } else {
            (normal(i - 1), normal(i))
        };
        (0.5 * (a.0 + b.0), 0.5 * (a.1 + b.1))
    };
    let left = (0..=legs).map(|i| {
        let (o, c) = (offset(i), centre[i]);
        Vec3::new(c.0 + o.0, c.1 + o.1, 0.0)
    });
    let right: Vec<Vec3> = (0..=legs)
        .map(|i| {
            let (o, c) = (offset(i), centre[i]);
            Vec3::new(c.0 - o.0, c.1 - o.1, 0.0)
        })
        .collect();
    left.chain(right.into_iter().rev()).collect()
}

/// A star of `n` vertices (`n` even) alternating between radius 1 and `inner`, on a
/// grid of 2⁻¹⁸.
pub fn exact_star(n: usize, inner: f64) -> Vec<Vec3> {
    (0..n)
        .map(|i| {
            let a = std::f64::consts::TAU * i as f64 / n as f64;
            let r = if i % 2 == 0 { 1.0 } else { inner };
            Vec3::new(snap(r * a.cos(), 18), snap(r * a.sin(), 18), 0.0)
        })
        .collect()
}

/// A star whose inner vertices are those of `farey(m)` doubled (strictly convex, as no
/// circle of that many vertices is in f32) and whose points are spikes `h` times as
/// high as the edge under them is long.
pub fn exact_spiky_star(m: i64, h: i64) -> Vec<Vec3> {
    let inner: Vec<[i64; 2]> = farey_points(m)
        .iter()
        .map(|p| [2 * p[0], 2 * p[1]])
        .collect();
    let mut v = Vec::with_capacity(2 * inner.len());
    for (i, &a) in inner.iter().enumerate() {
        let b = inner[(i + 1) % inner.len()];
        let d = [(b[0] - a[0]) / 2, (b[1] - a[1]) / 2];
        // Outwards from the counterclockwise polygon: the edge turned clockwise.
        let tip = [a[0] + d[0] + h * d[1], a[1] + d[1] - h * d[0]];
        v.extend([a, tip]);
    }
    to_vec3(&v)
}

/// A comb: a bar whose top is a lattice chain sagging in the middle (slopes from −1 to
/// 1, strictly increasing, so its vertices are reflex), with a tooth of height
/// `height` over the middle of each of its edges. `2k + 3` vertices for a chain of `k`
/// edges (`k ≈ 1.2 m²`).
pub fn exact_comb(m: i64, height: i64) -> Vec<Vec3> {
    let mut dirs: Vec<[i64; 2]> = Vec::new();
    for p in 1..=m {
        for q in -p..=p {
            if gcd(p, q.abs()) == 1 {
                dirs.push([p, q]);
            }
        }
    }
    dirs.sort_by(|a, b| (a[1] * b[0]).cmp(&(b[1] * a[0])));
    let mut chain = vec![[0i64, 0i64]];
    for d in &dirs {
        let [x, y] = chain[chain.len() - 1];
        chain.push([x + 2 * d[0], y + 2 * d[1]]);
    }
    let bottom = chain.iter().map(|p| p[1]).min().unwrap_or(0) - 7919;
    let right = chain[chain.len() - 1][0];
    let mut v = vec![[0, bottom], [right, bottom]];
    for (k, d) in dirs.iter().enumerate().rev() {
        let b = chain[k + 1];
        v.push(b);
        v.push([b[0] - d[0], b[1] - d[1] + height]);
    }
    v.push(chain[0]);
    // Centred, to stay within f32's exact integers.
    let v: Vec<[i64; 2]> = v.iter().map(|p| [p[0] - right / 2, p[1]]).collect();
    to_vec3(&v)
}

/// A corridor of width ½ along an Archimedean spiral (radius 1 + θ/2π at its outer
/// wall), `turns` times round with `per_turn` vertices per wall and turn, on a grid of
/// 2⁻¹⁶ (exact in f32 below 256).
pub fn exact_spiral(turns: usize, per_turn: usize) -> Vec<Vec3> {
    let k = turns * per_turn;
    let wall = |i: usize, inset: f64| {
        let a = std::f64::consts::TAU * i as f64 / per_turn as f64;
        let r = 1.0 + a / std::f64::consts::TAU - inset;
        Vec3::new(snap(r * a.cos(), 16), snap(r * a.sin(), 16), 0.0)
    };
    let outer = (0..=k).map(|i| wall(i, 0.0));
    let inner = (0..=k).rev().map(|i| wall(i, 0.5));
    outer.chain(inner).collect()
}

fn gcd(mut a: i64, mut b: i64) -> i64 {
    while b != 0 {
        (a, b) = (b, a % b);
    }
    a
}

/// The vertices of a strictly convex lattice polygon, counterclockwise: its edges are
/// the primitive integer vectors of coordinates at most `m` in magnitude, in order of
/// angle (`≈ 2.4 m²` vertices).
fn farey_points(m: i64) -> Vec<[i64; 2]> {
    let mut dirs: Vec<(i64, i64)> = Vec::new();
    for p in 1..=m {
        for q in 0..=m {
            if gcd(p, q) == 1 {
                dirs.extend([(p, q), (-q, p), (-p, -q), (q, -p)]);
            }
        }
    }
    dirs.sort_by(|a, b| {
        let angle = |d: &(i64, i64)| (d.1 as f64).atan2(d.0 as f64);
        angle(a).total_cmp(&angle(b))
    });
    let mut at = (0i64, 0i64);
    let mut v = Vec::with_capacity(dirs.len());
    for (dx, dy) in dirs {
        v.push(at);
        at = (at.0 + dx, at.1 + dy);
    }
    assert_eq!(at, (0, 0), "the edges close the polygon");
    let n = v.len() as i64;
    let centre = (
        v.iter().map(|p| p.0).sum::<i64>() / n,
        v.iter().map(|p| p.1).sum::<i64>() / n,
    );
    v.into_iter()
        .map(|(x, y)| [x - centre.0, y - centre.1])
        .collect()
}

/// [`farey_points`] as a polygon.
pub fn farey(m: i64) -> Vec<Vec3> {
    to_vec3(&farey_points(m))
}

/// Integer points as vertices in the plane z = 0 (exact below 2²⁴).
fn to_vec3(points: &[[i64; 2]]) -> Vec<Vec3> {
    points
        .iter()
        .map(|p| {
            assert!(
                p[0].abs() < 1 << 24 && p[1].abs() < 1 << 24,
                "{p:?} is not exact in f32"
            );
            Vec3::new(p[0] as f32, p[1] as f32, 0.0)
        })
        .collect()
}

/// `points` (integer coordinates) scaled by `k` with `k − 1` evenly spaced points
/// inserted along each edge: a polygon of the same shape with collinear vertices.
pub fn subdivided(points: &[Vec3], k: usize) -> Vec<Vec3> {
    let mut v = Vec::with_capacity(points.len() * k);
    for (i, &p) in points.iter().enumerate() {
        let q = points[(i + 1) % points.len()];
        for s in 0..k {
            v.push(p * k as f32 + (q - p) * s as f32);
        }
    }
    v
}
