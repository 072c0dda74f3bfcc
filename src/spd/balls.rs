//! The `balls` database, also known as the sphereflake (SPD `balls.c`).
//!
//! A sphere of radius ½ at the origin sprouts nine spheres of a third its radius, each
//! touching it: six around its "equator" and three around its "north pole", the
//! directions being the same for every sphere once rotated so that its own parent
//! direction is +Z. Each child sprouts nine more in turn, `size` levels deep, so size
//! factor `n` gives `1 + 9 + … + 9ⁿ = (9ⁿ⁺¹ − 1)/8` spheres. A square beige floor at
//! `z = −½` and three lights complete the scene.
//!
//! The nine unit directions are built as the SPD does: three vectors in the planes of
//! the axes (`(s, s, 0)`, `(s, 0, −s)`, `(0, s, −s)` with `s = 1/√2`) are rotated
//! about `(1, −1, 0)/√2` by `asin(2/√6)`, and that trio is rotated about +Z by 0°,
//! 120° and 240°. A child's centre is its parent's centre plus the rotated direction
//! times `r·(1 + ⅓)` (so the two spheres touch), and the child's own "up" is that
//! offset divided by the same scale. Everything is computed in double precision in
//! the order the SPD's vector library does, row-vector matrices included, so the
//! printed numbers are the SPD's to the last digit.

use super::tx::{IDENTITY, rotate, rotate_axis, transform_coord_w0};
use super::{NffSink, phong_power};
use glam::DVec3;
use std::f64::consts::PI;

/// The SPD program's default size factor (`balls.c`: `size_factor = 4`, 7381 spheres).
pub const DEFAULT_SIZE: u32 = 4;

/// Spheres handed to the sink at once.
const SPHERE_BATCH: usize = 1 << 16;

/// Ratio of a child's radius to its parent's.
const CHILD_RATIO: f64 = 1.0 / 3.0;

/// `v / |v|`, or `v` unchanged when it is zero (`lib_normalize_vector`).
fn normalize(v: DVec3) -> DVec3 {
    let d = (v.x * v.x + v.y * v.y + v.z * v.z).sqrt();
    if d > 0.0 {
        DVec3::new(v.x / d, v.y / d, v.z / d)
    } else {
        v
    }
}

/// `a × b` term by term as the SPD's `CROSS` macro.
fn cross(a: DVec3, b: DVec3) -> DVec3 {
    DVec3::new(
        a.y * b.z - a.z * b.y,
        a.z * b.x - a.x * b.z,
        a.x * b.y - a.y * b.x,
    )
}

/// The nine unit directions of the children of a sphere whose own direction is +Z.
fn child_directions() -> [DVec3; 9] {
    let s = 1.0 / 2.0f64.sqrt();
    let trio = [
        DVec3::new(s, s, 0.0),
        DVec3::new(s, 0.0, -s),
        DVec3::new(0.0, s, -s),
    ];
    let tilt = rotate_axis(
        normalize(DVec3::new(1.0, -1.0, 0.0)),
        (2.0 / 6.0f64.sqrt()).asin(),
    );
    let trio = trio.map(|v| transform_coord_w0(v, &tilt));
    let mut out = [DVec3::ZERO; 9];
    for set in 0..3 {
        let m = rotate(2, set as f64 * 2.0 * PI / 3.0);
        for (k, v) in trio.iter().enumerate() {
            out[set * 3 + k] = transform_coord_w0(*v, &m);
        }
    }
    out
}

/// One sphere of the flake: centre, radius, and the nesting depth (0 for the root).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Ball {
    center: DVec3,
    radius: f64,
    level: u32,
}

/// Every sphere of the flake at size factor `size`, parents before their children,
/// depth first, in the SPD's order.
fn flake(size: u32) -> Vec<Ball> {
    let dirs = child_directions();
    let mut out = Vec::new();
    grow(
        &dirs,
        size,
        0,
        DVec3::ZERO,
        0.5,
        DVec3::new(0.0, 0.0, 1.0),
        &mut out,
    );
    out
}

/// Emit the sphere at `center` and, while `depth > 0`, its children. `dir` is the
/// (nearly unit) direction from the parent, along which the children's set is turned.
fn grow(
    dirs: &[DVec3; 9],
    depth: u32,
    level: u32,
    center: DVec3,
    radius: f64,
    dir: DVec3,
    out: &mut Vec<Ball>,
) {
    out.push(Ball {
        center,
        radius,
        level,
    });
    if depth == 0 {
        return;
    }
    // The rotation taking +Z to `dir` (the SPD allows for `dir` being a hair short).
    let m = if dir.z >= 0.9999 {
        IDENTITY
    } else if dir.z <= -0.9999 {
        rotate(1, PI)
    } else {
        let z = DVec3::new(0.0, 0.0, 1.0);
        let axis = normalize(cross(z, dir));
        let cos = z.x * dir.x + z.y * dir.y + z.z * dir.z;
        rotate_axis(axis, cos.acos())
    };
    let scale = radius * (1.0 + CHILD_RATIO);
    for d in dirs {
        let t = transform_coord_w0(*d, &m);
        let c = DVec3::new(
            t.x * scale + center.x,
            t.y * scale + center.y,
            t.z * scale + center.z,
        );
        let child_dir = DVec3::new(
            (c.x - center.x) / scale,
            (c.y - center.y) / scale,
            (c.z - center.z) / scale,
        );
        grow(
            dirs,
            depth - 1,
            level + 1,
            c,
            radius * CHILD_RATIO,
            child_dir,
            out,
        );
    }
}

