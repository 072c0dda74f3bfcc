//! Meshing for the radiosity pass: every triangle of the scene (top level and
//! instanced), and every face of the top-level analytic shapes
//! [`super::tessellate`] handles, is split by repeated midpoint subdivision (each triangle into four
//! similar ones) until its longest edge is at most the patch size. Each source triangle
//! keeps its subdivision as a quadtree, so a hit's barycentric coordinates on the source
//! triangle find its element by descending the tree, and any element can be split again
//! later ([`Mesh::split`], adaptive subdivision). Elements split to different depths
//! leave T-junctions: [`Mesh::hanging_vertices`] lists the vertices that lie inside
//! another element's edge, so that the display can interpolate them along that edge.

use super::RadiosityError;
use crate::accel::NO_INSTANCE;
use crate::geometry::tessellate::{self, Lookup, Tessellation};
use crate::geometry::{Kind, Primitive};
use crate::math::{Vec3, gamma};
use crate::scene::{Geometry, INHERIT, Material, Scene};
use std::collections::HashMap;

/// Deepest subdivision of one source triangle (4^12 elements).
pub const MAX_LEVEL: u32 = 12;
/// Most elements a mesh may have.
pub const MAX_ELEMENTS: usize = 1 << 22;

/// One element (patch) of the radiosity mesh.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Element {
    /// Corners in world space, counterclockwise seen from the front.
    pub p: [Vec3; 3],
    /// Per-axis bound on the error of the corners and of points interpolated on them.
    pub err: Vec3,
    /// Unit normal of the front side (the side that emits and receives light).
    pub n: Vec3,
    /// Area.
    pub area: f32,
    /// Material index.
    pub material: u32,
    /// Indices into [`Mesh::vertices`] of the corners.
    pub verts: [u32; 3],
    /// Nonzero for the faces of one curved analytic surface: its elements share the
    /// corners they have in common whatever their normals (smooth display).
    pub smooth: u32,
}

impl Element {
    /// The point with barycentric coordinates `(u, v)` (weights of corners 1 and 2).
    #[inline]
    pub fn point(&self, u: f32, v: f32) -> Vec3 {
        self.p[0] * (1.0 - u - v) + self.p[1] * u + self.p[2] * v
    }

    /// The centroid.
    pub fn centroid(&self) -> Vec3 {
        (self.p[0] + self.p[1] + self.p[2]) / 3.0
    }
}

/// Marks a quadtree slot that holds an element index (otherwise it holds the index of
/// the first of four consecutive child slots).
const LEAF: u32 = 1 << 31;

/// The radiosity mesh.
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    /// The elements.
    pub elements: Vec<Element>,
    /// Shared corners: elements meet at a vertex when their corners coincide, they lie
    /// on the same plane and share the material (so a box's edge keeps its crease).
    pub vertices: Vec<Vec3>,
    /// Reflectance `color × kd` per material, each channel at most 0.999.
    pub reflectance: Vec<Vec3>,
    /// Emission per material.
    pub emission: Vec<Vec3>,
    /// Analytic primitives that are not meshed (they still occlude).
    pub unmeshed: usize,
    /// Root quadtree slot per source triangle.
    sources: HashMap<(u32, u32), u32>,
    /// Tessellated analytic shapes by `(geometry id, primitive)`.
    analytic: HashMap<(u32, u32), AnalyticSource>,
    /// Quadtree slots: `LEAF | element` or the first of four child slots.
    slots: Vec<u32>,
    /// The slot of each element.
    slot_of: Vec<u32>,
    welder: HashMap<VertexKey, u32>,
}

/// Corner order of the four children of a triangle `(a, b, c)` whose edge midpoints
/// are `ab`, `bc`, `ca`: corner a, corner b, corner c, middle.
fn children(t: [Vec3; 3]) -> [[Vec3; 3]; 4] {
    let [a, b, c] = t;
    let ab = (a + b) * 0.5;
    let bc = (b + c) * 0.5;
    let ca = (c + a) * 0.5;
    [[a, ab, ca], [ab, b, bc], [ca, bc, c], [bc, ca, ab]]
}

