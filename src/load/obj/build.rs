//! Faces to triangles, for a run of consecutive faces on one thread: ear clipping of
//! larger faces, shading normals (the file's, or a smoothing group's), texture
//! coordinates, degenerate faces dropped and counted, and each face's material.

use super::converted::{Converted, MAX_SMOOTH, Stop};
use super::in_force::InForce;
use super::material::DEFAULT_SLOT;
use super::parse::{Face, Obj};
use super::smoothing::{self, GroupKey, unit};
use crate::geometry::polygon::Triangulator;
use crate::geometry::{Kind, QuadUv, Triangle};
use crate::math::Vec3;
use crate::scene::Geometry;
use glam::Vec2;
use std::collections::HashMap;
use std::ops::Range;
use std::path::Path;
use std::sync::Arc;

/// What converting any faces of a model needs, shared by the threads that convert
/// them.
pub(super) struct Model<'a> {
    obj: &'a Obj,
    /// The file, as the triangles' origins name it.
    file: Arc<str>,
    /// Each `usemtl` as (index of the first face after it, its material slot).
    slots: Vec<(usize, u32)>,
    /// The index the default material has in the model's list once a face uses it.
    default_material: u32,
    /// The smoothing groups' normals ([`smoothing::group_normals`]).
    group_normals: HashMap<GroupKey, Vec3>,
}

impl<'a> Model<'a> {
    /// The faces of `obj` from the file at `path`; `slots` are the material slots of
    /// its `usemtl` statements, `default_material` the index of the default material
    /// once added. Sums the smoothing groups' normals (over every face, in order).
    pub fn new(path: &Path, obj: &'a Obj, slots: &[u32], default_material: u32) -> Self {
        let starts = obj.usemtl.iter().map(|u| u.first_face);
        Model {
            obj,
            file: Arc::from(path.display().to_string()),
            slots: starts.zip(slots.iter().copied()).collect(),
            default_material,
            group_normals: smoothing::group_normals(obj),
        }
    }

    /// How many faces (and lines) the model has.
    pub fn faces(&self) -> usize {
        self.obj.faces.len()
    }

    /// Triangles the whole model is likely to make: enough for faces of 3 vertices.
    pub fn triangles_expected(&self) -> usize {
        self.obj.corner_count() / 3
    }
}

/// Convert `faces` of `model` (a range of [`Obj::faces`]), in order, into `geometry`
/// (empty: its lists' memory is reused), with room made first for `expected`
/// triangles.
// Kept out of line so that profiles show the conversion.
#[inline(never)]
pub(super) fn convert(
    model: &Model,
    faces: Range<usize>,
    expected: usize,
    geometry: Geometry,
) -> Converted {
    let mut b = Builder::new(model, geometry);
    let g = &mut b.out.geometry;
    g.triangles.items.reserve(expected);
    g.triangles.material.reserve(expected);
    g.triangle_normals.reserve(expected);
    let stop = b.faces(faces).err();
    let mut out = b.out;
    out.stop = stop;
    out.smooth_tried =
        out.geometry.vertex_normals.len() + usize::from(stop == Some(Stop::TooManySmooth));
    out
}

/// Faces to triangles, one after the other.
struct Builder<'a> {
    model: &'a Model<'a>,
    out: Converted,
    // Scratch for polygons, reused from face to face.
    pts: Vec<Vec3>,
    nrm: Vec<Vec3>,
    tris: Vec<[usize; 3]>,
    uvs: Vec<Vec2>,
    triangulator: Triangulator,
}

/// What applies to a face besides its vertices.
struct FaceContext {
    /// The material slot of the `usemtl` in force.
    slot: u32,
    /// The smoothing group (0: none).
    group: u32,
}

impl<'a> Builder<'a> {
    fn new(model: &'a Model<'a>, geometry: Geometry) -> Self {
        Builder {
            model,
            out: Converted {
                geometry,
                ..Converted::default()
            },
            pts: Vec::new(),
            nrm: Vec::new(),
            tris: Vec::new(),
            uvs: Vec::new(),
            triangulator: Triangulator::new(),
        }
    }

    /// Add the triangles of `faces`, in order, up to the first that stops them.
    fn faces(&mut self, faces: Range<usize>) -> Result<(), Stop> {
        let model = self.model;
        let mut slots = InForce::from(&model.slots, DEFAULT_SLOT, faces.start);
        let mut groups = InForce::from(&model.obj.smoothing, 0, faces.start);
        let list = model.obj.faces.get(faces.clone()).unwrap_or_default();
        for (k, face) in faces.zip(list) {
            let context = FaceContext {
                slot: slots.at(k),
                group: groups.at(k),
            };
            if face.is_line {
                continue;
            }
            self.out.stats.polygons += 1;
            self.face(face, &context)?;
        }
        Ok(())
    }

    /// Add the triangles of one face (nothing if it is degenerate).
    fn face(&mut self, face: &Face, context: &FaceContext) -> Result<(), Stop> {
        if face.arity < 3 {
            self.degenerate(face.line);
            return Ok(());
        }
        let obj = self.model.obj;
        if !smoothing::positions(obj, face, &mut self.pts) {
            return Err(Stop::MissingVertex);
        }
        let smooth = self.shading_normals(face, context);
        self.texcoords(face);
        if !self.triangulate() {
            self.degenerate(face.line);
            return Ok(());
        }
        let m = self.material(context.slot);
        let first = self.out.geometry.triangles.len();
        for t in 0..self.tris.len() {
            self.triangle(t, smooth, m)?;
        }
        let count = self.out.geometry.triangles.len() - first;
        let line = u32::try_from(face.line).unwrap_or(u32::MAX);
        let g = &mut self.out.geometry;
        g.sources
            .add(Kind::Triangle, first, count, &self.model.file, line);
        self.quad_uv(face, first);
        Ok(())
    }

