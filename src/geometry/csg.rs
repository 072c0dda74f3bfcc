//! Constructive solid geometry by span lists (Roth 1982): every leaf reports all the
//! stretches of the ray's line inside it, the set operations combine the sorted lists,
//! and the first boundary of the result inside `(tmin, tmax)` is the hit.
//!
//! A CSG root is one primitive for the backends (one Embree user geometry holds all
//! roots of a scene). Boundaries taken from a subtracted solid carry its normal
//! flipped, so the result's normal always points out of the result. The leaf and the
//! flip travel in the hit's `u`/`v` so that [`Csg::surface`] can ask the leaf for the
//! accurate point.

use super::{Intersect, Param, Primitive, Shape, ShapeError, ShapeHit, Span, Spans, SurfacePoint};
use crate::math::{Aabb, Ray, Vec3, Xform};
use smallvec::SmallVec;

/// A set operation.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum CsgOp {
    /// A ∪ B.
    Union,
    /// A ∩ B.
    Intersection,
    /// A − B.
    Difference,
}

impl CsgOp {
    /// The operation's name in scene files.
    pub fn name(self) -> &'static str {
        match self {
            CsgOp::Union => "union",
            CsgOp::Intersection => "intersection",
            CsgOp::Difference => "difference",
        }
    }

    #[inline]
    fn apply(self, a: bool, b: bool) -> bool {
        match self {
            CsgOp::Union => a || b,
            CsgOp::Intersection => a && b,
            CsgOp::Difference => a && !b,
        }
    }
}

/// A CSG expression as loaders build it.
#[derive(Clone, Debug, PartialEq)]
pub enum CsgTree {
    /// A closed solid, with an optional material of its own (else the root's).
    Leaf {
        /// The solid.
        shape: Shape,
        /// Material index for the surfaces this leaf contributes.
        material: Option<u32>,
    },
    /// A set operation on two operands.
    Op {
        /// The operation.
        op: CsgOp,
        /// Left operand.
        a: Box<CsgTree>,
        /// Right operand.
        b: Box<CsgTree>,
    },
    /// An operand under an affine transform.
    Transform {
        /// Object to parent space.
        xform: Xform,
        /// The transformed operand.
        child: Box<CsgTree>,
    },
}

impl CsgTree {
    /// A leaf without a material of its own.
    pub fn leaf(shape: Shape) -> CsgTree {
        CsgTree::Leaf {
            shape,
            material: None,
        }
    }

    /// `op(a, b)`.
    pub fn op(op: CsgOp, a: CsgTree, b: CsgTree) -> CsgTree {
        CsgTree::Op {
            op,
            a: Box::new(a),
            b: Box::new(b),
        }
    }
}

/// A leaf of a compiled CSG: the solid, the transform from the CSG's space to the
/// leaf's (`None` for the identity) and its material.
#[derive(Clone, Debug, PartialEq)]
struct Leaf {
    shape: Shape,
    xform: Option<Xform>,
    material: Option<u32>,
}

/// One instruction of the postfix program that evaluates the expression.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Step {
    Leaf(u32),
    Op(CsgOp),
}

/// A compiled CSG solid.
#[derive(Clone, Debug, PartialEq)]
pub struct Csg {
    leaves: Vec<Leaf>,
    program: Vec<Step>,
    bounds: Aabb,
}

/// Deepest nesting accepted (the evaluation stack is sized by it).
pub const MAX_DEPTH: usize = 64;

/// A span end: where, the outward normal there, and which leaf (bit 0: flipped).
#[derive(Clone, Copy, Debug, PartialEq)]
struct End {
    t: f32,
    n: Vec3,
    tag: u32,
}

type List = SmallVec<[(End, End); 4]>;

impl Csg {
    /// Compile `tree`; `Err` if a leaf is not a closed solid, the result is unbounded,
    /// or the nesting is deeper than [`MAX_DEPTH`].
    pub fn new(tree: &CsgTree) -> Result<Csg, ShapeError> {
        let mut csg = Csg {
            leaves: Vec::new(),
            program: Vec::new(),
            bounds: Aabb::EMPTY,
        };
        let bounds = csg.compile(tree, None, 1)?;
        if !bounds.is_finite() && !bounds.is_empty() {
            return Err(ShapeError::CsgUnbounded);
        }
        csg.bounds = bounds;
        Ok(csg)
    }

