//! The Wavefront OBJ loader, with its MTL material libraries.
//!
//! [`load_geometry`] reads a model into triangles and materials for a scene file to
//! place; [`load`] wraps one into a whole [`Scene`] with an automatic camera and light,
//! so that `emray render model.obj` shows it.
//!
//! # Geometry
//!
//! The text is parsed once, by emray's own parser, which checks every statement as it
//! reads it; the faces are then triangulated and the materials mapped. A file larger
//! than 4 MB is cut into stretches of about 4 MB at line starts, parsed in parallel
//! on the current thread pool (when it has more than one thread) and joined in file
//! order (`stretches`, `join`); a first pass counts each stretch's elements and faces,
//! so that the stretches parse into their places in the file's lists (`sized`,
//! `sink`). The faces are then converted to triangles in chunks, in parallel, joined
//! in face order (`convert`, `converted`, `triangle_lists`). The model, the warnings
//! and the error are those of reading the file from start to end, whatever the cut,
//! as `tests/obj_stretches.rs` and `tests/obj_chunks.rs` check.
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
//! A file that cannot be read is an error naming it, and so is a gzip-compressed file or
//! UTF-16 text; a UTF-8 byte-order mark at the start is skipped. A malformed file is an error
//! `path:line:col: message` at the first problem found: a coordinate that is not a
//! number, too few or too many numbers in a `v`, `vt` or `vn`, a non-finite coordinate
//! or normal that a face uses (`nan`, `inf`, or a number too large for `f32`; unused
//! elements are not looked at once they parse as numbers), a vertex weight `w` of 0,
//! a face index that is 0, not an integer, or beyond the elements the file defines
//! (relative, negative indices count back from the last element defined before the
//! face), a vertex with more than three indices, a face without vertices, or a
//! `usemtl` without a name. Comments must be on a line of their own (a trailing `#`
//! is read as part of the statement).
//!
//! Faces are also checked in runs, as they end: a run ends at a `g` or `o` after some
//! faces, at a `usemtl` after some faces that changes the material (as the libraries
//! named before it define the name), and at the end of the file. A face may name an
//! element defined after it, but before its run ends; a vertex colour (`v x y z r g b`)
//! must exist for every vertex a face names once the file has given one. Such a problem
//! is an error for the whole file (`malformed OBJ file (face vertex index out of
//! bounds)`, ...) unless the file has a bad number, reported instead, or a vertex whose
//! colour is present where the first vertex's is not (or the other way round), reported
//! for a missing colour. A face's `vt` (`vn`) indices are used, and checked, only when
//! the file has defined texture coordinates (normals) by the end of its run.
//!
//! # Materials
//!
//! Material libraries (`mtllib`) are read relative to the OBJ file's directory; several
//! may be given, on one line or many (`mtllib a.mtl b.mtl` names one file when a file
//! of that whole name exists, else one per word). The name of an `mtllib` or `usemtl`
//! is the rest of the line after its first space, trimmed. Materials are matched to
//! `usemtl` by name after every library has been read (a later definition of a name
//! wins). Problems with materials never stop the load; each becomes a warning naming
//! the file, and the faces concerned get [`DEFAULT_MATERIAL`], a mid-grey diffuse:
//!
//! - a library that cannot be read, or is gzip-compressed or UTF-16 text (its faces'
//!   materials are then missing);
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
//!   the range is `range::IOR_RANGE`); a transmissive material with such an `Ni` gets
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
//!   15° above the centre, with up = +y, a 40° field of view (`Camera::angle_deg`),
//!   hither 0 and 512 × 512 pixels. `d = 1.05 · r / sin 20°`: the sphere fits inside
//!   the 40° cone of view with 5 % to spare.
//! - One white point light, intensity (1, 1, 1), no attenuation, at
//!   `eye + 0.25 · d · (up′ − right)`, where `right` and `up′` are the camera's unit
//!   right and up vectors: above and to the left of the eye.
//! - Ambient light 0.1 (white), black background.
//!
//! A model without a single non-degenerate face has nothing to frame: [`load`] reports
//! an error.

mod append;
mod build;
mod colours;
mod convert;
mod converted;
mod framing;
mod in_force;
mod join;
mod libs;
mod located;
mod material;
mod mtl;
mod numbers;
mod parse;
mod runs;
mod sink;
mod sized;
mod smoothing;
mod stretches;
mod texmap;
mod textures;
mod triangle_lists;

