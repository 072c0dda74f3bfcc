//! Faces to triangles in parallel. The faces are cut into chunks of consecutive faces,
//! converted on the current thread pool a batch of chunks at a time
//! ([`build::convert`]), and joined in face order ([`Converted::append`]) while the
//! next batch is converted, so that the thread joining them is not alone at work.
//! The lists of a joined chunk are kept, emptied, and a later chunk is converted into
//! them: fresh memory costs more than the copy (the kernel zeroes each page first
//! touched), and the chunks' lists would otherwise be fresh each time. The model, the
//! counts, the first lines noted and the error are those of converting the faces in
//! a row, which is what a model of one chunk does (no join).

use super::build::{self, Model};
use super::converted::Converted;
use crate::scene::Geometry;
use rayon::prelude::*;
use std::ops::Range;

/// Convert the faces of `model` in chunks of `chunk` faces (at least one), on the
/// current thread pool.
pub(super) fn convert(model: &Model, chunk: usize) -> Converted {
    let faces = model.faces();
    let chunks = cut(faces, chunk);
    if chunks.len() <= 1 {
        let expected = model.triangles_expected();
        return build::convert(model, 0..faces, expected, Geometry::default());
    }
    let batch = rayon::current_num_threads().max(1) * 4;
    let mut joined: Option<Converted> = None;
    let mut pending = Vec::new();
    let mut spares = Vec::new();
    for chunks in chunks.chunks(batch) {
        let earlier = std::mem::take(&mut pending);
        let into = spares.split_off(spares.len().saturating_sub(chunks.len()));
        let (emptied, converted) = rayon::join(
            || join(&mut joined, earlier),
            || convert_batch(model, chunks, into),
        );
        spares.extend(emptied);
        pending = converted;
        if joined.as_ref().is_some_and(|j| j.stop.is_some()) {
            break;
        }
    }
    let _emptied = join(&mut joined, pending);
    joined.unwrap_or_default()
}

/// Convert a batch of chunks in parallel, in order, into the emptied geometries `into`
/// (as far as they go; fresh ones then). The first chunk of the model makes room for
/// the whole model's triangles: the others are joined to it.
fn convert_batch(
    model: &Model,
    chunks: &[Range<usize>],
    mut into: Vec<Geometry>,
) -> Vec<Converted> {
    into.resize_with(chunks.len(), Geometry::default);
    chunks
        .par_iter()
        .zip(into)
        .map(|(faces, geometry)| {
            let expected = if faces.start == 0 {
                model.triangles_expected()
            } else {
                // Two triangles per face: room for quads.
                faces.len() * 2
            };
            build::convert(model, faces.clone(), expected, geometry)
        })
        .collect()
}

/// Join converted chunks, in order, to those joined so far; returns their emptied
/// geometries.
fn join(joined: &mut Option<Converted>, chunks: Vec<Converted>) -> Vec<Geometry> {
    let mut emptied = Vec::with_capacity(chunks.len());
    for next in chunks {
        match joined {
            Some(j) => emptied.push(j.append(next)),
            None => *joined = Some(next),
        }
    }
    emptied
}

/// The faces `0..faces` cut into ranges of `chunk` faces (the last one shorter).
fn cut(faces: usize, chunk: usize) -> Vec<Range<usize>> {
    let chunk = chunk.max(1);
    (0..faces)
        .step_by(chunk)
        .map(|start| start..faces.min(start.saturating_add(chunk)))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chunks_cover_the_faces_in_order() {
        assert_eq!(cut(7, 3), [0..3, 3..6, 6..7]);
        assert_eq!(cut(6, 3), [0..3, 3..6]);
        assert_eq!(cut(2, usize::MAX), vec![0..2]);
        assert_eq!(cut(2, 0), [0..1, 1..2]);
        assert!(cut(0, 4).is_empty());
    }
}
