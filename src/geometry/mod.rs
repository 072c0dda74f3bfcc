//! Exact ray/primitive intersectors shared by both backends.
//!
//! The pure-Rust BVH calls them from its leaves; the Embree backend calls the very same
//! functions from its user-geometry callbacks, so the two backends agree by
//! construction on everything but triangles (which Embree intersects natively).
//! Every intersector has a double-precision reference in [`reference`] used by the
//! tests to bound the f32 error.

mod cone;
mod plane;
pub mod polygon;
mod quadric;
pub mod reference;
mod sphere;
mod torus;
mod triangle;

pub use cone::Cone;
pub use plane::Plane;
pub use quadric::Quadric;
pub use sphere::Sphere;
pub use torus::Torus;
pub use triangle::{Triangle, WatertightRay};

use crate::math::{Aabb, Ray, Vec3};

/// What an intersector reports: the distance, two surface parameters and the
/// (unnormalised) geometric normal, which for closed shapes points outwards.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShapeHit {
    /// Ray parameter of the hit.
    pub t: f32,
    /// First surface parameter (triangles: barycentric weight of vertex 1).
    pub u: f32,
    /// Second surface parameter (triangles: barycentric weight of vertex 2).
    pub v: f32,
    /// Geometric normal, not normalised.
    pub ng: Vec3,
}

/// A hit point with the bound of its rounding error, for robust ray spawning.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfacePoint {
    /// The point, computed as accurately as the shape allows (not `o + t·d`).
    pub p: Vec3,
    /// Per-axis absolute error bound of `p`.
    pub err: Vec3,
    /// Unit geometric normal (outwards for closed shapes, by winding for triangles).
    pub ng: Vec3,
}

/// The interface of every analytic primitive: both backends call exactly these (the
/// BVH from its leaves, Embree from its user-geometry callbacks).
///
/// Rays need not have unit directions: instances transform rays into object space
/// without renormalising, and `t` must stay in the units of `ray.dir`.
pub trait Intersect {
    /// Conservative bounds. Unbounded primitives (the infinite plane, unclipped
    /// quadrics that are not ellipsoids) return bounds with infinite coordinates; the
    /// backends keep those out of their hierarchies (see [`Aabb::is_finite`]).
    fn bounds(&self) -> Aabb;
    /// The nearest hit with `t` in `(ray.tmin, ray.tmax)`, from either side of the
    /// surface; `ng` points out of the solid (or along the primitive's front side).
    fn intersect(&self, ray: &Ray) -> Option<ShapeHit>;
    /// Whether any hit lies in `(ray.tmin, ray.tmax)`.
    fn occluded(&self, ray: &Ray) -> bool {
        self.intersect(ray).is_some()
    }
    /// The accurate hit point for a hit this primitive reported for `ray`, with a
    /// per-axis bound on its error and the unit outward geometric normal.
    fn surface(&self, ray: &Ray, hit: &ShapeHit) -> SurfacePoint;
}

/// One stretch of a ray's line inside a solid: from `t_in` (entering, outward normal
/// `n_in`) to `t_out` (leaving, outward normal `n_out`), `t_in <= t_out`. Either end
/// may be infinite only for solids that are unbounded along the line.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Span {
    /// Parameter where the line enters.
    pub t_in: f32,
    /// Outward normal (not necessarily unit) at the entry.
    pub n_in: Vec3,
    /// Parameter where the line leaves.
    pub t_out: f32,
    /// Outward normal (not necessarily unit) at the exit.
    pub n_out: Vec3,
}

/// A short list of spans, sorted by `t_in` and disjoint; inline up to four.
pub type Spans = smallvec::SmallVec<[Span; 4]>;

/// A closed solid usable in CSG: it can list every stretch of a line inside it.
pub trait Solid: Intersect {
    /// Append to `out`, sorted and disjoint, every span where the whole line
    /// `ray.org + t·ray.dir`, `t ∈ (−∞, ∞)`, is inside the solid (ignoring `tmin`/`tmax`).
    fn spans(&self, ray: &Ray, out: &mut Spans);
    /// Whether point `p` is inside (boundary points may go either way).
    fn contains(&self, p: Vec3) -> bool;
}

/// The primitive kinds. The discriminant is the geometry id both backends report in
/// [`crate::Hit::geom_id`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[repr(u32)]
pub enum Kind {
    /// Triangles (from NFF `p` and `pp`).
    Triangle = 0,
    /// Spheres (NFF `s`).
    Sphere = 1,
    /// Open cones and cylinders (NFF `c`).
    Cone = 2,
}

impl Kind {
    /// All kinds in geometry-id order.
    pub const ALL: [Kind; 3] = [Kind::Triangle, Kind::Sphere, Kind::Cone];

