//! Joining the parsed stretches of a file, in file order, into what parsing the whole
//! file gives: the statements of one [`Obj`], or the file's first problem.
//!
//! A stretch's line numbers and element indices are already the file's, and its faces
//! name its own list of corners (see [`super::parse`]), which the join keeps as it is
//! (the largest list is not copied). The join moves the stretch's face and `usemtl`
//! indices past the earlier stretches' and adds the vertex colours counted before it.
//! The elements and faces of a file of several stretches are in the file's lists
//! already ([`super::sized`]); a stretch's own lists are moved. The first
//! stretch stopped by a problem ends the join: its problem is the error, unless the
//! file has a bad number on an earlier line, in this stretch or an earlier one. With
//! none, the forward references are checked against the elements of the whole file,
//! and a number that does not parse anywhere is the error.

use super::append::append_list;
use super::colours::Colours;
use super::located::Located;
use super::parse::{Corner, ForwardRef, KINDS, Obj, Part};

/// The stretches joined so far.
#[derive(Default)]
pub(super) struct Joined {
    obj: Obj,
    /// The faces and lines of the stretches joined (the file's list of faces may be
    /// filled in place: see [`super::sink`]).
    faces: usize,
    forward: [Vec<ForwardRef>; 3],
    colours: Colours,
    fatal_number: bool,
}

impl Joined {
    /// Join the stretch that follows.
    ///
    /// # Errors
    /// The problem that stopped `part`, or a bad number on an earlier line.
    pub fn add(&mut self, mut part: Part) -> Result<(), Located> {
        let obj = &mut self.obj;
        if obj.first_bad_number.is_none() {
            obj.first_bad_number = part.obj.first_bad_number.take();
        }
        if let Some(e) = part.error {
            return Err(first_bad_before(obj, e));
        }
        append(obj, part.obj, part.corners, self.faces);
        self.faces += part.faces;
        for (all, refs) in self.forward.iter_mut().zip(part.forward) {
            all.extend(refs);
        }
        self.colours.join(part.colours);
        self.fatal_number |= part.fatal_number;
        Ok(())
    }

    /// The whole file's statements.
    ///
    /// # Errors
    /// The first forward reference beyond the file's elements, or the first bad number
    /// when one does not parse (either way a bad number on an earlier line first).
    pub fn finish(mut self) -> Result<Obj, Located> {
        if let Some(w) = self.first_forward_beyond_the_end() {
            return Err(first_bad_before(&mut self.obj, w));
        }
        if self.fatal_number {
            if let Some(bad) = self.obj.first_bad_number.take() {
                return Err(bad);
            }
        }
        self.obj.colour_mismatch = self.colours.mismatch();
        Ok(self.obj)
    }

    /// The first forward reference in the file beyond the elements the file defines.
    fn first_forward_beyond_the_end(&self) -> Option<Located> {
        let counts = self.obj.counts;
        let totals = [counts.v, counts.vt, counts.vn];
        let mut worst: Option<Located> = None;
        for ((refs, (one, many)), total) in self.forward.iter().zip(KINDS).zip(totals) {
            let Some(r) = refs.iter().find(|r| r.index > total) else {
                continue;
            };
            let at = Located {
                message: format!(
                    "{one} index {} is out of range: the file has {total} {}",
                    r.index,
                    if total == 1 { one } else { many }
                ),
                ..r.at.clone()
            };
            if worst
                .as_ref()
                .is_none_or(|w| (at.line, at.col) < (w.line, w.col))
            {
                worst = Some(at);
            }
        }
        worst
    }
}

/// `e`, or the file's first bad number if it is on an earlier line.
fn first_bad_before(obj: &mut Obj, e: Located) -> Located {
    match obj.first_bad_number.take() {
        Some(b) if b.line < e.line => b,
        _ => e,
    }
}

/// Append the statements of the next stretch, with its `corners`, to those of the
/// earlier ones, which have `faces` faces and lines.
fn append(obj: &mut Obj, mut next: Obj, corners: Vec<Corner>, faces: usize) {
    let usemtl = obj.usemtl.len();
    let colours = obj.counts.colours;
    append_list(&mut obj.positions, &mut next.positions);
    append_list(&mut obj.world, &mut next.world);
    append_list(&mut obj.texcoords, &mut next.texcoords);
    append_list(&mut obj.normals, &mut next.normals);
    obj.corners.push(corners);
    append_list(&mut obj.faces, &mut next.faces);
    obj.usemtl.extend(next.usemtl.into_iter().map(|mut u| {
        u.first_face += faces;
        u
    }));
    obj.mtllibs.append(&mut next.mtllibs);
    let smoothing = next.smoothing.iter().map(|&(f, g)| (f + faces, g));
    obj.smoothing.extend(smoothing);
    obj.cuts.extend(next.cuts.into_iter().map(|mut c| {
        c.first_face += faces;
        c.counts.colours += colours;
        c.usemtl = c.usemtl.map(|k| k + usemtl);
        c
    }));
    obj.lines += next.lines;
    obj.counts = next.counts;
    obj.counts.colours += colours;
}
