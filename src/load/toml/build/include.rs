//! `include`: an NFF or OBJ file read once (however often it is placed), its
//! materials, textures and statistics joined to the scene's, and its content placed
//! under the node's transform: triangles baked with their normals, texture coordinates
//! and quads, analytic primitives by the placement rules, NFF lights on request. The
//! file is read in double precision into a frame of its own (an NFF file's eye, an OBJ
//! model's centre), and each placement maps that frame into the scene's in double
//! precision, so that a model far from its own origin keeps its detail. Errors
//! and warnings in the included file carry its own position and say where it was
//! included from; its primitives, materials and lights keep their own file and line as
//! their origin.

use super::super::format::{ObjectDef, Spanned};
use super::objects::Sink;
use super::types::Ty;
use super::{Builder, LOG_TARGET, R, f32v};
use crate::geometry::Kind;
use crate::geometry::{QuadUv, Triangle};
use crate::load::{LoadError, nff, obj, text};
use crate::math::Vec3;
use crate::scene::{Geometry, Light, LoadStats, Material, SceneSources, Spot};
use glam::{DAffine3, DMat3, DVec3};
use std::path::Path;
use std::rc::Rc;

/// The formats an `include` reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Format {
    Nff,
    Obj,
}

/// A parsed included file, its materials already appended to the scene's.
pub(super) struct Included {
    /// Its primitives, material indices local to the file, relative to `origin`.
    geometry: Geometry,
    /// The point of the file's own coordinates that is the zero of `geometry`.
    origin: DVec3,
    /// Where its materials and lights were defined.
    sources: SceneSources,
    /// Its lights (NFF).
    lights: Vec<Light>,
    /// Where its materials start in the scene's list.
    material_base: u32,
    format: Format,
}

/// An included file as read, before it joins the scene.
struct Read {
    geometry: Geometry,
    origin: DVec3,
    sources: SceneSources,
    materials: Vec<Material>,
    lights: Vec<Light>,
    stats: LoadStats,
    format: Format,
}

impl Builder<'_, '_> {
    /// `include`: an NFF or OBJ file's primitives (and optionally lights) under the node's
    /// transform; its materials, unless the node gives one for all of them.
    pub(super) fn include(
        &mut self,
        node: &Spanned<ObjectDef>,
        x: DAffine3,
        material: Option<u32>,
        sink: &mut Sink,
    ) -> R<()> {
        let o = node.get_ref();
        let file = self.need(&o.file, "file", node, Ty::Include)?;
        let inc = self.included(file)?;
        // From the file's frame to its own coordinates, then where the node places them.
        let x = x * DAffine3::from_translation(inc.origin);
        let mat = |m: u32| material.unwrap_or(inc.material_base + m);
        if let Some(l) = &o.lights {
            if *l.get_ref() {
                self.include_lights(&inc, l, &x, sink)?;
            }
        }
        place_triangles(
            Self::geometry(&mut self.geometry, sink),
            &inc.geometry,
            &x,
            mat,
        );
        let span = o.ty.span();
        for entry in inc.geometry.shapes() {
            let m = mat(entry.material);
            let origin = inc.geometry.sources.get(entry.kind, entry.prim);
            let before = self.placed(sink);
            self.place_shape(entry.shape, &x, m, span.clone(), sink)?;
            self.record_origin(sink, &before, origin);
        }
        Ok(())
    }

