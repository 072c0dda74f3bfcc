//! The `mount` database: a fractal mountain with a pyramid of four glass spheres in
//! front of it (SPD `mount.c`).
//!
//! The mountain is Carpenter's midpoint displacement applied to a square grid: the
//! square `[-1, 1]²` (all corners at height 0) is split into four quadrants; each edge
//! midpoint is raised by the mean of the edge's end heights plus a Gaussian deviate
//! scaled by the half-side length times the roughness, the centre by the mean of the
//! four corners plus √2 times that. The deviate's seed is a hash of the midpoint's grid
//! coordinates, so the two squares sharing an edge compute the same midpoint height
//! bit for bit and the mesh has no cracks. At the finest level each grid cell is output
//! as two triangles, so size factor `n` gives a `2ⁿ × 2ⁿ` grid and `2·4ⁿ` triangles.
//!
//! The hash is the original one of the 1987 paper, which the SPD keeps by default for
//! comparability even though it repeats itself (the SPD README: version 2.4 fixed it,
//! 3.x made the fix optional).

use super::tx::{rotate, rotate_axis, transform_vector};
use super::{NffSink, phong_power};
use glam::DVec3;
use std::f64::consts::PI;

/// The SPD program's default size factor.
pub const DEFAULT_SIZE: u32 = 6;

/// Fractal dimension of the surface (between 2 and 3); sets the roughness.
const FRACTAL_DIMENSION: f64 = 2.2;
/// Added to every hash: selects which mountain is grown.
const MOUNTAIN_NO: i64 = 21;
/// Lower-left corner and side of the mountain's square.
const CORNER: f64 = -1.0;
const WIDTH: f64 = 2.0;
/// The SPD's √2 for the centre point's larger variance, as written in `mount.c` (not
/// [`std::f64::consts::SQRT_2`]: the rounding shows in the output).
#[allow(clippy::approx_constant)]
const SPD_SQRT_2: f64 = 1.4142136;

/// The original (faulty, repetitive) SPD hash of grid point `(a, b)` at size factor
/// `c`: `((a << (23 − c)) + (b << (15 − c)) + (a << (7 − c))) & 0xffff` on unsigned
/// longs. For size factors above 7 the C shift count goes negative, which is undefined;
/// an x86-64 build shifts by the count modulo 64, and so do we.
pub(crate) fn hash_rand(a: i64, b: i64, c: u32) -> i64 {
    let shl = |v: i64, by: i64| (v as u64).wrapping_shl(by as u32);
    let c = i64::from(c);
    (shl(a, 23 - c)
        .wrapping_add(shl(b, 15 - c))
        .wrapping_add(shl(a, 7 - c))
        & 0xffff) as i64
}

/// The SPD's portable Gaussian deviate (Numerical Recipes' GASDEV over a small linear
/// congruential generator) for seed `seed`: deterministic, mean 0, variance 1.
pub(crate) fn gauss_rand(seed: i64) -> f64 {
    const M1: i64 = 134_456;
    const IA1: i64 = 8121;
    const IC1: i64 = 28_411;
    let mut ix2 = seed;
    loop {
        let ix1 = (IC1 + ix2 * IA1) % M1;
        ix2 = (IC1 + ix1 * IA1) % M1;
        // `ix * 2.0 * RM1` with `RM1` the macro `1.0/M1`: ((ix·2)·1)/M1.
        let v1 = ix1 as f64 * 2.0 * 1.0 / M1 as f64 - 1.0;
        let v2 = ix2 as f64 * 2.0 * 1.0 / M1 as f64 - 1.0;
        let r = v1 * v1 + v2 * v2;
        if r < 1.0 {
            let fac = (-2.0 * r.ln() / r).sqrt();
            return v1 * fac;
        }
    }
}

