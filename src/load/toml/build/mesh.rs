//! Triangles, polygons and meshes: their vertices (and optional vertex normals)
//! transformed into final coordinates, each polygon triangulated, degenerate ones
//! dropped and counted.

use super::super::format::{ObjectDef, Spanned, V3};
use super::objects::Sink;
use super::types::Ty;
use super::{Builder, R, article, f32v, v3};
use crate::geometry::Triangle;
use glam::{DAffine3, DVec3};
use std::ops::Range;

/// The vertices of a triangle, polygon or mesh, and their unit normals if given.
struct Vertices {
    pts: Vec<DVec3>,
    normals: Option<Vec<DVec3>>,
}

impl Builder<'_, '_> {
    /// `triangle` (exactly 3 vertices) or `polygon` (at least 3).
    pub(super) fn polygon(
        &mut self,
        node: &Spanned<ObjectDef>,
        ty: Ty,
        x: &DAffine3,
        material: u32,
        sink: &mut Sink,
    ) -> R<()> {
        let (vertices, v) = self.vertices(node, ty)?;
        let n = v.pts.len();
        let (enough, what) = if ty == Ty::Triangle {
            (n == 3, "exactly 3 vertices")
        } else {
            (n >= 3, "at least 3 vertices")
        };
        self.non_empty(vertices, "vertices", ty, what)?;
        if !enough {
            return Err(self.err(
                vertices.span(),
                format!("{} needs {what}, found {n}", article(ty.name())),
            ));
        }
        self.emit_polygon(&v, None, x, material, node.span(), sink);
        Ok(())
    }

    /// `mesh`: polygons given as lists of indices into its vertices.
    pub(super) fn mesh(
        &mut self,
        node: &Spanned<ObjectDef>,
        x: &DAffine3,
        material: u32,
        sink: &mut Sink,
    ) -> R<()> {
        let (vertices, v) = self.vertices(node, Ty::Mesh)?;
        self.non_empty(vertices, "vertices", Ty::Mesh, "at least one vertex")?;
        let faces = self.need(&node.get_ref().faces, "faces", node, Ty::Mesh)?;
        for f in self.non_empty(faces, "faces", Ty::Mesh, "at least one face")? {
            let idx = f.get_ref();
            if idx.len() < 3 {
                return Err(self.err(
                    f.span(),
                    format!(
                        "a face needs at least 3 vertex indices, found {}",
                        idx.len()
                    ),
                ));
            }
            if let Some(&bad) = idx.iter().find(|&&i| i as usize >= v.pts.len()) {
                return Err(self.err(
                    f.span(),
                    format!(
                        "vertex index {bad} is out of range: the mesh has {} vertices \
                         (indices start at 0)",
                        v.pts.len()
                    ),
                ));
            }
            self.emit_polygon(&v, Some(idx), x, material, f.span(), sink);
        }
        Ok(())
    }

    /// The `vertices` of a triangle, polygon or mesh (`ty`) with their span, and their
    /// `normals`, if given, one per vertex.
    fn vertices<'n>(
        &self,
        node: &'n Spanned<ObjectDef>,
        ty: Ty,
    ) -> R<(&'n Spanned<Vec<Spanned<V3>>>, Vertices)> {
        let o = node.get_ref();
        let vertices = self.need(&o.vertices, "vertices", node, ty)?;
        let vs = vertices.get_ref();
        let normals = match &o.normals {
            Some(n) => {
                if n.get_ref().len() != vs.len() {
                    return Err(self.err(
                        n.span(),
                        format!(
                            "`normals` must have one normal per vertex: {} vertices, {} normals",
                            vs.len(),
                            n.get_ref().len()
                        ),
                    ));
                }
                let mut out = Vec::with_capacity(vs.len());
                for v in n.get_ref() {
                    out.push(self.direction(v, "a vertex normal")?);
                }
                Some(out)
            }
            None => None,
        };
        let pts = vs.iter().map(|v| v3(v.get_ref())).collect();
        Ok((vertices, Vertices { pts, normals }))
    }

    /// Transform a polygon (the points `v.pts[indices[i]]`, or all of `v.pts`) and its
    /// vertex normals by `x`, triangulate it and add the triangles. Under a mirroring
    /// transform the vertex order is reversed so that the front side stays the front.
    fn emit_polygon(
        &mut self,
        v: &Vertices,
        indices: Option<&[u32]>,
        x: &DAffine3,
        material: u32,
        span: Range<usize>,
        sink: &mut Sink,
    ) {
        let normal_matrix = x.matrix3.inverse().transpose();
        let mirror = x.matrix3.determinant() < 0.0;
        self.pts.clear();
        self.nrm.clear();
        let n = indices.map_or(v.pts.len(), <[u32]>::len);
        for k in 0..n {
            let k = if mirror { n - 1 - k } else { k };
            let i = indices.map_or(k, |ix| ix[k] as usize);
            self.pts.push(f32v(x.transform_point3(v.pts[i])));
            if let Some(ns) = &v.normals {
                self.nrm.push(f32v((normal_matrix * ns[i]).normalize()));
            }
        }
        self.stats.polygons += 1;
        if self
            .triangulator
            .triangulate(&self.pts, &mut self.tris)
            .is_err()
        {
            self.stats.degenerate_dropped += 1;
            if self.first_degenerate.is_none() {
                self.first_degenerate = Some(span);
            }
            return;
        }
        let g = Self::geometry(&mut self.geometry, sink);
        for &[a, b, c] in &self.tris {
            let tri = Triangle {
                p: [self.pts[a], self.pts[b], self.pts[c]],
            };
            if v.normals.is_some() {
                g.add_smooth_triangle(tri, [self.nrm[a], self.nrm[b], self.nrm[c]], material);
            } else {
                g.add_triangle(tri, material);
            }
        }
    }
}
