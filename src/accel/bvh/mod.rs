//! The pure-Rust backend: a binned-SAH bounding volume hierarchy over every primitive
//! kind, built binary and collapsed into 4-wide nodes (the four children's boxes stored
//! axis by axis and tested together). Nearest-hit queries visit the children a ray
//! reaches nearest entry first and skip pushed ones that lie beyond the nearest hit
//! found meanwhile; any-hit (shadow) queries visit them in slot order.

mod build;
mod wide;

use crate::accel::unbounded::Unbounded;
use crate::accel::{Accel, AccelStats, Hit, NO_INSTANCE};
use crate::geometry::{Analytic, Intersect, Kind, Shape, Triangle, WatertightRay};
use crate::math::{Aabb, Ray, Xform};
use crate::scene::{Geometry, KindVisitor, Prims, Scene};
use std::sync::Arc;
use wide::{Node4, Visit};

/// One node of the binary tree the builder makes (then collapsed into [`Node4`]s): 32
/// bytes.
#[derive(Clone, Copy, Debug)]
#[repr(C)]
struct Node {
    bounds: Aabb,
    /// Leaf: index of the first primitive. Interior: index of the second child (the
    /// first child is the next node).
    offset: u32,
    /// Number of primitives; 0 for an interior node.
    count: u16,
    /// Split axis of an interior node.
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

/// Appends every analytic primitive of the lists it visits to `prims`, with its
/// `(geom_id, prim_id)` in `ids`.
struct Gather<'a> {
    prims: &'a mut Vec<Prim>,
    ids: &'a mut Vec<(u32, u32)>,
}

