//! What is in force at a face: the value of the last statement before it that sets one
//! (the material slot of a `usemtl`, the group of an `s`), found from any face on, so
//! that faces can be walked from the middle of the file as well as from its start.

/// The value in force at faces walked in increasing order, from a list of changes
/// `(index of the first face after the statement, value)` in file order.
pub(super) struct InForce<'a> {
    changes: &'a [(usize, u32)],
    /// The first change not yet applied.
    next: usize,
    value: u32,
}

impl<'a> InForce<'a> {
    /// Ready to walk faces from face `first` on; `before` is the value before any change.
    pub fn from(changes: &'a [(usize, u32)], before: u32, first: usize) -> Self {
        let next = changes.partition_point(|&(face, _)| face < first);
        let value = next
            .checked_sub(1)
            .and_then(|k| changes.get(k))
            .map_or(before, |&(_, v)| v);
        InForce {
            changes,
            next,
            value,
        }
    }

    /// The value in force at face `k` (not before the last face asked for).
    #[inline]
    pub fn at(&mut self, k: usize) -> u32 {
        while let Some(&(_, v)) = self.changes.get(self.next).filter(|(face, _)| *face <= k) {
            self.value = v;
            self.next += 1;
        }
        self.value
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_last_change_at_or_before_a_face_is_in_force() {
        // Two statements before face 2 (the second wins), one before face 4.
        let changes = [(0, 7), (2, 1), (2, 5), (4, 0)];
        let walked: Vec<u32> = {
            let mut v = InForce::from(&changes, 9, 0);
            (0..6).map(|k| v.at(k)).collect()
        };
        assert_eq!(walked, [7, 7, 5, 5, 0, 0]);
        for first in 0..6 {
            let mut v = InForce::from(&changes, 9, first);
            let rest: Vec<u32> = (first..6).map(|k| v.at(k)).collect();
            assert_eq!(rest, walked[first..], "from face {first}");
        }
        let mut none = InForce::from(&[], 9, 3);
        assert_eq!((none.at(3), none.at(100)), (9, 9));
        let late = [(3, 2)];
        let mut v = InForce::from(&late, 9, 1);
        assert_eq!([v.at(1), v.at(2), v.at(3)], [9, 9, 2]);
    }
}
