//! Image output: PNG (sRGB-encoded by default) and OpenEXR (linear f32), chosen by the
//! file extension, always written to a temporary file beside the target and renamed,
//! so a failed or interrupted write never leaves a truncated image, and
//! [`abandon_writes`] removes the temporary files of the writes in progress for a
//! process about to end. Besides the colour: the output variables' EXR channels
//! (`aov`, `channels`) and the cost heat maps (`heatmap`), drawn with the colour
//! maps of `colormap`.

pub(crate) mod aov;
mod atomic;
pub(crate) mod channels;
pub(crate) mod colormap;
mod font;
pub(crate) mod heatmap;
pub(crate) mod part;
mod pending;

pub(crate) use atomic::write_atomic;
pub use atomic::{create_folder, prepare, prepare_append, remove_stale_temps};
pub use part::{PartInfo, read_exr};
pub use pending::abandon_writes;

// The PNG writer's encodings, defined with the colour curves in `render`.
use crate::render::Film;
pub use crate::render::color::Encoding;
use crate::render::color::to_rgb8;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

/// Output file formats.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// 8-bit RGB PNG.
    Png,
    /// 32-bit float RGB OpenEXR.
    Exr,
}

/// Output failures; each names the file.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    /// The extension is neither `.png` nor `.exr`.
    #[error("{0}: unsupported output format (use a .png or .exr file name)")]
    Format(PathBuf),
    /// Writing failed.
    #[error("{path}: cannot write: {message}")]
    Write {
        /// Target file.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
}

impl Format {
    /// The format for a file name, by extension (case-insensitive).
    pub fn from_path(path: &Path) -> Result<Format, OutputError> {
        match path
            .extension()
            .and_then(|e| e.to_str())
            .map(|e| e.to_ascii_lowercase())
            .as_deref()
        {
            Some("png") => Ok(Format::Png),
            Some("exr") => Ok(Format::Exr),
            _ => Err(OutputError::Format(path.to_path_buf())),
        }
    }
}

/// How many pixels differ between two films of the same size once encoded as 8-bit
/// sRGB (what a viewer of the PNGs would see).
pub fn differing_pixels(a: &Film, b: &Film) -> usize {
    assert_eq!(
        (a.width, a.height),
        (b.width, b.height),
        "films of different sizes"
    );
    let (pa, pb) = (to_rgb8(a, Encoding::Srgb), to_rgb8(b, Encoding::Srgb));
    pa.chunks(3)
        .zip(pb.chunks(3))
        .filter(|(x, y)| x != y)
        .count()
}

/// Write `film` to `path` (format by extension) through a temporary file and a rename.
pub fn write_image(path: &Path, film: &Film, encoding: Encoding) -> Result<(), OutputError> {
    match Format::from_path(path)? {
        Format::Png => write_png_rgb8(path, film.width, film.height, &to_rgb8(film, encoding)),
        Format::Exr => part::write_exr(path, film, None),
    }
}

/// Write `width × height` RGB bytes as a PNG through a temporary file and a rename.
pub fn write_png_rgb8(path: &Path, width: u32, height: u32, rgb: &[u8]) -> Result<(), OutputError> {
    write_atomic(path, |file| {
        let mut w = BufWriter::new(file);
        let enc = image::codecs::png::PngEncoder::new(&mut w);
        image::ImageEncoder::write_image(enc, rgb, width, height, image::ExtendedColorType::Rgb8)
            .map_err(|e| e.to_string())?;
        let file = w.into_inner().map_err(|e| e.into_error().to_string())?;
        file.sync_all().map_err(|e| e.to_string())
    })
}

/// Write a text file through a temporary file and a rename.
pub fn write_text(path: &Path, text: &str) -> Result<(), OutputError> {
    write_atomic(path, |mut f| {
        f.write_all(text.as_bytes()).map_err(|e| e.to_string())
    })
}

/// Append `value` as one JSON line to `path` (the statistics log: one record per
/// render), creating the file and its folder if missing.
pub fn append_json_line(path: &Path, value: &impl serde::Serialize) -> Result<(), OutputError> {
    let err = |e: std::io::Error| OutputError::Write {
        path: path.to_path_buf(),
        message: e.to_string(),
    };
    let line = match serde_json::to_string(value) {
        Ok(l) => l,
        Err(e) => unreachable!("a report serialises: {e}"),
    };
    create_folder(path)?;
    let mut f = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(path)
        .map_err(err)?;
    writeln!(f, "{line}").map_err(err)
}

/// Whether `path` holds a whole image that decodes (what a resumed batch trusts).
pub fn is_complete_image(path: &Path) -> bool {
    match Format::from_path(path) {
        Ok(Format::Png) => image::open(path).is_ok(),
        Ok(Format::Exr) => part::read_exr(path).is_ok(),
        Err(_) => false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn png_and_exr_round_trip() {
        let dir = tempfile::tempdir().unwrap();
        let mut f = Film::new(3, 2);
        f.set(2, 1, Vec3::new(0.25, 0.5, 1.5));
        let png = dir.path().join("a.png");
        write_image(&png, &f, Encoding::Linear).unwrap();
        let img = image::open(&png).unwrap().to_rgb8();
        assert_eq!(img.dimensions(), (3, 2));
        assert_eq!(img.get_pixel(2, 1).0, [64, 128, 255]);
        let exr_path = dir.path().join("a.exr");
        write_image(&exr_path, &f, Encoding::Srgb).unwrap();
        let read = exr::prelude::read_first_rgba_layer_from_file(
            &exr_path,
            |res, _| vec![[0f32; 3]; res.width() * res.height()],
            |buf, pos, (r, g, b, _a): (f32, f32, f32, f32)| buf[pos.y() * 3 + pos.x()] = [r, g, b],
        )
        .unwrap();
        assert_eq!(read.layer_data.channel_data.pixels[5], [0.25, 0.5, 1.5]);
        // Only the two images: no temporary files left behind.
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 2);
    }

    #[test]
    fn unknown_extension_is_refused_and_writes_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a.jpg");
        let e = write_image(&p, &Film::new(1, 1), Encoding::Srgb).unwrap_err();
        assert!(e.to_string().contains("unsupported output format"));
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    }
}
