//! The OBJ statement parser: one pass over a stretch of the text (the whole file, or
//! a part of it that starts at a line start) gives its elements (`v`, `vt`, `vn`), the
//! faces and lines with their index triples, and the statements that apply to faces
//! (`usemtl`, `mtllib`, `s`, `g`, `o`), after checking every statement.
//!
//! A stretch is parsed knowing where it starts ([`Start`]): the lines before it, and
//! the elements defined before it, which [`count`] finds by looking at the keywords
//! of the earlier stretches alone. So line numbers and element indices are the file's
//! from the start, and a negative index counts back from the last element defined
//! before the face, whichever stretch defined it.
//!
//! The first problem stops the stretch with its `line:col`. Numbers are looked at
//! after the structure: a structural problem is reported unless a number on an earlier
//! line is bad (see [`super::numbers`]; [`super::join`] decides, as the bad number may
//! be in an earlier stretch). A positive index may name an element defined later in
//! the file: such forward references are noted, and checked against the whole file by
//! [`super::join`] and against the end of the face's run by [`super::runs`].

use super::colours::{ColourNote, Colours};
use super::located::{Located, article, col_of, comment_hint, name_after_space, show};
use super::numbers::{self, Element};
use super::sink::Sink;
use crate::load::LoadProgress;
use glam::{DVec3, Vec2, Vec3};
use rayon::prelude::*;

/// How many bytes are read between two advances of the load's progress.
const PROGRESS_CHUNK: usize = 1 << 20;

/// The fewest vertices a thread takes at a time when they are walked in parallel.
const ELEMENT_CHUNK: usize = 1 << 16;

/// Index of an element a corner does not name.
pub(super) const NONE: usize = usize::MAX;

/// A vertex of a face: 0-based indices of its position, texture coordinate and normal
/// ([`NONE`] when absent).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Corner {
    pub v: usize,
    pub vt: usize,
    pub vn: usize,
}

/// A face (`f`) or line (`l`) statement.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Face {
    pub line: usize,
    /// The list of [`Obj::corners`] its corners are in (its stretch's).
    pub part: usize,
    /// Index of its first corner in that list.
    pub first: usize,
    pub arity: usize,
    pub is_line: bool,
    /// Every vertex has a normal index.
    pub all_normals: bool,
    /// Every vertex has a texture coordinate index.
    pub all_texcoords: bool,
    /// The file had defined texture coordinates (normals) when the face's run ended:
    /// without, its indices of them are not used (set by [`super::runs`]).
    pub texcoords_defined: bool,
    pub normals_defined: bool,
}

/// Elements defined at a point of the file.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(super) struct Counts {
    pub v: usize,
    pub vt: usize,
    pub vn: usize,
    /// Vertex colour components read.
    pub colours: usize,
}

/// A `usemtl` statement.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct UseMtl {
    /// Index of the first face after it.
    pub first_face: usize,
    /// The material name: the rest of the line after the first space, trimmed.
    pub name: String,
    pub line: usize,
}

/// An `mtllib` statement.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct MtlLib {
    /// The library name(s): the rest of the line after the first space, trimmed.
    pub name: String,
    pub line: usize,
}

/// A statement that may end a run of faces: `g`, `o`, or a `usemtl`.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Cut {
    /// Index of the first face after it.
    pub first_face: usize,
    pub line: usize,
    /// Elements defined so far.
    pub counts: Counts,
    /// For a `usemtl`: its index in [`Obj::usemtl`].
    pub usemtl: Option<usize>,
}