    /// The material index of `slot`, noting a use of the default material.
    fn material(&mut self, slot: u32) -> u32 {
        if slot == DEFAULT_SLOT {
            self.out.default_used = true;
            self.model.default_material
        } else {
            slot
        }
    }

    /// The face's shading normals into `nrm`: the file's (a face with a zero-length
    /// one is noted and flat), else its smoothing group's. Whether it is smooth.
    fn shading_normals(&mut self, face: &Face, context: &FaceContext) -> bool {
        let obj = self.model.obj;
        self.nrm.clear();
        if face.all_normals && face.normals_defined {
            let normals = obj
                .corners_of(face)
                .iter()
                .filter_map(|c| obj.normals.get(c.vn).copied().and_then(unit));
            self.nrm.extend(normals);
            let smooth = self.nrm.len() == face.arity;
            if !smooth {
                self.zero_normal(face.line);
            }
            smooth
        } else if context.group != 0 {
            let grouped = |p: &Vec3| {
                let sum = self
                    .model
                    .group_normals
                    .get(&smoothing::key(*p, context.group));
                sum.and_then(|n| unit(*n))
            };
            self.nrm.extend(self.pts.iter().filter_map(grouped));
            self.nrm.len() == face.arity
        } else {
            false
        }
    }

    /// The face's texture coordinates into `uvs`, when it has them.
    fn texcoords(&mut self, face: &Face) {
        let obj = self.model.obj;
        self.uvs.clear();
        if !(face.all_texcoords && face.texcoords_defined) {
            return;
        }
        let uvs = obj
            .corners_of(face)
            .iter()
            .map(|c| obj.texcoords.get(c.vt).copied().unwrap_or_default());
        self.uvs.extend(uvs);
    }

    /// The face's triangles into `tris` (corner indices); false for a degenerate face.
    fn triangulate(&mut self) -> bool {
        self.tris.clear();
        if let Ok([a, b, c]) = <[Vec3; 3]>::try_from(self.pts.as_slice()) {
            let ng = (b - a).cross(c - a);
            if ng.is_nan() || ng == Vec3::ZERO {
                return false;
            }
            self.tris.push([0, 1, 2]);
            true
        } else {
            self.triangulator
                .triangulate(&self.pts, &mut self.tris)
                .is_ok()
        }
    }

    /// Add triangle `t` of `tris` with material `m`, smooth or flat, and its texture
    /// coordinates.
    fn triangle(&mut self, t: usize, smooth: bool, m: u32) -> Result<(), Stop> {
        let Some(&[a, b, c]) = self.tris.get(t) else {
            return Ok(());
        };
        let corner = |v: &[Vec3], i: usize| v.get(i).copied().unwrap_or_default();
        let tri = Triangle {
            p: [a, b, c].map(|i| corner(&self.pts, i)),
        };
        let n = smooth.then(|| [a, b, c].map(|i| corner(&self.nrm, i)));
        self.push(tri, n, m)?;
        if !self.uvs.is_empty() {
            let g = &mut self.out.geometry;
            let i = g.triangles.len() - 1;
            let uv = [a, b, c].map(|i| self.uvs.get(i).copied().unwrap_or_default());
            g.set_triangle_uvs(i, uv);
        }
        Ok(())
    }

    /// A textured quad takes its (u, v) from the bilinear patch; `first` is its first
    /// triangle.
    fn quad_uv(&mut self, face: &Face, first: usize) {
        let (Ok(p), Ok(uv)) = (
            <[Vec3; 4]>::try_from(self.pts.as_slice()),
            <[Vec2; 4]>::try_from(self.uvs.as_slice()),
        ) else {
            return;
        };
        let g = &mut self.out.geometry;
        if face.arity != 4 || g.triangles.len() != first + 2 {
            return;
        }
        if let Some(q) = QuadUv::new(p, uv) {
            let k = g.add_quad(q);
            g.set_triangle_quad(first, k);
            g.set_triangle_quad(first + 1, k);
        }
    }

    #[inline]
    fn push(&mut self, tri: Triangle, normals: Option<[Vec3; 3]>, m: u32) -> Result<(), Stop> {
        let out = &mut self.out;
        for p in tri.p {
            out.bounds = out.bounds.grow(p);
        }
        match normals {
            Some(n) => {
                if out.geometry.vertex_normals.len() >= MAX_SMOOTH {
                    return Err(Stop::TooManySmooth);
                }
                out.geometry.add_smooth_triangle(tri, n, m);
            }
            None => out.geometry.add_triangle(tri, m),
        }
        Ok(())
    }

    fn degenerate(&mut self, line: usize) {
        self.out.stats.degenerate_dropped += 1;
        self.out.first_degenerate.get_or_insert(line);
    }

    fn zero_normal(&mut self, line: usize) {
        self.out.zero_normals += 1;
        self.out.first_zero_normal.get_or_insert(line);
    }
}
