//! The Whitted tracer: samples through the film and their eye rays, each batch of
//! them (a tile's) traced by the wavefront ([`super::wavefront`]) and shaded by
//! [`super::shade`]. Every step is reported to a [`Recorder`] (a plain render's
//! records the counts alone, and compiles to the tracer without hooks).

use super::record::Recorder;
use super::wavefront::Eye;
use super::{GlobalIllumination, RayCounts, RayGen, Region, RenderSettings, area};
use crate::accel::Accel;
use crate::math::{Vec3, hash, hash_unit as unit};
use crate::scene::Scene;

/// The Whitted tracer over one scene and backend, with a render's settings.
pub(super) struct Tracer<'a, A: Accel> {
    pub(super) scene: &'a Scene,
    pub(super) accel: &'a A,
    pub(super) max_depth: u32,
    spp: u32,
    /// Emitting triangles, sampled as area lights.
    pub(super) area_lights: Vec<area::AreaLight>,
    /// Shadow rays per area light: `area_strata²` (`area_strata` per axis).
    pub(super) area_strata: u32,
    /// Two-pass mode: the diffuse term of the surfaces this solution covers.
    pub(super) gi: Option<&'a dyn GlobalIllumination>,
    /// Hall & Greenberg's adaptive tree depth: no secondary ray whose weight (largest
    /// channel) is below this; 0 = off.
    bailout: f32,
    /// Skip work that cannot change the image (see [`RenderSettings::skip`]).
    pub(super) skip: bool,
    /// SPD testing mode: cast the rays the SPD's reference casts (see
    /// [`Tracer::secondary`]).
    pub(super) spd: bool,
}

/// The identity of an eye ray's path through the ray tree, from its film position:
/// it seeds the area-light jitter at every hit of the tree (see [`children`]). Film
/// positions are exact, whichever backend traces the rays, so the noise is the same on
/// both (a seed from the hit point would change with its last bit).
#[inline]
fn eye_path(px: f32, py: f32) -> u32 {
    hash(px.to_bits() ^ hash(py.to_bits()))
}

/// The paths of the reflection and refraction rays spawned on `path`.
#[inline]
pub(super) fn children(path: u32) -> (u32, u32) {
    (hash(path ^ 0x2545_f491), hash(path ^ 0x9e37_79b9))
}

/// The pixels of tile `t` in blocks of [`BLOCK_W`]×[`BLOCK_H`], the blocks row by row
/// and the pixels of a block row by row (blocks cut by the tile's edge are smaller).
fn block_order(t: Region) -> Vec<(u32, u32)> {
    let mut order = Vec::with_capacity(((t.x1 - t.x0) * (t.y1 - t.y0)) as usize);
    for by in (t.y0..t.y1).step_by(BLOCK_H as usize) {
        for bx in (t.x0..t.x1).step_by(BLOCK_W as usize) {
            for j in by..(by + BLOCK_H).min(t.y1) {
                for i in bx..(bx + BLOCK_W).min(t.x1) {
                    order.push((i, j));
                }
            }
        }
    }
    order
}

/// The block of pixels whose eye rays are cast together: a packet of 8.
const BLOCK_W: u32 = 4;
/// See [`BLOCK_W`].
const BLOCK_H: u32 = 2;

/// Van der Corput radical inverse in base 2.
#[inline]
fn radical_inverse(i: u32) -> f32 {
    unit(i.reverse_bits())
}

impl<'a, A: Accel> Tracer<'a, A> {
    pub(super) fn new(scene: &'a Scene, accel: &'a A, s: &RenderSettings) -> Self {
        Tracer {
            scene,
            accel,
            max_depth: s.max_depth.max(1),
            spp: s.spp.max(1),
            area_lights: area::collect(scene),
            area_strata: s.area_strata,
            gi: None,
            bailout: if s.bailout.is_finite() {
                s.bailout.max(0.0)
            } else {
                0.0
            },
            skip: s.skip,
            spd: s.spd,
        }
    }

    /// Take the diffuse term of the surfaces `gi` covers from it (two-pass).
    pub(super) fn with_gi(mut self, gi: Option<&'a dyn GlobalIllumination>) -> Self {
        self.gi = gi;
        self
    }

    /// The film positions of the samples of grid position `(i, j)`: its centre with
    /// one sample, else `spp` stratified samples (a Hammersley set rotated per pixel by
    /// a hash of its coordinates, so the result does not depend on the thread
    /// schedule).
    fn samples(&self, i: u32, j: u32) -> impl Iterator<Item = (f32, f32)> {
        let n = self.spp;
        let (ox, oy) = if n == 1 {
            (0.0, 0.0)
        } else {
            let seed = hash(i.wrapping_mul(0x9e37_79b9) ^ hash(j));
            (unit(hash(seed)), unit(hash(seed ^ 0x5bd1_e995)))
        };
        (0..n).map(move |s| {
            if n == 1 {
                return (i as f32 + 0.5, j as f32 + 0.5);
            }
            let sx = ((s as f32 + ox) / n as f32).fract();
            let sy = (radical_inverse(s) + oy).fract();
            (i as f32 + sx, j as f32 + sy)
        })
    }

