//! The automatic view of [`super::load`]: a camera that sees the whole model and a
//! light beside it (see the module documentation of [`super`]).

use crate::math::{Aabb, DVec3, Vec3};
use crate::scene::{Camera, Light};

/// Full vertical field of view of the automatic camera, in degrees.
pub const AUTO_FOV_DEG: f32 = 40.0;
/// Width and height of the automatic camera's image, in pixels.
pub const AUTO_RESOLUTION: u32 = 512;
/// Elevation of the automatic camera above the model's centre, in degrees.
pub const AUTO_ELEVATION_DEG: f32 = 15.0;
/// How much farther than the tightest fit the automatic camera stands.
pub const AUTO_MARGIN: f32 = 1.05;
/// Offset of the automatic light from the eye, along the camera's up minus right
/// vectors, as a fraction of the eye's distance to the model's centre.
pub const AUTO_LIGHT_OFFSET: f32 = 0.25;
/// Ambient light intensity of the automatic scene.
pub const AUTO_AMBIENT: f32 = 0.1;

/// The automatic camera and light for a model with these bounds (see the module
/// documentation), or `None` for empty, infinite or zero-size bounds.
pub fn frame(bounds: &Aabb) -> Option<(Camera, Light)> {
    if bounds.is_empty() || !bounds.is_finite() {
        return None;
    }
    // In f64: the diagonal of a box near f32's range overflows f32.
    let (lo, hi) = (bounds.min.as_dvec3(), bounds.max.as_dvec3());
    let centre = (lo + hi) * 0.5;
    let r = 0.5 * (hi - lo).length();
    if r <= 0.0 {
        return None;
    }
    let half = f64::from(AUTO_FOV_DEG).to_radians() * 0.5;
    let dist = f64::from(AUTO_MARGIN) * r / half.sin();
    let elev = f64::from(AUTO_ELEVATION_DEG).to_radians();
    let back = DVec3::new(0.0, elev.sin(), elev.cos());
    let from = centre + back * dist;
    // The camera's basis, as the eye-ray generator builds it.
    let forward = -back;
    let right = forward.cross(DVec3::Y).normalize();
    let up = right.cross(forward);
    let light = from + (up - right) * (f64::from(AUTO_LIGHT_OFFSET) * dist);
    let (from, at, light) = (from.as_vec3(), centre.as_vec3(), light.as_vec3());
    if !(from.is_finite() && light.is_finite()) || from == at {
        return None;
    }
    let camera = Camera {
        from,
        at,
        up: Vec3::Y,
        angle_deg: AUTO_FOV_DEG,
        hither: 0.0,
        width: AUTO_RESOLUTION,
        height: AUTO_RESOLUTION,
    };
    Some((camera, Light::point(light, Vec3::ONE)))
}
