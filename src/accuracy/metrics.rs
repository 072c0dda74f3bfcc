//! Error metrics between a test image and a reference: RMSE, PSNR, relative MSE, the
//! largest absolute error, the share of pixels whose 8-bit sRGB value differs, and
//! FLIP (NVIDIA's perceptual difference, on the 8-bit sRGB images: LDR only), plus a
//! heat-map picture of where they differ. Used by `emray compare` and `emray study`.

use crate::output::colormap::magma;
use crate::render::Film;
use crate::render::color::{Encoding, srgb_decode, to_rgb8};
use glam::Vec3;
use serde::Serialize;
use std::path::{Path, PathBuf};

/// Offset in the denominator of the relative MSE, `(v − r)² / (r + 0.01)²`, so that
/// black reference pixels do not divide by zero.
pub const REL_MSE_EPSILON: f32 = 0.01;

/// Every metric of one comparison. Values are linear (EXR as stored, PNG decoded).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Metrics {
    /// Root mean squared error over every channel of every pixel.
    pub rmse: f64,
    /// Peak signal-to-noise ratio in dB for a peak of 1: `10 log10(1 / MSE)`;
    /// infinite for identical images.
    pub psnr: f64,
    /// Mean over channels of `(v − r)² / (r + 0.01)²`.
    pub rel_mse: f64,
    /// Largest absolute difference of one channel.
    pub max_abs: f64,
    /// Share (0..1) of pixels whose 8-bit sRGB encoding differs in any channel.
    pub diff_8bit: f64,
    /// Mean FLIP error (0..1) of the 8-bit sRGB images.
    pub flip: f64,
}

/// What can go wrong reading or comparing images; every message names the file.
#[derive(Debug, thiserror::Error)]
pub enum MetricsError {
    /// The file could not be read or decoded.
    #[error("{path}: cannot read image: {message}")]
    Read {
        /// The file.
        path: PathBuf,
        /// Why.
        message: String,
    },
    /// The extension is neither `.png` nor `.exr`.
    #[error("{0}: unsupported image format (use a .png or .exr file)")]
    Format(PathBuf),
    /// The two images differ in size.
    #[error("{a}: {aw}x{ah} but {b}: {bw}x{bh}: images must have the same size")]
    Size {
        /// First file.
        a: PathBuf,
        /// Its width.
        aw: u32,
        /// Its height.
        ah: u32,
        /// Second file.
        b: PathBuf,
        /// Its width.
        bw: u32,
        /// Its height.
        bh: u32,
    },
}

/// Read a PNG (decoded to linear with `encoding`) or an EXR (its R, G and B channels,
/// linear) into a film.
pub fn read_image(path: &Path, encoding: Encoding) -> Result<Film, MetricsError> {
    let err = |m: &dyn std::fmt::Display| MetricsError::Read {
        path: path.to_path_buf(),
        message: m.to_string(),
    };
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase());
    match ext.as_deref() {
        Some("png") => {
            let file = std::fs::File::open(path).map_err(|e| err(&e))?;
            let reader = image::ImageReader::with_format(
                std::io::BufReader::new(file),
                image::ImageFormat::Png,
            );
            let img = reader.decode().map_err(|e| err(&e))?.into_rgb32f();
            let mut film = Film::new(img.width(), img.height());
            for (p, q) in film.pixels.iter_mut().zip(img.pixels()) {
                let c = Vec3::new(q[0], q[1], q[2]);
                *p = match encoding {
                    Encoding::Srgb => c.map(srgb_decode),
                    Encoding::Linear => c,
                };
            }
            Ok(film)
        }
        Some("exr") => {
            let image = exr::prelude::read_first_rgba_layer_from_file(
                path,
                |res, _| Film::new(res.width() as u32, res.height() as u32),
                |film: &mut Film, pos, (r, g, b, _a): (f32, f32, f32, f32)| {
                    film.set(pos.x() as u32, pos.y() as u32, Vec3::new(r, g, b))
                },
            )
            .map_err(|e| err(&e))?;
            Ok(image.layer_data.channel_data.pixels)
        }
        _ => Err(MetricsError::Format(path.to_path_buf())),
    }
}