/// The pyramid of four spheres of radius `radius` resting around `center`: one on
/// top, three below it spaced 120° apart, each touching the top one.
fn create_spheres(w: &mut impl NffSink, center: DVec3, radius: f64) {
    let axis = DVec3::new(1.0, 1.0, 0.0);
    let len = (axis.x * axis.x + axis.y * axis.y + axis.z * axis.z).sqrt();
    let axis = DVec3::new(axis.x / len, axis.y / len, axis.z / len);
    let angle = (-1.0f64 / 3.0).acos();

    let pt = DVec3::new(0.0, 0.0, radius * (3.0f64 / 2.0).sqrt());
    w.sphere(
        DVec3::new(center.x + pt.x, center.y + pt.y, center.z + pt.z),
        radius,
    );

    let new_pt = transform_vector(pt, &rotate_axis(axis, angle));
    for i in 0..3 {
        let mx = rotate(2, f64::from(i) * 2.0 * PI / 3.0);
        let p = transform_vector(new_pt, &mx);
        w.sphere(
            DVec3::new(p.x + center.x, p.y + center.y, p.z + center.z),
            radius,
        );
    }
}

/// Heights of a square's corners: lower left, lower right, upper right, upper left.
#[derive(Clone, Copy, Debug)]
struct Corners {
    ll: f64,
    lr: f64,
    ur: f64,
    ul: f64,
}

/// The recursive subdivision state shared by every call; `emit` receives the
/// triangles in the SPD's order.
struct Mountain<F: FnMut([DVec3; 3])> {
    emit: F,
    /// Grid points per side (`2^size`), as a double.
    fnum_pts: f64,
    size: u32,
    roughness: f64,
}

impl<F: FnMut([DVec3; 3])> Mountain<F> {
    fn displacement(&self, x: i64, y: i64) -> f64 {
        gauss_rand(MOUNTAIN_NO + hash_rand(x, y, self.size))
    }

    /// Grow the square of `width` grid cells whose lower-left grid point is
    /// `(ll_x, ll_y)`.
    fn grow(&mut self, width: i64, ll_x: i64, ll_y: i64, z: Corners) {
        if width == 1 {
            let coord = |i: i64| (i as f64) * WIDTH / self.fnum_pts;
            let l_fx = CORNER + coord(ll_x);
            let r_fx = CORNER + coord(ll_x + 1);
            let l_fy = CORNER + coord(ll_y);
            let u_fy = CORNER + coord(ll_y + 1);
            let quad = [
                DVec3::new(l_fx, l_fy, z.ll),
                DVec3::new(r_fx, l_fy, z.lr),
                DVec3::new(r_fx, u_fy, z.ur),
                DVec3::new(l_fx, u_fy, z.ul),
            ];
            (self.emit)([quad[0], quad[1], quad[2]]);
            (self.emit)([quad[2], quad[3], quad[0]]);
            return;
        }
        let half = width >> 1;
        let hside_length = (half as f64) * WIDTH / self.fnum_pts;
        let rise = hside_length * self.roughness;

        let lower = (z.ll + z.lr) / 2.0 + rise * self.displacement(ll_x + half, ll_y);
        let right = (z.lr + z.ur) / 2.0 + rise * self.displacement(ll_x + width, ll_y + half);
        let upper = (z.ur + z.ul) / 2.0 + rise * self.displacement(ll_x + half, ll_y + width);
        let left = (z.ul + z.ll) / 2.0 + rise * self.displacement(ll_x, ll_y + half);
        let middle = (z.ll + z.lr + z.ur + z.ul) / 4.0
            + SPD_SQRT_2 * rise * self.displacement(ll_x + half, ll_y + half);

        let c = |ll, lr, ur, ul| Corners { ll, lr, ur, ul };
        self.grow(half, ll_x, ll_y, c(z.ll, lower, middle, left));
        self.grow(half, ll_x + half, ll_y, c(lower, z.lr, right, middle));
        self.grow(
            half,
            ll_x + half,
            ll_y + half,
            c(middle, right, z.ur, upper),
        );
        self.grow(half, ll_x, ll_y + half, c(left, middle, upper, z.ul));
    }
}

