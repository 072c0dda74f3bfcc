//! The TOML scene format: camera, render settings, named materials, lights, reusable
//! definitions and a tree of objects (analytic primitives, triangles, polygons, meshes,
//! included NFF files, groups, instances and CSG), each with a material and a list of
//! transforms. The reference is `docs/scene-format.md`.
//!
//! Reading happens in two steps: TOML text into the [`format`](mod@format) structures (serde, with
//! the span of every value kept), then those into a [`Scene`] (the `build` module),
//! which resolves names, applies defaults and transforms, and checks everything the
//! types cannot. Errors of both steps carry the file, line and column of the offending
//! key or table; errors in an included file carry that file's position and say where it
//! was included from.

pub mod format;

mod build;

use super::LoadError;
use crate::scene::Scene;
use format::SceneFile;
use std::ops::Range;
use std::path::Path;

/// Largest accepted image side in pixels.
pub const MAX_SIDE: u32 = 16_384;

/// The `[render]` settings meant for the renderer (`max_depth`, `spp`), the same values
/// the scene carries in [`Scene::render`]; `background` and `ambient` are part of the
/// scene itself. The command line overrides them.
pub type SceneSettings = crate::scene::RenderHints;

/// Read and build the scene file at `path`; a scene without objects is a warning.
///
/// # Errors
/// `path: cannot read: …` when the file cannot be read, else whatever [`parse_str`]
/// reports.
pub fn load(path: &Path) -> Result<Scene, LoadError> {
    load_with_settings(path).map(|(scene, _)| scene)
}

/// [`load`], also returning the `[render]` settings meant for the renderer (a copy of
/// the scene's [`Scene::render`]).
///
/// # Errors
/// As [`load`].
pub fn load_with_settings(path: &Path) -> Result<(Scene, SceneSettings), LoadError> {
    let text = read_text(path)?;
    let (scene, settings) = parse_str_with_settings(&text, path)?;
    super::warn_if_empty(&scene, path);
    Ok((scene, settings))
}

/// Build a scene from TOML text. `path` labels the errors, and included files are found
/// relative to its directory.
///
/// # Errors
/// The first problem found, as `path:line:col: message`.
pub fn parse_str(src: &str, path: &Path) -> Result<Scene, LoadError> {
    parse_str_with_settings(src, path).map(|(scene, _)| scene)
}

/// [`parse_str`], also returning the `[render]` settings meant for the renderer.
///
/// # Errors
/// As [`parse_str`].
pub fn parse_str_with_settings(
    src: &str,
    path: &Path,
) -> Result<(Scene, SceneSettings), LoadError> {
    let source = Source::new(path, src);
    let file = parse_file_in(&source)?;
    build::build(&file, &source, None)
}

/// [`parse_str`] in the frame whose origin is the world point `origin` rather than the
/// camera's eye (see [`Scene::origin`]): with [`glam::DVec3::ZERO`], the scene holds the
/// file's own coordinates (rounded to single precision), which is what tests of the
/// format compare with.
///
/// # Errors
/// As [`parse_str`].
pub fn parse_str_at(src: &str, path: &Path, origin: glam::DVec3) -> Result<Scene, LoadError> {
    let source = Source::new(path, src);
    let file = parse_file_in(&source)?;
    build::build(&file, &source, Some(origin)).map(|(scene, _)| scene)
}

/// Read TOML text into the format structures only (no names resolved, nothing built):
/// what a tool that rewrites scene files works on.
///
/// # Errors
/// TOML syntax errors, unknown keys, wrong types and missing required keys, with their
/// position.
pub fn parse_file(src: &str, path: &Path) -> Result<SceneFile, LoadError> {
    parse_file_in(&Source::new(path, src))
}

fn parse_file_in(source: &Source) -> Result<SceneFile, LoadError> {
    ::toml::from_str::<SceneFile>(source.text).map_err(|e| {
        let span = e.span().unwrap_or(0..0);
        source.err(span, serde_message(e.message()))
    })
}

/// The file's bytes as text (see [`super::text`]; invalid UTF-8 is an error: TOML
/// requires UTF-8).
pub(crate) fn read_text(path: &Path) -> Result<String, LoadError> {
    let bytes = super::text::read_body(path)?;
    String::from_utf8(bytes).map_err(|e| {
        let off = e.utf8_error().valid_up_to();
        let src = String::from_utf8_lossy(e.as_bytes()).into_owned();
        Source::new(path, &src).err(off..off, "the file is not valid UTF-8 (TOML must be)")
    })
}

/// A source file: its path, its text and where its lines start.
pub(crate) struct Source<'a> {
    path: &'a Path,
    text: &'a str,
    line_starts: Vec<usize>,
}

impl<'a> Source<'a> {
    pub(crate) fn new(path: &'a Path, text: &'a str) -> Self {
        let mut line_starts = vec![0];
        line_starts.extend(text.match_indices('\n').map(|(i, _)| i + 1));
        Source {
            path,
            text,
            line_starts,
        }
    }

