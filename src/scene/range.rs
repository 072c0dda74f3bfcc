//! The range of values a scene may hold so that every ray the renderer casts stays
//! finite: where geometry, lights and the camera may lie, and which indices of
//! refraction a transmitting material may have. The loaders check their input against
//! these and report the offending value at its `file:line:col`; everything after them
//! (intersectors, ray spawning, both backends) relies on it.
//!
//! Why these bounds: rays must stay within Embree's accepted range (about 1.8·10¹⁸ per
//! component, origins and unnormalised shadow-ray directions alike), and the f32
//! intersectors form products of up to three coordinate differences (the watertight
//! triangle test's `t`) and squared lengths of edge cross products, which must not
//! overflow f32 (3.4·10³⁸). With every coordinate within ±10⁹, the largest such
//! quantity is about 10³⁷.

use crate::math::{Aabb, Vec3};
use std::ops::RangeInclusive;

/// Largest magnitude of any coordinate of the scene: primitives (their whole extent,
/// after transforms), lights and the camera. Unbounded primitives (planes, unbounded
/// quadrics) are checked through the points and sizes that define them.
pub const MAX_COORDINATE: f32 = 1e9;

/// Indices of refraction a transmitting material (`T > 0`) may have: a ratio of two of
/// them squared stays far inside f32, so Snell's law cannot overflow. Real materials
/// lie between 1 and about 4.
pub const IOR_RANGE: RangeInclusive<f32> = 1e-3..=1e3;

/// A value outside the range emray traces; the message names the value and the range.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum RangeError {
    /// A point with a coordinate beyond ±[`MAX_COORDINATE`].
    #[error(
        "{what} {} lies outside the range emray traces (every coordinate within \
         ±{MAX_COORDINATE:e}); scale the scene down or move it nearer the origin",
        show(*.point)
    )]
    Point {
        /// What the point is (`the eye`, ...).
        what: String,
        /// The point.
        point: Vec3,
    },
    /// A coordinate beyond ±[`MAX_COORDINATE`].
    #[error(
        "{what} {} lies outside the range emray traces (every coordinate within \
         ±{MAX_COORDINATE:e}); scale the scene down or move it nearer the origin",
        number(*.value)
    )]
    Coordinate {
        /// What the coordinate is.
        what: String,
        /// Its value.
        value: f32,
    },
    /// Bounds with a NaN coordinate.
    #[error("{what} has non-finite bounds")]
    NonFiniteBounds {
        /// What the bounds are of.
        what: String,
    },
    /// Bounds reaching beyond ±[`MAX_COORDINATE`].
    #[error(
        "{what} reaches from {} to {}, outside the range emray traces (every \
         coordinate within ±{MAX_COORDINATE:e}); scale the scene down or move it nearer \
         the origin",
        show(*.min),
        show(*.max)
    )]
    Bounds {
        /// What the bounds are of.
        what: String,
        /// Lower corner.
        min: Vec3,
        /// Upper corner.
        max: Vec3,
    },
    /// The index of refraction of a transmitting material outside [`IOR_RANGE`].
    #[error(
        "index of refraction {} for a transmitting surface (transmittance {transmittance}): \
         it must lie between {:e} and {:e} (1 for no bending; 0 is only meaningful on \
         opaque surfaces, transmittance 0)",
        number(*.ior),
        IOR_RANGE.start(),
        IOR_RANGE.end()
    )]
    Ior {
        /// The material's transmittance.
        transmittance: f32,
        /// Its index of refraction.
        ior: f32,
    },
}

/// `Err` when a point lies outside ±[`MAX_COORDINATE`].
pub fn check_point(what: &str, p: Vec3) -> Result<(), RangeError> {
    if p.abs().cmple(Vec3::splat(MAX_COORDINATE)).all() {
        return Ok(());
    }
    Err(RangeError::Point {
        what: what.into(),
        point: p,
    })
}

/// `Err` when one coordinate lies outside ±[`MAX_COORDINATE`].
pub fn check_coordinate(what: &str, x: f32) -> Result<(), RangeError> {
    if x.abs() <= MAX_COORDINATE {
        return Ok(());
    }
    Err(RangeError::Coordinate {
        what: what.into(),
        value: x,
    })
}

/// `Err` when a primitive's bounds reach outside ±[`MAX_COORDINATE`] (an unbounded
/// primitive's infinite bounds are not checked here).
pub fn check_bounds(what: &str, b: &Aabb) -> Result<(), RangeError> {
    if b.min.is_nan() || b.max.is_nan() {
        return Err(RangeError::NonFiniteBounds { what: what.into() });
    }
    let unbounded = !b.min.is_finite() || !b.max.is_finite();
    if unbounded || b.min.x > b.max.x {
        return Ok(());
    }
    let worst = b.min.abs().max(b.max.abs()).max_element();
    if worst <= MAX_COORDINATE {
        return Ok(());
    }
    Err(RangeError::Bounds {
        what: what.into(),
        min: b.min,
        max: b.max,
    })
}

