//! The `rings` database (Eric Haines, SPD 3.14): objects of six pentagonal rings that
//! join the midpoints of a dodecahedron's edges, stacked in a pyramid that the viewer
//! looks at from its tip, against a white wall; three lights.
//!
//! A ring is 5 spheres at the vertices of a pentagon and 5 cylinders joining each to
//! the previous one, all of radius 0.07412. The first pentagon lies in the XY plane;
//! the other five are it turned about X by the dodecahedron's dihedral angle and then
//! about Z by odd tenths of a turn. Layer `d` (0-based) of the pyramid is a
//! (d+1)×(d+1) square of objects, one unit further from the eye per layer.
//!
//! Size factor `n`: n(n+1)(2n+1)/6 objects of 30 spheres and 30 cylinders, so
//! 5·n(n+1)(2n+1) of each (30, 150, 420, …, 4200 at 7), plus the wall polygon.

use super::tx::{rotate, transform_point};
use super::{NffSink, phong_power};
use glam::DVec3;
use std::f64::consts::PI;

/// The SPD program's default size factor (`rings.c`: `size_factor = 7`, 8,401
/// primitives, the largest below 10,000).
pub const DEFAULT_SIZE: u32 = 7;

/// Radius of the spheres and cylinders.
const RADIUS: f64 = 0.07412;
/// Above 1, succeeding layers spread out more.
const SPREAD_OUT: f64 = 1.0;

/// Write the database at size factor `size`.
pub fn generate(size: u32, w: &mut impl NffSink) {
    let spread = 1.0 / (PI / 8.0).sin();
    let (y_diff, xz_diff) = if SPREAD_OUT <= spread {
        (spread / SPREAD_OUT, 1.0)
    } else {
        (1.0, SPREAD_OUT / spread)
    };

    w.background(DVec3::new(0.078, 0.361, 0.753));
    let from = DVec3::new(-1.0, -spread, 0.5);
    let at = DVec3::new(from.x, from.y + 1.0, from.z);
    w.viewpoint(from, at, DVec3::new(0.0, 0.0, 1.0), 45.0, 1.0, (512, 512));
    w.light(DVec3::new(3.0, -spread, 3.0));
    w.light(DVec3::new(-4.0, -spread, 1.0));
    w.light(DVec3::new(2.0, -spread, -4.0));

    // The wall just spans the 45° view, plus 1%.
    w.fill(DVec3::ONE, 1.0, 0.0, phong_power(0.0), 0.0, 0.0);
    let wy = y_diff * (size as f64 + 1.0);
    let wxz = 1.01 * (wy - from.y) * (PI / 8.0).tan();
    w.polygon(&[
        DVec3::new(wxz + from.x, wy, wxz + from.z),
        DVec3::new(-wxz + from.x, wy, wxz + from.z),
        DVec3::new(-wxz + from.x, wy, -wxz + from.z),
        DVec3::new(wxz + from.x, wy, -wxz + from.z),
    ]);

    // Red, green, blue and their complements.
    let colors = [
        DVec3::new(1.0, 0.0, 0.0),
        DVec3::new(0.0, 1.0, 0.0),
        DVec3::new(0.0, 0.0, 1.0),
        DVec3::new(0.0, 1.0, 1.0),
        DVec3::new(1.0, 0.0, 1.0),
        DVec3::new(1.0, 1.0, 0.0),
    ];
    let dodec = ring_points(RADIUS);

    for depth in 0..size as i64 {
        let oy = y_diff * (depth + 1) as f64;
        for objz in 0..=depth {
            let oz = xz_diff * (2 * objz - depth) as f64;
            for objx in 0..=depth {
                let offset = DVec3::new(xz_diff * (2 * objx - depth) as f64, oy, oz);
                for elem in 0..30 {
                    let base = dodec[elem] + offset;
                    let prev = if elem % 5 == 0 {
                        w.fill(colors[elem / 5], 0.5, 0.2, phong_power(37.0), 0.0, 0.0);
                        elem + 4
                    } else {
                        elem - 1
                    };
                    let apex = dodec[prev] + offset;
                    w.cone(base, RADIUS, apex, RADIUS);
                    w.sphere(base, RADIUS);
                }
            }
        }
    }
}

