//! The recorder that builds `emray explain`'s ray tree from the tracer's hooks: every
//! ray of a wanted sample-grid position recorded under its node number as the
//! wavefront reaches it, and once the position is complete its rays put together into
//! trees by their parent links (each ray under the hit that spawned it, children in
//! the order they were spawned). The other positions of the tile are traced and
//! forgotten.

use super::{
    AreaNode, BoundaryNode, HitNode, LightNode, MaterialNode, Medium, NotCastNode, Passed,
    Position, Prim, RayNode, ShadowRay, TermNode, arr,
};
use crate::math::Vec3;
use crate::render::RayCounts;
use crate::render::media::Media;
use crate::render::record::{Boundary, LightTerm, Met, NotCast, RayKind, Recorder, Term, Traced};
use crate::scene::{Hit, Material, NO_INSTANCE, Scene};
use std::collections::HashMap;

/// Records the ray trees of the wanted positions.
pub(super) struct ExplainRecorder<'s> {
    scene: &'s Scene,
    wanted: Vec<(u32, u32)>,
    /// What one sample weighs in the pixel.
    share: f32,
    counts: RayCounts,
    /// The rays of the batch's wanted positions, by node.
    rays: HashMap<u32, Recorded>,
    /// The position being completed, when it is wanted.
    current: Option<(u32, u32)>,
    done: Vec<Position>,
}

/// A recorded ray with its links.
struct Recorded {
    ray: RayNode,
    parent: Option<u32>,
    position: (u32, u32),
}

impl<'s> ExplainRecorder<'s> {
    pub(super) fn new(scene: &'s Scene, wanted: Vec<(u32, u32)>, share: f32) -> Self {
        ExplainRecorder {
            scene,
            wanted,
            share,
            counts: RayCounts::default(),
            rays: HashMap::new(),
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

    /// Ray `node`, if it is recorded.
    fn ray_mut(&mut self, node: u32) -> Option<&mut RayNode> {
        self.rays.get_mut(&node).map(|r| &mut r.ray)
    }

    /// The hit of ray `node`, if it is recorded.
    fn hit_mut(&mut self, node: u32) -> Option<&mut HitNode> {
        self.ray_mut(node)?.hit.as_deref_mut()
    }

    /// Ray `node` with its subtree, taken out of the records (`children[k]`: the nodes
    /// spawned at `k`'s hit, in order).
    fn take_tree(&mut self, node: u32, children: &HashMap<u32, Vec<u32>>) -> Option<RayNode> {
        let mut ray = self.rays.remove(&node)?.ray;
        let subtrees: Vec<RayNode> = children
            .get(&node)
            .into_iter()
            .flatten()
            .filter_map(|&c| self.take_tree(c, children))
            .collect();
        if let Some(hit) = ray.hit.as_deref_mut() {
            hit.children = subtrees;
        }
        Some(ray)
    }

    /// The eye rays of `position` with their trees, in sample order.
    fn trees_of(&mut self, position: (u32, u32)) -> Vec<RayNode> {
        let mut eyes = Vec::new();
        let mut children: HashMap<u32, Vec<u32>> = HashMap::new();
        for (&node, r) in &self.rays {
            if r.position != position {
                continue;
            }
            match r.parent {
                None => eyes.push(node),
                Some(p) => children.entry(p).or_default().push(node),
            }
        }
        eyes.sort_unstable();
        for list in children.values_mut() {
            list.sort_unstable();
        }
        eyes.into_iter()
            .filter_map(|e| self.take_tree(e, &children))
            .collect()
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

    fn batch(&mut self) {
        self.rays.clear();
    }

    fn position(&mut self, i: u32, j: u32) {
        self.current = self.wanted.contains(&(i, j)).then_some((i, j));
    }

    fn position_end(&mut self, value: Vec3) {
        let Some(grid) = self.current.take() else {
            return;
        };
        let samples = self.trees_of(grid);
        self.done.push(Position {
            grid: [grid.0, grid.1],
            value: arr(value),
            share: self.share,
            samples,
        });
    }

    fn ray(&mut self, t: &Traced) {
        if !self.wanted.contains(&t.position) {
            return;
        }
        let ray = RayNode {
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
        };
        let recorded = Recorded {
            ray,
            parent: t.parent,
            position: t.position,
        };
        self.rays.insert(t.node, recorded);
    }

    fn ray_end(&mut self, node: u32, radiance: Vec3) {
        if let Some(ray) = self.ray_mut(node) {
            ray.radiance = arr(radiance);
        }
    }

    fn miss(&mut self, node: u32, radiance: Vec3) {
        let share = self.share;
        if let Some(ray) = self.ray_mut(node) {
            ray.background = Some(arr(radiance));
            ray.contribution = arr(Vec3::from(ray.weight) * radiance * share);
        }
    }

    fn pass_through(&mut self, node: u32, at: &Met) {
        if !self.rays.contains_key(&node) {
            return;
        }
        let passed = Passed {
            prim: self.prim(at.hit),
            point: self.world(at.surf.point.p),
            entering: at.entering,
        };
        if let Some(ray) = self.ray_mut(node) {
            ray.passed.push(passed);
        }
    }

    fn hit(&mut self, node: u32, at: &Met) {
        if !self.rays.contains_key(&node) {
            return;
        }
        let material = &self.scene.materials[at.surf.material as usize];
        let hit = HitNode {
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
        if let Some(ray) = self.ray_mut(node) {
            ray.hit = Some(Box::new(hit));
        }
    }

    fn shading(&mut self, node: u32, m: &Material, ns: Vec3) {
        let Some(index) = self.hit_mut(node).map(|h| h.material.index) else {
            return;
        };
        let material = self.material(index, m);
        if let Some(hit) = self.hit_mut(node) {
            hit.material = material;
            hit.normal = arr(ns);
        }
    }

    fn term(&mut self, node: u32, term: Term, value: Vec3) {
        if let Some(hit) = self.hit_mut(node) {
            hit.terms.push(TermNode {
                term,
                value: arr(value),
            });
        }
    }

    fn area_light(&mut self, node: u32, light: usize, rays: u32, visible: u32, value: Vec3) {
        if let Some(hit) = self.hit_mut(node) {
            hit.area_lights.push(AreaNode {
                light,
                rays,
                visible,
                value: arr(value),
            });
        }
    }

    fn light(&mut self, node: u32, term: &LightTerm) {
        if !self.rays.contains_key(&node) {
            return;
        }
        let light = self.light_node(term);
        if let Some(hit) = self.hit_mut(node) {
            hit.lights.push(light);
        }
    }

    fn local(&mut self, node: u32, color: Vec3) {
        let share = self.share;
        let Some(ray) = self.ray_mut(node) else {
            return;
        };
        ray.contribution = arr(Vec3::from(ray.weight) * color * share);
        if let Some(hit) = ray.hit.as_deref_mut() {
            hit.local = arr(color);
        }
    }

    fn boundary(&mut self, node: u32, b: &Boundary) {
        if !self.rays.contains_key(&node) {
            return;
        }
        let beyond = self.media(&b.inside);
        if let Some(hit) = self.hit_mut(node) {
            hit.boundary = Some(BoundaryNode {
                n1: b.n1,
                n2: b.n2,
                total_internal_reflection: b.tir,
                media_beyond: beyond,
            });
        }
    }

    fn not_cast(&mut self, node: u32, kind: RayKind, why: NotCast, weight: Vec3) {
        if let Some(hit) = self.hit_mut(node) {
            hit.not_cast.push(NotCastNode {
                kind,
                why,
                weight: arr(weight),
            });
        }
    }
}
