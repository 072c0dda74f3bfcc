//! Cost heat maps (`emray render --heatmap`): a per-pixel quantity (rays cast, time
//! spent, deepest ray) through the magma colour map, from its smallest value in the
//! image (black) to its largest (pale yellow), with a colour bar below the picture
//! labelled with both ends and the quantity's name and unit. The same values always
//! give the same bytes.
//!
//! Time is measured, and a few pixels always take far longer than the rest (the first
//! of each thread, one whose thread the system paused): the time map's scale ends at
//! the 99th percentile, the label then reads `N+`, and the slower pixels show at the
//! top colour.

use super::colormap::magma;
use super::{OutputError, font, write_png_rgb8};
use std::path::Path;

/// What a heat map shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Quantity {
    /// Rays cast for the pixel, every kind.
    Rays,
    /// Time spent on the pixel, in nanoseconds.
    Time,
    /// The depth of the pixel's deepest ray (the eye ray is 1).
    Depth,
}

impl Quantity {
    /// The names `--heatmap` takes.
    pub const NAMES: [&'static str; 3] = ["rays", "time", "depth"];

    /// The quantity named `name`.
    pub fn from_name(name: &str) -> Option<Quantity> {
        match name {
            "rays" => Some(Quantity::Rays),
            "time" => Some(Quantity::Time),
            "depth" => Some(Quantity::Depth),
            _ => None,
        }
    }
}

/// A heat map's picture: sRGB bytes, row-major.
#[derive(Clone, Debug, PartialEq)]
pub struct Picture {
    /// Width.
    pub width: u32,
    /// Height.
    pub height: u32,
    /// RGB bytes.
    pub rgb: Vec<u8>,
}

impl Picture {
    fn new(width: u32, height: u32) -> Self {
        Picture {
            width,
            height,
            rgb: vec![0; width as usize * height as usize * 3],
        }
    }

