//! The `shells` database: a spiral sea shell of overlapping spheres, after Pickover's
//! method (IEEE CG&A, November 1989; SPD `shells.c`). Many tiny, heavily overlapping
//! spheres make it a deliberately pathological scene.
//!
//! With `steps = 180·2ˢⁱᶻᵉ`, sphere `i` for `i` from `−⅔·steps` to `⅓·steps` sits at
//! angle `θ = 18π·i/steps` (nine turns in all) on the logarithmic spiral
//! `r = k·e^(aθ)`: centre `(r sin θ, r cos θ, β r)` and radius `r/γ`, with the SPD's
//! defaults `k = 1`, `a = 0.15`, `β = −2`, `γ = 1` (and `α = 0`, which selects the
//! `z = β r` form). That is `steps + 1 = 180·2ˢⁱᶻᵉ + 1` spheres and nothing else (the
//! SPD's comment mentions a square, but the program writes none).

use super::NffSink;
use glam::DVec3;
use rayon::prelude::*;
use std::f64::consts::PI;

/// The SPD program's default size factor: `shells.c` sets `size_factor = 5`, 5761
/// spheres, the largest size under the SPD's 10,000-primitive budget (size 6 would
/// give 11,521).
pub const DEFAULT_SIZE: u32 = 5;

/// Spiral size factor `k`.
const K: f64 = 1.0;
/// Exponent constant `a` of the spiral.
const A: f64 = 0.15;
/// Height factor `β`: `z = β r`.
const BETA: f64 = -2.0;
/// Radius divisor `γ`.
const GAMMA: f64 = 1.0;

/// The spheres (centre, radius) at size factor `size`, in the SPD's order, each
/// computed from its index alone (in parallel on the current rayon pool).
fn spheres(size: u32) -> Vec<(DVec3, f64)> {
    let steps = steps(size);
    (-steps * 2 / 3..=steps / 3)
        .into_par_iter()
        .map(|i| sphere(i, steps))
        .collect()
}

/// `180·2ˢⁱᶻᵉ`, the spheres per nine turns.
fn steps(size: u32) -> i64 {
    (180.0 * 2.0f64.powi(size as i32)) as i64
}

/// Sphere `i` of the spiral of `steps` steps.
fn sphere(i: i64, steps: i64) -> (DVec3, f64) {
    let angle = 3.0 * 6.0 * PI * i as f64 / steps as f64;
    let r = K * (A * angle).exp();
    (
        DVec3::new(r * angle.sin(), r * angle.cos(), BETA * r),
        r / GAMMA,
    )
}

/// Write the database at size factor `size`.
pub fn generate(size: u32, w: &mut impl NffSink) {
    w.background(DVec3::new(0.078, 0.361, 0.753));
    w.viewpoint(
        DVec3::new(-6.0, -60.0, 35.0),
        DVec3::new(0.0, 8.0, -15.0),
        DVec3::new(0.0, 0.0, 1.0),
        45.0,
        0.5,
        (512, 512),
    );
    w.light(DVec3::new(-100.0, -100.0, 100.0));
    w.fill(
        DVec3::new(1.0, 0.8, 0.4),
        0.8,
        0.2,
        super::phong_power(10.0),
        0.0,
        1.0,
    );
    w.spheres(&spheres(size));
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spd::NffWriter;
    use std::path::Path;

    #[test]
    fn sphere_count_is_180_times_two_to_the_size_plus_one() {
        for n in 1..=5 {
            assert_eq!(spheres(n).len(), 180 * (1 << n) + 1, "size {n}");
        }
        assert_eq!(spheres(DEFAULT_SIZE).len(), 5761);
        assert!(spheres(DEFAULT_SIZE + 1).len() >= 10_000);
    }

    /// Made in parallel, the spheres are those of the plain loop, in its order.
    #[test]
    fn spheres_made_on_several_threads_are_the_loops() {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(4)
            .build()
            .unwrap();
        let bits = |s: &[(DVec3, f64)]| -> Vec<[u64; 4]> {
            s.iter()
                .map(|(c, r)| [c.x, c.y, c.z, *r].map(f64::to_bits))
                .collect()
        };
        let steps = steps(6);
        let want: Vec<_> = (-steps * 2 / 3..=steps / 3)
            .map(|i| sphere(i, steps))
            .collect();
        assert_eq!(bits(&pool.install(|| spheres(6))), bits(&want));
    }

    #[test]
    fn spheres_follow_the_logarithmic_spiral() {
        let s = spheres(2);
        let steps = 720.0;
        // Every centre is at distance r from the axis and at height −2r.
        for (c, r) in &s {
            assert!((c.truncate().length() - r).abs() <= 1e-12 * r);
            assert!((c.z + 2.0 * r).abs() <= 1e-12 * r);
        }
        // The last sphere is at angle 6π (three turns past the origin's direction).
        let (c, r) = s[s.len() - 1];
        assert!((r - (0.15 * 6.0 * PI).exp()).abs() < 1e-12 * r);
        assert!(c.x.abs() < 1e-12 * r && c.y > 0.0);
        // Each sphere is the previous one turned by 18π/steps about the axis and
        // scaled by e^(0.15·18π/steps) about the origin.
        let (dth, ratio) = (18.0 * PI / steps, (0.15 * 18.0 * PI / steps).exp());
        let rot = glam::DMat3::from_rotation_z(-dth);
        for p in s.windows(2) {
            let ((c0, r0), (c1, r1)) = (p[0], p[1]);
            assert!((r1 / r0 - ratio).abs() < 1e-12);
            let want = rot * c0 * ratio;
            assert!(c1.distance(want) < 1e-12 * r1, "{c1} vs {want}");
        }
    }

    #[test]
    fn output_parses_with_the_expected_counts() {
        let mut w = NffWriter::new();
        generate(1, &mut w);
        let scene = crate::load::nff::parse_str(&w.finish(), Path::new("x")).unwrap();
        assert_eq!(scene.geometry.spheres().len(), 361);
        assert_eq!(scene.geometry.triangles.len(), 0);
        assert_eq!(scene.lights.len(), 1);
    }
}