/// Everything read from an OBJ file.
#[derive(Debug, Default)]
pub(super) struct Obj {
    /// Vertex positions, divided by their weights, in the frame of [`Obj::recentre`]
    /// (until then the world's).
    pub positions: Vec<Vec3>,
    /// Vertex positions in the world, in double precision.
    pub world: Vec<DVec3>,
    pub texcoords: Vec<Vec2>,
    pub normals: Vec<Vec3>,
    /// The corners of the faces and lines, one list per stretch of the file (the
    /// stretches' lists are not copied into one).
    pub corners: Vec<Vec<Corner>>,
    /// Faces and lines in file order.
    pub faces: Vec<Face>,
    pub usemtl: Vec<UseMtl>,
    pub mtllibs: Vec<MtlLib>,
    /// Smoothing-group statements (`s`) as (index of the first face after it, group;
    /// 0 = off), in file order.
    pub smoothing: Vec<(usize, u32)>,
    pub cuts: Vec<Cut>,
    /// Number of `l` statements.
    pub lines: usize,
    /// Elements defined by the whole file.
    pub counts: Counts,
    /// The first `v` whose colour (x y z r g b) is present where the first `v`'s is
    /// not, or the other way round (found when the stretches are joined).
    pub colour_mismatch: Option<Located>,
    /// The first bad number of the file (see [`super::numbers`]).
    pub first_bad_number: Option<Located>,
}

/// Element kinds that faces index: vertices, texture coordinates, normals.
pub(super) const KINDS: [(&str, &str); 3] = [
    ("vertex", "vertices"),
    ("texture coordinate", "texture coordinates"),
    ("normal", "normals"),
];

/// A positive index beyond the elements defined so far: valid only if the file defines
/// enough elements later.
#[derive(Debug)]
pub(super) struct ForwardRef {
    pub index: usize,
    pub at: Located,
}

/// Where a stretch starts: after `line` lines of the file, which define `counts`
/// elements (their vertex colours are not counted: see [`count`]) and `faces` faces
/// and lines; `part` is its place among the stretches (the list of corners its faces
/// name: see [`Face::part`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(super) struct Start {
    pub line: usize,
    pub counts: Counts,
    pub faces: usize,
    pub part: usize,
}

/// What a stretch gives. In [`Part::obj`], line numbers and element indices are the
/// file's; the indices of corners, faces and `usemtl` statements, and the vertex
/// colours counted, are the stretch's own.
#[derive(Debug, Default)]
pub(super) struct Part {
    /// The statements read ([`Obj::colour_mismatch`] is left for the join), but for
    /// the corners, and for the elements and faces when they go to the file's lists
    /// (see [`super::sink`]).
    pub obj: Obj,
    /// The corners of the faces and lines read.
    pub corners: Vec<Corner>,
    /// How many faces and lines were read.
    pub faces: usize,
    /// Per kind: forward references, each larger than the one before in the stretch
    /// (the first in the file that turns out out of range is always among them).
    pub forward: [Vec<ForwardRef>; 3],
    /// Which vertices have colours.
    pub colours: Colours,
    /// A number that does not parse (or a weight of 0) was met.
    pub fatal_number: bool,
    /// The problem that stopped the stretch (a bad number on an earlier line may come
    /// first: see [`super::join`]).
    pub error: Option<Located>,
}

/// The parser's state between lines.
struct Parser<S> {
    part: Part,
    /// Where the elements and faces go.
    sink: S,
    /// The stretch's place among the file's ([`Start::part`]).
    index: usize,
}

/// The words of a statement after its keyword: how many, and the first seven.
struct Words<'a> {
    n: usize,
    first: [&'a str; 7],
}

impl<'a> Words<'a> {
    fn new(words: std::str::SplitWhitespace<'a>) -> Self {
        let mut w = Words {
            n: 0,
            first: [""; 7],
        };
        for word in words {
            if let Some(slot) = w.first.get_mut(w.n) {
                *slot = word;
            }
            w.n += 1;
        }
        w
    }

    fn kept(&self) -> &[&'a str] {
        &self.first[..self.n.min(self.first.len())]
    }

    /// The `k`-th word (0-based), if kept.
    fn get(&self, k: usize) -> Option<&'a str> {
        self.kept().get(k).copied()
    }
}

impl Obj {
    /// The corners of `face` (none if it names corners that do not exist).
    pub fn corners_of(&self, face: &Face) -> &[Corner] {
        corners_of(&self.corners, face)
    }

    /// How many corners the faces and lines have.
    pub fn corner_count(&self) -> usize {
        self.corners.iter().map(Vec::len).sum()
    }

