//! The Wavefront OBJ loader, with its MTL material libraries.
//!
//! [`load_geometry`] reads a model into triangles and materials for a scene file to
//! place; [`load`] wraps one into a whole [`Scene`] with an automatic camera and light,
//! so that `emray render model.obj` shows it.
//!
//! # Geometry
//!
//! Parsing is [`tobj`]'s (no triangulation, separate position and normal indices);
//! this module checks the file first, triangulates and maps the materials:
//!
//! - Faces (`f`) with 3 vertices become one triangle directly; larger ones, convex or
//!   not, are cut by ear clipping ([`crate::geometry::polygon`]), never as a blind fan,
//!   and every triangle keeps the face's winding.
//! - A face whose every vertex has a normal index (`v/vt/vn` or `v//vn`) is smooth:
//!   its triangles carry the file's normals, made unit length, as per-vertex shading
//!   normals. Other faces are flat. A face with a zero-length normal is shaded flat
//!   and counted in a warning.
//! - Degenerate faces (fewer than 3 vertices, fewer than 3 distinct positions, or no
//!   area) are dropped, counted in [`LoadStats::degenerate_dropped`], and reported by
//!   one warning naming the first one's line. [`LoadStats::polygons`] counts the faces
//!   read, degenerate or not.
//! - Lines (`l`) are skipped with a warning; points, curves and surfaces are ignored.
//!   Groups and objects (`g`, `o`) do not split materials: every face keeps the
//!   material of the `usemtl` in force where it appears, whatever group it is in.
//!
//! # Errors
//!
//! A file that cannot be read is an error naming it. A malformed file is an error
//! `path:line:col: message` at the first problem found: a coordinate that is not a
//! number, too few or too many numbers in a `v`, `vt` or `vn`, a non-finite coordinate
//! or normal that a face uses (`nan`, `inf`, or a number too large for `f32`; unused
//! elements are not looked at once they parse as numbers), a vertex weight `w` of 0,
//! a face index that is 0, not an integer, or beyond the elements the file defines
//! (relative, negative indices count back from the last element defined before the
//! face), a vertex with more than three indices, a face without vertices, or a
//! `usemtl` without a name. Comments must be on a line of their own (`tobj` reads a
//! trailing `#` as part of the statement).
//!
//! # Materials
//!
//! Material libraries (`mtllib`) are read relative to the OBJ file's directory; several
//! may be given, on one line or many. Materials are matched to `usemtl` by name after
//! every library has been read (a later definition of a name wins). Problems with
//! materials never stop the load; each becomes a warning naming the file, and the faces
//! concerned get [`DEFAULT_MATERIAL`], a mid-grey diffuse:
//!
//! - a library that cannot be read (its faces' materials are then missing);
//! - a `usemtl` naming a material no library defines (one warning per name);
//! - a malformed MTL statement (`path:line:col`): it is ignored, and a `newmtl` without
//!   a name drops the statements up to the next `newmtl`. A colour given as one number
//!   (`Kd 0.8`) is grey, as the MTL format specifies.
//!
//! Faces before any `usemtl` also get [`DEFAULT_MATERIAL`], without a warning.
//! Emission (`Ke`), `Tf` and other statements are ignored. Material indices in
//! [`ObjData`] are local to [`ObjData::materials`]: one per material defined by the
//! libraries, in the order read, then the default material if some face uses it.
//!
//! # Texture maps
//!
//! File names are relative to the library's directory; each image is read once.
//!
//! - `map_Kd` multiplies the colour (sRGB-decoded), `map_Ks` the highlight and mirror
//!   weights by its mean (sRGB-decoded), `bump`/`map_bump`/`map_Bump` is a height
//!   field (read linearly, scaled by `-bm`), `norm`/`map_Kn` a tangent-space normal map
//!   (linear). Options: `-bm`, `-clamp on|off` and `-s u v` (texture coordinates are
//!   multiplied by it; the material keeps the last one given) are used; the others
//!   (`-o`, `-t`, `-mm`, `-blendu`, ...) are skipped with a warning.
//! - `refl` with a 2:1 latitude-longitude or 4:3 cube-cross image becomes the scene's
//!   environment map (the first one that loads; a command-line `--envmap` wins). Six
//!   `refl -type cube_right|cube_left|cube_top|cube_bottom|cube_back|cube_front FILE`
//!   statements (the faces +x, −x, +y, −y, +z, −z: the front is −z) make a cube map
//!   instead, used when no single-image `refl` loads; a missing face is a warning.
//! - Other maps (`map_Ka`, `map_d`, `map_Ns`, `disp`, `decal`) are skipped with one
//!   warning per library.
//! - A map whose file cannot be read is a warning naming the file and the library's
//!   line. A missing colour map shows as [`MISSING_TEXTURE`], a magenta and black
//!   checkerboard (8 × 8 squares per unit of texture coordinates), so the problem is
//!   visible; a missing specular, bump or normal map is left out.
//!
//! Faces with `vt` on every vertex carry their texture coordinates (interpolated
//! barycentrically, triangles of larger faces keeping their corners'). Without `vt` a
//! triangle's texture coordinates are its barycentric coordinates.
//!
//! Faces without `vn` in a smoothing group (`s 1`, `s 2`, ...; `s off` and `s 0` end
//! it) are smooth: each vertex gets the normalised sum of the area-weighted normals of
//! the group's faces at that position (positions are matched exactly, across `g`
//! and `o`). Outside smoothing groups such faces are flat.
//!
//! An MTL material becomes a Whitted [`Material`] as follows (means are over r, g, b;
//! colours are clamped to be non-negative, `Ns` too, `d` to [0, 1]):
//!
//! - colour = `Kd`, and kd = 1. ka = mean(`Ka`) / mean(`Kd`) (exact when `Ka` is a
//!   multiple of `Kd`, else the mean ambient reflectance is kept); without `Ka`, ka =
//!   1 (the ambient colour is the diffuse colour, as in NFF).
//! - Without `Kd`, or with a black `Kd`, the diffuse term is zero whatever the colour,
//!   so the colour carries the ambient term instead: colour = `Ka` (black without one),
//!   kd = 0, ka = 1.
//! - ks = mean(`Ks`) (0 without `Ks`), shine = `Ns` (1 without `Ns`).
//! - t = 1 − `d` (`d` from `d`, else 1 − `Tr`, else 1): a material with `d` < 1
//!   transmits, whatever its illumination model.
//! - ior = `Ni`, or 1 when absent or outside 0.001–1000 (many exporters write `Ni 0`;
//!   the range is [`range::IOR_RANGE`]); a transmissive material with such an `Ni` gets
//!   a warning.
//! - priority = 0.
//!
//! The illumination model (`illum`) then switches terms off or the mirror on:
//!
//! | illum | MTL meaning | emray material |
//! |---|---|---|
//! | 0 | colour on, ambient off | diffuse only: ka = 0, ks = 0 |
//! | 1 | colour on, ambient on | ambient and diffuse: ks = 0 |
//! | 2 | highlight on | ambient, diffuse and the Phong highlight (ks, shine) |
//! | 3 | reflection on, ray trace on | as 2, plus a mirror: kr = mean(`Ks`) |
//! | 4 | glass on, ray trace on | as 2 (transparency comes from `d`) |
//! | 5 | Fresnel on, ray trace on | as 3 (a constant kr: no Fresnel term) |
//! | 6 | refraction on, Fresnel off, ray trace on | as 2 (transparency from `d`) |
//! | 7 | refraction on, Fresnel on, ray trace on | as 3 (transparency from `d`) |
//! | 8, 9, 10, other, none | reflection or glass without ray tracing, shadow matte | as 2 |
//!
//! kr is 0 except for illum 3, 5 and 7.
//!
//! # The automatic view ([`load`], [`frame`])
//!
//! With `c` the centre of the model's bounding box and `r` half its diagonal (the
//! radius of a sphere around the box):
//!
//! - The camera looks at `c` from `c + d · (0, sin 15°, cos 15°)`: on the +z side,
//!   15° above the centre, with up = +y, a 40° field of view ([`Camera::angle_deg`]),
//!   hither 0 and 512 × 512 pixels. `d = 1.05 · r / sin 20°`: the sphere fits inside
//!   the 40° cone of view with 5 % to spare.
//! - One white point light, intensity (1, 1, 1), no attenuation, at
//!   `eye + 0.25 · d · (up′ − right)`, where `right` and `up′` are the camera's unit
//!   right and up vectors: above and to the left of the eye.
//! - Ambient light 0.1 (white), black background.
//!
//! A model without a single non-degenerate face has nothing to frame: [`load`] reports
//! an error.

use super::LoadError;
use crate::geometry::polygon::Triangulator;
use crate::geometry::{QuadUv, Triangle};
use crate::math::{Aabb, DVec3, Vec3};
use crate::scene::texture::{Image, Wrap};
use crate::scene::{
    Camera, Environment, Geometry, Light, LoadStats, Material, Scene, Texture, range,
};
use glam::Vec2;
use std::cell::RefCell;
use std::collections::HashMap;
use std::io::Cursor;
use std::path::Path;

/// The material of faces without one: before any `usemtl`, or whose material is
/// missing. Mid-grey (0.5), fully diffuse, ambient weight 1, no highlight.
pub const DEFAULT_MATERIAL: Material = Material {
    color: Vec3::splat(0.5),
    ..Material::DEFAULT
};

