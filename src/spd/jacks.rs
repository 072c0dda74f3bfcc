//! The `jacks` database (Alexander Enzmann, SPD 3.14): a "jack" of three crossed
//! cylinders with a sphere at each of their six ends, and recursively a half-size copy
//! in each of the eight octants between its arms, like a Menger sponge.
//!
//! The whole structure is turned −30° about X and −20° about Y. The SPD program builds
//! it with its transformation stack (row vectors, each new transformation applied
//! before the ones already on the stack) and writes every primitive transformed:
//! points through the matrix, radii times the length of the matrix's first row. We do
//! the same arithmetic in the same order.
//!
//! A jack is 3 cylinders and 6 spheres; size factor `n` nests `n` levels deep, so there
//! are (8ⁿ − 1)/7 jacks: 9·(8ⁿ − 1)/7 primitives (9, 81, 657, 5265, 42129, …).

use super::tx::{IDENTITY, Matrix, multiply};
use super::{NffSink, phong_power};
use glam::DVec3;
use std::f64::consts::PI;

/// emray's default size factor: the SPD convention of the largest size below 10,000
/// primitives, 4 (5,265 primitives; size 5 has 42,129). The `jacks.c` program itself
/// starts from `size_factor = 1` (9 primitives), which is no benchmark; `-s 1` gives it.
pub const DEFAULT_SIZE: u32 = 4;

/// Write the database at size factor `size` (nesting depth; 0 writes no jacks).
pub fn generate(size: u32, w: &mut impl NffSink) {
    w.background(DVec3::new(0.2, 0.05, 0.2));
    w.viewpoint(
        DVec3::new(0.0, 0.0, -8.0),
        DVec3::ZERO,
        DVec3::new(0.0, 1.0, 0.0),
        25.0,
        0.001,
        (256, 256),
    );
    w.light(DVec3::new(-10.0, 3.0, -20.0));

    let mut tx = TxStack::new();
    tx.push();
    tx.rotate_x(-30.0 * PI / 180.0);
    tx.rotate_y(-20.0 * PI / 180.0);
    w.fill(
        DVec3::new(0.737, 0.561, 0.561),
        0.7,
        0.7,
        phong_power(20.0),
        0.0,
        1.0,
    );
    if size >= 1 {
        rec_jack(1, size, &mut tx, w);
    }
    tx.pop();
}

/// One jack and, below the deepest level, its eight half-size children.
fn rec_jack(depth: u32, max_depth: u32, tx: &mut TxStack, w: &mut impl NffSink) {
    jack(tx, w);
    if depth < max_depth {
        // The SPD steps a double from −0.5 while it is ≤ 0.5: −0.5, then 0.5.
        for i in [-0.5, 0.5] {
            for j in [-0.5, 0.5] {
                for k in [-0.5, 0.5] {
                    tx.push();
                    tx.translate(DVec3::new(i, j, k));
                    tx.scale(0.5);
                    rec_jack(depth + 1, max_depth, tx, w);
                    tx.pop();
                }
            }
        }
    }
}

/// Three cylinders along the axes from −1 to 1 (radius 0.1) and spheres of radius 0.2
/// at their ends, all scaled by 0.75 to keep neighbours apart.
fn jack(tx: &mut TxStack, w: &mut impl NffSink) {
    tx.push();
    tx.scale(0.75);
    let axes = [DVec3::X, DVec3::Y, DVec3::Z];
    for a in axes {
        let (base, apex) = (-a, a);
        let r = tx.radius(0.1);
        w.cone(tx.point(base), r, tx.point(apex), r);
    }
    for c in axes.into_iter().chain(axes.map(|a| -a)) {
        w.sphere(tx.point(c), tx.radius(0.2));
    }
    tx.pop();
}

/// The SPD's transformation stack.
struct TxStack {
    current: Matrix,
    saved: Vec<Matrix>,
}

impl TxStack {
    fn new() -> Self {
        TxStack {
            current: IDENTITY,
            saved: Vec::new(),
        }
    }

    fn push(&mut self) {
        self.saved.push(self.current);
    }

