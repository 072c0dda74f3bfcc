//! The pure-Rust backend: a binned-SAH bounding volume hierarchy over every primitive
//! kind, built binary then collapsed into 4-wide nodes (the four children's boxes
//! stored axis by axis and tested together). Nearest-hit queries visit the children a
//! ray reaches nearest entry first and skip pushed ones that lie beyond the nearest hit
//! found meanwhile; any-hit (shadow) queries visit them in slot order.
//!
//! - `build`: the binary SAH builder;
//! - `wide`: the 4-wide nodes and the collapse into them;
//! - `traverse`: the walk down the 4-wide nodes;
//! - `leaf`: the leaves' primitives in leaf order, triangles four to a pack.

mod build;
mod leaf;
mod traverse;
mod wide;

use crate::accel::unbounded::Unbounded;
use crate::accel::{Accel, AccelStats, Hit, NO_INSTANCE};
use crate::geometry::{Analytic, Intersect, Kind, ShapeHit, WatertightRay, WatertightRay4};
use crate::math::{Aabb, Ray, Xform, next_float_up};
use crate::scene::{Geometry, KindVisitor, Prims, Scene};
use leaf::{Leaf, LeafData, Other, Prim};
use rayon::prelude::*;
use std::sync::Arc;
use traverse::Visit;
use wide::Node4;

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

/// Appends every analytic primitive of the lists it visits to `prims`.
struct Gather<'a> {
    prims: &'a mut Vec<Prim>,
}

impl KindVisitor<'_> for Gather<'_> {
    type Output = ();
    fn visit<P: Analytic>(&mut self, list: &Prims<P>) {
        let shapes = (list.items.par_iter().enumerate())
            .map(|(i, prim)| Prim::Shape(prim.clone().into(), i as u32));
        self.prims.par_extend(shapes);
    }
}

/// The primitives of a level: its triangles, its analytic shapes kind by kind, then
/// `instances` instances.
fn gather(geometry: &Geometry, instances: usize) -> Vec<Prim> {
    let mut prims = Vec::with_capacity(geometry.prim_count() + instances);
    let triangles = (geometry.triangles.items.par_iter().enumerate())
        .map(|(i, t)| Prim::Triangle(*t, i as u32));
    prims.par_extend(triangles);
    geometry.visit_all(&mut Gather { prims: &mut prims });
    prims.extend((0..instances as u32).map(Prim::Instance));
    prims
}

/// What the builder reads of `prims` (with `instance_bounds` for instances): the
/// indices of those that go in the tree, their bounds, and whether each is a triangle.
/// Unbounded primitives stay out of the tree (see `Unbounded`), and so do empty ones
/// (an instance of an object without bounded primitives).
fn tree_prims(prims: &[Prim], instance_bounds: &[Aabb]) -> (Vec<usize>, Vec<Aabb>, Vec<bool>) {
    let (bounded, bounds): (Vec<usize>, Vec<Aabb>) = (prims.par_iter().enumerate())
        .map(|(i, p)| (i, p.bounds(instance_bounds)))
        .filter(|(_, b)| b.is_finite())
        .unzip();
    let triangle = (bounded.par_iter())
        .map(|&i| matches!(prims[i], Prim::Triangle(..)))
        .collect();
    (bounded, bounds, triangle)
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
    /// Bounds of the tree (not of the unbounded primitives).
    tree_bounds: Aabb,
    /// The leaves and their primitives.
    leaves: LeafData,
    /// Primitives in the tree (each triangle once, not the padding lanes of its pack).
    prim_count: usize,
    /// The scene's primitives with infinite bounds (planes, unbounded quadrics, the
    /// instances' copies of them), kept out of every level's tree and tested against
    /// every ray before the top level's (empty in the objects' levels).
    unbounded: Unbounded,
    instances: Vec<PlacedObject>,
    /// The kinds of the top level and of each instanced object, once per object (see
    /// [`AccelStats::kinds`]).
    kinds: Vec<(Kind, usize)>,
}

/// Depth the builder keeps the binary tree below (see `build::SAH_DEPTH`): a bound on
/// the work of one traversal however the primitives lie.
const MAX_DEPTH: usize = 64;