    fn set(&mut self, x: u32, y: u32, c: [u8; 3]) {
        if x < self.width && y < self.height {
            let k = (y as usize * self.width as usize + x as usize) * 3;
            self.rgb[k..k + 3].copy_from_slice(&c);
        }
    }
}

/// A magma colour as bytes.
fn colour(t: f32) -> [u8; 3] {
    magma(t)
        .to_array()
        .map(|c| (c.clamp(0.0, 1.0) * 255.0).round() as u8)
}

/// The value as the bar prints it: whole numbers as they are, others with three
/// significant digits.
fn label(v: f64) -> String {
    if v.fract() == 0.0 && v.abs() < 1e9 {
        return format!("{v:.0}");
    }
    let digits = (2 - v.abs().log10().floor() as i32).clamp(0, 6) as usize;
    format!("{v:.digits$}")
}

/// The values in the unit the bar shows, and the bar's title.
fn scaled(q: Quantity, max: f64) -> (f64, String) {
    match q {
        Quantity::Rays => (1.0, "rays per pixel".into()),
        Quantity::Depth => (1.0, "ray tree depth".into()),
        Quantity::Time => {
            let (div, unit) = if max < 1e4 {
                (1.0, "ns")
            } else if max < 1e7 {
                (1e3, "us")
            } else {
                (1e6, "ms")
            };
            (div, format!("time per pixel ({unit})"))
        }
    }
}

/// The scale of a heat map of `values`: the smallest finite value, the value shown at
/// the top colour (the largest, or for time its 99th percentile), and whether values
/// above that top were clipped.
fn range(values: &[f32], q: Quantity) -> (f32, f32, bool) {
    let mut finite: Vec<f32> = values.iter().copied().filter(|v| v.is_finite()).collect();
    if finite.is_empty() {
        return (0.0, 0.0, false);
    }
    finite.sort_unstable_by(f32::total_cmp);
    let (lo, hi) = (finite[0], finite[finite.len() - 1]);
    if q != Quantity::Time {
        return (lo, hi, false);
    }
    let top = finite[(finite.len() - 1) * 99 / 100];
    (lo, top, top < hi)
}

/// The heat map of the `width × height` values `values` (row-major) of quantity `q`.
pub fn picture(values: &[f32], width: u32, height: u32, q: Quantity) -> Picture {
    let (lo, hi, clipped) = range(values, q);
    let span = hi - lo;
    let t = |v: f32| if span > 0.0 { (v - lo) / span } else { 0.0 };
    let (div, title) = scaled(q, hi as f64);
    let min_text = label(lo as f64 / div);
    let max_text = label(hi as f64 / div) + if clipped { "+" } else { "" };
    // Text at twice the font's size on pictures wide enough for it.
    let s = if width >= 256 { 2 } else { 1 };
    let m = 4 * s;
    let labels = font::width(&min_text) + font::width(&max_text) + 8;
    let need = (font::width(&title).max(labels)) * s + 2 * m;
    let w = width.max(need);
    let (bar_h, text_h) = (8 * s, font::GLYPH.1 * s);
    let strip = m + bar_h + 2 * s + text_h + 2 * s + text_h + m;
    let mut pic = Picture::new(w, height + strip);
    for y in 0..height {
        for x in 0..width {
            pic.set(x, y, colour(t(values[(y * width + x) as usize])));
        }
    }
    let y_bar = height + m;
    let bar_w = w - 2 * m;
    for x in 0..bar_w {
        let c = colour(x as f32 / (bar_w - 1).max(1) as f32);
        for y in y_bar..y_bar + bar_h {
            pic.set(m + x, y, c);
        }
    }
    let white = [255, 255, 255];
    let y_num = y_bar + bar_h + 2 * s;
    font::draw(&min_text, m, y_num, s, |x, y| pic.set(x, y, white));
    let x_max = w - m - font::width(&max_text) * s;
    font::draw(&max_text, x_max, y_num, s, |x, y| pic.set(x, y, white));
    let x_title = (w - font::width(&title) * s) / 2;
    font::draw(&title, x_title, y_num + text_h + 2 * s, s, |x, y| {
        pic.set(x, y, white)
    });
    pic
}

/// Write the heat map of `values` to the PNG `path`.
pub fn write_heatmap(
    path: &Path,
    values: &[f32],
    width: u32,
    height: u32,
    q: Quantity,
) -> Result<(), OutputError> {
    let pic = picture(values, width, height, q);
    write_png_rgb8(path, pic.width, pic.height, &pic.rgb)
}

/// Write the heat map of what a render's variables `aov` gathered of `q` to the PNG
/// `path`.
pub fn write_aov_heatmap(
    path: &Path,
    aov: &crate::render::aov::AovFilm,
    q: Quantity,
) -> Result<(), OutputError> {
    let values = match q {
        Quantity::Rays => &aov.rays,
        Quantity::Time => &aov.time,
        Quantity::Depth => &aov.tree_depth,
    };
    write_heatmap(path, values, aov.width, aov.height, q)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_smallest_value_is_black_the_largest_pale_and_the_bar_is_below() {
        let values: Vec<f32> = (0..64).map(|k| (k % 8) as f32).collect();
        let pic = picture(&values, 8, 8, Quantity::Rays);
        let at = |x: u32, y: u32| {
            let k = ((y * pic.width + x) * 3) as usize;
            [pic.rgb[k], pic.rgb[k + 1], pic.rgb[k + 2]]
        };
        assert_eq!(at(0, 0), colour(0.0));
        assert_eq!(at(7, 0), colour(1.0));
        assert!(pic.width > 8, "widened for the labels: {}", pic.width);
        assert!(pic.height > 8 + 20);
        // The same values always give the same picture.
        assert_eq!(pic, picture(&values, 8, 8, Quantity::Rays));
    }

    #[test]
    fn labels_and_units() {
        assert_eq!(label(12.0), "12");
        assert_eq!(label(2.25), "2.25");
        assert_eq!(label(0.123456), "0.123");
        assert_eq!(scaled(Quantity::Time, 5e5).1, "time per pixel (us)");
        assert_eq!(scaled(Quantity::Time, 5e8).0, 1e6);
        // A flat image maps to black without dividing by zero.
        let pic = picture(&[3.0; 4], 2, 2, Quantity::Depth);
        assert_eq!(&pic.rgb[..3], &colour(0.0));
        // Time's scale ends at the 99th percentile: one slow pixel in 200 is clipped.
        let mut times = vec![100.0; 200];
        times[7] = 1e6;
        times[8] = 200.0;
        assert_eq!(range(&times, Quantity::Time), (100.0, 100.0, true));
        assert_eq!(range(&times, Quantity::Rays), (100.0, 1e6, false));
    }
}
