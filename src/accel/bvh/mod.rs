//! The pure-Rust backend: a binned-SAH bounding volume hierarchy over every primitive
//! kind, stored as a flat node array (left child next to its parent), traversed
//! near-child-first with the far interval shrinking as hits are found.

mod build;

use crate::accel::{Accel, AccelStats, Hit};
use crate::geometry::{Kind, Shape, Triangle, WatertightRay};
use crate::math::{Aabb, Ray};
use crate::scene::Scene;

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
#[derive(Clone, Copy, Debug)]
enum Prim {
    Triangle(Triangle),
    Shape(Shape),
}

/// The built hierarchy.
pub struct Bvh {
    nodes: Vec<Node>,
    prims: Vec<Prim>,
    /// `(geom_id, prim_id)` of each entry of `prims`.
    ids: Vec<(u32, u32)>,
}

/// Traversal stack depth; the builder caps the tree depth below it.
const STACK: usize = 64;

impl Bvh {
    /// Build over every primitive of `scene`.
    pub fn build(scene: &Scene) -> Bvh {
        let mut prims = Vec::with_capacity(scene.prim_count());
        let mut ids = Vec::with_capacity(scene.prim_count());
        for (i, t) in scene.triangles.items.iter().enumerate() {
            prims.push(Prim::Triangle(*t));
            ids.push((Kind::Triangle as u32, i as u32));
        }
        for kind in [Kind::Sphere, Kind::Cone] {
            for i in 0..scene.count(kind) {
                let shape = scene.shape(kind, i as u32).expect("analytic kind");
                prims.push(Prim::Shape(shape));
                ids.push((kind as u32, i as u32));
            }
        }
        let bounds: Vec<Aabb> = prims
            .iter()
            .map(|p| match p {
                Prim::Triangle(t) => t.bounds(),
                Prim::Shape(s) => s.bounds(),
            })
            .collect();
        let (nodes, order) = build::build(&bounds);
        Bvh {
            nodes,
            prims: order.iter().map(|&i| prims[i as usize]).collect(),
            ids: order.iter().map(|&i| ids[i as usize]).collect(),
        }
    }

    /// Number of nodes.
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Walk the tree; `leaf` is called for each primitive index of every leaf the ray
    /// reaches and returns the new `tmax` (or `None` to stop at once).
    #[inline]
    fn traverse(&self, ray: &Ray, mut leaf: impl FnMut(usize, f32) -> Option<f32>) {
        if self.nodes.is_empty() {
            return;
        }
        let inv = ray.dir.recip();
        let neg = [inv.x < 0.0, inv.y < 0.0, inv.z < 0.0];
        let mut tmax = ray.tmax;
        let mut stack = [0u32; STACK];
        let mut sp = 0usize;
        let mut idx = 0usize;
        loop {
            let node = &self.nodes[idx];
            if node.bounds.hit(ray.org, inv, ray.tmin, tmax).is_some() {
                if node.count > 0 {
                    let start = node.offset as usize;
                    for i in start..start + node.count as usize {
                        match leaf(i, tmax) {
                            Some(t) => tmax = t,
                            None => return,
                        }
                    }
                } else {
                    // Visit the child on the ray's side of the split first.
                    let (near, far) = if neg[node.axis as usize] {
                        (node.offset as usize, idx + 1)
                    } else {
                        (idx + 1, node.offset as usize)
                    };
                    stack[sp] = far as u32;
                    sp += 1;
                    idx = near;
                    continue;
                }
            }
            if sp == 0 {
                return;
            }
            sp -= 1;
            idx = stack[sp] as usize;
        }
    }
}

impl Accel for Bvh {
    fn intersect(&self, ray: &Ray) -> Option<Hit> {
        let mut best: Option<Hit> = None;
        let mut wt = WatertightRay::new(ray);
        let mut r = *ray;
        self.traverse(ray, |i, tmax| {
            let h = match &self.prims[i] {
                Prim::Triangle(t) => {
                    wt.set_tmax(tmax);
                    t.intersect_wt(&wt)
                }
                Prim::Shape(s) => {
                    r.tmax = tmax;
                    s.intersect(&r)
                }
            };
            match h {
                Some(h) => {
                    let (geom_id, prim_id) = self.ids[i];
                    best = Some(Hit {
                        t: h.t,
                        geom_id,
                        prim_id,
                        u: h.u,
                        v: h.v,
                        ng: h.ng,
                    });
                    Some(h.t)
                }
                None => Some(tmax),
            }
        });
        best
    }

    fn occluded(&self, ray: &Ray) -> bool {
        let mut hit = false;
        let wt = WatertightRay::new(ray);
        self.traverse(ray, |i, tmax| {
            let h = match &self.prims[i] {
                Prim::Triangle(t) => t.intersect_wt(&wt).is_some(),
                Prim::Shape(s) => s.occluded(ray),
            };
            if h {
                hit = true;
                None
            } else {
                Some(tmax)
            }
        });
        hit
    }

    fn stats(&self) -> AccelStats {
        AccelStats {
            backend: "bvh",
            prims: self.prims.len(),
            nodes: self.nodes.len(),
            bytes: self.nodes.len() * std::mem::size_of::<Node>()
                + self.prims.len()
                    * (std::mem::size_of::<Prim>() + std::mem::size_of::<(u32, u32)>()),
            detail: format!("binned SAH, {} bins, max leaf {}", build::BINS, build::MAX_LEAF),
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
