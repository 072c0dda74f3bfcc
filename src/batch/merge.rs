//! Parts of one image rendered apart (`emray render --band I/N` or `--crop`) and put
//! back together: each part is an EXR whose data window is its region and which
//! carries a hash of the scene and the settings; [`merge`] checks that the parts come
//! from one render and cover the image exactly once.

use crate::output::aov::{ids_path, read_ids, write_ids};
use crate::output::channels::{Channel, read_exr_channels, write_exr_channels};
use crate::output::part::{HASH_ATTRIBUTE, PartInfo};
use crate::output::{Encoding, Format, OutputError, write_image};
use crate::render::Film;
use crate::render::aov::ids::IdEntry;
use std::path::{Path, PathBuf};

/// Why parts do not make one image.
#[derive(Debug, thiserror::Error)]
pub enum MergeError {
    /// A part could not be read.
    #[error("{0}")]
    Read(String),
    /// An EXR that is not a part (no hash).
    #[error(
        "{}: not a part (no {} attribute; render it with --band or --crop)",
        path.display(), HASH_ATTRIBUTE
    )]
    NotAPart {
        /// The file.
        path: PathBuf,
    },
    /// No part given.
    #[error("no parts to merge")]
    NoParts,
    /// A part of an image of another size than the first part's.
    #[error(
        "{}: part of a {}x{} image, but {} is of a {}x{} image",
        part.display(), full.0, full.1, first.display(), first_full.0, first_full.1
    )]
    OtherImage {
        /// The part.
        part: PathBuf,
        /// Its image's size.
        full: (u32, u32),
        /// The first part.
        first: PathBuf,
        /// The first part's image's size.
        first_full: (u32, u32),
    },
    /// A part of another render (scene, settings or backend) than the first part.
    #[error(
        "{}: rendered from another scene or other settings than {} (hash {hash} vs \
         {first_hash})",
        part.display(), first.display()
    )]
    OtherRender {
        /// The part.
        part: PathBuf,
        /// The first part.
        first: PathBuf,
        /// The part's render hash.
        hash: String,
        /// The first part's.
        first_hash: String,
    },
    /// A part with other channels (output variables) than the first part.
    #[error(
        "{}: has the channels {}, but {} has {} (render the parts with the same --aov)",
        part.display(), channels, first.display(), first_channels
    )]
    OtherChannels {
        /// The part.
        part: PathBuf,
        /// Its channels besides the colour.
        channels: String,
        /// The first part.
        first: PathBuf,
        /// The first part's.
        first_channels: String,
    },
    /// Two parts hold one pixel.
    #[error(
        "{}: pixel ({x}, {y}) is also in {}: the parts overlap",
        part.display(), other.display()
    )]
    Overlap {
        /// The later part.
        part: PathBuf,
        /// The pixel's column.
        x: u32,
        /// Its row.
        y: u32,
        /// The earlier part holding it.
        other: PathBuf,
    },
    /// Pixels no part holds.
    #[error("the parts leave {missing} pixels uncovered, the first at ({x}, {y})")]
    Uncovered {
        /// How many.
        missing: usize,
        /// The first one's column.
        x: u32,
        /// Its row.
        y: u32,
    },
}

/// The whole image stitched from its parts: the colour, the other channels (the
/// output variables the parts were rendered with, in name order), and what the ids
/// of an `id` channel stand for (from the parts' `.ids.json` files, ascending).
#[derive(Clone, Debug, PartialEq)]
pub struct Merged {
    /// The colour.
    pub film: Film,
    /// The other channels.
    pub channels: Vec<Channel>,
    /// The ids, when there is an `id` channel.
    pub ids: Option<Vec<IdEntry>>,
}

impl Merged {
    /// The files [`Merged::write`] writes to `path`: the image, and beside an EXR the
    /// ids of an `id` channel.
    pub fn files(path: &Path) -> Result<Vec<PathBuf>, OutputError> {
        let mut files = vec![path.to_path_buf()];
        if Format::from_path(path)? == Format::Exr {
            files.push(ids_path(path));
        }
        Ok(files)
    }

    /// Write the whole image to `path`: every channel of the parts to an EXR (with the
    /// `.ids.json` of an `id` channel), the colour alone to a PNG (`encoding`), saying
    /// so when channels are left out.
    pub fn write(&self, path: &Path, encoding: Encoding) -> Result<(), OutputError> {
        let format = Format::from_path(path)?;
        if self.channels.is_empty() || format == Format::Png {
            if !self.channels.is_empty() {
                log::warn!(
                    "{}: a PNG holds the colour alone; the parts' other channels are left out",
                    path.display()
                );
            }
            return write_image(path, &self.film, encoding);
        }
        write_exr_channels(path, &self.film, &self.channels, None)?;
        if let Some(ids) = &self.ids {
            write_ids(path, ids)?;
        }
        Ok(())
    }
}

