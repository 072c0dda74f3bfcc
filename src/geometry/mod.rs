//! Exact ray/primitive intersectors shared by both backends.
//!
//! The pure-Rust BVH calls them from its leaves; the Embree backend calls the very same
//! functions from its user-geometry callbacks, so the two backends agree by
//! construction on everything but triangles (which Embree intersects natively).
//! Every intersector has a double-precision reference in [`precise`]
//! used by the tests to bound the f32 error.
//!
//! A primitive kind implements two traits in its own file: [`Intersect`], the ray
//! queries, and [`Primitive`], what a scene primitive adds (texture parameterisation,
//! material, a solid's inside, baking under a transform, meshing for radiosity). The
//! kinds are listed once, in the table behind [`Kind`] and [`Shape`]
//! (`for_each_kind!` in `kinds.rs`), which also declares their modules here:
//! adding an analytic primitive means its own file plus one row in that table.

pub mod bezier;
mod error;
mod kinds;
mod param;
pub mod polygon;
pub mod precise;
pub mod tessellate;
mod triangle;
mod triangle4;

/// Declares the module of each analytic kind and re-exports its type, from the kinds
/// table.
macro_rules! kind_modules {
    ($(($v:ident, $id:literal, $vis:vis mod $module:ident, $name:ident, $t:ty,
        $($rest:tt)*)),* $(,)?) => {
        $($vis mod $module; pub use $module::$name;)*
    };
}
kinds::for_each_kind!(kind_modules);

pub use csg::{CsgOp, CsgTree};
pub use error::ShapeError;
pub use kinds::{Analytic, Kind, Shape};
pub(crate) use kinds::{for_each_kind, kind_rows};
pub use param::{Param, QuadUv, inverse_bilinear};
pub use polyhedron::MAX_PLANES;
pub use tessellate::Tessellation;
pub use triangle::{Triangle, WatertightRay};
pub use triangle4::{Hits4, Triangle4, WatertightRay4};

// A hit point with its error bound: defined in `math`, whose transforms map it.
pub use crate::math::SurfacePoint;

use crate::math::{Aabb, Ray, Vec3};
use glam::DAffine3;

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

/// What a scene primitive adds to the ray queries of [`Intersect`]: its texture
/// parameterisation, the material of a hit, for a closed solid its inside (what CSG
/// combines), its exact rewriting under a transform and its faces for the radiosity
/// mesh. Each kind implements it in its own file; the defaults are those of an open
/// surface (no inside: not a CSG operand, no spans, contains nothing) that neither bakes
/// nor is meshed, and each kind overrides what applies to it.
pub trait Primitive: Intersect {
    /// The texture coordinates and tangents at `p`, a point on the primitive with unit
    /// outward geometric normal `ng` (see [`Param`]).
    fn param(&self, p: Vec3, ng: Vec3) -> Param;

    /// The material of `hit`, given `own`, the primitive's material in the store: `own`
    /// unless a part of the primitive has its own (a CSG leaf).
    #[inline]
    fn material(&self, hit: &ShapeHit, own: u32) -> u32 {
        let _ = hit;
        own
    }

    /// Whether this is a closed solid, usable as a CSG operand (false: an open
    /// surface).
    fn is_solid(&self) -> bool {
        false
    }

    /// Append to `out`, sorted and disjoint, every span where the whole line
    /// `ray.org + t·ray.dir`, `t ∈ (−∞, ∞)`, is inside the solid (ignoring
    /// `tmin`/`tmax`); nothing for an open surface.
    fn spans(&self, ray: &Ray, out: &mut Spans) {
        let _ = (ray, out);
    }

    /// Whether point `p` is inside the solid (boundary points may go either way); false
    /// for an open surface.
    fn contains(&self, p: Vec3) -> bool {
        let _ = p;
        false
    }

    /// This primitive under the affine map `m`, rewritten in final coordinates as a
    /// primitive of the same kind when that is exact (a sphere under a similarity, a
    /// polyhedron under any invertible map, ...). `None`, the default, when it is not:
    /// a loader then places the primitive by an instance, or inside CSG by a transform
    /// of its leaf.
    fn bake(&self, m: &DAffine3) -> Option<Shape> {
        let _ = m;
        None
    }

    /// The primitive as convex planar faces for the radiosity mesh, curved surfaces on
    /// a grid of cells about `patch` across (see [`tessellate`](mod@tessellate)).
    /// `None`, the default, for a kind that is not meshed: it only occludes in the
    /// radiosity pass, the Whitted renderer shades it, and the radiosity report counts
    /// it among the primitives not meshed.
    fn tessellate(&self, patch: f32) -> Option<Tessellation> {
        let _ = patch;
        None
    }
}

/// `a·b − c·d` without cancellation: both products are exact in f64 (24 + 24 bits of
/// significand fit in 53), so the result is rounded once in f64 and once to f32, within
/// about half an f32 ulp of the exact value. (Kahan's algorithm with two fused
/// multiply-adds is within 1.5 ulp, and without the FMA target feature each `mul_add`
/// is a call to a software `fmaf`, several times slower than these five instructions.)
#[inline]
pub(crate) fn diff_of_products(a: f32, b: f32, c: f32, d: f32) -> f32 {
    (f64::from(a) * f64::from(b) - f64::from(c) * f64::from(d)) as f32
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

/// [`quadratic_roots`] in f64, for intersectors that set their quadratic up in f64
/// (the cone): the same labelling, the same cancellation-free form.
#[inline]
pub(crate) fn quadratic_roots_f64(a: f64, b: f64, c: f64, disc: f64) -> (f64, f64) {
    let q = -(b + disc.sqrt().copysign(b));
    let r_qa = q / a;
    let r_cq = if q != 0.0 { c / q } else { f64::NAN };
    if b.is_sign_negative() {
        (r_cq, r_qa)
    } else {
        (r_qa, r_cq)
    }
}

#[cfg(test)]
mod tests {
    use super::diff_of_products;

    #[test]
    fn difference_of_products_keeps_what_cancellation_loses() {
        // 4097² − 4096·4098 = 1 exactly, but 4097² = 16785409 is not an f32 (above
        // 2^24 only even integers are), so the naive f32 expression returns 0 or 2.
        let naive = 4097f32 * 4097f32 - 4096f32 * 4098f32;
        assert_ne!(naive, 1.0);
        assert_eq!(diff_of_products(4097.0, 4097.0, 4096.0, 4098.0), 1.0);
        // Within half an ulp of the exact value, checked in exact integer arithmetic.
        let mut rng = crate::math::Rng::new(0x2545_f491);
        for _ in 0..10_000 {
            // Integers of up to 24 bits, exact in f32.
            let mut next = || i64::from(rng.next_u32() >> 8) - (1 << 23);
            let (a, b, c, d) = (next(), next(), next(), next());
            let exact = i128::from(a) * i128::from(b) - i128::from(c) * i128::from(d);
            let got = diff_of_products(a as f32, b as f32, c as f32, d as f32);
            let ulp = f64::from(got.abs()) * f64::from(f32::EPSILON);
            assert!((got as f64 - exact as f64).abs() <= 0.5 * ulp.max(f64::MIN_POSITIVE));
        }
    }
}
