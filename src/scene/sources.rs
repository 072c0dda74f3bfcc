//! Where things were defined: for each index of a list (the primitives of one kind, the
//! materials), the file and line of the source entity that made it, so that a hit can
//! be traced back to the NFF line, the TOML object or the OBJ face it came from
//! (`emray explain`, the id layer of `--aov`).
//!
//! The table is compact whatever the scene's size: it stores runs, not one entry per
//! index. A run is a block of consecutive indices made by consecutive lines of one file
//! that each made the same number of them (an OBJ mesh of quads split into two
//! triangles each, an NFF file of spheres), so a million-triangle mesh whose faces are
//! written one per line is a handful of runs.
//!
//! Where a scene was read from is not part of what it is: the tables of two scenes
//! always compare equal (a scene file and its rewrite in another file build equal
//! scenes), and a table's `Debug` form shows nothing of it (the hash that ties the
//! parts of an image together, `emray merge`, is taken from that form: the same scene
//! read from another path is the same render).

use crate::geometry::Kind;
use std::sync::Arc;

/// Where one item was defined.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Origin {
    /// The file (as the loader was given it; `spd:NAME` for a generated database).
    pub file: Arc<str>,
    /// 1-based line.
    pub line: u32,
}

impl std::fmt::Display for Origin {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}:{}", self.file, self.line)
    }
}

/// Consecutive indices `first..first + count`, item `k` of them made by line
/// `line + k / per` of file `file`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Run {
    first: u32,
    count: u32,
    per: u32,
    file: u32,
    line: u32,
}

/// The origins of one list's items, as runs (see the module documentation).
#[derive(Clone, Default)]
pub struct Sources {
    files: Vec<Arc<str>>,
    runs: Vec<Run>,
}

/// Always equal: see the module documentation.
impl PartialEq for Sources {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

impl Eq for Sources {}

impl std::fmt::Debug for Sources {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Sources")
    }
}

impl Sources {
    /// Items `first..first + count` were made by line `line` of `file`. Items must be
    /// recorded in increasing order of index; an index recorded twice, or past
    /// `u32::MAX`, is left out.
    pub fn add(&mut self, first: usize, count: usize, file: &Arc<str>, line: u32) {
        let (Ok(first), Ok(count)) = (u32::try_from(first), u32::try_from(count)) else {
            return;
        };
        if count == 0 || first.checked_add(count).is_none() {
            return;
        }
        if let Some(last) = self.runs.last() {
            if first < last.first + last.count {
                return;
            }
        }
        let file = self.file_index(file);
        if let Some(last) = self.runs.last_mut() {
            let next_line = last.line as u64 + (last.count / last.per) as u64;
            let continues = last.file == file
                && last.per == count
                && last.first + last.count == first
                && next_line == line as u64;
            if continues {
                last.count += count;
                return;
            }
        }
        self.runs.push(Run {
            first,
            count,
            per: count,
            file,
            line,
        });
    }

    /// Items `first..first + count` were made by lines `line..line + count`, one each:
    /// the table that adding them one by one would make, without a look-up per item.
    pub fn add_lines(&mut self, first: usize, count: usize, file: &Arc<str>, line: u32) {
        let Some(rest) = count.checked_sub(1) else {
            return;
        };
        self.add(first, 1, file, line);
        if !self.extend_last(first, rest, line) {
            self.add_each(first + 1, rest, file, line.saturating_add(1));
        }
    }

    /// Add `rest` items to the last run, on the lines after `line`, if item `first`
    /// ends it on `line` as a run of one item per line, and the items' indices and
    /// lines stay within `u32`; whether it did.
    fn extend_last(&mut self, first: usize, rest: usize, line: u32) -> bool {
        let Some(last) = self.runs.last_mut() else {
            return false;
        };
        let ends_here = last.per == 1
            && (last.first + last.count) as usize == first + 1
            && u64::from(last.line) + u64::from(last.count) - 1 == u64::from(line);
        let rest_fits = u32::try_from(first + 1 + rest).is_ok();
        match u32::try_from(rest)
            .ok()
            .filter(|&r| line.checked_add(r).is_some())
        {
            Some(rest) if ends_here && rest_fits => {
                last.count += rest;
                true
            }
            _ => false,
        }
    }