    /// `lights = true`: the included NFF file's lights under `x` (at the top level only).
    fn include_lights(
        &mut self,
        inc: &Included,
        l: &Spanned<bool>,
        x: &DAffine3,
        sink: &Sink,
    ) -> R<()> {
        if inc.format == Format::Obj {
            return Err(self.err(
                l.span(),
                "`lights` is for NFF includes (an OBJ file has no lights)",
            ));
        }
        if sink.in_define() {
            return Err(self.err(
                l.span(),
                "an include inside a define cannot bring lights (a define is an \
                 object placed by instances; lights are not instanced)",
            ));
        }
        for (k, light) in inc.lights.iter().enumerate() {
            if let Some(o) = inc.sources.lights.get(k as u32) {
                let index = self.lights.len();
                self.sources.lights.add(index, 1, &o.file, o.line);
            }
            self.lights.push(Light {
                pos: f32v(x.transform_point3(light.pos.as_dvec3())),
                spot: light.spot.map(|sp| Spot {
                    dir: f32v((x.matrix3 * sp.dir.as_dvec3()).normalize()),
                    ..sp
                }),
                ..*light
            });
        }
        Ok(())
    }

    /// The included file `file`, read once however often it is placed.
    fn included(&mut self, file: &Spanned<String>) -> R<Rc<Included>> {
        let rel = Path::new(file.get_ref());
        let path = self.relative_path(file.get_ref());
        if let Some(inc) = self.includes.get(&path) {
            return Ok(inc.clone());
        }
        let is = |e: &str| rel.extension().is_some_and(|x| x.eq_ignore_ascii_case(e));
        if is("toml") {
            return Err(self.err(
                file.span(),
                format!(
                    "cannot include `{}`: only NFF and OBJ files can be included",
                    rel.display()
                ),
            ));
        }
        let read = if is("obj") {
            self.read_obj(file, &path)?
        } else {
            self.read_nff(file, &path)?
        };
        let material_base = self.materials.len() as u32;
        for k in 0..read.materials.len() {
            if let Some(o) = read.sources.materials.get(k as u32) {
                let index = material_base as usize + k;
                self.sources.materials.add(index, 1, &o.file, o.line);
            }
        }
        self.materials.extend_from_slice(&read.materials);
        self.stats.polygons += read.stats.polygons;
        self.stats.degenerate_dropped += read.stats.degenerate_dropped;
        let inc = Rc::new(Included {
            geometry: read.geometry,
            origin: read.origin,
            sources: read.sources,
            lights: read.lights,
            material_base,
            format: read.format,
        });
        self.includes.insert(path, inc.clone());
        Ok(inc)
    }

    /// An OBJ file (with its MTL materials and their textures, which join the scene's).
    fn read_obj(&mut self, file: &Spanned<String>, path: &Path) -> R<Read> {
        std::fs::File::open(path).map_err(|e| self.unreadable(file, path, e))?;
        let from = self.included_from(file);
        let data =
            obj::load_geometry_at(path, obj::Origin::Centre).map_err(|e| located(e, &from))?;
        for w in &data.warnings {
            log::warn!(target: LOG_TARGET, "{w}{from}");
        }
        // The model's maps index its own textures: move them past the scene's.
        let base = self.textures.len() as u32;
        self.textures.extend(data.textures);
        if self.environment.is_none() {
            self.environment = data.environment;
        }
        let materials = data
            .materials
            .into_iter()
            .map(|m| Material {
                maps: m.maps.offset(base),
                ..m
            })
            .collect();
        Ok(Read {
            geometry: data.geometry,
            origin: data.origin,
            sources: SceneSources::default(),
            materials,
            lights: Vec::new(),
            stats: data.stats,
            format: Format::Obj,
        })
    }

    /// An NFF file.
    fn read_nff(&self, file: &Spanned<String>, path: &Path) -> R<Read> {
        let bytes = std::fs::read(path).map_err(|e| self.unreadable(file, path, e))?;
        let from = self.included_from(file);
        let text = text::lossy(&bytes, path).map_err(|e| located(e, &from))?;
        let scene = nff::parse_str(&text, path).map_err(|e| located(e, &from))?;
        Ok(Read {
            geometry: scene.geometry,
            origin: scene.origin,
            sources: scene.sources,
            materials: scene.materials,
            lights: scene.lights,
            stats: scene.load_stats,
            format: Format::Nff,
        })
    }

