//! The `gears` database (Eric Haines, SPD 3.14): a cubic array of meshed gears over a
//! reflective square, five lights.
//!
//! Each gear is a top face, one rectangle per edge of the outline, and a bottom face.
//! The outline has 36 teeth of 4 vertices each (144 vertices, concave): two on the
//! outer radius at ±0.19 of the tooth angle and two on the inner (root) radius at 0.3
//! and 0.7 of it. The bottom face walks the teeth the other way round, so it faces
//! down. Neighbouring gears are turned half a tooth against each other so that they
//! mesh; one gear in five is transparent.
//!
//! Size factor `n`: n³ gears, each 2 + 144 polygons, plus the ground square:
//! 146·n³ + 1 polygons (147, 1169, 3943, 9345, …).

use super::{NffSink, phong_power};
use glam::DVec3;
use std::f64::consts::PI;

/// The SPD program's default size factor (`gears.c`: `size_factor = 4`, 9,345
/// polygons, the largest below 10,000).
pub const DEFAULT_SIZE: u32 = 4;

/// Teeth on a gear (a multiple of 4).
const TEETH: usize = 36;
/// The tip radius relative to the full radius (a little less, so gears don't touch).
const OUTER_EDGE_RATIO: f64 = 0.995;
/// The root radius relative to the full radius.
const INNER_EDGE_RATIO: f64 = 0.9;
/// Gear thickness relative to the whole array's size (at most).
const DEPTH_RATIO: f64 = 0.1;

/// Write the database at size factor `size`.
pub fn generate(size: u32, w: &mut impl NffSink) {
    let sf = size as f64;
    w.background(DVec3::new(0.078, 0.361, 0.753));
    w.viewpoint(
        DVec3::new(-1.1, -2.1, 2.6),
        DVec3::ZERO,
        DVec3::new(0.0, 0.0, 1.0),
        45.0,
        1.0,
        (512, 512),
    );
    for l in [
        DVec3::new(2.0, 4.0, 4.0),
        DVec3::new(-2.0, 4.0, 3.0),
        DVec3::new(2.0, -2.5, 2.5),
        DVec3::new(-1.0, -4.0, 2.0),
        // just behind the eye
        DVec3::new(-1.111, -2.121, 2.626),
    ] {
        w.light(l);
    }

    // Ground square, off white.
    w.fill(
        DVec3::new(1.0, 0.85, 0.7),
        0.3,
        0.6,
        phong_power(37.0),
        0.0,
        0.0,
    );
    w.polygon(&[
        DVec3::new(2.0, 2.0, 0.0),
        DVec3::new(-2.0, 2.0, 0.0),
        DVec3::new(-2.0, -2.0, 0.0),
        DVec3::new(2.0, -2.0, 0.0),
    ]);

    let edge_diff = 1.0 - INNER_EDGE_RATIO;
    let outer_radius = 1.0 / (sf - (size as f64 - 1.0) * edge_diff / 2.0);
    let zero = DVec3::new(-1.0 + outer_radius, -1.0 + outer_radius, 1.0);
    let step = outer_radius * (2.0 - edge_diff);
    let offset = DVec3::new(step, step, -1.0 / sf);
    let thickness = DEPTH_RATIO.min(1.0 / (2.0 * sf));

    let n = size as usize;
    for iz in 0..n {
        for iy in 0..n {
            for ix in 0..n {
                let center = DVec3::new(
                    zero.x + ix as f64 * offset.x,
                    zero.y + iy as f64 * offset.y,
                    zero.z + iz as f64 * offset.z,
                );
                // Pseudo-random colour, scaled so its largest component is 1.
                let c = DVec3::new(
                    0.01 + fraction((ix * 3 + iy * 2 + iz + 1) as f64 * 5.0 / 7.0),
                    0.01 + fraction((iy * 3 + iz * 2 + ix + 1) as f64 * 3.0 / 7.0),
                    0.01 + fraction((iz * 3 + ix * 2 + iy + 1) as f64 * 2.0 / 7.0),
                );
                let scale = c_max(c_max(c.x, c.y), c.z);
                let c = DVec3::new(c.x / scale, c.y / scale, c.z / scale);
                if (ix * 4 + iy * 2 + iz) % 5 == 0 {
                    w.fill(c, 0.2, 0.0, phong_power(0.0), 0.8, 1.1);
                } else {
                    w.fill(c, 1.0, 0.0, phong_power(0.0), 0.0, 0.0);
                }
                let angle = PI * ((ix + iy + iz) % 2) as f64 / TEETH as f64;
                gear(
                    w,
                    center,
                    angle,
                    OUTER_EDGE_RATIO * outer_radius,
                    (1.0 - edge_diff) * outer_radius,
                    thickness,
                );
            }
        }
    }
}

