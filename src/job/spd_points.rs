//! [`PointCache`]: the scene points (`super::spd_prims::scene_point`) of the last few
//! distinct points a thread rounded, by their bits, so that a point shared by
//! neighbouring polygons (the corners of a height field's cells, of a tetrahedron's
//! faces, of a gear's side quads) is rounded as printed once rather than once per
//! polygon. The point is a function of its numbers and the frame's origin alone, so a
//! remembered one is the one rounding would give.

use super::spd_prims::scene_point;
use crate::math::{DVec3, Vec3};
use glam::DVec3 as D;

/// Points remembered (a power of two).
const SLOTS: usize = 16;

/// The last points rounded in one frame, one per slot by a hash of their bits.
#[derive(Debug, Default)]
pub(crate) struct PointCache {
    /// The frame's origin the points were rounded in.
    origin: Option<DVec3>,
    slots: [Option<([u64; 3], Option<Vec3>)>; SLOTS],
}

impl PointCache {
    /// `scene_point(origin, p)`, remembered.
    #[inline]
    pub fn point(&mut self, origin: DVec3, p: D) -> Option<Vec3> {
        if self.origin.map(bits) != Some(bits(origin)) {
            *self = PointCache {
                origin: Some(origin),
                ..PointCache::default()
            };
        }
        let key = bits(p);
        let slot = &mut self.slots[slot_of(&key)];
        match *slot {
            Some((k, point)) if k == key => point,
            _ => {
                let point = scene_point(origin, p);
                *slot = Some((key, point));
                point
            }
        }
    }
}

/// The bits of `v`'s numbers (`-0` is not `0`, a NaN is itself).
#[inline]
fn bits(v: D) -> [u64; 3] {
    v.to_array().map(f64::to_bits)
}

/// The slot of a point whose numbers' bits are `key`.
#[inline]
fn slot_of(key: &[u64; 3]) -> usize {
    let mixed = key[0] ^ key[1].rotate_left(21) ^ key[2].rotate_left(42);
    (mixed.wrapping_mul(0x9e37_79b9_7f4a_7c15) >> (64 - SLOTS.trailing_zeros())) as usize
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Points remembered or not, in any order, in one frame and then another, with
    /// signed zeros, NaNs and points out of range: what rounding each gives.
    #[test]
    fn remembered_points_are_the_points_rounding_gives() {
        let mut cache = PointCache::default();
        let points: Vec<D> = (0..200)
            .map(|k| {
                let k = k % 37;
                D::new(k as f64 * 0.1, (k % 5) as f64 / 3.0, -0.0)
            })
            .chain([
                D::new(f64::NAN, 0.0, 0.0),
                D::new(1e30, 0.0, 0.0),
                D::new(0.0, 0.0, 0.0),
                D::new(-0.0, 0.0, 0.0),
            ])
            .collect();
        for origin in [D::ZERO, D::new(1.0, 2.0, 3.0), D::ZERO] {
            for &p in points.iter().chain(points.iter().rev()) {
                let want = scene_point(origin, p).map(|v| v.to_array().map(f32::to_bits));
                let got = cache
                    .point(origin, p)
                    .map(|v| v.to_array().map(f32::to_bits));
                assert_eq!(got, want, "{p:?} in the frame of {origin:?}");
            }
        }
    }
}
