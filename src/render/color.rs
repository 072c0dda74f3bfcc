//! Colour encoding: the sRGB transfer curves and the conversion of a film's linear
//! radiance to 8-bit RGB, shared by the image writers, the radiosity mesh export and
//! the image metrics.

use super::Film;

/// How linear values become 8-bit values.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
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
    match encoding {
        Encoding::Srgb => {
            let steps = srgb8_steps();
            encode(film, |c| steps.code(c))
        }
        Encoding::Linear => encode(film, |c| code_of(clamp01(c))),
    }
}

/// The film's channels through `code`, as RGB bytes.
#[inline]
fn encode(film: &Film, code: impl Fn(f32) -> u8) -> Vec<u8> {
    let mut out = vec![0u8; film.pixels.len() * 3];
    for (rgb, p) in out.chunks_exact_mut(3).zip(&film.pixels) {
        rgb[0] = code(p.x);
        rgb[1] = code(p.y);
        rgb[2] = code(p.z);
    }
    out
}

/// `c` clamped to [0, 1], NaN as 0.
#[inline]
fn clamp01(c: f32) -> f32 {
    if c.is_nan() { 0.0 } else { c.clamp(0.0, 1.0) }
}

/// The 8-bit code of an encoded value in [0, 1], rounded to nearest.
#[inline]
fn code_of(e: f32) -> u8 {
    (e * 255.0 + 0.5) as u8
}

/// The 8-bit sRGB code of a linear value, exactly `code_of(srgb_encode(clamp01(c)))`.
pub fn srgb8(c: f32) -> u8 {
    srgb8_steps().code(c)
}

/// Where the 8-bit sRGB code steps up: `at[k]` is the least linear value whose code is
/// `k + 1`. Encoding then needs eight comparisons instead of a `powf`, and gives the
/// formula's codes exactly, as the formula's codes never decrease as the value grows
/// (checked for every f32 in [0, 1] by the tests' exhaustive run).
struct Srgb8Steps {
    at: [f32; 255],
    /// The code at the low end of each of [`BUCKETS`] equal parts of [0, 1]: where the
    /// search for a value's code starts (a step or two below it at most).
    start: [u8; BUCKETS],
}

/// How many equal parts [`Srgb8Steps::start`] cuts [0, 1] into.
const BUCKETS: usize = 4096;

impl Srgb8Steps {
    fn new() -> Self {
        let code = |c: f32| code_of(srgb_encode(c));
        let mut at = [0.0f32; 255];
        for (k, t) in at.iter_mut().enumerate() {
            // Bisection over the bit patterns of [0, 1], ordered as the values are.
            let (mut lo, mut hi) = (0u32, 1.0f32.to_bits());
            while lo < hi {
                let mid = lo + (hi - lo) / 2;
                if code(f32::from_bits(mid)) as usize > k {
                    hi = mid;
                } else {
                    lo = mid + 1;
                }
            }
            *t = f32::from_bits(lo);
        }
        let mut start = [0u8; BUCKETS];
        for (i, s) in start.iter_mut().enumerate() {
            let low = i as f32 / BUCKETS as f32;
            *s = at.partition_point(|&t| t <= low) as u8;
        }
        Srgb8Steps { at, start }
    }

    #[inline]
    fn code(&self, c: f32) -> u8 {
        let c = clamp01(c);
        // The bucket's low end is at most c, so its code is at most c's: step up.
        let bucket = ((c * BUCKETS as f32) as usize).min(BUCKETS - 1);
        let mut k = self.start[bucket] as usize;
        while k < self.at.len() && self.at[k] <= c {
            k += 1;
        }
        k as u8
    }
}

fn srgb8_steps() -> &'static Srgb8Steps {
    static STEPS: std::sync::OnceLock<Srgb8Steps> = std::sync::OnceLock::new();
    STEPS.get_or_init(Srgb8Steps::new)
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

    /// The stepped encoding gives the formula's code for the values around every step
    /// (a thousand f32 either side), a dense sweep and the special values.
    #[test]
    fn srgb8_is_the_formula() {
        let formula = |c: f32| code_of(srgb_encode(clamp01(c)));
        let steps = srgb8_steps();
        let check = |c: f32| assert_eq!(srgb8(c), formula(c), "{c:e}");
        for &t in &steps.at {
            let b = t.to_bits();
            for d in 0..1000u32 {
                check(f32::from_bits(b.saturating_sub(d)));
                check(f32::from_bits(b + d));
            }
        }
        for k in 0..=100_000 {
            check(k as f32 / 100_000.0);
        }
        for c in [
            -1.0,
            0.0,
            1.0,
            2.0,
            f32::NAN,
            f32::INFINITY,
            -f32::INFINITY,
            1e-40,
        ] {
            check(c);
        }
    }

    /// Every f32 in [0, 1]: the codes of the formula never decrease, so the steps give
    /// them exactly. About a billion values: run by hand in release mode,
    /// `cargo test --release --lib srgb8_codes_never_decrease -- --ignored`.
    #[test]
    #[ignore = "exhaustive: a billion powf calls"]
    fn srgb8_codes_never_decrease() {
        let mut last = 0u8;
        for b in 0..=1.0f32.to_bits() {
            let c = code_of(srgb_encode(f32::from_bits(b)));
            assert!(c >= last, "{:e}", f32::from_bits(b));
            last = c;
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
