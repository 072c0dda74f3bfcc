//! OpenEXR files that hold a part of an image: the data window is the part, the display
//! window the whole image, and a text attribute `emray_hash` names the scene and
//! settings it was rendered from, so that `emray merge` can check the parts belong
//! together.

use super::{OutputError, write_atomic};
use crate::render::{Film, Region};
use exr::prelude::{
    AttributeValue, Image, ImageAttributes, IntegerBounds, Layer, LayerAttributes, ReadChannels,
    ReadLayers, SpecificChannels, Text, Vec2, WritableImage, read,
};
use glam::Vec3;
use std::io::BufWriter;
use std::path::Path;

/// The attribute holding the scene-and-settings hash.
pub const HASH_ATTRIBUTE: &str = "emray_hash";

/// Where a part lies and what it was rendered from.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PartInfo {
    /// Size of the whole image.
    pub full: (u32, u32),
    /// The pixels the part holds.
    pub region: Region,
    /// Scene-and-settings hash, if the file has one.
    pub hash: Option<String>,
}

/// Write `film` as a linear f32 RGB EXR. With `part`, `film` is `part.region` of a
/// `part.full` image: the data window says so and the hash is stored.
pub fn write_exr(path: &Path, film: &Film, part: Option<&PartInfo>) -> Result<(), OutputError> {
    let w = film.width as usize;
    let (full, origin) = placement(film, part);
    let px = &film.pixels;
    let channels = SpecificChannels::rgb(|p: Vec2<usize>| {
        let v = px[p.y() * w + p.x()];
        (v.x, v.y, v.z)
    });
    let layer = Layer::new(
        (w, film.height as usize),
        layer_attributes(path, origin, part)?,
        encoding(),
        channels,
    );
    write_image(
        path,
        &Image::new(
            ImageAttributes::new(IntegerBounds::new((0, 0), full)),
            layer,
        ),
    )
}

/// The whole image's size and where `film` lies in it: the part's, or the film's own.
pub(super) fn placement(film: &Film, part: Option<&PartInfo>) -> ((usize, usize), (i32, i32)) {
    match part {
        Some(p) => (
            (p.full.0 as usize, p.full.1 as usize),
            (p.region.x0 as i32, p.region.y0 as i32),
        ),
        None => ((film.width as usize, film.height as usize), (0, 0)),
    }
}

/// A layer's attributes: its position in the whole image and the part's hash.
pub(super) fn layer_attributes(
    path: &Path,
    origin: (i32, i32),
    part: Option<&PartInfo>,
) -> Result<LayerAttributes, OutputError> {
    let mut attributes = LayerAttributes {
        layer_position: Vec2(origin.0, origin.1),
        ..LayerAttributes::default()
    };
    if let Some(hash) = part.and_then(|p| p.hash.as_deref()) {
        let text = Text::new_or_none(hash).ok_or_else(|| OutputError::Write {
            path: path.to_path_buf(),
            message: "the part hash is not plain text".into(),
        })?;
        attributes
            .other
            .insert(Text::from(HASH_ATTRIBUTE), AttributeValue::Text(text));
    }
    Ok(attributes)
}

/// Lossless compression with blocks in increasing order: compressed in parallel, they
/// are still written in one order, so the same image always gives the same bytes.
pub(super) fn encoding() -> exr::image::Encoding {
    exr::image::Encoding {
        line_order: exr::meta::attribute::LineOrder::Increasing,
        ..exr::image::Encoding::FAST_LOSSLESS
    }
}

/// Write `image` to `path` atomically (a temporary file, then a rename).
pub(super) fn write_image<'i, L>(path: &Path, image: &'i Image<L>) -> Result<(), OutputError>
where
    L: exr::image::write::layers::WritableLayers<'i>,
{
    write_atomic(path, |file| {
        let mut bw = BufWriter::new(file);
        image
            .write()
            .to_buffered(&mut bw)
            .map_err(|e| e.to_string())?;
        let file = bw.into_inner().map_err(|e| e.into_error().to_string())?;
        file.sync_all().map_err(|e| e.to_string())
    })
}

/// Read an RGB EXR: its pixels (the data window) and where they lie.
pub fn read_exr(path: &Path) -> Result<(Film, PartInfo), String> {
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .rgb_channels(
            |size, _| Film::new(size.x() as u32, size.y() as u32),
            |film: &mut Film, pos, (r, g, b): (f32, f32, f32)| {
                film.set(pos.x() as u32, pos.y() as u32, Vec3::new(r, g, b))
            },
        )
        .first_valid_layer()
        .all_attributes()
        .from_file(path)
        .map_err(|e| format!("{}: not a readable RGB EXR: {e}", path.display()))?;
    let layer = image.layer_data;
    let film = layer.channel_data.pixels;
    let size = (film.width as usize, film.height as usize);
    let info = part_info(path, &image.attributes, &layer.attributes, size)?;
    Ok((film, info))
}

/// Where a layer of `size` pixels lies in its image (display window), and its hash.
pub(crate) fn part_info(
    path: &Path,
    image: &ImageAttributes,
    layer: &LayerAttributes,
    size: (usize, usize),
) -> Result<PartInfo, String> {
    let display = image.display_window;
    let pos = layer.layer_position;
    let (dx, dy) = (display.position.x(), display.position.y());
    let (fw, fh) = (display.size.x(), display.size.y());
    let (x0, y0) = (pos.x() - dx, pos.y() - dy);
    let fits = x0 >= 0
        && y0 >= 0
        && x0 as u64 + size.0 as u64 <= fw as u64
        && y0 as u64 + size.1 as u64 <= fh as u64;
    if !fits || fw > u32::MAX as usize || fh > u32::MAX as usize {
        return Err(format!(
            "{}: the data window lies outside the display window",
            path.display()
        ));
    }
    let region = Region {
        x0: x0 as u32,
        x1: x0 as u32 + size.0 as u32,
        y0: y0 as u32,
        y1: y0 as u32 + size.1 as u32,
    };
    let hash = match layer.other.get(&Text::from(HASH_ATTRIBUTE)) {
        Some(AttributeValue::Text(t)) => Some(t.to_string()),
        _ => None,
    };
    Ok(PartInfo {
        full: (fw as u32, fh as u32),
        region,
        hash,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_same_film_always_gives_the_same_exr_bytes() {
        // Enough rows for many blocks, compressed in parallel.
        let (w, h) = (300, 400);
        let mut film = Film::new(w, h);
        for y in 0..h {
            for x in 0..w {
                let v = ((x * 7 + y * 13) % 97) as f32 / 97.0;
                film.set(x, y, Vec3::new(v, 1.0 - v, v * v));
            }
        }
        let dir = tempfile::tempdir().unwrap();
        let bytes: Vec<Vec<u8>> = (0..6)
            .map(|i| {
                let path = dir.path().join(format!("{i}.exr"));
                write_exr(&path, &film, None).unwrap();
                std::fs::read(&path).unwrap()
            })
            .collect();
        assert!(
            bytes.iter().all(|b| *b == bytes[0]),
            "EXR bytes differ between writes"
        );
        let (back, info) = read_exr(&dir.path().join("0.exr")).unwrap();
        assert_eq!(back.pixels, film.pixels);
        assert_eq!(info.full, (w, h));
    }
}
