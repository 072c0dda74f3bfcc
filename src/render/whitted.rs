//! The Whitted tracer: samples through the film, eye rays (cast a tile at a time with
//! one sample per pixel), and each ray followed to the surface it is shaded at, through
//! the surfaces of nested media it passes; the shading itself is in [`super::shade`].
//! Every step is reported to a [`Recorder`] (a plain render's records the counts
//! alone, and compiles to the tracer without hooks).

use super::media::{MAX_SKIPS, Media};
use super::record::{Met, RayKind, Recorder, Traced};
use super::{GlobalIllumination, RayCounts, RayGen, Region, RenderSettings, area};
use crate::accel::{Accel, Hit};
use crate::math::{Ray, Vec3, hash, hash_unit as unit, offset_ray_origin};
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
    gi: Option<&'a dyn GlobalIllumination>,
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

    /// The value of sample-grid position `(i, j)`: its centre with one sample, else the
    /// mean of `spp` stratified samples (a Hammersley set rotated per pixel by a hash
    /// of its coordinates, so the result does not depend on the thread schedule).
    pub(super) fn pixel<R: Recorder>(&self, raygen: &RayGen, i: u32, j: u32, rec: &mut R) -> Vec3 {
        if self.spp == 1 {
            return self.eye(raygen, i as f32 + 0.5, j as f32 + 0.5, rec);
        }
        let seed = hash(i.wrapping_mul(0x9e37_79b9) ^ hash(j));
        let (ox, oy) = (unit(hash(seed)), unit(hash(seed ^ 0x5bd1_e995)));
        let n = self.spp;
        let mut sum = Vec3::ZERO;
        for s in 0..n {
            let sx = ((s as f32 + ox) / n as f32).fract();
            let sy = (radical_inverse(s) + oy).fract();
            sum += self.eye(raygen, i as f32 + sx, j as f32 + sy, rec);
        }
        sum / n as f32
    }

    /// The values of the grid positions of tile `t`, row by row, given to `out`: as
    /// [`Tracer::pixel`] gives them, but with one sample per pixel the tile's eye rays
    /// are cast together first (packets on backends that have them; see
    /// [`Accel::intersect_coherent`]), then each is shaded from its hit.
    pub(super) fn tile<R: Recorder>(
        &self,
        raygen: &RayGen,
        t: Region,
        out: &mut impl FnMut(Vec3),
        rec: &mut R,
    ) {
        if self.spp != 1 {
            for j in t.y0..t.y1 {
                for i in t.x0..t.x1 {
                    rec.position(i, j);
                    let v = self.pixel(raygen, i, j, rec);
                    rec.position_end(v);
                    out(v);
                }
            }
            return;
        }
        // Cast in blocks of 4×2 pixels (a packet of 8 is one block: rays closer
        // together than a row's 8 visit fewer nodes), shaded row by row.
        let order = block_order(t);
        let rays: Vec<Ray> = order
            .iter()
            .map(|&(i, j)| raygen.ray(i as f32 + 0.5, j as f32 + 0.5))
            .collect();
        let mut cast = vec![None; rays.len()];
        rec.coherent(true, rays.len());
        self.accel.intersect_coherent(&rays, &mut cast);
        rec.coherent(false, rays.len());
        let width = (t.x1 - t.x0) as usize;
        let mut row_major = vec![0; rays.len()];
        for (k, &(i, j)) in order.iter().enumerate() {
            row_major[(j - t.y0) as usize * width + (i - t.x0) as usize] = k;
        }
        for k in row_major {
            let (ray, hit) = (&rays[k], cast[k]);
            let (x, y) = (order[k].0 as f32 + 0.5, order[k].1 as f32 + 0.5);
            rec.position(x as u32, y as u32);
            rec.counts().eye += 1;
            rec.ray(&Traced::eye(ray));
            let path = eye_path(x, y);
            let v = self.trace_from(ray, hit, 1, path, Media::AIR, Vec3::ONE, rec);
            rec.ray_end(v);
            rec.position_end(v);
            out(v);
        }
    }

    /// The value of the eye ray through continuous film position `(px, py)`.
    pub(super) fn sample<R: Recorder>(
        &self,
        raygen: &RayGen,
        px: f32,
        py: f32,
        rec: &mut R,
    ) -> Vec3 {
        self.eye(raygen, px, py, rec)
    }

    /// The value of the eye ray through film position `(px, py)`.
    fn eye<R: Recorder>(&self, raygen: &RayGen, px: f32, py: f32, rec: &mut R) -> Vec3 {
        rec.counts().eye += 1;
        let path = eye_path(px, py);
        let ray = raygen.ray(px, py);
        rec.ray(&Traced::eye(&ray));
        let v = self.trace(&ray, 1, path, Media::AIR, Vec3::ONE, rec);
        rec.ray_end(v);
        v
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

    /// Radiance along `ray` at ray-tree depth `depth` (the eye ray is depth 1), which
    /// travels inside `media`; `weight` is the product of the coefficients between this
    /// ray and the eye (what its radiance is multiplied by in the pixel).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn trace<R: Recorder>(
        &self,
        ray: &Ray,
        depth: u32,
        path: u32,
        media: Media,
        weight: Vec3,
        rec: &mut R,
    ) -> Vec3 {
        let first = self.accel.intersect(ray);
        self.trace_from(ray, first, depth, path, media, weight, rec)
    }

    /// [`Tracer::trace`] given the ray's nearest hit, `first`.
    #[allow(clippy::too_many_arguments)]
    fn trace_from<R: Recorder>(
        &self,
        ray: &Ray,
        first: Option<Hit>,
        depth: u32,
        path: u32,
        media: Media,
        weight: Vec3,
        rec: &mut R,
    ) -> Vec3 {
        let scene = self.scene;
        let mut ray = *ray;
        let mut media = media;
        let mut next = first;
        // Surfaces of lower-priority media inside a higher-priority one are skipped
        // (nested dielectrics): the ray goes on through them, at most this many times.
        let mut skips = 0;
        loop {
            let Some(hit) = next else {
                let sky = scene.escape(ray.dir);
                rec.miss(sky);
                return sky;
            };
            let surf = scene.surface_of(&hit, &ray, self.accel.exact_triangle_hits());
            let m = &scene.materials[surf.material as usize];
            let d = ray.dir.normalize();
            let entering = surf.point.ng.dot(d) < 0.0;
            let met = Met {
                hit: &hit,
                surf: &surf,
                entering,
                media: &media,
            };
            if m.t > 0.0
                && skips < MAX_SKIPS
                && media.is_false_boundary(scene, surf.material, entering)
            {
                rec.pass_through(&met);
                skips += 1;
                media = if entering {
                    media.enter(surf.material)
                } else {
                    media.leave(surf.material)
                };
                let ng = if entering {
                    -surf.point.ng
                } else {
                    surf.point.ng
                };
                ray = Ray::new(
                    offset_ray_origin(surf.point.p, surf.point.err, ng, d),
                    ray.dir,
                );
                next = self.accel.intersect(&ray);
                continue;
            }
            rec.hit(&met);
            if depth == 1 {
                rec.counts().eye_hit += 1;
            }
            let gi = self.gi.and_then(|g| g.radiosity_at(&hit, surf.point.p, d));
            let radiance = self.shade(&surf, d, entering, depth, path, media, weight, gi, rec);
            return saturate(radiance, rec.counts());
        }
    }
}

impl<'a> Traced<'a> {
    /// An eye ray.
    #[inline(always)]
    fn eye(ray: &'a Ray) -> Self {
        Traced {
            kind: RayKind::Eye,
            depth: 1,
            ray,
            local_weight: Vec3::ONE,
            weight: Vec3::ONE,
            discarded: false,
        }
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
