//! The analytic primitives' object types, one file each: the type's name, the keys it
//! takes, and its constructor, which checks those fields and builds the [`Shape`] in
//! the object's own coordinates moved by an [`At`] offset (the rest of its transform is
//! applied where it is placed).

mod aabox;
mod capped_cone;
mod cone;
mod cylinder;
mod obox;
mod plane;
mod polyhedron;
mod quadric;
mod sphere;
mod torus;

use super::super::format::V3;
use super::super::format::{ObjectDef, Spanned};
use super::types::Ty;
use super::{Builder, R, f32v, v3};
use crate::geometry::Shape;
use crate::math::Vec3;
use glam::DVec3;
use std::fmt;

/// Where a primitive's points go: its keys' coordinates plus `offset`, added in double
/// precision before they become single precision. A primitive placed by a translation
/// alone (the scene's frame origin, and any `translate` steps) is built in place this
/// way, so a primitive far from the world's origin keeps its precision.
#[derive(Clone, Copy, Debug)]
pub(super) struct At {
    /// Added to every point.
    pub(super) offset: DVec3,
}

impl At {
    /// In the object's own coordinates.
    pub(super) const LOCAL: At = At {
        offset: DVec3::ZERO,
    };

    /// The point `v`, moved.
    pub(super) fn point(&self, v: &V3) -> Vec3 {
        f32v(v3(v) + self.offset)
    }
}

/// An analytic primitive's object type.
pub(super) struct AnalyticType {
    /// The value of `type`.
    pub(super) name: &'static str,
    /// The keys it takes besides `type`, `material` and `transform`.
    pub(super) keys: &'static [&'static str],
    /// Its constructor: the shape of an object table of this type, `ty`.
    build: fn(&Builder<'_, '_>, &Spanned<ObjectDef>, Ty, At) -> R<Shape>,
}

/// The analytic types, in the order the list of all types shows them.
pub(super) static ANALYTIC: [AnalyticType; 10] = [
    sphere::TYPE,
    cone::TYPE,
    cylinder::TYPE,
    capped_cone::TYPE,
    aabox::TYPE,
    obox::TYPE,
    polyhedron::TYPE,
    quadric::TYPE,
    plane::TYPE,
    torus::TYPE,
];

/// Types are told apart by name (each name is one type).
impl PartialEq for AnalyticType {
    fn eq(&self, other: &Self) -> bool {
        self.name == other.name
    }
}

impl Eq for AnalyticType {}

impl fmt::Debug for AnalyticType {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name)
    }
}

impl Builder<'_, '_> {
    /// An analytic primitive of type `t` in its own coordinates moved by `at` (before
    /// the rest of its transform).
    pub(super) fn analytic(
        &self,
        node: &Spanned<ObjectDef>,
        t: &'static AnalyticType,
        at: At,
    ) -> R<Shape> {
        (t.build)(self, node, Ty::Analytic(t), at)
    }
}

/// A primitive constructor's message, prefixed with the object type unless it names
/// the primitive already.
fn from_constructor(ty: Ty, e: impl fmt::Display) -> String {
    let e = e.to_string();
    const NAMES: [&str; 9] = [
        "box",
        "oriented box",
        "capped cone",
        "cylinder",
        "polyhedron",
        "prism",
        "quadric",
        "plane",
        "torus",
    ];
    if NAMES.iter().any(|n| e.starts_with(n)) {
        e
    } else {
        format!("{}: {e}", ty.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Kind;
    use std::collections::BTreeSet;
    use std::path::Path;

    /// One object of each analytic type (its keys) and the kind it builds.
    const EXAMPLES: [(&str, &str, Kind); 10] = [
        ("sphere", "center = [0, 0, 0]\nradius = 1", Kind::Sphere),
        (
            "cone",
            "base = [0, 0, 0]\nbase_radius = 1\napex = [0, 1, 0]",
            Kind::Cone,
        ),
        (
            "cylinder",
            "base = [0, 0, 0]\naxis = [0, 1, 0]\nheight = 1\nradius = 1",
            Kind::CappedCone,
        ),
        (
            "capped_cone",
            "base = [0, 0, 0]\naxis = [0, 1, 0]\nheight = 1\nbase_radius = 1\ntop_radius = 0.5",
            Kind::CappedCone,
        ),
        ("box", "min = [0, 0, 0]\nmax = [1, 1, 1]", Kind::Box),
        ("obox", "center = [0, 0, 0]\nsize = [1, 2, 3]", Kind::OBox),
        (
            "polyhedron",
            "preset = \"octahedron\"\nradius = 1",
            Kind::Polyhedron,
        ),
        (
            "quadric",
            "coefficients = [1, 1, 1, 0, 0, 0, 0, 0, 0, -1]",
            Kind::Quadric,
        ),
        (
            "plane",
            "point = [0, 0, 0]\nnormal = [0, 1, 0]",
            Kind::Plane,
        ),
        (
            "torus",
            "center = [0, 0, 0]\naxis = [0, 1, 0]\nmajor_radius = 2\nminor_radius = 0.5",
            Kind::Torus,
        ),
    ];

    /// The kinds table and the object types are different lists (see
    /// [`types`](super::super::types)); this ties them: every analytic type builds its
    /// kind, and the analytic types with the set operations cover every analytic kind.
    #[test]
    fn analytic_types_cover_the_analytic_kinds() {
        let names: Vec<&str> = ANALYTIC.iter().map(|t| t.name).collect();
        let examples: Vec<&str> = EXAMPLES.iter().map(|e| e.0).collect();
        assert_eq!(names, examples, "an example for each analytic type");
        for (name, keys, kind) in EXAMPLES {
            let src = format!(
                "[camera]\nfrom = [0, 0, 5]\nat = [0, 0, 0]\n\n[[objects]]\ntype = \"{name}\"\n{keys}\n"
            );
            let scene = crate::load::toml::parse_str(&src, Path::new("kinds.toml"))
                .unwrap_or_else(|e| panic!("{name}: {e}"));
            let built: Vec<Kind> = scene.geometry.shapes().map(|e| e.kind).collect();
            assert_eq!(built, [kind], "{name}");
        }
        let covered: BTreeSet<Kind> = EXAMPLES.iter().map(|e| e.2).chain([Kind::Csg]).collect();
        assert_eq!(covered, Kind::analytic().collect());
    }
}
