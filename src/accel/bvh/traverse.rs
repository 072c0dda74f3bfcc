//! The walk down the 4-wide tree: one node's four slab tests at once, its children
//! taken nearest entry first for nearest-hit queries (in slot order for any-hit ones),
//! the rest on a stack that lives in registers and one small array.

use super::leaf::Leaf;
use super::wide::{LEAF, Node4};
use crate::math::Ray;
use glam::Vec4;

/// Far distances are widened by this factor so that rounding never drops a box a ray
/// touches (the same bound as [`Aabb::hit`](crate::math::Aabb::hit)).
const FAR_SCALE: f32 = 1.0 + 2.0 * crate::math::gamma(3);

/// What a leaf visit tells the traversal.
pub(super) enum Visit {
    /// Go on, looking for hits nearer than this.
    Continue(f32),
    /// Stop: the answer is known.
    Stop,
}

/// A ray prepared for the slab tests: origin and reciprocal direction broadcast to four
/// lanes, and for each axis which of a node's two planes it enters through.
struct SlabRay {
    org: [Vec4; 3],
    inv: [Vec4; 3],
    /// `inv` widened by [`FAR_SCALE`], for the exit distances.
    inv_far: [Vec4; 3],
    /// Per axis, the index in [`Node4::planes`] of the plane the ray enters a box
    /// through (the lower one for a positive direction), and of the one it leaves by.
    near: [usize; 3],
    far: [usize; 3],
    tmin: Vec4,
}

impl SlabRay {
    #[inline(always)]
    fn new(ray: &Ray) -> SlabRay {
        let inv = ray.dir.recip().to_array();
        let org = ray.org.to_array();
        SlabRay {
            org: org.map(Vec4::splat),
            inv: inv.map(Vec4::splat),
            // Rounding `inv × FAR_SCALE` once here widens the exit distance by at least
            // as much as multiplying each distance by it (FAR_SCALE is 6 ulps above 1,
            // the bound needs 3), so boxes are as conservative as with the product.
            inv_far: inv.map(|i| Vec4::splat(i * FAR_SCALE)),
            near: [0, 1, 2].map(|a| if inv[a] < 0.0 { 3 + a } else { a }),
            far: [0, 1, 2].map(|a| if inv[a] < 0.0 { a } else { 3 + a }),
            tmin: Vec4::splat(ray.tmin),
        }
    }

    /// The slots of `node` whose boxes the ray enters before `tmax` (bit `i` for slot
    /// `i`), with the entry distances.
    #[inline(always)]
    fn hit(&self, node: &Node4, tmax: f32) -> (u32, [f32; 4]) {
        let mut tn = self.tmin;
        let mut tf = Vec4::splat(tmax);
        for a in 0..3 {
            let lo = Vec4::from_array(node.planes[self.near[a]]);
            let hi = Vec4::from_array(node.planes[self.far[a]]);
            // `max`/`min` keep their argument when the distance is NaN (a ray in a
            // slab's plane with a zero direction component), leaving the interval as it
            // was (x86; on other targets such a ray may miss the box).
            tn = ((lo - self.org[a]) * self.inv[a]).max(tn);
            tf = ((hi - self.org[a]) * self.inv_far[a]).min(tf);
        }
        (tn.cmple(tf).bitmask() & node.used, tn.to_array())
    }
}

/// The traversal stack: node references with their entry distances. Most walks need a
/// few entries; the array holds [`Stack::INLINE`] and a heap vector takes any more, so
/// no tree is too deep for it and no ray pays for a large array it does not use.
struct Stack {
    inline: [(u32, f32); Stack::INLINE],
    len: usize,
    spill: Vec<(u32, f32)>,
}

impl Stack {
    const INLINE: usize = 16;

    #[inline(always)]
    fn new() -> Stack {
        Stack {
            inline: [(0, 0.0); Stack::INLINE],
            len: 0,
            spill: Vec::new(),
        }
    }

    #[inline(always)]
    fn push(&mut self, entry: (u32, f32)) {
        if self.len < Stack::INLINE {
            self.inline[self.len] = entry;
        } else {
            self.spill.push(entry);
        }
        self.len += 1;
    }

