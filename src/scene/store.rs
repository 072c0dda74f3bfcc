//! The primitive store: one typed list per primitive kind, generated from the kinds
//! table ([`crate::geometry::Kind`]), each with a material index per primitive.
//!
//! A primitive is addressed as `(kind, index)`: the index within its kind's list is the
//! `prim_id` both backends report ([`Hit::prim_id`]). Triangles have their own fields
//! (vertex normals, texture coordinates, textured quads); every analytic kind is
//! reached through the same small API: [`Geometry::add_shape`] and [`Geometry::push`]
//! to add, [`Geometry::count`] to count, the per-kind accessors (`spheres()`, ...) to
//! read one list, and [`Geometry::visit`]/[`Geometry::visit_all`] to run code on a
//! list at its static type (a [`KindVisitor`], as the backends do to build).

use super::{Hit, PrimSources, Surface};
use crate::geometry::{Analytic, Kind, Param, QuadUv, Shape, ShapeHit, Triangle, for_each_kind};
use crate::math::{Aabb, Ray, Vec3};
use glam::Vec2;

/// Primitives of one kind with a material index each.
#[derive(Clone, Debug, PartialEq)]
pub struct Prims<T> {
    /// The primitives; a primitive's index is its `prim_id`.
    pub items: Vec<T>,
    /// Material index per primitive.
    pub material: Vec<u32>,
}

impl<T> Default for Prims<T> {
    fn default() -> Self {
        Prims {
            items: Vec::new(),
            material: Vec::new(),
        }
    }
}

impl<T> Prims<T> {
    /// Append one primitive.
    pub fn push(&mut self, item: T, material: u32) {
        self.items.push(item);
        self.material.push(material);
    }

    /// Number of primitives.
    pub fn len(&self) -> usize {
        self.items.len()
    }

    /// True when there are none.
    pub fn is_empty(&self) -> bool {
        self.items.is_empty()
    }

    /// Append `other`'s primitives, their materials mapped by `material`; an empty
    /// list takes `other`'s storage as it is.
    pub fn append(&mut self, mut other: Prims<T>, material: impl Fn(u32) -> u32) {
        for m in &mut other.material {
            *m = material(*m);
        }
        if self.items.is_empty() {
            *self = other;
        } else {
            self.items.append(&mut other.items);
            self.material.append(&mut other.material);
        }
    }

    /// Every primitive with its `prim_id` and material.
    pub fn iter(&self) -> impl Iterator<Item = (u32, &T, u32)> + '_ {
        (0u32..)
            .zip(&self.items)
            .zip(&self.material)
            .map(|((i, item), &m)| (i, item, m))
    }
}

/// Code run on one kind's list at its static type: [`Geometry::visit`] calls it for one
/// kind, [`Geometry::visit_all`] for every analytic kind in geometry-id order. The
/// kind is `P::KIND`; the lists are borrowed for `'g` (a visitor that keeps them, as
/// Embree's user geometries do, names it).
pub trait KindVisitor<'g> {
    /// What one visit returns.
    type Output;
    /// Work on the list of kind `P::KIND`.
    fn visit<P: Analytic>(&mut self, prims: &'g Prims<P>) -> Self::Output;
}

/// One analytic primitive of a store, as [`Geometry::shapes`] lists them.
#[derive(Clone, Debug, PartialEq)]
pub struct ShapeEntry {
    /// Its kind.
    pub kind: Kind,
    /// Its index within the kind's list (its `prim_id`).
    pub prim: u32,
    /// The primitive.
    pub shape: Shape,
    /// Its material index.
    pub material: u32,
}