    /// The centre of the box around the finite vertex positions (the origin 0 when
    /// there is none): where a model alone is re-centred. Found in parallel on the
    /// current thread pool; `min` and `max` pick one of their operands, so the box is
    /// the one found in a row, to the bit.
    pub fn centre(&self) -> DVec3 {
        let empty = || (DVec3::INFINITY, DVec3::NEG_INFINITY);
        let (lo, hi) = self
            .world
            .par_iter()
            .with_min_len(ELEMENT_CHUNK)
            .filter(|p| p.is_finite())
            .fold(empty, |(lo, hi), p| (lo.min(*p), hi.max(*p)))
            .reduce(empty, |(lo, hi), (l, h)| (lo.min(l), hi.max(h)));
        if lo.cmple(hi).all() {
            (lo + hi) * 0.5
        } else {
            DVec3::ZERO
        }
    }

    /// Move the positions into the frame whose origin is the world point `origin`:
    /// each becomes `world − origin`, computed in double precision (in parallel on the
    /// current thread pool).
    pub fn recentre(&mut self, origin: DVec3) {
        self.positions
            .par_iter_mut()
            .zip(self.world.par_iter())
            .with_min_len(ELEMENT_CHUNK)
            .for_each(|(p, w)| *p = (*w - origin).as_vec3());
    }
}

/// The corners of `face` in `lists` ([`Obj::corners`]).
pub(super) fn corners_of<'a>(lists: &'a [Vec<Corner>], face: &Face) -> &'a [Corner] {
    let list = lists.get(face.part).map(Vec::as_slice);
    list.and_then(|c| c.get(face.first..face.first + face.arity))
        .unwrap_or_default()
}

/// Parse a stretch of OBJ text (lines split as [`str::lines`] does) that starts at
/// `start`, its elements and faces into `sink`, telling `progress` of its bytes as
/// they are read.
pub(super) fn parse(
    text: &str,
    start: Start,
    sink: impl Sink,
    progress: &LoadProgress<'_>,
) -> Part {
    let mut p = Parser {
        part: Part::default(),
        sink,
        index: start.part,
    };
    p.part.obj.counts = start.counts;
    // Bytes read since `progress` was last advanced, and before.
    let (mut read, mut told) = (0, 0);
    for (i, line) in text.lines().enumerate() {
        if let Err(e) = p.statement(start.line + i + 1, line) {
            p.part.error = Some(e);
            return p.part;
        }
        read += line.len() + 1;
        if read >= PROGRESS_CHUNK {
            progress.advance(read as u64);
            (told, read) = (told + read, 0);
        }
    }
    progress.advance(text.len().saturating_sub(told) as u64);
    if !p.sink.filled() {
        p.part.error = Some(miscounted());
    }
    p.part
}

/// The error when a stretch reads more or fewer elements or faces than the count pass
/// found (which cannot be: both go by the same keywords).
fn miscounted() -> Located {
    Located::whole_file("internal error: a stretch of the file was miscounted".into())
}

/// The lines of a stretch and the elements they define, as far as their keywords
/// tell: exact up to the stretch's first problem, after which nothing counts.
pub(super) fn count(text: &str) -> Start {
    let mut n = Start::default();
    for line in text.lines() {
        n.line += 1;
        match keyword(line) {
            Some("v") => n.counts.v += 1,
            Some("vt") => n.counts.vt += 1,
            Some("vn") => n.counts.vn += 1,
            Some("f" | "l") => n.faces += 1,
            _ => {}
        }
    }
    n
}

/// The keyword of a statement: its first word, as [`str::split_whitespace`] finds it
/// (looked at byte by byte when it is ASCII, as it almost always is).
fn keyword(line: &str) -> Option<&str> {
    let b = line.as_bytes();
    let n = b
        .iter()
        .position(|c| !c.is_ascii_graphic())
        .unwrap_or(b.len());
    // The word ends at ASCII whitespace (vertical tab included), or the line's end.
    if n > 0
        && b.get(n)
            .is_none_or(|&c| c.is_ascii_whitespace() || c == 0x0B)
    {
        return line.get(..n);
    }
    line.split_whitespace().next()
}

/// The byte offset of `word`, a slice of `line`.
fn offset(line: &str, word: &str) -> usize {
    (word.as_ptr() as usize).saturating_sub(line.as_ptr() as usize)
}

