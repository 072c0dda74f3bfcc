//! Texture map statements of MTL files (`map_Kd`, `bump`, `refl`, ...): which maps
//! emray uses, and their options and file name.

use super::located::show;
use std::path::{Path, PathBuf};

/// Statements of texture maps.
pub(super) fn is_texture_statement(kw: &str) -> bool {
    kw.starts_with("map_") || matches!(kw, "bump" | "disp" | "decal" | "refl" | "norm")
}

/// The texture maps emray uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum MapKind {
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

impl MapKind {
    /// The map a texture statement gives, `None` for the maps emray does not use.
    pub fn of(kw: &str) -> Option<MapKind> {
        Some(match kw {
            "map_Kd" => MapKind::Color,
            "map_Ks" => MapKind::Specular,
            "bump" | "map_bump" | "map_Bump" => MapKind::Bump,
            "norm" | "map_Kn" => MapKind::Normal,
            "refl" => MapKind::Reflection,
            _ => return None,
        })
    }
}

/// `refl -type` of the cube faces +x, −x, +y, −y, +z, −z: the front is −z (where a
/// camera with the default orientation looks), the right +x, the top +y.
pub(super) const CUBE_TYPES: [&str; 6] = [
    "cube_right",
    "cube_left",
    "cube_top",
    "cube_bottom",
    "cube_back",
    "cube_front",
];

/// A texture statement of a material.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct TexStmt {
    pub material: String,
    pub kind: MapKind,
    /// The file name as written.
    pub name: String,
    /// The file, relative to the library's directory.
    pub file: PathBuf,
    /// `-bm`.
    pub bump_scale: f32,
    /// `-clamp on`.
    pub clamp: bool,
    /// `-s u v`.
    pub scale: [f32; 2],
    /// For `refl -type cube_*`: the face, +x −x +y −y +z −z as 0..6.
    pub cube: Option<usize>,
    /// Where: `library:line`.
    pub at: String,
}

/// A problem with a texture statement: the word it concerns (the end of the line when
/// `None`) and the message.
pub(super) type MapProblem<'a> = (Option<&'a str>, String);

/// What a texture statement gives: the map, and a note on options that are ignored.
pub(super) struct Map {
    pub stmt: TexStmt,
    pub note: Option<String>,
}

/// Read a texture statement of map `kind` in material `material`: `rest` are the words
/// after the keyword, `library` the MTL file and `ln` the line.
///
/// # Errors
/// An unknown option, a `-bm` without a number, no file name, or an unknown `refl`
/// type.
pub(super) fn read_map<'a>(
    kind: MapKind,
    rest: &[&'a str],
    material: &str,
    library: &Path,
    ln: usize,
) -> Result<Map, MapProblem<'a>> {
    let MapOptions {
        file: name,
        bump_scale,
        clamp,
        scale,
        map_type,
        mut ignored,
    } = parse_map(rest).map_err(|e| (rest.first().copied(), e))?;
    let mut cube = None;
    match map_type.as_deref() {
        None => {}
        Some("sphere") if kind == MapKind::Reflection => {}
        Some(t) if kind == MapKind::Reflection => {
            cube = CUBE_TYPES.iter().position(|&c| c == t);
            if cube.is_none() {
                let message = format!(
                    "unknown reflection map type {}: expected sphere, cube_top, cube_bottom, \
                     cube_front, cube_back, cube_left or cube_right",
                    show(t)
                );
                return Err((rest.get(1).copied(), message));
            }
        }
        Some(_) => ignored.push("-type".into()),
    }
    let note = (!ignored.is_empty()).then(|| {
        format!(
            "{}:{ln}: texture option(s) {} not supported; ignored",
            library.display(),
            ignored.join(" ")
        )
    });
    let stmt = TexStmt {
        material: material.to_string(),
        kind,
        file: library.parent().unwrap_or(Path::new("")).join(&name),
        name,
        bump_scale,
        clamp,
        scale,
        cube,
        at: format!("{}:{ln}", library.display()),
    };
    Ok(Map { stmt, note })
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

