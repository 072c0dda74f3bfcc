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
    /// The keys of an object of this type, as a scene file writes them (the tests
    /// build it).
    #[cfg(test)]
    example: &'static str,
}

/// The analytic types, in the order the list of all types shows them.
pub(super) static ANALYTIC: &[AnalyticType] = &[
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
/// the primitive already (it starts with the type's name or one of the names the
/// constructors give their primitives).
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
    if e.starts_with(ty.name()) || NAMES.iter().any(|n| e.starts_with(n)) {
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

    /// The kinds table and the object types are different lists (see
    /// [`types`](super::super::types)); this ties them: the example of every analytic
    /// type builds one primitive, and the analytic types with the set operations cover
    /// every analytic kind.
    #[test]
    fn analytic_types_cover_the_analytic_kinds() {
        let mut covered = BTreeSet::from([Kind::Csg]);
        for t in ANALYTIC {
            let src = format!(
                "[camera]\nfrom = [0, 0, 5]\nat = [0, 0, 0]\n\n[[objects]]\ntype = \"{}\"\n{}\n",
                t.name, t.example
            );
            let scene = crate::load::toml::parse_str(&src, Path::new("kinds.toml"))
                .unwrap_or_else(|e| panic!("{}: {e}", t.name));
            let built: Vec<Kind> = scene.geometry.shapes().map(|e| e.kind).collect();
            assert_eq!(built.len(), 1, "{}", t.name);
            covered.extend(built);
        }
        assert_eq!(covered, Kind::analytic().collect());
    }
}
