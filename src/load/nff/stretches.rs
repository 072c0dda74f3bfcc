//! Parsing a file's stretches in parallel and joining them in file order.
//!
//! The stretches ([`split::cut`]) are parsed a batch at a time, each batch while the
//! one before it is joined, so that the join, which must go in order, does not leave
//! the other threads idle. A stretch whose first token is not where the one before
//! stopped (the cut fell inside an entity) is read again from there, with the rest of
//! the file, as one stretch; the first error in file order is the one that sequential
//! reading reports, since every stretch before it was read from an entity's start.

use super::merge::Merger;
use super::parser::{self, Parsed, Place, Source};
use super::split;
use crate::load::{LoadError, LoadProgress};
use crate::math::DVec3;
use crate::scene::Scene;
use rayon::prelude::*;
use std::path::Path;
use std::sync::Arc;

/// Parse `src` (the file `path`, in the frame whose origin is `origin`) in stretches of
/// about `stretch` bytes; each stretch parsed advances `progress` by its bytes.
///
/// # Errors
/// The first problem in file order.
pub(super) fn parse_in_stretches(
    src: &str,
    path: &Path,
    origin: DVec3,
    stretch: usize,
    progress: &LoadProgress<'_>,
) -> Result<Scene, LoadError> {
    let stretches = Stretches::new(Source { src, path, origin }, stretch);
    let mut joiner = Joiner {
        merger: Merger::new(path, origin),
        resume: None,
        joined: 0,
    };
    let batch = rayon::current_num_threads().max(1) * 4;
    let mut pending = Vec::new();
    for first in (0..stretches.places.len()).step_by(batch) {
        let last = (first + batch).min(stretches.places.len());
        let earlier = std::mem::take(&mut pending);
        let (done, parsed) = rayon::join(
            || joiner.join(earlier, &stretches),
            || stretches.parse(first..last, progress),
        );
        if done? {
            return joiner.merger.finish();
        }
        pending = parsed;
    }
    joiner.join(pending, &stretches)?;
    joiner.merger.finish()
}

/// A file cut into stretches.
struct Stretches<'a, 'p> {
    source: Source<'a, 'p>,
    /// The file's name, as the sources name it.
    file: Arc<str>,
    /// Where each stretch starts.
    places: Vec<Place>,
}

impl<'a, 'p> Stretches<'a, 'p> {
    fn new(source: Source<'a, 'p>, stretch: usize) -> Self {
        let src = source.src;
        Stretches {
            source,
            file: Arc::from(source.path.display().to_string()),
            places: places(src, &split::cut(src, stretch)),
        }
    }

    /// Where stretch `k` ends: where the next one starts (`usize::MAX` for the last).
    fn end(&self, k: usize) -> usize {
        self.places.get(k + 1).map_or(usize::MAX, |p| p.pos)
    }

    /// Parse stretches `ks` in parallel, in order.
    fn parse(&self, ks: std::ops::Range<usize>, progress: &LoadProgress<'_>) -> Vec<Parsed> {
        ks.into_par_iter()
            .map(|k| {
                let (from, end) = (self.places[k], self.end(k));
                let parsed = parser::parse(self.source, self.file.clone(), from, end);
                progress.advance((end.min(self.source.src.len()) - from.pos) as u64);
                parsed
            })
            .collect()
    }

    /// Read the rest of the file from `place` as one stretch.
    fn rest(&self, place: Place) -> Parsed {
        parser::parse(self.source, self.file.clone(), place, usize::MAX)
    }
}

/// The stretches joined so far.
struct Joiner<'p> {
    merger: Merger<'p>,
    /// Where the last stretch joined stopped: `None` when it read to the end.
    resume: Option<Place>,
    /// Stretches joined.
    joined: usize,
}

impl Joiner<'_> {
    /// Join the next stretches, `parsed`, in order; `Ok(true)` when the file is read to
    /// its end (the rest of the stretches then have nothing to add).
    fn join(&mut self, parsed: Vec<Parsed>, stretches: &Stretches) -> Result<bool, LoadError> {
        for parsed in parsed {
            if self.joined > 0 {
                let Some(stop) = self.resume else {
                    return Ok(true);
                };
                if parsed.first != Some(stop.pos) {
                    join(&mut self.merger, stretches.rest(stop))?;
                    return Ok(true);
                }
            }
            self.resume = parsed.stop;
            self.joined += 1;
            join(&mut self.merger, parsed)?;
        }
        Ok(false)
    }
}

/// Join a parsed stretch, or stop at its error (after its warnings).
fn join(merger: &mut Merger<'_>, parsed: Parsed) -> Result<(), LoadError> {
    match parsed.error {
        Some(e) => {
            merger.notes(&parsed.part.notes);
            Err(e)
        }
        None => {
            merger.add(parsed.part);
            Ok(())
        }
    }
}

/// The stretches starting at `starts` (line starts), with their line numbers.
fn places(src: &str, starts: &[usize]) -> Vec<Place> {
    let b = src.as_bytes();
    let breaks: Vec<usize> = starts
        .par_iter()
        .enumerate()
        .map(|(k, &s)| {
            let end = starts.get(k + 1).copied().unwrap_or(b.len());
            split::line_breaks(b, s, end)
        })
        .collect();
    let mut line = 1;
    starts
        .iter()
        .zip(&breaks)
        .map(|(&pos, &n)| {
            let place = Place {
                pos,
                line,
                line_start: pos,
            };
            line += n;
            place
        })
        .collect()
}