/// The child `(u, v)` falls in and its coordinates there (the inverse of [`children`]).
#[inline]
pub(crate) fn descend(u: f32, v: f32) -> (usize, f32, f32) {
    let w = 1.0 - u - v;
    if w >= 0.5 {
        (0, 2.0 * u, 2.0 * v)
    } else if u >= 0.5 {
        (1, 1.0 - 2.0 * w - 2.0 * v, 2.0 * v)
    } else if v >= 0.5 {
        (2, 2.0 * u, 1.0 - 2.0 * w - 2.0 * u)
    } else {
        (3, 1.0 - 2.0 * u, 1.0 - 2.0 * v)
    }
}

/// Barycentric coordinates `(u, v)` of the centroids of the `4^level` sub-triangles
/// of one triangle, in subdivision order: a stratified quadrature rule with equal
/// weights.
pub fn centroid_pattern(level: u32) -> Vec<(f32, f32)> {
    let unit = [Vec3::ZERO, Vec3::X, Vec3::Y];
    let mut tris = vec![unit];
    for _ in 0..level {
        tris = tris.iter().flat_map(|t| children(*t)).collect();
    }
    tris.iter()
        .map(|t| {
            let c = (t[0] + t[1] + t[2]) / 3.0;
            (c.x, c.y)
        })
        .collect()
}

/// A tessellated analytic shape: its face lookup and, per face, the fan triangles and
/// their quadtree roots.
#[derive(Clone, Debug)]
struct AnalyticSource {
    lookup: Lookup,
    faces: Vec<Vec<([Vec3; 3], u32)>>,
    open: bool,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
struct VertexKey {
    pos: [u32; 3],
    normal: [i32; 3],
    material: u32,
}

impl Mesh {
    /// Mesh the triangles of `scene` into elements of edge at most `patch_size`.
    ///
    /// # Errors
    /// A patch size that is not a positive finite number, or a mesh that would exceed
    /// [`MAX_ELEMENTS`].
    pub fn build(scene: &Scene, patch_size: f32) -> Result<Mesh, RadiosityError> {
        if !(patch_size.is_finite() && patch_size > 0.0) {
            return Err(RadiosityError::Settings(format!(
                "patch size {patch_size} is not a positive number"
            )));
        }
        let mut mesh = Mesh {
            reflectance: scene
                .materials
                .iter()
                .map(|m| (m.color * m.kd).min(Vec3::splat(0.999)))
                .collect(),
            emission: scene
                .materials
                .iter()
                .map(|m: &Material| m.emission)
                .collect(),
            ..Default::default()
        };
        let top = |g: &Geometry| g.count_unmeshed();
        for (k, tri) in scene.geometry.triangles.items.iter().enumerate() {
            let material = scene.geometry.triangles.material[k];
            let root = mesh.add_source(tri.p, Vec3::ZERO, material, patch_size, 0)?;
            if let Some(root) = root {
                mesh.sources.insert((NO_INSTANCE, k as u32), root);
            }
        }
        mesh.unmeshed = mesh.add_shapes(&scene.geometry, patch_size)?;
        for (ii, inst) in scene.instances.iter().enumerate() {
            let object = &scene.objects[inst.object as usize];
            mesh.unmeshed += top(object);
            for (k, tri) in object.triangles.items.iter().enumerate() {
                let mut material = object.triangles.material[k];
                if material == INHERIT {
                    material = inst.material;
                }
                let mut err = Vec3::ZERO;
                let p = tri.p.map(|p| {
                    let (q, e) = inst.xform.point_to_world(p, Vec3::ZERO);
                    err = err.max(e);
                    q
                });
                let root = mesh.add_source(p, err, material, patch_size, 0)?;
                if let Some(root) = root {
                    mesh.sources.insert((ii as u32, k as u32), root);
                }
            }
        }
        Ok(mesh)
    }

