//! The NFF loader (Eric Haines' Neutral File Format, SPD 3.14; the conventions are in
//! docs/nff.md and docs/architecture.md).
//!
//! The file is read as a stream of whitespace-separated tokens, each remembering its
//! line and column, so an entity's numbers may be spread over lines as the writer
//! pleases; `#` starts a comment that runs to the end of the line. Tokens are slices of
//! the source: nothing is allocated per token.
//!
//! A large file is cut into stretches at lines that start an entity (`split`), the
//! stretches are parsed in parallel (`parser`, into a `part::Part` each), and the parts
//! are joined in file order (`merge`), each batch while the next is parsed
//! (`stretches`): the scene, the warnings and the first error are those of reading the
//! file from start to end, whatever the cut.
//!
//! Entities: `v` (viewpoint: `from`, `at`, `up`, `angle`, `hither`, `resolution` in
//! that order), `b` (background), `l x y z [r g b]` (point light), `f` (material),
//! `c` (open cone/cylinder), `s` (sphere), `p` (polygon), `pp` (polygon with vertex
//! normals). Points (`from`, `at`, light positions, sphere centres, cone ends, polygon
//! vertices) are read in double precision and moved into the scene's frame, whose
//! origin is the eye (see [`Scene::origin`]), before they become single precision.
//! Everything is validated here, so the renderer can trust the scene: every
//! number is finite, sizes are positive where they must be, the resolution is sane, and
//! degenerate polygons are dropped with one warning per file and counted in
//! [`LoadStats::degenerate_dropped`](crate::scene::LoadStats).

mod lexer;
mod merge;
mod number;
mod parser;
mod part;
mod split;
mod stretches;

use super::{LoadError, LoadProgress, text};
use crate::math::DVec3;
use crate::scene::Scene;
use lexer::Lexer;
pub(crate) use merge::Merger;
pub(crate) use parser::{fill, unit_normal, up_is_usable, world_bounds};
pub(crate) use part::{Note, Part};
use std::path::Path;
use stretches::parse_in_stretches;

/// Where the loader's warnings come from (the same wherever in the loader they are
/// logged).
const LOG_TARGET: &str = module_path!();

/// The size of the stretches a large file is cut into to be parsed in parallel.
const STRETCH: usize = 4 << 20;

/// Largest accepted image side.
pub const MAX_RESOLUTION_SIDE: u64 = 65_536;
/// Largest accepted pixel count (2²⁸).
pub const MAX_PIXELS: u64 = 1 << 28;

/// Read and parse the NFF file at `path`; a scene without objects is a warning.
///
/// # Errors
/// `path: cannot read: …` when the file cannot be read, `path: …` when it is not text
/// (gzip-compressed, UTF-16), otherwise whatever [`parse_str`] reports. A leading
/// UTF-8 byte-order mark is skipped, and bytes that are not UTF-8 (in comments, say)
/// are replaced, which leaves line and column numbers intact (see `super::text`).
pub fn load(path: &Path) -> Result<Scene, LoadError> {
    load_with(path, &LoadProgress::silent())
}

/// [`load`], telling `progress` how many of the file's bytes are parsed.
///
/// # Errors
/// As [`load`].
pub fn load_with(path: &Path, progress: &LoadProgress<'_>) -> Result<Scene, LoadError> {
    let src = text::read_lossy(path)?;
    progress.expect(src.len() as u64);
    let origin = eye_of(&src).unwrap_or(DVec3::ZERO);
    let scene = parse_in_stretches(&src, path, origin, STRETCH, progress)?;
    super::warn_if_empty(&scene, path);
    Ok(scene)
}

/// Parse NFF text; `path` only labels the errors.
///
/// # Errors
/// The first problem found, as `path:line:col: message` with the position of the
/// offending token (1-based; a column counts characters), or `path: no viewpoint ('v')
/// in file` when there is no `v`.
pub fn parse_str(src: &str, path: &Path) -> Result<Scene, LoadError> {
    parse_str_at(src, path, eye_of(src).unwrap_or(DVec3::ZERO))
}

/// [`parse_str`] in the frame whose origin is the world point `origin`: every point of
/// the file, `p`, becomes `p − origin` (computed in double precision) in the scene.
///
/// # Errors
/// As [`parse_str`].
pub fn parse_str_at(src: &str, path: &Path, origin: DVec3) -> Result<Scene, LoadError> {
    parse_in_stretches(src, path, origin, STRETCH, &LoadProgress::silent())
}