/// Check that `a` and `b` (read from `pa`, `pb`) have the same size.
pub fn check_sizes(a: &Film, pa: &Path, b: &Film, pb: &Path) -> Result<(), MetricsError> {
    if (a.width, a.height) != (b.width, b.height) {
        return Err(MetricsError::Size {
            a: pa.to_path_buf(),
            aw: a.width,
            ah: a.height,
            b: pb.to_path_buf(),
            bw: b.width,
            bh: b.height,
        });
    }
    Ok(())
}

/// NaN counts as the largest error: a NaN pixel never passes a threshold.
#[inline]
fn diff(v: f32, r: f32) -> f64 {
    let d = (v as f64 - r as f64).abs();
    if d.is_nan() { f64::INFINITY } else { d }
}

/// Every metric of `test` against `reference` (same size; panics otherwise: check with
/// [`check_sizes`] first).
pub fn compare(test: &Film, reference: &Film) -> Metrics {
    assert_eq!(
        (test.width, test.height),
        (reference.width, reference.height),
        "images of different sizes"
    );
    let n = (test.pixels.len() * 3).max(1) as f64;
    let (mut se, mut rel, mut max_abs) = (0.0f64, 0.0f64, 0.0f64);
    for (v, r) in test.pixels.iter().zip(&reference.pixels) {
        for (v, r) in v.to_array().into_iter().zip(r.to_array()) {
            let d = diff(v, r);
            se += d * d;
            let den = (r as f64).abs() + REL_MSE_EPSILON as f64;
            rel += d * d / (den * den);
            max_abs = max_abs.max(d);
        }
    }
    let mse = se / n;
    let (ta, ra) = (
        to_rgb8(test, Encoding::Srgb),
        to_rgb8(reference, Encoding::Srgb),
    );
    let differing = ta
        .chunks(3)
        .zip(ra.chunks(3))
        .filter(|(x, y)| x != y)
        .count();
    Metrics {
        rmse: mse.sqrt(),
        psnr: if mse == 0.0 {
            f64::INFINITY
        } else {
            -10.0 * mse.log10()
        },
        rel_mse: rel / n,
        max_abs,
        diff_8bit: differing as f64 / test.pixels.len().max(1) as f64,
        flip: flip_map(&ta, &ra, test.width, test.height).0,
    }
}

/// FLIP of two 8-bit sRGB images: the mean error and the per-pixel error map.
fn flip_map(test: &[u8], reference: &[u8], w: u32, h: u32) -> (f64, Vec<f32>) {
    if test == reference {
        return (0.0, vec![0.0; w as usize * h as usize]);
    }
    let t = nv_flip::FlipImageRgb8::with_data(w, h, test);
    let r = nv_flip::FlipImageRgb8::with_data(w, h, reference);
    let map = nv_flip::flip(r, t, nv_flip::DEFAULT_PIXELS_PER_DEGREE);
    let pool = nv_flip::FlipPool::from_image(&map);
    (pool.mean() as f64, map.to_vec())
}