    /// The kind with geometry id `id`.
    pub fn from_id(id: u32) -> Option<Kind> {
        Kind::ALL.get(id as usize).copied()
    }

    /// Plural name used in statistics (`triangles`, `spheres`, `cones`).
    pub fn name(self) -> &'static str {
        match self {
            Kind::Triangle => "triangles",
            Kind::Sphere => "spheres",
            Kind::Cone => "cones",
        }
    }
}

/// An analytic primitive, intersected by user geometry on Embree.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shape {
    /// A sphere.
    Sphere(Sphere),
    /// An open cone or cylinder.
    Cone(Cone),
}

impl Shape {
    /// The kind (geometry id) of this shape.
    pub fn kind(&self) -> Kind {
        match self {
            Shape::Sphere(_) => Kind::Sphere,
            Shape::Cone(_) => Kind::Cone,
        }
    }

    /// Conservative bounds.
    pub fn bounds(&self) -> Aabb {
        match self {
            Shape::Sphere(s) => s.bounds(),
            Shape::Cone(c) => c.bounds(),
        }
    }

    /// The nearest hit in `(ray.tmin, ray.tmax)`.
    #[inline]
    pub fn intersect(&self, ray: &Ray) -> Option<ShapeHit> {
        match self {
            Shape::Sphere(s) => s.intersect(ray),
            Shape::Cone(c) => c.intersect(ray),
        }
    }

    /// Whether any hit lies in `(ray.tmin, ray.tmax)`.
    #[inline]
    pub fn occluded(&self, ray: &Ray) -> bool {
        match self {
            Shape::Sphere(s) => s.occluded(ray),
            Shape::Cone(c) => c.occluded(ray),
        }
    }

    /// The accurate hit point for a hit at `t`.
    pub fn surface(&self, ray: &Ray, t: f32) -> SurfacePoint {
        match self {
            Shape::Sphere(s) => s.surface(ray, t),
            Shape::Cone(c) => c.surface(ray, t),
        }
    }
}

/// `a·b − c·d` with one rounding error (Kahan's algorithm with a fused multiply-add).
#[inline]
pub(crate) fn diff_of_products(a: f32, b: f32, c: f32, d: f32) -> f32 {
    let cd = c * d;
    let err = (-c).mul_add(d, cd);
    let dop = a.mul_add(b, -cd);
    dop + err
}

/// The two roots of `a t² + 2 b t + c = 0` as `(entry, exit)`, given
/// `disc = b² − a c ≥ 0`, in the cancellation-free form (q = −(b + sign(b)·√D), roots
/// q/a and c/q).
///
/// With `F(t) = a t² + 2 b t + c` negative inside the solid, the exit root is the one
/// where `F` grows, `a t + b = +√D`, and the entry root the one with `−√D`: this labels
/// the roots exactly, without evaluating a normal at a rounded hit point. When `a → 0`
/// the equation degenerates to linear and `q/a` goes to ±∞ while `c/q` stays the one
/// finite root.
#[inline]
pub(crate) fn quadratic_roots(a: f32, b: f32, c: f32, disc: f32) -> (f32, f32) {
    let q = -(b + disc.sqrt().copysign(b));
    let r_qa = q / a;
    // q = 0 only when b = D = 0: no isolated root.
    let r_cq = if q != 0.0 { c / q } else { f32::NAN };
    // q/a = (−b − sign(b)√D)/a: the entry root when b ≥ 0.
    if b.is_sign_negative() {
        (r_cq, r_qa)
    } else {
        (r_qa, r_cq)
    }
}

impl Intersect for Sphere {
    fn bounds(&self) -> Aabb {
        Sphere::bounds(self)
    }
    #[inline]
    fn intersect(&self, ray: &Ray) -> Option<ShapeHit> {
        Sphere::intersect(self, ray)
    }
    #[inline]
    fn occluded(&self, ray: &Ray) -> bool {
        Sphere::occluded(self, ray)
    }
    fn surface(&self, ray: &Ray, hit: &ShapeHit) -> SurfacePoint {
        Sphere::surface(self, ray, hit.t)
    }
}

impl Intersect for Cone {
    fn bounds(&self) -> Aabb {
        Cone::bounds(self)
    }
    #[inline]
    fn intersect(&self, ray: &Ray) -> Option<ShapeHit> {
        Cone::intersect(self, ray)
    }
    #[inline]
    fn occluded(&self, ray: &Ray) -> bool {
        Cone::occluded(self, ray)
    }
    fn surface(&self, ray: &Ray, hit: &ShapeHit) -> SurfacePoint {
        Cone::surface(self, ray, hit.t)
    }
}