/// Generates the store from the kinds table.
macro_rules! define_store {
    ($(($v:ident, $id:literal, $vis:vis mod $module:ident, $name:ident, $t:ty, $field:ident,
        $plural:literal, $singular:literal, $doc:literal)),* $(,)?) => {
        /// Primitives: the top level of a scene, or an object that instances place.
        #[derive(Clone, Debug, Default, PartialEq)]
        pub struct Geometry {
            /// Triangles.
            pub triangles: Prims<Triangle>,
            /// Per triangle: index into `vertex_normals`, or `u32::MAX` for flat shading.
            pub triangle_normals: Vec<u32>,
            /// Per-vertex shading normals of smooth triangles.
            pub vertex_normals: Vec<[Vec3; 3]>,
            /// Per triangle: index into `vertex_uvs`, or `u32::MAX` for none; may be
            /// shorter than `triangles` (the rest have none).
            pub triangle_uvs: Vec<u32>,
            /// Per-vertex texture coordinates of triangles that have them (OBJ `vt`).
            pub vertex_uvs: Vec<[Vec2; 3]>,
            /// Per triangle: index into `quads` when the triangle is half of a textured
            /// quad face (its `(u, v)` then come from the quad's bilinear patch), or
            /// `u32::MAX`; may be shorter than `triangles`.
            pub triangle_quads: Vec<u32>,
            /// Textured quad faces (OBJ faces of four vertices with `vt`, planar and
            /// convex).
            pub quads: Vec<QuadUv>,
            /// Where each primitive was defined (file and line), as far as the loader
            /// recorded it.
            pub sources: PrimSources,
            $(#[doc = $doc] $field: Prims<$t>,)*
        }

        impl Geometry {
            $(
                #[doc = concat!("The ", $plural, " (kind [`Kind::", stringify!($v), "`]).")]
                pub fn $field(&self) -> &Prims<$t> {
                    &self.$field
                }
            )*

            /// Add an analytic primitive to its kind's list.
            pub fn add_shape(&mut self, shape: Shape, material: u32) {
                match shape {
                    $(Shape::$v(p) => self.$field.push(p, material),)*
                }
            }

            /// Number of primitives of `kind` in this store (not counting copies that
            /// instances place: see [`super::Scene::count_with_instances`]).
            pub fn count(&self, kind: Kind) -> usize {
                match kind {
                    Kind::Triangle => self.triangles.len(),
                    $(Kind::$v => self.$field.len(),)*
                }
            }

            /// Append `other`'s primitives after this store's, their materials mapped
            /// by `material`, their sources and their triangles' normals, texture
            /// coordinates and quads numbered on.
            pub fn append(&mut self, other: Geometry, material: impl Fn(u32) -> u32) {
                let Geometry {
                    triangles, triangle_normals, vertex_normals, triangle_uvs, vertex_uvs,
                    triangle_quads, quads, sources, $($field,)*
                } = other;
                let mark = self.mark();
                self.sources.append_owned(sources, &|k| mark.count(k));
                let first_triangle = self.triangles.len();
                self.triangles.append(triangles, &material);
                append_indices(&mut self.triangle_normals, triangle_normals, first_triangle,
                    self.vertex_normals.len());
                append_indices(&mut self.triangle_uvs, triangle_uvs, first_triangle,
                    self.vertex_uvs.len());
                append_indices(&mut self.triangle_quads, triangle_quads, first_triangle,
                    self.quads.len());
                extend(&mut self.vertex_normals, vertex_normals);
                extend(&mut self.vertex_uvs, vertex_uvs);
                extend(&mut self.quads, quads);
                $(self.$field.append($field, &material);)*
            }

            /// Run `visitor` on the list of `kind` (`None` for triangles).
            #[inline]
            pub fn visit<'g, V: KindVisitor<'g>>(
                &'g self,
                kind: Kind,
                visitor: &mut V,
            ) -> Option<V::Output> {
                match kind {
                    Kind::Triangle => None,
                    $(Kind::$v => Some(visitor.visit(&self.$field)),)*
                }
            }

            /// Run `visitor` on the list of every analytic kind, in geometry-id order
            /// (empty lists included).
            pub fn visit_all<'g, V: KindVisitor<'g, Output = ()>>(&'g self, visitor: &mut V) {
                $(visitor.visit(&self.$field);)*
            }

            /// As [`Geometry::visit_all`], stopping at the first error.
            pub fn try_visit_all<'g, V, E>(&'g self, visitor: &mut V) -> Result<(), E>
            where
                V: KindVisitor<'g, Output = Result<(), E>>,
            {
                $(visitor.visit(&self.$field)?;)*
                Ok(())
            }
        }
    };
}

for_each_kind!(define_store);

