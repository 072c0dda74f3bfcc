//! The pure-Rust backend: a binned-SAH bounding volume hierarchy over every primitive
//! kind, stored as a flat node array (left child next to its parent), traversed
//! nearer-child-first (both children's boxes tested at the parent), skipping pushed
//! nodes that lie beyond the nearest hit found meanwhile.

mod build;

use crate::accel::{Accel, AccelStats, Hit, NO_INSTANCE};
use crate::geometry::{Intersect, Kind, Shape, Triangle, WatertightRay};
use crate::math::{Aabb, Ray, Xform};
use crate::scene::{Geometry, Scene};
use std::sync::Arc;

/// One node: 32 bytes.
#[derive(Clone, Copy, Debug)]
#[repr(C)]
struct Node {
    bounds: Aabb,
    /// Leaf: index of the first primitive. Interior: index of the second child (the
    /// first child is the next node).
    offset: u32,
    /// Number of primitives; 0 for an interior node.
    count: u16,
    /// Split axis of an interior node (decides which child is near).
    axis: u16,
}

/// A primitive as stored in the leaves, in traversal order.
#[derive(Clone, Debug)]
enum Prim {
    Triangle(Triangle),
    Shape(Shape),
    /// An index into `Bvh::instances`.
    Instance(u32),
}

impl Prim {
    fn bounds(&self, instances: &[PlacedObject]) -> Aabb {
        match self {
            Prim::Triangle(t) => t.bounds(),
            Prim::Shape(s) => s.bounds(),
            Prim::Instance(i) => instances[*i as usize].bounds,
        }
    }
}

/// An instance: the object's own hierarchy under a transform.
struct PlacedObject {
    xform: Xform,
    object: Arc<Bvh>,
    bounds: Aabb,
}

/// The built hierarchy: two levels when the scene has instances (the top level's
/// leaves hold instances, whose objects have hierarchies of their own).
pub struct Bvh {
    nodes: Vec<Node>,
    prims: Vec<Prim>,
    /// `(geom_id, prim_id)` of each entry of `prims` (`(u32::MAX, instance)` for
    /// instances).
    ids: Vec<(u32, u32)>,
    /// Primitives with infinite bounds (planes, unbounded quadrics, instances of
    /// them): kept out of the tree and tested against every ray before it.
    unbounded: Vec<usize>,
    instances: Vec<PlacedObject>,
}

/// Traversal stack depth; the builder caps the tree depth below it.
const STACK: usize = 64;

impl Bvh {
    /// Build over every primitive of `scene`: a hierarchy per instanced object, and a
    /// top-level one over the scene's own primitives and the instances.
    pub fn build(scene: &Scene) -> Bvh {
        let objects: Vec<Arc<Bvh>> = scene
            .objects
            .iter()
            .map(|g| Arc::new(Bvh::build_level(g, Vec::new())))
            .collect();
        let instances = scene
            .instances
            .iter()
            .map(|inst| {
                let object = objects[inst.object as usize].clone();
                let bounds = inst.xform.bounds_to_world(&object.bounds());
                PlacedObject {
                    xform: inst.xform,
                    object,
                    bounds,
                }
            })
            .collect();
        Bvh::build_level(&scene.geometry, instances)
    }

    fn build_level(geometry: &Geometry, instances: Vec<PlacedObject>) -> Bvh {
        let n = geometry.prim_count() + instances.len();
        let mut prims = Vec::with_capacity(n);
        let mut ids = Vec::with_capacity(n);
        for (i, t) in geometry.triangles.items.iter().enumerate() {
            prims.push(Prim::Triangle(*t));
            ids.push((Kind::Triangle as u32, i as u32));
        }
        for (kind, i, shape) in geometry.analytic() {
            prims.push(Prim::Shape(shape));
            ids.push((kind as u32, i));
        }
        for i in 0..instances.len() {
            prims.push(Prim::Instance(i as u32));
            ids.push((u32::MAX, i as u32));
        }
        let all_bounds: Vec<Aabb> = prims.iter().map(|p| p.bounds(&instances)).collect();
        // Unbounded primitives stay out of the tree; empty ones (an instance of an empty
        // object) are dropped.
        let unbounded_idx: Vec<usize> = (0..prims.len())
            .filter(|&i| !all_bounds[i].is_finite() && !all_bounds[i].is_empty())
            .collect();
        let bounded: Vec<usize> = (0..prims.len())
            .filter(|&i| all_bounds[i].is_finite())
            .collect();
        let bounds: Vec<Aabb> = bounded.iter().map(|&i| all_bounds[i]).collect();
        let (nodes, order) = build::build(&bounds);
        let mut out_prims: Vec<Prim> = order
            .iter()
            .map(|&k| prims[bounded[k as usize]].clone())
            .collect();
        let mut out_ids: Vec<(u32, u32)> =
            order.iter().map(|&k| ids[bounded[k as usize]]).collect();
        let mut unbounded = Vec::with_capacity(unbounded_idx.len());
        for i in unbounded_idx {
            unbounded.push(out_prims.len());
            out_prims.push(prims[i].clone());
            out_ids.push(ids[i]);
        }
        Bvh {
            nodes,
            prims: out_prims,
            ids: out_ids,
            unbounded,
            instances,
        }
    }

