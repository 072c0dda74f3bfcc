//! The bottom layer: rays, boxes, transforms, orthonormal frames, surface points with
//! their error bounds and the floating-point error tools used for robust ray spawning,
//! the coordinate hashes that drive sampling, and the one seeded random number
//! generator ([`Rng`]) for tests, benches and stress rays. It imports nothing from the
//! rest of the crate.

mod aabb;
mod rng;
mod robust;
mod xform;

pub use aabb::Aabb;
pub use glam::{DVec3, Vec3};
pub use rng::Rng;
pub use robust::{RayOrigins, gamma, gamma64, next_float_down, next_float_up, offset_ray_origin};
pub use xform::{Xform, XformError, similarity_scale};

/// A ray with its valid parameter interval `[tmin, tmax]`.
///
/// `dir` need not be unit length; `t` is measured in units of `dir`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    /// Origin.
    pub org: Vec3,
    /// Direction.
    pub dir: Vec3,
    /// Smallest accepted hit distance.
    pub tmin: f32,
    /// Largest accepted hit distance.
    pub tmax: f32,
}

impl Ray {
    /// A ray over `[0, +inf)`.
    pub fn new(org: Vec3, dir: Vec3) -> Self {
        Ray {
            org,
            dir,
            tmin: 0.0,
            tmax: f32::INFINITY,
        }
    }

    /// The point at parameter `t`.
    #[inline]
    pub fn at(&self, t: f32) -> Vec3 {
        self.org + self.dir * t
    }

    /// Whether both backends can trace this ray: origin and direction finite and
    /// within [`MAX_RAY_COMPONENT`] in every component, and an interval that is not
    /// NaN. Every ray query checks it first and treats any other ray as hitting
    /// nothing, so that no value reaches a traversal or Embree that they do not accept.
    ///
    /// Branch-free, on the bits: a non-negative float orders as its bit pattern, and
    /// NaN's patterns lie above infinity's, so `|x| <= limit` is `bits(|x|) <=
    /// bits(limit)` for every `x`, NaN included (every eye ray passes through here
    /// before Embree sees it).
    #[inline]
    pub fn is_traceable(&self) -> bool {
        const LIMIT: u32 = MAX_RAY_COMPONENT.to_bits();
        let within = |x: f32| (x.to_bits() & 0x7fff_ffff) <= LIMIT;
        let all_within = |v: Vec3| within(v.x) & within(v.y) & within(v.z);
        all_within(self.org) & all_within(self.dir) & !self.tmin.is_nan() & !self.tmax.is_nan()
    }
}

/// Largest magnitude of a ray's origin or direction component that the ray queries
/// accept: Embree's own bound (`FLT_LARGE`, about 1.8·10¹⁸), above which its traversal
/// is undefined. Scenes are kept far inside it (see `scene::MAX_COORDINATE`). NaN
/// fails every comparison with it, so the test also rejects non-finite values.
pub const MAX_RAY_COMPONENT: f32 = 1.844e18;

/// The same ray in double precision, for reference computations.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DRay {
    /// Origin.
    pub org: DVec3,
    /// Direction.
    pub dir: DVec3,
}

impl From<&Ray> for DRay {
    fn from(r: &Ray) -> Self {
        DRay {
            org: r.org.as_dvec3(),
            dir: r.dir.as_dvec3(),
        }
    }
}

/// A hit point with the bound of its rounding error, for robust ray spawning.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfacePoint {
    /// The point, computed as accurately as the shape allows (not `o + t·d`).
    pub p: Vec3,
    /// Per-axis absolute error bound of `p`.
    pub err: Vec3,
    /// Unit geometric normal (outwards for closed shapes, by winding for triangles).
    pub ng: Vec3,
}

/// A right-handed orthonormal frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    /// First tangent.
    pub x: Vec3,
    /// Second tangent.
    pub y: Vec3,
    /// Normal (the frame's z axis).
    pub z: Vec3,
}

impl Frame {
    /// A frame whose z axis is the unit vector `n` (Duff et al. 2017, branchless ONB).
    pub fn from_z(n: Vec3) -> Self {
        let sign = 1.0f32.copysign(n.z);
        let a = -1.0 / (sign + n.z);
        let b = n.x * n.y * a;
        let x = Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
        let y = Vec3::new(b, sign + n.y * n.y * a, -n.y);
        Frame { x, y, z: n }
    }
}

/// A 32-bit integer hash (Wellons' lowbias32): per-pixel sample offsets and the
/// jittered shadow rays of area lights.
#[inline]
pub fn hash(mut x: u32) -> u32 {
    x ^= x >> 16;
    x = x.wrapping_mul(0x7feb_352d);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846c_a68b);
    x ^= x >> 16;
    x
}

/// The top 24 bits of `x` as a float in `[0, 1)`.
#[inline]
pub fn hash_unit(x: u32) -> f32 {
    (x >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The bit test of `is_traceable` against the plain comparisons, over the values
    /// at and around its edges: zeros, the limit and its neighbours, infinities, NaNs.
    #[test]
    fn traceable_is_the_comparison_with_the_limit() {
        let edges = [
            0.0,
            -0.0,
            1.0,
            f32::MIN_POSITIVE,
            MAX_RAY_COMPONENT,
            next_float_up(MAX_RAY_COMPONENT),
            next_float_down(MAX_RAY_COMPONENT),
            f32::MAX,
            f32::INFINITY,
            f32::NAN,
            f32::from_bits(0x7fff_ffff),
            f32::from_bits(0x7f80_0001),
        ];
        let values = edges.iter().flat_map(|&x| [x, -x]);
        for x in values {
            for axis in 0..6 {
                let mut c = [1.0f32; 6];
                c[axis] = x;
                let ray = Ray {
                    org: Vec3::new(c[0], c[1], c[2]),
                    dir: Vec3::new(c[3], c[4], c[5]),
                    tmin: 0.0,
                    tmax: f32::INFINITY,
                };
                let expected = x.abs() <= MAX_RAY_COMPONENT;
                assert_eq!(ray.is_traceable(), expected, "{x:e} on axis {axis}");
            }
        }
        let nan_interval = Ray {
            tmax: f32::NAN,
            ..Ray::new(Vec3::ZERO, Vec3::X)
        };
        assert!(!nan_interval.is_traceable());
    }
}
