//! EXR files with channels besides the colour (the output variables of `--aov`):
//! written with every channel in one layer, in the name order EXR requires, and read
//! back whole, so that `emray merge` can stitch every channel of the parts.

use super::OutputError;
use super::part::{PartInfo, encoding, layer_attributes, placement, write_image};
use crate::render::Film;
use exr::prelude::{
    AnyChannel, AnyChannels, FlatSamples, Image, ImageAttributes, IntegerBounds, Layer,
    ReadChannels, ReadLayers, read,
};
use glam::Vec3;
use smallvec::SmallVec;
use std::path::Path;

/// The samples of one channel, row-major over the data window.
#[derive(Clone, Debug, PartialEq)]
pub enum Samples {
    /// 32-bit floats.
    F32(Vec<f32>),
    /// 32-bit unsigned integers (ids).
    U32(Vec<u32>),
}

impl Samples {
    /// The number of samples.
    pub fn len(&self) -> usize {
        match self {
            Samples::F32(v) => v.len(),
            Samples::U32(v) => v.len(),
        }
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The EXR type's name (`float`, `uint`), for messages.
    pub fn type_name(&self) -> &'static str {
        match self {
            Samples::F32(_) => "float",
            Samples::U32(_) => "uint",
        }
    }

    /// Empty samples of the same type, for `n` values.
    pub fn like(&self, n: usize) -> Samples {
        match self {
            Samples::F32(_) => Samples::F32(vec![0.0; n]),
            Samples::U32(_) => Samples::U32(vec![0; n]),
        }
    }

    /// Copy sample `from` of `src` (of the same type) to sample `to`.
    pub fn copy_from(&mut self, to: usize, src: &Samples, from: usize) {
        match (self, src) {
            (Samples::F32(d), Samples::F32(s)) => d[to] = s[from],
            (Samples::U32(d), Samples::U32(s)) => d[to] = s[from],
            _ => {}
        }
    }
}

/// A channel besides `R`, `G` and `B`.
#[derive(Clone, Debug, PartialEq)]
pub struct Channel {
    /// Its name (`Z`, `N.X`, `id`, ...).
    pub name: String,
    /// Its samples.
    pub samples: Samples,
}

impl Channel {
    /// A float channel.
    pub fn f32(name: &str, samples: Vec<f32>) -> Self {
        Channel {
            name: name.to_string(),
            samples: Samples::F32(samples),
        }
    }
}

/// Write `film` and `extra` (as many samples each as the film has pixels) as one EXR
/// layer, a part of an image when `part` says so (as [`super::part::write_exr`]).
pub fn write_exr_channels(
    path: &Path,
    film: &Film,
    extra: &[Channel],
    part: Option<&PartInfo>,
) -> Result<(), OutputError> {
    let (full, origin) = placement(film, part);
    let rgb = |f: fn(&Vec3) -> f32| FlatSamples::F32(film.pixels.iter().map(f).collect());
    let mut list: SmallVec<[AnyChannel<FlatSamples>; 4]> = SmallVec::new();
    list.push(AnyChannel::new("R", rgb(|v| v.x)));
    list.push(AnyChannel::new("G", rgb(|v| v.y)));
    list.push(AnyChannel::new("B", rgb(|v| v.z)));
    for c in extra {
        let samples = match &c.samples {
            Samples::F32(v) => FlatSamples::F32(v.clone()),
            Samples::U32(v) => FlatSamples::U32(v.clone()),
        };
        list.push(AnyChannel::new(c.name.as_str(), samples));
    }
    let layer = Layer::new(
        (film.width as usize, film.height as usize),
        layer_attributes(path, origin, part)?,
        encoding(),
        AnyChannels::sort(list),
    );
    write_image(
        path,
        &Image::new(
            ImageAttributes::new(IntegerBounds::new((0, 0), full)),
            layer,
        ),
    )
}

/// Read an EXR's first layer whole: its colour, its other channels (in name order) and
/// where its pixels lie.
pub fn read_exr_channels(path: &Path) -> Result<(Film, Vec<Channel>, PartInfo), String> {
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_file(path)
        .map_err(|e| format!("{}: not a readable EXR: {e}", path.display()))?;
    let layer = &image.layer_data;
    let (w, h) = (layer.size.x(), layer.size.y());
    let mut film = Film::new(w as u32, h as u32);
    let mut extra = Vec::new();
    let mut found = 0;
    for c in &layer.channel_data.list {
        let name = c.name.to_string();
        let k = match name.as_str() {
            "R" => 0,
            "G" => 1,
            "B" => 2,
            _ => {
                let samples = match &c.sample_data {
                    FlatSamples::U32(v) => Samples::U32(v.clone()),
                    other => Samples::F32(other.values_as_f32().collect()),
                };
                extra.push(Channel { name, samples });
                continue;
            }
        };
        found += 1;
        for (p, v) in film.pixels.iter_mut().zip(c.sample_data.values_as_f32()) {
            p[k] = v;
        }
    }
    if found != 3 {
        return Err(format!("{}: not an RGB EXR", path.display()));
    }
    let info = super::part::part_info(path, &image.attributes, &layer.attributes, (w, h))?;
    Ok((film, extra, info))
}