/// Append `other`, a per-triangle list of indices into a list that had `base` items
/// (`u32::MAX` for none), to `list`, which is per triangle for the first `first`
/// triangles but may be shorter (the rest have none).
fn append_indices(list: &mut Vec<u32>, other: Vec<u32>, first: usize, base: usize) {
    if other.is_empty() {
        return;
    }
    if first == 0 && base == 0 {
        // The indices stay as they are: `other`'s storage is the list.
        *list = other;
        return;
    }
    list.resize(first, u32::MAX);
    let base = base as u32;
    list.extend(other.into_iter().map(|k| {
        if k == u32::MAX {
            k
        } else {
            k.wrapping_add(base)
        }
    }));
}

/// `list` followed by `other` (`other`'s storage when `list` is empty).
fn extend<T>(list: &mut Vec<T>, mut other: Vec<T>) {
    if list.is_empty() {
        *list = other;
    } else {
        list.append(&mut other);
    }
}

/// The primitive counts of a [`Geometry`] at one moment ([`Geometry::mark`]), per kind.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct GeometryMark([usize; Kind::ALL.len()]);

impl GeometryMark {
    /// How many primitives of `kind` there were.
    pub fn count(&self, kind: Kind) -> usize {
        self.0[kind as usize]
    }
}

impl Geometry {
    /// Add an analytic primitive of a statically known kind.
    pub fn push<P: Analytic>(&mut self, prim: P, material: u32) {
        self.add_shape(prim.into(), material);
    }

    /// Total number of primitives in this store (not counting instances' copies).
    pub fn prim_count(&self) -> usize {
        Kind::ALL.into_iter().map(|k| self.count(k)).sum()
    }

    /// Add a flat triangle.
    pub fn add_triangle(&mut self, tri: Triangle, material: u32) {
        self.triangles.push(tri, material);
        self.triangle_normals.push(u32::MAX);
    }

    /// Add a triangle with per-vertex shading normals.
    pub fn add_smooth_triangle(&mut self, tri: Triangle, normals: [Vec3; 3], material: u32) {
        self.triangles.push(tri, material);
        self.triangle_normals.push(self.vertex_normals.len() as u32);
        self.vertex_normals.push(normals);
    }

    /// The analytic primitive `prim` of `kind` (`None` for triangles and for an index
    /// past the end of the list).
    pub fn shape(&self, kind: Kind, prim: u32) -> Option<Shape> {
        self.visit(kind, &mut ShapeAt(prim as usize)).flatten()
    }