    /// [`Sources::add`] for each of `count` items from `first` on, one per line from
    /// `line` on (lines saturating at `u32::MAX`).
    fn add_each(&mut self, first: usize, count: usize, file: &Arc<str>, line: u32) {
        for k in 0..count {
            let line = line.saturating_add(u32::try_from(k).unwrap_or(u32::MAX));
            self.add(first + k, 1, file, line);
        }
    }

    /// Append `other`'s items after the first `offset` indices: the table that adding
    /// `other`'s items here one by one, in order, `offset` places on, would make.
    pub fn append(&mut self, other: &Sources, offset: usize) {
        let end = other
            .runs
            .last()
            .map_or(0, |r| (r.first + r.count) as usize);
        let fits = u32::try_from(end + offset).is_ok();
        if self.runs.is_empty() && self.files.is_empty() && fits {
            // Each run of `other` was added where the run before it refused it, as it
            // would be here: adding them one by one remakes them, `offset` places on.
            self.files.clone_from(&other.files);
            let shift = |r: &Run| Run {
                first: r.first + offset as u32,
                ..*r
            };
            self.runs = other.runs.iter().map(shift).collect();
            return;
        }
        self.append_each(other, offset);
    }

    /// [`Sources::append`], adding `other`'s runs one by one.
    fn append_each(&mut self, other: &Sources, offset: usize) {
        for run in &other.runs {
            let file = &other.files[run.file as usize];
            let first = run.first as usize + offset;
            let lines = run.count / run.per;
            // The first line of a run may continue the last run here; the rest then do.
            self.add(first, run.per as usize, file, run.line);
            if lines > 1 {
                let Some(last) = self.runs.last_mut() else {
                    return;
                };
                if last.first + last.count == first as u32 + run.per {
                    last.count += run.count - run.per;
                }
            }
        }
    }

    /// Whether `other` records the same origins as `self` (the equality that the
    /// [`PartialEq`] implementation leaves out).
    pub fn same_origins(&self, other: &Sources) -> bool {
        let key = |s: &Sources| -> Vec<(Run, Arc<str>)> {
            s.runs
                .iter()
                .map(|r| (*r, s.files[r.file as usize].clone()))
                .map(|(r, f)| (Run { file: 0, ..r }, f))
                .collect()
        };
        key(self) == key(other)
    }

    fn file_index(&mut self, file: &Arc<str>) -> u32 {
        // The same `Arc` nearly always (one loader, one file): its pointer first.
        match self
            .files
            .iter()
            .rposition(|f| Arc::ptr_eq(f, file) || f == file)
        {
            Some(k) => k as u32,
            None => {
                self.files.push(file.clone());
                self.files.len() as u32 - 1
            }
        }
    }

    /// Where item `index` was defined, if it was recorded.
    pub fn get(&self, index: u32) -> Option<Origin> {
        let k = self.runs.partition_point(|r| r.first <= index);
        let run = self.runs.get(k.checked_sub(1)?)?;
        let offset = index - run.first;
        if offset >= run.count {
            return None;
        }
        Some(Origin {
            file: self.files[run.file as usize].clone(),
            line: run.line + offset / run.per,
        })
    }

    /// The number of runs stored (what the table costs).
    pub fn runs(&self) -> usize {
        self.runs.len()
    }
}

/// The origins of a [`Geometry`](super::Geometry)'s primitives, one [`Sources`] per kind.
#[derive(Clone, Default)]
pub struct PrimSources {
    kinds: Vec<Sources>,
}

impl std::fmt::Debug for PrimSources {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("PrimSources")
    }
}

/// Always equal: see the module documentation.
impl PartialEq for PrimSources {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

impl Eq for PrimSources {}

impl PrimSources {
    /// Primitives `first..first + count` of `kind` were made by line `line` of `file`.
    pub fn add(&mut self, kind: Kind, first: usize, count: usize, file: &Arc<str>, line: u32) {
        let k = kind as usize;
        if self.kinds.len() <= k {
            self.kinds.resize_with(k + 1, Sources::default);
        }
        self.kinds[k].add(first, count, file, line);
    }

    /// Primitives `first..first + count` of `kind` were made by lines
    /// `line..line + count`, one each (see [`Sources::add_lines`]).
    pub fn add_lines(
        &mut self,
        kind: Kind,
        first: usize,
        count: usize,
        file: &Arc<str>,
        line: u32,
    ) {
        let k = kind as usize;
        if self.kinds.len() <= k {
            self.kinds.resize_with(k + 1, Sources::default);
        }
        self.kinds[k].add_lines(first, count, file, line);
    }

