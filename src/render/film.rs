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
    /// neighbouring samples (SPD corner-ray mode), rows in parallel.
    pub fn average_corners(&self) -> Film {
        let (w, h) = (self.width - 1, self.height - 1);
        let mut out = Film::new(w, h);
        let stride = self.width as usize;
        out.pixels
            .par_chunks_mut(w.max(1) as usize)
            .enumerate()
            .for_each(|(j, row)| {
                let top = &self.pixels[j * stride..(j + 1) * stride];
                let bottom = &self.pixels[(j + 1) * stride..(j + 2) * stride];
                for (i, px) in row.iter_mut().enumerate() {
                    *px = corner_mean([top[i], top[i + 1], bottom[i], bottom[i + 1]]);
                }
            });
        out
    }
}

/// The value of an SPD-mode pixel from its corners (top-left, top-right, bottom-left,
/// bottom-right), summed in that order.
#[inline(always)]
pub fn corner_mean(k: [Vec3; 4]) -> Vec3 {
    (k[0] + k[1] + k[2] + k[3]) * 0.25
}