    /// Every analytic primitive with its `(kind, prim_id)` and material, in
    /// geometry-id order, then in the order of each kind's list.
    pub fn shapes(&self) -> impl Iterator<Item = ShapeEntry> + '_ {
        Kind::analytic().flat_map(move |kind| {
            (0..self.count(kind) as u32).map(move |prim| {
                let entry = self.visit(kind, &mut EntryAt(prim as usize));
                entry.expect("an analytic kind")
            })
        })
    }

    /// How many primitives of each kind there are now, to find later the ones added
    /// since ([`Geometry::bounds_since`]).
    pub fn mark(&self) -> GeometryMark {
        GeometryMark(Kind::ALL.map(|k| self.count(k)))
    }

    /// The bounds of each primitive added since `mark`.
    pub fn bounds_since(&self, mark: GeometryMark) -> impl Iterator<Item = Aabb> + '_ {
        let tris = self.triangles.items[mark.0[0]..]
            .iter()
            .map(Triangle::bounds);
        let shapes = Kind::analytic().flat_map(move |kind| {
            let first = mark.0[kind as usize];
            (first..self.count(kind)).map(move |i| {
                let bounds = self.visit(kind, &mut BoundsAt(i));
                bounds.expect("an analytic kind")
            })
        });
        tris.chain(shapes)
    }

    /// Bounds of everything (infinite when an unbounded primitive is present).
    pub fn bounds(&self) -> Aabb {
        let mut b = Aabb::EMPTY;
        for t in &self.triangles.items {
            b = b.union(&t.bounds());
        }
        let mut all = AllBounds(b);
        self.visit_all(&mut all);
        all.0
    }

    /// Add texture coordinates to triangle `tri` (an index into `triangles`).
    pub fn set_triangle_uvs(&mut self, tri: usize, uv: [Vec2; 3]) {
        if self.triangle_uvs.len() <= tri {
            self.triangle_uvs.resize(tri + 1, u32::MAX);
        }
        self.triangle_uvs[tri] = self.vertex_uvs.len() as u32;
        self.vertex_uvs.push(uv);
    }

    /// Add a textured quad face; returns its index for [`Geometry::set_triangle_quad`].
    pub fn add_quad(&mut self, quad: QuadUv) -> u32 {
        self.quads.push(quad);
        self.quads.len() as u32 - 1
    }

    /// Make triangle `tri` (an index into `triangles`) half of quad `quad`: its texture
    /// coordinates come from the quad's bilinear patch.
    pub fn set_triangle_quad(&mut self, tri: usize, quad: u32) {
        if self.triangle_quads.len() <= tri {
            self.triangle_quads.resize(tri + 1, u32::MAX);
        }
        self.triangle_quads[tri] = quad;
    }

    /// The texture coordinates and tangents at `surf`, a hit on these primitives (in
    /// their space).
    pub fn param(&self, hit: &Hit, surf: &Surface) -> Param {
        let kind = Kind::from_id(hit.geom_id).unwrap_or(Kind::Triangle);
        let i = hit.prim_id as usize;
        let at = &mut ParamAt {
            i,
            p: surf.point.p,
            ng: surf.point.ng,
        };
        match self.visit(kind, at) {
            Some(param) => param,
            None => self.triangle_param(i, hit, surf),
        }
    }

    fn triangle_param(&self, i: usize, hit: &Hit, surf: &Surface) -> Param {
        let quad = match self.triangle_quads.get(i) {
            Some(&k) if k != u32::MAX => self.quads[k as usize].param(surf.point.p),
            _ => None,
        };
        if let Some(param) = quad {
            return param;
        }
        let uv = match self.triangle_uvs.get(i) {
            Some(&k) if k != u32::MAX => Some(&self.vertex_uvs[k as usize]),
            _ => None,
        };
        self.triangles.items[i].param(hit.u, hit.v, uv)
    }

    /// The surface at a hit on these primitives, for `ray` in their space.
    pub fn surface(&self, hit: &Hit, ray: &Ray) -> Surface {
        let kind = Kind::from_id(hit.geom_id).expect("backend reported an unknown geometry");
        let i = hit.prim_id as usize;
        match self.visit(kind, &mut SurfaceAt { i, hit, ray }) {
            Some(surface) => surface,
            None => self.triangle_surface(i, hit),
        }
    }

    /// `hit` with a triangle's barycentrics and distance computed by emray's own
    /// watertight test ([`Triangle::intersect`]) on the triangle the backend reported,
    /// so that a hit is the same point whichever backend found it (Embree's triangle
    /// arithmetic differs from the BVH's in the last bits, and reflections between
    /// curved meshes magnify that into visible differences a few bounces down). When
    /// the test does not confirm the hit (a ray within rounding of the triangle's edge,
    /// which the backend gave to this triangle and the test to its neighbour), the
    /// backend's values stay. Other kinds are computed by emray's intersectors on both
    /// backends already.
    #[inline]
    pub fn exact_hit(&self, hit: &Hit, ray: &Ray) -> Hit {
        if hit.geom_id != Kind::Triangle as u32 {
            return *hit;
        }
        let Some(tri) = self.triangles.items.get(hit.prim_id as usize) else {
            return *hit;
        };
        match tri.intersect(ray) {
            Some(h) => Hit {
                t: h.t,
                u: h.u,
                v: h.v,
                ..*hit
            },
            None => *hit,
        }
    }

    fn triangle_surface(&self, i: usize, hit: &Hit) -> Surface {
        let tri = &self.triangles.items[i];
        let point = tri.surface(hit.u, hit.v);
        let ns = match self.triangle_normals[i] {
            u32::MAX => point.ng,
            k => {
                let n = self.vertex_normals[k as usize];
                let w = 1.0 - hit.u - hit.v;
                (n[0] * w + n[1] * hit.u + n[2] * hit.v).normalize_or(point.ng)
            }
        };
        Surface {
            point,
            ns,
            material: self.triangles.material[i],
            param: None,
        }
    }
}

/// Primitive `.0` of a list as a [`Shape`].
struct ShapeAt(usize);

impl KindVisitor<'_> for ShapeAt {
    type Output = Option<Shape>;
    fn visit<P: Analytic>(&mut self, prims: &Prims<P>) -> Option<Shape> {
        prims.items.get(self.0).map(|p| p.clone().into())
    }
}