    /// Append `other`'s primitives after the first `offset(kind)` of each kind (see
    /// [`Sources::append`]).
    pub fn append(&mut self, other: &PrimSources, offset: &dyn Fn(Kind) -> usize) {
        for (k, sources) in other.kinds.iter().enumerate() {
            if sources.runs.is_empty() {
                continue;
            }
            let kind = Kind::ALL[k];
            if self.kinds.len() <= k {
                self.kinds.resize_with(k + 1, Sources::default);
            }
            self.kinds[k].append(sources, offset(kind));
        }
    }

    /// [`PrimSources::append`] for a table that is not needed after: taken as it is
    /// (its storage kept, not copied) when `self` records nothing and no primitive
    /// comes before `other`'s.
    pub fn append_owned(&mut self, other: PrimSources, offset: &dyn Fn(Kind) -> usize) {
        let nothing_before = Kind::ALL.into_iter().all(|kind| offset(kind) == 0);
        let empty = |s: &Sources| s.runs.is_empty() && s.files.is_empty();
        if nothing_before && self.kinds.iter().all(empty) {
            *self = other;
            return;
        }
        self.append(&other, offset);
    }

    /// Whether `other` records the same origins as `self` (see
    /// [`Sources::same_origins`]).
    pub fn same_origins(&self, other: &PrimSources) -> bool {
        (0..self.kinds.len().max(other.kinds.len())).all(|k| {
            let empty = Sources::default();
            let a = self.kinds.get(k).unwrap_or(&empty);
            let b = other.kinds.get(k).unwrap_or(&empty);
            a.same_origins(b)
        })
    }

    /// Where primitive `prim` of `kind` was defined, if it was recorded.
    pub fn get(&self, kind: Kind, prim: u32) -> Option<Origin> {
        self.kinds.get(kind as usize)?.get(prim)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runs_of_lines_that_make_as_many_items_merge() {
        let f: Arc<str> = Arc::from("mesh.obj");
        let g: Arc<str> = Arc::from("other.nff");
        let mut s = Sources::default();
        // 1000 quads on lines 10.., two triangles each: one run.
        for k in 0..1000 {
            s.add(2 * k, 2, &f, 10 + k as u32);
        }
        assert_eq!(s.runs(), 1);
        assert_eq!(s.get(0).unwrap().line, 10);
        assert_eq!(s.get(1).unwrap().line, 10);
        assert_eq!(s.get(1999).unwrap().to_string(), "mesh.obj:1009");
        // A pentagon (three triangles) breaks the run; another file too.
        s.add(2000, 3, &f, 1010);
        s.add(2003, 1, &g, 4);
        assert_eq!(s.runs(), 3);
        assert_eq!(s.get(2002).unwrap().line, 1010);
        assert_eq!(s.get(2003).unwrap().to_string(), "other.nff:4");
        assert_eq!(s.get(2004), None);
        // A gap (a line that made nothing, such as a dropped polygon) starts a run.
        s.add(2004, 1, &g, 9);
        assert_eq!(s.get(2004).unwrap().line, 9);
    }

    /// Items on consecutive lines, added at once, make the table that adding them one
    /// by one makes: after runs of any shape, from another file, on an index already
    /// recorded, past `u32::MAX`.
    #[test]
    fn items_on_consecutive_lines_at_once_or_one_by_one() {
        let f: Arc<str> = Arc::from("a.nff");
        let g: Arc<str> = Arc::from("b.nff");
        // Items first..first + count made by a line of a file.
        type Added<'a> = (usize, usize, &'a Arc<str>, u32);
        let starts: [&[Added]; 5] = [
            &[],
            &[(0, 1, &f, 1), (1, 1, &f, 2)],
            &[(0, 2, &f, 1), (2, 2, &f, 2)],
            &[(0, 1, &g, 7)],
            &[(0, 1, &f, 3)],
        ];
        for start in starts {
            for (count, line) in [(0, 3), (1, 3), (5, 3), (5, 4), (4, u32::MAX - 2)] {
                let end = start.iter().map(|&(i, n, _, _)| i + n).max().unwrap_or(0);
                for first in [end.saturating_sub(1), end, end + 1, u32::MAX as usize - 2] {
                    let mut at_once = Sources::default();
                    let mut each = Sources::default();
                    for &(i, n, file, l) in start {
                        at_once.add(i, n, file, l);
                        each.add(i, n, file, l);
                    }
                    at_once.add_lines(first, count, &f, line);
                    each.add_each(first, count, &f, line);
                    let what = format!("{start:?} then {count} from {first} on line {line}");
                    assert!(at_once.same_origins(&each), "{what}");
                    assert_eq!(at_once.runs(), each.runs(), "{what}");
                }
            }
        }
        let mut s = Sources::default();
        s.add_lines(0, 1000, &f, 10);
        s.add_lines(1000, 1000, &f, 1010);
        assert_eq!(s.runs(), 1);
        assert_eq!(s.get(1999).unwrap().line, 2009);
    }

