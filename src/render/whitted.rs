//! Whitted shading: ambient, Phong light from point lights with shadow rays, emission
//! and area lights, mirror reflection and Snell refraction through nested media. The
//! shading formula is in docs/architecture.md ("NFF semantics") and docs/nff.md.

use super::{GlobalIllumination, RayGen, Region, RenderSettings, area};
use crate::accel::{Accel, Hit};
use crate::math::{
    Ray, RayOrigins, Vec3, hash, hash_unit as unit, next_float_down, offset_ray_origin,
};
use crate::scene::{Light, Material, Scene, Surface};

/// Rays cast, by type.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RayCounts {
    /// Eye (primary) rays.
    pub eye: u64,
    /// Eye rays that hit something.
    pub eye_hit: u64,
    /// Reflection rays.
    pub reflection: u64,
    /// Refraction (transmission) rays.
    pub refraction: u64,
    /// Shadow rays.
    pub shadow: u64,
    /// Total internal reflection events (no refraction ray was cast).
    pub tir: u64,
    /// Reflection or refraction rays not spawned because their accumulated weight was
    /// below the `--bailout` threshold.
    pub bailed: u64,
    /// Shadow rays not cast: the light is behind the shading normal or sends nothing.
    pub skipped_shadow: u64,
    /// Reflection rays not cast at hits on non-reflective (`Ks = 0`) surfaces below
    /// the depth limit.
    pub skipped_reflection: u64,
    /// Rays whose radiance overflowed f32 and was saturated (an infinite channel
    /// clamped to ±`f32::MAX`, a NaN one set to 0): the scene's colours, intensities
    /// or weights are too large. 0 for sane scenes.
    pub saturated: u64,
}

impl RayCounts {
    /// All rays cast.
    pub fn total(&self) -> u64 {
        self.eye + self.reflection + self.refraction + self.shadow
    }
}

impl std::ops::AddAssign for RayCounts {
    fn add_assign(&mut self, o: Self) {
        self.eye += o.eye;
        self.eye_hit += o.eye_hit;
        self.reflection += o.reflection;
        self.refraction += o.refraction;
        self.shadow += o.shadow;
        self.tir += o.tir;
        self.bailed += o.bailed;
        self.skipped_shadow += o.skipped_shadow;
        self.skipped_reflection += o.skipped_reflection;
        self.saturated += o.saturated;
    }
}

