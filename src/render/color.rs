//! Colour encoding: the sRGB transfer curves and the conversion of a film's linear
//! radiance to 8-bit RGB, shared by the image writers, the radiosity mesh export and
//! the image metrics.

use super::Film;

/// How linear values become 8-bit values.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Encoding {
    /// Linear values through the sRGB transfer curve (what image viewers expect).
    #[default]
    Srgb,
    /// Values written as they are, clamped to [0, 1] (the classic NFF renderers' way).
    Linear,
}

/// The sRGB transfer function (IEC 61966-2-1) for a linear value in [0, 1].
#[inline]
pub fn srgb_encode(v: f32) -> f32 {
    if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// The sRGB decoding curve (IEC 61966-2-1) for a value in [0, 1].
#[inline]
pub fn srgb_decode(v: f32) -> f32 {
    if v <= 0.040_45 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

/// 8-bit RGB bytes of `film`, clamped to [0, 1] (NaN as 0) and encoded.
pub fn to_rgb8(film: &Film, encoding: Encoding) -> Vec<u8> {
    let mut out = Vec::with_capacity(film.pixels.len() * 3);
    for p in &film.pixels {
        for c in p.to_array() {
            let c = if c.is_nan() { 0.0 } else { c.clamp(0.0, 1.0) };
            let e = match encoding {
                Encoding::Srgb => srgb_encode(c),
                Encoding::Linear => c,
            };
            out.push((e * 255.0 + 0.5) as u8);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn srgb_curve_endpoints_and_midpoint() {
        assert_eq!(srgb_encode(0.0), 0.0);
        assert!((srgb_encode(1.0) - 1.0).abs() < 1e-6);
        // 18% grey encodes to about 46%.
        assert!((srgb_encode(0.18) - 0.4613).abs() < 1e-3);
    }

    #[test]
    fn srgb_decode_inverts_encode() {
        assert_eq!(srgb_decode(0.0), 0.0);
        assert!((srgb_decode(1.0) - 1.0).abs() < 1e-6);
        for k in 0..=100 {
            let v = k as f32 / 100.0;
            assert!((srgb_decode(srgb_encode(v)) - v).abs() < 1e-5, "{v}");
        }
    }

    #[test]
    fn rgb8_clamps_and_encodes() {
        let mut f = Film::new(2, 1);
        f.set(0, 0, Vec3::new(-1.0, 0.5, 2.0));
        f.set(1, 0, Vec3::new(f32::NAN, 0.0, 1.0));
        assert_eq!(to_rgb8(&f, Encoding::Linear), vec![0, 128, 255, 0, 0, 255]);
        assert_eq!(to_rgb8(&f, Encoding::Srgb)[1], 188);
    }
}
