//! Test polygons: regular polygons, the SPD's gear outline, combs and spirals.

use crate::math::Vec3;
use std::f32::consts::TAU;

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
