//! The difference of two renders of one image (Embree's and the BVH's), as the PNGs
//! show them: each pixel's channels encoded to 8 bits as the render writes them, the
//! absolute difference amplified into an image, the pixels that differ counted (as
//! [`emray::output::differing_pixels`] counts them) and the largest difference.

use emray::output::Encoding;
use emray::render::Film;
use emray::render::color::to_rgb8;
use serde::Serialize;

/// What a difference of 8-bit levels is multiplied by in the image.
pub const GAIN: u8 = 32;

/// Two renders compared.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Difference {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Pixels where any channel differs.
    pub differing: usize,
    /// The largest difference of a channel, in 8-bit levels.
    pub max: u8,
    /// What a level of difference is multiplied by in [`Difference::rgb`].
    pub gain: u8,
    /// The image: each channel's difference times the gain (at most 255), RGB bytes.
    #[serde(skip)]
    pub rgb: Vec<u8>,
}

/// `a` against `b`, both encoded with `encoding`; an error for films of different sizes.
pub fn of(a: &Film, b: &Film, encoding: Encoding) -> Result<Difference, String> {
    if (a.width, a.height) != (b.width, b.height) {
        return Err(format!(
            "the renders to compare are {}x{} and {}x{}",
            a.width, a.height, b.width, b.height
        ));
    }
    let (pa, pb) = (to_rgb8(a, encoding), to_rgb8(b, encoding));
    let mut rgb = Vec::with_capacity(pa.len());
    let (mut differing, mut max) = (0, 0);
    for (x, y) in pa.chunks_exact(3).zip(pb.chunks_exact(3)) {
        let d: Vec<u8> = x.iter().zip(y).map(|(p, q)| p.abs_diff(*q)).collect();
        differing += usize::from(d.iter().any(|&c| c > 0));
        max = d.iter().fold(max, |m, &c| m.max(c));
        rgb.extend(d.iter().map(|&c| c.saturating_mul(GAIN)));
    }
    Ok(Difference {
        width: a.width,
        height: a.height,
        differing,
        max,
        gain: GAIN,
        rgb,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use emray::math::Vec3;

    fn film(values: &[f32]) -> Film {
        Film {
            width: values.len() as u32,
            height: 1,
            pixels: values.iter().map(|&v| Vec3::splat(v)).collect(),
        }
    }

    #[test]
    fn counts_as_the_library_does_and_amplifies() {
        let a = film(&[0.0, 0.5, 1.0, 0.25]);
        let b = film(&[0.0, 0.5001, 0.9, 0.25]);
        let d = of(&a, &b, Encoding::Srgb).unwrap();
        assert_eq!(d.differing, emray::output::differing_pixels(&a, &b));
        assert_eq!(d.differing, 1, "0.5 and 0.5001 encode alike");
        assert!(d.max > 0);
        assert_eq!(d.rgb.len(), 4 * 3);
        assert_eq!(d.rgb[6], d.max.saturating_mul(GAIN));
        assert!(d.rgb[..6].iter().chain(&d.rgb[9..]).all(|&c| c == 0));
        assert_eq!(of(&a, &a, Encoding::Srgb).unwrap().differing, 0);
        assert!(of(&a, &film(&[0.0]), Encoding::Srgb).is_err());
    }
}
