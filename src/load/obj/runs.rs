//! Runs of faces, and the index checks made when a run ends.
//!
//! A run is the faces and lines between two of these: a `g` or `o` statement after
//! some faces, a `usemtl` after some faces that changes the material (as the libraries
//! read before it define the name: an unknown name is no material), and the end of the
//! file. When a run ends, the indices of its faces must name elements defined so far:
//! a face may name a vertex defined after it, but within its run. A face's texture
//! coordinate (normal) indices are used only if the file has defined texture
//! coordinates (normals) when its run ends, and only then checked. A vertex colour
//! (`v x y z r g b`) must exist for every vertex a face names once any colour has been
//! read.
//!
//! Then the elements that faces use must be in range: every position (within
//! ±[`range::MAX_COORDINATE`]) and every normal used (finite), where a run with normals
//! whose first vertex has no normal index uses the file's first normal.
//!
//! The faces of a long run, and the elements of all faces, are checked in parallel on
//! the current thread pool, in chunks of a given number of faces; the problem reported
//! is the first in file order, as checking the faces in a row finds.

use super::located::Located;
use super::parse::{Corner, Counts, Face, NONE, Obj, corners_of};
use crate::scene::range;
use rayon::prelude::*;
use std::collections::HashMap;
use std::ops::Range;

/// An index beyond the elements defined when its run ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum OutOfBounds {
    Vertex,
    Colour,
    Texture,
    Normal,
}

impl OutOfBounds {
    fn message(self) -> &'static str {
        match self {
            OutOfBounds::Vertex => "face vertex index out of bounds",
            OutOfBounds::Colour => "face vertex color index out of bounds",
            OutOfBounds::Texture => "face texcoord index out of bounds",
            OutOfBounds::Normal => "face normal index out of bounds",
        }
    }
}

/// Check the runs of `obj` and mark which faces' texture coordinates and normals are
/// defined. `materials` are the names the libraries define, in the order read, each
/// with the line of the `mtllib` that read it. The faces are checked in parallel in
/// chunks of `chunk` faces or more.
///
/// # Errors
/// The file's first bad number if it has one and some run or element fails; else
/// [`Obj::colour_mismatch`] for a missing vertex colour, or a message for the whole
/// file.
pub(super) fn check(
    obj: &mut Obj,
    materials: &[(usize, &str)],
    chunk: usize,
) -> Result<(), Located> {
    let mut normal0_used = false;
    for (run, counts) in runs(obj, materials) {
        if let Err(e) = end_run(obj, run, counts, chunk, &mut normal0_used) {
            return Err(obj
                .first_bad_number
                .take()
                .or_else(|| (e == OutOfBounds::Colour).then(|| obj.colour_mismatch.take())?)
                .unwrap_or_else(|| {
                    Located::whole_file(format!("malformed OBJ file ({})", e.message()))
                }));
        }
    }
    if !elements_in_range(obj, normal0_used, chunk) {
        return Err(obj
            .first_bad_number
            .take()
            .unwrap_or_else(|| Located::whole_file("vertex coordinates out of range".into())));
    }
    Ok(())
}

/// The runs of faces (ranges of [`Obj::faces`]) with the elements defined at their end.
fn runs(obj: &Obj, materials: &[(usize, &str)]) -> Vec<(Range<usize>, Counts)> {
    let mut out = Vec::new();
    let mut defined: HashMap<&str, usize> = HashMap::new();
    let mut read = 0; // materials read before the current statement
    let mut current: Option<usize> = None;
    let mut start = 0;
    for cut in &obj.cuts {
        let pending = cut.first_face > start;
        let ends = match cut.usemtl {
            None => pending,
            Some(k) => {
                while let Some(&(_, name)) = materials.get(read).filter(|(l, _)| *l < cut.line) {
                    defined.insert(name, read);
                    read += 1;
                }
                let id = obj
                    .usemtl
                    .get(k)
                    .and_then(|u| defined.get(u.name.as_str()).copied());
                let changed = id != current;
                current = id;
                changed && pending
            }
        };
        if ends {
            out.push((start..cut.first_face, cut.counts));
            start = cut.first_face;
        }
    }
    out.push((start..obj.faces.len(), obj.counts));
    out
}

/// Check the indices of a run against the elements defined at its end, and mark its
/// faces' texture coordinates and normals as defined or not; in parallel, in chunks
/// of `chunk` faces or more.
fn end_run(
    obj: &mut Obj,
    run: Range<usize>,
    counts: Counts,
    chunk: usize,
    normal0_used: &mut bool,
) -> Result<(), OutOfBounds> {
    let Obj { faces, corners, .. } = obj;
    let faces = faces.get_mut(run).unwrap_or_default();
    let first = faces.iter().find_map(|f| corners_of(corners, f).first());
    if let Some(c) = first {
        check_corner(c, &counts)?;
        if counts.vn > 0 && c.vn == NONE {
            *normal0_used = true;
        }
    }
    let problem = faces
        .par_iter_mut()
        .with_min_len(chunk.max(1))
        .find_map_first(|face| {
            face.texcoords_defined = counts.vt > 0;
            face.normals_defined = counts.vn > 0;
            let corners = corners_of(corners, face);
            corners.iter().find_map(|c| check_corner(c, &counts).err())
        });
    problem.map_or(Ok(()), Err)
}

/// Check one vertex's indices against the elements defined.
fn check_corner(c: &Corner, counts: &Counts) -> Result<(), OutOfBounds> {
    if c.v >= counts.v {
        return Err(OutOfBounds::Vertex);
    }
    if counts.colours > 0 && c.v.saturating_mul(3).saturating_add(2) >= counts.colours {
        return Err(OutOfBounds::Colour);
    }
    if counts.vt > 0 && c.vt != NONE && c.vt >= counts.vt {
        return Err(OutOfBounds::Texture);
    }
    if counts.vn > 0 && c.vn != NONE && c.vn >= counts.vn {
        return Err(OutOfBounds::Normal);
    }
    Ok(())
}