/// A part as read.
struct ReadPart<'a> {
    path: &'a Path,
    film: Film,
    channels: Vec<Channel>,
    info: PartInfo,
}

/// The names and types of channels, for messages and comparisons.
fn describe(channels: &[Channel]) -> String {
    if channels.is_empty() {
        return "no channel besides R, G, B".into();
    }
    let names: Vec<String> = channels
        .iter()
        .map(|c| format!("{} ({})", c.name, c.samples.type_name()))
        .collect();
    names.join(", ")
}

/// Read `parts` and stitch them into the whole image, every channel of it, refusing
/// parts of different images or renders, with other channels, overlapping parts and
/// uncovered pixels.
pub fn merge(parts: &[PathBuf]) -> Result<Merged, MergeError> {
    let mut read: Vec<ReadPart> = Vec::with_capacity(parts.len());
    for p in parts {
        let (film, channels, info) = read_exr_channels(p).map_err(MergeError::Read)?;
        if info.hash.is_none() {
            return Err(MergeError::NotAPart { path: p.clone() });
        }
        read.push(ReadPart {
            path: p,
            film,
            channels,
            info,
        });
    }
    let Some(first) = read.first() else {
        return Err(MergeError::NoParts);
    };
    for part in &read[1..] {
        check_same_render(part, first)?;
    }
    let (film, channels) = stitch(&read)?;
    let ids = if channels.iter().any(|c| c.name == "id") {
        Some(merge_ids(&read)?)
    } else {
        None
    };
    Ok(Merged {
        film,
        channels,
        ids,
    })
}

/// Refuse `part` unless it is of the same image, render and channels as `first`.
fn check_same_render(part: &ReadPart, first: &ReadPart) -> Result<(), MergeError> {
    let (info, info0) = (&part.info, &first.info);
    if info.full != info0.full {
        return Err(MergeError::OtherImage {
            part: part.path.to_path_buf(),
            full: info.full,
            first: first.path.to_path_buf(),
            first_full: info0.full,
        });
    }
    if info.hash != info0.hash {
        let hash = |i: &PartInfo| i.hash.clone().unwrap_or_else(|| "-".into());
        return Err(MergeError::OtherRender {
            part: part.path.to_path_buf(),
            first: first.path.to_path_buf(),
            hash: hash(info),
            first_hash: hash(info0),
        });
    }
    let (mine, theirs) = (describe(&part.channels), describe(&first.channels));
    if mine != theirs {
        return Err(MergeError::OtherChannels {
            part: part.path.to_path_buf(),
            channels: mine,
            first: first.path.to_path_buf(),
            first_channels: theirs,
        });
    }
    Ok(())
}

/// Every channel of the whole image from the parts, which must cover it exactly once.
fn stitch(read: &[ReadPart]) -> Result<(Film, Vec<Channel>), MergeError> {
    let (w, h) = read[0].info.full;
    let n = w as usize * h as usize;
    let mut owner: Vec<u32> = vec![u32::MAX; n];
    let mut out = Film::new(w, h);
    let mut channels: Vec<Channel> = read[0]
        .channels
        .iter()
        .map(|c| Channel {
            name: c.name.clone(),
            samples: c.samples.like(n),
        })
        .collect();
    for (k, part) in read.iter().enumerate() {
        let r = part.info.region;
        for j in r.y0..r.y1 {
            for i in r.x0..r.x1 {
                let at = (j * w + i) as usize;
                let o = &mut owner[at];
                if *o != u32::MAX {
                    return Err(MergeError::Overlap {
                        part: part.path.to_path_buf(),
                        x: i,
                        y: j,
                        other: read[*o as usize].path.to_path_buf(),
                    });
                }
                *o = k as u32;
                out.set(i, j, part.film.get(i - r.x0, j - r.y0));
                let from = ((j - r.y0) * r.width() + (i - r.x0)) as usize;
                for (dst, src) in channels.iter_mut().zip(&part.channels) {
                    dst.samples.copy_from(at, &src.samples, from);
                }
            }
        }
    }
    if let Some(idx) = owner.iter().position(|&o| o == u32::MAX) {
        return Err(MergeError::Uncovered {
            missing: owner.iter().filter(|&&o| o == u32::MAX).count(),
            x: idx as u32 % w,
            y: idx as u32 / w,
        });
    }
    Ok((out, channels))
}

/// The ids of every part's `.ids.json`, each once, ascending.
fn merge_ids(read: &[ReadPart]) -> Result<Vec<IdEntry>, MergeError> {
    let mut all: Vec<IdEntry> = Vec::new();
    for part in read {
        all.extend(read_ids(part.path).map_err(MergeError::Read)?);
    }
    all.sort_by_key(|e| e.id);
    all.dedup_by_key(|e| e.id);
    Ok(all)
}