impl<S: Sink> Parser<S> {
    fn statement(&mut self, ln: usize, line: &str) -> Result<(), Located> {
        let Some(kw) = keyword(line) else {
            return Ok(());
        };
        let mut words = line
            .get(offset(line, kw) + kw.len()..)
            .unwrap_or_default()
            .split_whitespace();
        match kw {
            "v" => self.vertex(ln, line, kw, &Words::new(words))?,
            "vt" => self.element(Element::Texture, ln, line, &Words::new(words))?,
            "vn" => self.element(Element::Normal, ln, line, &Words::new(words))?,
            "f" | "l" => self.face(ln, line, kw == "l", words)?,
            "usemtl" => self.usemtl(ln, line)?,
            "mtllib" => self.part.obj.mtllibs.push(MtlLib {
                name: name_after_space(line).to_string(),
                line: ln,
            }),
            "s" => {
                // `s off`, `s 0` or no number: off; any other word names a group.
                let group = match words.next() {
                    None | Some("off") | Some("0") => 0,
                    Some(w) => w.parse::<u32>().unwrap_or(u32::MAX).max(1),
                };
                self.part.obj.smoothing.push((self.part.faces, group));
            }
            "g" | "o" => self.cut(ln, None),
            _ => {}
        }
        Ok(())
    }

    /// A statement that may end a run of faces.
    fn cut(&mut self, ln: usize, usemtl: Option<usize>) {
        self.part.obj.cuts.push(Cut {
            first_face: self.part.faces,
            line: ln,
            counts: self.part.obj.counts,
            usemtl,
        });
    }

    /// `v x y z`, `v x y z w` or `v x y z r g b`.
    fn vertex(&mut self, ln: usize, line: &str, kw: &str, w: &Words) -> Result<(), Located> {
        let err = |tok: Option<&str>, message: String| Located::at_token(ln, line, tok, message);
        let n = w.n;
        if n < 3 {
            let message = format!("expected 3 vertex coordinates (x y z), found {n}");
            return Err(err(None, message));
        }
        if n == 5 || n > 6 {
            let tok = w.get(if n == 5 { 3 } else { 6 });
            let hint = tok.map_or("", comment_hint);
            let message =
                format!("a vertex is 'x y z', 'x y z w' or 'x y z r g b', found {n} numbers{hint}");
            return Err(err(tok, message));
        }
        self.part.colours.note(ColourNote {
            has_colour: n == 6,
            line: ln,
            col: col_of(line, kw),
        });
        let read = self.numbers(Element::Vertex, ln, line, w);
        let (p, world) = (Vec3::from(read.values), DVec3::from(read.exact));
        if !self.sink.vertex(&mut self.part.obj, p, world) {
            return Err(miscounted());
        }
        self.part.obj.counts.v += 1;
        self.part.obj.counts.colours += read.colours;
        Ok(())
    }

    /// `vt u v [w]` or `vn x y z`.
    fn element(&mut self, kind: Element, ln: usize, line: &str, w: &Words) -> Result<(), Located> {
        let n = w.n;
        let (need, message) = match kind {
            Element::Texture => (2, "expected 2 texture coordinates (u v)"),
            _ => (3, "expected 3 normal components (x y z)"),
        };
        if n < need {
            return Err(Located::at_token(
                ln,
                line,
                None,
                format!("{message}, found {n}"),
            ));
        }
        let [a, b, c] = self.numbers(kind, ln, line, w).values;
        let obj = &mut self.part.obj;
        let room = if kind == Element::Texture {
            obj.counts.vt += 1;
            self.sink.texcoord(obj, Vec2::new(a, b))
        } else {
            obj.counts.vn += 1;
            self.sink.normal(obj, Vec3::new(a, b, c))
        };
        if !room {
            return Err(miscounted());
        }
        Ok(())
    }