    /// The values of the grid positions of tile `t`, row by row, given to `out`: each
    /// the mean of its samples (its centre alone with one sample). The tile is one
    /// batch of the wavefront; with one sample per pixel its eye rays are cast in
    /// packets of 4×2 pixels ([`Accel::intersect_coherent`]).
    pub(super) fn tile<R: Recorder>(
        &self,
        raygen: &RayGen,
        t: Region,
        out: &mut impl FnMut(Vec3),
        rec: &mut R,
    ) {
        let width = t.x1 - t.x0;
        let positions: Vec<(u32, u32)> = (t.y0..t.y1)
            .flat_map(|j| (t.x0..t.x1).map(move |i| (i, j)))
            .collect();
        let slot = |i: u32, j: u32| (j - t.y0) * width + (i - t.x0);
        // With one sample, the eyes in blocks of 4×2 pixels (a packet of 8 is one
        // block: rays closer together than a row's 8 visit fewer nodes).
        let order = if self.spp == 1 {
            block_order(t)
        } else {
            positions.clone()
        };
        let eyes: Vec<Eye> = if self.spp == 1 {
            // The pixel centres, without the samples' iterator.
            let centre = |i: u32| i as f32 + 0.5;
            let eye_at = |&(i, j): &(u32, u32)| eye(raygen, centre(i), centre(j), slot(i, j));
            order.iter().map(eye_at).collect()
        } else {
            order
                .iter()
                .flat_map(|&(i, j)| {
                    self.samples(i, j)
                        .map(move |(x, y)| eye(raygen, x, y, slot(i, j)))
                })
                .collect()
        };
        let mut values = Vec::new();
        self.trace_batch(&eyes, &positions, self.spp == 1, rec, &mut values);
        // The eyes of each position: `spp` in a row in sample order, or with one
        // sample the eye of each slot.
        let mut eye_of = vec![0; positions.len()];
        if self.spp == 1 {
            for (k, e) in eyes.iter().enumerate() {
                eye_of[e.slot as usize] = k;
            }
        }
        let n = self.spp as usize;
        for (slot, &(i, j)) in positions.iter().enumerate() {
            rec.position(i, j);
            let v = if n == 1 {
                values[eye_of[slot]]
            } else {
                self.mean(&values[slot * n..(slot + 1) * n])
            };
            rec.position_end(v);
            out(v);
        }
    }

    /// The value of a position from its `spp` samples' values.
    fn mean(&self, values: &[Vec3]) -> Vec3 {
        let mut sum = Vec3::ZERO;
        for &v in values {
            sum += v;
        }
        sum / self.spp as f32
    }

    /// The value of the eye ray through continuous film position `(px, py)`.
    pub(super) fn sample<R: Recorder>(
        &self,
        raygen: &RayGen,
        px: f32,
        py: f32,
        rec: &mut R,
    ) -> Vec3 {
        let position = [(px as u32, py as u32)];
        let eyes = [eye(raygen, px, py, 0)];
        let mut value = Vec::with_capacity(1);
        self.trace_batch(&eyes, &position, false, rec, &mut value);
        value[0]
    }

    /// Whether a secondary ray of accumulated `weight` is worth casting.
    #[inline]
    pub(super) fn worth(&self, weight: Vec3, counts: &mut RayCounts) -> bool {
        if weight.max_element() < self.bailout {
            counts.bailed += 1;
            return false;
        }
        true
    }
}

/// The eye ray through film position `(px, py)`, for position slot `slot`.
fn eye(raygen: &RayGen, px: f32, py: f32, slot: u32) -> Eye {
    Eye {
        ray: raygen.ray(px, py),
        slot,
        path: eye_path(px, py),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn block_order_visits_every_pixel_of_a_tile_once_in_blocks() {
        for (w, h) in [(16, 16), (5, 3), (1, 1), (7, 1), (4, 2)] {
            let t = Region {
                x0: 10,
                y0: 20,
                x1: 10 + w,
                y1: 20 + h,
            };
            let order = block_order(t);
            let mut sorted = order.clone();
            sorted.sort_by_key(|&(i, j)| (j, i));
            sorted.dedup();
            assert_eq!(sorted.len(), (w * h) as usize);
            assert!(
                sorted
                    .iter()
                    .all(|&(i, j)| (10..10 + w).contains(&i) && (20..20 + h).contains(&j))
            );
            if (w, h) == (16, 16) {
                // The first packet of 8 is the 4×2 block at the tile's corner.
                let first: Vec<_> = order[..8].to_vec();
                let block: Vec<_> = (20..22)
                    .flat_map(|j| (10..14).map(move |i| (i, j)))
                    .collect();
                assert_eq!(first, block);
            }
        }
    }

    #[test]
    fn radical_inverse_is_stratified() {
        let mut v: Vec<f32> = (0..8).map(radical_inverse).collect();
        v.sort_by(f32::total_cmp);
        for (k, x) in v.iter().enumerate() {
            assert!((*x - k as f32 / 8.0).abs() < 1e-6);
        }
    }
}