/// [`parse_str`], with the text cut into stretches of about `stretch` bytes that are
/// parsed in parallel. The scene, the warnings and the error are the same whatever
/// the size; a small one makes many stretches of a small file (to test that).
///
/// # Errors
/// As [`parse_str`].
pub fn parse_str_in_stretches(src: &str, path: &Path, stretch: usize) -> Result<Scene, LoadError> {
    let origin = eye_of(src).unwrap_or(DVec3::ZERO);
    parse_in_stretches(src, path, origin, stretch, &LoadProgress::silent())
}

/// The eye (`from`) of the file's first viewpoint, found by a quick scan of the tokens
/// (`None` when there is none or it does not read: the parse then says why).
fn eye_of(src: &str) -> Option<DVec3> {
    let mut lex = Lexer::new(src);
    while lex.next()?.text != "v" {}
    if lex.next()?.text != "from" {
        return None;
    }
    let mut xyz = [0.0; 3];
    for c in &mut xyz {
        *c = lex
            .next()?
            .text
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())?;
    }
    Some(DVec3::from(xyz))
}

/// Whether a token is meant as a number (as opposed to an entity keyword): it parses,
/// or starts like one. `nan` and `inf` count, so that they are reported as non-finite.
fn looks_numeric(t: &str) -> bool {
    matches!(t.as_bytes().first(), Some(b'0'..=b'9' | b'+' | b'-' | b'.'))
        || t.parse::<f32>().is_ok()
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Kind;

    #[test]
    fn numeric_detection() {
        for s in [
            "1", "-2", "+3", ".5", "1e3", "nan", "NaN", "inf", "-inf", "infinity",
        ] {
            assert!(looks_numeric(s), "{s}");
        }
        for s in ["v", "b", "l", "f", "c", "s", "p", "pp", "from", "abc"] {
            assert!(!looks_numeric(s), "{s}");
        }
    }

    #[test]
    fn long_tokens_are_shortened_in_messages() {
        let long = "x".repeat(1000);
        let s = show(&long);
        assert!(s.len() < 60, "{s}");
        assert_eq!(show("abc"), "'abc'");
    }

    /// Each primitive, material and light knows the line of its entity; a polygon's
    /// triangles share their `p`'s line; the scene's `Debug` form (the render hash of
    /// `emray merge`) does not depend on the file's name.
    #[test]
    fn primitives_materials_and_lights_know_their_line() {
        let src = "v from 0 0 5 at 0 0 0 up 0 1 0 angle 40 hither 1 resolution 8 8\n\
                   l 1 1 1\n\
                   f 1 0 0 1 0 0 0 0\n\
                   s 0 0 0 1\n\
                   # a quad: two triangles\n\
                   p 4 0 0 0 1 0 0 1 1 0 0 1 0\n\
                   c 0 0 0 1 0 1 0 1\n";
        let scene = parse_str(src, Path::new("dir/a.nff")).unwrap();
        let g = &scene.geometry;
        let at = |o: Option<crate::scene::Origin>| o.unwrap().to_string();
        assert_eq!(at(g.sources.get(Kind::Sphere, 0)), "dir/a.nff:4");
        assert_eq!(g.count(Kind::Triangle), 2);
        assert_eq!(at(g.sources.get(Kind::Triangle, 0)), "dir/a.nff:6");
        assert_eq!(at(g.sources.get(Kind::Triangle, 1)), "dir/a.nff:6");
        assert_eq!(at(g.sources.get(Kind::Cone, 0)), "dir/a.nff:7");
        assert_eq!(at(scene.sources.materials.get(0)), "dir/a.nff:3");
        assert_eq!(at(scene.sources.lights.get(0)), "dir/a.nff:2");
        let elsewhere = parse_str(src, Path::new("b.nff")).unwrap();
        assert_eq!(format!("{scene:?}"), format!("{elsewhere:?}"));
    }

    #[test]
    fn eof_position_is_after_the_last_token() {
        let e = parse_str("v\nfrom 1 2", Path::new("t.nff")).unwrap_err();
        assert_eq!((e.line, e.col), (2, 9));
        assert_eq!(
            e.message,
            "unexpected end of file while reading the viewpoint 'from' z"
        );
    }
}