    /// Read the numbers of an element statement, keeping the file's first problem.
    fn numbers(&mut self, kind: Element, ln: usize, line: &str, w: &Words) -> numbers::Numbers {
        let mut read = numbers::read(kind, ln, line, w.kept(), w.n);
        self.part.fatal_number |= read.fatal;
        if self.part.obj.first_bad_number.is_none() {
            self.part.obj.first_bad_number = read.bad.take();
        }
        read
    }

    /// `usemtl NAME`.
    fn usemtl(&mut self, ln: usize, line: &str) -> Result<(), Located> {
        let name = name_after_space(line);
        if name.is_empty() {
            return Err(Located::at_token(
                ln,
                line,
                None,
                "expected a material name after 'usemtl' (separated by a space)".into(),
            ));
        }
        let k = self.part.obj.usemtl.len();
        self.part.obj.usemtl.push(UseMtl {
            first_face: self.part.faces,
            name: name.to_string(),
            line: ln,
        });
        self.cut(ln, Some(k));
        Ok(())
    }

    /// `f v/vt/vn ...` or `l v/vt ...`.
    fn face(
        &mut self,
        ln: usize,
        line: &str,
        is_line: bool,
        words: std::str::SplitWhitespace,
    ) -> Result<(), Located> {
        let first = self.part.corners.len();
        let mut all_normals = true;
        let mut all_texcoords = true;
        for tok in words {
            let (corner, normal, texcoord) = self.corner(ln, line, tok)?;
            self.part.corners.push(corner);
            all_normals &= normal;
            all_texcoords &= texcoord;
        }
        let arity = self.part.corners.len() - first;
        if is_line {
            self.part.obj.lines += 1;
        } else if arity == 0 {
            return Err(Located::at_token(
                ln,
                line,
                None,
                "face without vertices".into(),
            ));
        }
        let face = Face {
            line: ln,
            part: self.index,
            first,
            arity,
            is_line,
            all_normals: all_normals && !is_line,
            all_texcoords: all_texcoords && !is_line,
            texcoords_defined: false,
            normals_defined: false,
        };
        if !self.sink.face(&mut self.part.obj, face) {
            return Err(miscounted());
        }
        self.part.faces += 1;
        Ok(())
    }

    /// One vertex of a face, `v`, `v/vt`, `v//vn` or `v/vt/vn`, with whether it has a
    /// normal index and a texture coordinate index.
    fn corner(
        &mut self,
        ln: usize,
        line: &str,
        tok: &str,
    ) -> Result<(Corner, bool, bool), Located> {
        let err = |message: String| Located::at_token(ln, line, Some(tok), message);
        let mut idx = [NONE; 3];
        let mut parts = 0;
        let mut last_empty = false;
        for (k, part) in tok.split('/').enumerate() {
            parts += 1;
            last_empty = part.is_empty();
            let Some(slot) = idx.get_mut(k) else {
                return Err(err(format!(
                    "vertex {} has more than 3 indices (v/vt/vn){}",
                    show(tok),
                    comment_hint(tok)
                )));
            };
            if part.is_empty() {
                if k == 0 {
                    return Err(err(format!("missing vertex index in {}", show(tok))));
                }
                continue;
            }
            *slot = self.index(k, part, tok, &err)?;
        }
        let [v, vt, vn] = idx;
        let normal = parts >= 3 && !last_empty;
        Ok((Corner { v, vt, vn }, normal, vt != NONE))
    }

    /// The 0-based element index of `part`, index `k` (v, vt, vn) of the vertex `tok`.
    fn index(
        &mut self,
        k: usize,
        part: &str,
        tok: &str,
        err: &impl Fn(String) -> Located,
    ) -> Result<usize, Located> {
        let (one, many) = KINDS.get(k).copied().unwrap_or(KINDS[0]);
        let Ok(x) = part.parse::<isize>() else {
            return Err(err(format!(
                "expected {} index, found {}{}",
                article(one),
                show(part),
                comment_hint(tok)
            )));
        };
        let count = match k {
            0 => self.part.obj.counts.v,
            1 => self.part.obj.counts.vt,
            _ => self.part.obj.counts.vn,
        };
        if x == 0 {
            return Err(err(format!(
                "{one} index 0 is invalid (OBJ indices start at 1)"
            )));
        }
        if x < 0 {
            return count.checked_sub(x.unsigned_abs()).ok_or_else(|| {
                err(format!(
                    "relative {one} index {x} reaches before the first {one} ({count} {} \
                     defined so far)",
                    if count == 1 { one } else { many }
                ))
            });
        }
        let x = x.unsigned_abs();
        if x > count {
            self.forward_ref(k, x, err(String::new()));
        }
        Ok(x - 1)
    }