    fn pop(&mut self) {
        self.current = self.saved.pop().expect("balanced push/pop");
    }

    /// Apply `m` before everything already on the stack.
    fn prepend(&mut self, m: &Matrix) {
        self.current = multiply(m, &self.current);
    }

    fn rotate_x(&mut self, angle: f64) {
        let (s, c) = (angle.sin(), angle.cos());
        let mut m = IDENTITY;
        m[1][1] = c;
        m[2][2] = c;
        m[1][2] = s;
        m[2][1] = -s;
        self.prepend(&m);
    }

    fn rotate_y(&mut self, angle: f64) {
        let (s, c) = (angle.sin(), angle.cos());
        let mut m = IDENTITY;
        m[0][0] = c;
        m[2][2] = c;
        m[2][0] = s;
        m[0][2] = -s;
        self.prepend(&m);
    }

    fn scale(&mut self, s: f64) {
        let mut m = IDENTITY;
        m[0][0] = s;
        m[1][1] = s;
        m[2][2] = s;
        self.prepend(&m);
    }

    fn translate(&mut self, t: DVec3) {
        let mut m = IDENTITY;
        m[3][0] = t.x;
        m[3][1] = t.y;
        m[3][2] = t.z;
        self.prepend(&m);
    }

    /// A point through the current matrix (`lib_transform_point`).
    fn point(&self, v: DVec3) -> DVec3 {
        let m = &self.current;
        DVec3::new(
            v.x * m[0][0] + v.y * m[1][0] + v.z * m[2][0] + m[3][0],
            v.x * m[0][1] + v.y * m[1][1] + v.z * m[2][1] + m[3][1],
            v.x * m[0][2] + v.y * m[1][2] + v.z * m[2][2] + m[3][2],
        )
    }

