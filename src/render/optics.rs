//! The two directions a Whitted ray tree branches into at a surface: the mirror
//! reflection and Snell's refraction.

use crate::math::Vec3;

/// Mirror `d` about the unit normal `n`.
#[inline]
pub(super) fn reflect(d: Vec3, n: Vec3) -> Vec3 {
    d - n * (2.0 * d.dot(n))
}

/// Snell's law: the refracted direction of unit `d` through a surface with unit normal
/// `n` facing the incoming ray, for `eta = n₁/n₂`; `None` on total internal reflection.
///
/// For any `eta` between 10⁻⁶ and 10⁶ (the ratio of two indices of
/// [`range::IOR_RANGE`](crate::scene::range::IOR_RANGE), which every transmitting
/// material's index lies in) the result is a finite unit vector: `eta²` stays far inside
/// f32 and the refracted direction has length `eta`-ish before it is normalised. Inputs
/// that are not finite give `None`, never a NaN direction.
#[inline]
pub(super) fn refract(d: Vec3, n: Vec3, eta: f32) -> Option<Vec3> {
    let cos_i = (-d).dot(n).min(1.0);
    let k = 1.0 - eta * eta * (1.0 - cos_i * cos_i);
    // A NaN `k` (from non-finite inputs) is no refraction either.
    if k < 0.0 || k.is_nan() {
        return None;
    }
    let t = (d * eta + n * (eta * cos_i - k.sqrt())).normalize();
    t.is_finite().then_some(t)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reflect_mirrors_about_the_normal() {
        let r = reflect(Vec3::new(1.0, -1.0, 0.0), Vec3::Y);
        assert_eq!(r, Vec3::new(1.0, 1.0, 0.0));
    }

    /// Any pair of indices a material may have, at any angle: a finite unit direction
    /// or total internal reflection, never NaN; and garbage in gives `None`.
    #[test]
    fn refraction_is_finite_over_the_whole_index_range() {
        let (lo, hi) = (
            *crate::scene::range::IOR_RANGE.start(),
            *crate::scene::range::IOR_RANGE.end(),
        );
        let iors = [lo, 0.01, 0.5, 1.0, 1.5, 2.4, 100.0, hi];
        let mut refracted = 0;
        for k in 0..=200 {
            let th = (k as f32 / 200.0) * std::f32::consts::FRAC_PI_2;
            let d = Vec3::new(th.sin(), 0.3 * th.cos(), -th.cos()).normalize();
            for n1 in iors {
                for n2 in iors {
                    if let Some(t) = refract(d, Vec3::Z, n1 / n2) {
                        assert!(t.is_finite(), "{n1}/{n2} at {th}: {t}");
                        assert!((t.length() - 1.0).abs() < 1e-5, "{n1}/{n2}: {t}");
                        assert!(t.z <= 0.0, "goes through: {t}");
                        refracted += 1;
                    }
                }
            }
        }
        assert!(refracted > 1000, "{refracted}");
        for eta in [f32::NAN, f32::INFINITY, 1e30] {
            assert_eq!(
                refract(Vec3::NEG_Z * 0.99 + Vec3::X * 0.14, Vec3::Z, eta),
                None
            );
        }
        assert_eq!(refract(Vec3::splat(f32::NAN), Vec3::Z, 1.5), None);
    }

    #[test]
    fn refraction_obeys_snell_and_total_internal_reflection() {
        let n = Vec3::Z;
        for deg in [0.0f32, 10.0, 30.0, 45.0, 60.0, 80.0] {
            let th = deg.to_radians();
            let d = Vec3::new(th.sin(), 0.0, -th.cos());
            // Air to glass: sin θt = sin θi / 1.5.
            let t = refract(d, n, 1.0 / 1.5).unwrap();
            let sin_t = t.x;
            assert!((sin_t - th.sin() / 1.5).abs() < 1e-6, "{deg}°");
            assert!(t.z < 0.0, "goes through");
            // Glass to air: TIR beyond the critical angle asin(1/1.5) = 41.8°.
            let out = refract(d, n, 1.5);
            assert_eq!(out.is_none(), deg > 41.81, "{deg}°");
            if let Some(o) = out {
                assert!((o.x - th.sin() * 1.5).abs() < 1e-5);
            }
        }
    }
}