    /// Tessellate and mesh the analytic shapes of `g` that [`tessellate`] handles; the
    /// number of the others (left out of the mesh).
    fn add_shapes(&mut self, g: &Geometry, patch_size: f32) -> Result<usize, RadiosityError> {
        let mut unmeshed = 0;
        for entry in g.shapes() {
            let Some(t) = entry.shape.tessellate(patch_size) else {
                unmeshed += 1;
                continue;
            };
            let id = (entry.kind, entry.prim as usize);
            self.add_shape(id, t, entry.material, patch_size)?;
        }
        Ok(unmeshed)
    }

    /// Mesh the faces of one tessellated shape (each a fan of source triangles).
    fn add_shape(
        &mut self,
        (kind, prim): (Kind, usize),
        t: Tessellation,
        material: u32,
        patch_size: f32,
    ) -> Result<(), RadiosityError> {
        let smooth = if t.smooth {
            self.analytic.len() as u32 + 1
        } else {
            0
        };
        let mut faces = Vec::with_capacity(t.faces.len());
        for (face, &depth) in t.faces.iter().zip(&t.depth) {
            let mut fan = Vec::new();
            for k in 1..face.len().saturating_sub(1) {
                let tri = [face[0], face[k], face[k + 1]];
                let err = Vec3::splat(depth);
                if let Some(root) = self.add_source(tri, err, material, patch_size, smooth)? {
                    fan.push((tri, root));
                }
            }
            faces.push(fan);
        }
        let source = AnalyticSource {
            lookup: t.lookup,
            faces,
            open: t.open,
        };
        self.analytic.insert((kind as u32, prim as u32), source);
        Ok(())
    }

    /// Mesh one source triangle; its root quadtree slot (`None`: degenerate, skipped).
    fn add_source(
        &mut self,
        p: [Vec3; 3],
        err: Vec3,
        material: u32,
        patch_size: f32,
        smooth: u32,
    ) -> Result<Option<u32>, RadiosityError> {
        let n = (p[1] - p[0]).cross(p[2] - p[0]);
        let len = n.length();
        if !(len > 0.0 && len.is_finite()) {
            return Ok(None);
        }
        let n = n / len;
        let longest = longest_edge(&p);
        let mut level = 0;
        while level < MAX_LEVEL && longest / (1u32 << level) as f32 > patch_size {
            level += 1;
        }
        if self.elements.len() + (1usize << (2 * level)) > MAX_ELEMENTS {
            return Err(too_many(patch_size));
        }
        let magnitude = p[0].abs().max(p[1].abs()).max(p[2].abs()).max_element();
        let err = err + Vec3::splat(magnitude * gamma(12));
        let root = self.slots.len() as u32;
        self.slots.push(0);
        let proto = Element {
            p,
            err,
            n,
            area: 0.0,
            material,
            verts: [0; 3],
            smooth,
        };
        self.fill(root, p, level, &proto);
        Ok(Some(root))
    }

    /// Fill `slot` with triangle `t` subdivided `level` times.
    fn fill(&mut self, slot: u32, t: [Vec3; 3], level: u32, proto: &Element) {
        if level == 0 {
            let k = self.elements.len() as u32;
            let e = self.element(t, proto);
            self.elements.push(e);
            self.slot_of.push(slot);
            self.slots[slot as usize] = LEAF | k;
            return;
        }
        let first = self.slots.len() as u32;
        self.slots.extend([0; 4]);
        self.slots[slot as usize] = first;
        for (c, child) in children(t).into_iter().enumerate() {
            self.fill(first + c as u32, child, level - 1, proto);
        }
    }

