//! The `sombrero` database: a height field of a damped radial cosine, a "Mexican hat"
//! (SPD `sombrero.c`, by Alexander Enzmann), which NFF receives as triangles.
//!
//! At size factor `n` the field has `w = 32·2ⁿ⁻¹` samples a side. Sample `(i, j)` is
//! taken at `x = −4 + j·8/w`, `y = −4 + i·8/w` (the square `[-4, 4)²`) and holds, in
//! single precision, `h = c·cos(2πa·ρ)·e^(−bρ)/3` with `ρ = √(x² + y²)`, `a = b = 1`,
//! `c = 3` (and the SPD's π of 3.14159265358). The SPD library then lays the samples
//! out on the grid `x, z ∈ [−4, 4]` with spacing `8/(w − 1)`, height `y = −3 + h`, and
//! writes each of the `(w − 1)²` cells as two triangles, `2(w − 1)²` in all (1922 at
//! size 1).

use super::NffSink;
use glam::DVec3;

/// emray's default size factor: the SPD convention of the largest size below 10,000
/// primitives, 2 (7,938 triangles; size 3 has 31,752). The `sombrero.c` program itself
/// starts from `size_factor = 1` (1,922 triangles); `-s 1` gives it.
pub const DEFAULT_SIZE: u32 = 2;

/// The SPD's value of π in this program, truncated as `sombrero.c` writes it (kept so
/// the heights round exactly as the SPD's do).
#[allow(clippy::approx_constant)]
const SPD_PI: f64 = 3.14159265358;
/// Frequency `a`, damping `b` and amplitude `c` of the sombrero function.
const A: f64 = 1.0;
const B: f64 = 1.0;
const C: f64 = 3.0;
/// The sampled square `[X0, X1)²`.
const X0: f64 = -4.0;
const X1: f64 = 4.0;
/// Where the samples go: `x` and `z` span `[-4, 4]`, heights are offset by −3.
const OUT_X: (f64, f64) = (-4.0, 4.0);
const OUT_Y0: f64 = -3.0;
const OUT_Z: (f64, f64) = (-4.0, 4.0);

/// Samples a side at size factor `size`.
fn side(size: u32) -> usize {
    32 << (size.max(1) - 1)
}

/// The sombrero function at `(x, y)`, rounded to single precision as the SPD stores
/// it.
fn height(x: f64, y: f64) -> f32 {
    let two_pi_a = 2.0 * SPD_PI * A;
    let rho = (x * x + y * y).sqrt();
    (C * (two_pi_a * rho).cos() * (-B * rho).exp() / 3.0) as f32
}

/// The `n × n` samples, row `i` at `y = X0 + i·Δ`, column `j` at `x = X0 + j·Δ`,
/// with the coordinates stepped by repeated addition as the SPD does.
fn samples(n: usize) -> Vec<Vec<f32>> {
    let delta = (X1 - X0) / n as f64;
    let mut rows = Vec::with_capacity(n);
    let mut y = X0;
    for _ in 0..n {
        let mut row = Vec::with_capacity(n);
        let mut x = X0;
        for _ in 0..n {
            row.push(height(x, y));
            x += delta;
        }
        rows.push(row);
        y += delta;
    }
    rows
}

/// The triangles of the height field `data` (`SPD lib_output_polygon_height`), made
/// as they are taken (the largest fields have millions).
fn triangles(data: &[Vec<f32>]) -> impl Iterator<Item = [DVec3; 3]> + '_ {
    let rows = data.len();
    let cols = data[0].len();
    let dx = (OUT_X.1 - OUT_X.0) / (cols - 1) as f64;
    let dz = (OUT_Z.1 - OUT_Z.0) / (rows - 1) as f64;
    let vert = move |i: usize, j: usize| {
        DVec3::new(
            OUT_X.0 + j as f64 * dx,
            OUT_Y0 + f64::from(data[i][j]),
            OUT_Z.0 + i as f64 * dz,
        )
    };
    (0..rows - 1).flat_map(move |i| {
        (0..cols - 1).flat_map(move |j| {
            [
                [vert(i, j), vert(i + 1, j + 1), vert(i, j + 1)],
                [vert(i, j), vert(i + 1, j), vert(i + 1, j + 1)],
            ]
        })
    })
}