    /// The error for an included file (named by `file`, found at `path`) that cannot
    /// be read.
    fn unreadable(&self, file: &Spanned<String>, path: &Path, e: std::io::Error) -> LoadError {
        self.err(
            file.span(),
            format!("cannot read included file `{}`: {e}", path.display()),
        )
    }

    /// ` (included from PATH:LINE:COL)`: where `file` is named, the end of the messages
    /// about the included file.
    fn included_from(&self, file: &Spanned<String>) -> String {
        let (line, col) = self.src.position(file.span().start);
        format!(" (included from {}:{line}:{col})", self.src.path.display())
    }
}

/// An error in an included file, saying where it was included `from`.
fn located(mut e: LoadError, from: &str) -> LoadError {
    e.message = format!("{}{from}", e.message);
    e
}

/// How an include's triangles are placed: its transform and what follows from it.
struct Placement {
    x: DAffine3,
    normal_matrix: DMat3,
    /// The transform mirrors: the winding is reversed to keep the front side.
    mirror: bool,
    identity: bool,
}

impl Placement {
    fn new(x: &DAffine3) -> Self {
        Placement {
            x: *x,
            normal_matrix: x.matrix3.inverse().transpose(),
            mirror: x.matrix3.determinant() < 0.0,
            identity: *x == DAffine3::IDENTITY,
        }
    }

    fn point(&self, v: Vec3) -> Vec3 {
        f32v(self.x.transform_point3(v.as_dvec3()))
    }

    /// Triangle `i` of `s`: its placed corners and vertex normals, if it has them.
    fn triangle(&self, s: &Geometry, i: usize) -> ([Vec3; 3], Option<[Vec3; 3]>) {
        let mut p = s.triangles.items[i].p;
        if !self.identity {
            p = p.map(|v| self.point(v));
        }
        let normals = match s.triangle_normals[i] {
            u32::MAX => None,
            k => {
                let mut n = s.vertex_normals[k as usize];
                if !self.identity {
                    n = n.map(|v| f32v((self.normal_matrix * v.as_dvec3()).normalize()));
                }
                Some(n)
            }
        };
        if self.mirror {
            ([p[0], p[2], p[1]], normals.map(|n| [n[0], n[2], n[1]]))
        } else {
            (p, normals)
        }
    }
}

/// Add the triangles of `s` under `x` to `g`, with their vertex normals, texture
/// coordinates and quads (each quad placed once, when a triangle first needs it), and
/// the materials `mat` gives for theirs.
fn place_triangles(g: &mut Geometry, s: &Geometry, x: &DAffine3, mat: impl Fn(u32) -> u32) {
    let place = Placement::new(x);
    let mut quads = vec![u32::MAX; s.quads.len()];
    for i in 0..s.triangles.items.len() {
        let m = mat(s.triangles.material[i]);
        let (p, normals) = place.triangle(s, i);
        match normals {
            Some(n) => g.add_smooth_triangle(Triangle { p }, n, m),
            None => g.add_triangle(Triangle { p }, m),
        }
        let placed = g.triangles.len() - 1;
        if let Some(o) = s.sources.get(Kind::Triangle, i as u32) {
            g.sources.add(Kind::Triangle, placed, 1, &o.file, o.line);
        }
        if let Some(&k) = s.triangle_uvs.get(i).filter(|&&k| k != u32::MAX) {
            let t = s.vertex_uvs[k as usize];
            let t = if place.mirror { [t[0], t[2], t[1]] } else { t };
            g.set_triangle_uvs(placed, t);
        }
        if let Some(&k) = s.triangle_quads.get(i).filter(|&&k| k != u32::MAX) {
            if quads[k as usize] == u32::MAX {
                let q = s.quads[k as usize];
                quads[k as usize] = g.add_quad(QuadUv {
                    p: if place.identity {
                        q.p
                    } else {
                        q.p.map(|v| place.point(v))
                    },
                    ..q
                });
            }
            g.set_triangle_quad(placed, quads[k as usize]);
        }
    }
}