/// What a colour map that cannot be read shows: a magenta and black checkerboard,
/// 8 × 8 squares over the unit square of texture coordinates.
pub const MISSING_TEXTURE: Texture = Texture::Checker {
    a: Vec3::new(1.0, 0.0, 1.0),
    b: Vec3::ZERO,
    scale: 8.0,
};

/// Full vertical field of view of the automatic camera, in degrees.
pub const AUTO_FOV_DEG: f32 = 40.0;
/// Width and height of the automatic camera's image, in pixels.
pub const AUTO_RESOLUTION: u32 = 512;
/// Elevation of the automatic camera above the model's centre, in degrees.
pub const AUTO_ELEVATION_DEG: f32 = 15.0;
/// How much farther than the tightest fit the automatic camera stands.
pub const AUTO_MARGIN: f32 = 1.05;
/// Offset of the automatic light from the eye, along the camera's up minus right
/// vectors, as a fraction of the eye's distance to the model's centre.
pub const AUTO_LIGHT_OFFSET: f32 = 0.25;
/// Ambient light intensity of the automatic scene.
pub const AUTO_AMBIENT: f32 = 0.1;

/// A model read from an OBJ file, ready to be placed in a scene.
#[derive(Clone, Debug, PartialEq)]
pub struct ObjData {
    /// The triangles; their material indices point into `materials`.
    pub geometry: Geometry,
    /// The materials of the libraries, in the order read, then [`DEFAULT_MATERIAL`] if
    /// a face uses it.
    pub materials: Vec<Material>,
    /// The textures the materials' maps index.
    pub textures: Vec<Texture>,
    /// The environment from the first usable reflection map (`refl`), if any.
    pub environment: Option<Environment>,
    /// Bounds of the triangles ([`Aabb::EMPTY`] when there are none).
    pub bounds: Aabb,
    /// Problems that did not stop the load, each naming its file (and line when known).
    pub warnings: Vec<String>,
    /// Faces read and degenerate faces dropped.
    pub stats: LoadStats,
}

/// Read the OBJ file at `path` (and its material libraries) into a scene: the model,
/// an automatic camera and a light (see the module documentation). Warnings are logged.
///
/// # Errors
/// Whatever [`load_geometry`] reports, or `path: …` when the model has no
/// non-degenerate face to frame.
pub fn load(path: &Path) -> Result<Scene, LoadError> {
    let data = load_geometry(path)?;
    for w in &data.warnings {
        log::warn!("{w}");
    }
    let Some((camera, light)) = frame(&data.bounds) else {
        let message = if data.stats.polygons == 0 {
            "no faces ('f') to render".to_string()
        } else if data.geometry.triangles.is_empty() {
            format!(
                "nothing to render: all {} faces are degenerate",
                data.stats.polygons
            )
        } else {
            "the model is too large to frame (its size overflows f32)".to_string()
        };
        return Err(whole_file(path, message));
    };
    let mut scene = Scene::new(camera);
    scene.lights = vec![light];
    scene.ambient = Vec3::splat(AUTO_AMBIENT);
    scene.materials = data.materials;
    scene.textures = data.textures;
    scene.environment = data.environment;
    scene.geometry = data.geometry;
    scene.load_stats = data.stats;
    Ok(scene)
}

/// The automatic camera and light for a model with these bounds (see the module
/// documentation), or `None` for empty, infinite or zero-size bounds.
pub fn frame(bounds: &Aabb) -> Option<(Camera, Light)> {
    if bounds.is_empty() || !bounds.is_finite() {
        return None;
    }
    // In f64: the diagonal of a box near f32's range overflows f32.
    let (lo, hi) = (bounds.min.as_dvec3(), bounds.max.as_dvec3());
    let centre = (lo + hi) * 0.5;
    let r = 0.5 * (hi - lo).length();
    if r <= 0.0 {
        return None;
    }
    let half = f64::from(AUTO_FOV_DEG).to_radians() * 0.5;
    let dist = f64::from(AUTO_MARGIN) * r / half.sin();
    let elev = f64::from(AUTO_ELEVATION_DEG).to_radians();
    let back = DVec3::new(0.0, elev.sin(), elev.cos());
    let from = centre + back * dist;
    // The camera's basis, as the eye-ray generator builds it.
    let forward = -back;
    let right = forward.cross(DVec3::Y).normalize();
    let up = right.cross(forward);
    let light = from + (up - right) * (f64::from(AUTO_LIGHT_OFFSET) * dist);
    let (from, at, light) = (from.as_vec3(), centre.as_vec3(), light.as_vec3());
    if !(from.is_finite() && light.is_finite()) || from == at {
        return None;
    }
    let camera = Camera {
        from,
        at,
        up: Vec3::Y,
        angle_deg: AUTO_FOV_DEG,
        hither: 0.0,
        width: AUTO_RESOLUTION,
        height: AUTO_RESOLUTION,
    };
    Some((camera, Light::point(light, Vec3::ONE)))
}

/// Read the OBJ file at `path` and the material libraries it names.
///
/// # Errors
/// `path: cannot read: …` when the file cannot be read, `path:line:col: …` at the
/// first malformed statement (see the module documentation). Bytes that are not UTF-8
/// are replaced, which leaves line numbers intact. Problems with material libraries are
/// warnings, not errors.
pub fn load_geometry(path: &Path) -> Result<ObjData, LoadError> {
    let t0 = std::time::Instant::now();
    let bytes = std::fs::read(path).map_err(|e| whole_file(path, format!("cannot read: {e}")))?;
    let text = String::from_utf8_lossy(&bytes);
    let t_read = t0.elapsed();
    let scan = match scan(&text) {
        Ok(s) => s,
        Err(e) => {
            // The scan does not parse numbers: an earlier bad number is the first error.
            let first = find_bad_number(&text, e.line).unwrap_or(e);
            return Err(first.at(path));
        }
    };

    let libs = MtlLibs {
        dir: path.parent().unwrap_or(Path::new("")),
        obj: path,
        mtllib_lines: &scan.mtllib_lines,
        calls: Default::default(),
        read: Default::default(),
        warnings: Default::default(),
        maps: Default::default(),
    };
    let options = tobj_options();
    let t_scan = t0.elapsed();
    let parsed = tobj::load_obj_buf(&mut Cursor::new(text.as_bytes()), &options, |p| {
        libs.load(p)
    });
    let (models, mtl) = match parsed {
        Ok(r) => r,
        Err(e) => {
            let located = find_bad_number(&text, usize::MAX).or_else(|| {
                (e == tobj::LoadError::FaceColorOutOfBounds)
                    .then(|| scan.colour_mismatch.clone())
                    .flatten()
            });
            return Err(match located {
                Some(l) => l.at(path),
                None => whole_file(path, format!("malformed OBJ file ({e})")),
            });
        }
    };
    // Every library that failed has been reported by `libs`; what did load is here.
    let mtl = mtl.unwrap_or_default();

    for m in &models {
        let usable = m
            .mesh
            .positions
            .iter()
            .all(|v| v.abs() <= range::MAX_COORDINATE)
            && m.mesh.normals.iter().all(|v| v.is_finite());
        if !usable {
            return Err(match find_bad_number(&text, usize::MAX) {
                Some(l) => l.at(path),
                None => whole_file(path, "vertex coordinates out of range".into()),
            });
        }
        if !mesh_is_consistent(&m.mesh) {
            return Err(whole_file(
                path,
                "internal error: the OBJ parser returned an inconsistent mesh".into(),
            ));
        }
    }
    let tobj_faces: usize = models.iter().map(|m| face_count(&m.mesh)).sum();
    if tobj_faces != scan.faces.len() {
        return Err(whole_file(
            path,
            format!(
                "internal error: the OBJ parser found {tobj_faces} faces, the scan {}",
                scan.faces.len()
            ),
        ));
    }

    let mut warnings = libs.warnings.into_inner();
    let read_libs = libs.read.into_inner();
    let maps = libs.maps.into_inner();
    let mut b = Builder::new(path, &mtl, &mut warnings);
    b.load_maps(&maps);
    let runs = b.resolve_usemtl(&scan, &read_libs);
    let t_parse = t0.elapsed();
    b.build(&models, &scan, &runs)?;
    let t_build = t0.elapsed();
    log::info!(
        "{}: read {:.0} ms, scan {:.0} ms, parse (tobj) {:.0} ms, conversion {:.0} ms",
        path.display(),
        t_read.as_secs_f64() * 1e3,
        (t_scan - t_read).as_secs_f64() * 1e3,
        (t_parse - t_scan).as_secs_f64() * 1e3,
        (t_build - t_parse).as_secs_f64() * 1e3
    );
    let Builder {
        geometry,
        materials,
        textures,
        environment,
        bounds,
        stats,
        first_degenerate,
        zero_normals,
        first_zero_normal,
        ..
    } = b;

    if let Some(k) = first_degenerate {
        warnings.push(format!(
            "{}: dropped {} degenerate face(s) (fewer than 3 distinct vertices or zero \
             area), the first at line {}",
            path.display(),
            stats.degenerate_dropped,
            face_line(&text, k)
        ));
    }
    if let Some(k) = first_zero_normal {
        warnings.push(format!(
            "{}: {zero_normals} face(s) with a zero-length vertex normal shaded flat, the \
             first at line {}",
            path.display(),
            face_line(&text, k)
        ));
    }
    if scan.lines > 0 {
        warnings.push(format!(
            "{}: ignored {} line element(s) ('l'): only faces are rendered",
            path.display(),
            scan.lines
        ));
    }
    Ok(ObjData {
        geometry,
        materials,
        textures,
        environment,
        bounds,
        warnings,
        stats,
    })
}