impl Bvh {
    /// Build over every primitive of `scene`: a hierarchy per instanced object, and a
    /// top-level one over the scene's own primitives and the instances; the unbounded
    /// primitives of all of them in one `Unbounded` list.
    pub fn build(scene: &Scene) -> Bvh {
        let objects: Vec<Arc<Bvh>> = scene
            .objects
            .par_iter()
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
    fn build_level(geometry: &Geometry, instances: Vec<PlacedObject>) -> Bvh {
        let prims = gather(geometry, instances.len());
        let instance_bounds: Vec<Aabb> = instances.iter().map(|i| i.bounds).collect();
        let (bounded, bounds, triangle) = tree_prims(&prims, &instance_bounds);
        let (binary, order) = build::build(&bounds, &triangle);
        let tree_bounds = binary.first().map_or(Aabb::EMPTY, |n| n.bounds);
        let (nodes, ranges) = wide::collapse(&binary);
        let order: Vec<usize> = order.par_iter().map(|&k| bounded[k as usize]).collect();
        Bvh {
            nodes,
            tree_bounds,
            leaves: LeafData::new(&ranges, &order, &prims),
            prim_count: order.len(),
            unbounded: Unbounded::default(),
            instances,
            kinds: Vec::new(),
        }
    }

    /// Number of nodes.
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Bytes of the structure: the nodes, the leaves with their primitives, the
    /// unbounded list and the instances, with each instanced object's hierarchy counted
    /// once however many instances place it.
    pub fn memory_bytes(&self) -> usize {
        let own = self.nodes.len() * std::mem::size_of::<Node4>()
            + self.leaves.memory_bytes()
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

    /// Walk the tree (see [`traverse::traverse`]), ordered for nearest-hit queries.
    #[inline]
    fn traverse<const ORDERED: bool>(&self, ray: &Ray, leaf: impl FnMut(&Leaf, f32) -> Visit) {
        traverse::traverse::<ORDERED>(&self.nodes, &self.leaves.leaves, ray, leaf)
    }
}

/// A ray prepared for every primitive kind of a leaf. The 4-wide triangle form is made
/// at the first triangle pack the ray reaches: a ray through analytic shapes alone
/// never pays for it.
struct LeafRay {
    ray: Ray,
    wt: Option<WatertightRay4>,
}

impl LeafRay {
    #[inline]
    fn new(ray: Ray) -> LeafRay {
        LeafRay { ray, wt: None }
    }

    /// The ray for triangle packs, with the far end of its interval at `tmax`.
    #[inline]
    fn watertight(&mut self, tmax: f32) -> &WatertightRay4 {
        let ray = &self.ray;
        let wt = self
            .wt
            .get_or_insert_with(|| WatertightRay4::new(&WatertightRay::new(ray)));
        wt.set_tmax(tmax);
        wt
    }
}

impl Bvh {
    /// The nearest hit among `leaf`'s primitives in `(ray.tmin, tmax)`, or at `tmax`
    /// when it wins the tie with `found`, the nearest hit of the hierarchy so far
    /// ([`Hit::wins_tie_with`]: analytic shapes only), if any: its triangle packs in
    /// order, then its other primitives.
    #[inline]
    fn leaf_nearest(
        &self,
        leaf: &Leaf,
        r: &mut LeafRay,
        mut tmax: f32,
        found: Option<Hit>,
    ) -> Option<Hit> {
        let mut best = None;
        for p in leaf.packs() {
            if let Some((lane, h)) = self.leaves.packs[p].nearest(r.watertight(tmax)) {
                let id = self.leaves.pack_ids[p][lane];
                best = Some(hit(h, Kind::Triangle as u32, id));
                tmax = h.t;
            }
        }
        for o in &self.leaves.others[leaf.others()] {
            let current = best.or(found).filter(|c| c.t == tmax);
            // With a hit at `tmax` already, look up to and including `tmax` for a
            // coincident primitive defined before it.
            let reach = current.map_or(tmax, |_| next_float_up(tmax));
            if let Some(h) = self.other_nearest(
                o,
                &Ray {
                    tmax: reach,
                    ..r.ray
                },
            ) {
                if h.t < tmax || current.is_some_and(|c| h.wins_tie_with(&c)) {
                    tmax = h.t;
                    best = Some(h);
                }
            }
        }
        best
    }

    /// The nearest hit of a shape or instance in the ray's interval.
    #[inline]
    fn other_nearest(&self, o: &Other, ray: &Ray) -> Option<Hit> {
        match o {
            Other::Shape(s, id) => s.intersect(ray).map(|h| hit(h, s.kind() as u32, *id)),
            Other::Instance(k) => {
                let inst = &self.instances[*k as usize];
                let local = inst.xform.ray_to_object(ray);
                inst.object
                    .nearest(&local)
                    .map(|h| Hit { inst_id: *k, ..h })
            }
        }
    }

    /// Whether any of `leaf`'s primitives is hit in the ray's interval.
    #[inline]
    fn leaf_occluded(&self, leaf: &Leaf, r: &mut LeafRay) -> bool {
        let tmax = r.ray.tmax;
        leaf.packs()
            .any(|p| self.leaves.packs[p].occluded(r.watertight(tmax)))
            || self.leaves.others[leaf.others()].iter().any(|o| match o {
                Other::Shape(s, _) => s.occluded(&r.ray),
                Other::Instance(k) => {
                    let inst = &self.instances[*k as usize];
                    inst.object.any(&inst.xform.ray_to_object(&r.ray))
                }
            })
    }

    /// The nearest hit; none for a ray that is not [traceable](Ray::is_traceable).
    fn nearest(&self, ray: &Ray) -> Option<Hit> {
        if !ray.is_traceable() {
            return None;
        }
        // The unbounded primitives first: the hierarchy is searched up to the nearest
        // of them, and one at the same distance as theirs does not displace it.
        let unbounded = self.unbounded.nearest(ray);
        let tmax = unbounded.map_or(ray.tmax, |h| h.t);
        let ray = Ray { tmax, ..*ray };
        let mut r = LeafRay::new(ray);
        let mut found = None;
        self.traverse::<true>(&ray, |leaf, tmax| {
            match self.leaf_nearest(leaf, &mut r, tmax, found) {
                Some(h) => {
                    found = Some(h);
                    Visit::Continue(h.t)
                }
                None => Visit::Continue(tmax),
            }
        });
        found.or(unbounded)
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
        let mut r = LeafRay::new(*ray);
        let mut hit = false;
        self.traverse::<false>(ray, |leaf, tmax| {
            if self.leaf_occluded(leaf, &mut r) {
                hit = true;
                Visit::Stop
            } else {
                Visit::Continue(tmax)
            }
        });
        hit
    }
}

/// A primitive's hit as the backend reports it (outside any instance).
#[inline]
fn hit(h: ShapeHit, geom_id: u32, prim_id: u32) -> Hit {
    Hit {
        t: h.t,
        geom_id,
        prim_id,
        u: h.u,
        v: h.v,
        ng: h.ng,
        inst_id: NO_INSTANCE,
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

/// The leaves test triangles with the watertight test, four at a time with lanes
/// bit-identical to the one-triangle test (`agreement` checks it).
impl Accel for Bvh {
    #[inline(always)]
    fn exact_triangle_hits(&self) -> bool {
        true
    }

    fn intersect(&self, ray: &Ray) -> Option<Hit> {
        self.nearest(ray)
    }

    fn occluded(&self, ray: &Ray) -> bool {
        self.any(ray)
    }

    fn stats(&self) -> AccelStats {
        AccelStats {
            backend: "bvh",
            prims: self.prim_count + self.unbounded.len(),
            nodes: self.nodes.len(),
            bytes: self.memory_bytes(),
            detail: format!(
                "binned SAH, {} bins, max leaf {}, 4-wide nodes, triangles 4 to a pack",
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
    use crate::geometry::{Cone, Sphere, Triangle};
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
                    // What `exact_triangle_hits` promises: testing again changes nothing.
                    let again = scene.geometry.exact_hit(&g, &ray);
                    let bits = |h: &Hit| (h.t.to_bits(), h.u.to_bits(), h.v.to_bits());
                    assert_eq!(bits(&again), bits(&g), "n={n} ray {ray:?}");
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
        let mut seen_tris = vec![0u32; scene.geometry.triangles.items.len()];
        let mut seen_others = 0;
        let mut stack = vec![(0usize, 0usize)];
        let mut max_depth = 0;
        let mut slots = 0;
        let instance_bounds: Vec<Aabb> = bvh.instances.iter().map(|i| i.bounds).collect();
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
                    let leaf_index = (child & !LEAF) as usize;
                    for pb in bvh.leaves.leaf_prim_bounds(leaf_index, &instance_bounds) {
                        assert!(b.contains(pb.min) && b.contains(pb.max));
                    }
                    let leaf = bvh.leaves.leaves[leaf_index];
                    for p in leaf.packs() {
                        let ids = bvh.leaves.pack_ids[p];
                        // Padding lanes repeat the last triangle.
                        let mut lanes = ids.to_vec();
                        lanes.dedup();
                        for id in lanes {
                            seen_tris[id as usize] += 1;
                        }
                    }
                    seen_others += leaf.others().len();
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
        let seen: Vec<u32> = seen_tris;
        assert_eq!(
            seen.len() + seen_others,
            scene.geometry.prim_count(),
            "every primitive in a leaf"
        );
        assert!(seen.iter().all(|&c| c == 1));
        // Collapsing fills the nodes: far fewer than one per two children.
        assert!(slots as f64 > 3.0 * bvh.nodes.len() as f64, "{slots} slots");
        assert!(max_depth < MAX_DEPTH, "depth {max_depth}");
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
        // Packs and shapes alone take more than 30 bytes a primitive.
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