/// One gear: top face at `center.z`, sides, bottom face `thickness` lower.
fn gear(
    w: &mut impl NffSink,
    center: DVec3,
    offset_angle: f64,
    outer: f64,
    inner: f64,
    thickness: f64,
) {
    let tooth_angle = 2.0 * PI / TEETH as f64;

    let top = outline(center, offset_angle, tooth_angle, outer, inner, 0.0, 1.0);
    w.polygon(&top);

    for i in 0..top.len() {
        let next = (i + 1) % top.len();
        let (a, b) = (top[i], top[next]);
        w.polygon(&[
            a,
            DVec3::new(a.x, a.y, a.z - thickness),
            DVec3::new(b.x, b.y, b.z - thickness),
            b,
        ]);
    }

    let bottom = outline(
        center,
        offset_angle,
        tooth_angle,
        outer,
        inner,
        -thickness,
        -1.0,
    );
    w.polygon(&bottom);
}

/// The 4·TEETH outline vertices at height `z` (relative to `center`), walking the
/// teeth counter-clockwise (`sense` 1) or clockwise (−1) as seen from +Z.
fn outline(
    center: DVec3,
    offset_angle: f64,
    tooth_angle: f64,
    outer: f64,
    inner: f64,
    z: f64,
    sense: f64,
) -> Vec<DVec3> {
    let outer_pt = DVec3::new(outer, 0.0, z);
    let inner_pt = DVec3::new(inner, 0.0, z);
    let ta = sense * tooth_angle;
    let mut pts = Vec::with_capacity(4 * TEETH);
    for t in 0..TEETH {
        let turn = 2.0 * PI * t as f64 / TEETH as f64;
        let gear_angle = if sense > 0.0 {
            offset_angle + turn
        } else {
            offset_angle - turn
        };
        for (frac, p) in [
            (-0.19, outer_pt),
            (0.19, outer_pt),
            (0.3, inner_pt),
            (0.7, inner_pt),
        ] {
            // gear_angle − 0.19·ta, then + 0.19·ta, + 0.3·ta, + 0.7·ta, as the SPD.
            let a = if frac < 0.0 {
                gear_angle - 0.19 * ta
            } else {
                gear_angle + frac * ta
            };
            pts.push(rotate_z(p, a) + center);
        }
    }
    pts
}

/// `v` turned by `angle` about Z, through the SPD's rotation matrix
/// (`lib_transform_vector`, row vector times matrix, zero terms included).
fn rotate_z(v: DVec3, angle: f64) -> DVec3 {
    let (s, c) = (angle.sin(), angle.cos());
    // Rows: [c, s, 0], [−s, c, 0], [0, 0, 1].
    DVec3::new(
        v.x * c + v.y * -s + v.z * 0.0,
        v.x * s + v.y * c + v.z * 0.0,
        v.x * 0.0 + v.y * 0.0 + v.z * 1.0,
    )
}

/// C's `FRACTION(a)`: `a - (int)a`.
fn fraction(a: f64) -> f64 {
    a - a.trunc()
}