/// `tobj`'s options: faces as written (we triangulate), separate index lists, points
/// and lines kept so that its faces match the scan's one for one.
fn tobj_options() -> tobj::LoadOptions {
    // `..Default::default()` keeps this compiling should a tobj feature add fields.
    #[allow(clippy::needless_update)]
    tobj::LoadOptions {
        triangulate: false,
        single_index: false,
        ignore_points: false,
        ignore_lines: false,
        ..Default::default()
    }
}

fn whole_file(path: &Path, message: String) -> LoadError {
    LoadError {
        path: path.to_path_buf(),
        line: 0,
        col: 0,
        message,
    }
}

/// A problem at a place in a file.
#[derive(Clone, Debug, PartialEq)]
struct Located {
    line: usize,
    col: usize,
    message: String,
}

impl Located {
    fn at(self, path: &Path) -> LoadError {
        LoadError {
            path: path.to_path_buf(),
            line: self.line,
            col: self.col,
            message: self.message,
        }
    }
}

/// 1-based column (in characters) of `tok`, a slice of `line`.
fn col_of(line: &str, tok: &str) -> usize {
    let off = (tok.as_ptr() as usize).saturating_sub(line.as_ptr() as usize);
    line.get(..off).map_or(1, |s| s.chars().count() + 1)
}

/// 1-based column just after the last token of `line`.
fn col_end(line: &str) -> usize {
    line.trim_end().chars().count() + 1
}

/// A token for a message: quoted, and shortened if long.
fn show(t: &str) -> String {
    const MAX: usize = 40;
    if t.chars().count() <= MAX {
        format!("'{t}'")
    } else {
        let head: String = t.chars().take(MAX).collect();
        format!("'{head}…'")
    }
}

/// A hint for a token that starts a comment after a statement.
fn comment_hint(tok: &str) -> &'static str {
    if tok.starts_with('#') {
        " (comments must be on a line of their own)"
    } else {
        ""
    }
}

// ---------------------------------------------------------------------------------
// The scan: structure and indices, checked before tobj sees the file

/// Face flag: the statement is a line (`l`), not a face.
const FACE_IS_LINE: u8 = 1;
/// Face flag: every vertex of the face has a normal index.
const FACE_ALL_NORMALS: u8 = 2;
/// Face flag: every vertex of the face has a texture coordinate index.
const FACE_ALL_TEXCOORDS: u8 = 4;

/// What the scan learns about the file that tobj does not say.
#[derive(Debug, Default)]
struct Scan {
    /// Per `f` or `l` statement, in file order (as tobj returns them): `FACE_*` flags.
    faces: Vec<u8>,
    /// `usemtl` statements in file order.
    usemtl: Vec<UseMtl>,
    /// Line of each `mtllib` statement, in order.
    mtllib_lines: Vec<usize>,
    /// Number of `l` statements.
    lines: usize,
    /// Smoothing-group statements (`s`) as (index of the first face after it, group;
    /// 0 = off), in file order.
    smoothing: Vec<(usize, u32)>,
    /// The first `v` whose colour (x y z r g b) is present where the first `v`'s is
    /// not, or the other way round: tobj refuses faces on such vertices.
    colour_mismatch: Option<Located>,
}

/// A `usemtl` statement.
#[derive(Debug)]
struct UseMtl {
    /// Index (among `Scan::faces`) of the first face after it.
    first_face: usize,
    /// The material name, as tobj reads it.
    name: String,
    line: usize,
}

/// Element kinds that faces index: vertices, texture coordinates, normals.
const KINDS: [(&str, &str); 3] = [
    ("vertex", "vertices"),
    ("texture coordinate", "texture coordinates"),
    ("normal", "normals"),
];

/// A positive index beyond the elements defined so far: valid only if the file defines
/// enough elements later.
#[derive(Debug)]
struct ForwardRef {
    index: usize,
    at: Located,
}

/// Scan the OBJ text line by line as tobj splits it, check what tobj would reject (or
/// panic on) except malformed numbers, and record per-face facts. No number is parsed
/// but face indices.
// Kept out of line (called once) so that profiles show the scan as its own phase.
#[inline(never)]
fn scan(text: &str) -> Result<Scan, Located> {
    let mut s = Scan::default();
    let mut counts = [0usize; 3];
    // Per kind: forward references, each larger than the one before (the first that
    // turns out out of range is always among them).
    let mut forward: [Vec<ForwardRef>; 3] = Default::default();
    let mut first_has_colour: Option<(bool, usize)> = None;
    for (i, line) in text.lines().enumerate() {
        let ln = i + 1;
        let mut words = line.split_whitespace();
        let Some(kw) = words.next() else { continue };
        let err = |tok: Option<&str>, message: String| Located {
            line: ln,
            col: tok.map_or_else(|| col_end(line), |t| col_of(line, t)),
            message,
        };
        match kw {
            "v" => {
                let mut n = 0;
                let mut fourth = None;
                let mut seventh = None;
                for w in words {
                    n += 1;
                    match n {
                        4 => fourth = Some(w),
                        7 => seventh = Some(w),
                        _ => {}
                    }
                }
                if n < 3 {
                    return Err(err(
                        None,
                        format!("expected 3 vertex coordinates (x y z), found {n}"),
                    ));
                }
                if n == 5 || n > 6 {
                    let tok = if n == 5 { fourth } else { seventh };
                    let hint = tok.map_or("", comment_hint);
                    return Err(err(
                        tok,
                        format!(
                            "a vertex is 'x y z', 'x y z w' or 'x y z r g b', found {n} \
                             numbers{hint}"
                        ),
                    ));
                }
                let has_colour = n == 6;
                match first_has_colour {
                    None => first_has_colour = Some((has_colour, ln)),
                    Some((first, first_ln)) => {
                        if first != has_colour && s.colour_mismatch.is_none() {
                            let (this, that) = if has_colour {
                                ("has a colour", "has none")
                            } else {
                                ("has no colour", "has one")
                            };
                            s.colour_mismatch = Some(err(
                                Some(kw),
                                format!(
                                    "this vertex {this} but the first one (line \
                                     {first_ln}) {that}: vertex colours must be on every \
                                     vertex or on none"
                                ),
                            ));
                        }
                    }
                }
                counts[0] += 1;
            }
            "vt" => {
                let n = words.count();
                if n < 2 {
                    return Err(err(
                        None,
                        format!("expected 2 texture coordinates (u v), found {n}"),
                    ));
                }
                counts[1] += 1;
            }
            "vn" => {
                let n = words.count();
                if n < 3 {
                    return Err(err(
                        None,
                        format!("expected 3 normal components (x y z), found {n}"),
                    ));
                }
                counts[2] += 1;
            }
            "f" | "l" => {
                let mut n = 0;
                let mut all_normals = true;
                let mut all_texcoords = true;
                for tok in words {
                    n += 1;
                    // One pass over the token's parts: what they say about normals and
                    // texture coordinates is collected on the way.
                    let mut parts = 0;
                    let mut last_empty = false;
                    let mut has_vt = false;
                    for (k, part) in tok.split('/').enumerate() {
                        parts += 1;
                        last_empty = part.is_empty();
                        if k == 1 {
                            has_vt = !part.is_empty();
                        }
                        if k >= 3 {
                            return Err(err(
                                Some(tok),
                                format!(
                                    "vertex {} has more than 3 indices (v/vt/vn){}",
                                    show(tok),
                                    comment_hint(tok)
                                ),
                            ));
                        }
                        if part.is_empty() {
                            if k == 0 {
                                return Err(err(
                                    Some(tok),
                                    format!("missing vertex index in {}", show(tok)),
                                ));
                            }
                            continue;
                        }
                        let Ok(x) = part.parse::<isize>() else {
                            return Err(err(
                                Some(tok),
                                format!(
                                    "expected {} index, found {}{}",
                                    article(KINDS[k].0),
                                    show(part),
                                    comment_hint(tok)
                                ),
                            ));
                        };
                        let (one, many) = KINDS[k];
                        if x == 0 {
                            return Err(err(
                                Some(tok),
                                format!("{one} index 0 is invalid (OBJ indices start at 1)"),
                            ));
                        }
                        if x < 0 {
                            if x.unsigned_abs() > counts[k] {
                                return Err(err(
                                    Some(tok),
                                    format!(
                                        "relative {one} index {x} reaches before the first \
                                         {one} ({} {} defined so far)",
                                        counts[k],
                                        if counts[k] == 1 { one } else { many }
                                    ),
                                ));
                            }
                        } else if x as usize > counts[k] {
                            let refs = &mut forward[k];
                            if refs.last().is_none_or(|r| r.index < x as usize) {
                                refs.push(ForwardRef {
                                    index: x as usize,
                                    at: err(Some(tok), String::new()),
                                });
                            }
                        }
                    }
                    if parts < 3 || last_empty {
                        all_normals = false;
                    }
                    if !has_vt {
                        all_texcoords = false;
                    }
                }
                if kw == "l" {
                    s.lines += 1;
                    s.faces.push(FACE_IS_LINE);
                } else {
                    if n == 0 {
                        return Err(err(None, "face without vertices".into()));
                    }
                    let mut flags = 0;
                    if all_normals {
                        flags |= FACE_ALL_NORMALS;
                    }
                    if all_texcoords {
                        flags |= FACE_ALL_TEXCOORDS;
                    }
                    s.faces.push(flags);
                }
            }
            "usemtl" => {
                // Exactly as tobj extracts it (from the first space on, trimmed).
                let name = line.split_once(' ').unwrap_or_default().1.trim();
                if name.is_empty() {
                    return Err(err(
                        None,
                        "expected a material name after 'usemtl' (separated by a space)".into(),
                    ));
                }
                s.usemtl.push(UseMtl {
                    first_face: s.faces.len(),
                    name: name.to_string(),
                    line: ln,
                });
            }
            "mtllib" => s.mtllib_lines.push(ln),
            "s" => {
                // `s off`, `s 0` or no number: off; any other word names a group.
                let group = match words.next() {
                    None | Some("off") | Some("0") => 0,
                    Some(w) => w.parse::<u32>().unwrap_or(u32::MAX).max(1),
                };
                s.smoothing.push((s.faces.len(), group));
            }
            _ => {}
        }
    }
    // Forward references beyond the end: report the first in the file.
    let mut worst: Option<Located> = None;
    for (k, refs) in forward.iter().enumerate() {
        if let Some(r) = refs.iter().find(|r| r.index > counts[k]) {
            let (one, many) = KINDS[k];
            let at = Located {
                message: format!(
                    "{one} index {} is out of range: the file has {} {}",
                    r.index,
                    counts[k],
                    if counts[k] == 1 { one } else { many }
                ),
                ..r.at.clone()
            };
            if worst
                .as_ref()
                .is_none_or(|w| (at.line, at.col) < (w.line, w.col))
            {
                worst = Some(at);
            }
        }
    }
    match worst {
        Some(w) => Err(w),
        None => Ok(s),
    }
}