/// Whether every position and normal that faces use is in range (the faces checked in
/// parallel, in chunks of `chunk` faces or more).
fn elements_in_range(obj: &Obj, normal0_used: bool, chunk: usize) -> bool {
    let usable_position = |i: usize| {
        obj.world.get(i).is_some_and(|p| {
            p.to_array()
                .iter()
                .all(|c| c.abs() <= range::MAX_COORDINATE as f64)
        })
    };
    let usable_normal = |i: usize| obj.normals.get(i).is_some_and(|n| n.is_finite());
    if normal0_used && !usable_normal(0) {
        return false;
    }
    obj.faces
        .par_iter()
        .with_min_len(chunk.max(1))
        .all(|f: &Face| {
            obj.corners_of(f).iter().all(|c| {
                usable_position(c.v) && (!f.normals_defined || c.vn == NONE || usable_normal(c.vn))
            })
        })
}

#[cfg(test)]
mod tests {
    use super::super::stretches::parse;
    use super::*;

    fn checked(src: &str, materials: &[(usize, &str)]) -> Result<Obj, Located> {
        let mut obj = parse(src, usize::MAX, &crate::load::LoadProgress::silent()).unwrap();
        check(&mut obj, materials, 1).map(|()| obj)
    }

    #[test]
    fn a_forward_index_must_be_defined_before_its_run_ends() {
        let tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
        assert!(checked(&format!("f 1 2 3\n{tri}"), &[]).is_ok());
        let e = checked(&format!("f 1 2 3\ng x\n{tri}"), &[]).unwrap_err();
        assert_eq!(
            (e.line, e.message.as_str()),
            (0, "malformed OBJ file (face vertex index out of bounds)")
        );
        // A usemtl ends the run only when the material changes.
        let src = format!("usemtl a\nf 1 2 3\nusemtl b\n{tri}");
        assert!(checked(&src, &[]).is_ok());
        assert!(checked(&src, &[(0, "b")]).is_err());
        // A bad number anywhere is the error.
        let e = checked(&format!("f 1 2 3\ng\nv 0 0 nan\n{tri}"), &[]).unwrap_err();
        assert_eq!(e.line, 3);
    }

    #[test]
    fn the_first_problem_in_file_order_is_reported_whatever_the_chunks() {
        // Face 40 names a vertex, face 70 a texture coordinate, defined after their
        // run ends: checked in chunks of any size, the vertex comes first.
        let mut src = String::from("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\n");
        for k in 0..100 {
            src.push_str(match k {
                40 => "f 1 2 4\n",
                70 => "f 1/2 2/1 3/1\n",
                _ => "f 1 2 3\n",
            });
        }
        src.push_str("g\nv 1 1 1\nvt 1 1\n");
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(3)
            .build()
            .unwrap();
        let first = |src: &str, chunk| {
            let mut obj = parse(src, usize::MAX, &crate::load::LoadProgress::silent()).unwrap();
            pool.install(|| check(&mut obj, &[], chunk))
                .unwrap_err()
                .message
        };
        for chunk in [1, 7, usize::MAX] {
            let e = first(&src, chunk);
            assert!(e.contains("vertex index out"), "{chunk}: {e}");
            let e = first(&src.replace("f 1 2 4\n", "f 1 2 3\n"), chunk);
            assert!(e.contains("texcoord index out"), "{chunk}: {e}");
        }
    }

    #[test]
    fn texture_coordinates_and_normals_count_once_defined_in_the_run() {
        let src = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1/1 2/1/1 3/1/1\ng\nvt 0 0\nvn 0 0 1\n\
                   f 1/1/1 2/1/1 3/1/1\n";
        let obj = checked(src, &[]).unwrap();
        let defined: Vec<(bool, bool)> = obj
            .faces
            .iter()
            .map(|f| (f.texcoords_defined, f.normals_defined))
            .collect();
        assert_eq!(defined, [(false, false), (true, true)]);
    }

    #[test]
    fn colours_must_cover_the_vertices_faces_name() {
        let e = checked("v 0 0 0\nv 1 0 0 1 1 1\nv 0 1 0\nf 1 2 3\n", &[]).unwrap_err();
        assert_eq!((e.line, e.col), (2, 1));
        assert!(e.message.contains("vertex colours"), "{}", e.message);
        // Colours that do not parse are not read: later vertices lack theirs.
        let e = checked(
            "v 0 0 0 r g b\nv 1 0 0 1 1 1\nv 0 1 0 1 1 1\nf 1 2 3\n",
            &[],
        )
        .unwrap_err();
        assert!(
            e.message.contains("color index out of bounds"),
            "{}",
            e.message
        );
    }

    #[test]
    fn used_elements_must_be_in_range() {
        // Unused elements are not looked at.
        assert!(
            checked(
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nv inf 0 0\nvn 0 0 1\nvn nan 0 0\nf 1 2 3\n",
                &[]
            )
            .is_ok()
        );
        // The first normal stands for a missing normal index at the start of a run.
        let e = checked(
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn nan 0 0\nvn 0 0 1\nf 1 2//2 3//2\n",
            &[],
        )
        .unwrap_err();
        assert_eq!(e.line, 4);
        let e = checked("v 0 0 0\nv 1 0 0\nv 1e10 1 0\nf 1 2 3\n", &[]).unwrap_err();
        assert!(e.message.contains("outside the range"), "{}", e.message);
    }
}
