//! What one stretch of an NFF file makes: its primitives, materials, lights and
//! viewpoints, in file order, before they are joined with the stretches before it
//! (`super::merge`).
//!
//! A stretch does not know the material in effect where it starts: its primitives
//! before its first `f` name [`INHERITED`], resolved when the stretches are joined;
//! the others name the stretch's own materials by their index in it. Warnings are kept
//! in order, to be logged when the stretch is joined, so that they come out once and
//! in file order however the stretches were parsed.

use crate::geometry::polygon::Triangulator;
use crate::geometry::{Analytic, Kind, Triangle};
use crate::math::Vec3;
use crate::scene::{Camera, Geometry, Light, Material};
use std::sync::Arc;

/// The material index of a primitive that uses the material in effect before its
/// stretch.
pub(crate) const INHERITED: u32 = u32::MAX;

/// Something to log or to do, in file order, when a stretch is joined.
#[derive(Clone, Debug)]
pub(crate) enum Note {
    /// A warning, as it is logged.
    Warning(String),
    /// A `v` at this line and column: a warning if a viewpoint came before.
    Viewpoint { line: usize, col: usize },
    /// A complete viewpoint: the camera from here on.
    Camera(Camera),
}

/// A material, light or primitive list of a stretch, with its entities' lines.
#[derive(Default)]
pub(crate) struct Part {
    /// Primitives; their materials are [`INHERITED`] or indices into `materials`, and
    /// their sources count from 0.
    pub geometry: Geometry,
    /// The `f` entities, with their lines.
    pub materials: Vec<(Material, u32)>,
    /// Whether a primitive uses the material in effect before the stretch.
    pub inherits: bool,
    /// The lights, whether each had a colour, and their lines.
    pub lights: Vec<(Light, bool, u32)>,
    /// The last background.
    pub background: Option<Vec3>,
    /// Warnings and viewpoints in order.
    pub notes: Vec<Note>,
    /// Polygons read, and those dropped as degenerate.
    pub polygons: usize,
    pub degenerate_dropped: usize,
    /// Line and column of the first dropped polygon.
    pub first_degenerate: Option<(usize, usize)>,
    /// The file, as the sources name it.
    pub file: Arc<str>,
    /// Scratch: a polygon's triangles.
    tris: Vec<[usize; 3]>,
    triangulator: Triangulator,
}

/// More smooth triangles than `u32` indices can count.
#[derive(Debug)]
pub(crate) struct TooManySmooth;

impl Part {
    /// An empty stretch of the file `file`.
    pub fn new(file: Arc<str>) -> Self {
        Part {
            file,
            triangulator: Triangulator::new(),
            ..Part::default()
        }
    }

    /// The material of the next primitive: [`INHERITED`] before the part's first `f`
    /// (the part then inherits), else the index of its last.
    #[inline]
    pub fn material_index(&mut self) -> u32 {
        match self.materials.len() {
            0 => {
                self.inherits = true;
                INHERITED
            }
            n => n as u32 - 1,
        }
    }

    /// The material of the next primitive as [`Part::material_index`] gives it, but
    /// without marking the part as inheriting: for a primitive that may yet be dropped
    /// (see [`Part::add_triangulated`]).
    #[inline]
    pub fn material_in_effect(&self) -> u32 {
        match self.materials.len() {
            0 => INHERITED,
            n => n as u32 - 1,
        }
    }

    /// An `f` on line `line`.
    pub fn add_material(&mut self, material: Material, line: u32) {
        self.materials.push((material, line));
    }

    /// An `l` on line `line`; without a colour, its colour is set when the scene is
    /// complete.
    pub fn add_light(&mut self, light: Light, has_color: bool, line: u32) {
        self.lights.push((light, has_color, line));
    }

    /// An analytic primitive (`s`, `c`) on line `line`.
    #[inline]
    pub fn add_analytic<P: Analytic>(&mut self, prim: P, kind: Kind, line: u32) {
        let m = self.material_index();
        self.add_analytic_with(prim, kind, line, m);
    }

    /// An analytic primitive on line `line` with material `material`, the
    /// [`Part::material_index`] of its line (taken when it was read, for a primitive
    /// added after the entities that followed it).
    #[inline]
    pub fn add_analytic_with<P: Analytic>(
        &mut self,
        prim: P,
        kind: Kind,
        line: u32,
        material: u32,
    ) {
        self.record(kind, 1, line);
        self.geometry.push(prim, material);
    }