/// Write the database at size factor `size`.
pub fn generate(size: u32, w: &mut impl NffSink) {
    w.background(DVec3::new(0.078, 0.361, 0.753));
    w.viewpoint(
        DVec3::new(0.0, 5.0, -8.0),
        DVec3::ZERO,
        DVec3::new(0.0, 0.0, 1.0),
        40.0,
        0.01,
        (512, 512),
    );
    w.light(DVec3::new(10.0, 10.0, -10.0));
    // Shiny red.
    w.fill(
        DVec3::new(1.0, 0.1, 0.1),
        0.8,
        0.0,
        super::phong_power(40.0),
        0.0,
        1.0,
    );
    for t in triangles(&samples(side(size))) {
        w.polygon(&t);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spd::NffWriter;
    use std::collections::BTreeMap;
    use std::path::Path;

    #[test]
    fn triangle_count_is_twice_the_cells() {
        for n in 1..=3 {
            let w = side(n);
            assert_eq!(w, 32 << (n - 1));
            assert_eq!(triangles(&samples(w)).count(), 2 * (w - 1) * (w - 1));
        }
        assert_eq!(triangles(&samples(side(1))).count(), 1922);
    }

    #[test]
    fn triangles_form_a_grid_whose_heights_follow_the_function() {
        let n = side(1);
        let tris: Vec<_> = triangles(&samples(n)).collect();
        // Distinct vertices, keyed by grid position.
        let step = 8.0 / (n - 1) as f64;
        let mut grid: BTreeMap<(i64, i64), f64> = BTreeMap::new();
        for t in &tris {
            for v in t {
                let j = ((v.x + 4.0) / step).round() as i64;
                let i = ((v.z + 4.0) / step).round() as i64;
                assert!((v.x - (-4.0 + j as f64 * step)).abs() < 1e-12);
                assert!((v.z - (-4.0 + i as f64 * step)).abs() < 1e-12);
                // Shared vertices agree exactly.
                if let Some(h) = grid.insert((i, j), v.y) {
                    assert_eq!(h, v.y);
                }
            }
        }
        assert_eq!(grid.len(), n * n);
        // Grid point (i, j) holds the sombrero sampled at (−4 + j/4, −4 + i/4).
        let delta = 8.0 / n as f64;
        for (&(i, j), &y) in &grid {
            let (sx, sy) = (-4.0 + j as f64 * delta, -4.0 + i as f64 * delta);
            let rho = (sx * sx + sy * sy).sqrt();
            let want = -3.0 + (2.0 * std::f64::consts::PI * rho).cos() * (-rho).exp();
            assert!((y - want).abs() < 1e-6, "({i}, {j}): {y} vs {want}");
        }
        // The centre sample is the peak: cos 0 · e⁰ = 1.
        assert_eq!(grid[&(16, 16)], -2.0);
        // Every triangle winds counterclockwise seen from above (normal along +y).
        for t in &tris {
            assert!((t[1] - t[0]).cross(t[2] - t[0]).y > 0.0);
        }
    }

    #[test]
    fn output_parses_with_the_expected_counts() {
        let mut w = NffWriter::new();
        generate(1, &mut w);
        let scene = crate::load::nff::parse_str(&w.finish(), Path::new("x")).unwrap();
        assert_eq!(scene.load_stats.polygons, 1922);
        assert_eq!(scene.geometry.triangles.len(), 1922);
        assert_eq!(scene.load_stats.degenerate_dropped, 0);
        assert_eq!(scene.lights.len(), 1);
    }
}