pub use framing::{
    AUTO_AMBIENT, AUTO_ELEVATION_DEG, AUTO_FOV_DEG, AUTO_LIGHT_OFFSET, AUTO_MARGIN,
    AUTO_RESOLUTION, frame,
};

use super::{LoadError, LoadProgress, text};
use crate::math::{Aabb, DVec3, Vec3};
use crate::scene::{Environment, Geometry, LoadStats, Material, Scene, Texture};
use build::Model;
use converted::Converted;
use located::whole_file;
use material::{DEFAULT_SLOT, Materials};
use std::path::Path;
use std::time::{Duration, Instant};

/// The size of the stretches a large file is cut into to be parsed in parallel.
const STRETCH: usize = 4 << 20;

/// The faces in a chunk of faces converted to triangles in parallel.
const FACE_CHUNK: usize = 1 << 14;

/// How a load is cut to run on the threads of a pool.
#[derive(Clone, Copy, Debug)]
struct Cuts {
    /// The size of the stretches of text parsed in parallel.
    stretch: usize,
    /// The faces of a chunk converted to triangles in parallel.
    faces: usize,
}

impl Cuts {
    /// The cuts on the current thread pool: [`STRETCH`] and [`FACE_CHUNK`], or none
    /// when there is one thread (stretches and chunks would only add work: the count of
    /// the stretches, and the copies that join them).
    fn for_pool() -> Self {
        if rayon::current_num_threads() > 1 {
            Cuts {
                stretch: STRETCH,
                faces: FACE_CHUNK,
            }
        } else {
            Cuts {
                stretch: usize::MAX,
                faces: usize::MAX,
            }
        }
    }
}

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
    /// The world point the triangles' coordinates are relative to (see [`Origin`]).
    pub origin: DVec3,
}

/// Where the frame of a model's triangles lies: their coordinates are the world's
/// minus this origin, computed in double precision from the file's numbers.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Origin {
    /// This world point (the world's own origin for a model placed by a transform).
    At(DVec3),
    /// The centre of the model's bounds: a model rendered alone.
    Centre,
}

/// Read the OBJ file at `path` (and its material libraries) into a scene: the model,
/// an automatic camera and a light (see the module documentation). Warnings are logged.
///
/// # Errors
/// Whatever [`load_geometry`] reports, or `path: …` when the model has no
/// non-degenerate face to frame.
pub fn load(path: &Path) -> Result<Scene, LoadError> {
    load_with(path, &LoadProgress::silent())
}

/// [`load`], telling `progress` how many of the file's bytes are parsed.
///
/// # Errors
/// As [`load`].
pub fn load_with(path: &Path, progress: &LoadProgress<'_>) -> Result<Scene, LoadError> {
    let data = read_geometry(path, Origin::Centre, Cuts::for_pool(), progress)?;
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
    scene.origin = data.origin;
    Ok(scene)
}

/// Read the OBJ file at `path` and the material libraries it names.
///
/// # Errors
/// `path: cannot read: …` when the file cannot be read, `path: …` when it is not text
/// (gzip-compressed, UTF-16), `path:line:col: …` at the first malformed statement (see
/// the module documentation). A leading UTF-8 byte-order mark is skipped, and bytes
/// that are not UTF-8 are replaced, which leaves line numbers intact (see
/// `super::text`). Problems with material libraries are warnings, not errors.
pub fn load_geometry(path: &Path) -> Result<ObjData, LoadError> {
    load_geometry_at(path, Origin::At(DVec3::ZERO))
}

/// [`load_geometry`] with the triangles in the frame of `origin`.
///
/// # Errors
/// As [`load_geometry`].
pub fn load_geometry_at(path: &Path, origin: Origin) -> Result<ObjData, LoadError> {
    read_geometry(path, origin, Cuts::for_pool(), &LoadProgress::silent())
}

/// [`load_geometry`], with the text cut into stretches of about `stretch` bytes that
/// are parsed in parallel. The model, the warnings and the error are the same whatever
/// the size; a small one makes many stretches of a small file (to test that).
///
/// # Errors
/// As [`load_geometry`].
pub fn load_geometry_in_stretches(path: &Path, stretch: usize) -> Result<ObjData, LoadError> {
    let cuts = Cuts {
        stretch,
        ..Cuts::for_pool()
    };
    read_geometry(path, Origin::At(DVec3::ZERO), cuts, &LoadProgress::silent())
}