fn article(noun: &str) -> String {
    if noun.starts_with(['a', 'e', 'i', 'o', 'u']) {
        format!("an {noun}")
    } else {
        format!("a {noun}")
    }
}

/// The first malformed or non-finite number of a `v`, `vt` or `vn` statement before
/// line `limit`, as tobj reads them (`f32` parsing); texture coordinates only need to
/// be numbers.
fn find_bad_number(text: &str, limit: usize) -> Option<Located> {
    const XYZ: [&str; 3] = ["x", "y", "z"];
    for (i, line) in text.lines().enumerate() {
        let ln = i + 1;
        if ln >= limit {
            break;
        }
        let mut words = line.split_whitespace();
        let (what, names, need, finite): (&str, &[&str], usize, bool) = match words.next() {
            Some("v") => ("vertex", &XYZ, 3, true),
            Some("vn") => ("normal", &XYZ, 3, true),
            Some("vt") => ("texture", &["u", "v"], 2, false),
            _ => continue,
        };
        let err = |tok: Option<&str>, message: String| {
            Some(Located {
                line: ln,
                col: tok.map_or_else(|| col_end(line), |t| col_of(line, t)),
                message,
            })
        };
        let mut xyz = [0.0f32; 3];
        for (k, name) in names.iter().enumerate().take(need) {
            let Some(tok) = words.next() else {
                return err(
                    None,
                    format!("expected {what} {name}, found the end of the line"),
                );
            };
            match tok.parse::<f32>() {
                Ok(v) if what == "vertex" && v.is_finite() => {
                    if let Err(e) = range::check_coordinate(&format!("vertex {name}"), v) {
                        return err(Some(tok), e.to_string());
                    }
                    xyz[k] = v
                }
                Ok(v) if v.is_finite() || !finite => xyz[k] = v,
                Ok(_) => {
                    return err(
                        Some(tok),
                        format!("{what} {name} {} is not a finite number", show(tok)),
                    );
                }
                Err(_) => {
                    return err(
                        Some(tok),
                        format!(
                            "expected {what} {name}, found {}{}",
                            show(tok),
                            comment_hint(tok)
                        ),
                    );
                }
            }
        }
        if what != "vertex" {
            continue;
        }
        // An optional weight w (one more number; three more are a colour).
        let (Some(w_tok), None) = (words.next(), words.next()) else {
            continue;
        };
        match w_tok.parse::<f32>() {
            Ok(0.0) => return err(Some(w_tok), "vertex weight w is 0".into()),
            Ok(w) if w.is_finite() => {
                if xyz.iter().any(|c| !(c / w).is_finite()) {
                    return err(
                        Some(w_tok),
                        format!(
                            "vertex coordinates divided by the weight w = {} are not finite",
                            show(w_tok)
                        ),
                    );
                }
                for (c, name) in xyz.iter().zip(XYZ) {
                    let what = format!("vertex {name} / w =");
                    if let Err(e) = range::check_coordinate(&what, c / w) {
                        return err(Some(w_tok), e.to_string());
                    }
                }
            }
            Ok(_) => {
                return err(
                    Some(w_tok),
                    format!("vertex weight w {} is not a finite number", show(w_tok)),
                );
            }
            Err(_) => {
                return err(
                    Some(w_tok),
                    format!(
                        "expected vertex weight w, found {}{}",
                        show(w_tok),
                        comment_hint(w_tok)
                    ),
                );
            }
        }
    }
    None
}

/// The line of the `k`-th (0-based) `f` or `l` statement.
fn face_line(text: &str, k: usize) -> usize {
    let mut seen = 0;
    for (i, line) in text.lines().enumerate() {
        if matches!(line.split_whitespace().next(), Some("f" | "l")) {
            if seen == k {
                return i + 1;
            }
            seen += 1;
        }
    }
    0
}

/// Faces of a tobj mesh (its arities are left out when every face is a triangle).
fn face_count(mesh: &tobj::Mesh) -> usize {
    if mesh.face_arities.is_empty() {
        mesh.indices.len() / 3
    } else {
        mesh.face_arities.len()
    }
}

/// Index lists that agree with the arities and stay inside their arrays, so that the
/// conversion cannot index out of bounds.
fn mesh_is_consistent(mesh: &tobj::Mesh) -> bool {
    let total: usize = if mesh.face_arities.is_empty() {
        mesh.indices.len() - mesh.indices.len() % 3
    } else {
        mesh.face_arities.iter().map(|&a| a as usize).sum()
    };
    let np = mesh.positions.len() / 3;
    let nn = mesh.normals.len() / 3;
    total == mesh.indices.len()
        && mesh.indices.iter().all(|&i| (i as usize) < np)
        && (mesh.normal_indices.is_empty()
            || (mesh.normal_indices.len() == total
                && mesh.normal_indices.iter().all(|&i| (i as usize) < nn)))
}

// ---------------------------------------------------------------------------------
// Material libraries

/// Loads the libraries tobj asks for (it calls [`MtlLibs::load`] once per `mtllib`),
/// collecting warnings instead of failing.
struct MtlLibs<'a> {
    /// Directory of the OBJ file: library names are relative to it.
    dir: &'a Path,
    obj: &'a Path,
    mtllib_lines: &'a [usize],
    /// Number of `mtllib` statements handled so far.
    calls: RefCell<usize>,
    /// Libraries read, as named in the file.
    read: RefCell<Vec<String>>,
    warnings: RefCell<Vec<String>>,
    /// Texture statements of the libraries read, in order.
    maps: RefCell<Vec<TexStmt>>,
}

impl MtlLibs<'_> {
    fn load(&self, name: &Path) -> tobj::MTLLoadResult {
        let line = {
            let mut calls = self.calls.borrow_mut();
            *calls += 1;
            self.mtllib_lines.get(*calls - 1).copied().unwrap_or(0)
        };
        let at = if line > 0 {
            format!("{}:{line}", self.obj.display())
        } else {
            self.obj.display().to_string()
        };
        let Some(name) = name.to_str().filter(|n| !n.is_empty()) else {
            self.warn(format!("{at}: 'mtllib' without a file name"));
            return Err(tobj::LoadError::OpenFileFailed);
        };
        // `mtllib a.mtl b.mtl`: tobj hands over the rest of the line as one name.
        let single = self.dir.join(name);
        let names: Vec<&str> = if !single.exists() && name.split_whitespace().nth(1).is_some() {
            name.split_whitespace().collect()
        } else {
            vec![name]
        };
        let mut materials = Vec::new();
        let mut map = HashMap::new();
        let mut any = false;
        for n in names {
            let full = self.dir.join(n);
            let bytes = match std::fs::read(&full) {
                Ok(b) => b,
                Err(e) => {
                    self.warn(format!(
                        "{at}: cannot read material library '{n}' ({}): {e}; faces using \
                         its materials get the default grey material",
                        full.display()
                    ));
                    continue;
                }
            };
            let mut warnings = Vec::new();
            let text = sanitize_mtl(
                &String::from_utf8_lossy(&bytes),
                &full,
                &mut warnings,
                &mut self.maps.borrow_mut(),
            );
            self.warnings.borrow_mut().extend(warnings);
            match tobj::load_mtl_buf(&mut Cursor::new(text.as_bytes())) {
                Ok((mats, names)) => {
                    let offset = materials.len();
                    materials.extend(mats);
                    map.extend(names.into_iter().map(|(k, v)| (k, v + offset)));
                    self.read.borrow_mut().push(n.to_string());
                    any = true;
                }
                Err(e) => self.warn(format!(
                    "{}: malformed material library ({e}); its materials are not used",
                    full.display()
                )),
            }
        }
        if any {
            Ok((materials, map))
        } else {
            Err(tobj::LoadError::OpenFileFailed)
        }
    }

    fn warn(&self, w: String) {
        self.warnings.borrow_mut().push(w);
    }
}