    /// Bounds of everything in this level (infinite with unbounded primitives).
    fn bounds(&self) -> Aabb {
        let mut b = self.nodes.first().map_or(Aabb::EMPTY, |n| n.bounds);
        for &i in &self.unbounded {
            b = b.union(&self.prims[i].bounds(&self.instances));
        }
        b
    }

    /// Number of nodes.
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Walk the tree; `leaf` is called for each primitive index of every leaf the ray
    /// reaches and returns the new `tmax` (or `None` to stop at once). Both children's
    /// boxes are tested at their parent: the nearer one (by entry distance) is visited
    /// first, the other is pushed with its entry distance and skipped when it comes off
    /// the stack if a hit closer than that was found meanwhile.
    #[inline]
    fn traverse(&self, ray: &Ray, mut leaf: impl FnMut(usize, f32) -> Option<f32>) {
        let Some(root) = self.nodes.first() else {
            return;
        };
        let inv = ray.dir.recip();
        let mut tmax = ray.tmax;
        if root.bounds.hit(ray.org, inv, ray.tmin, tmax).is_none() {
            return;
        }
        let mut stack = [(0u32, 0f32); STACK];
        let mut sp = 0usize;
        let mut idx = 0usize;
        loop {
            let node = &self.nodes[idx];
            if node.count == 0 {
                let (l, r) = (idx + 1, node.offset as usize);
                let hl = self.nodes[l].bounds.hit(ray.org, inv, ray.tmin, tmax);
                let hr = self.nodes[r].bounds.hit(ray.org, inv, ray.tmin, tmax);
                match (hl, hr) {
                    (Some(tl), Some(tr)) => {
                        let (near, far, tfar) = if tl <= tr { (l, r, tr) } else { (r, l, tl) };
                        stack[sp] = (far as u32, tfar);
                        sp += 1;
                        idx = near;
                        continue;
                    }
                    (Some(_), None) => {
                        idx = l;
                        continue;
                    }
                    (None, Some(_)) => {
                        idx = r;
                        continue;
                    }
                    (None, None) => {}
                }
            } else {
                let start = node.offset as usize;
                for i in start..start + node.count as usize {
                    match leaf(i, tmax) {
                        Some(t) => tmax = t,
                        None => return,
                    }
                }
            }
            // Next: the nearest pushed node that may still hold a closer hit.
            loop {
                if sp == 0 {
                    return;
                }
                sp -= 1;
                let (next, tentry) = stack[sp];
                if tentry <= tmax {
                    idx = next as usize;
                    break;
                }
            }
        }
    }
}

impl Bvh {
    /// The nearest hit of primitive `i` in `(ray.tmin, tmax)`.
    #[inline]
    fn hit_prim(&self, i: usize, ray: &Ray, wt: &mut WatertightRay, tmax: f32) -> Option<Hit> {
        let (geom_id, prim_id) = self.ids[i];
        let h = match &self.prims[i] {
            Prim::Triangle(t) => {
                wt.set_tmax(tmax);
                t.intersect_wt(wt)
            }
            Prim::Shape(s) => s.intersect(&Ray { tmax, ..*ray }),
            Prim::Instance(k) => {
                let inst = &self.instances[*k as usize];
                let local = inst.xform.ray_to_object(&Ray { tmax, ..*ray });
                return inst.object.nearest(&local).map(|h| Hit {
                    inst_id: prim_id,
                    ..h
                });
            }
        }?;
        Some(Hit {
            t: h.t,
            geom_id,
            prim_id,
            u: h.u,
            v: h.v,
            ng: h.ng,
            inst_id: NO_INSTANCE,
        })
    }