/// A heat map of where `test` differs from `reference`: the per-pixel FLIP error
/// through the magma colour map (black = no visible difference, yellow-white = the
/// largest), as a film of sRGB-decoded values ready for [`crate::output::write_image`].
pub fn heat_map(test: &Film, reference: &Film) -> Film {
    let (ta, ra) = (
        to_rgb8(test, Encoding::Srgb),
        to_rgb8(reference, Encoding::Srgb),
    );
    let (_, map) = flip_map(&ta, &ra, test.width, test.height);
    let mut out = Film::new(test.width, test.height);
    for (p, &e) in out.pixels.iter_mut().zip(&map) {
        *p = magma(e).map(srgb_decode);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::color::srgb_encode;

    fn flat(w: u32, h: u32, v: Vec3) -> Film {
        let mut f = Film::new(w, h);
        f.pixels.fill(v);
        f
    }

    #[test]
    fn identical_images_have_no_error() {
        let a = flat(8, 8, Vec3::new(0.2, 0.5, 0.9));
        let m = compare(&a, &a);
        assert_eq!(m.rmse, 0.0);
        assert_eq!(m.psnr, f64::INFINITY);
        assert_eq!(m.rel_mse, 0.0);
        assert_eq!(m.max_abs, 0.0);
        assert_eq!(m.diff_8bit, 0.0);
        assert_eq!(m.flip, 0.0);
    }

    #[test]
    fn constant_offset_gives_the_analytic_values() {
        // Every channel off by 0.1: RMSE 0.1, PSNR 20 dB, max 0.1; relative MSE
        // 0.01 / (0.5 + 0.01)^2.
        let r = flat(16, 16, Vec3::splat(0.5));
        let v = flat(16, 16, Vec3::splat(0.6));
        let m = compare(&v, &r);
        assert!((m.rmse - 0.1).abs() < 1e-6, "{}", m.rmse);
        assert!((m.psnr - 20.0).abs() < 1e-4, "{}", m.psnr);
        assert!((m.max_abs - 0.1).abs() < 1e-6);
        let rel = 0.01 / (0.51f64 * 0.51);
        assert!(
            (m.rel_mse - rel).abs() < 1e-6 * rel.max(1.0),
            "{}",
            m.rel_mse
        );
        assert_eq!(m.diff_8bit, 1.0);
        assert!(m.flip > 0.0 && m.flip < 1.0, "{}", m.flip);
    }

    #[test]
    fn one_wrong_pixel() {
        // One pixel of 100 off by 1 in one channel: MSE = 1/300.
        let r = flat(10, 10, Vec3::ZERO);
        let mut v = r.clone();
        v.set(3, 4, Vec3::new(1.0, 0.0, 0.0));
        let m = compare(&v, &r);
        assert!((m.rmse - (1.0f64 / 300.0).sqrt()).abs() < 1e-9);
        assert!((m.psnr - 10.0 * 300f64.log10()).abs() < 1e-9);
        assert_eq!(m.max_abs, 1.0);
        assert!((m.diff_8bit - 0.01).abs() < 1e-12);
        assert!((m.rel_mse - 1.0 / (0.01f64 * 0.01) / 300.0).abs() < 1e-3);
        // FLIP sees the red dot, the heat map is brightest there.
        assert!(m.flip > 0.0);
        let heat = heat_map(&v, &r);
        let peak = heat.get(3, 4).length();
        assert!(peak > heat.get(9, 0).length(), "hot where it differs");
    }

    #[test]
    fn nan_is_the_largest_error() {
        let r = flat(4, 4, Vec3::ZERO);
        let mut v = r.clone();
        v.set(0, 0, Vec3::new(f32::NAN, 0.0, 0.0));
        let m = compare(&v, &r);
        assert_eq!(m.max_abs, f64::INFINITY);
        assert_eq!(m.psnr, f64::NEG_INFINITY);
        assert!(m.rmse.is_infinite());
    }

    #[test]
    fn srgb_round_trips() {
        for k in 0..=100 {
            let v = k as f32 / 100.0;
            assert!((srgb_decode(srgb_encode(v)) - v).abs() < 1e-5, "{v}");
        }
    }

    #[test]
    fn png_and_exr_read_back() {
        let dir = tempfile::tempdir().unwrap();
        let mut f = Film::new(5, 3);
        for (k, p) in f.pixels.iter_mut().enumerate() {
            *p = Vec3::new(k as f32 / 15.0, 0.25, 2.5);
        }
        let exr = dir.path().join("a.exr");
        crate::output::write_image(&exr, &f, Encoding::Srgb).unwrap();
        assert_eq!(read_image(&exr, Encoding::Srgb).unwrap(), f);
        let png = dir.path().join("a.png");
        crate::output::write_image(&png, &f, Encoding::Srgb).unwrap();
        let back = read_image(&png, Encoding::Srgb).unwrap();
        // 8-bit quantisation, and the PNG clamps 2.5 to 1.
        for (a, b) in back.pixels.iter().zip(&f.pixels) {
            assert!((a.x - b.x).abs() < 0.01 && (a.y - b.y).abs() < 0.01);
            assert!((a.z - 1.0).abs() < 1e-6);
        }
        let bad = dir.path().join("x.jpg");
        assert!(matches!(
            read_image(&bad, Encoding::Srgb),
            Err(MetricsError::Format(_))
        ));
        let missing = dir.path().join("missing.png");
        let e = read_image(&missing, Encoding::Srgb)
            .unwrap_err()
            .to_string();
        assert!(e.contains("missing.png"), "{e}");
    }
}
