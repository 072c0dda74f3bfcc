//! The primitive kinds, listed once.
//!
//! [`for_each_kind!`] holds the table of analytic kinds: one row per kind with its
//! geometry id (the id both backends report in [`crate::Hit::geom_id`]), its module,
//! the type the scene stores, the name of its list in the store, its plural and
//! singular names and its documentation. Every per-kind item is generated from that
//! table: the kinds' module declarations and re-exports in [`geometry`](super),
//! [`Kind`], [`Kind::ALL`], the names, [`Shape`] and its dispatch of [`Intersect`] and
//! [`Primitive`] here, the store's lists and their visitor in [`crate::scene`].
//!
//! Adding an analytic primitive therefore means: its own file (the type with its
//! [`Intersect`] and [`Primitive`] impls: bounds, hits, the accurate surface point, the
//! texture parameterisation and what applies of a solid's inside, baking and meshing)
//! plus one row in the table; and, for the scene format, its object type in
//! `load/toml/build/shapes/` (`docs/architecture.md` has the whole list). Triangles are
//! not in the table: Embree intersects them natively and they carry vertex normals,
//! texture coordinates and quads, so the store keeps them apart; they are
//! [`Kind::Triangle`], geometry id 0.

use super::{Intersect, Param, Primitive, ShapeHit, Spans, SurfacePoint, Tessellation};
use crate::math::{Aabb, Ray, Vec3};
use glam::DAffine3;
use std::sync::Arc;

/// Invoke the macro `$m` with the table of analytic kinds, one row per kind in
/// geometry-id order. A row of the table reads
///
/// `(Variant, geometry id, mod module, Type, store field, "plural", "singular", "doc")`
///
/// - `Variant` names the [`Kind`] and [`Shape`] variants;
/// - the geometry id is the [`Kind`] discriminant (1, 2, ...: 0 is the triangles);
/// - `mod module` is the kind's file in `src/geometry/`, which declares `Type` (`pub
///   mod` to make the module itself public); `geometry` declares the module and
///   re-exports the type from this row;
/// - `Type` is what [`Shape`] and the store hold: the type itself, or `Arc<Type>` for
///   a large one (so that cloning a [`Shape`] stays cheap);
/// - the store field names the kind's list in [`crate::scene::Geometry`];
/// - the plural name is used in statistics, the singular one in messages.
///
/// `$m` receives each row with the stored type spelled out as a path that resolves
/// anywhere in the crate:
///
/// `(Variant, id, mod module, Type, stored type, field, "plural", "singular", "doc")`
macro_rules! for_each_kind {
    ($m:ident) => {
        $crate::geometry::kind_rows! { $m []
            (Sphere, 1, mod sphere, Sphere, spheres, "spheres", "sphere", "Spheres (NFF `s`)."),
            (Cone, 2, mod cone, Cone, cones, "cones", "open cone",
                "Open cones and cylinders (NFF `c`)."),
            (Csg, 3, pub mod csg, Arc<Csg>, csg, "csg", "CSG solid",
                "Constructive solid geometry roots."),
            (Quadric, 4, mod quadric, Arc<Quadric>, quadrics, "quadrics", "quadric",
                "General quadrics, optionally clipped to a box."),
            (CappedCone, 5, mod capped, Arc<CappedCone>, capped_cones, "capped_cones",
                "capped cone", "Capped (closed) cones and cylinders."),
            (Box, 6, mod aabox, AaBox, boxes, "boxes", "box", "Axis-aligned boxes."),
            (OBox, 7, mod obox, Arc<OBox>, oriented_boxes, "oriented_boxes", "oriented box",
                "Oriented boxes."),
            (Polyhedron, 8, mod polyhedron, Arc<Polyhedron>, polyhedra, "polyhedra",
                "polyhedron", "Convex polyhedra."),
            (Plane, 9, mod plane, Plane, planes, "planes", "plane", "Infinite planes."),
            (Torus, 10, mod torus, Arc<Torus>, tori, "tori", "torus", "Tori."),
        }
    };
}
pub(crate) use for_each_kind;