/// Parse the options and file name of a texture statement (everything after the
/// keyword). Options emray does not use are skipped with their arguments.
fn parse_map(words: &[&str]) -> Result<MapOptions, String> {
    let mut o = MapOptions {
        file: String::new(),
        bump_scale: 1.0,
        clamp: false,
        scale: [1.0, 1.0],
        map_type: None,
        ignored: Vec::new(),
    };
    let mut i = 0;
    while let Some(&opt) = words.get(i).filter(|w| is_option(w)) {
        i = o.option(opt, words, i + 1)?;
    }
    let file = words.get(i..).filter(|w| !w.is_empty());
    o.file = file.ok_or("expected a file name")?.join(" ");
    Ok(o)
}

/// A number for an option's argument.
fn number(t: &str) -> Option<f32> {
    t.parse::<f32>().ok().filter(|v| v.is_finite())
}

/// A word that starts an option: a dash, and not a number.
fn is_option(w: &str) -> bool {
    w.starts_with('-') && number(w).is_none()
}

impl MapOptions {
    /// Take option `opt`, whose arguments start at `words[i]`; the index after them.
    fn option(&mut self, opt: &str, words: &[&str], mut i: usize) -> Result<usize, String> {
        let arg = |i: usize| words.get(i).copied();
        match opt {
            "-bm" => {
                self.bump_scale = arg(i)
                    .and_then(number)
                    .ok_or_else(|| "expected a number after '-bm'".to_string())?;
                i += 1;
            }
            "-clamp" => {
                self.clamp = arg(i) == Some("on");
                i += 1;
            }
            "-type" => {
                self.map_type = arg(i).map(str::to_string);
                i += 1;
            }
            "-blendu" | "-blendv" | "-boost" | "-cc" | "-imfchan" | "-texres" => {
                self.ignored.push(opt.to_string());
                i += 1;
            }
            "-mm" => {
                self.ignored.push(opt.to_string());
                i += 2;
            }
            "-o" | "-s" | "-t" => {
                let mut got = [1.0f32; 3];
                let mut n = 0;
                while let Some((slot, x)) = got.get_mut(n).zip(arg(i).and_then(number)) {
                    *slot = x;
                    i += 1;
                    n += 1;
                }
                if opt == "-s" && n > 0 && got[0] != 0.0 && got[1] != 0.0 {
                    self.scale = [got[0], got[1]];
                } else {
                    self.ignored.push(opt.to_string());
                }
            }
            _ => return Err(format!("unknown texture option {}", show(opt))),
        }
        Ok(i)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn options_and_file_names() {
        let o = parse_map(&[
            "-bm", "0.5", "-s", "2", "3", "-clamp", "on", "my", "file.png",
        ])
        .unwrap();
        assert_eq!(
            (o.file.as_str(), o.bump_scale, o.scale, o.clamp),
            ("my file.png", 0.5, [2.0, 3.0], true)
        );
        let o = parse_map(&["-o", "1", "-mm", "0", "1", "-5"]).unwrap();
        assert_eq!(
            (o.file.as_str(), o.ignored),
            ("-5", vec!["-o".into(), "-mm".into()])
        );
        // A word with a dash that is no number is an option.
        assert!(parse_map(&["-5.png"]).is_err());
        assert!(parse_map(&["-bm", "x", "f.png"]).is_err());
        assert!(parse_map(&["-zz", "f.png"]).is_err());
        // Options that run past the end leave no file name.
        assert!(parse_map(&["-mm", "0"]).is_err());
    }

    #[test]
    fn reflection_types() {
        let lib = Path::new("d/lib.mtl");
        let m = read_map(
            MapKind::Reflection,
            &["-type", "cube_top", "t.png"],
            "m",
            lib,
            3,
        )
        .unwrap_or_else(|_| panic!("a cube face"));
        assert_eq!((m.stmt.cube, m.stmt.at.as_str()), (Some(2), "d/lib.mtl:3"));
        assert_eq!(m.stmt.file, Path::new("d/t.png"));
        assert!(
            read_map(
                MapKind::Reflection,
                &["-type", "cube", "t.png"],
                "m",
                lib,
                3
            )
            .is_err()
        );
        let m = read_map(MapKind::Color, &["-type", "sphere", "t.png"], "m", lib, 3)
            .unwrap_or_else(|_| panic!("a colour map"));
        assert!(m.note.unwrap().contains("-type"));
    }
}