    #[inline(always)]
    fn pop(&mut self) -> Option<(u32, f32)> {
        self.len = self.len.checked_sub(1)?;
        if self.len < Stack::INLINE {
            Some(self.inline[self.len])
        } else {
            self.spill.pop()
        }
    }
}

/// Take the children of a node in `mask` (with entry distances `tn`): returns the one
/// to visit next and pushes the others so that they come off the stack in visiting
/// order. With `ORDERED`, nearest entry first (slot order between equal entries);
/// otherwise in slot order.
#[inline(always)]
fn take_children<const ORDERED: bool>(
    node: &Node4,
    mut mask: u32,
    tn: &[f32; 4],
    stack: &mut Stack,
) -> u32 {
    let first = mask.trailing_zeros() as usize;
    mask &= mask - 1;
    if mask == 0 {
        return node.child[first];
    }
    let second = mask.trailing_zeros() as usize;
    mask &= mask - 1;
    if ORDERED && mask == 0 {
        let (near, far) = if tn[second] < tn[first] {
            (second, first)
        } else {
            (first, second)
        };
        stack.push((node.child[far], tn[far]));
        return node.child[near];
    }
    let mut hits = [(0u32, 0f32); 4];
    hits[0] = (node.child[first], tn[first]);
    hits[1] = (node.child[second], tn[second]);
    let mut k = 2;
    while mask != 0 {
        let i = mask.trailing_zeros() as usize;
        mask &= mask - 1;
        hits[k] = (node.child[i], tn[i]);
        k += 1;
    }
    if ORDERED {
        // Insertion sort, nearest first; stable, so equal entries keep slot order.
        for i in 1..k {
            let mut j = i;
            while j > 0 && hits[j].1 < hits[j - 1].1 {
                hits.swap(j, j - 1);
                j -= 1;
            }
        }
    }
    for &h in hits[1..k].iter().rev() {
        stack.push(h);
    }
    hits[0].0
}

/// From node reference `cur`, go down to the next leaf the ray reaches before `tmax`
/// (pushing the siblings to visit later), popping the stack whenever a node is missed;
/// `None` when the stack runs out. Kept apart from the leaf visits so that the node
/// tests run in a tight loop that holds the ray in registers.
#[inline(always)]
fn next_leaf<const ORDERED: bool>(
    nodes: &[Node4],
    slab: &SlabRay,
    mut cur: u32,
    tmax: f32,
    stack: &mut Stack,
) -> Option<u32> {
    loop {
        if cur & LEAF != 0 {
            return Some(cur);
        }
        let node = &nodes[cur as usize];
        let (mask, tn) = slab.hit(node, tmax);
        cur = if mask != 0 {
            take_children::<ORDERED>(node, mask, &tn, stack)
        } else {
            pop::<ORDERED>(stack, tmax)?
        };
    }
}

/// The nearest pushed child that may still hold a hit before `tmax`.
#[inline(always)]
fn pop<const ORDERED: bool>(stack: &mut Stack, tmax: f32) -> Option<u32> {
    loop {
        let (next, tentry) = stack.pop()?;
        if !ORDERED || tentry <= tmax {
            return Some(next);
        }
    }
}

/// Walk `nodes`, calling `leaf` for every leaf the ray reaches with the current far end
/// of the interval. With `ORDERED`, the children a node's box tests hit are visited
/// nearest entry first, the others pushed with their entry distance and dropped when
/// they come off the stack if a hit nearer than that was found meanwhile. Without it
/// (any-hit queries, where the first hit ends the walk) they are visited in slot order.
#[inline(always)]
pub(super) fn traverse<const ORDERED: bool>(
    nodes: &[Node4],
    leaves: &[Leaf],
    ray: &Ray,
    mut leaf: impl FnMut(&Leaf, f32) -> Visit,
) {
    if nodes.is_empty() {
        return;
    }
    let slab = SlabRay::new(ray);
    let mut tmax = ray.tmax;
    let mut stack = Stack::new();
    let mut cur = 0u32;
    while let Some(found) = next_leaf::<ORDERED>(nodes, &slab, cur, tmax, &mut stack) {
        match leaf(&leaves[(found & !LEAF) as usize], tmax) {
            Visit::Continue(t) => tmax = t,
            Visit::Stop => return,
        }
        let Some(next) = pop::<ORDERED>(&mut stack, tmax) else {
            return;
        };
        cur = next;
    }
}