    /// An element on triangle `t` with `proto`'s normal, error bound and material, its
    /// corners welded to the mesh's vertices.
    fn element(&mut self, t: [Vec3; 3], proto: &Element) -> Element {
        let verts = t.map(|q| {
            let key = self.key(q, proto);
            let next = self.vertices.len() as u32;
            *self.welder.entry(key).or_insert_with(|| {
                self.vertices.push(q);
                next
            })
        });
        Element {
            p: t,
            area: 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length(),
            verts,
            ..*proto
        }
    }

    fn key(&self, q: Vec3, e: &Element) -> VertexKey {
        // A smooth surface's group takes the place of the normal (outside its range).
        let normal = match e.smooth {
            0 => (e.n * 1024.0).round().as_ivec3().to_array(),
            g => [i32::MIN, g as i32, i32::MIN],
        };
        VertexKey {
            pos: q.to_array().map(f32::to_bits),
            normal,
            material: e.material,
        }
    }

    /// Split each listed element into four (midpoint subdivision): the first child
    /// takes the element's index, the others are appended.
    ///
    /// # Errors
    /// The mesh would exceed [`MAX_ELEMENTS`].
    pub fn split(&mut self, which: &[usize]) -> Result<(), RadiosityError> {
        if self.elements.len() + 3 * which.len() > MAX_ELEMENTS {
            return Err(RadiosityError::Settings(format!(
                "adaptive subdivision would exceed {MAX_ELEMENTS} elements; raise --subdiv-threshold or --min-patch-size"
            )));
        }
        for &k in which {
            let proto = self.elements[k];
            let slot = self.slot_of[k];
            let first = self.slots.len() as u32;
            self.slots.extend([0; 4]);
            self.slots[slot as usize] = first;
            for (c, child) in children(proto.p).into_iter().enumerate() {
                let e = self.element(child, &proto);
                let index = if c == 0 {
                    self.elements[k] = e;
                    self.slot_of[k] = first;
                    k as u32
                } else {
                    self.elements.push(e);
                    self.slot_of.push(first + c as u32);
                    self.elements.len() as u32 - 1
                };
                self.slots[(first + c as u32) as usize] = LEAF | index;
            }
        }
        Ok(())
    }

    /// The T-junctions: `(m, a, b)` where vertex `m` is the midpoint of the edge `a b`
    /// of an element (so `m` belongs only to finer elements on the other side), longest
    /// edges first, so that interpolating `m` from `a` and `b` in this order sees final
    /// values at `a` and `b`.
    pub fn hanging_vertices(&self) -> Vec<(u32, u32, u32)> {
        let mut found: HashMap<u32, (u32, u32)> = HashMap::new();
        let mut stack = Vec::new();
        for e in &self.elements {
            for k in 0..3 {
                stack.push((e.verts[k], e.verts[(k + 1) % 3]));
                while let Some((a, b)) = stack.pop() {
                    let mid = (self.vertices[a as usize] + self.vertices[b as usize]) * 0.5;
                    if let Some(&m) = self.welder.get(&self.key(mid, e)) {
                        if m != a && m != b {
                            found.insert(m, (a, b));
                            stack.push((a, m));
                            stack.push((m, b));
                        }
                    }
                }
            }
        }
        let len = |&(_, a, b): &(u32, u32, u32)| {
            (self.vertices[a as usize] - self.vertices[b as usize]).length_squared()
        };
        let mut out: Vec<(u32, u32, u32)> =
            found.into_iter().map(|(m, (a, b))| (m, a, b)).collect();
        out.sort_by(|x, y| len(y).total_cmp(&len(x)).then(x.0.cmp(&y.0)));
        out
    }

    /// The element at barycentric `(u, v)` of triangle `prim` of instance `inst`
    /// ([`NO_INSTANCE`] for the top level), with the point's coordinates in it.
    pub fn locate(&self, inst: u32, prim: u32, u: f32, v: f32) -> Option<(usize, f32, f32)> {
        let slot = *self.sources.get(&(inst, prim))?;
        Some(self.descend_from(slot, u, v))
    }

