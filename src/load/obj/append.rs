//! Lists joined end to end in parallel: a list that follows another is moved after it
//! by the threads of the current pool, so that the thread joining the parts of a model
//! in order does not copy (and touch the fresh memory of) every item alone. The list
//! moved from is left empty with its memory, for reuse.

use rayon::prelude::*;

/// The fewest items a thread moves at a time.
const MOVE_CHUNK: usize = 1 << 12;

/// Move `next`'s items after `list`'s (`next`'s storage itself when `list` is empty).
pub(super) fn append_list<T: Send>(list: &mut Vec<T>, next: &mut Vec<T>) {
    if list.is_empty() {
        std::mem::swap(list, next);
    } else {
        list.par_extend(next.par_drain(..).with_min_len(MOVE_CHUNK));
    }
}

/// Move `next`'s items, changed by `f`, after `list`'s.
pub(super) fn append_mapped<T, U, F>(list: &mut Vec<U>, next: &mut Vec<T>, f: F)
where
    T: Send,
    U: Send,
    F: Fn(T) -> U + Sync + Send,
{
    list.par_extend(next.par_drain(..).with_min_len(MOVE_CHUNK).map(f));
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lists_follow_in_order_and_leave_theirs_empty() {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(3)
            .build()
            .unwrap();
        pool.install(|| {
            let mut list = Vec::new();
            append_list(&mut list, &mut vec![1, 2]);
            let mut long: Vec<u32> = (3..20_000).collect();
            append_list(&mut list, &mut long);
            assert!(long.is_empty() && long.capacity() >= 19_997);
            append_list(&mut list, &mut Vec::new());
            assert_eq!(list, (1..20_000).collect::<Vec<u32>>());
            append_mapped(&mut list, &mut (0..10_000).collect(), |k: u32| k * 2);
            assert_eq!(list.len(), 29_999);
            assert_eq!(list[19_999..20_002], [0, 2, 4]);
            assert_eq!(list.last(), Some(&19_998));
        });
    }
}