/// `Err` when a material that transmits (`t > 0`) has an index of refraction outside
/// [`IOR_RANGE`]; any finite index is accepted for an opaque one, which never uses it
/// (the SPD writes 0 there).
pub fn check_ior(t: f32, ior: f32) -> Result<(), RangeError> {
    if t <= 0.0 || t.is_nan() || IOR_RANGE.contains(&ior) {
        return Ok(());
    }
    Err(RangeError::Ior {
        transmittance: t,
        ior,
    })
}

fn show(p: Vec3) -> String {
    format!("({}, {}, {})", number(p.x), number(p.y), number(p.z))
}

/// `x` as a message shows it: plainly between 10⁻⁴ and 10⁹, in exponent form beyond
/// (`2e30`, not thirty-one digits).
pub(crate) fn number(x: f32) -> String {
    let a = x.abs();
    if a == 0.0 || (1e-4..1e9).contains(&a) || !a.is_finite() {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn points_within_the_range_pass_and_others_name_the_range() {
        assert!(check_point("the eye", Vec3::splat(MAX_COORDINATE)).is_ok());
        let e = check_point("the eye", Vec3::new(-1.0, -2.226e26, 0.5))
            .unwrap_err()
            .to_string();
        assert!(e.contains("the eye (-1, -2.226e26, 0.5)"), "{e}");
        assert!(e.contains("±1e9"), "{e}");
        assert!(check_point("x", Vec3::new(f32::NAN, 0.0, 0.0)).is_err());
    }

    #[test]
    fn bounds_are_checked_unless_unbounded_or_empty() {
        let b = Aabb::from_points(Vec3::splat(-1.0), Vec3::splat(1.0));
        assert!(check_bounds("a sphere", &b).is_ok());
        let far = Aabb::from_points(Vec3::splat(-1.0), Vec3::new(1.0, 2e9, 1.0));
        assert!(
            check_bounds("a sphere", &far)
                .unwrap_err()
                .to_string()
                .contains("a sphere reaches")
        );
        let plane = Aabb {
            min: Vec3::splat(f32::NEG_INFINITY),
            max: Vec3::splat(f32::INFINITY),
        };
        assert!(check_bounds("a plane", &plane).is_ok());
        assert!(check_bounds("nothing", &Aabb::EMPTY).is_ok());
    }

    #[test]
    fn messages_name_the_value_and_the_range() {
        let text = |r: Result<(), RangeError>| r.unwrap_err().to_string();
        assert_eq!(
            text(check_point("the eye", Vec3::new(-1.0, -2.226e26, 0.5))),
            "the eye (-1, -2.226e26, 0.5) lies outside the range emray traces (every \
             coordinate within ±1e9); scale the scene down or move it nearer the origin"
        );
        assert_eq!(
            text(check_coordinate("vertex x", 3e9)),
            "vertex x 3e9 lies outside the range emray traces (every coordinate within \
             ±1e9); scale the scene down or move it nearer the origin"
        );
        let far = Aabb::from_points(Vec3::splat(-1.0), Vec3::new(1.0, 2e9, 1.0));
        assert_eq!(
            text(check_bounds("a sphere", &far)),
            "a sphere reaches from (-1, -1, -1) to (1, 2e9, 1), outside the range emray \
             traces (every coordinate within ±1e9); scale the scene down or move it nearer \
             the origin"
        );
        let nan = Aabb {
            min: Vec3::splat(f32::NAN),
            max: Vec3::ONE,
        };
        assert_eq!(
            text(check_bounds("a cone", &nan)),
            "a cone has non-finite bounds"
        );
        assert_eq!(
            text(check_ior(0.8, 2e3)),
            "index of refraction 2000 for a transmitting surface (transmittance 0.8): it \
             must lie between 1e-3 and 1e3 (1 for no bending; 0 is only meaningful on \
             opaque surfaces, transmittance 0)"
        );
    }

    #[test]
    fn only_transmitting_materials_need_a_usable_index() {
        // The SPD's opaque surfaces write 0.
        assert!(check_ior(0.0, 0.0).is_ok());
        assert!(check_ior(0.8, 1.1).is_ok());
        for bad in [0.0, -1.5, 1e-4, 2e3] {
            let e = check_ior(0.8, bad).unwrap_err().to_string();
            assert!(e.contains("between 1e-3 and 1e3"), "{e}");
        }
    }
}