    /// A table appended whole to an empty one is taken with its storage; appended
    /// after primitives it is added as [`PrimSources::append`] adds it.
    #[test]
    fn an_owned_table_appended_to_an_empty_one_is_taken_as_it_is() {
        let f: Arc<str> = Arc::from("a.nff");
        let mut table = PrimSources::default();
        table.add_lines(Kind::Sphere, 0, 10, &f, 1);
        table.add(Kind::Triangle, 0, 2, &f, 11);
        table.add(Kind::Triangle, 2, 2, &f, 16);
        let copy = table.clone();
        let runs = table.kinds[Kind::Triangle as usize].runs.as_ptr();
        let mut taken = PrimSources::default();
        taken.append_owned(table, &|_| 0);
        assert!(taken.same_origins(&copy));
        let triangles = &taken.kinds[Kind::Triangle as usize];
        assert_eq!(triangles.runs.as_ptr(), runs, "the storage taken");
        assert_eq!(taken.get(Kind::Triangle, 3).unwrap().line, 16);
        for offset in [0, 5] {
            let mut before = PrimSources::default();
            before.add(Kind::Triangle, 0, 1, &f, 1);
            let (mut owned, mut copied) = (before.clone(), before);
            owned.append_owned(copy.clone(), &|_| offset + 1);
            copied.append(&copy, &|_| offset + 1);
            assert!(owned.same_origins(&copied), "offset {offset}");
            let last = owned.get(Kind::Sphere, offset as u32 + 10).unwrap();
            assert_eq!(last.line, 10, "offset {offset}");
        }
    }

    /// Appended to an empty table, a table's runs are copied: the table that adding
    /// them one by one makes, whatever runs it holds and wherever it is appended.
    #[test]
    fn appending_to_an_empty_table_copies_the_runs() {
        let f: Arc<str> = Arc::from("a.nff");
        let g: Arc<str> = Arc::from("b.nff");
        let mut table = Sources::default();
        table.add_lines(0, 10, &f, 1);
        table.add(10, 2, &f, 11);
        table.add(12, 2, &f, 12);
        table.add(14, 3, &f, 13);
        table.add(17, 1, &g, 13);
        table.add(18, 1, &f, 15);
        table.add(20, 4, &f, 20);
        table.add_lines(24, 5, &f, 21);
        let end = 29;
        for offset in [
            0,
            1,
            1000,
            u32::MAX as usize - end,
            u32::MAX as usize - end + 1,
        ] {
            let (mut copied, mut each) = (Sources::default(), Sources::default());
            copied.append(&table, offset);
            each.append_each(&table, offset);
            assert!(copied.same_origins(&each), "offset {offset}");
            assert_eq!(copied.runs, each.runs, "offset {offset}");
        }
        let mut s = Sources::default();
        s.append(&table, 3);
        assert_eq!(s.get(3).unwrap().line, 1);
        assert_eq!(s.get(20).unwrap().to_string(), "b.nff:13");
        assert_eq!(s.get(22), None);
    }

    #[test]
    fn unrecorded_and_repeated_indices() {
        let f: Arc<str> = Arc::from("a");
        let mut s = Sources::default();
        assert_eq!(s.get(0), None);
        s.add(5, 2, &f, 1);
        assert_eq!(s.get(4), None);
        assert_eq!(s.get(7), None);
        s.add(6, 1, &f, 2);
        assert_eq!(s.get(6).unwrap().line, 1, "the first record stays");
        s.add(9, 0, &f, 3);
        assert_eq!(s.runs(), 1);
        let mut p = PrimSources::default();
        p.add(Kind::Sphere, 0, 1, &f, 7);
        assert_eq!(p.get(Kind::Sphere, 0).unwrap().line, 7);
        assert_eq!(p.get(Kind::Triangle, 0), None);
    }
}
