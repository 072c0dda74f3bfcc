//! The `tetra` database: a Sierpinski tetrahedron (SPD `tetra.c`), after the scene
//! Glassner (1984) and Kay & Kajiya (1986) tested their ray tracers with.
//!
//! A tetrahedron is inscribed in the cube `[-1, 1]³` with its corners at the cube
//! corners whose coordinates multiply to +1. It is replaced by four tetrahedra of half
//! its size, one at each of its corners (the sub-cubes of half the side centred
//! halfway to those corners), `size − 1` times, and each of the `4ˢⁱᶻᵉ⁻¹` final
//! tetrahedra is written as its four triangular faces: `4ˢⁱᶻᵉ` triangles in all, no
//! floor. Every coordinate is a dyadic fraction, so the numbers are exact.

use super::NffSink;
use glam::DVec3;

/// The SPD program's default size factor (`tetra.c`: `size_factor = 6`, 4096
/// triangles).
pub const DEFAULT_SIZE: u32 = 6;

/// The cube corners, in the SPD's x-major order, whose signs multiply to +1: the
/// corners of the tetrahedron inscribed in the cube.
fn corner_signs() -> impl Iterator<Item = DVec3> {
    [-1.0, 1.0].into_iter().flat_map(|x: f64| {
        [-1.0, 1.0].into_iter().flat_map(move |y: f64| {
            [-1.0, 1.0]
                .into_iter()
                .filter(move |z: &f64| x * y * z == 1.0)
                .map(move |z| DVec3::new(x, y, z))
        })
    })
}

/// The triangles of the pyramid at size factor `depth` inscribed in the cube of
/// centre `center` and half-side `half`, to `out` in the SPD's order as they are made.
fn triangles(depth: u32, center: DVec3, half: f64, out: &mut impl FnMut(&[DVec3; 3])) {
    if depth <= 1 {
        let mut p = [DVec3::ZERO; 4];
        for (p, s) in p.iter_mut().zip(corner_signs()) {
            *p = DVec3::new(
                center.x + s.x * half,
                center.y + s.y * half,
                center.z + s.z * half,
            );
        }
        // Face k uses corners k, k+1, k+2 (mod 4), reversed for odd k so that every
        // face winds the same way seen from outside.
        for face in 0..4 {
            let mut ord = [face, (face + 1) % 4, (face + 2) % 4];
            if face % 2 == 1 {
                ord.swap(0, 2);
            }
            out(&ord.map(|i| p[i]));
        }
    } else {
        for s in corner_signs() {
            let sub = DVec3::new(
                center.x + s.x * half / 2.0,
                center.y + s.y * half / 2.0,
                center.z + s.z * half / 2.0,
            );
            triangles(depth - 1, sub, half / 2.0, out);
        }
    }
}

/// Write the database at size factor `size`.
pub fn generate(size: u32, w: &mut impl NffSink) {
    w.background(DVec3::new(0.078, 0.361, 0.753));
    // Kay & Kajiya's view and light, moved into these world coordinates.
    w.viewpoint(
        DVec3::new(1.022846, -3.177154, -2.174512),
        DVec3::new(-0.004103, -0.004103, 0.216539),
        DVec3::new(-0.816497, -0.816497, 0.816497),
        45.0,
        1.0,
        (512, 512),
    );
    w.light(DVec3::new(2.0, -18.0, -5.0));
    // Red, purely diffuse; the SPD passes an index of refraction of 0 here.
    w.fill(
        DVec3::new(1.0, 0.2, 0.2),
        1.0,
        0.0,
        super::phong_power(0.0),
        0.0,
        0.0,
    );
    triangles(size, DVec3::ZERO, 1.0, &mut |t| w.polygon(t));
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spd::NffWriter;
    use std::collections::BTreeSet;
    use std::path::Path;

    fn tris(n: u32) -> Vec<[DVec3; 3]> {
        let mut v = Vec::new();
        triangles(n, DVec3::ZERO, 1.0, &mut |t| v.push(*t));
        v
    }

    /// A triangle as an exactly comparable key (all coordinates are dyadic).
    fn key(t: &[DVec3; 3]) -> [[u64; 3]; 3] {
        t.map(|v| v.to_array().map(f64::to_bits))
    }

    #[test]
    fn triangle_count_is_four_to_the_size() {
        for n in 1..=5 {
            assert_eq!(tris(n).len(), 4usize.pow(n), "size {n}");
        }
    }

    #[test]
    fn size_n_is_four_half_size_copies_of_size_n_minus_1() {
        let corners: Vec<DVec3> = corner_signs().collect();
        assert_eq!(corners.len(), 4);
        for n in 2..=4 {
            let want: BTreeSet<_> = corners
                .iter()
                .flat_map(|c| {
                    // Scale by ½ about the corner c: v ↦ c + (v − c)/2.
                    tris(n - 1)
                        .into_iter()
                        .map(move |t| t.map(|v| *c + (v - *c) * 0.5))
                })
                .map(|t| key(&t))
                .collect();
            let got: BTreeSet<_> = tris(n).iter().map(key).collect();
            assert_eq!(got.len(), 4usize.pow(n), "no duplicate triangles");
            assert_eq!(got, want, "size {n}");
        }
    }

    #[test]
    fn faces_are_equilateral_and_wind_counterclockwise_seen_from_outside() {
        let t = tris(3);
        // Each final tetrahedron is four consecutive faces; every corner is in three.
        for tet in t.chunks(4) {
            let centre = tet.iter().flatten().copied().sum::<DVec3>() / 12.0;
            for f in tet {
                let (a, b, c) = (f[0], f[1], f[2]);
                let e = a.distance(b);
                assert!((b.distance(c) - e).abs() < 1e-12);
                assert!((c.distance(a) - e).abs() < 1e-12);
                let n = (b - a).cross(c - a);
                assert!(n.dot((a + b + c) / 3.0 - centre) > 0.0, "{f:?}");
            }
        }
    }

    #[test]
    fn output_parses_with_the_expected_counts() {
        for n in 1..=3 {
            let mut w = NffWriter::new();
            generate(n, &mut w);
            let scene = crate::load::nff::parse_str(&w.finish(), Path::new("x")).unwrap();
            assert_eq!(scene.load_stats.polygons, 4usize.pow(n));
            assert_eq!(scene.geometry.triangles.len(), 4usize.pow(n));
            assert_eq!(scene.load_stats.degenerate_dropped, 0);
            assert_eq!(scene.geometry.spheres().len(), 0);
            assert_eq!(scene.lights.len(), 1);
        }
    }
}