/// [`load_geometry_in_stretches`], with the faces converted to triangles in parallel
/// in chunks of `faces` faces (at least one). The model, the warnings and the error
/// are the same whatever the sizes.
///
/// # Errors
/// As [`load_geometry`].
pub fn load_geometry_in_chunks(
    path: &Path,
    stretch: usize,
    faces: usize,
) -> Result<ObjData, LoadError> {
    let cuts = Cuts { stretch, faces };
    read_geometry(path, Origin::At(DVec3::ZERO), cuts, &LoadProgress::silent())
}

/// [`load_geometry_at`] cut as `cuts` says, telling `progress` how many of the file's
/// bytes are parsed.
fn read_geometry(
    path: &Path,
    origin: Origin,
    cuts: Cuts,
    progress: &LoadProgress<'_>,
) -> Result<ObjData, LoadError> {
    let t0 = Instant::now();
    let text = text::read_lossy(path)?;
    progress.expect(text.len() as u64);
    let t_read = t0.elapsed();
    let mut obj = stretches::parse(&text, cuts.stretch, progress).map_err(|e| e.at(path))?;
    let t_parse = t0.elapsed();

    let libs = libs::read(path, &obj.mtllibs);
    let t_libs = t0.elapsed();
    runs::check(&mut obj, &libs.names_read_at(), cuts.faces).map_err(|e| e.at(path))?;
    let origin = match origin {
        Origin::At(p) => p,
        Origin::Centre => obj.centre(),
    };
    obj.recentre(origin);
    let t_checks = t0.elapsed();
    let mut warnings = libs.warnings;
    let mut materials = Materials::new(path, &libs.materials, &mut warnings);
    materials.load_maps(&libs.maps, &mut warnings);
    let names_libraries = !obj.mtllibs.is_empty();
    let slots = materials.slots(
        &obj.usemtl,
        names_libraries,
        &libs.read,
        path,
        &mut warnings,
    );
    let t_materials = t0.elapsed();

    let model = Model::new(path, &obj, &slots, materials.default_index());
    let b = convert::convert(&model, cuts.faces);
    if let Some(stop) = b.stop {
        return Err(stop.error(path));
    }
    if b.default_used {
        materials.index(DEFAULT_SLOT);
    }
    let t_build = t0.elapsed();
    let ms = |a: Duration, b: Duration| b.saturating_sub(a).as_secs_f64() * 1e3;
    log::info!(
        "{}: read {:.0} ms, parse {:.0} ms, index checks {:.0} ms, materials {:.0} ms, \
         conversion {:.0} ms",
        path.display(),
        ms(Duration::ZERO, t_read),
        ms(t_read, t_parse),
        ms(t_libs, t_checks),
        ms(t_parse, t_libs) + ms(t_checks, t_materials),
        ms(t_materials, t_build)
    );
    warnings.extend(summary_warnings(path, &b, obj.lines));
    Ok(ObjData {
        geometry: b.geometry,
        materials: materials.list,
        textures: materials.textures,
        environment: materials.environment,
        bounds: b.bounds,
        warnings,
        stats: b.stats,
        origin,
    })
}

/// The warnings that sum up the faces: degenerate ones dropped, zero-length normals,
/// lines ignored.
fn summary_warnings(path: &Path, b: &Converted, lines: usize) -> Vec<String> {
    let mut warnings = Vec::new();
    if let Some(line) = b.first_degenerate {
        warnings.push(format!(
            "{}: dropped {} degenerate face(s) (fewer than 3 distinct vertices or zero \
             area), the first at line {line}",
            path.display(),
            b.stats.degenerate_dropped,
        ));
    }
    if let Some(line) = b.first_zero_normal {
        warnings.push(format!(
            "{}: {} face(s) with a zero-length vertex normal shaded flat, the first at line \
             {line}",
            path.display(),
            b.zero_normals,
        ));
    }
    if lines > 0 {
        warnings.push(format!(
            "{}: ignored {lines} line element(s) ('l'): only faces are rendered",
            path.display(),
        ));
    }
    warnings
}