/// Write the database at size factor `size`.
pub fn generate(size: u32, w: &mut impl NffSink) {
    // Radius of the sphere that would enclose the whole flake.
    let radius = 1.0;
    w.background(DVec3::new(0.078, 0.361, 0.753));
    w.viewpoint(
        DVec3::new(2.1, 1.3, 1.7),
        DVec3::ZERO,
        DVec3::new(0.0, 0.0, 1.0),
        45.0,
        0.01,
        (512, 512),
    );
    w.light(DVec3::new(4.0, 3.0, 2.0));
    w.light(DVec3::new(1.0, -4.0, 4.0));
    w.light(DVec3::new(-3.0, 1.0, 5.0));
    // Beige floor.
    w.fill(
        DVec3::new(1.0, 0.75, 0.33),
        0.8,
        0.0,
        phong_power(0.0),
        0.0,
        1.0,
    );
    let (x, y, z) = (12.0 * radius, 12.0 * radius, -radius / 2.0);
    w.polygon(&[
        DVec3::new(x, y, z),
        DVec3::new(-x, y, z),
        DVec3::new(-x, -y, z),
        DVec3::new(x, -y, z),
    ]);
    // Mirrored spheres.
    w.fill(
        DVec3::new(1.0, 0.9, 0.7),
        0.5,
        0.5,
        phong_power(37.0),
        0.0,
        1.0,
    );
    // In batches, which a scene builder makes in parallel.
    for batch in flake(size).chunks(SPHERE_BATCH) {
        let spheres: Vec<(DVec3, f64)> = batch.iter().map(|b| (b.center, b.radius)).collect();
        w.spheres(&spheres);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spd::NffWriter;
    use std::path::Path;

    fn sphere_count(n: u32) -> usize {
        (9usize.pow(n + 1) - 1) / 8
    }

    #[test]
    fn sphere_counts_follow_the_geometric_series() {
        assert_eq!(sphere_count(4), 7381);
        for n in 0..=4 {
            assert_eq!(flake(n).len(), sphere_count(n), "size {n}");
        }
    }

    #[test]
    fn child_directions_are_unit_and_distinct() {
        let d = child_directions();
        for (i, a) in d.iter().enumerate() {
            assert!((a.length() - 1.0).abs() < 1e-12, "{a}");
            for b in &d[i + 1..] {
                assert!(a.distance(*b) > 0.5, "{a} {b}");
            }
        }
        // Six around the equator, three on the upper hemisphere.
        assert_eq!(d.iter().filter(|v| v.z.abs() < 1e-12).count(), 6);
        assert_eq!(d.iter().filter(|v| v.z > 0.5).count(), 3);
    }

    #[test]
    fn every_child_touches_its_parent() {
        let balls = flake(3);
        // Depth-first order: a sphere's parent is the last sphere one level up.
        let mut stack: Vec<Ball> = Vec::new();
        for b in &balls {
            stack.truncate(b.level as usize);
            if let Some(p) = stack.last() {
                assert!((b.radius - p.radius / 3.0).abs() <= 1e-15 * p.radius);
                let d = b.center.distance(p.center);
                let want = p.radius + b.radius;
                assert!((d - want).abs() <= 1e-9 * want, "{d} vs {want}");
                // Children grow away from the grandparent: never back into it.
                if stack.len() >= 2 {
                    let g = stack[stack.len() - 2];
                    assert!(b.center.distance(g.center) > g.radius + b.radius);
                }
            }
            stack.push(*b);
        }
    }

    #[test]
    fn output_parses_with_the_expected_counts() {
        for n in 1..=2 {
            let mut w = NffWriter::new();
            generate(n, &mut w);
            let text = w.finish();
            let scene = crate::load::nff::parse_str(&text, Path::new("x")).unwrap();
            assert_eq!(scene.geometry.spheres().len(), sphere_count(n));
            assert_eq!(scene.load_stats.polygons, 1);
            assert_eq!(scene.lights.len(), 3);
            assert_eq!(scene.materials.len(), 2);
        }
    }

    #[test]
    fn phong_power_follows_the_half_angle() {
        assert_eq!(phong_power(0.0), 100_000.0);
        assert_eq!(phong_power(90.0), 1.0);
        // cos(ang)^power = 1/2.
        for ang in [5.0, 10.0, 37.0, 60.0] {
            let p = phong_power(ang);
            let half = (ang * PI / 180.0f64).cos().powf(p);
            assert!((half - 0.5).abs() < 1e-12, "{ang}: {p}");
        }
        assert_eq!(crate::spd::fmt_g(phong_power(37.0)), "3.0827");
    }
}
