//! The recorder that builds `emray explain`'s ray tree from the tracer's hooks: a
//! stack of the rays being followed, each finished ray attached to the hit that
//! spawned it, or to its position when it is an eye ray. Only the wanted sample-grid
//! positions are recorded; the others of their tile are traced and forgotten.

use super::{
    AreaNode, BoundaryNode, HitNode, LightNode, MaterialNode, Medium, NotCastNode, Passed,
    Position, Prim, RayNode, ShadowRay, TermNode, arr,
};
use crate::math::Vec3;
use crate::render::RayCounts;
use crate::render::media::Media;
use crate::render::record::{Boundary, LightTerm, Met, NotCast, RayKind, Recorder, Term, Traced};
use crate::scene::{Hit, Material, NO_INSTANCE, Scene};

/// Records the ray trees of the wanted positions.
pub(super) struct ExplainRecorder<'s> {
    scene: &'s Scene,
    wanted: Vec<(u32, u32)>,
    /// What one sample weighs in the pixel.
    share: f32,
    counts: RayCounts,
    /// Whether the current position is wanted.
    active: bool,
    /// The rays being followed, the eye ray first.
    stack: Vec<RayNode>,
    current: Option<Position>,
    done: Vec<Position>,
}

impl<'s> ExplainRecorder<'s> {
    pub(super) fn new(scene: &'s Scene, wanted: Vec<(u32, u32)>, share: f32) -> Self {
        ExplainRecorder {
            scene,
            wanted,
            share,
            counts: RayCounts::default(),
            active: false,
            stack: Vec::new(),
            current: None,
            done: Vec::new(),
        }
    }

    /// The recorded positions in the order of `wanted` (an empty record for one that
    /// was not traced).
    pub(super) fn into_positions(mut self, wanted: &[(u32, u32)]) -> Vec<Position> {
        wanted
            .iter()
            .map(|&(i, j)| {
                let k = self.done.iter().position(|p| p.grid == [i, j]);
                match k {
                    Some(k) => self.done.swap_remove(k),
                    None => Position {
                        grid: [i, j],
                        value: [0.0; 3],
                        share: self.share,
                        samples: Vec::new(),
                    },
                }
            })
            .collect()
    }

    /// The hit of the ray being followed.
    fn hit_mut(&mut self) -> Option<&mut HitNode> {
        if !self.active {
            return None;
        }
        self.stack.last_mut()?.hit.as_deref_mut()
    }

    /// Primitive `hit` with where it and its instance were defined.
    /// A point of the scene's frame in the file's own coordinates (see
    /// [`Scene::origin`]).
    fn world(&self, p: Vec3) -> [f64; 3] {
        self.scene.to_world(p).to_array()
    }

    fn prim(&self, hit: &Hit) -> Prim {
        let kind = hit.kind();
        let scene = self.scene;
        let (geometry, instance) = if hit.inst_id == NO_INSTANCE {
            (&scene.geometry, None)
        } else {
            let inst = &scene.instances[hit.inst_id as usize];
            (&scene.objects[inst.object as usize], Some(hit.inst_id))
        };
        Prim {
            kind: kind.singular(),
            index: hit.prim_id,
            instance,
            source: geometry
                .sources
                .get(kind, hit.prim_id)
                .map(|o| o.to_string()),
            instance_source: instance
                .and_then(|i| scene.sources.instances.get(i))
                .map(|o| o.to_string()),
        }
    }

    fn media(&self, media: &Media) -> Vec<Medium> {
        media
            .iter()
            .map(|id| Medium {
                material: id,
                ior: self.scene.materials[id as usize].ior,
            })
            .collect()
    }

    fn material(&self, index: u32, m: &Material) -> MaterialNode {
        MaterialNode {
            index,
            source: self
                .scene
                .sources
                .materials
                .get(index)
                .map(|o| o.to_string()),
            color: arr(m.color),
            ka: m.ka,
            kd: m.kd,
            ks: m.ks,
            shine: m.shine,
            kr: m.kr,
            t: m.t,
            ior: m.ior,
            emission: arr(m.emission),
        }
    }

    fn light_node(&self, term: &LightTerm) -> LightNode {
        let light = &self.scene.lights[term.light];
        let status = match (term.shadow, term.occluded, term.useless) {
            (None, _, _) => "behind",
            (Some(_), true, _) => "shadowed",
            (Some(_), false, true) => "unlit",
            (Some(_), false, false) => "lit",
        };
        let colour = light.color.max_element();
        LightNode {
            light: term.light,
            source: self
                .scene
                .sources
                .lights
                .get(term.light as u32)
                .map(|o| o.to_string()),
            status,
            shadow_ray: term.shadow.map(|r| ShadowRay {
                origin: self.world(r.org),
                direction: arr(r.dir),
                tmax: r.tmax,
                occluded: term.occluded,
            }),
            intensity: arr(term.intensity),
            attenuation: if colour != 0.0 {
                term.intensity.max_element() / colour
            } else {
                0.0
            },
            diffuse: arr(term.diffuse),
            specular: term.specular,
            value: arr(term.value),
        }
    }
}