    /// Whether primitive `i` has any hit in the ray's interval.
    #[inline]
    fn occludes(&self, i: usize, ray: &Ray, wt: &WatertightRay) -> bool {
        match &self.prims[i] {
            Prim::Triangle(t) => t.intersect_wt(wt).is_some(),
            Prim::Shape(s) => s.occluded(ray),
            Prim::Instance(k) => {
                let inst = &self.instances[*k as usize];
                inst.object.any(&inst.xform.ray_to_object(ray))
            }
        }
    }

    fn nearest(&self, ray: &Ray) -> Option<Hit> {
        let mut best: Option<Hit> = None;
        let mut wt = WatertightRay::new(ray);
        let mut tmax = ray.tmax;
        for &i in &self.unbounded {
            if let Some(h) = self.hit_prim(i, ray, &mut wt, tmax) {
                tmax = h.t;
                best = Some(h);
            }
        }
        let ray = Ray { tmax, ..*ray };
        self.traverse(&ray, |i, tmax| {
            match self.hit_prim(i, &ray, &mut wt, tmax) {
                Some(h) => {
                    best = Some(h);
                    Some(h.t)
                }
                None => Some(tmax),
            }
        });
        best
    }

    fn any(&self, ray: &Ray) -> bool {
        let wt = WatertightRay::new(ray);
        if self.unbounded.iter().any(|&i| self.occludes(i, ray, &wt)) {
            return true;
        }
        let mut hit = false;
        self.traverse(ray, |i, tmax| {
            if self.occludes(i, ray, &wt) {
                hit = true;
                None
            } else {
                Some(tmax)
            }
        });
        hit
    }
}

impl Bvh {
    /// The kinds in the leaves and the unbounded list, each instanced object counted
    /// once (see [`AccelStats::kinds`]).
    fn kinds(&self) -> Vec<(Kind, usize)> {
        let mut kinds = Vec::new();
        let mut levels: Vec<&Bvh> = vec![self];
        for inst in &self.instances {
            if !levels.iter().any(|l| std::ptr::eq(*l, &*inst.object)) {
                levels.push(&inst.object);
            }
        }
        for level in levels {
            for &(geom_id, _) in &level.ids {
                if let Some(kind) = Kind::from_id(geom_id) {
                    crate::accel::add_kind(&mut kinds, kind, 1);
                }
            }
        }
        kinds
    }
}

impl Accel for Bvh {
    fn intersect(&self, ray: &Ray) -> Option<Hit> {
        self.nearest(ray)
    }

    fn occluded(&self, ray: &Ray) -> bool {
        self.any(ray)
    }