/// Statements of texture maps.
fn is_texture_statement(kw: &str) -> bool {
    kw.starts_with("map_") || matches!(kw, "bump" | "disp" | "decal" | "refl" | "norm")
}

/// The texture maps emray uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum MapKind {
    /// `map_Kd`.
    Color,
    /// `map_Ks`.
    Specular,
    /// `bump`, `map_bump`, `map_Bump`.
    Bump,
    /// `norm`, `map_Kn`: a tangent-space normal map.
    Normal,
    /// `refl`: a reflection map, used as the scene's environment.
    Reflection,
}

/// `refl -type` of the cube faces +x, −x, +y, −y, +z, −z: the front is −z (where a
/// camera with the default orientation looks), the right +x, the top +y.
const CUBE_TYPES: [&str; 6] = [
    "cube_right",
    "cube_left",
    "cube_top",
    "cube_bottom",
    "cube_back",
    "cube_front",
];

/// A texture statement of a material.
#[derive(Clone, Debug)]
struct TexStmt {
    material: String,
    kind: MapKind,
    /// The file name as written.
    name: String,
    /// The file, relative to the library's directory.
    file: std::path::PathBuf,
    /// `-bm`.
    bump_scale: f32,
    /// `-clamp on`.
    clamp: bool,
    /// `-s u v`.
    scale: [f32; 2],
    /// For `refl -type cube_*`: the face, +x −x +y −y +z −z as 0..6.
    cube: Option<usize>,
    /// Where: `library:line`.
    at: String,
}

/// Parse the options and file name of a texture statement (everything after the
/// keyword). Options emray does not use are skipped with their arguments.
fn parse_map(words: &[&str]) -> Result<MapOptions, String> {
    let mut bm = 1.0;
    let mut scale = [1.0f32, 1.0];
    let mut clamp = false;
    let mut ignored = Vec::new();
    let mut map_type = None;
    let mut i = 0;
    let number = |t: &str| t.parse::<f32>().ok().filter(|v| v.is_finite());
    while i < words.len() && words[i].starts_with('-') && number(words[i]).is_none() {
        let opt = words[i];
        i += 1;
        let arg = |i: usize| words.get(i).copied();
        match opt {
            "-bm" => {
                bm = arg(i)
                    .and_then(number)
                    .ok_or_else(|| "expected a number after '-bm'".to_string())?;
                i += 1;
            }
            "-clamp" => {
                clamp = arg(i) == Some("on");
                i += 1;
            }
            "-type" => {
                map_type = arg(i).map(str::to_string);
                i += 1;
            }
            "-blendu" | "-blendv" | "-boost" | "-cc" | "-imfchan" | "-texres" => {
                ignored.push(opt.to_string());
                i += 1;
            }
            "-mm" => {
                ignored.push(opt.to_string());
                i += 2;
            }
            "-o" | "-s" | "-t" => {
                let mut n = 0;
                let mut got = [1.0f32; 3];
                while n < 3 {
                    let Some(x) = arg(i).and_then(number) else {
                        break;
                    };
                    got[n] = x;
                    i += 1;
                    n += 1;
                }
                if opt == "-s" && n > 0 && got[0] != 0.0 && got[1] != 0.0 {
                    scale = [got[0], got[1]];
                } else {
                    ignored.push(opt.to_string());
                }
            }
            _ => return Err(format!("unknown texture option {}", show(opt))),
        }
    }
    if i >= words.len() {
        return Err("expected a file name".into());
    }
    Ok(MapOptions {
        file: words[i..].join(" "),
        bump_scale: bm,
        clamp,
        scale,
        map_type,
        ignored,
    })
}

/// A texture statement's file and options.
struct MapOptions {
    file: String,
    bump_scale: f32,
    clamp: bool,
    scale: [f32; 2],
    /// `-type` (used by `refl`: `sphere` or `cube_top`, ...).
    map_type: Option<String>,
    ignored: Vec<String>,
}

/// The MTL text with every statement tobj would reject, or panic on, removed (each
/// with a warning `path:line:col`), one-number colours expanded to grey, and texture
/// maps removed (one warning in all).
fn sanitize_mtl(
    text: &str,
    path: &Path,
    warnings: &mut Vec<String>,
    maps: &mut Vec<TexStmt>,
) -> String {
    let mut out = String::with_capacity(text.len() + 64);
    let mut skipping = false;
    let mut unsupported: Vec<String> = Vec::new();
    let mut material = String::new();
    let mut option_notes = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let ln = i + 1;
        let mut words = line.split_whitespace();
        let Some(kw) = words.next() else { continue };
        let mut warn = |tok: Option<&str>, message: String| {
            let col = tok.map_or_else(|| col_end(line), |t| col_of(line, t));
            warnings.push(format!(
                "{}:{ln}:{col}: {message}; statement ignored",
                path.display()
            ));
        };
        let finite = |t: &str| t.parse::<f32>().is_ok_and(f32::is_finite);
        match kw {
            "newmtl" => {
                // As tobj reads the name: the trimmed line after the keyword.
                let name = line.trim()[kw.len()..].trim();
                if name.is_empty() {
                    warn(
                        None,
                        "'newmtl' without a name (its statements up to the next 'newmtl' \
                         are skipped)"
                            .into(),
                    );
                    skipping = true;
                    continue;
                }
                skipping = false;
                material = name.to_string();
            }
            _ if skipping => continue,
            "Ka" | "Kd" | "Ks" | "Ke" => {
                let v: [Option<&str>; 3] = [words.next(), words.next(), words.next()];
                match v {
                    [Some(r), None, None] if finite(r) => {
                        out.push_str(&format!("{kw} {r} {r} {r}\n"));
                        continue;
                    }
                    [Some(r), Some(g), Some(b)] if finite(r) && finite(g) && finite(b) => {}
                    _ => {
                        let bad = v.iter().flatten().find(|t| !finite(t)).copied();
                        let found = match (bad, v.iter().flatten().count()) {
                            (Some(t), _) => format!("found {}", show(t)),
                            (None, 0) => "found nothing".to_string(),
                            (None, n) => format!("found {n} numbers"),
                        };
                        warn(
                            bad,
                            format!("expected a colour 'r g b' (or one grey value), {found}"),
                        );
                        continue;
                    }
                }
            }
            "Ns" | "Ni" | "d" | "Tr" => match words.next() {
                Some(t) if finite(t) => {}
                t => {
                    let found = t.map_or("nothing".into(), show);
                    warn(t, format!("expected a number after '{kw}', found {found}"));
                    continue;
                }
            },
            "illum" => match words.next() {
                Some(t) if t.parse::<u8>().is_ok() => {}
                t => {
                    let found = t.map_or("nothing".into(), show);
                    warn(
                        t,
                        format!("expected an illumination model 0–10 after 'illum', found {found}"),
                    );
                    continue;
                }
            },
            k if is_texture_statement(k) => {
                let kind = match k {
                    "map_Kd" => MapKind::Color,
                    "map_Ks" => MapKind::Specular,
                    "bump" | "map_bump" | "map_Bump" => MapKind::Bump,
                    "norm" | "map_Kn" => MapKind::Normal,
                    "refl" => MapKind::Reflection,
                    other => {
                        if !unsupported.iter().any(|u| u == other) {
                            unsupported.push(other.to_string());
                        }
                        continue;
                    }
                };
                let rest: Vec<&str> = words.collect();
                match parse_map(&rest) {
                    Ok(MapOptions {
                        file: name,
                        bump_scale,
                        clamp,
                        scale,
                        map_type,
                        mut ignored,
                    }) => {
                        let mut cube = None;
                        match map_type.as_deref() {
                            None => {}
                            Some("sphere") if kind == MapKind::Reflection => {}
                            Some(t) if kind == MapKind::Reflection => {
                                cube = CUBE_TYPES.iter().position(|&c| c == t);
                                if cube.is_none() {
                                    warn(
                                        rest.get(1).copied(),
                                        format!(
                                            "unknown reflection map type {}: expected sphere, \
                                             cube_top, cube_bottom, cube_front, cube_back, \
                                             cube_left or cube_right",
                                            show(t)
                                        ),
                                    );
                                    continue;
                                }
                            }
                            Some(_) => ignored.push("-type".into()),
                        }
                        if !ignored.is_empty() {
                            option_notes.push(format!(
                                "{}:{ln}: texture option(s) {} not supported; ignored",
                                path.display(),
                                ignored.join(" ")
                            ));
                        }
                        maps.push(TexStmt {
                            material: material.clone(),
                            kind,
                            file: path.parent().unwrap_or(Path::new("")).join(&name),
                            name,
                            bump_scale,
                            clamp,
                            scale,
                            cube,
                            at: format!("{}:{ln}", path.display()),
                        });
                    }
                    Err(e) => warn(rest.first().copied(), e),
                }
                continue;
            }
            _ => {}
        }
        out.push_str(line);
        out.push('\n');
    }
    warnings.extend(option_notes);
    if !unsupported.is_empty() {
        warnings.push(format!(
            "{}: ignored the texture map statement(s) {}: not supported (map_Kd, map_Ks, \
             bump, map_bump, norm and refl are)",
            path.display(),
            unsupported.join(", ")
        ));
    }
    out
}

