//! Perceptual colour maps for pictures of numbers rather than of scenes: the error heat
//! map of `emray compare --diff` and the cost heat maps of `emray render --heatmap`
//! share this one.

use glam::Vec3;

/// The magma colour map at `x` in [0, 1] (piecewise linear through 9 of its stops),
/// as sRGB values in [0, 1]: black for 0, through purple and orange, to pale yellow
/// for 1; its brightness grows monotonically. NaN maps to 1 (the most visible).
pub fn magma(x: f32) -> Vec3 {
    const STOPS: [[f32; 3]; 9] = [
        [0.001, 0.000, 0.014],
        [0.071, 0.044, 0.209],
        [0.232, 0.059, 0.437],
        [0.390, 0.100, 0.502],
        [0.550, 0.161, 0.506],
        [0.716, 0.215, 0.475],
        [0.868, 0.288, 0.409],
        [0.967, 0.439, 0.360],
        [0.987, 0.991, 0.750],
    ];
    let x = if x.is_nan() { 1.0 } else { x.clamp(0.0, 1.0) };
    let f = x * (STOPS.len() - 1) as f32;
    let k = (f as usize).min(STOPS.len() - 2);
    let t = f - k as f32;
    Vec3::from(STOPS[k]).lerp(Vec3::from(STOPS[k + 1]), t)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn magma_is_monotone_in_brightness_and_clamps() {
        let mut last = -1.0;
        for k in 0..=20 {
            let b = magma(k as f32 / 20.0).element_sum();
            assert!(b > last, "magma brightens");
            last = b;
        }
        assert_eq!(magma(-3.0), magma(0.0));
        assert_eq!(magma(7.0), magma(1.0));
        assert_eq!(magma(f32::NAN), magma(1.0));
    }
}
