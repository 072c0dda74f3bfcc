//! The local light at a hit: ambient, emission and the area lights' diffuse light
//! ([`Tracer::local_diffuse`]), and each point light's Phong diffuse and highlight
//! after its shadow ray. The shadow rays of a whole depth of the wavefront are queued
//! ([`Tracer::queue_lights`]), cast together as one any-hit batch
//! ([`Accel::occluded_batch`]), and then each light's share is added to its hit in the
//! order of the scene's lights ([`Tracer::finish_lights`]), the order a recursive
//! tracer adds them in. Every term is reported to the [`Recorder`].

use super::area;
use super::optics::reflect;
use super::path::Tree;
use super::record::{LightTerm, Recorder, Term};
use super::whitted::Tracer;
use crate::accel::Accel;
use crate::math::{Ray, RayOrigins, Vec3, next_float_down};
use crate::scene::Material;

/// The point lights' shadow rays of one depth of a batch, waiting to be cast, with
/// what Phong's terms need of each hit afterwards.
#[derive(Debug, Default)]
pub(super) struct LightQueue {
    hits: Vec<Lit>,
    queries: Vec<Query>,
    rays: Vec<Ray>,
    /// The light of each shadow ray.
    ray_light: Vec<u32>,
    /// The node of each shadow ray (for the recorder's [`Recorder::cast`]).
    ray_nodes: Vec<u32>,
    /// The answers, by ray.
    occluded: Vec<bool>,
    /// The rays light by light (`rays[by_light[k]]` is cast `k`-th), and their answers.
    by_light: Vec<u32>,
    sorted: Vec<Ray>,
    sorted_occluded: Vec<bool>,
}

/// A shaded hit waiting for its point lights.
#[derive(Clone, Copy, Debug)]
struct Lit {
    node: u32,
    /// The material's colour, `Kd`, `Ks` and `Shine` after textures.
    color: Vec3,
    kd: f32,
    ks: f32,
    shine: f32,
    /// The shading normal facing the ray.
    ns: Vec3,
    /// The ray's unit direction.
    d: Vec3,
    /// Its queries: `queries[first..end]`, in the lights' order.
    first: u32,
    end: u32,
}

/// One point light at one hit.
#[derive(Clone, Copy, Debug)]
struct Query {
    light: u32,
    /// The light is behind the shading normal or sends nothing here.
    useless: bool,
    /// The light's intensity arriving at the point.
    intensity: Vec3,
    /// From the point to the light.
    to_light: Vec3,
    /// Its shadow ray in [`LightQueue::rays`], or [`NOT_CAST`].
    shadow: u32,
}

/// A query whose shadow ray was not cast.
const NOT_CAST: u32 = u32::MAX;

/// Where a hit is and how it faces, for its shadow rays.
pub(super) struct Receiver<'o> {
    pub node: u32,
    pub p: Vec3,
    pub ns: Vec3,
    pub d: Vec3,
    pub origins: &'o mut RayOrigins,
}

