//! The wavefront's records: the state of a path waiting in a depth's queue (what a
//! recursive tracer passes down as arguments), and the ray tree of a batch as nodes
//! with parent links, whose radiance is put together bottom-up once every ray of the
//! batch was cast.
//!
//! The tree evaluates a node exactly as a recursion would return it: its local light,
//! plus the refraction's weighted radiance, plus the reflection's, saturated to f32's
//! range (see [`saturate`]); a miss is the background, unsaturated. The sums are taken
//! in the same order, so the wavefront's pixels are the recursion's, bit for bit.

use super::RayCounts;
use super::media::Media;
use super::record::Recorder;
use crate::math::{Ray, Vec3};

/// A ray in a depth's queue, with the state of its path.
#[derive(Clone, Copy, Debug)]
pub(super) struct PathState {
    /// The ray.
    pub ray: Ray,
    /// Its node in the batch's [`Tree`].
    pub node: u32,
    /// The sample-grid position it is for, as an index into the batch's positions.
    pub slot: u32,
    /// Its depth in the ray tree (the eye ray is 1).
    pub depth: u32,
    /// The identity of its path through the ray tree (the area lights' jitter seed).
    pub path: u32,
    /// The media it travels in.
    pub media: Media,
    /// The product of the weights between it and the eye: what its radiance is
    /// multiplied by in the sample.
    pub weight: Vec3,
    /// Surfaces of lower-priority media it went through so far (see
    /// [`super::media::MAX_SKIPS`]).
    pub skips: u32,
}

/// A ray of the batch's tree: what it brings back before its children, and its
/// children with their weights.
#[derive(Clone, Copy, Debug)]
pub(super) struct Node {
    /// The local light of its hit (every term, once its shadow rays were cast), or the
    /// background when it missed.
    pub local: Vec3,
    /// It left the scene: its radiance is `local`, not saturated.
    pub missed: bool,
    /// The refraction ray and its weight `T × filter`.
    pub refraction: Option<(u32, Vec3)>,
    /// The reflection ray and its weight, when its light is used (a discarded
    /// reflection is cast but not linked).
    pub reflection: Option<(u32, f32)>,
}

impl Node {
    const NEW: Node = Node {
        local: Vec3::ZERO,
        missed: false,
        refraction: None,
        reflection: None,
    };
}

/// The ray tree of a batch: node `k` is the `k`-th ray spawned, children after
/// their parents.
#[derive(Debug, Default)]
pub(super) struct Tree {
    pub nodes: Vec<Node>,
}

impl Tree {
    /// A new node; its number.
    #[inline]
    pub fn push(&mut self) -> u32 {
        self.nodes.push(Node::NEW);
        (self.nodes.len() - 1) as u32
    }

    /// Node `k`.
    #[inline]
    pub fn node(&mut self, k: u32) -> &mut Node {
        &mut self.nodes[k as usize]
    }

    /// The radiance of every node into `value` (`value[k]` for node `k`), children
    /// first, each told to `rec` as it is known.
    pub fn resolve<R: Recorder>(&self, rec: &mut R, value: &mut Vec<Vec3>) {
        value.clear();
        value.resize(self.nodes.len(), Vec3::ZERO);
        for (k, node) in self.nodes.iter().enumerate().rev() {
            let v = if node.missed {
                node.local
            } else {
                let mut c = node.local;
                if let Some((child, w)) = node.refraction {
                    c += w * value[child as usize];
                }
                if let Some((child, w)) = node.reflection {
                    c += w * value[child as usize];
                }
                saturate(c, rec.counts())
            };
            value[k] = v;
            rec.ray_end(k as u32, v);
        }
    }
}

/// A ray's radiance as f32 can hold it. Finite inputs can still overflow (a light of
/// 10³⁸ on a white surface, weights above 1 multiplied down a deep ray tree), and an
/// infinite channel times a zero weight further up the tree would be NaN. So an
/// infinite channel saturates at ±`f32::MAX` and a NaN one (∞ − ∞, only possible with
/// negative NFF colours) counts as 0; either is counted in [`RayCounts::saturated`].
/// Finite radiance passes unchanged.
#[inline]
pub(super) fn saturate(c: Vec3, counts: &mut RayCounts) -> Vec3 {
    if c.is_finite() {
        return c;
    }
    counts.saturated += 1;
    let f = |x: f32| {
        if x.is_nan() {
            0.0
        } else {
            x.clamp(-f32::MAX, f32::MAX)
        }
    };
    Vec3::new(f(c.x), f(c.y), f(c.z))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_tree_resolves_as_the_recursion_returns() {
        // Eye (0) hits glass: refraction (1) and reflection (2); the refraction hits a
        // mirror whose reflection (3) misses.
        let mut t = Tree::default();
        for _ in 0..4 {
            t.push();
        }
        let (l0, l1, l2, sky) = (
            Vec3::new(0.1, 0.2, 0.3),
            Vec3::new(0.5, 0.25, 0.125),
            Vec3::new(0.7, 0.0, 0.1),
            Vec3::new(0.2, 0.4, 0.6),
        );
        let wt = Vec3::new(0.9, 0.8, 0.7);
        *t.node(0) = Node {
            local: l0,
            missed: false,
            refraction: Some((1, wt)),
            reflection: Some((2, 0.3)),
        };
        *t.node(1) = Node {
            local: l1,
            missed: false,
            refraction: None,
            reflection: Some((3, 0.6)),
        };
        t.node(2).local = l2;
        *t.node(3) = Node {
            local: sky,
            missed: true,
            ..Node::NEW
        };
        let mut counts = RayCounts::default();
        let mut v = Vec::new();
        t.resolve(&mut counts, &mut v);
        let refracted = l1 + 0.6 * sky;
        let expected = l0 + wt * refracted + 0.3 * l2;
        assert_eq!(v[3], sky);
        assert_eq!(v[1], refracted);
        assert_eq!(v[0], expected);
        assert_eq!(counts.saturated, 0);
    }

    #[test]
    fn overflowing_radiance_saturates_and_is_counted() {
        let mut t = Tree::default();
        t.push();
        t.push();
        *t.node(0) = Node {
            local: Vec3::new(f32::MAX, 0.0, 1.0),
            missed: false,
            refraction: None,
            reflection: Some((1, 1.0)),
        };
        t.node(1).local = Vec3::new(f32::MAX, 0.0, 0.0);
        let mut counts = RayCounts::default();
        let mut v = Vec::new();
        t.resolve(&mut counts, &mut v);
        assert_eq!(v[0], Vec3::new(f32::MAX, 0.0, 1.0));
        assert_eq!(counts.saturated, 1);
    }
}