/// The 30 ring vertices (6 pentagons of 5), scaled to fit with their spheres in the
/// unit sphere.
fn ring_points(minor_radius: f64) -> [DVec3; 30] {
    let scale = 1.0 / (1.0 + minor_radius);
    let mut v = [DVec3::ZERO; 30];
    for (i, p) in v.iter_mut().take(5).enumerate() {
        let a = i as f64 * 2.0 * PI / 5.0;
        *p = DVec3::new(scale * a.cos(), scale * a.sin(), 0.0);
    }
    // The angle between two adjacent dodecahedron faces.
    let x_rotation = 2.0 * ((PI / 3.0).cos() / (PI / 5.0).sin()).acos();
    let xm = rotate(0, x_rotation);
    for pentagon in 1..6 {
        // 1/10th plus N fifths of the way around.
        let z_rotation = PI * (2.0 * (pentagon - 1) as f64 + 1.0) / 5.0;
        let zm = rotate(2, z_rotation);
        for i in 0..5 {
            let t = transform_point(v[i], &xm);
            v[5 * pentagon + i] = transform_point(t, &zm);
        }
    }
    v
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    fn nums(line: &str) -> Vec<f64> {
        line.split_whitespace()
            .skip(1)
            .map(|t| t.parse().unwrap())
            .collect()
    }

    fn objects(n: usize) -> usize {
        n * (n + 1) * (2 * n + 1) / 6
    }

    #[test]
    fn primitive_counts_follow_the_pyramid() {
        for n in 0..=4u32 {
            let text = super::super::Database::Rings.generate(n);
            let count = |tag: &str| {
                text.lines()
                    .filter(|l| l.split_whitespace().next() == Some(tag))
                    .count()
            };
            let objs = objects(n as usize);
            assert_eq!(count("s"), 30 * objs, "size {n}");
            assert_eq!(count("c"), 30 * objs, "size {n}");
            assert_eq!(count("s"), 5 * (n * (n + 1) * (2 * n + 1)) as usize);
            assert_eq!(count("p"), 1);
            assert_eq!(count("f"), 1 + 6 * objs, "one colour per ring");
            assert_eq!(count("l"), 3);
        }
        assert_eq!(30 * objects(7), 4200);
    }

    #[test]
    fn cylinders_join_consecutive_spheres_of_each_ring() {
        let text = super::super::Database::Rings.generate(2);
        let prims: Vec<&str> = text
            .lines()
            .filter(|l| l.starts_with("c ") || l.starts_with("s "))
            .collect();
        // Pairs (cylinder, sphere); rings of 5 pairs.
        for ring in prims.chunks(10) {
            let cyl: Vec<Vec<f64>> = ring.iter().step_by(2).map(|l| nums(l)).collect();
            let sph: Vec<Vec<f64>> = ring.iter().skip(1).step_by(2).map(|l| nums(l)).collect();
            let centre = |v: &Vec<f64>| DVec3::new(v[0], v[1], v[2]);
            let ring_centre = sph.iter().fold(DVec3::ZERO, |s, v| s + centre(v)) / 5.0;
            let normal = (centre(&sph[1]) - centre(&sph[0]))
                .cross(centre(&sph[2]) - centre(&sph[0]))
                .normalize();
            for i in 0..5 {
                let c = &cyl[i];
                // Base at this sphere, apex at the previous one (wrapping round).
                assert_eq!(DVec3::new(c[0], c[1], c[2]), centre(&sph[i]));
                assert_eq!(DVec3::new(c[4], c[5], c[6]), centre(&sph[(i + 4) % 5]));
                assert_eq!((c[3], c[7], sph[i][3]), (RADIUS, RADIUS, RADIUS));
                // A regular pentagon: equal sides, planar, equidistant from its centre.
                let side = (centre(&sph[i]) - centre(&sph[(i + 4) % 5])).length();
                let side0 = (centre(&sph[0]) - centre(&sph[4])).length();
                assert!((side - side0).abs() < 1e-4);
                assert!((centre(&sph[i]) - ring_centre).dot(normal).abs() < 1e-4);
                let r = (centre(&sph[i]) - ring_centre).length();
                assert!((r - (centre(&sph[0]) - ring_centre).length()).abs() < 1e-4);
            }
        }
    }

    #[test]
    fn rings_are_great_circle_pentagons_about_the_dodecahedron_face_axes() {
        let v = ring_points(RADIUS);
        let scale = 1.0 / (1.0 + RADIUS);
        // Every vertex on the sphere that, with the spheres' radius, fits in radius 1.
        for p in &v {
            assert!((p.length() - scale).abs() < 1e-12);
        }
        // 30 distinct vertices.
        for (i, a) in v.iter().enumerate() {
            for b in &v[i + 1..] {
                assert!((*a - *b).length() > 0.1);
            }
        }
        // Each ring is centred on the origin; its axis is a dodecahedron face axis, and
        // any two of the six face axes meet at arccos(1/√5) ≈ 63.43°.
        let axes: Vec<DVec3> = v
            .chunks(5)
            .map(|r| {
                let c = r.iter().fold(DVec3::ZERO, |s, p| s + *p) / 5.0;
                assert!(c.length() < 1e-12);
                (r[1] - r[0]).cross(r[2] - r[0]).normalize()
            })
            .collect();
        for (i, a) in axes.iter().enumerate() {
            for b in &axes[i + 1..] {
                assert!((a.dot(*b).abs() - 1.0 / 5f64.sqrt()).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn output_parses_with_the_nff_loader() {
        let text = super::super::Database::Rings.generate(2);
        let scene = crate::load::nff::parse_str(&text, Path::new("x")).unwrap();
        assert_eq!(scene.geometry.spheres().len(), 150);
        assert_eq!(scene.geometry.cones().len(), 150);
        assert_eq!(scene.load_stats.polygons, 1);
        assert_eq!(scene.lights.len(), 3);
    }
}