impl<A: Accel> Tracer<'_, A> {
    /// Queue the shadow rays of every point light at the hit `at` (material `m`),
    /// whose local light so far is in its node.
    pub(super) fn queue_lights<R: Recorder>(
        &self,
        at: Receiver,
        m: &Material,
        queue: &mut LightQueue,
        rec: &mut R,
    ) {
        let first = queue.queries.len() as u32;
        for (index, light) in self.scene.lights.iter().enumerate() {
            let to_light = light.pos - at.p;
            // No shadow ray when the shading normal faces away from the light or the
            // light sends nothing here (with `skip` off the ray is cast and ignored,
            // to measure what skipping saves).
            let intensity = light.intensity_at(at.p);
            let useless = at.ns.dot(to_light) <= 0.0 || intensity == Vec3::ZERO;
            let mut shadow = NOT_CAST;
            if useless && self.skip {
                rec.counts().skipped_shadow += 1;
            } else {
                rec.counts().shadow += 1;
                let org = at.origins.towards(to_light);
                let mut ray = Ray::new(org, light.pos - org);
                ray.tmax = next_float_down(1.0);
                shadow = queue.rays.len() as u32;
                queue.rays.push(ray);
                queue.ray_light.push(index as u32);
                if R::ACTIVE {
                    queue.ray_nodes.push(at.node);
                }
            }
            queue.queries.push(Query {
                light: index as u32,
                useless,
                intensity,
                to_light,
                shadow,
            });
        }
        queue.hits.push(Lit {
            node: at.node,
            color: m.color,
            kd: m.kd,
            ks: m.ks,
            shine: m.shine,
            ns: at.ns,
            d: at.d,
            first,
            end: queue.queries.len() as u32,
        });
    }

    /// Cast the queued shadow rays together and add each light's diffuse and
    /// highlight to its hit's local light in `tree`, in the lights' order; empties
    /// the queue.
    pub(super) fn finish_lights<R: Recorder>(
        &self,
        queue: &mut LightQueue,
        tree: &mut Tree,
        rec: &mut R,
    ) {
        rec.cast(true, &queue.ray_nodes);
        self.cast_shadows(queue);
        rec.cast(false, &queue.ray_nodes);
        for hit in &queue.hits {
            let node = tree.node(hit.node);
            let mut color = node.local;
            for q in &queue.queries[hit.first as usize..hit.end as usize] {
                color += phong(hit, q, &queue.rays, &queue.occluded, rec);
            }
            node.local = color;
            rec.local(hit.node, color);
        }
        queue.hits.clear();
        queue.queries.clear();
        queue.rays.clear();
        queue.ray_light.clear();
        queue.ray_nodes.clear();
    }

    /// Answer the queued shadow rays into `queue.occluded`: cast light by light (the
    /// rays to one light from neighbouring hits are coherent: packets of them share
    /// most of their way), as one batch.
    fn cast_shadows(&self, queue: &mut LightQueue) {
        let n = queue.rays.len();
        queue.occluded.clear();
        queue.occluded.resize(n, false);
        let lights = self.scene.lights.len();
        if lights <= 1 {
            self.accel.occluded_batch(&queue.rays, &mut queue.occluded);
            return;
        }
        // A counting sort of the rays by light, stable.
        let mut start = vec![0u32; lights + 1];
        for &l in &queue.ray_light {
            start[l as usize + 1] += 1;
        }
        for l in 0..lights {
            start[l + 1] += start[l];
        }
        queue.by_light.clear();
        queue.by_light.resize(n, 0);
        for (i, &l) in queue.ray_light.iter().enumerate() {
            let at = &mut start[l as usize];
            queue.by_light[*at as usize] = i as u32;
            *at += 1;
        }
        queue.sorted.clear();
        queue
            .sorted
            .extend(queue.by_light.iter().map(|&i| queue.rays[i as usize]));
        queue.sorted_occluded.clear();
        queue.sorted_occluded.resize(n, false);
        self.accel
            .occluded_batch(&queue.sorted, &mut queue.sorted_occluded);
        for (&i, &o) in queue.by_light.iter().zip(&queue.sorted_occluded) {
            queue.occluded[i as usize] = o;
        }
    }

    /// Ambient, emission (front side) and the area lights' diffuse light at `at`
    /// (for node `node` of path `path`).
    pub(super) fn local_diffuse<R: Recorder>(
        &self,
        node: u32,
        at: &area::Receiver,
        m: &Material,
        entering: bool,
        path: u32,
        rec: &mut R,
    ) -> Vec3 {
        let mut color = self.scene.ambient * m.color * m.ka;
        rec.term(node, Term::Ambient, color);
        if entering && m.is_emitter() {
            rec.term(node, Term::Emission, m.emission);
            color += m.emission;
        }
        if !self.area_lights.is_empty() && m.kd > 0.0 {
            let (e, rays) = area::direct_recorded(
                self.accel,
                &self.area_lights,
                at,
                self.area_strata,
                path,
                &mut |light, rays, visible, value| {
                    rec.area_light(node, light, rays, visible, value)
                },
            );
            rec.counts().shadow += rays;
            let area = m.color * m.kd * e;
            rec.term(node, Term::Area, area);
            color += area;
        }
        color
    }
}

/// What the light of query `q` adds at `hit`, reported to `rec`: `intensity ×
/// (colour × Kd × (N·L) + Ks × (R·V)^Shine)` when its shadow ray reached it, else 0.
#[inline(always)]
fn phong<R: Recorder>(hit: &Lit, q: &Query, rays: &[Ray], occluded: &[bool], rec: &mut R) -> Vec3 {
    let shadow = (q.shadow != NOT_CAST).then(|| &rays[q.shadow as usize]);
    let blocked = shadow.is_some() && occluded[q.shadow as usize];
    let term = LightTerm {
        light: q.light as usize,
        shadow,
        useless: q.useless,
        occluded: blocked,
        intensity: q.intensity,
        diffuse: Vec3::ZERO,
        specular: 0.0,
        value: Vec3::ZERO,
    };
    if shadow.is_none() || blocked || q.useless {
        rec.light(hit.node, &term);
        return Vec3::ZERO;
    }
    let (ns, d) = (hit.ns, hit.d);
    let l = q.to_light.normalize();
    let diffuse = hit.color * (hit.kd * ns.dot(l));
    let mut c = diffuse;
    let mut specular = 0.0;
    if hit.ks > 0.0 {
        let rv = reflect(-l, ns).dot(-d).max(0.0);
        specular = hit.ks * rv.powf(hit.shine);
        c += Vec3::splat(specular);
    }
    let value = q.intensity * c;
    rec.light(
        hit.node,
        &LightTerm {
            diffuse,
            specular,
            value,
            ..term
        },
    );
    value
}