pub(super) struct Tracer<'a, A: Accel> {
    scene: &'a Scene,
    accel: &'a A,
    max_depth: u32,
    spp: u32,
    /// Emitting triangles, sampled as area lights.
    area_lights: Vec<area::AreaLight>,
    /// Shadow rays per area light: `area_samples²`.
    area_samples: u32,
    /// Two-pass mode: the diffuse term of the surfaces this solution covers.
    gi: Option<&'a dyn GlobalIllumination>,
    /// Hall & Greenberg's adaptive tree depth: no secondary ray whose weight (largest
    /// channel) is below this; 0 = off.
    bailout: f32,
    /// Skip work that cannot change the image (see [`RenderSettings::skip`]).
    skip: bool,
    /// SPD testing mode: cast the rays the SPD's reference casts (see
    /// [`Tracer::secondary`]).
    spd: bool,
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
fn children(path: u32) -> (u32, u32) {
    (hash(path ^ 0x2545_f491), hash(path ^ 0x9e37_79b9))
}

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
fn saturate(c: Vec3, counts: &mut RayCounts) -> Vec3 {
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

/// Mirror `d` about the unit normal `n`.
#[inline]
fn reflect(d: Vec3, n: Vec3) -> Vec3 {
    d - n * (2.0 * d.dot(n))
}

/// Snell's law: the refracted direction of unit `d` through a surface with unit normal
/// `n` facing the incoming ray, for `eta = n₁/n₂`; `None` on total internal reflection.
///
/// For any `eta` between 10⁻⁶ and 10⁶ (the ratio of two indices of
/// [`range::IOR_RANGE`](crate::scene::range::IOR_RANGE), which every transmitting
/// material's index lies in) the result is a finite unit vector: `eta²` stays far inside
/// f32 and the refracted direction has length `eta`-ish before it is normalised. Inputs
/// that are not finite give `None`, never a NaN direction.
#[inline]
fn refract(d: Vec3, n: Vec3, eta: f32) -> Option<Vec3> {
    let cos_i = (-d).dot(n).min(1.0);
    let k = 1.0 - eta * eta * (1.0 - cos_i * cos_i);
    // A NaN `k` (from non-finite inputs) is no refraction either.
    if k < 0.0 || k.is_nan() {
        return None;
    }
    let t = (d * eta + n * (eta * cos_i - k.sqrt())).normalize();
    t.is_finite().then_some(t)
}

impl<'a, A: Accel> Tracer<'a, A> {
    pub(super) fn new(scene: &'a Scene, accel: &'a A, s: &RenderSettings) -> Self {
        Tracer {
            scene,
            accel,
            max_depth: s.max_depth.max(1),
            spp: s.spp.max(1),
            area_lights: area::collect(scene),
            area_samples: s.area_samples,
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
    pub(super) fn pixel(&self, raygen: &RayGen, i: u32, j: u32, counts: &mut RayCounts) -> Vec3 {
        if self.spp == 1 {
            return self.eye(raygen, i as f32 + 0.5, j as f32 + 0.5, counts);
        }
        let seed = hash(i.wrapping_mul(0x9e37_79b9) ^ hash(j));
        let (ox, oy) = (unit(hash(seed)), unit(hash(seed ^ 0x5bd1_e995)));
        let n = self.spp;
        let mut sum = Vec3::ZERO;
        for s in 0..n {
            let sx = ((s as f32 + ox) / n as f32).fract();
            let sy = (radical_inverse(s) + oy).fract();
            sum += self.eye(raygen, i as f32 + sx, j as f32 + sy, counts);
        }
        sum / n as f32
    }

    /// The values of the grid positions of tile `t`, row by row, pushed onto `px`: as
    /// [`Tracer::pixel`] gives them, but with one sample per pixel the tile's eye rays
    /// are cast together first (packets on backends that have them; see
    /// [`Accel::intersect_coherent`]), then each is shaded from its hit.
    pub(super) fn tile(
        &self,
        raygen: &RayGen,
        t: Region,
        px: &mut Vec<Vec3>,
        counts: &mut RayCounts,
    ) {
        if self.spp != 1 {
            for j in t.y0..t.y1 {
                for i in t.x0..t.x1 {
                    px.push(self.pixel(raygen, i, j, counts));
                }
            }
            return;
        }
        let centres: Vec<(f32, f32)> = (t.y0..t.y1)
            .flat_map(|j| (t.x0..t.x1).map(move |i| (i as f32 + 0.5, j as f32 + 0.5)))
            .collect();
        let rays: Vec<Ray> = centres.iter().map(|&(x, y)| raygen.ray(x, y)).collect();
        let mut hits = vec![None; rays.len()];
        self.accel.intersect_coherent(&rays, &mut hits);
        for ((ray, hit), &(x, y)) in rays.iter().zip(hits).zip(&centres) {
            counts.eye += 1;
            let path = eye_path(x, y);
            px.push(self.trace_from(ray, hit, 1, path, Media::AIR, Vec3::ONE, counts));
        }
    }

    /// The value of the eye ray through continuous film position `(px, py)`.
    pub(super) fn sample(&self, raygen: &RayGen, px: f32, py: f32, counts: &mut RayCounts) -> Vec3 {
        self.eye(raygen, px, py, counts)
    }

    /// The value of the eye ray through film position `(px, py)`.
    fn eye(&self, raygen: &RayGen, px: f32, py: f32, counts: &mut RayCounts) -> Vec3 {
        counts.eye += 1;
        let path = eye_path(px, py);
        self.trace(&raygen.ray(px, py), 1, path, Media::AIR, Vec3::ONE, counts)
    }

    /// Whether a secondary ray of accumulated `weight` is worth casting.
    #[inline]
    fn worth(&self, weight: Vec3, counts: &mut RayCounts) -> bool {
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
    fn trace(
        &self,
        ray: &Ray,
        depth: u32,
        path: u32,
        media: Media,
        weight: Vec3,
        counts: &mut RayCounts,
    ) -> Vec3 {
        let first = self.accel.intersect(ray);
        self.trace_from(ray, first, depth, path, media, weight, counts)
    }

    /// [`Tracer::trace`] given the ray's nearest hit, `first`.
    #[allow(clippy::too_many_arguments)]
    fn trace_from(
        &self,
        ray: &Ray,
        first: Option<Hit>,
        depth: u32,
        path: u32,
        media: Media,
        weight: Vec3,
        counts: &mut RayCounts,
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
                return scene.escape(ray.dir);
            };
            let surf = scene.surface(&hit, &ray);
            let m = &scene.materials[surf.material as usize];
            let d = ray.dir.normalize();
            let entering = surf.point.ng.dot(d) < 0.0;
            if m.t > 0.0
                && skips < MAX_SKIPS
                && media.is_false_boundary(scene, surf.material, entering)
            {
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
            if depth == 1 {
                counts.eye_hit += 1;
            }
            let gi = self.gi.and_then(|g| g.radiosity_at(&hit, surf.point.p, d));
            let radiance = self.shade(&surf, d, entering, depth, path, media, weight, gi, counts);
            return saturate(radiance, counts);
        }
    }

    /// Whitted shading of a true surface hit seen along unit direction `d`; `gi` is the
    /// radiosity there in two-pass mode, which replaces the ambient, emitted and
    /// area-light terms (the radiosity pass knows only emitters: point lights still
    /// add their direct diffuse and highlights, reflection and refraction stay).
    #[allow(clippy::too_many_arguments)]
    fn shade(
        &self,
        surf: &Surface,
        d: Vec3,
        entering: bool,
        depth: u32,
        path: u32,
        media: Media,
        weight: Vec3,
        gi: Option<Vec3>,
        counts: &mut RayCounts,
    ) -> Vec3 {
        let scene = self.scene;
        // Textured inputs and the bumped shading normal (scene/texture.rs).
        let (m, ns) = scene.shading(surf);
        let m = &m;
        let p = surf.point.p;
        let ng_out = surf.point.ng;
        // Both sides are surfaces: face the normals towards the incoming ray.
        let ng = if entering { ng_out } else { -ng_out };
        let ns = if ns.dot(d) > 0.0 { -ns } else { ns };
        // Every ray leaving this hit starts from one of the two offset points.
        let mut origins = RayOrigins::new(p, surf.point.err, ng);

        let mut color = match gi {
            Some(b) => b,
            None => {
                let at = area::Receiver {
                    p,
                    err: surf.point.err,
                    ng,
                    ns,
                };
                self.local_diffuse(&at, m, entering, path, counts)
            }
        };
        for light in &scene.lights {
            color += self.direct(light, surf, m, &mut origins, ns, d, counts);
        }

        if depth >= self.max_depth {
            return color;
        }
        self.secondary(
            color,
            surf,
            m,
            ns,
            d,
            entering,
            &mut origins,
            depth,
            path,
            media,
            weight,
            counts,
        )
    }

    /// `color` plus the light of the reflection and refraction rays from `surf`: Snell
    /// refraction into the next medium (on total internal reflection the transmitted
    /// energy goes to the reflection ray), and mirror reflection weighted by `Kr` (plus
    /// that energy).
    ///
    /// In SPD mode the rays are cast and counted as the SPD's reference does: a
    /// reflection ray from every transmitter, also with `Ks = 0` (cast, its light of
    /// weight 0 not added, so the image does not change), and on total internal
    /// reflection a refraction ray counted though none exists (the reference counts
    /// the refraction it tries). Measured against the SPD's published counts on gears
    /// (glass with `Ks = 0`): without the first, reflection is 71% short; casting the
    /// total internal reflection's ray as a ray of its own overshoots by 2.8% to 4%.
    #[allow(clippy::too_many_arguments)]
    fn secondary(
        &self,
        mut color: Vec3,
        surf: &Surface,
        m: &Material,
        ns: Vec3,
        d: Vec3,
        entering: bool,
        origins: &mut RayOrigins,
        depth: u32,
        path: u32,
        media: Media,
        weight: Vec3,
        counts: &mut RayCounts,
    ) -> Vec3 {
        let scene = self.scene;
        let (reflected, refracted) = children(path);
        let mut reflect_weight = m.kr;
        let mut total_internal = false;
        if m.t > 0.0 {
            // Snell's law between the medium the ray is in and the one it goes into.
            let (n1, n2, inside) = if entering {
                let inside = media.enter(surf.material);
                (media.ior(scene), m.ior, inside)
            } else {
                let inside = media.leave(surf.material);
                (m.ior, inside.ior(scene), inside)
            };
            match refract(d, ns, n1 / n2) {
                Some(dir) => {
                    // Light is filtered by the medium it goes into.
                    let filter = inside
                        .current(scene)
                        .map_or(Vec3::ONE, |id| scene.materials[id as usize].filter);
                    let w = m.t * filter;
                    if self.worth(weight * w, counts) {
                        counts.refraction += 1;
                        let ray = Ray::new(origins.towards(dir), dir);
                        color +=
                            w * self.trace(&ray, depth + 1, refracted, inside, weight * w, counts);
                    }
                }
                None => {
                    // Total internal reflection: the transmitted energy is reflected.
                    counts.tir += 1;
                    reflect_weight += m.t;
                    total_internal = true;
                }
            }
        }
        let w = weight * reflect_weight;
        let dir = reflect(d, ns);
        if reflect_weight > 0.0 {
            if self.worth(w, counts) {
                counts.reflection += 1;
                let ray = Ray::new(origins.towards(dir), dir);
                color += reflect_weight * self.trace(&ray, depth + 1, reflected, media, w, counts);
            }
        } else if !self.skip || (self.spd && m.t > 0.0) {
            // Cast and thrown away: the SPD reference casts it, or to measure what
            // skipping saves.
            counts.reflection += 1;
            self.trace(
                &Ray::new(origins.towards(dir), dir),
                depth + 1,
                reflected,
                media,
                w,
                counts,
            );
        } else {
            counts.skipped_reflection += 1;
        }
        if self.spd && total_internal {
            // The reference counts the refraction ray it tries here as cast.
            counts.refraction += 1;
        }
        color
    }
}

impl<A: Accel> Tracer<'_, A> {
    /// The diffuse and highlight light `light` sends to `surf` (material `m`, shading
    /// normal `ns` facing the ray of unit direction `d`), after its shadow ray from one
    /// of `origins`.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn direct(
        &self,
        light: &Light,
        surf: &Surface,
        m: &Material,
        origins: &mut RayOrigins,
        ns: Vec3,
        d: Vec3,
        counts: &mut RayCounts,
    ) -> Vec3 {
        let p = surf.point.p;
        let to_light = light.pos - p;
        // No shadow ray when the shading normal faces away from the light or the
        // light sends nothing here (with `skip` off the ray is cast and ignored,
        // to measure what skipping saves).
        let intensity = light.intensity_at(p);
        let useless = ns.dot(to_light) <= 0.0 || intensity == Vec3::ZERO;
        if useless && self.skip {
            counts.skipped_shadow += 1;
            return Vec3::ZERO;
        }
        counts.shadow += 1;
        let org = origins.towards(to_light);
        let mut shadow = Ray::new(org, light.pos - org);
        shadow.tmax = next_float_down(1.0);
        if self.accel.occluded(&shadow) || useless {
            return Vec3::ZERO;
        }
        let l = to_light.normalize();
        let mut c = m.color * (m.kd * ns.dot(l));
        if m.ks > 0.0 {
            let rv = reflect(-l, ns).dot(-d).max(0.0);
            c += Vec3::splat(m.ks * rv.powf(m.shine));
        }
        intensity * c
    }

    /// Ambient, emission (front side) and the area lights' diffuse light.
    fn local_diffuse(
        &self,
        at: &area::Receiver,
        m: &crate::scene::Material,
        entering: bool,
        path: u32,
        counts: &mut RayCounts,
    ) -> Vec3 {
        let mut color = self.scene.ambient * m.color * m.ka;
        if entering && m.is_emitter() {
            color += m.emission;
        }
        if !self.area_lights.is_empty() && m.kd > 0.0 {
            let (e, rays) =
                area::direct(self.accel, &self.area_lights, at, self.area_samples, path);
            counts.shadow += rays;
            color += m.color * m.kd * e;
        }
        color
    }
}

/// Most lower-priority surfaces one ray may pass through.
const MAX_SKIPS: u32 = 64;

/// The transmissive solids a ray is inside (material indices, innermost last), for
/// Snell's law with the right indices when media nest (a liquid in a glass) and for
/// Schmidt & Budge's priorities when they overlap.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Media {
    ids: [u32; MEDIA_DEPTH],
    len: u8,
}

