//! The object types: each `type` an object table can have, the keys each takes, and
//! the check that a table is of a known type and has none but its keys.
//!
//! The types are words of the scene format, not the primitive kinds of
//! [`Kind`](crate::geometry::Kind): `cylinder` and `capped_cone` both build a capped
//! cone, `union`, `intersection` and `difference` build the one CSG kind, a
//! `polyhedron` may be a preset or a prism, and meshes, Bézier patches, includes,
//! groups and instances are not primitives of their own. The analytic types come
//! first, from [`ANALYTIC`].

use super::super::format::{ObjectDef, Spanned};
use super::shapes::{ANALYTIC, AnalyticType};
use super::{Builder, R, article, did_you_mean};
use crate::geometry::CsgOp;

/// Deepest nesting of objects (groups, CSG, instances copied into defines).
const MAX_NESTING: usize = 256;

/// An object type.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Ty {
    /// An analytic primitive (sphere, cone, box, ...).
    Analytic(&'static AnalyticType),
    Triangle,
    Polygon,
    Mesh,
    Bezier,
    Include,
    Group,
    Instance,
    /// `union`, `intersection` or `difference`.
    Csg(CsgOp),
}

/// The types other than the analytic primitives: each one's name and the keys it takes
/// besides `type`, `material` and `transform`.
const OTHER_TYPES: [(&str, Ty, &[&str]); 10] = [
    ("triangle", Ty::Triangle, &["vertices", "normals"]),
    ("polygon", Ty::Polygon, &["vertices", "normals"]),
    ("mesh", Ty::Mesh, &["vertices", "faces", "normals"]),
    ("bezier", Ty::Bezier, &["patches", "builtin", "tolerance"]),
    ("include", Ty::Include, &["file", "lights"]),
    ("group", Ty::Group, &["children"]),
    ("instance", Ty::Instance, &["of"]),
    ("union", Ty::Csg(CsgOp::Union), &["children"]),
    ("intersection", Ty::Csg(CsgOp::Intersection), &["children"]),
    ("difference", Ty::Csg(CsgOp::Difference), &["children"]),
];

/// Every type's name, type and keys (besides `type`, `material` and `transform`): the
/// analytic primitives, then the others.
fn types() -> impl Iterator<Item = (&'static str, Ty, &'static [&'static str])> {
    ANALYTIC
        .iter()
        .map(|t| (t.name, Ty::Analytic(t), t.keys))
        .chain(OTHER_TYPES)
}

impl Ty {
    /// The name the scene file gives the type.
    pub(super) fn name(self) -> &'static str {
        types().find(|t| t.1 == self).map_or("?", |t| t.0)
    }
}

impl Builder<'_, '_> {
    /// The node's type, after checking that it takes every key it has.
    pub(super) fn ty(&self, node: &Spanned<ObjectDef>, depth: usize) -> R<Ty> {
        let o = node.get_ref();
        if depth > MAX_NESTING {
            return Err(self.err(
                node.span(),
                format!("objects nested deeper than {MAX_NESTING} levels"),
            ));
        }
        let name = o.ty.get_ref().as_str();
        let Some((_, ty, keys)) = types().find(|t| t.0 == name) else {
            let all: Vec<&str> = types().map(|t| t.0).collect();
            return Err(self.err(
                o.ty.span(),
                format!(
                    "unknown object type `{name}`{}; types: {}",
                    did_you_mean(name, all.iter().copied()),
                    all.join(", ")
                ),
            ));
        };
        for (key, span) in o.keys() {
            if key != "material" && key != "transform" && !keys.contains(&key) {
                return Err(self.err(
                    span,
                    format!(
                        "`{key}` does not apply to {} (its keys: {}material, transform)",
                        article(name),
                        keys.iter().map(|k| format!("{k}, ")).collect::<String>()
                    ),
                ));
            }
        }
        Ok(ty)
    }

    /// The value of a key that an object of type `ty` requires.
    pub(super) fn need<'o, T>(
        &self,
        field: &'o Option<Spanned<T>>,
        key: &str,
        node: &Spanned<ObjectDef>,
        ty: Ty,
    ) -> R<&'o Spanned<T>> {
        field.as_ref().ok_or_else(|| {
            self.err(
                node.span(),
                format!("missing key `{key}` for {}", article(ty.name())),
            )
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeSet;

    #[test]
    fn every_type_has_distinct_keys() {
        for (name, _, keys) in types() {
            let set: BTreeSet<_> = keys.iter().collect();
            assert_eq!(set.len(), keys.len(), "{name}");
            for k in keys {
                assert!(
                    super::super::super::format::OBJECT_KEYS.contains(k),
                    "{name}.{k}"
                );
            }
        }
        let names: BTreeSet<_> = types().map(|t| t.0).collect();
        assert_eq!(names.len(), types().count());
    }
}
