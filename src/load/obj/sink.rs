//! Where the parser puts the elements (`v`, `vt`, `vn`) and faces of a stretch: lists
//! of the stretch's own ([`Lists`], for a file parsed as one stretch), or the stretch's
//! slices of the file's lists, sized by the count pass before the parse ([`Slices`]),
//! so that no join copies them.

use super::parse::{Face, Obj};
use glam::{DVec3, Vec2, Vec3};

/// What the parser puts a stretch's elements and faces into. Each method says whether
/// there was room.
pub(super) trait Sink {
    /// A vertex: its position and its position in the world.
    fn vertex(&mut self, obj: &mut Obj, p: Vec3, world: DVec3) -> bool;
    fn texcoord(&mut self, obj: &mut Obj, t: Vec2) -> bool;
    fn normal(&mut self, obj: &mut Obj, n: Vec3) -> bool;
    fn face(&mut self, obj: &mut Obj, face: Face) -> bool;
    /// Whether every place was filled (always, for lists).
    fn filled(&self) -> bool;
}

/// The lists of the stretch's [`Obj`], pushed onto.
pub(super) struct Lists;

impl Sink for Lists {
    fn vertex(&mut self, obj: &mut Obj, p: Vec3, world: DVec3) -> bool {
        obj.positions.push(p);
        obj.world.push(world);
        true
    }

    fn texcoord(&mut self, obj: &mut Obj, t: Vec2) -> bool {
        obj.texcoords.push(t);
        true
    }

    fn normal(&mut self, obj: &mut Obj, n: Vec3) -> bool {
        obj.normals.push(n);
        true
    }

    fn face(&mut self, obj: &mut Obj, face: Face) -> bool {
        obj.faces.push(face);
        true
    }

    fn filled(&self) -> bool {
        true
    }
}

/// A stretch's places in the file's lists, filled in order (the stretch's [`Obj`] keeps
/// none of these lists).
#[derive(Default)]
pub(super) struct Slices<'a> {
    pub positions: Places<'a, Vec3>,
    pub world: Places<'a, DVec3>,
    pub texcoords: Places<'a, Vec2>,
    pub normals: Places<'a, Vec3>,
    pub faces: Places<'a, Face>,
}

impl Sink for Slices<'_> {
    fn vertex(&mut self, _: &mut Obj, p: Vec3, world: DVec3) -> bool {
        self.positions.put(p) && self.world.put(world)
    }

    fn texcoord(&mut self, _: &mut Obj, t: Vec2) -> bool {
        self.texcoords.put(t)
    }

    fn normal(&mut self, _: &mut Obj, n: Vec3) -> bool {
        self.normals.put(n)
    }

    fn face(&mut self, _: &mut Obj, face: Face) -> bool {
        self.faces.put(face)
    }

    fn filled(&self) -> bool {
        self.positions.filled()
            && self.world.filled()
            && self.texcoords.filled()
            && self.normals.filled()
            && self.faces.filled()
    }
}

/// A slice filled from its start.
pub(super) struct Places<'a, T> {
    slice: &'a mut [T],
    next: usize,
}

/// No places.
impl<T> Default for Places<'_, T> {
    fn default() -> Self {
        Places {
            slice: &mut [],
            next: 0,
        }
    }
}

impl<'a, T> Places<'a, T> {
    pub fn new(slice: &'a mut [T]) -> Self {
        Places { slice, next: 0 }
    }

    /// Put `x` in the next place, if there is one.
    #[inline]
    fn put(&mut self, x: T) -> bool {
        match self.slice.get_mut(self.next) {
            Some(place) => {
                *place = x;
                self.next += 1;
                true
            }
            None => false,
        }
    }

    fn filled(&self) -> bool {
        self.next == self.slice.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slices_fill_in_order_and_say_when_full() {
        let mut obj = Obj::default();
        let mut positions = [Vec3::ZERO; 2];
        let mut world = [DVec3::ZERO; 2];
        {
            let mut s = Slices {
                positions: Places::new(&mut positions),
                world: Places::new(&mut world),
                ..Slices::default()
            };
            assert!(!s.filled());
            assert!(s.vertex(&mut obj, Vec3::X, DVec3::X));
            assert!(!s.filled());
            assert!(s.vertex(&mut obj, Vec3::Y, DVec3::Y));
            assert!(s.filled());
            assert!(!s.vertex(&mut obj, Vec3::Z, DVec3::Z));
            assert!(!s.texcoord(&mut obj, Vec2::ONE));
        }
        assert_eq!(positions, [Vec3::X, Vec3::Y]);
        assert!(obj.positions.is_empty());
        assert!(Lists.vertex(&mut obj, Vec3::Z, DVec3::Z));
        assert_eq!((obj.positions.len(), obj.world.len()), (1, 1));
    }
}