impl KindVisitor for Gather<'_> {
    type Output = ();
    fn visit<P: Analytic>(&mut self, list: &Prims<P>) {
        for (i, prim, _) in list.iter() {
            self.prims.push(Prim::Shape(prim.clone().into()));
            self.ids.push((P::KIND as u32, i));
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
    nodes: Vec<Node4>,
    /// `(first primitive, count)` of each leaf.
    leaves: Vec<(u32, u32)>,
    /// Stack depth a traversal needs (see [`wide::collapse`]).
    stack_need: usize,
    /// Bounds of the tree (not of the unbounded primitives).
    tree_bounds: Aabb,
    prims: Vec<Prim>,
    /// `(geom_id, prim_id)` of each entry of `prims` (`(u32::MAX, instance)` for
    /// instances).
    ids: Vec<(u32, u32)>,
    /// The scene's primitives with infinite bounds (planes, unbounded quadrics, the
    /// instances' copies of them), kept out of every level's tree and tested against
    /// every ray before the top level's (empty in the objects' levels).
    unbounded: Unbounded,
    instances: Vec<PlacedObject>,
    /// The kinds of the top level and of each instanced object, once per object (see
    /// [`AccelStats::kinds`]).
    kinds: Vec<(Kind, usize)>,
}

/// Traversal stack depth; the builder caps the tree depth below it.
const STACK: usize = 64;

impl Bvh {
    /// Build over every primitive of `scene`: a hierarchy per instanced object, and a
    /// top-level one over the scene's own primitives and the instances; the unbounded
    /// primitives of all of them in one [`Unbounded`] list.
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
                let bounds = inst.xform.bounds_to_world(&object.tree_bounds);
                PlacedObject {
                    xform: inst.xform,
                    object,
                    bounds,
                }
            })
            .collect();
        let mut bvh = Bvh::build_level(&scene.geometry, instances);
        bvh.unbounded = Unbounded::new(scene);
        bvh.kinds = scene_kinds(scene);
        bvh
    }

    /// The hierarchy over the bounded primitives of `geometry` and `instances` (an
    /// instance whose object's tree is empty is left out).
    /// Bytes of the hierarchy: nodes, leaves, the primitives it holds with their ids,
    /// the unbounded list, the placed instances, and each instanced object's hierarchy
    /// once however often it is placed.
    pub fn memory_bytes(&self) -> usize {
        let own = self.nodes.len() * std::mem::size_of::<Node4>()
            + self.leaves.len() * std::mem::size_of::<(u32, u32)>()
            + self.prims.len() * (std::mem::size_of::<Prim>() + std::mem::size_of::<(u32, u32)>())
            + self.unbounded.memory_bytes()
            + self.instances.len() * std::mem::size_of::<PlacedObject>();
        let mut seen = std::collections::HashSet::new();
        let objects: usize = self
            .instances
            .iter()
            .filter(|i| seen.insert(Arc::as_ptr(&i.object)))
            .map(|i| i.object.memory_bytes())
            .sum();
        own + objects
    }

    fn build_level(geometry: &Geometry, instances: Vec<PlacedObject>) -> Bvh {
        let n = geometry.prim_count() + instances.len();
        let mut prims = Vec::with_capacity(n);
        let mut ids = Vec::with_capacity(n);
        for (i, t) in geometry.triangles.items.iter().enumerate() {
            prims.push(Prim::Triangle(*t));
            ids.push((Kind::Triangle as u32, i as u32));
        }
        geometry.visit_all(&mut Gather {
            prims: &mut prims,
            ids: &mut ids,
        });
        for i in 0..instances.len() {
            prims.push(Prim::Instance(i as u32));
            ids.push((u32::MAX, i as u32));
        }
        let all_bounds: Vec<Aabb> = prims.iter().map(|p| p.bounds(&instances)).collect();
        // Unbounded primitives stay out of the tree (see `Unbounded`), and so do empty
        // ones (an instance of an object without bounded primitives).
        let bounded: Vec<usize> = (0..prims.len())
            .filter(|&i| all_bounds[i].is_finite())
            .collect();
        let bounds: Vec<Aabb> = bounded.iter().map(|&i| all_bounds[i]).collect();
        let (binary, order) = build::build(&bounds);
        let tree_bounds = binary.first().map_or(Aabb::EMPTY, |n| n.bounds);
        let (nodes, leaves, stack_need) = wide::collapse(&binary);
        let out_prims: Vec<Prim> = order
            .iter()
            .map(|&k| prims[bounded[k as usize]].clone())
            .collect();
        let out_ids: Vec<(u32, u32)> = order.iter().map(|&k| ids[bounded[k as usize]]).collect();
        Bvh {
            nodes,
            leaves,
            stack_need,
            tree_bounds,
            prims: out_prims,
            ids: out_ids,
            unbounded: Unbounded::default(),
            instances,
            kinds: Vec::new(),
        }
    }

    /// Number of nodes.
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Walk the tree (see [`wide::traverse`]), ordered for nearest-hit queries.
    #[inline]
    fn traverse<const ORDERED: bool>(&self, ray: &Ray, leaf: impl FnMut(usize, f32) -> Visit) {
        if self.stack_need <= wide::STACK_SMALL {
            wide::traverse::<ORDERED, { wide::STACK_SMALL }>(&self.nodes, &self.leaves, ray, leaf)
        } else {
            wide::traverse::<ORDERED, { wide::STACK4 }>(&self.nodes, &self.leaves, ray, leaf)
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

    /// The nearest hit; none for a ray that is not [traceable](Ray::is_traceable).
    fn nearest(&self, ray: &Ray) -> Option<Hit> {
        if !ray.is_traceable() {
            return None;
        }
        let mut best = self.unbounded.nearest(ray);
        let mut wt = WatertightRay::new(ray);
        let tmax = best.map_or(ray.tmax, |h| h.t);
        let ray = Ray { tmax, ..*ray };
        self.traverse::<true>(&ray, |i, tmax| {
            match self.hit_prim(i, &ray, &mut wt, tmax) {
                Some(h) => {
                    best = Some(h);
                    Visit::Continue(h.t)
                }
                None => Visit::Continue(tmax),
            }
        });
        best
    }

    /// Whether anything is hit; nothing is for a ray that is not
    /// [traceable](Ray::is_traceable).
    fn any(&self, ray: &Ray) -> bool {
        if !ray.is_traceable() {
            return false;
        }
        if self.unbounded.any(ray) {
            return true;
        }
        let wt = WatertightRay::new(ray);
        let mut hit = false;
        self.traverse::<false>(ray, |i, tmax| {
            if self.occludes(i, ray, &wt) {
                hit = true;
                Visit::Stop
            } else {
                Visit::Continue(tmax)
            }
        });
        hit
    }
}

/// The kinds of `scene`'s top level and of each object its instances place, each
/// object counted once (see [`AccelStats::kinds`]).
fn scene_kinds(scene: &Scene) -> Vec<(Kind, usize)> {
    let mut kinds = Vec::new();
    let mut levels: Vec<&Geometry> = vec![&scene.geometry];
    let mut placed = vec![false; scene.objects.len()];
    for inst in &scene.instances {
        let object = inst.object as usize;
        if !std::mem::replace(&mut placed[object], true) {
            levels.push(&scene.objects[object]);
        }
    }
    for level in levels {
        for kind in Kind::ALL {
            crate::accel::add_kind(&mut kinds, kind, level.count(kind));
        }
    }
    kinds
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
            prims: self.prims.len() + self.unbounded.len(),
            nodes: self.nodes.len(),
            bytes: self.memory_bytes(),
            detail: format!(
                "binned SAH, {} bins, max leaf {}, 4-wide nodes",
                build::BINS,
                build::MAX_LEAF
            ),
            kinds: self.kinds.clone(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn node_sizes() {
        assert_eq!(std::mem::size_of::<Node>(), 32);
        // A 4-wide node fills exactly two cache lines and starts on one.
        assert_eq!(std::mem::size_of::<Node4>(), 128);
        assert_eq!(std::mem::align_of::<Node4>(), 64);
    }
}

#[cfg(test)]
mod agreement {
    //! The BVH against a brute-force loop over the same intersectors: it must find
    //! exactly the same nearest hit (the same `t`, bit for bit).
    use super::wide::LEAF;
    use super::*;
    use crate::geometry::{Cone, Sphere};
    use crate::math::{Rng, Vec3};
    use crate::scene::{Camera, Material};

    /// A point uniform in the cube of edge `s` about the origin.
    fn v(rng: &mut Rng, s: f32) -> Vec3 {
        rng.vec3_in(-0.5 * s, 0.5 * s)
    }

    pub(crate) fn random_scene(n: usize, rng: &mut Rng) -> Scene {
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
            let c = v(rng, 10.0);
            match rng.below(3) {
                0 => {
                    s.geometry.triangles.push(
                        Triangle {
                            p: [c + v(rng, 1.0), c + v(rng, 1.0), c + v(rng, 1.0)],
                        },
                        0,
                    );
                    s.geometry.triangle_normals.push(u32::MAX);
                }
                1 => s.geometry.push(Sphere::new(c, rng.range(0.05, 0.55)), 0),
                _ => s.geometry.push(
                    Cone::new(c, rng.range(0.0, 0.5), c + v(rng, 2.0), rng.range(0.0, 0.5)),
                    0,
                ),
            }
        }
        s
    }

    fn brute(scene: &Scene, ray: &Ray) -> Option<(f32, u32, u32)> {
        let mut best: Option<(f32, u32, u32)> = None;
        let mut r = *ray;
        for (i, t) in scene.geometry.triangles.items.iter().enumerate() {
            if let Some(h) = t.intersect(&r) {
                r.tmax = h.t;
                best = Some((h.t, 0, i as u32));
            }
        }
        for kind in [Kind::Sphere, Kind::Cone] {
            for i in 0..scene.geometry.count(kind) {
                if let Some(h) = scene.geometry.shape(kind, i as u32).unwrap().intersect(&r) {
                    r.tmax = h.t;
                    best = Some((h.t, kind as u32, i as u32));
                }
            }
        }
        best
    }

    #[test]
    fn bvh_equals_brute_force() {
        let mut rng = Rng::new(7);
        for n in [0usize, 1, 5, 100, 2000] {
            let scene = random_scene(n, &mut rng);
            let bvh = Bvh::build(&scene);
            let mut hits = 0;
            for _ in 0..3000 {
                let org = v(&mut rng, 30.0);
                let dir = (v(&mut rng, 10.0) - org).normalize();
                let mut ray = Ray::new(org, dir);
                if rng.next_f32() < 0.3 {
                    ray.tmax = rng.range(0.0, 30.0);
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
        let scene = random_scene(5000, &mut Rng::new(3));
        let bvh = Bvh::build(&scene);
        // Every primitive in exactly one leaf, every child inside its parent's slot.
        let mut seen = vec![0u32; bvh.prims.len()];
        let mut stack = vec![(0usize, 0usize)];
        let mut max_depth = 0;
        let mut slots = 0;
        while let Some((i, depth)) = stack.pop() {
            max_depth = max_depth.max(depth);
            let n = bvh.nodes[i];
            for slot in 0..4 {
                let (child, b) = (n.child[slot], n.slot_bounds(slot));
                if child == u32::MAX {
                    assert!(b.is_empty());
                    continue;
                }
                slots += 1;
                if child & LEAF != 0 {
                    let (start, count) = bvh.leaves[(child & !LEAF) as usize];
                    let range = start as usize..(start + count) as usize;
                    for (k, prim) in bvh.prims[range.clone()].iter().enumerate() {
                        seen[range.start + k] += 1;
                        let pb = prim.bounds(&bvh.instances);
                        assert!(b.contains(pb.min) && b.contains(pb.max));
                    }
                } else {
                    let c = bvh.nodes[child as usize];
                    for cs in 0..4 {
                        let cb = c.slot_bounds(cs);
                        assert!(cb.is_empty() || (b.contains(cb.min) && b.contains(cb.max)));
                    }
                    stack.push((child as usize, depth + 1));
                }
            }
        }
        assert!(seen.iter().all(|&c| c == 1));
        assert!(bvh.stack_need <= wide::STACK4, "stack {}", bvh.stack_need);
        assert!(bvh.stack_need >= max_depth, "stack {}", bvh.stack_need);
        // Collapsing fills the nodes: far fewer than one per two children.
        assert!(slots as f64 > 3.0 * bvh.nodes.len() as f64, "{slots} slots");
        assert!(max_depth < STACK, "depth {max_depth}");
        // A SAH tree over 5000 scattered primitives is far shallower than a list.
        assert!(max_depth < 40, "depth {max_depth}");
    }

    #[test]
    fn memory_counts_an_instanced_object_once() {
        use crate::scene::Instance;
        let mut rng = Rng::new(5);
        let mut scene = random_scene(200, &mut rng);
        let flat = Bvh::build(&scene);
        let own = flat.memory_bytes();
        // The primitives alone take more than 30 bytes each.
        assert!(own > 200 * 30, "{own}");
        assert_eq!(flat.stats().bytes, own);
        scene.objects.push(random_scene(300, &mut rng).geometry);
        let place = |x: f32| Instance {
            object: 0,
            xform: Xform::new(glam::Affine3A::from_translation(Vec3::X * x)).unwrap(),
            material: 0,
        };
        scene.instances.push(place(20.0));
        let once = Bvh::build(&scene).memory_bytes();
        scene.instances.push(place(40.0));
        let twice = Bvh::build(&scene).memory_bytes();
        let object = Bvh::build_level(&scene.objects[0], Vec::new()).memory_bytes();
        assert!(once > own + object, "{once} vs {own} + {object}");
        // A second instance adds its place in the top level, not the object again.
        assert!(twice - once < object / 4, "{twice} − {once} vs {object}");
    }

    #[test]
    fn coincident_primitives_still_build() {
        // 10 000 identical spheres: no split separates them; median splits must.
        let mut s = random_scene(0, &mut Rng::new(1));
        for _ in 0..10_000 {
            s.geometry.push(Sphere::new(Vec3::ZERO, 1.0), 0);
        }
        let bvh = Bvh::build(&s);
        let h = bvh
            .intersect(&Ray::new(Vec3::Z * 5.0, -Vec3::Z))
            .expect("hit");
        assert_eq!(h.t, 4.0);
    }
}