/// The rows of [`for_each_kind!`] one at a time into `[...]`, each with its stored type
/// as a path, then all of them to `$m`.
#[doc(hidden)]
macro_rules! kind_rows {
    ($m:ident [$($done:tt)*]) => {
        $m! { $($done)* }
    };
    ($m:ident [$($done:tt)*]
        ($v:ident, $id:literal, $vis:vis mod $module:ident, Arc<$t:ident>, $($rest:tt)*)
        $(, $($more:tt)*)?) => {
        $crate::geometry::kind_rows! { $m [$($done)*
            ($v, $id, $vis mod $module, $t, ::std::sync::Arc<$crate::geometry::$t>, $($rest)*),]
            $($($more)*)? }
    };
    ($m:ident [$($done:tt)*]
        ($v:ident, $id:literal, $vis:vis mod $module:ident, $t:ident, $($rest:tt)*)
        $(, $($more:tt)*)?) => {
        $crate::geometry::kind_rows! { $m [$($done)*
            ($v, $id, $vis mod $module, $t, $crate::geometry::$t, $($rest)*),]
            $($($more)*)? }
    };
}
pub(crate) use kind_rows;

/// One analytic kind's stored type (a row of the kinds table): a [`Primitive`] with
/// its [`Kind`], convertible into a [`Shape`], shareable with the backends' threads.
pub trait Analytic:
    Primitive + Clone + std::fmt::Debug + PartialEq + Into<Shape> + Send + Sync + 'static
{
    /// The kind (geometry id) of this type.
    const KIND: Kind;
}

impl<T: Intersect + ?Sized> Intersect for Arc<T> {
    #[inline]
    fn bounds(&self) -> Aabb {
        T::bounds(self)
    }
    #[inline]
    fn intersect(&self, ray: &Ray) -> Option<ShapeHit> {
        T::intersect(self, ray)
    }
    #[inline]
    fn occluded(&self, ray: &Ray) -> bool {
        T::occluded(self, ray)
    }
    #[inline]
    fn surface(&self, ray: &Ray, hit: &ShapeHit) -> SurfacePoint {
        T::surface(self, ray, hit)
    }
}

impl<T: Primitive + ?Sized> Primitive for Arc<T> {
    #[inline]
    fn is_solid(&self) -> bool {
        T::is_solid(self)
    }
    #[inline]
    fn spans(&self, ray: &Ray, out: &mut Spans) {
        T::spans(self, ray, out)
    }
    #[inline]
    fn contains(&self, p: Vec3) -> bool {
        T::contains(self, p)
    }
    #[inline]
    fn param(&self, p: Vec3, ng: Vec3) -> Param {
        T::param(self, p, ng)
    }
    #[inline]
    fn material(&self, hit: &ShapeHit, own: u32) -> u32 {
        T::material(self, hit, own)
    }
    fn bake(&self, m: &DAffine3) -> Option<Shape> {
        T::bake(self, m)
    }
    fn tessellate(&self, patch: f32) -> Option<Tessellation> {
        T::tessellate(self, patch)
    }
}

