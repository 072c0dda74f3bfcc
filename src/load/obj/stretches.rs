//! Parsing a file in stretches, in parallel, with the result of parsing it whole.
//!
//! The text is cut into stretches of about a given size at line starts (every OBJ
//! statement is one line). A first parallel pass counts the lines of each stretch and
//! the elements its keywords define ([`parse::count`]); summed in order, they tell each
//! stretch where it starts. A second parallel pass parses the stretches
//! ([`parse::parse`]), a batch at a time, and [`Joined`] joins them in file order,
//! each batch while the next is parsed, so that the join, which copies the stretches'
//! lists into the file's (with the other threads' help, see [`super::append`]), does
//! not leave the other threads idle. A small file is one stretch, parsed without the
//! count.

use super::join::Joined;
use super::located::Located;
use super::parse::{self, Obj, Part, Start};
use super::sink::{Lists, Slices};
use super::sized::Sized;
use crate::load::LoadProgress;
use rayon::prelude::*;

/// Parse `text` in stretches of about `stretch` bytes (at least one line each), on
/// the current thread pool; each stretch parsed advances `progress` by its bytes.
///
/// # Errors
/// The problem that parsing the file from start to end reports first.
pub(super) fn parse(
    text: &str,
    stretch: usize,
    progress: &LoadProgress<'_>,
) -> Result<Obj, Located> {
    let pieces = cut(text, stretch);
    if pieces.len() <= 1 {
        // One stretch, into lists of its own, without the count.
        let mut joined = Joined::default();
        for piece in pieces {
            joined.add(parse::parse(piece, Start::default(), Lists, progress))?;
        }
        return joined.finish();
    }
    let (starts, total) = starts(&pieces);
    let mut lists = Sized::new(&total);
    let mut obj = parse_into(&pieces, &starts, lists.slices(&starts), progress)?;
    lists.into_obj(&mut obj);
    Ok(obj)
}

/// Parse the stretches `pieces`, which start at `starts`, into their `slices` of the
/// file's lists, a batch at a time, each batch joined while the next is parsed.
fn parse_into(
    pieces: &[&str],
    starts: &[Start],
    slices: Vec<Slices<'_>>,
    progress: &LoadProgress<'_>,
) -> Result<Obj, Located> {
    let batch = rayon::current_num_threads().max(1) * 4;
    let mut slices = slices.into_iter();
    let mut joined = Joined::default();
    let mut pending = Vec::new();
    for (pieces, starts) in pieces.chunks(batch).zip(starts.chunks(batch)) {
        let into: Vec<Slices> = slices.by_ref().take(pieces.len()).collect();
        let earlier = std::mem::take(&mut pending);
        let (added, parsed) = rayon::join(
            || add(&mut joined, earlier),
            || parse_batch(pieces, starts, into, progress),
        );
        added?;
        pending = parsed;
    }
    add(&mut joined, pending)?;
    joined.finish()
}

/// Parse a batch of stretches in parallel, in order, each into its slices.
fn parse_batch(
    pieces: &[&str],
    starts: &[Start],
    into: Vec<Slices<'_>>,
    progress: &LoadProgress<'_>,
) -> Vec<Part> {
    pieces
        .par_iter()
        .zip(starts)
        .zip(into)
        .map(|((piece, &start), sink)| parse::parse(piece, start, sink, progress))
        .collect()
}

/// Join parsed stretches in order.
fn add(joined: &mut Joined, parts: Vec<Part>) -> Result<(), Located> {
    parts.into_iter().try_for_each(|part| joined.add(part))
}

/// Where each stretch starts: the lines, elements and faces of the stretches before
/// it, and its place; and what the whole file has.
fn starts(pieces: &[&str]) -> (Vec<Start>, Start) {
    let counts: Vec<Start> = pieces.par_iter().map(|p| parse::count(p)).collect();
    let mut at = Start::default();
    let mut out = Vec::with_capacity(pieces.len());
    for (part, n) in counts.into_iter().enumerate() {
        out.push(Start { part, ..at });
        at.line += n.line;
        at.counts.v += n.counts.v;
        at.counts.vt += n.counts.vt;
        at.counts.vn += n.counts.vn;
        at.faces += n.faces;
    }
    (out, at)
}

/// `text` cut into stretches of about `size` bytes, each but the last ending with a
/// line break.
fn cut(text: &str, size: usize) -> Vec<&str> {
    let mut pieces = Vec::new();
    let mut rest = text;
    while !rest.is_empty() {
        let end = match rest.as_bytes().get(size.max(1) - 1..) {
            None => rest.len(),
            Some(tail) => tail
                .iter()
                .position(|&b| b == b'\n')
                .map_or(rest.len(), |k| size.max(1) + k),
        };
        let (piece, after) = rest.split_at(end);
        pieces.push(piece);
        rest = after;
    }
    pieces
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stretches_end_at_line_breaks() {
        let text = "v 1 2 3\r\nvt 0 0\n\nf 1 2 3\n# é\nvn 0 0 1";
        for size in [1, 2, 5, 9, 10, 11, 30, usize::MAX] {
            let pieces = cut(text, size);
            assert_eq!(pieces.concat(), text, "{size}");
            let (last, earlier) = pieces.split_last().unwrap();
            assert!(
                earlier
                    .iter()
                    .all(|p| p.ends_with('\n') && p.len() >= size.min(text.len())),
                "{size}: {pieces:?}"
            );
            assert!(!last.is_empty());
        }
        assert_eq!(cut(text, 1).len(), 6);
        assert!(cut("", 1).is_empty());
        let (starts, total) = starts(&cut(text, 1));
        let at = |s: &Start| {
            (
                s.line,
                s.counts.v,
                s.counts.vt,
                s.counts.vn,
                s.faces,
                s.part,
            )
        };
        let got: Vec<_> = starts.iter().map(at).collect();
        assert_eq!(
            got,
            [
                (0, 0, 0, 0, 0, 0),
                (1, 1, 0, 0, 0, 1),
                (2, 1, 1, 0, 0, 2),
                (3, 1, 1, 0, 0, 3),
                (4, 1, 1, 0, 1, 4),
                (5, 1, 1, 0, 1, 5)
            ]
        );
        assert_eq!(at(&total), (6, 1, 1, 1, 1, 0));
    }
}