/// C's `MAX(a, b)`: `a > b ? a : b`.
fn c_max(a: f64, b: f64) -> f64 {
    if a > b { a } else { b }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    /// Polygons as vertex lists, in file order.
    fn polygons(text: &str) -> Vec<Vec<DVec3>> {
        let mut out = Vec::new();
        let mut lines = text.lines();
        while let Some(l) = lines.next() {
            if let Some(n) = l.strip_prefix("p ") {
                let n: usize = n.parse().unwrap();
                let v = (0..n)
                    .map(|_| {
                        let c: Vec<f64> = lines
                            .next()
                            .unwrap()
                            .split_whitespace()
                            .map(|t| t.parse().unwrap())
                            .collect();
                        DVec3::new(c[0], c[1], c[2])
                    })
                    .collect();
                out.push(v);
            }
        }
        out
    }

    /// Twice the signed area of the XY projection.
    fn signed_area(v: &[DVec3]) -> f64 {
        (0..v.len())
            .map(|i| {
                let (a, b) = (v[i], v[(i + 1) % v.len()]);
                a.x * b.y - b.x * a.y
            })
            .sum()
    }

    #[test]
    fn polygon_counts_are_146_per_gear_plus_ground() {
        for n in 1..=3u32 {
            let text = super::super::Database::Gears.generate(n);
            let polys = polygons(&text);
            let gears = (n * n * n) as usize;
            assert_eq!(polys.len(), 146 * gears + 1, "size {n}");
            let big = polys.iter().filter(|p| p.len() == 144).count();
            let quads = polys.iter().filter(|p| p.len() == 4).count();
            assert_eq!(big, 2 * gears);
            assert_eq!(quads, 144 * gears + 1);
            assert_eq!(
                text.lines().filter(|l| l.starts_with("f ")).count(),
                gears + 1
            );
        }
        assert_eq!(146 * 64 + 1, 9345);
    }

    #[test]
    fn faces_are_planar_and_teeth_outline_is_concave() {
        let text = super::super::Database::Gears.generate(2);
        let polys = polygons(&text);
        for gear in polys[1..].chunks(146) {
            let (top, sides, bottom) = (&gear[0], &gear[1..145], &gear[145]);
            assert_eq!(top.len(), 144);
            // Top and bottom are flat, the bottom `thickness` below the top.
            assert!(top.iter().all(|v| (v.z - top[0].z).abs() < 1e-6));
            assert!(bottom.iter().all(|v| (v.z - bottom[0].z).abs() < 1e-6));
            assert!((top[0].z - bottom[0].z - 0.1).abs() < 1e-6);
            // Top faces up (counter-clockwise from +Z), bottom down.
            assert!(signed_area(top) > 0.0);
            assert!(signed_area(bottom) < 0.0);
            // Concave: the turn direction changes along the outline.
            let turns: Vec<f64> = (0..144)
                .map(|i| {
                    let (a, b, c) = (top[i], top[(i + 1) % 144], top[(i + 2) % 144]);
                    (b - a).truncate().perp_dot((c - b).truncate())
                })
                .collect();
            assert!(turns.iter().any(|&t| t > 1e-9) && turns.iter().any(|&t| t < -1e-9));
            // 36 teeth: vertices alternate two on the tip circle, two on the root circle.
            let centre = top.iter().fold(DVec3::ZERO, |s, v| s + *v) / 144.0;
            let radii: Vec<f64> = top
                .iter()
                .map(|v| (*v - centre).truncate().length())
                .collect();
            let tip = radii.iter().cloned().fold(0.0, f64::max);
            let tips = radii.iter().filter(|&&r| (r - tip).abs() < 1e-5).count();
            assert_eq!(tips, 72);
            assert!((radii[0] - tip).abs() < 1e-5 && (radii[2] - tip).abs() > 1e-3);
            assert!((tip / radii[2] - OUTER_EDGE_RATIO / INNER_EDGE_RATIO).abs() < 1e-4);
            // Each side rectangle is planar and joins consecutive top vertices.
            for (i, s) in sides.iter().enumerate() {
                assert_eq!(s[0], top[i]);
                assert_eq!(s[3], top[(i + 1) % 144]);
                let n = (s[1] - s[0]).cross(s[2] - s[0]);
                assert!(n.normalize().dot(s[3] - s[0]).abs() < 1e-9);
            }
        }
    }

    #[test]
    fn neighbouring_gears_mesh_without_touching() {
        let text = super::super::Database::Gears.generate(2);
        let polys = polygons(&text);
        let tops: Vec<&Vec<DVec3>> = polys[1..].chunks(146).map(|g| &g[0]).collect();
        let centre = |p: &Vec<DVec3>| p.iter().fold(DVec3::ZERO, |s, v| s + *v) / p.len() as f64;
        // Gears 0 and 1 are side by side in X on the same layer.
        let (a, b) = (centre(tops[0]), centre(tops[1]));
        assert!((a.z - b.z).abs() < 1e-5 && (a.y - b.y).abs() < 1e-5);
        let tip = (tops[0][0] - a).truncate().length();
        let root = (tops[0][2] - a).truncate().length();
        let d = b.x - a.x;
        // Teeth overlap radially (they mesh) but tips stay clear of the other's root.
        assert!(d < 2.0 * tip && d > tip + root);
    }

    #[test]
    fn output_parses_with_the_nff_loader() {
        let text = super::super::Database::Gears.generate(1);
        let scene = crate::load::nff::parse_str(&text, Path::new("x")).unwrap();
        assert_eq!(scene.load_stats.polygons, 147);
        assert_eq!(scene.load_stats.degenerate_dropped, 0);
        assert_eq!(scene.lights.len(), 5);
        assert_eq!(
            scene.geometry.spheres().len() + scene.geometry.cones().len(),
            0
        );
        // 144-gons triangulate into 142 triangles, quads into 2.
        assert_eq!(scene.geometry.triangles.len(), 2 * 142 + 145 * 2);
    }
}
