//! What a ray query reports: the hit, in the same terms whichever backend found it.

use crate::geometry::Kind;
use crate::math::Vec3;

/// The nearest hit along a ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Ray parameter.
    pub t: f32,
    /// Geometry id: a [`Kind`] discriminant.
    pub geom_id: u32,
    /// Index of the primitive within its kind.
    pub prim_id: u32,
    /// First surface parameter (triangles: barycentric weight of vertex 1).
    pub u: f32,
    /// Second surface parameter (triangles: barycentric weight of vertex 2).
    pub v: f32,
    /// Geometric normal, not normalised; for triangles `(p1 − p0) × (p2 − p0)`. In the
    /// object space of the instance for instanced hits.
    pub ng: Vec3,
    /// Index of the instance hit ([`crate::scene::Scene::instances`]), or
    /// [`NO_INSTANCE`] for top-level primitives.
    pub inst_id: u32,
}

/// [`Hit::inst_id`] of a top-level primitive.
pub const NO_INSTANCE: u32 = u32::MAX;

impl Hit {
    /// Whether this hit, at the same distance as `current` and on the same level (the
    /// scene's top level, or the same instance), is the one to keep: the rule for
    /// coincident primitives, which both backends apply to their analytic shapes. The
    /// primitive defined first wins: the lower index within a kind, and between kinds
    /// the kind listed first in the kinds table.
    #[inline]
    pub fn wins_tie_with(&self, current: &Hit) -> bool {
        self.t == current.t
            && self.inst_id == current.inst_id
            && (self.geom_id, self.prim_id) < (current.geom_id, current.prim_id)
    }

    /// The primitive kind hit.
    pub fn kind(&self) -> Kind {
        Kind::from_id(self.geom_id).expect("invalid geometry id")
    }
}