fn mean(c: [f32; 3]) -> f32 {
    (c[0] + c[1] + c[2]) / 3.0
}

/// An MTL material as a Whitted material (the mapping of the module documentation),
/// with a warning when its `Ni` cannot be used for a transmissive material.
fn convert_material(m: &tobj::Material) -> (Material, Option<String>) {
    let clamp = |c: [f32; 3]| c.map(|v| v.max(0.0));
    let ka_rgb = m.ambient.map(clamp);
    let kd_rgb = m.diffuse.map(clamp);
    let ks_rgb = m.specular.map(clamp).unwrap_or([0.0; 3]);
    let tr = m
        .unknown_param
        .get("Tr")
        .and_then(|s| s.split_whitespace().next())
        .and_then(|s| s.parse::<f32>().ok())
        .filter(|v| v.is_finite());
    let d = m
        .dissolve
        .filter(|v| v.is_finite())
        .or(tr.map(|t| 1.0 - t))
        .unwrap_or(1.0)
        .clamp(0.0, 1.0);
    let illum = m.illumination_model.unwrap_or(2);

    let (color, kd, mut ka) = match kd_rgb {
        Some(kd) if mean(kd) > 0.0 => {
            let ka = ka_rgb.map_or(1.0, |ka| mean(ka) / mean(kd));
            (Vec3::from(kd), 1.0, ka)
        }
        // A black or missing Kd: the diffuse term is zero whatever the colour, which
        // can then carry Ka exactly.
        _ => (Vec3::from(ka_rgb.unwrap_or([0.0; 3])), 0.0, 1.0),
    };
    let mut ks = mean(ks_rgb);
    let mut kr = 0.0;
    match illum {
        0 => {
            ka = 0.0;
            ks = 0.0;
        }
        1 => ks = 0.0,
        3 | 5 | 7 => kr = mean(ks_rgb),
        _ => {}
    }
    let t = 1.0 - d;
    let ni = m.optical_density.filter(|n| range::IOR_RANGE.contains(n));
    let warning = (t > 0.0 && ni.is_none()).then(|| {
        let found = m
            .optical_density
            .map_or("no 'Ni'".to_string(), |n| format!("Ni {n}"));
        format!(
            "material '{}' is transparent (d = {d}) but has {found}: index of refraction 1 \
             used",
            m.name
        )
    });
    let material = Material {
        color,
        ka,
        kd,
        ks,
        shine: m
            .shininess
            .filter(|s| s.is_finite())
            .unwrap_or(1.0)
            .max(0.0),
        kr,
        t,
        ior: ni.unwrap_or(1.0),
        filter: Vec3::ONE,
        priority: 0,
        ..Material::DEFAULT
    };
    (material, warning)
}

// ---------------------------------------------------------------------------------
// From tobj's meshes to triangles

/// Material slot of faces that get [`DEFAULT_MATERIAL`] (appended on first use).
const DEFAULT_SLOT: u32 = u32::MAX;

struct Builder<'a> {
    path: &'a Path,
    warnings: &'a mut Vec<String>,
    /// Library material index by name (a later definition wins, as in tobj).
    by_name: HashMap<&'a str, u32>,
    geometry: Geometry,
    materials: Vec<Material>,
    textures: Vec<Texture>,
    environment: Option<Environment>,
    default_index: Option<u32>,
    bounds: Aabb,
    stats: LoadStats,
    first_degenerate: Option<usize>,
    zero_normals: usize,
    first_zero_normal: Option<usize>,
    // Scratch for polygons, reused from face to face.
    pts: Vec<Vec3>,
    nrm: Vec<Vec3>,
    tris: Vec<[usize; 3]>,
    uvs: Vec<Vec2>,
    triangulator: Triangulator,
}