    fn forward_ref(&mut self, k: usize, index: usize, at: Located) {
        let Some(refs) = self.part.forward.get_mut(k) else {
            return;
        };
        if refs.last().is_none_or(|r| r.index < index) {
            refs.push(ForwardRef { index, at });
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<Obj, Located> {
        super::super::stretches::parse(text, usize::MAX, &LoadProgress::silent())
    }

    #[test]
    fn the_centre_found_in_parallel_is_the_one_found_in_a_row() {
        // Signed zeros tie: `min` and `max` keep the later of equal operands, which
        // joins in order. Infinite and NaN positions are left out.
        let world: Vec<DVec3> = (0..5 * ELEMENT_CHUNK + 17)
            .map(|k| match k % 7 {
                0 => DVec3::new(-0.0, 0.0, -0.0),
                1 => DVec3::new(0.0, -0.0, 0.0),
                2 if k % 3 == 0 => DVec3::new(f64::INFINITY, 1.0, f64::NAN),
                _ => DVec3::new(0.0, (k % 11) as f64, -((k % 5) as f64)),
            })
            .collect();
        let obj = Obj {
            world,
            ..Obj::default()
        };
        let finite = obj.world.iter().filter(|p| p.is_finite());
        let (lo, hi) = finite.fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(*p), hi.max(*p))
        });
        let bits = |v: DVec3| v.to_array().map(f64::to_bits);
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(3)
            .build()
            .unwrap();
        let centre = pool.install(|| obj.centre());
        assert_eq!(bits(centre), bits((lo + hi) * 0.5));
        assert_eq!(centre, DVec3::new(0.0, 5.0, -2.0));
    }

    #[test]
    fn records_faces_materials_and_libraries() {
        let src = "\
mtllib a.mtl
v 0 0 0
v 1 0 0
v 0 1 0
vt 0 0
vn 0 0 1
f 1 2 3
usemtl m1
f 1//1 2//1 3//1
f 1/1/1 2/1/1 3/1
l 1 2
mtllib b.mtl
usemtl m 2
f -3/-1/-1 -2/1/1 -1//1
";
        let obj = parse(src).unwrap();
        let flags: Vec<(bool, bool, bool, usize)> = obj
            .faces
            .iter()
            .map(|f| (f.is_line, f.all_normals, f.all_texcoords, f.line))
            .collect();
        assert_eq!(
            flags,
            [
                (false, false, false, 7),
                (false, true, false, 9),
                (false, false, true, 10),
                (true, false, false, 11),
                (false, true, false, 14)
            ]
        );
        assert_eq!(obj.lines, 1);
        let libs: Vec<(usize, &str)> = obj
            .mtllibs
            .iter()
            .map(|l| (l.line, l.name.as_str()))
            .collect();
        assert_eq!(libs, [(1, "a.mtl"), (12, "b.mtl")]);
        let u: Vec<(usize, &str, usize)> = obj
            .usemtl
            .iter()
            .map(|u| (u.first_face, u.name.as_str(), u.line))
            .collect();
        assert_eq!(u, [(1, "m1", 8), (4, "m 2", 13)]);
        assert!(obj.colour_mismatch.is_none());
        // Relative indices count back from the last element defined.
        let last = obj.corners_of(&obj.faces[4]);
        let c = |v, vt, vn| Corner { v, vt, vn };
        assert_eq!(last, [c(0, 0, 0), c(1, 0, 0), c(2, NONE, 0)]);
        assert_eq!(obj.positions[1], Vec3::X);
    }

    #[test]
    fn errors() {
        let err = |src: &str| parse(src).unwrap_err();
        // Texture and normal indices are checked too.
        let e = err("v 0 0 0\nvt 0 0\nf 1/0 1/1 1/1\n");
        assert_eq!((e.line, e.col), (3, 3));
        assert!(
            e.message.contains("texture coordinate index 0"),
            "{}",
            e.message
        );
        let e = err("v 0 0 0\nvn 0 0 1\nf 1//1 1//-2 1//1\n");
        assert_eq!((e.line, e.col), (3, 8));
        assert!(
            e.message.contains("relative normal index -2"),
            "{}",
            e.message
        );
        let e = err("v 0 0 0\nf /1 1 1\n");
        assert!(e.message.contains("missing vertex index"), "{}", e.message);
        let e = err("v 0 0 0\nf 1 1 99999999999999999999999\n");
        assert!(
            e.message.contains("expected a vertex index"),
            "{}",
            e.message
        );
        let e = err("v 0 0 0\nf 1 1/1/1/ 1\n");
        assert!(e.message.contains("more than 3 indices"), "{}", e.message);
        // The earliest of several forward references beyond the end.
        let e = err("f 1/1 1/1 1/1\nf 7 1 1\nf 1 1 1/9\nv 0 0 0\nvt 0 0\n");
        assert_eq!((e.line, e.col), (2, 3));
        // Columns count characters.
        let e = err("g é\nv 0 0 0\nf 1 1 é\n");
        assert_eq!((e.line, e.col), (3, 7));
        // Mixed vertex colours are noted (an error only when a face lacks a colour).
        let obj = parse("v 0 0 0 1 0 0\nv 1 0 0\n").unwrap();
        let m = obj.colour_mismatch.unwrap();
        assert_eq!((m.line, m.col), (2, 1));
        // An `l` may have no vertex, an `f` may not.
        assert!(parse("l\n").is_ok());
        assert_eq!(err("f  \n").col, 2);
    }

    #[test]
    fn bad_numbers_come_first_when_earlier() {
        // A bad number before a structural problem is the error.
        let e = parse("v 0 0 zero\nf 1 2 3\n").unwrap_err();
        assert_eq!((e.line, e.col), (1, 7));
        // On the same line, the structure is.
        let e = parse("v x 0\n").unwrap_err();
        assert!(e.message.contains("expected 3 vertex"), "{}", e.message);
        // A number that does not parse is an error wherever it is, even unused.
        let e = parse("v 0 0 0\nvt 0 0\nvt 0 u\n").unwrap_err();
        assert_eq!((e.line, e.col), (3, 6));
        // Non-finite numbers are noted, not errors (unless used: see `runs`).
        let obj = parse("v 0 0 0\nv inf 0 0\nv 0 1e39 0\n").unwrap();
        assert_eq!(obj.first_bad_number.unwrap().line, 2);
        // But then the first bad number is the error.
        let e = parse("v 0 0 0\nv inf 0 0\nv 0 1e39 0\nv 0 0 x\n").unwrap_err();
        assert_eq!(e.line, 2);
    }

    #[test]
    fn keywords_are_the_first_words() {
        for line in [
            "v 1",
            "vt\t1",
            "f",
            " vn 1",
            "\u{a0}v 1",
            "v\u{a0}1",
            "v\u{b}1",
            "v\u{1}x",
            "é 1",
            "",
        ] {
            assert_eq!(keyword(line), line.split_whitespace().next(), "{line:?}");
        }
        let line = " \u{a0}usemtl a";
        assert_eq!(offset(line, keyword(line).unwrap()), 3);
    }

    #[test]
    fn smoothing_groups_and_cuts() {
        let obj = parse("s 1\nf 1 1 1\ns off\ns x\ng a\no\ns\ns 0\nusemtl m\nv 0 0 0\n").unwrap();
        assert_eq!(
            obj.smoothing,
            [(0, 1), (1, 0), (1, u32::MAX), (1, 0), (1, 0)]
        );
        let cuts: Vec<(usize, Option<usize>, usize)> = obj
            .cuts
            .iter()
            .map(|c| (c.line, c.usemtl, c.counts.v))
            .collect();
        assert_eq!(cuts, [(5, None, 0), (6, None, 0), (9, Some(0), 0)]);
        assert_eq!(obj.counts.v, 1);
    }
}
