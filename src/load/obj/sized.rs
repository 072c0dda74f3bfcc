//! The file's lists of elements (`v`, `vt`, `vn`) and faces, made at the size the
//! count pass finds, before the parse, and cut into the stretches' slices, which the
//! stretches fill in parallel (see [`super::sink::Slices`]). The lists are filled with
//! blanks first, on the current thread pool: the pages the kernel zeroes on first
//! touch are shared among the threads, and the parse writes each item once, in place,
//! where the stretches' own lists were copied into the file's by one thread.

use super::parse::{Face, Obj, Start};
use super::sink::{Places, Slices};
use glam::{DVec3, Vec2, Vec3};
use rayon::prelude::*;

/// The fewest items a thread fills at a time.
const FILL_CHUNK: usize = 1 << 14;

/// The file's lists of elements and faces.
pub(super) struct Sized {
    positions: Vec<Vec3>,
    world: Vec<DVec3>,
    texcoords: Vec<Vec2>,
    normals: Vec<Vec3>,
    faces: Vec<Face>,
}

/// A face not read yet.
const BLANK: Face = Face {
    line: 0,
    part: 0,
    first: 0,
    arity: 0,
    is_line: false,
    all_normals: false,
    all_texcoords: false,
    texcoords_defined: false,
    normals_defined: false,
};

impl Sized {
    /// Lists for the elements and faces counted in `total` (the count of the whole
    /// file), filled with blanks.
    pub fn new(total: &Start) -> Self {
        let c = &total.counts;
        Sized {
            positions: blanks(Vec3::ZERO, c.v),
            world: blanks(DVec3::ZERO, c.v),
            texcoords: blanks(Vec2::ZERO, c.vt),
            normals: blanks(Vec3::ZERO, c.vn),
            faces: blanks(BLANK, total.faces),
        }
    }

    /// The places of each stretch, which starts at `starts` (in order; the lists end
    /// where the last stretch does).
    pub fn slices(&mut self, starts: &[Start]) -> Vec<Slices<'_>> {
        let at = |f: fn(&Start) -> usize| starts.iter().map(f).collect::<Vec<_>>();
        let mut positions = cut(&mut self.positions, &at(|s| s.counts.v)).into_iter();
        let mut world = cut(&mut self.world, &at(|s| s.counts.v)).into_iter();
        let mut texcoords = cut(&mut self.texcoords, &at(|s| s.counts.vt)).into_iter();
        let mut normals = cut(&mut self.normals, &at(|s| s.counts.vn)).into_iter();
        let mut faces = cut(&mut self.faces, &at(|s| s.faces)).into_iter();
        let mut next = || -> Option<Slices<'_>> {
            Some(Slices {
                positions: Places::new(positions.next()?),
                world: Places::new(world.next()?),
                texcoords: Places::new(texcoords.next()?),
                normals: Places::new(normals.next()?),
                faces: Places::new(faces.next()?),
            })
        };
        std::iter::from_fn(&mut next).collect()
    }

    /// Give the lists to `obj`, whose own are empty (its stretches read into these).
    pub fn into_obj(self, obj: &mut Obj) {
        obj.positions = self.positions;
        obj.world = self.world;
        obj.texcoords = self.texcoords;
        obj.normals = self.normals;
        obj.faces = self.faces;
    }
}

/// `n` copies of `blank`, made in parallel.
fn blanks<T: Clone + Send + Sync>(blank: T, n: usize) -> Vec<T> {
    let mut list = Vec::with_capacity(n);
    list.par_extend(rayon::iter::repeat_n(blank, n).with_min_len(FILL_CHUNK));
    list
}

/// `list` cut at the increasing offsets `starts` (the first is 0): one slice per
/// offset, the last one to the end. An offset past the end (which the count pass never
/// gives) makes empty slices, which the parse reports as miscounted.
fn cut<'a, T>(list: &'a mut [T], starts: &[usize]) -> Vec<&'a mut [T]> {
    let mut slices = Vec::with_capacity(starts.len());
    let mut rest = list;
    for (k, &start) in starts.iter().enumerate() {
        let end = starts.get(k + 1).map_or(rest.len(), |&next| {
            next.saturating_sub(start).min(rest.len())
        });
        let (slice, after) = std::mem::take(&mut rest).split_at_mut(end);
        slices.push(slice);
        rest = after;
    }
    slices
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lists_are_cut_at_each_start() {
        let mut list: Vec<u32> = (0..10).collect();
        let slices = cut(&mut list, &[0, 3, 3, 7]);
        let lens: Vec<usize> = slices.iter().map(|s| s.len()).collect();
        assert_eq!(lens, [3, 0, 4, 3]);
        assert_eq!(slices[3], [7, 8, 9]);
        // Offsets past the end give empty slices, not a panic.
        let slices = cut(&mut list, &[0, 12, 20]);
        let lens: Vec<usize> = slices.iter().map(|s| s.len()).collect();
        assert_eq!(lens, [10, 0, 0]);
    }

    #[test]
    fn the_lists_have_the_counted_size() {
        let mut total = Start::default();
        (
            total.counts.v,
            total.counts.vt,
            total.counts.vn,
            total.faces,
        ) = (5, 2, 0, 40_000);
        let mut sized = Sized::new(&total);
        let mut starts = [Start::default(); 2];
        (starts[1].counts.v, starts[1].faces) = (4, 39_999);
        assert_eq!(sized.slices(&starts).len(), 2);
        let mut obj = Obj::default();
        sized.into_obj(&mut obj);
        assert_eq!(obj.world.len(), 5);
        assert_eq!(obj.faces.len(), 40_000);
        assert_eq!(obj.faces[39_999], BLANK);
    }
}