/// Write the database at size factor `size`.
pub fn generate(size: u32, w: &mut impl NffSink) {
    // UNC sky blue.
    w.background(DVec3::new(0.078, 0.361, 0.753));
    w.viewpoint(
        DVec3::new(-1.6, 1.6, 1.7),
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(0.0, 0.0, 1.0),
        45.0,
        0.01,
        (512, 512),
    );
    w.light(DVec3::new(-100.0, -100.0, 100.0));

    // Clear crystal spheres.
    w.fill(DVec3::ONE, 0.1, 0.1, phong_power(6.7), 0.9, 1.5);
    create_spheres(w, DVec3::new(-0.8, 0.8, 1.0), 0.17);

    // Grey mountain.
    w.fill(
        DVec3::new(0.5, 0.45, 0.35),
        1.0,
        0.0,
        phong_power(0.0),
        0.0,
        0.0,
    );
    for_each_triangle(size, |t| w.polygon(&t));
}

/// Subdivide the flat square into the fractal mountain at size factor `size`, passing
/// each triangle to `emit` in the SPD's order.
fn for_each_triangle(size: u32, emit: impl FnMut([DVec3; 3])) {
    let num_pts: i64 = 1 << size;
    let ratio = 2.0 / (2.0f64.ln() / (FRACTAL_DIMENSION - 1.0)).exp();
    let mut m = Mountain {
        emit,
        fnum_pts: num_pts as f64,
        size,
        roughness: (ratio * ratio - 1.0).sqrt(),
    };
    let flat = Corners {
        ll: 0.0,
        lr: 0.0,
        ur: 0.0,
        ul: 0.0,
    };
    m.grow(num_pts, 0, 0, flat);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spd::NffWriter;
    use std::collections::HashMap;
    use std::path::Path;

    fn nff(size: u32) -> String {
        let mut w = NffWriter::new();
        generate(size, &mut w);
        w.finish()
    }

    /// The mountain's triangles at size factor `size`, in full precision.
    fn mountain(size: u32) -> Vec<[DVec3; 3]> {
        let mut tris = Vec::new();
        for_each_triangle(size, |t| tris.push(t));
        tris
    }

    fn bits(v: DVec3) -> [u64; 3] {
        [v.x.to_bits(), v.y.to_bits(), v.z.to_bits()]
    }

    #[test]
    fn counts_follow_two_times_four_to_the_size() {
        for size in 0..=4 {
            let text = nff(size);
            let tris = text.lines().filter(|l| *l == "p 3").count();
            assert_eq!(tris, 2 * 4usize.pow(size), "size {size}");
            assert_eq!(text.lines().filter(|l| l.starts_with("s ")).count(), 4);
            assert_eq!(text.lines().filter(|l| l.starts_with("l ")).count(), 1);
            assert_eq!(text.lines().filter(|l| l.starts_with("f ")).count(), 2);
        }
    }

    #[test]
    fn hash_is_the_original_and_deterministic() {
        // (a << 17) + (b << 9) + (a << 1), masked to 16 bits, at size 6.
        assert_eq!(hash_rand(1, 0, 6), 2);
        assert_eq!(hash_rand(0, 1, 6), 512);
        assert_eq!(hash_rand(3, 5, 6), (5 * 512 + 3 * 2) & 0xffff);
        // At size 3: (a << 20) + (b << 12) + (a << 4).
        assert_eq!(hash_rand(5, 3, 3), ((3 << 12) + (5 << 4)) & 0xffff);
        // The repetition that makes it faulty: b's high bits are masked away.
        assert_eq!(hash_rand(1, 7, 6), hash_rand(1, 7 + 128, 6));
        for (a, b, c) in [(0, 0, 3), (17, 42, 6), (64, 64, 6), (5, 9, 8)] {
            assert_eq!(hash_rand(a, b, c), hash_rand(a, b, c));
            assert!((0..=0xffff).contains(&hash_rand(a, b, c)));
        }
        assert_eq!(gauss_rand(21).to_bits(), gauss_rand(21).to_bits());
        // A Gaussian deviate: the mean of many is near 0, the variance near 1.
        let xs: Vec<f64> = (0..20_000).map(gauss_rand).collect();
        let mean = xs.iter().sum::<f64>() / xs.len() as f64;
        let var = xs.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / xs.len() as f64;
        assert!(mean.abs() < 0.05, "mean {mean}");
        assert!((var - 1.0).abs() < 0.1, "variance {var}");
    }

    #[test]
    fn triangles_form_a_crack_free_mesh() {
        for size in 1..=4 {
            let tris = mountain(size);
            let n = 1usize << size;
            // Every grid point has one height, bit for bit, wherever it is used.
            let mut height: HashMap<[u64; 2], u64> = HashMap::new();
            let mut edges: HashMap<([u64; 3], [u64; 3]), usize> = HashMap::new();
            for t in &tris {
                for v in t {
                    let z = height
                        .entry([v.x.to_bits(), v.y.to_bits()])
                        .or_insert(v.z.to_bits());
                    assert_eq!(*z, v.z.to_bits(), "size {size}: vertex {v} has two heights");
                }
                for k in 0..3 {
                    let (a, b) = (bits(t[k]), bits(t[(k + 1) % 3]));
                    *edges
                        .entry(if a < b { (a, b) } else { (b, a) })
                        .or_default() += 1;
                }
                // Counter-clockwise seen from above: the normal points up.
                let nz = (t[1] - t[0]).cross(t[2] - t[0]).z;
                assert!(nz > 0.0);
            }
            assert_eq!(height.len(), (n + 1) * (n + 1), "size {size}");
            // Interior edges are shared by exactly two triangles; the 4n border edges
            // belong to one.
            assert!(edges.values().all(|&c| c == 1 || c == 2));
            let border: Vec<_> = edges.iter().filter(|&(_, &c)| c == 1).collect();
            assert_eq!(border.len(), 4 * n, "size {size}");
            for ((a, b), _) in border {
                let on_border = |p: &[u64; 3]| {
                    let (x, y) = (f64::from_bits(p[0]), f64::from_bits(p[1]));
                    (x.abs() == 1.0 && f64::from_bits(a[0]) == f64::from_bits(b[0]))
                        || (y.abs() == 1.0 && f64::from_bits(a[1]) == f64::from_bits(b[1]))
                };
                assert!(on_border(a) && on_border(b));
            }
            assert_eq!(edges.len(), 3 * n * n + 2 * n);
            // The square's corners stay at height 0 and the surface is displaced.
            assert_eq!(height[&[(-1.0f64).to_bits(), (-1.0f64).to_bits()]], 0);
            assert_eq!(height[&[1.0f64.to_bits(), 1.0f64.to_bits()]], 0);
            assert!(height.values().any(|&z| f64::from_bits(z).abs() > 1e-3));
        }
    }

    #[test]
    fn output_parses_with_the_expected_counts() {
        let text = nff(2);
        let scene = crate::load::nff::parse_str(&text, Path::new("x")).unwrap();
        assert_eq!(scene.geometry.spheres().len(), 4);
        assert_eq!(scene.geometry.triangles.len(), 32);
        assert_eq!(scene.load_stats.polygons, 32);
        assert_eq!(scene.load_stats.degenerate_dropped, 0);
        assert_eq!(scene.lights.len(), 1);
        assert_eq!(scene.geometry.cones().len(), 0);
    }

    #[test]
    fn spheres_form_a_touching_pyramid() {
        let mut w = NffWriter::new();
        create_spheres(&mut w, DVec3::new(-0.8, 0.8, 1.0), 0.17);
        let text = w.finish();
        let c: Vec<DVec3> = text
            .lines()
            .map(|l| {
                let f: Vec<f64> = l[2..].split(' ').map(|t| t.parse().unwrap()).collect();
                assert_eq!(f[3], 0.17);
                DVec3::new(f[0], f[1], f[2])
            })
            .collect();
        assert_eq!(c.len(), 4);
        for i in 0..4 {
            for j in i + 1..4 {
                // Every pair touches: centres one diameter apart.
                assert!((c[i].distance(c[j]) - 0.34).abs() < 1e-5, "{i} {j}");
            }
        }
        // The top sphere is straight above the three below it.
        assert!(c[1..].iter().all(|p| p.z < c[0].z));
    }

    #[test]
    fn phong_power_matches_the_spd_library() {
        assert_eq!(phong_power(0.0), 100_000.0);
        assert_eq!(phong_power(90.0), 1.0);
        // cos(60°)^1 = ½: the exponent is the half-power lobe's.
        assert!((phong_power(60.0) - 1.0).abs() < 1e-12);
        assert_eq!(super::super::fmt_g(phong_power(6.7)), "101.148");
    }
}