    /// The element of a tessellated analytic shape (`kind`, top-level primitive
    /// `prim`) under the point `p` of its true surface with geometric normal `ng`, the
    /// coordinates of `p`'s projection in it, and whether the shape is an open surface;
    /// `None` for shapes that are not tessellated.
    pub fn locate_analytic(
        &self,
        kind: Kind,
        prim: u32,
        p: Vec3,
        ng: Vec3,
    ) -> Option<(usize, f32, f32, bool)> {
        let src = self.analytic.get(&(kind as u32, prim))?;
        let fan = src.faces.get(src.lookup.face(p, ng))?;
        let score = |&(t, _): &&([Vec3; 3], u32)| {
            let (u, v) = tessellate::barycentric(t, p);
            u.min(v).min(1.0 - u - v)
        };
        let best = fan.iter().max_by(|a, b| score(a).total_cmp(&score(b)))?;
        let (u, v) = tessellate::barycentric(&best.0, p);
        let (u, v) = tessellate::clamp_barycentric(u, v);
        let (k, u, v) = self.descend_from(best.1, u, v);
        Some((k, u, v, src.open))
    }

    /// The leaf under `(u, v)` from quadtree slot `slot`.
    fn descend_from(&self, mut slot: u32, u: f32, v: f32) -> (usize, f32, f32) {
        let (mut u, mut v) = (u.clamp(0.0, 1.0), v.clamp(0.0, 1.0));
        loop {
            let s = self.slots[slot as usize];
            if s & LEAF != 0 {
                return ((s & !LEAF) as usize, u, v);
            }
            let (c, cu, cv) = descend(u, v);
            slot = s + c as u32;
            (u, v) = (cu, cv);
        }
    }

    /// Total area.
    pub fn area(&self) -> f64 {
        self.elements.iter().map(|e| e.area as f64).sum()
    }
}

/// The longest edge of a triangle.
pub fn longest_edge(p: &[Vec3; 3]) -> f32 {
    (p[1] - p[0])
        .length()
        .max((p[2] - p[1]).length())
        .max((p[0] - p[2]).length())
}

fn too_many(patch_size: f32) -> RadiosityError {
    RadiosityError::Settings(format!(
        "patch size {patch_size} gives more than {MAX_ELEMENTS} elements; use a larger --patch-size"
    ))
}

impl Geometry {
    /// Analytic primitives of an instanced object, which the radiosity mesh leaves out.
    fn count_unmeshed(&self) -> usize {
        self.prim_count() - self.triangles.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn descend_inverts_children() {
        let t = [Vec3::ZERO, Vec3::X, Vec3::Y];
        for &(u, v) in &[
            (0.1f32, 0.2f32),
            (0.7, 0.1),
            (0.1, 0.8),
            (0.3, 0.3),
            (0.45, 0.4),
        ] {
            let (c, cu, cv) = descend(u, v);
            let child = children(t)[c];
            let q = child[0] * (1.0 - cu - cv) + child[1] * cu + child[2] * cv;
            assert!((q - Vec3::new(u, v, 0.0)).length() < 1e-6, "{u} {v} -> {c}");
            assert!(cu >= -1e-6 && cv >= -1e-6 && cu + cv <= 1.0 + 1e-6);
        }
    }

    #[test]
    fn centroid_pattern_is_the_mean_centroid() {
        for level in 0..3 {
            let p = centroid_pattern(level);
            assert_eq!(p.len(), 1 << (2 * level));
            let (su, sv) = p.iter().fold((0.0, 0.0), |a, b| (a.0 + b.0, a.1 + b.1));
            assert!((su / p.len() as f32 - 1.0 / 3.0).abs() < 1e-6);
            assert!((sv / p.len() as f32 - 1.0 / 3.0).abs() < 1e-6);
        }
    }
}