/// Generates [`Kind`], [`Shape`] and their per-kind code from the table.
macro_rules! define_kinds {
    ($(($v:ident, $id:literal, $vis:vis mod $module:ident, $name:ident, $t:ty, $field:ident,
        $plural:literal, $singular:literal, $doc:literal)),* $(,)?) => {
        /// The primitive kinds. The discriminant is the geometry id both backends report
        /// in [`crate::Hit::geom_id`].
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
        #[repr(u32)]
        pub enum Kind {
            /// Triangles (NFF `p` and `pp`, meshes, tessellated patches).
            Triangle = 0,
            $(#[doc = $doc] $v = $id,)*
        }

        impl Kind {
            /// All kinds in geometry-id order.
            pub const ALL: [Kind; 1 + [$($id),*].len()] = [Kind::Triangle, $(Kind::$v),*];

            /// Plural name used in statistics (`triangles`, `spheres`, `cones`, ...).
            pub fn name(self) -> &'static str {
                match self {
                    Kind::Triangle => "triangles",
                    $(Kind::$v => $plural,)*
                }
            }

            /// Singular name for messages.
            pub fn singular(self) -> &'static str {
                match self {
                    Kind::Triangle => "triangle",
                    $(Kind::$v => $singular,)*
                }
            }
        }

        /// An analytic primitive of any kind (intersected by user geometry on Embree).
        #[derive(Clone, Debug, PartialEq)]
        pub enum Shape {
            $(#[doc = concat!("One of the ", $plural, ": ", $doc)] $v($t),)*
        }

        impl Shape {
            /// The kind (geometry id) of this shape.
            pub fn kind(&self) -> Kind {
                match self {
                    $(Shape::$v(_) => Kind::$v,)*
                }
            }
        }

        $(
            impl Analytic for $t {
                const KIND: Kind = Kind::$v;
            }

            impl From<$t> for Shape {
                fn from(prim: $t) -> Shape {
                    Shape::$v(prim)
                }
            }
        )*

        impl Intersect for Shape {
            fn bounds(&self) -> Aabb {
                match self {
                    $(Shape::$v(s) => Intersect::bounds(s),)*
                }
            }

            #[inline]
            fn intersect(&self, ray: &Ray) -> Option<ShapeHit> {
                match self {
                    $(Shape::$v(s) => Intersect::intersect(s, ray),)*
                }
            }

            #[inline]
            fn occluded(&self, ray: &Ray) -> bool {
                match self {
                    $(Shape::$v(s) => Intersect::occluded(s, ray),)*
                }
            }

            fn surface(&self, ray: &Ray, hit: &ShapeHit) -> SurfacePoint {
                match self {
                    $(Shape::$v(s) => Intersect::surface(s, ray, hit),)*
                }
            }
        }

        impl Primitive for Shape {
            fn is_solid(&self) -> bool {
                match self {
                    $(Shape::$v(s) => Primitive::is_solid(s),)*
                }
            }

            #[inline]
            fn spans(&self, ray: &Ray, out: &mut Spans) {
                match self {
                    $(Shape::$v(s) => Primitive::spans(s, ray, out),)*
                }
            }

            fn contains(&self, p: Vec3) -> bool {
                match self {
                    $(Shape::$v(s) => Primitive::contains(s, p),)*
                }
            }

            fn param(&self, p: Vec3, ng: Vec3) -> Param {
                match self {
                    $(Shape::$v(s) => Primitive::param(s, p, ng),)*
                }
            }

            fn material(&self, hit: &ShapeHit, own: u32) -> u32 {
                match self {
                    $(Shape::$v(s) => Primitive::material(s, hit, own),)*
                }
            }

            fn bake(&self, m: &DAffine3) -> Option<Shape> {
                match self {
                    $(Shape::$v(s) => Primitive::bake(s, m),)*
                }
            }

            fn tessellate(&self, patch: f32) -> Option<Tessellation> {
                match self {
                    $(Shape::$v(s) => Primitive::tessellate(s, patch),)*
                }
            }
        }
    };
}

for_each_kind!(define_kinds);

// The geometry id of every kind is its index in `Kind::ALL` (what `from_id` relies on).
const _: () = {
    let mut i = 0;
    while i < Kind::ALL.len() {
        assert!(
            Kind::ALL[i] as usize == i,
            "kind ids must be 0, 1, 2, ... in order"
        );
        i += 1;
    }
};

impl Kind {
    /// The kind with geometry id `id`.
    pub fn from_id(id: u32) -> Option<Kind> {
        Kind::ALL.get(id as usize).copied()
    }

    /// The analytic kinds (all but [`Kind::Triangle`]), in geometry-id order.
    pub fn analytic() -> impl Iterator<Item = Kind> {
        Kind::ALL.into_iter().skip(1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Sphere, Torus};

    #[test]
    fn ids_names_and_shapes_follow_the_table() {
        assert_eq!(Kind::Triangle as u32, 0);
        assert_eq!(Kind::Sphere as u32, 1);
        assert_eq!(Kind::Torus as u32, 10);
        for (i, k) in Kind::ALL.into_iter().enumerate() {
            assert_eq!(Kind::from_id(i as u32), Some(k));
        }
        assert_eq!(Kind::from_id(Kind::ALL.len() as u32), None);
        assert_eq!(Kind::OBox.name(), "oriented_boxes");
        assert_eq!(Kind::Cone.singular(), "open cone");
        let s: Shape = Sphere::new(Vec3::ZERO, 1.0).into();
        assert_eq!(s.kind(), Kind::Sphere);
        assert_eq!(<Arc<Torus> as Analytic>::KIND, Kind::Torus);
        assert_eq!(Kind::analytic().count(), Kind::ALL.len() - 1);
    }
}