    /// 1-based line and column (in characters) of byte `offset`.
    fn position(&self, offset: usize) -> (usize, usize) {
        let offset = offset.min(self.text.len());
        let line = self.line_starts.partition_point(|&s| s <= offset);
        let start = self.line_starts[line - 1];
        let col = self
            .text
            .get(start..offset)
            .map_or(offset - start, |s| s.chars().count())
            + 1;
        (line, col)
    }

    /// An error at the start of `span`.
    pub(crate) fn err(&self, span: Range<usize>, message: impl Into<String>) -> LoadError {
        let (line, col) = self.position(span.start);
        LoadError {
            path: self.path.to_path_buf(),
            line,
            col,
            message: message.into(),
        }
    }
}

/// A serde/TOML message made to read like the rest: "key" rather than "field", with a
/// suggestion for a misspelt key, and on one line.
pub(crate) fn serde_message(msg: &str) -> String {
    let msg = msg.trim().replace('\n', "; ");
    if let Some(rest) = msg.strip_prefix("unknown field ") {
        let names: Vec<&str> = rest.split('`').skip(1).step_by(2).collect();
        if let Some((&unknown, expected)) = names.split_first() {
            let is_object = expected.len() > 12;
            let mut out = format!("unknown key `{unknown}`");
            if let Some(s) = suggest(unknown, expected.iter().copied()) {
                out += &format!(" (did you mean `{s}`?)");
            }
            if is_object {
                out += "; docs/scene-format.md lists the keys of each object type";
            } else if !expected.is_empty() {
                out += &format!("; expected one of: {}", expected.join(", "));
            }
            return out;
        }
    }
    if let Some(rest) = msg.strip_prefix("missing field ") {
        return format!("missing key {rest}");
    }
    type_message(&msg).unwrap_or(msg)
}

/// serde's type errors (`invalid type: map, expected a sequence`) in TOML's own terms,
/// expectation first: `expected an array, found a table`.
fn type_message(msg: &str) -> Option<String> {
    let (found, expected) = if let Some(rest) = msg
        .strip_prefix("invalid type: ")
        .or_else(|| msg.strip_prefix("invalid value: "))
    {
        let (found, expected) = rest.split_once(", expected ")?;
        if let Some(digits) = too_large(found) {
            return Some(too_large_message(digits, expected));
        }
        (toml_found(found), expected)
    } else {
        let rest = msg.strip_prefix("invalid length ")?;
        let (n, expected) = rest.split_once(", expected ")?;
        let values = if n == "1" { "value" } else { "values" };
        (format!("an array of {n} {values}"), expected)
    };
    Some(format!(
        "expected {}, found {found}",
        toml_expected(expected)
    ))
}

/// The digits of a whole number too large for TOML's 64-bit integers, which the toml
/// crate reports as found ``integer `N` as i128``.
fn too_large(found: &str) -> Option<&str> {
    found
        .strip_prefix("integer `")?
        .strip_suffix("` as i128")
        .filter(|d| !d.is_empty())
}

/// The message for a whole number too large for TOML where `expected` was wanted: a
/// number may be written with a decimal point (`1e20`, `100000000000000000000.0`),
/// which TOML reads as a float.
fn too_large_message(digits: &str, expected: &str) -> String {
    let expected = toml_expected(expected);
    if expected.starts_with("a number") {
        format!(
            "number too large: {digits} (TOML whole numbers are 64-bit; write {digits}.0 \
             to give it as a number)"
        )
    } else {
        format!("number too large: {digits} (expected {expected})")
    }
}

/// What serde says it found (`serde::de::Unexpected`), in TOML's terms.
fn toml_found(found: &str) -> String {
    let unquote = |s: &str| s.trim_matches('`').to_string();
    match found.split_once(' ') {
        _ if found == "map" => "a table".into(),
        _ if found == "sequence" => "an array".into(),
        Some(("string", s)) => format!("the string {s}"),
        Some(("integer", v)) => format!("the whole number {}", unquote(v)),
        Some(("floating", v)) => format!("the number {}", unquote(v.trim_start_matches("point "))),
        Some(("boolean", v)) => format!("the boolean {}", unquote(v)),
        _ => found.to_string(),
    }
}

/// What serde says it expected, in TOML's terms.
fn toml_expected(expected: &str) -> String {
    if let Some(n) = expected
        .strip_prefix("an array of length ")
        .or_else(|| expected.strip_prefix("a tuple of size "))
    {
        return format!("an array of {n} values");
    }
    if expected.starts_with("struct ") || expected == "a map" {
        return "a table".into();
    }
    match expected {
        "a sequence" => "an array".into(),
        "u8" | "u16" | "u32" | "u64" | "usize" => "a whole number, 0 or more".into(),
        "i8" | "i16" | "i32" | "i64" | "isize" => "a whole number".into(),
        "f32" | "f64" => "a number".into(),
        "a boolean" | "bool" => "true or false".into(),
        other => other.to_string(),
    }
}