/// Primitive `.0` of a list as a [`ShapeEntry`].
struct EntryAt(usize);

impl KindVisitor<'_> for EntryAt {
    type Output = ShapeEntry;
    fn visit<P: Analytic>(&mut self, prims: &Prims<P>) -> ShapeEntry {
        ShapeEntry {
            kind: P::KIND,
            prim: self.0 as u32,
            shape: prims.items[self.0].clone().into(),
            material: prims.material[self.0],
        }
    }
}

/// The bounds of primitive `.0` of a list.
struct BoundsAt(usize);

impl KindVisitor<'_> for BoundsAt {
    type Output = Aabb;
    fn visit<P: Analytic>(&mut self, prims: &Prims<P>) -> Aabb {
        prims.items[self.0].bounds()
    }
}

/// The union of the bounds of every primitive visited, starting from `.0`.
struct AllBounds(Aabb);

impl KindVisitor<'_> for AllBounds {
    type Output = ();
    fn visit<P: Analytic>(&mut self, prims: &Prims<P>) {
        for p in &prims.items {
            self.0 = self.0.union(&p.bounds());
        }
    }
}

/// The parameterisation at `p` (unit outward normal `ng`) on primitive `i` of a list.
struct ParamAt {
    i: usize,
    p: Vec3,
    ng: Vec3,
}

impl KindVisitor<'_> for ParamAt {
    type Output = Param;
    #[inline]
    fn visit<P: Analytic>(&mut self, prims: &Prims<P>) -> Param {
        prims.items[self.i].param(self.p, self.ng)
    }
}

/// The surface at `hit` on primitive `i` of a list, for `ray`.
struct SurfaceAt<'a> {
    i: usize,
    hit: &'a Hit,
    ray: &'a Ray,
}

impl KindVisitor<'_> for SurfaceAt<'_> {
    type Output = Surface;
    #[inline]
    fn visit<P: Analytic>(&mut self, prims: &Prims<P>) -> Surface {
        let hit = self.hit;
        let shape = &prims.items[self.i];
        let shape_hit = ShapeHit {
            t: hit.t,
            u: hit.u,
            v: hit.v,
            ng: hit.ng,
        };
        let point = shape.surface(self.ray, &shape_hit);
        Surface {
            point,
            ns: point.ng,
            material: shape.material(&shape_hit, prims.material[self.i]),
            param: None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri(x: f32) -> Triangle {
        Triangle {
            p: [Vec3::new(x, 0.0, 0.0), Vec3::Y, Vec3::Z],
        }
    }

    /// A store of a flat, a smooth and a flat triangle.
    fn mixed() -> Geometry {
        let mut g = Geometry::default();
        g.add_triangle(tri(1.0), 0);
        g.add_smooth_triangle(tri(2.0), [Vec3::X, Vec3::Y, Vec3::Z], 1);
        g.add_triangle(tri(3.0), 0);
        g
    }

    /// Appended to an empty store, a store's normal indices are its own storage, kept
    /// as they are; appended after triangles with normals, they are numbered on.
    #[test]
    fn normal_indices_appended_to_an_empty_store_are_taken_as_they_are() {
        let other = mixed();
        let indices = other.triangle_normals.as_ptr();
        let mut g = Geometry::default();
        g.append(other, |m| m);
        assert_eq!(g.triangle_normals, [u32::MAX, 0, u32::MAX]);
        assert_eq!(g.triangle_normals.as_ptr(), indices, "the storage taken");
        g.append(mixed(), |m| m + 5);
        assert_eq!(
            g.triangle_normals,
            [u32::MAX, 0, u32::MAX, u32::MAX, 1, u32::MAX]
        );
        assert_eq!(g.vertex_normals.len(), 2);
        assert_eq!(g.triangles.material, [0, 1, 0, 5, 6, 5]);
    }

    /// An empty store after triangles without normals: the indices start at the
    /// appended triangles, padded with "none" before them.
    #[test]
    fn normal_indices_appended_after_flat_triangles_are_padded() {
        let mut g = Geometry::default();
        g.triangles.push(tri(0.0), 0);
        g.append(mixed(), |m| m);
        assert_eq!(g.triangle_normals, [u32::MAX, u32::MAX, 0, u32::MAX]);
    }
}