impl<'a> Builder<'a> {
    fn new(path: &'a Path, mtl: &'a [tobj::Material], warnings: &'a mut Vec<String>) -> Self {
        let mut materials = Vec::with_capacity(mtl.len() + 1);
        let mut by_name = HashMap::new();
        for (i, m) in mtl.iter().enumerate() {
            let (mat, warning) = convert_material(m);
            if let Some(w) = warning {
                warnings.push(format!("{}: {w}", path.display()));
            }
            materials.push(mat);
            by_name.insert(m.name.as_str(), i as u32);
        }
        Builder {
            path,
            warnings,
            by_name,
            geometry: Geometry::default(),
            materials,
            textures: Vec::new(),
            environment: None,
            default_index: None,
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

    /// Load the texture maps of the materials (each image once) and set the materials'
    /// maps; a file that cannot be read is a warning and gets the documented default.
    fn load_maps(&mut self, maps: &[TexStmt]) {
        let mut cache: HashMap<(std::path::PathBuf, bool, bool), u32> = HashMap::new();
        let mut missing: Option<u32> = None;
        let mut cube: [Option<&TexStmt>; 6] = [None; 6];
        for m in maps {
            let Some(&i) = self.by_name.get(m.material.as_str()) else {
                continue;
            };
            if let Some(face) = m.cube {
                cube[face].get_or_insert(m);
                continue;
            }
            if m.kind == MapKind::Reflection {
                if self.environment.is_none() {
                    match Environment::load(&m.file) {
                        Ok(env) => self.environment = Some(env),
                        Err(e) => self.warnings.push(format!(
                            "{}: reflection map '{}' not used: {e}; the background stays",
                            m.at, m.name
                        )),
                    }
                }
                continue;
            }
            let srgb = matches!(m.kind, MapKind::Color | MapKind::Specular);
            let key = (m.file.clone(), srgb, m.clamp);
            let tex = match cache.get(&key) {
                Some(&t) => Some(t),
                None => match Image::load(&m.file, srgb) {
                    Ok(mut img) => {
                        if m.clamp {
                            img.wrap = Wrap::Clamp;
                        }
                        self.textures.push(Texture::Image(std::sync::Arc::new(img)));
                        let t = self.textures.len() as u32 - 1;
                        cache.insert(key, t);
                        Some(t)
                    }
                    Err(e) => {
                        let what = if m.kind == MapKind::Color {
                            "the colour becomes a magenta and black checkerboard"
                        } else {
                            "the map is left out"
                        };
                        self.warnings.push(format!(
                            "{}: texture '{}' of material {} not found or unreadable ({e}); \
                             {what}",
                            m.at,
                            m.name,
                            show(&m.material)
                        ));
                        (m.kind == MapKind::Color).then(|| {
                            *missing.get_or_insert_with(|| {
                                self.textures.push(MISSING_TEXTURE);
                                self.textures.len() as u32 - 1
                            })
                        })
                    }
                },
            };
            let Some(t) = tex else { continue };
            let maps = &mut self.materials[i as usize].maps;
            if m.scale != [1.0, 1.0] {
                maps.uv_scale = m.scale;
            }
            match m.kind {
                MapKind::Color => maps.color = t,
                MapKind::Specular => maps.specular = t,
                MapKind::Bump => {
                    maps.bump = t;
                    maps.bump_scale = m.bump_scale;
                }
                MapKind::Normal => maps.normal = t,
                MapKind::Reflection => {}
            }
        }
        self.load_cube(&cube);
    }

    /// The environment from the six `refl -type cube_*` faces, unless a single-image
    /// reflection map already gave one; a missing or unreadable face is a warning.
    fn load_cube(&mut self, cube: &[Option<&TexStmt>; 6]) {
        let Some(first) = cube.iter().flatten().next() else {
            return;
        };
        if self.environment.is_some() {
            return;
        }
        let missing: Vec<&str> = (0..6)
            .filter(|&k| cube[k].is_none())
            .map(|k| CUBE_TYPES[k])
            .collect();
        if !missing.is_empty() {
            self.warnings.push(format!(
                "{}: cube reflection map incomplete, missing {}; the background stays",
                first.at,
                missing.join(", ")
            ));
            return;
        }
        let files = cube.map(|m| m.map(|m| m.file.clone()).unwrap_or_default());
        match Environment::load_faces(&files) {
            Ok(env) => self.environment = Some(env),
            Err(e) => self.warnings.push(format!(
                "{}: cube reflection map not used: {e}; the background stays",
                first.at
            )),
        }
    }

    /// The material slot of each `usemtl`, warning once per name that no library
    /// defines.
    fn resolve_usemtl(&mut self, scan: &Scan, libs: &[String]) -> Vec<u32> {
        let mut missing: Vec<&str> = Vec::new();
        let mut slots = Vec::with_capacity(scan.usemtl.len());
        for u in &scan.usemtl {
            match self.by_name.get(u.name.as_str()) {
                Some(&i) => slots.push(i),
                None => {
                    slots.push(DEFAULT_SLOT);
                    if !missing.contains(&u.name.as_str()) {
                        missing.push(&u.name);
                        let where_ = if scan.mtllib_lines.is_empty() {
                            "the file names no material library ('mtllib')".to_string()
                        } else if libs.is_empty() {
                            "no material library could be read".to_string()
                        } else {
                            format!("it is not in {}", libs.join(", "))
                        };
                        self.warnings.push(format!(
                            "{}:{}: material {} not found ({where_}); its faces get the \
                             default grey material",
                            self.path.display(),
                            u.line,
                            show(&u.name)
                        ));
                    }
                }
            }
        }
        slots
    }

    fn material_index(&mut self, slot: u32) -> u32 {
        if slot != DEFAULT_SLOT {
            return slot;
        }
        *self.default_index.get_or_insert_with(|| {
            self.materials.push(DEFAULT_MATERIAL);
            self.materials.len() as u32 - 1
        })
    }

    // Kept out of line (called once) so that profiles show the conversion.
    #[inline(never)]
    fn build(
        &mut self,
        models: &[tobj::Model],
        scan: &Scan,
        slots: &[u32],
    ) -> Result<(), LoadError> {
        let total: usize = models.iter().map(|m| m.mesh.indices.len()).sum();
        self.geometry.triangles.items.reserve(total / 3);
        self.geometry.triangles.material.reserve(total / 3);
        self.geometry.triangle_normals.reserve(total / 3);
        let group_normals = smoothing_group_normals(models, scan);

        let mut face = 0usize;
        let mut run = 0usize; // next `usemtl` to take effect
        let mut slot = DEFAULT_SLOT;
        let mut srun = 0usize; // next `s` to take effect
        let mut group = 0u32;
        for model in models {
            let mesh = &model.mesh;
            let smooth_mesh = !mesh.normal_indices.is_empty();
            let textured_mesh = !mesh.texcoord_indices.is_empty();
            let pos = |i: u32| mesh_pos(mesh, i);
            let nrm = |i: u32| {
                let i = i as usize * 3;
                Vec3::new(mesh.normals[i], mesh.normals[i + 1], mesh.normals[i + 2])
            };
            let tex = |i: u32| {
                let i = i as usize * 2;
                Vec2::new(mesh.texcoords[i], mesh.texcoords[i + 1])
            };
            let mut off = 0usize;
            for f in 0..face_count(mesh) {
                let arity = mesh.face_arities.get(f).map_or(3, |&a| a as usize);
                let idx = &mesh.indices[off..off + arity];
                let nidx = smooth_mesh.then(|| &mesh.normal_indices[off..off + arity]);
                let tidx = textured_mesh.then(|| &mesh.texcoord_indices[off..off + arity]);
                off += arity;
                while run < scan.usemtl.len() && scan.usemtl[run].first_face <= face {
                    slot = slots[run];
                    run += 1;
                }
                while srun < scan.smoothing.len() && scan.smoothing[srun].0 <= face {
                    group = scan.smoothing[srun].1;
                    srun += 1;
                }
                let flags = scan.faces[face];
                let k = face;
                face += 1;
                if flags & FACE_IS_LINE != 0 {
                    continue;
                }
                self.stats.polygons += 1;
                let normals = nidx.filter(|_| flags & FACE_ALL_NORMALS != 0);
                let texcoords = tidx.filter(|_| flags & FACE_ALL_TEXCOORDS != 0);
                // Without `vn`, a smoothing group gives averaged normals.
                let grouped = |p: Vec3| {
                    group_normals
                        .get(&(p.to_array().map(f32::to_bits), group))
                        .and_then(|n| unit(*n))
                };
                if arity < 3 {
                    self.degenerate(k);
                    continue;
                }
                self.pts.clear();
                self.pts.extend(idx.iter().map(|&i| pos(i)));
                self.nrm.clear();
                let mut smooth = false;
                if let Some(ni) = normals {
                    self.nrm.extend(ni.iter().filter_map(|&i| unit(nrm(i))));
                    smooth = self.nrm.len() == arity;
                    if !smooth {
                        self.zero_normal(k);
                    }
                } else if group != 0 {
                    self.nrm.extend(self.pts.iter().filter_map(|&p| grouped(p)));
                    smooth = self.nrm.len() == arity;
                }
                self.uvs.clear();
                if let Some(ti) = texcoords {
                    self.uvs.extend(ti.iter().map(|&i| tex(i)));
                }
                if arity == 3 {
                    let p = [self.pts[0], self.pts[1], self.pts[2]];
                    let ng = (p[1] - p[0]).cross(p[2] - p[0]);
                    if ng.is_nan() || ng == Vec3::ZERO {
                        self.degenerate(k);
                        continue;
                    }
                    self.tris.clear();
                    self.tris.push([0, 1, 2]);
                } else if self
                    .triangulator
                    .triangulate(&self.pts, &mut self.tris)
                    .is_err()
                {
                    self.degenerate(k);
                    continue;
                }
                let m = self.material_index(slot);
                let first = self.geometry.triangles.len();
                for t in 0..self.tris.len() {
                    let [a, b, c] = self.tris[t];
                    let tri = Triangle {
                        p: [self.pts[a], self.pts[b], self.pts[c]],
                    };
                    let n = smooth.then(|| [self.nrm[a], self.nrm[b], self.nrm[c]]);
                    self.push(tri, n, m)?;
                    if !self.uvs.is_empty() {
                        let i = self.geometry.triangles.len() - 1;
                        self.geometry
                            .set_triangle_uvs(i, [self.uvs[a], self.uvs[b], self.uvs[c]]);
                    }
                }
                // A textured quad takes its (u, v) from the bilinear patch.
                if arity == 4 && self.uvs.len() == 4 && self.geometry.triangles.len() == first + 2 {
                    let p = [self.pts[0], self.pts[1], self.pts[2], self.pts[3]];
                    let uv = [self.uvs[0], self.uvs[1], self.uvs[2], self.uvs[3]];
                    if let Some(q) = QuadUv::new(p, uv) {
                        let k = self.geometry.add_quad(q);
                        self.geometry.set_triangle_quad(first, k);
                        self.geometry.set_triangle_quad(first + 1, k);
                    }
                }
            }
        }
        Ok(())
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

    fn degenerate(&mut self, face: usize) {
        self.stats.degenerate_dropped += 1;
        self.first_degenerate.get_or_insert(face);
    }

    fn zero_normal(&mut self, face: usize) {
        self.zero_normals += 1;
        self.first_zero_normal.get_or_insert(face);
    }
}

/// Position `i` of `mesh`.
#[inline]
fn mesh_pos(mesh: &tobj::Mesh, i: u32) -> Vec3 {
    let i = i as usize * 3;
    Vec3::new(
        mesh.positions[i],
        mesh.positions[i + 1],
        mesh.positions[i + 2],
    )
}

/// For faces without `vn` in a smoothing group: the sum of the area-weighted normals
/// of the group's faces around each position (keyed by the position's bits, so groups
/// join across `g`/`o` boundaries, and the group number).
fn smoothing_group_normals(models: &[tobj::Model], scan: &Scan) -> HashMap<([u32; 3], u32), Vec3> {
    let mut sums: HashMap<([u32; 3], u32), Vec3> = HashMap::new();
    if scan.smoothing.iter().all(|&(_, g)| g == 0) {
        return sums;
    }
    let mut face = 0usize;
    let mut srun = 0usize;
    let mut group = 0u32;
    for model in models {
        let mesh = &model.mesh;
        let mut off = 0usize;
        for f in 0..face_count(mesh) {
            let arity = mesh.face_arities.get(f).map_or(3, |&a| a as usize);
            let idx = &mesh.indices[off..off + arity];
            off += arity;
            while srun < scan.smoothing.len() && scan.smoothing[srun].0 <= face {
                group = scan.smoothing[srun].1;
                srun += 1;
            }
            let flags = scan.faces[face];
            face += 1;
            if group == 0 || flags & (FACE_IS_LINE | FACE_ALL_NORMALS) != 0 || arity < 3 {
                continue;
            }
            // Newell's normal: twice the vector area of the polygon.
            let mut n = Vec3::ZERO;
            for k in 0..arity {
                let (a, b) = (mesh_pos(mesh, idx[k]), mesh_pos(mesh, idx[(k + 1) % arity]));
                n += a.cross(b);
            }
            if !n.is_finite() {
                continue;
            }
            for &i in idx {
                let key = (mesh_pos(mesh, i).to_array().map(f32::to_bits), group);
                *sums.entry(key).or_insert(Vec3::ZERO) += n;
            }
        }
    }
    sums
}

/// `n` made unit length, or `None` when it is zero. Scaled first so that huge finite
/// components do not overflow.
fn unit(n: Vec3) -> Option<Vec3> {
    let m = n.abs().max_element();
    if m > 0.0 {
        (n / m).try_normalize()
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mtl(name: &str, f: impl FnOnce(&mut tobj::Material)) -> tobj::Material {
        let mut m = tobj::Material {
            name: name.into(),
            diffuse: Some([0.2, 0.4, 0.6]),
            specular: Some([0.3, 0.6, 0.9]),
            shininess: Some(20.0),
            ..Default::default()
        };
        f(&mut m);
        m
    }

    #[test]
    fn illumination_models() {
        // (illum, ka, ks, kr) with Kd = (0.2 0.4 0.6), Ks mean 0.6, no Ka.
        let ks = 0.6;
        let table: [(Option<u8>, f32, f32, f32); 12] = [
            (Some(0), 0.0, 0.0, 0.0),
            (Some(1), 1.0, 0.0, 0.0),
            (Some(2), 1.0, ks, 0.0),
            (Some(3), 1.0, ks, ks),
            (Some(4), 1.0, ks, 0.0),
            (Some(5), 1.0, ks, ks),
            (Some(6), 1.0, ks, 0.0),
            (Some(7), 1.0, ks, ks),
            (Some(8), 1.0, ks, 0.0),
            (Some(9), 1.0, ks, 0.0),
            (Some(10), 1.0, ks, 0.0),
            (None, 1.0, ks, 0.0),
        ];
        for (illum, ka, ks, kr) in table {
            let (m, w) = convert_material(&mtl("m", |m| m.illumination_model = illum));
            assert!(w.is_none());
            let got = (m.ka, m.ks, m.kr);
            assert!(
                (got.0 - ka).abs() < 1e-6 && (got.1 - ks).abs() < 1e-6 && (got.2 - kr).abs() < 1e-6,
                "illum {illum:?}: {got:?}"
            );
            assert_eq!(
                (m.color, m.kd, m.shine),
                (Vec3::new(0.2, 0.4, 0.6), 1.0, 20.0)
            );
            assert_eq!(
                (m.t, m.ior),
                (0.0, 1.0),
                "illum {illum:?}: opaque without d"
            );
        }
    }

    #[test]
    fn ambient_transparency_and_defaults() {
        // Ka relative to Kd.
        let (m, _) = convert_material(&mtl("m", |m| m.ambient = Some([0.1, 0.2, 0.3])));
        assert!((m.ka - 0.5).abs() < 1e-6, "{}", m.ka);
        // No Kd: the colour carries Ka, no diffuse term.
        let (m, _) = convert_material(&mtl("m", |m| {
            m.diffuse = None;
            m.ambient = Some([0.1, 0.2, 0.3]);
        }));
        assert_eq!((m.color, m.kd, m.ka), (Vec3::new(0.1, 0.2, 0.3), 0.0, 1.0));
        // Nothing at all: black, Ns 1.
        let (m, _) = convert_material(&tobj::Material::default());
        assert_eq!((m.color, m.kd, m.ks, m.shine), (Vec3::ZERO, 0.0, 0.0, 1.0));
        // d wins over Tr, transmittance for any illum; negative colours clamped.
        let (m, w) = convert_material(&mtl("glass", |m| {
            m.dissolve = Some(0.3);
            m.unknown_param.insert("Tr".into(), "0.9".into());
            m.optical_density = Some(1.33);
            m.illumination_model = Some(2);
            m.diffuse = Some([-1.0, 0.5, 0.5]);
        }));
        assert!(w.is_none());
        assert!((m.t - 0.7).abs() < 1e-6 && m.ior == 1.33 && m.kr == 0.0);
        assert_eq!(m.color, Vec3::new(0.0, 0.5, 0.5));
        let (m, w) = convert_material(&mtl("tr", |m| {
            m.unknown_param.insert("Tr".into(), "0.25".into());
        }));
        assert_eq!((m.t, m.ior), (0.25, 1.0));
        assert!(w.unwrap().contains("no 'Ni'"));
        // An opaque material's unusable Ni is no concern.
        let (m, w) = convert_material(&mtl("m", |m| m.optical_density = Some(0.0)));
        assert!(w.is_none() && m.ior == 1.0);
    }

    #[test]
    fn mtl_statements_tobj_would_reject_or_panic_on_are_removed() {
        let src = "\
newmtl a
Kd 0.5
Ka
Ks 1 1
Ke spectral x.rfl
Ns
d -halo 0.5
illum two
map_Kd tex.png
bump b.png
newmtl
Kd 1 0 0
newmtl b
Kd 0 1 0
Ni 1.5
";
        let mut warnings = Vec::new();
        let mut maps = Vec::new();
        let out = sanitize_mtl(src, Path::new("x.mtl"), &mut warnings, &mut maps);
        let (mats, names) = tobj::load_mtl_buf(&mut Cursor::new(out.as_bytes())).unwrap();
        assert_eq!(mats.len(), 2);
        assert_eq!(mats[names["a"]].diffuse, Some([0.5; 3]));
        assert_eq!(mats[names["a"]].ambient, None);
        assert_eq!(mats[names["a"]].specular, None);
        assert_eq!(mats[names["a"]].dissolve, None);
        // The nameless material's Kd did not leak into `a`.
        assert_eq!(mats[names["b"]].diffuse, Some([0.0, 1.0, 0.0]));
        assert_eq!(mats[names["b"]].optical_density, Some(1.5));
        let lines: Vec<&str> = warnings
            .iter()
            .filter_map(|w| w.strip_prefix("x.mtl:"))
            .filter(|w| w.starts_with(|c: char| c.is_ascii_digit()))
            .collect();
        let at: Vec<&str> = lines.iter().map(|w| &w[..w.find(':').unwrap()]).collect();
        assert_eq!(at, ["3", "4", "5", "6", "7", "8", "11"], "{warnings:?}");
        // The texture statements are taken out for emray's own loader, with their
        // material.
        let kinds: Vec<(MapKind, &str, &str)> = maps
            .iter()
            .map(|m| (m.kind, m.material.as_str(), m.name.as_str()))
            .collect();
        assert_eq!(
            kinds,
            [
                (MapKind::Color, "a", "tex.png"),
                (MapKind::Bump, "a", "b.png")
            ]
        );
        assert_eq!(maps[1].at, "x.mtl:10");
        assert!(lines[1].starts_with("4:7:"), "{}", lines[1]); // `Ks 1 1`: at its end
        assert!(lines[3].starts_with("6:3:"), "{}", lines[3]);
    }

    #[test]
    fn scan_records_faces_materials_and_libraries() {
        let src = "\
mtllib a.mtl
v 0 0 0
v 1 0 0
v 0 1 0
vt 0 0
vn 0 0 1
f 1 2 3
usemtl m1
f 1//1 2//1 3//1
f 1/1/1 2/1/1 3/1
l 1 2
mtllib b.mtl
usemtl m 2
f -3/-1/-1 -2/1/1 -1//1
";
        let s = scan(src).unwrap();
        assert_eq!(
            s.faces,
            [
                0,
                FACE_ALL_NORMALS,
                FACE_ALL_TEXCOORDS,
                FACE_IS_LINE,
                FACE_ALL_NORMALS
            ]
        );
        assert_eq!(s.lines, 1);
        assert_eq!(s.mtllib_lines, [1, 12]);
        let u: Vec<(usize, &str, usize)> = s
            .usemtl
            .iter()
            .map(|u| (u.first_face, u.name.as_str(), u.line))
            .collect();
        assert_eq!(u, [(1, "m1", 8), (4, "m 2", 13)]);
        assert!(s.colour_mismatch.is_none());
    }

    #[test]
    fn scan_errors() {
        let err = |src: &str| scan(src).unwrap_err();
        // Texture and normal indices are checked too (tobj overflows on index 0).
        let e = err("v 0 0 0\nvt 0 0\nf 1/0 1/1 1/1\n");
        assert_eq!((e.line, e.col), (3, 3));
        assert!(
            e.message.contains("texture coordinate index 0"),
            "{}",
            e.message
        );
        let e = err("v 0 0 0\nvn 0 0 1\nf 1//1 1//-2 1//1\n");
        assert_eq!((e.line, e.col), (3, 8));
        assert!(
            e.message.contains("relative normal index -2"),
            "{}",
            e.message
        );
        let e = err("v 0 0 0\nf /1 1 1\n");
        assert!(e.message.contains("missing vertex index"), "{}", e.message);
        let e = err("v 0 0 0\nf 1 1 99999999999999999999999\n");
        assert!(
            e.message.contains("expected a vertex index"),
            "{}",
            e.message
        );
        // The earliest of several forward references beyond the end.
        let e = err("f 1/1 1/1 1/1\nf 7 1 1\nf 1 1 1/9\nv 0 0 0\nvt 0 0\n");
        assert_eq!((e.line, e.col), (2, 3));
        // Columns count characters.
        let e = err("g é\nv 0 0 0\nf 1 1 é\n");
        assert_eq!((e.line, e.col), (3, 7));
        // Mixed vertex colours are noted (an error only when tobj refuses them).
        let s = scan("v 0 0 0 1 0 0\nv 1 0 0\n").unwrap();
        let m = s.colour_mismatch.unwrap();
        assert_eq!((m.line, m.col), (2, 1));
    }

    #[test]
    fn bad_numbers() {
        let find = |src: &str| find_bad_number(src, usize::MAX).unwrap();
        let e = find("v 1e8 0 0 1e-31\n");
        assert!(e.message.contains("divided by the weight"), "{}", e.message);
        let e = find("v 1 2 3 w\n");
        assert_eq!((e.line, e.col), (1, 9));
        // vt only needs numbers; the limit stops the search.
        assert!(find_bad_number("vt inf 0\n", usize::MAX).is_none());
        assert!(find_bad_number("v 0 0 0\nv x 0 0\n", 2).is_none());
        // Colours are not looked at (tobj ignores bad ones).
        assert!(find_bad_number("v 0 0 0 red green blue\n", usize::MAX).is_none());
    }

    #[test]
    fn face_lines() {
        let src = "v 0 0 0\nf 1 1 1\n# c\n  l 1 1\nf 1 1 1\n";
        assert_eq!([0, 1, 2, 3].map(|k| face_line(src, k)), [2, 4, 5, 0]);
    }
}
