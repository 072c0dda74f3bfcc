//! Faces to triangles: ear clipping of larger faces, shading normals (the file's, or a
//! smoothing group's), texture coordinates, degenerate faces dropped and counted, and
//! each face's material.

use super::located::whole_file;
use super::material::{DEFAULT_SLOT, Materials};
use super::parse::{Face, Obj};
use super::smoothing::{self, GroupKey, unit};
use crate::geometry::polygon::Triangulator;
use crate::geometry::{Kind, QuadUv, Triangle};
use crate::load::LoadError;
use crate::math::{Aabb, Vec3};
use crate::scene::{Geometry, LoadStats};
use glam::Vec2;
use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

/// The triangles of a model, with what was noted on the way.
pub(super) struct Builder<'a> {
    path: &'a Path,
    /// The file, as the triangles' origins name it.
    file: Arc<str>,
    pub geometry: Geometry,
    pub bounds: Aabb,
    pub stats: LoadStats,
    /// Line of the first degenerate face.
    pub first_degenerate: Option<usize>,
    /// Faces with a zero-length normal, and the line of the first.
    pub zero_normals: usize,
    pub first_zero_normal: Option<usize>,
    // Scratch for polygons, reused from face to face.
    pts: Vec<Vec3>,
    nrm: Vec<Vec3>,
    tris: Vec<[usize; 3]>,
    uvs: Vec<Vec2>,
    triangulator: Triangulator,
}

/// What applies to a face besides its vertices.
struct FaceContext<'a> {
    /// The material slot of the `usemtl` in force.
    slot: u32,
    /// The smoothing group (0: none).
    group: u32,
    group_normals: &'a HashMap<GroupKey, Vec3>,
}

impl<'a> Builder<'a> {
    pub fn new(path: &'a Path) -> Self {
        Builder {
            path,
            file: Arc::from(path.display().to_string()),
            geometry: Geometry::default(),
            bounds: Aabb::EMPTY,
            stats: LoadStats::default(),
            first_degenerate: None,
            zero_normals: 0,
            first_zero_normal: None,
            pts: Vec::new(),
            nrm: Vec::new(),
            tris: Vec::new(),
            uvs: Vec::new(),
            triangulator: Triangulator::new(),
        }
    }

    /// Add the faces of `obj` in file order; `slots` are the material slots of its
    /// `usemtl` statements.
    // Kept out of line (called once) so that profiles show the conversion.
    #[inline(never)]
    pub fn build(
        &mut self,
        obj: &Obj,
        slots: &[u32],
        materials: &mut Materials,
    ) -> Result<(), LoadError> {
        let corners = obj.corner_count();
        self.geometry.triangles.items.reserve(corners / 3);
        self.geometry.triangles.material.reserve(corners / 3);
        self.geometry.triangle_normals.reserve(corners / 3);
        let groups = smoothing::face_groups(obj);
        let group_normals = smoothing::group_normals(obj, &groups);
        let mut next_usemtl = obj.usemtl.iter().zip(slots).peekable();
        let mut slot = DEFAULT_SLOT;
        for (k, (face, &group)) in obj.faces.iter().zip(&groups).enumerate() {
            while let Some((_, &s)) = next_usemtl.next_if(|(u, _)| u.first_face <= k) {
                slot = s;
            }
            if face.is_line {
                continue;
            }
            self.stats.polygons += 1;
            let context = FaceContext {
                slot,
                group,
                group_normals: &group_normals,
            };
            self.face(obj, face, &context, materials)?;
        }
        Ok(())
    }

    /// Add the triangles of one face (nothing if it is degenerate).
    fn face(
        &mut self,
        obj: &Obj,
        face: &Face,
        context: &FaceContext,
        materials: &mut Materials,
    ) -> Result<(), LoadError> {
        if face.arity < 3 {
            self.degenerate(face.line);
            return Ok(());
        }
        if !smoothing::positions(obj, face, &mut self.pts) {
            return Err(whole_file(
                self.path,
                "internal error: a face names a vertex the file does not define".into(),
            ));
        }
        let smooth = self.shading_normals(obj, face, context);
        self.texcoords(obj, face);
        if !self.triangulate() {
            self.degenerate(face.line);
            return Ok(());
        }
        let m = materials.index(context.slot);
        let first = self.geometry.triangles.len();
        for t in 0..self.tris.len() {
            self.triangle(t, smooth, m)?;
        }
        let count = self.geometry.triangles.len() - first;
        let line = u32::try_from(face.line).unwrap_or(u32::MAX);
        let g = &mut self.geometry;
        g.sources
            .add(Kind::Triangle, first, count, &self.file, line);
        self.quad_uv(face, first);
        Ok(())
    }

    /// The face's shading normals into `nrm`: the file's (a face with a zero-length
    /// one is noted and flat), else its smoothing group's. Whether it is smooth.
    fn shading_normals(&mut self, obj: &Obj, face: &Face, context: &FaceContext) -> bool {
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
                let sum = context
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
    fn texcoords(&mut self, obj: &Obj, face: &Face) {
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
    fn triangle(&mut self, t: usize, smooth: bool, m: u32) -> Result<(), LoadError> {
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
            let i = self.geometry.triangles.len() - 1;
            let uv = [a, b, c].map(|i| self.uvs.get(i).copied().unwrap_or_default());
            self.geometry.set_triangle_uvs(i, uv);
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
        if face.arity != 4 || self.geometry.triangles.len() != first + 2 {
            return;
        }
        if let Some(q) = QuadUv::new(p, uv) {
            let k = self.geometry.add_quad(q);
            self.geometry.set_triangle_quad(first, k);
            self.geometry.set_triangle_quad(first + 1, k);
        }
    }

    #[inline]
    fn push(&mut self, tri: Triangle, normals: Option<[Vec3; 3]>, m: u32) -> Result<(), LoadError> {
        for p in tri.p {
            self.bounds = self.bounds.grow(p);
        }
        match normals {
            Some(n) => {
                if self.geometry.vertex_normals.len() >= u32::MAX as usize {
                    return Err(whole_file(self.path, "too many smooth triangles".into()));
                }
                self.geometry.add_smooth_triangle(tri, n, m);
            }
            None => self.geometry.add_triangle(tri, m),
        }
        Ok(())
    }

    fn degenerate(&mut self, line: usize) {
        self.stats.degenerate_dropped += 1;
        self.first_degenerate.get_or_insert(line);
    }

    fn zero_normal(&mut self, line: usize) {
        self.zero_normals += 1;
        self.first_zero_normal.get_or_insert(line);
    }
}
