//! A linear RGB f32 image.

use glam::Vec3;
use rayon::prelude::*;

/// Linear RGB pixels, row-major from the top-left.
#[derive(Clone, Debug, PartialEq)]
pub struct Film {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Pixel values.
    pub pixels: Vec<Vec3>,
}

impl Film {
    /// A black film, zeroed by the threads of the current rayon pool: a large film's
    /// memory is first touched here, and one thread faulting its pages in while the
    /// others wait was a serial stretch of a short render.
    pub fn new(width: u32, height: u32) -> Self {
        let n = width as usize * height as usize;
        let mut pixels = Vec::with_capacity(n);
        pixels.par_extend(rayon::iter::repeat_n(Vec3::ZERO, n));
        Film {
            width,
            height,
            pixels,
        }
    }

    /// Pixel `(i, j)`.
    #[inline]
    pub fn get(&self, i: u32, j: u32) -> Vec3 {
        self.pixels[(j * self.width + i) as usize]
    }

    /// Set pixel `(i, j)`.
    #[inline]
    pub fn set(&mut self, i: u32, j: u32, v: Vec3) {
        self.pixels[(j * self.width + i) as usize] = v;
    }

    /// The `(w−1) × (h−1)` film whose pixels are the means of this film's 2×2 blocks of
    /// neighbouring samples (SPD corner-ray mode), computed in parallel straight into
    /// the new film.
    pub fn average_corners(&self) -> Film {
        let (w, h) = (self.width - 1, self.height - 1);
        let (cols, stride) = (w as usize, self.width as usize);
        let pixels = (0..cols * h as usize)
            .into_par_iter()
            .map(|k| {
                let top = k / cols * stride + k % cols;
                let bottom = top + stride;
                let p = &self.pixels;
                corner_mean([p[top], p[top + 1], p[bottom], p[bottom + 1]])
            })
            .collect();
        Film {
            width: w,
            height: h,
            pixels,
        }
    }
}

/// The value of an SPD-mode pixel from its corners (top-left, top-right, bottom-left,
/// bottom-right), summed in that order.
#[inline(always)]
pub fn corner_mean(k: [Vec3; 4]) -> Vec3 {
    (k[0] + k[1] + k[2] + k[3]) * 0.25
}