    /// A radius times the matrix's X scale (the length of its first row, after
    /// dividing by the homogeneous element), as the SPD's NFF output does.
    fn radius(&self, r: f64) -> f64 {
        let m = &self.current;
        let h = m[3][3];
        let (x, y, z) = if h != 0.0 {
            (m[0][0] / h, m[0][1] / h, m[0][2] / h)
        } else {
            (m[0][0], m[0][1], m[0][2])
        };
        r * (x * x + y * y + z * z).sqrt().abs()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    fn count(text: &str, tag: &str) -> usize {
        text.lines()
            .filter(|l| l.split_whitespace().next() == Some(tag))
            .count()
    }

    fn jacks(n: u32) -> usize {
        (8usize.pow(n) - 1) / 7
    }

    fn nums(line: &str) -> Vec<f64> {
        line.split_whitespace()
            .skip(1)
            .map(|t| t.parse().unwrap())
            .collect()
    }

    #[test]
    fn primitive_counts_follow_the_recursion() {
        for n in 0..=3 {
            let text = super::super::Database::Jacks.generate(n);
            assert_eq!(count(&text, "c"), 3 * jacks(n), "size {n}");
            assert_eq!(count(&text, "s"), 6 * jacks(n), "size {n}");
            assert_eq!(count(&text, "f"), 1);
            assert_eq!(count(&text, "l"), 1);
            assert_eq!(count(&text, "p"), 0);
        }
        assert_eq!(9 * jacks(4), 5265);
    }

    #[test]
    fn arms_are_symmetric_about_each_jack_centre() {
        let text = super::super::Database::Jacks.generate(3);
        let lines: Vec<&str> = text
            .lines()
            .filter(|l| l.starts_with("c ") || l.starts_with("s "))
            .collect();
        // Each jack: 3 cylinders then 6 spheres (+X, +Y, +Z, −X, −Y, −Z).
        assert_eq!(lines.len() % 9, 0);
        for jack in lines.chunks(9) {
            let cyl: Vec<Vec<f64>> = jack[..3].iter().map(|l| nums(l)).collect();
            let sph: Vec<Vec<f64>> = jack[3..].iter().map(|l| nums(l)).collect();
            let centre = DVec3::new(
                (cyl[0][0] + cyl[0][4]) / 2.0,
                (cyl[0][1] + cyl[0][5]) / 2.0,
                (cyl[0][2] + cyl[0][6]) / 2.0,
            );
            let arm = (DVec3::new(cyl[0][4], cyl[0][5], cyl[0][6]) - centre).length();
            for (a, c) in cyl.iter().enumerate() {
                let base = DVec3::new(c[0], c[1], c[2]);
                let apex = DVec3::new(c[4], c[5], c[6]);
                // Every cylinder is centred on the jack's centre, of the same length.
                assert!(((base + apex) / 2.0 - centre).length() < 1e-5);
                assert!(((apex - centre).length() - arm).abs() < 1e-5);
                // Its ends carry the spheres +axis and −axis.
                let plus = DVec3::new(sph[a][0], sph[a][1], sph[a][2]);
                let minus = DVec3::new(sph[a + 3][0], sph[a + 3][1], sph[a + 3][2]);
                assert!((plus - apex).length() < 1e-5 && (minus - base).length() < 1e-5);
                // Radii: cylinder half the sphere's, both proportional to the arm.
                assert!((c[3] - c[7]).abs() < 1e-9);
                assert!((sph[a][3] - 2.0 * c[3]).abs() < 1e-6);
                assert!((c[3] / arm - 0.1).abs() < 1e-4);
            }
            // The three arms are mutually perpendicular.
            let dir = |c: &Vec<f64>| DVec3::new(c[4] - c[0], c[5] - c[1], c[6] - c[2]).normalize();
            assert!(dir(&cyl[0]).dot(dir(&cyl[1])).abs() < 1e-4);
            assert!(dir(&cyl[1]).dot(dir(&cyl[2])).abs() < 1e-4);
            assert!(dir(&cyl[0]).dot(dir(&cyl[2])).abs() < 1e-4);
        }
    }

    #[test]
    fn children_sit_in_the_octants_at_half_size() {
        let text = super::super::Database::Jacks.generate(2);
        let cyl: Vec<Vec<f64>> = text
            .lines()
            .filter(|l| l.starts_with("c "))
            .map(nums)
            .collect();
        let centre = |c: &Vec<f64>| DVec3::new(c[0] + c[4], c[1] + c[5], c[2] + c[6]) / 2.0;
        let root = centre(&cyl[0]);
        assert!(root.length() < 1e-6, "root jack at the origin");
        let r0 = cyl[0][3];
        let mut dirs = Vec::new();
        for child in cyl[3..].chunks(3) {
            assert!((child[0][3] - r0 / 2.0).abs() < 1e-6);
            // Child centres are (±0.5, ±0.5, ±0.5) rotated: √0.75 from the root.
            let c = centre(&child[0]) - root;
            assert!((c.length() - 0.75f64.sqrt()).abs() < 1e-5);
            dirs.push(c);
        }
        assert_eq!(dirs.len(), 8);
        // Eight distinct octants: pairwise distances are 1, √2 or √3.
        for (i, a) in dirs.iter().enumerate() {
            for b in &dirs[i + 1..] {
                let d = (*a - *b).length();
                assert!(
                    [1.0, 2f64.sqrt(), 3f64.sqrt()]
                        .iter()
                        .any(|e| (d - e).abs() < 1e-5)
                );
            }
        }
    }

    #[test]
    fn output_parses_with_the_nff_loader() {
        let text = super::super::Database::Jacks.generate(2);
        let scene = crate::load::nff::parse_str(&text, Path::new("x")).unwrap();
        assert_eq!(scene.geometry.cones().len(), 27);
        assert_eq!(scene.geometry.spheres().len(), 54);
        assert_eq!(scene.lights.len(), 1);
        assert_eq!(scene.load_stats.polygons, 0);
    }

    #[test]
    fn phong_power_matches_the_spd_values() {
        assert_eq!(super::super::fmt_g(phong_power(20.0)), "11.1434");
        assert_eq!(super::super::fmt_g(phong_power(37.0)), "3.0827");
        assert_eq!(phong_power(0.0), 100000.0);
    }
}