    fn compile(
        &mut self,
        tree: &CsgTree,
        xform: Option<Xform>,
        level: usize,
    ) -> Result<Aabb, ShapeError> {
        if level > MAX_DEPTH {
            return Err(ShapeError::CsgTooDeep);
        }
        match tree {
            CsgTree::Leaf { shape, material } => {
                if !shape.is_solid() {
                    return Err(ShapeError::NotSolid(shape.kind()));
                }
                let b = shape.bounds();
                let b = match &xform {
                    Some(x) => x.bounds_to_world(&b),
                    None => b,
                };
                let id = u32::try_from(self.leaves.len())
                    .ok()
                    .filter(|&i| i < 1 << 23)
                    .ok_or(ShapeError::CsgTooManyLeaves)?;
                self.leaves.push(Leaf {
                    shape: shape.clone(),
                    xform,
                    material: *material,
                });
                self.program.push(Step::Leaf(id));
                Ok(b)
            }
            CsgTree::Op { op, a, b } => {
                let ba = self.compile(a, xform, level + 1)?;
                let bb = self.compile(b, xform, level + 1)?;
                self.program.push(Step::Op(*op));
                let bounds = match op {
                    CsgOp::Union => ba.union(&bb),
                    CsgOp::Intersection => Aabb {
                        min: ba.min.max(bb.min),
                        max: ba.max.min(bb.max),
                    },
                    CsgOp::Difference => ba,
                };
                Ok(bounds)
            }
            CsgTree::Transform { xform: x, child } => {
                let combined = match xform {
                    Some(outer) => outer.then_inner(x),
                    None => *x,
                };
                self.compile(child, Some(combined), level + 1)
            }
        }
    }

    /// Number of leaves.
    pub fn leaf_count(&self) -> usize {
        self.leaves.len()
    }

    /// The material of leaf `i`, if it has its own.
    pub fn leaf_material(&self, i: usize) -> Option<u32> {
        self.leaves.get(i).and_then(|l| l.material)
    }

    /// The spans of the whole line through the result.
    fn evaluate(&self, ray: &Ray) -> List {
        let mut stack: SmallVec<[List; 4]> = SmallVec::new();
        let mut scratch = Spans::new();
        for step in &self.program {
            match *step {
                Step::Leaf(i) => {
                    let leaf = &self.leaves[i as usize];
                    scratch.clear();
                    let mut list = List::new();
                    match &leaf.xform {
                        None => leaf.shape.spans(ray, &mut scratch),
                        Some(x) => leaf.shape.spans(&x.ray_to_object(ray), &mut scratch),
                    }
                    for s in &scratch {
                        let (n_in, n_out) = match &leaf.xform {
                            None => (s.n_in, s.n_out),
                            Some(x) => (x.normal_to_world(s.n_in), x.normal_to_world(s.n_out)),
                        };
                        let tag = i << 1;
                        list.push((
                            End {
                                t: s.t_in,
                                n: n_in,
                                tag,
                            },
                            End {
                                t: s.t_out,
                                n: n_out,
                                tag,
                            },
                        ));
                    }
                    stack.push(list);
                }
                Step::Op(op) => {
                    let b = stack.pop().unwrap_or_default();
                    let a = stack.pop().unwrap_or_default();
                    stack.push(combine(op, &a, &b));
                }
            }
        }
        stack.pop().unwrap_or_default()
    }

    /// Every boundary of the result along the line, in order (for tests and tools).
    pub fn boundaries(&self, ray: &Ray) -> Vec<(f32, Vec3)> {
        self.evaluate(ray)
            .iter()
            .flat_map(|(a, b)| [(a.t, a.n), (b.t, b.n)])
            .collect()
    }

    fn first(&self, ray: &Ray) -> Option<End> {
        if !(ray.org.is_finite() && ray.dir.is_finite()) {
            return None;
        }
        self.evaluate(ray)
            .iter()
            .flat_map(|(a, b)| [*a, *b])
            .find(|e| e.t > ray.tmin && e.t < ray.tmax && e.t.is_finite())
    }

    /// Which leaf a hit came from and whether its normal was flipped.
    pub fn hit_leaf(hit: &ShapeHit) -> (usize, bool) {
        (hit.u as usize, hit.v != 0.0)
    }
}

