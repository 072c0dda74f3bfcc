//! Floating-point error bounds and ray-origin offsets (pbrt, 3rd ed., §6.8).
//!
//! No scene-size epsilon: a spawned ray starts at the hit point moved along the
//! geometric normal by the bound on the hit point's rounding error, then rounded one
//! ulp further away, so it cannot re-hit the surface it leaves.

use super::Vec3;

/// `n·u / (1 − n·u)` with `u = 2⁻²⁴`: the relative error bound of `n` f32 operations.
#[inline]
pub const fn gamma(n: u32) -> f32 {
    let nu = n as f32 * (f32::EPSILON * 0.5);
    nu / (1.0 - nu)
}

/// `n·u / (1 − n·u)` with `u = 2⁻⁵³`: the relative error bound of `n` f64 operations
/// (the f64 fallbacks of the f32 tests).
#[inline]
pub const fn gamma64(n: u32) -> f64 {
    let nu = n as f64 * (f64::EPSILON * 0.5);
    nu / (1.0 - nu)
}

/// The next representable f32 above `v` (`+inf` stays).
#[inline]
pub fn next_float_up(v: f32) -> f32 {
    if v.is_infinite() && v > 0.0 {
        return v;
    }
    let v = if v == -0.0 { 0.0 } else { v };
    let bits = v.to_bits();
    let bits = if v >= 0.0 { bits + 1 } else { bits - 1 };
    f32::from_bits(bits)
}

/// The next representable f32 below `v` (`-inf` stays).
#[inline]
pub fn next_float_down(v: f32) -> f32 {
    if v.is_infinite() && v < 0.0 {
        return v;
    }
    let v = if v == 0.0 { -0.0 } else { v };
    let bits = v.to_bits();
    let bits = if v > 0.0 { bits - 1 } else { bits + 1 };
    f32::from_bits(bits)
}

/// The origin for a ray leaving point `p` (with per-axis absolute error bound `err`)
/// in direction `w`, off a surface with geometric normal `n` (any length, any side).
///
/// The point is pushed along `±n`, towards the side `w` points to, by the projection of
/// the error box on `n`, and each coordinate is rounded away from `p`.
#[inline]
pub fn offset_ray_origin(p: Vec3, err: Vec3, n: Vec3, w: Vec3) -> Vec3 {
    let d = n.abs().dot(err);
    let nn = n.length();
    // d / |n| is the distance needed; avoid dividing: scale n by d / |n|².
    let mut offset = n * (d / (nn * nn));
    if w.dot(n) < 0.0 {
        offset = -offset;
    }
    let mut po = p + offset;
    for i in 0..3 {
        if offset[i] > 0.0 {
            po[i] = next_float_up(po[i]);
        } else if offset[i] < 0.0 {
            po[i] = next_float_down(po[i]);
        }
    }
    po
}

/// The origins of the rays leaving one surface point, computed once per side: since
/// [`offset_ray_origin`] depends on the direction only through the side it points to
/// (the sign of `w·n`), every ray leaving a hit (shadow rays to each light, reflection,
/// refraction) starts from one of two points, each computed at most once.
#[derive(Clone, Copy, Debug)]
pub struct RayOrigins {
    p: Vec3,
    err: Vec3,
    n: Vec3,
    front: Option<Vec3>,
    back: Option<Vec3>,
}

impl RayOrigins {
    /// The origins off point `p` (error bound `err`) of a surface with normal `n`.
    #[inline]
    pub fn new(p: Vec3, err: Vec3, n: Vec3) -> Self {
        RayOrigins {
            p,
            err,
            n,
            front: None,
            back: None,
        }
    }

    /// `offset_ray_origin(p, err, n, w)`, bit for bit.
    #[inline]
    pub fn towards(&mut self, w: Vec3) -> Vec3 {
        let (p, err, n) = (self.p, self.err, self.n);
        if w.dot(n) < 0.0 {
            *self
                .back
                .get_or_insert_with(|| offset_ray_origin(p, err, n, -n))
        } else {
            *self
                .front
                .get_or_insert_with(|| offset_ray_origin(p, err, n, n))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn next_float_steps_one_ulp() {
        assert!(next_float_up(1.0) > 1.0);
        assert_eq!(next_float_up(1.0) - 1.0, f32::EPSILON);
        assert!(next_float_down(1.0) < 1.0);
        assert!(next_float_up(0.0) > 0.0);
        assert!(next_float_down(0.0) < 0.0);
        assert!(next_float_up(-0.0) > 0.0);
        assert_eq!(next_float_up(f32::INFINITY), f32::INFINITY);
    }

    #[test]
    fn cached_origins_equal_the_offset_for_every_direction() {
        let mut rng = crate::math::Rng::new(0x9e37_79b9);
        let mut r = || rng.range(-1.0, 1.0);
        for _ in 0..200 {
            let p = Vec3::new(r(), r(), r()) * 1e3;
            let err = Vec3::new(r().abs(), r().abs(), r().abs()) * 1e-4;
            let n = Vec3::new(r(), r(), r());
            let mut o = RayOrigins::new(p, err, n);
            for _ in 0..20 {
                let w = Vec3::new(r(), r(), r());
                let want = offset_ray_origin(p, err, n, w);
                assert_eq!(o.towards(w).to_array(), want.to_array(), "{p} {n} {w}");
            }
            // Directions in the surface's plane and opposite the normal.
            for w in [Vec3::ZERO, -n, n, n.cross(Vec3::X)] {
                let want = offset_ray_origin(p, err, n, w);
                assert_eq!(o.towards(w).to_array(), want.to_array(), "{p} {n} {w}");
            }
        }
    }

    #[test]
    fn offset_moves_to_the_side_of_w() {
        let n = Vec3::new(0.0, 0.0, 2.0);
        let err = Vec3::splat(1e-3);
        let up = offset_ray_origin(Vec3::ZERO, err, n, Vec3::Z);
        let down = offset_ray_origin(Vec3::ZERO, err, n, -Vec3::Z);
        assert!(up.z >= 1e-3 && up.x == 0.0 && up.y == 0.0);
        assert!(down.z <= -1e-3);
    }

    #[test]
    fn offset_scales_with_the_error_not_a_constant() {
        let n = Vec3::Y;
        let small = offset_ray_origin(Vec3::ZERO, Vec3::splat(1e-20), n, Vec3::Y);
        assert!(small.y > 0.0 && small.y < 1e-19);
    }
}