impl Recorder for ExplainRecorder<'_> {
    const ACTIVE: bool = true;

    fn counts(&mut self) -> &mut RayCounts {
        &mut self.counts
    }

    fn position(&mut self, i: u32, j: u32) {
        self.active = self.wanted.contains(&(i, j));
        self.stack.clear();
        self.current = self.active.then(|| Position {
            grid: [i, j],
            value: [0.0; 3],
            share: self.share,
            samples: Vec::new(),
        });
    }

    fn position_end(&mut self, value: Vec3) {
        if let Some(mut p) = self.current.take() {
            p.value = arr(value);
            self.done.push(p);
        }
        self.active = false;
    }

    fn ray(&mut self, t: &Traced) {
        if !self.active {
            return;
        }
        self.stack.push(RayNode {
            kind: t.kind,
            depth: t.depth,
            origin: self.world(t.ray.org),
            direction: arr(t.ray.dir),
            local_weight: arr(t.local_weight),
            weight: arr(t.weight),
            discarded: t.discarded,
            passed: Vec::new(),
            hit: None,
            background: None,
            contribution: [0.0; 3],
            radiance: [0.0; 3],
        });
    }

    fn ray_end(&mut self, radiance: Vec3) {
        let Some(mut node) = self.active.then(|| self.stack.pop()).flatten() else {
            return;
        };
        node.radiance = arr(radiance);
        match self.stack.last_mut() {
            Some(parent) => {
                if let Some(hit) = parent.hit.as_deref_mut() {
                    hit.children.push(node);
                }
            }
            None => {
                if let Some(p) = self.current.as_mut() {
                    p.samples.push(node);
                }
            }
        }
    }

    fn miss(&mut self, radiance: Vec3) {
        let share = self.share;
        if let Some(top) = self.stack.last_mut().filter(|_| self.active) {
            top.background = Some(arr(radiance));
            top.contribution = arr(Vec3::from(top.weight) * radiance * share);
        }
    }

    fn pass_through(&mut self, at: &Met) {
        if !self.active {
            return;
        }
        let passed = Passed {
            prim: self.prim(at.hit),
            point: self.world(at.surf.point.p),
            entering: at.entering,
        };
        if let Some(top) = self.stack.last_mut() {
            top.passed.push(passed);
        }
    }

    fn hit(&mut self, at: &Met) {
        if !self.active {
            return;
        }
        let material = &self.scene.materials[at.surf.material as usize];
        let node = HitNode {
            t: at.hit.t,
            point: self.world(at.surf.point.p),
            prim: self.prim(at.hit),
            entering: at.entering,
            geometric_normal: arr(at.surf.point.ng),
            normal: arr(at.surf.ns),
            material: self.material(at.surf.material, material),
            media: self.media(at.media),
            terms: Vec::new(),
            area_lights: Vec::new(),
            lights: Vec::new(),
            local: [0.0; 3],
            boundary: None,
            not_cast: Vec::new(),
            children: Vec::new(),
        };
        if let Some(top) = self.stack.last_mut() {
            top.hit = Some(Box::new(node));
        }
    }

    fn shading(&mut self, m: &Material, ns: Vec3) {
        let Some(index) = self.hit_mut().map(|h| h.material.index) else {
            return;
        };
        let material = self.material(index, m);
        if let Some(hit) = self.hit_mut() {
            hit.material = material;
            hit.normal = arr(ns);
        }
    }

    fn term(&mut self, term: Term, value: Vec3) {
        if let Some(hit) = self.hit_mut() {
            hit.terms.push(TermNode {
                term,
                value: arr(value),
            });
        }
    }

    fn area_light(&mut self, light: usize, rays: u32, visible: u32, value: Vec3) {
        if let Some(hit) = self.hit_mut() {
            hit.area_lights.push(AreaNode {
                light,
                rays,
                visible,
                value: arr(value),
            });
        }
    }

    fn light(&mut self, term: &LightTerm) {
        if !self.active {
            return;
        }
        let node = self.light_node(term);
        if let Some(hit) = self.hit_mut() {
            hit.lights.push(node);
        }
    }

    fn local(&mut self, color: Vec3) {
        let share = self.share;
        let Some(top) = self.stack.last_mut().filter(|_| self.active) else {
            return;
        };
        top.contribution = arr(Vec3::from(top.weight) * color * share);
        if let Some(hit) = top.hit.as_deref_mut() {
            hit.local = arr(color);
        }
    }

    fn boundary(&mut self, b: &Boundary) {
        if !self.active {
            return;
        }
        let beyond = self.media(&b.inside);
        if let Some(hit) = self.hit_mut() {
            hit.boundary = Some(BoundaryNode {
                n1: b.n1,
                n2: b.n2,
                total_internal_reflection: b.tir,
                media_beyond: beyond,
            });
        }
    }

    fn not_cast(&mut self, kind: RayKind, why: NotCast, weight: Vec3) {
        if let Some(hit) = self.hit_mut() {
            hit.not_cast.push(NotCastNode {
                kind,
                why,
                weight: arr(weight),
            });
        }
    }
}