    /// Analytic primitives of one kind on consecutive lines, one each from `first_line`
    /// on: what [`Part::add_analytic`] adds for each in turn.
    pub fn add_analytic_lines<P: Analytic>(
        &mut self,
        prims: impl IntoIterator<Item = P>,
        kind: Kind,
        first_line: u32,
    ) {
        let mut prims = prims.into_iter().peekable();
        if prims.peek().is_none() {
            return;
        }
        let m = self.material_index();
        let first = self.geometry.count(kind);
        for prim in prims {
            self.geometry.push(prim, m);
        }
        let count = self.geometry.count(kind) - first;
        let g = &mut self.geometry;
        g.sources
            .add_lines(kind, first, count, &self.file, first_line);
    }

    /// A polygon (`p`, or `pp` when `normals` are given, one per point) on line `line`,
    /// triangulated; a degenerate one is dropped and counted, and the first one's
    /// position, `at()`, kept for the warning.
    ///
    /// # Errors
    /// [`TooManySmooth`] past `u32::MAX` smooth triangles.
    pub fn add_polygon(
        &mut self,
        pts: &[Vec3],
        normals: Option<&[Vec3]>,
        line: u32,
        at: impl FnOnce() -> (usize, usize),
    ) -> Result<(), TooManySmooth> {
        if self.triangulator.triangulate(pts, &mut self.tris).is_err() {
            self.add_degenerate(at);
            return Ok(());
        }
        self.polygons += 1;
        let m = self.material_index();
        self.record(Kind::Triangle, self.tris.len(), line);
        let g = &mut self.geometry;
        for &[a, b, c] in &self.tris {
            let tri = Triangle {
                p: [pts[a], pts[b], pts[c]],
            };
            g.triangles.push(tri, m);
            let k = match normals {
                Some(n) => {
                    let k = u32::try_from(g.vertex_normals.len())
                        .ok()
                        .filter(|&k| k < u32::MAX)
                        .ok_or(TooManySmooth)?;
                    g.vertex_normals.push([n[a], n[b], n[c]]);
                    k
                }
                None => u32::MAX,
            };
            g.triangle_normals.push(k);
        }
        Ok(())
    }

    /// A degenerate polygon, dropped and counted as [`Part::add_polygon`] drops it; its
    /// position, `at()`, is kept if it is the first.
    pub fn add_degenerate(&mut self, at: impl FnOnce() -> (usize, usize)) {
        self.polygons += 1;
        self.degenerate_dropped += 1;
        if self.first_degenerate.is_none() {
            self.first_degenerate = Some(at());
        }
    }

    /// A polygon on line `line` already triangulated into `tris`, with their vertex
    /// normals (one triple per triangle) for a `pp`: what [`Part::add_polygon`] adds
    /// for it, with material `material`, the [`Part::material_index`] of its line, or
    /// [`INHERITED`] before the part's first `f` (the part then inherits).
    ///
    /// # Errors
    /// [`TooManySmooth`] past `u32::MAX` smooth triangles.
    pub fn add_triangulated(
        &mut self,
        tris: &[Triangle],
        normals: Option<&[[Vec3; 3]]>,
        line: u32,
        material: u32,
    ) -> Result<(), TooManySmooth> {
        self.polygons += 1;
        self.inherits |= material == INHERITED;
        self.record(Kind::Triangle, tris.len(), line);
        let g = &mut self.geometry;
        let first = g.triangles.items.len();
        g.triangles.items.extend_from_slice(tris);
        g.triangles.material.resize(first + tris.len(), material);
        match normals {
            Some(n) => {
                debug_assert_eq!(n.len(), tris.len());
                let k = g.vertex_normals.len();
                let last = k + n.len();
                // The last index, `last − 1`, below `u32::MAX` (the flat marker).
                if u32::try_from(last).is_err() {
                    return Err(TooManySmooth);
                }
                g.triangle_normals.extend(k as u32..last as u32);
                g.vertex_normals.extend_from_slice(n);
            }
            None => {
                let flat = std::iter::repeat_n(u32::MAX, tris.len());
                g.triangle_normals.extend(flat);
            }
        }
        Ok(())
    }

    /// The next `count` primitives of `kind` come from line `line`.
    #[inline]
    fn record(&mut self, kind: Kind, count: usize, line: u32) {
        let first = self.geometry.count(kind);
        let g = &mut self.geometry;
        g.sources.add(kind, first, count, &self.file, line);
    }
}