/// Combine two sorted, disjoint span lists by `op`, sweeping their boundaries in order.
fn combine(op: CsgOp, a: &List, b: &List) -> List {
    let mut out = List::new();
    let (mut ia, mut ib) = (0usize, 0usize);
    let (mut in_a, mut in_b, mut inside) = (false, false, false);
    let mut start: Option<End> = None;
    let event = |l: &List, k: usize| -> Option<End> {
        l.get(k / 2).map(|s| if k % 2 == 0 { s.0 } else { s.1 })
    };
    loop {
        let ea = event(a, ia);
        let eb = event(b, ib);
        let (e, from_b) = match (ea, eb) {
            (None, None) => break,
            (Some(x), None) => (x, false),
            (None, Some(y)) => (y, true),
            (Some(x), Some(y)) => {
                if x.t <= y.t {
                    (x, false)
                } else {
                    (y, true)
                }
            }
        };
        let mut e = e;
        if from_b {
            ib += 1;
            in_b = !in_b;
            if op == CsgOp::Difference {
                e.n = -e.n;
                e.tag ^= 1;
            }
        } else {
            ia += 1;
            in_a = !in_a;
        }
        let now = op.apply(in_a, in_b);
        if now != inside {
            inside = now;
            if now {
                start = Some(e);
            } else if let Some(s) = start.take() {
                // Zero-length stretches (A − A, touching solids) are no surface at all.
                if e.t > s.t {
                    out.push((s, e));
                }
            }
        }
    }
    out
}

impl Intersect for Csg {
    fn bounds(&self) -> Aabb {
        self.bounds
    }

    fn intersect(&self, ray: &Ray) -> Option<ShapeHit> {
        let e = self.first(ray)?;
        Some(ShapeHit {
            t: e.t,
            u: (e.tag >> 1) as f32,
            v: (e.tag & 1) as f32,
            ng: e.n,
        })
    }

    fn occluded(&self, ray: &Ray) -> bool {
        self.first(ray).is_some()
    }

    fn surface(&self, ray: &Ray, hit: &ShapeHit) -> SurfacePoint {
        let (i, flip) = Csg::hit_leaf(hit);
        let Some(leaf) = self.leaves.get(i) else {
            let p = ray.at(hit.t);
            return SurfacePoint {
                p,
                err: p.abs() * crate::math::gamma(4),
                ng: hit.ng.normalize_or(-ray.dir.normalize()),
            };
        };
        let n_world = if flip { -hit.ng } else { hit.ng };
        let sp = match &leaf.xform {
            None => leaf.shape.surface(
                ray,
                &ShapeHit {
                    ng: n_world,
                    ..*hit
                },
            ),
            Some(x) => {
                let local = x.ray_to_object(ray);
                let sp = leaf.shape.surface(
                    &local,
                    &ShapeHit {
                        ng: x.normal_to_object(n_world),
                        ..*hit
                    },
                );
                x.surface_to_world(&sp)
            }
        };
        SurfacePoint {
            ng: if flip { -sp.ng } else { sp.ng },
            ..sp
        }
    }
}

impl Primitive for Csg {
    fn is_solid(&self) -> bool {
        true
    }

    fn spans(&self, ray: &Ray, out: &mut Spans) {
        out.extend(self.evaluate(ray).iter().map(|(a, b)| Span {
            t_in: a.t,
            n_in: a.n,
            t_out: b.t,
            n_out: b.n,
        }));
    }

    fn contains(&self, p: Vec3) -> bool {
        let mut stack: SmallVec<[bool; 16]> = SmallVec::new();
        for step in &self.program {
            match *step {
                Step::Leaf(i) => {
                    let leaf = &self.leaves[i as usize];
                    let q = match &leaf.xform {
                        None => p,
                        Some(x) => x.to_object.transform_point3(p),
                    };
                    stack.push(leaf.shape.contains(q));
                }
                Step::Op(op) => {
                    let b = stack.pop().unwrap_or(false);
                    let a = stack.pop().unwrap_or(false);
                    stack.push(op.apply(a, b));
                }
            }
        }
        stack.pop().unwrap_or(false)
    }

    /// The planar parameterisation about the normal ([`Param::planar`]).
    fn param(&self, p: Vec3, ng: Vec3) -> Param {
        Param::planar(p, ng)
    }
    /// The material of the leaf hit, if it has its own.
    fn material(&self, hit: &ShapeHit, own: u32) -> u32 {
        let (leaf, _) = Csg::hit_leaf(hit);
        self.leaf_material(leaf).unwrap_or(own)
    }
}