/// The candidate closest to `word` by edit distance, if close enough to be a likely
/// misspelling (at most a third of the word's length, at least 1).
fn suggest<'c>(word: &str, candidates: impl IntoIterator<Item = &'c str>) -> Option<&'c str> {
    let limit = (word.chars().count() / 3).max(1);
    candidates
        .into_iter()
        .map(|c| (edit_distance(word, c), c))
        .filter(|&(d, _)| d <= limit)
        .min_by_key(|&(d, _)| d)
        .map(|(_, c)| c)
}

/// Edit distance over characters, case-insensitive, counting insertions, deletions,
/// substitutions and transpositions of neighbours (`fvo` → `fov`) as one edit each
/// (optimal string alignment).
fn edit_distance(a: &str, b: &str) -> usize {
    let a: Vec<char> = a.to_lowercase().chars().collect();
    let b: Vec<char> = b.to_lowercase().chars().collect();
    let w = b.len() + 1;
    let mut d = vec![0usize; (a.len() + 1) * w];
    for (j, cell) in d.iter_mut().enumerate().take(w) {
        *cell = j;
    }
    for i in 1..=a.len() {
        d[i * w] = i;
        for j in 1..=b.len() {
            let cost = usize::from(a[i - 1] != b[j - 1]);
            let mut v = (d[(i - 1) * w + j] + 1)
                .min(d[i * w + j - 1] + 1)
                .min(d[(i - 1) * w + j - 1] + cost);
            if i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] {
                v = v.min(d[(i - 2) * w + j - 2] + 1);
            }
            d[i * w + j] = v;
        }
    }
    d[a.len() * w + b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn positions_count_lines_and_characters() {
        let s = Source::new(Path::new("x.toml"), "ab\nçd = 1\n\nz");
        assert_eq!(s.position(0), (1, 1));
        assert_eq!(s.position(1), (1, 2));
        assert_eq!(s.position(3), (2, 1));
        // 'ç' is two bytes, one column.
        assert_eq!(s.position(5), (2, 2));
        assert_eq!(s.position(11), (3, 1));
        assert_eq!(s.position(12), (4, 1));
        assert_eq!(s.position(99), (4, 2));
    }

    #[test]
    fn suggestions_only_for_near_misses() {
        let c = ["sphere", "cone", "cylinder"];
        assert_eq!(suggest("spere", c), Some("sphere"));
        assert_eq!(suggest("Sphere", c), Some("sphere"));
        assert_eq!(suggest("cylnder", c), Some("cylinder"));
        assert_eq!(suggest("torus", c), None);
        assert_eq!(edit_distance("kitten", "sitting"), 3);
        assert_eq!(edit_distance("", "abc"), 3);
        assert_eq!(edit_distance("fvo", "fov"), 1);
        assert_eq!(suggest("chiar", ["chair", "table"]), Some("chair"));
    }

    #[test]
    fn serde_messages_are_rephrased() {
        assert_eq!(
            serde_message("unknown field `fvo`, expected one of `from`, `at`, `fov`"),
            "unknown key `fvo` (did you mean `fov`?); expected one of: from, at, fov"
        );
        assert_eq!(
            serde_message("missing field `position`"),
            "missing key `position`"
        );
        let many: Vec<String> = format::OBJECT_KEYS
            .iter()
            .map(|k| format!("`{k}`"))
            .collect();
        let m = serde_message(&format!(
            "unknown field `radus`, expected one of {}",
            many.join(", ")
        ));
        assert!(
            m.starts_with("unknown key `radus` (did you mean `radius`?)"),
            "{m}"
        );
        assert!(m.contains("docs/scene-format.md"), "{m}");
    }

    #[test]
    fn type_errors_speak_toml() {
        let cases = [
            (
                "invalid type: map, expected an array of length 3",
                "expected an array of 3 values, found a table",
            ),
            (
                "invalid length 2, expected an array of length 3",
                "expected an array of 3 values, found an array of 2 values",
            ),
            (
                "invalid type: integer `5`, expected a sequence",
                "expected an array, found the whole number 5",
            ),
            (
                "invalid type: floating point `1.5`, expected u32",
                "expected a whole number, 0 or more, found the number 1.5",
            ),
            (
                "invalid value: integer `-5`, expected u32",
                "expected a whole number, 0 or more, found the whole number -5",
            ),
            (
                "invalid type: integer `5`, expected struct CameraDef",
                "expected a table, found the whole number 5",
            ),
            (
                "invalid type: string \"x\", expected a number",
                "expected a number, found the string \"x\"",
            ),
            (
                "invalid type: boolean `true`, expected a number",
                "expected a number, found the boolean true",
            ),
            (
                "invalid type: integer `99999999999999999999` as i128, expected a number",
                "number too large: 99999999999999999999 (TOML whole numbers are 64-bit; \
                 write 99999999999999999999.0 to give it as a number)",
            ),
            (
                "invalid type: integer `-99999999999999999999` as i128, expected u32",
                "number too large: -99999999999999999999 (expected a whole number, 0 or more)",
            ),
        ];
        for (serde, toml) in cases {
            assert_eq!(serde_message(serde), toml);
        }
    }
}
