//! The `lattice` database (Antonio Costa, SPD 3.14): shiny spheres on the points of a
//! cubic grid over the unit cube, each joined to its neighbours in +X, +Y and +Z by a
//! matte cylinder (red, green, blue by direction); six lights.
//!
//! Size factor `n`: (n+1)³ spheres of radius 1/(4n) and 3·n·(n+1)² cylinders of
//! radius 1/(16n), each starting and ending just inside the spheres it joins.
//! Everything gets its own `f` line before it, as the SPD program writes them.

use super::{NffSink, phong_power};
use glam::DVec3;

/// The SPD program's default size factor: `lattice.c` starts with
/// `static int size_factor = 12;` — 2,197 spheres and 6,084 cylinders (8,281
/// primitives), the largest lattice below 10,000 primitives (13 gives 10,388).
pub const DEFAULT_SIZE: u32 = 12;

/// Sphere radius relative to the grid spacing.
const RADIUS1: f64 = 1.0 / 4.0;
/// Cylinder radius relative to the grid spacing.
const RADIUS2: f64 = 1.0 / 16.0;

/// Write the database at size factor `size` (at least 1).
pub fn generate(size: u32, w: &mut impl NffSink) {
    let sf = size as f64;
    let inv_factor = 1.0 / sf;
    let radius1 = RADIUS1 / sf;
    let radius2 = RADIUS2 / sf;
    // Cylinders start this far from a sphere's centre: inside it, where the sphere's
    // radius has shrunk to the cylinder's (less 1%).
    let delta = (radius1 * (1.0 - (RADIUS2 / RADIUS1).sqrt())) * 0.99;

    w.background(DVec3::new(0.078, 0.361, 0.753));
    let mid = ((size >> 1) as f64 + 0.5) * inv_factor;
    let half_cell = 1.0 / ((size << 1) as f64);
    w.viewpoint(
        DVec3::new(mid, 1.0, 1.0 - half_cell),
        DVec3::new(mid, -1.0, -1.0 - half_cell),
        DVec3::new(0.2, 1.0, 0.0),
        60.0,
        0.0,
        (512, 512),
    );
    for l in [
        DVec3::new(2.0, 0.5, 0.5),
        DVec3::new(-1.0, 0.5, 0.5),
        DVec3::new(0.5, 2.0, 0.5),
        DVec3::new(0.5, -1.0, 0.5),
        DVec3::new(0.5, 0.5, 2.0),
        DVec3::new(0.5, 0.5, -1.0),
    ] {
        w.light(l);
    }

    let sphere_shine = phong_power(37.0);
    let matte = phong_power(0.0);
    for x in 0..=size {
        let x0 = x as f64 / sf;
        for y in 0..=size {
            let y0 = y as f64 / sf;
            for z in 0..=size {
                let z0 = z as f64 / sf;
                w.fill(DVec3::splat(0.9), 0.5, 0.5, sphere_shine, 0.0, 0.0);
                w.sphere(DVec3::new(x0, y0, z0), radius1);
                if x != size {
                    w.fill(DVec3::new(0.9, 0.1, 0.1), 0.99, 0.0, matte, 0.0, 0.0);
                    w.cone(
                        DVec3::new(x0 + delta, y0, z0),
                        radius2,
                        DVec3::new(x0 + inv_factor - delta, y0, z0),
                        radius2,
                    );
                }
                if y != size {
                    w.fill(DVec3::new(0.1, 0.9, 0.1), 0.99, 0.0, matte, 0.0, 0.0);
                    w.cone(
                        DVec3::new(x0, y0 + delta, z0),
                        radius2,
                        DVec3::new(x0, y0 + inv_factor - delta, z0),
                        radius2,
                    );
                }
                if z != size {
                    w.fill(DVec3::new(0.1, 0.1, 0.9), 0.99, 0.0, matte, 0.0, 0.0);
                    w.cone(
                        DVec3::new(x0, y0, z0 + delta),
                        radius2,
                        DVec3::new(x0, y0, z0 + inv_factor - delta),
                        radius2,
                    );
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    fn prims(text: &str, tag: &str) -> Vec<Vec<f64>> {
        text.lines()
            .filter(|l| l.split_whitespace().next() == Some(tag))
            .map(|l| {
                l.split_whitespace()
                    .skip(1)
                    .map(|t| t.parse().unwrap())
                    .collect()
            })
            .collect()
    }

    #[test]
    fn counts_are_cubes_of_spheres_and_their_neighbour_links() {
        for n in 1..=4usize {
            let text = super::super::Database::Lattice.generate(n as u32);
            let spheres = (n + 1).pow(3);
            let cylinders = 3 * n * (n + 1) * (n + 1);
            assert_eq!(prims(&text, "s").len(), spheres, "size {n}");
            assert_eq!(prims(&text, "c").len(), cylinders, "size {n}");
            assert_eq!(prims(&text, "f").len(), spheres + cylinders);
            assert_eq!(prims(&text, "l").len(), 6);
            assert_eq!(prims(&text, "p").len(), 0);
        }
        assert_eq!(13usize.pow(3) + 3 * 12 * 13 * 13, 8281);
        assert!(14usize.pow(3) + 3 * 13 * 14 * 14 >= 10_000);
    }

    #[test]
    fn spheres_on_a_grid_and_cylinders_join_neighbours() {
        let n = 3;
        let text = super::super::Database::Lattice.generate(n);
        let spacing = 1.0 / n as f64;
        let spheres = prims(&text, "s");
        let mut grid = std::collections::HashSet::new();
        for s in &spheres {
            let idx: Vec<i64> = s[..3]
                .iter()
                .map(|c| (c / spacing).round() as i64)
                .collect();
            for (c, i) in s[..3].iter().zip(&idx) {
                assert!((c - *i as f64 * spacing).abs() < 1e-5, "on the grid");
                assert!((0..=n as i64).contains(i));
            }
            assert!((s[3] - spacing / 4.0).abs() < 1e-6);
            assert!(grid.insert(idx), "each grid point once");
        }
        for c in prims(&text, "c") {
            let (a, b) = (DVec3::new(c[0], c[1], c[2]), DVec3::new(c[4], c[5], c[6]));
            assert_eq!(c[3], c[7]);
            assert!((c[3] - spacing / 16.0).abs() < 1e-6);
            // Along one axis, in the + direction.
            let d = b - a;
            let axis = (0..3).filter(|&k| d[k].abs() > 1e-9).collect::<Vec<_>>();
            assert_eq!(axis.len(), 1);
            assert!(d[axis[0]] > 0.0);
            // Its ends lie inside the two neighbouring spheres, whose centres are one
            // grid step apart, and it covers the gap between them.
            let mut lo = a;
            lo[axis[0]] = (a[axis[0]] / spacing).floor() * spacing;
            let mut hi = lo;
            hi[axis[0]] += spacing;
            let r1 = spacing / 4.0;
            assert!((a - lo).length() < r1 && (b - hi).length() < r1);
            assert!((a - lo).length() > 0.0 && (b - hi).length() > 0.0);
            let lo_idx: Vec<i64> = (0..3).map(|k| (lo[k] / spacing).round() as i64).collect();
            let hi_idx: Vec<i64> = (0..3).map(|k| (hi[k] / spacing).round() as i64).collect();
            assert!(grid.contains(&lo_idx) && grid.contains(&hi_idx));
        }
    }

    #[test]
    fn colours_follow_primitive_kind_and_direction() {
        let text = super::super::Database::Lattice.generate(2);
        let lines: Vec<&str> = text.lines().collect();
        for (i, l) in lines.iter().enumerate() {
            let Some(f) = l.strip_prefix("f ") else {
                continue;
            };
            let next = lines[i + 1];
            let v: Vec<f64> = next
                .split_whitespace()
                .skip(1)
                .map(|t| t.parse().unwrap())
                .collect();
            match (next.as_bytes()[0], f) {
                (b's', "0.9 0.9 0.9 0.5 0.5 3.0827 0 0") => {}
                (b'c', "0.9 0.1 0.1 0.99 0 100000 0 0") => assert!(v[4] > v[0]),
                (b'c', "0.1 0.9 0.1 0.99 0 100000 0 0") => assert!(v[5] > v[1]),
                (b'c', "0.1 0.1 0.9 0.99 0 100000 0 0") => assert!(v[6] > v[2]),
                other => panic!("unexpected pair {other:?}"),
            }
        }
    }

    #[test]
    fn output_parses_with_the_nff_loader() {
        let text = super::super::Database::Lattice.generate(2);
        let scene = crate::load::nff::parse_str(&text, Path::new("x")).unwrap();
        assert_eq!(scene.geometry.spheres().len(), 27);
        assert_eq!(scene.geometry.cones().len(), 54);
        assert_eq!(scene.lights.len(), 6);
        assert_eq!(scene.load_stats.polygons, 0);
    }
}