    fn stats(&self) -> AccelStats {
        AccelStats {
            backend: "bvh",
            prims: self.prims.len(),
            nodes: self.nodes.len(),
            bytes: self.nodes.len() * std::mem::size_of::<Node>()
                + self.prims.len()
                    * (std::mem::size_of::<Prim>() + std::mem::size_of::<(u32, u32)>()),
            detail: format!(
                "binned SAH, {} bins, max leaf {}",
                build::BINS,
                build::MAX_LEAF
            ),
            kinds: self.kinds(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn node_is_32_bytes() {
        assert_eq!(std::mem::size_of::<Node>(), 32);
    }
}

#[cfg(test)]
mod agreement {
    //! The BVH against a brute-force loop over the same intersectors: it must find
    //! exactly the same nearest hit (the same `t`, bit for bit).
    use super::*;
    use crate::geometry::{Cone, Sphere};
    use crate::math::Vec3;
    use crate::scene::{Camera, Material};

    fn rng(seed: &mut u64) -> f32 {
        *seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((*seed >> 40) as f32) / (1u64 << 24) as f32
    }

    fn v(seed: &mut u64, s: f32) -> Vec3 {
        Vec3::new(rng(seed) - 0.5, rng(seed) - 0.5, rng(seed) - 0.5) * s
    }

    pub(crate) fn random_scene(n: usize, seed: &mut u64) -> Scene {
        let cam = Camera {
            from: Vec3::Z * 10.0,
            at: Vec3::ZERO,
            up: Vec3::Y,
            angle_deg: 45.0,
            hither: 0.1,
            width: 8,
            height: 8,
        };
        let mut s = Scene::new(cam);
        s.materials.push(Material::default());
        for _ in 0..n {
            let c = v(seed, 10.0);
            match (rng(seed) * 3.0) as u32 {
                0 => {
                    s.triangles.push(
                        Triangle {
                            p: [c + v(seed, 1.0), c + v(seed, 1.0), c + v(seed, 1.0)],
                        },
                        0,
                    );
                    s.triangle_normals.push(u32::MAX);
                }
                1 => s.spheres.push(Sphere::new(c, 0.05 + rng(seed) * 0.5), 0),
                _ => s.cones.push(
                    Cone::new(c, rng(seed) * 0.5, c + v(seed, 2.0), rng(seed) * 0.5),
                    0,
                ),
            }
        }
        s
    }

    fn brute(scene: &Scene, ray: &Ray) -> Option<(f32, u32, u32)> {
        let mut best: Option<(f32, u32, u32)> = None;
        let mut r = *ray;
        for (i, t) in scene.triangles.items.iter().enumerate() {
            if let Some(h) = t.intersect(&r) {
                r.tmax = h.t;
                best = Some((h.t, 0, i as u32));
            }
        }
        for kind in [Kind::Sphere, Kind::Cone] {
            for i in 0..scene.count(kind) {
                if let Some(h) = scene.shape(kind, i as u32).unwrap().intersect(&r) {
                    r.tmax = h.t;
                    best = Some((h.t, kind as u32, i as u32));
                }
            }
        }
        best
    }

    #[test]
    fn bvh_equals_brute_force() {
        let mut seed = 7u64;
        for n in [0usize, 1, 5, 100, 2000] {
            let scene = random_scene(n, &mut seed);
            let bvh = Bvh::build(&scene);
            let mut hits = 0;
            for _ in 0..3000 {
                let org = v(&mut seed, 30.0);
                let dir = (v(&mut seed, 10.0) - org).normalize();
                let mut ray = Ray::new(org, dir);
                if rng(&mut seed) < 0.3 {
                    ray.tmax = rng(&mut seed) * 30.0;
                }
                let want = brute(&scene, &ray);
                let got = bvh.intersect(&ray);
                assert_eq!(got.map(|h| h.t), want.map(|w| w.0), "n={n} ray {ray:?}");
                if let (Some(g), Some(w)) = (got, want) {
                    hits += 1;
                    // Same primitive unless two primitives are hit at the same t.
                    if (g.geom_id, g.prim_id) != (w.1, w.2) {
                        assert_eq!(g.t, w.0);
                    }
                }
                assert_eq!(bvh.occluded(&ray), want.is_some(), "occluded, n={n}");
            }
            if n >= 100 {
                assert!(hits > 300, "test rays should hit often ({hits})");
            }
        }
    }

    #[test]
    fn tree_is_well_formed() {
        let mut seed = 3u64;
        let scene = random_scene(5000, &mut seed);
        let bvh = Bvh::build(&scene);
        // Every primitive in exactly one leaf, every child inside its parent.
        let mut seen = vec![0u32; bvh.prims.len()];
        let mut stack = vec![(0usize, 0usize)];
        let mut max_depth = 0;
        while let Some((i, depth)) = stack.pop() {
            max_depth = max_depth.max(depth);
            let n = bvh.nodes[i];
            if n.count > 0 {
                let range = n.offset as usize..(n.offset + n.count as u32) as usize;
                for (k, prim) in bvh.prims[range.clone()].iter().enumerate() {
                    seen[range.start + k] += 1;
                    let b = prim.bounds(&bvh.instances);
                    assert!(n.bounds.contains(b.min) && n.bounds.contains(b.max));
                }
            } else {
                for c in [i + 1, n.offset as usize] {
                    let cb = bvh.nodes[c].bounds;
                    assert!(n.bounds.contains(cb.min) && n.bounds.contains(cb.max));
                    stack.push((c, depth + 1));
                }
            }
        }
        assert!(seen.iter().all(|&c| c == 1));
        assert!(max_depth < STACK, "depth {max_depth}");
        // A SAH tree over 5000 scattered primitives is far shallower than a list.
        assert!(max_depth < 40, "depth {max_depth}");
    }

    #[test]
    fn coincident_primitives_still_build() {
        // 10 000 identical spheres: no split separates them; median splits must.
        let mut s = random_scene(0, &mut 1);
        for _ in 0..10_000 {
            s.spheres.push(Sphere::new(Vec3::ZERO, 1.0), 0);
        }
        let bvh = Bvh::build(&s);
        let h = bvh
            .intersect(&Ray::new(Vec3::Z * 5.0, -Vec3::Z))
            .expect("hit");
        assert_eq!(h.t, 4.0);
    }
}