/// Nesting depth tracked; deeper entries are not recorded (the ray then sees the
/// innermost recorded medium).
const MEDIA_DEPTH: usize = 8;

impl Media {
    /// Outside everything.
    const AIR: Media = Media {
        ids: [0; MEDIA_DEPTH],
        len: 0,
    };

    fn iter(&self) -> impl Iterator<Item = u32> + '_ {
        self.ids[..self.len as usize].iter().copied()
    }

    /// The medium in force: the highest priority, the innermost among equals.
    fn current(&self, scene: &Scene) -> Option<u32> {
        let mut best: Option<u32> = None;
        for id in self.iter() {
            let p = scene.materials[id as usize].priority;
            match best {
                Some(b) if p < scene.materials[b as usize].priority => {}
                _ => best = Some(id),
            }
        }
        best
    }

    /// Index of refraction of the medium in force (1 outside everything).
    fn ior(&self, scene: &Scene) -> f32 {
        self.current(scene)
            .map_or(1.0, |id| scene.materials[id as usize].ior)
    }

    /// Whether the boundary of `material` is not optically there: entering it while a
    /// higher-priority medium is in force, or leaving it while one it is inside of is.
    fn is_false_boundary(&self, scene: &Scene, material: u32, entering: bool) -> bool {
        let p = scene.materials[material as usize].priority;
        let higher = |id: u32| id != material && scene.materials[id as usize].priority > p;
        if entering {
            self.iter().any(higher)
        } else {
            self.iter().any(|id| id == material) && self.iter().any(higher)
        }
    }

    fn enter(&self, material: u32) -> Media {
        let mut m = *self;
        if (m.len as usize) < MEDIA_DEPTH {
            m.ids[m.len as usize] = material;
            m.len += 1;
        }
        m
    }

    /// Without the innermost entry of `material` (unchanged if the ray was not in it:
    /// an open transmissive surface seen from its back).
    fn leave(&self, material: u32) -> Media {
        let mut m = *self;
        if let Some(k) = m.ids[..m.len as usize]
            .iter()
            .rposition(|&id| id == material)
        {
            m.ids.copy_within(k + 1..m.len as usize, k);
            m.len -= 1;
            m.ids[m.len as usize] = 0;
        }
        m
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reflect_mirrors_about_the_normal() {
        let r = reflect(Vec3::new(1.0, -1.0, 0.0), Vec3::Y);
        assert_eq!(r, Vec3::new(1.0, 1.0, 0.0));
    }

    /// Any pair of indices a material may have, at any angle: a finite unit direction
    /// or total internal reflection, never NaN; and garbage in gives `None`.
    #[test]
    fn refraction_is_finite_over_the_whole_index_range() {
        let (lo, hi) = (
            *crate::scene::range::IOR_RANGE.start(),
            *crate::scene::range::IOR_RANGE.end(),
        );
        let iors = [lo, 0.01, 0.5, 1.0, 1.5, 2.4, 100.0, hi];
        let mut refracted = 0;
        for k in 0..=200 {
            let th = (k as f32 / 200.0) * std::f32::consts::FRAC_PI_2;
            let d = Vec3::new(th.sin(), 0.3 * th.cos(), -th.cos()).normalize();
            for n1 in iors {
                for n2 in iors {
                    if let Some(t) = refract(d, Vec3::Z, n1 / n2) {
                        assert!(t.is_finite(), "{n1}/{n2} at {th}: {t}");
                        assert!((t.length() - 1.0).abs() < 1e-5, "{n1}/{n2}: {t}");
                        assert!(t.z <= 0.0, "goes through: {t}");
                        refracted += 1;
                    }
                }
            }
        }
        assert!(refracted > 1000, "{refracted}");
        for eta in [f32::NAN, f32::INFINITY, 1e30] {
            assert_eq!(
                refract(Vec3::NEG_Z * 0.99 + Vec3::X * 0.14, Vec3::Z, eta),
                None
            );
        }
        assert_eq!(refract(Vec3::splat(f32::NAN), Vec3::Z, 1.5), None);
    }

    #[test]
    fn refraction_obeys_snell_and_total_internal_reflection() {
        let n = Vec3::Z;
        for deg in [0.0f32, 10.0, 30.0, 45.0, 60.0, 80.0] {
            let th = deg.to_radians();
            let d = Vec3::new(th.sin(), 0.0, -th.cos());
            // Air to glass: sin θt = sin θi / 1.5.
            let t = refract(d, n, 1.0 / 1.5).unwrap();
            let sin_t = t.x;
            assert!((sin_t - th.sin() / 1.5).abs() < 1e-6, "{deg}°");
            assert!(t.z < 0.0, "goes through");
            // Glass to air: TIR beyond the critical angle asin(1/1.5) = 41.8°.
            let out = refract(d, n, 1.5);
            assert_eq!(out.is_none(), deg > 41.81, "{deg}°");
            if let Some(o) = out {
                assert!((o.x - th.sin() * 1.5).abs() < 1e-5);
            }
        }
    }

    fn dielectrics(priorities: [u32; 3]) -> Scene {
        let cam = crate::scene::Camera {
            from: Vec3::Z,
            at: Vec3::ZERO,
            up: Vec3::Y,
            angle_deg: 40.0,
            hither: 0.0,
            width: 1,
            height: 1,
        };
        let mut s = Scene::new(cam);
        for (k, ior) in [1.5f32, 1.31, 1.33].into_iter().enumerate() {
            s.materials.push(crate::scene::Material {
                t: 1.0,
                ior,
                priority: priorities[k],
                ..Default::default()
            });
        }
        s
    }

    #[test]
    fn nested_media_use_the_enclosing_index() {
        let s = dielectrics([0, 0, 0]);
        let air = Media::AIR;
        assert_eq!(air.ior(&s), 1.0);
        // Into the ice (1), then into the liquid (2) inside it: the liquid is in force;
        // leaving the liquid returns to the ice, not to air.
        let ice = air.enter(1);
        let liquid = ice.enter(2);
        assert_eq!(liquid.ior(&s), 1.33);
        assert_eq!(liquid.leave(2).ior(&s), 1.31);
        assert_eq!(liquid.leave(2).leave(1), air);
        // Leaving a medium the ray was never in (an open surface's back) changes nothing.
        assert_eq!(ice.leave(0), ice);
        // With equal priorities every boundary is real.
        assert!(!liquid.is_false_boundary(&s, 2, false));
        assert!(!ice.is_false_boundary(&s, 2, true));
    }

    #[test]
    fn priorities_skip_the_lower_medium_inside_the_higher() {
        // Ice (priority 2) overlaps the liquid (priority 1) in the cavity walls.
        let s = dielectrics([0, 2, 1]);
        let in_ice = Media::AIR.enter(1);
        // Entering the liquid inside the ice: a false boundary; the ice stays in force.
        assert!(in_ice.is_false_boundary(&s, 2, true));
        let both = in_ice.enter(2);
        assert_eq!(both.ior(&s), 1.31);
        // Leaving the ice into the cavity, below the liquid level: a real boundary into
        // the liquid (1.31 -> 1.33), not into air.
        assert!(!both.is_false_boundary(&s, 1, false));
        assert_eq!(both.leave(1).ior(&s), 1.33);
        // Entering the ice from the liquid is real (higher priority).
        assert!(!Media::AIR.enter(2).is_false_boundary(&s, 1, true));
        // Leaving the liquid while inside the ice: false.
        assert!(both.is_false_boundary(&s, 2, false));
    }

    #[test]
    fn media_depth_is_bounded() {
        let mut m = Media::AIR;
        for i in 0..20 {
            m = m.enter(i);
        }
        assert_eq!(m.len as usize, MEDIA_DEPTH);
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
