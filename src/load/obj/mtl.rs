//! The MTL statement parser: a material library's text to its materials and texture
//! statements, with a warning `path:line:col` for each malformed statement, which is
//! then ignored.
//!
//! - `newmtl NAME` starts a material (the name is the rest of the line, trimmed); one
//!   without a name also drops the statements up to the next `newmtl`. Statements
//!   before the first `newmtl` are checked and dropped. A name defined twice gives two
//!   materials (the later one is the one `usemtl` finds).
//! - `Ka`, `Kd`, `Ks`, `Ke` take `r g b` (more numbers are ignored) or one grey value;
//!   `Ns`, `Ni`, `d`, `Tr` one number; `illum` an integer 0–255. Numbers must be
//!   finite. `Ke`, and every statement not named here (`Tf`, `sharpness`, ...), are
//!   ignored.
//! - Texture statements are read by [`super::texmap`]; those emray does not use are
//!   named in one warning per library.

use super::located::{Located, show};
use super::texmap::{self, MapKind, TexStmt};
use std::path::Path;

/// An MTL material as read.
#[derive(Clone, Debug, Default, PartialEq)]
pub(super) struct MtlMaterial {
    pub name: String,
    /// `Ka`.
    pub ambient: Option<[f32; 3]>,
    /// `Kd`.
    pub diffuse: Option<[f32; 3]>,
    /// `Ks`.
    pub specular: Option<[f32; 3]>,
    /// `Ns`.
    pub shininess: Option<f32>,
    /// `d`.
    pub dissolve: Option<f32>,
    /// `Tr` (1 − `d`).
    pub transparency: Option<f32>,
    /// `Ni`.
    pub optical_density: Option<f32>,
    /// `illum`.
    pub illumination_model: Option<u8>,
}

/// What a material library gives.
#[derive(Debug, Default)]
pub(super) struct Library {
    /// The materials in the order defined.
    pub materials: Vec<MtlMaterial>,
    /// The texture statements emray uses, in order.
    pub maps: Vec<TexStmt>,
    pub warnings: Vec<String>,
}

/// Parse the text of the material library at `path` (lines split as [`str::lines`]
/// does).
pub(super) fn parse(text: &str, path: &Path) -> Library {
    let mut p = MtlParser {
        path,
        lib: Library::default(),
        current: None,
        skipping: false,
        unsupported: Vec::new(),
        option_notes: Vec::new(),
    };
    for (i, line) in text.lines().enumerate() {
        p.statement(i + 1, line);
    }
    p.finish()
}

/// The parser's state between lines.
struct MtlParser<'a> {
    path: &'a Path,
    lib: Library,
    /// The material being defined.
    current: Option<MtlMaterial>,
    /// After a `newmtl` without a name: statements are dropped.
    skipping: bool,
    /// Texture statements emray does not use, each named once.
    unsupported: Vec<String>,
    /// Notes on ignored texture options, reported after the statements' warnings.
    option_notes: Vec<String>,
}

/// A malformed statement: the word it concerns (the end of the line when `None`) and
/// the message.
type Problem<'a> = (Option<&'a str>, String);

fn finite(t: &str) -> Option<f32> {
    t.parse::<f32>().ok().filter(|v| v.is_finite())
}

/// The words' text, or "nothing", for a message.
fn found(t: Option<&str>) -> String {
    t.map_or("nothing".into(), show)
}

impl MtlParser<'_> {
    fn statement(&mut self, ln: usize, line: &str) {
        let mut words = line.split_whitespace();
        let Some(kw) = words.next() else { return };
        let result = match kw {
            "newmtl" => self.newmtl(line),
            _ if self.skipping => Ok(()),
            "Ka" | "Kd" | "Ks" | "Ke" => self.colour(kw, words),
            "Ns" | "Ni" | "d" | "Tr" => self.number(kw, words.next()),
            "illum" => self.illum(words.next()),
            k if texmap::is_texture_statement(k) => self.texture(k, words, ln),
            _ => Ok(()),
        };
        if let Err((tok, message)) = result {
            let at = Located::at_token(ln, line, tok, message);
            self.lib.warnings.push(format!(
                "{}:{ln}:{}: {}; statement ignored",
                self.path.display(),
                at.col,
                at.message
            ));
        }
    }

    /// `newmtl NAME`: the name is the trimmed line after the keyword.
    fn newmtl<'l>(&mut self, line: &'l str) -> Result<(), Problem<'l>> {
        let name = line.trim().get("newmtl".len()..).unwrap_or_default().trim();
        if name.is_empty() {
            self.skipping = true;
            let message =
                "'newmtl' without a name (its statements up to the next 'newmtl' are skipped)";
            return Err((None, message.into()));
        }
        self.skipping = false;
        if let Some(done) = self.current.take() {
            self.lib.materials.push(done);
        }
        self.current = Some(MtlMaterial {
            name: name.to_string(),
            ..MtlMaterial::default()
        });
        Ok(())
    }

    /// `Ka`, `Kd`, `Ks`, `Ke`: `r g b` or one grey value.
    fn colour<'l>(
        &mut self,
        kw: &str,
        mut words: std::str::SplitWhitespace<'l>,
    ) -> Result<(), Problem<'l>> {
        let v = [words.next(), words.next(), words.next()];
        let rgb = match v.map(|t| t.map(|t| (t, finite(t)))) {
            [Some((_, Some(r))), None, None] => [r; 3],
            [Some((_, Some(r))), Some((_, Some(g))), Some((_, Some(b)))] => [r, g, b],
            _ => {
                let bad = v.iter().flatten().find(|t| finite(t).is_none()).copied();
                let what = match (bad, v.iter().flatten().count()) {
                    (Some(t), _) => format!("found {}", show(t)),
                    (None, 0) => "found nothing".to_string(),
                    (None, n) => format!("found {n} numbers"),
                };
                let message = format!("expected a colour 'r g b' (or one grey value), {what}");
                return Err((bad, message));
            }
        };
        if let Some(m) = &mut self.current {
            match kw {
                "Ka" => m.ambient = Some(rgb),
                "Kd" => m.diffuse = Some(rgb),
                "Ks" => m.specular = Some(rgb),
                _ => {}
            }
        }
        Ok(())
    }

    /// `Ns`, `Ni`, `d`, `Tr`: one number.
    fn number<'l>(&mut self, kw: &str, t: Option<&'l str>) -> Result<(), Problem<'l>> {
        let Some(x) = t.and_then(finite) else {
            let message = format!("expected a number after '{kw}', found {}", found(t));
            return Err((t, message));
        };
        if let Some(m) = &mut self.current {
            match kw {
                "Ns" => m.shininess = Some(x),
                "Ni" => m.optical_density = Some(x),
                "d" => m.dissolve = Some(x),
                _ => m.transparency = Some(x),
            }
        }
        Ok(())
    }

    /// `illum N`.
    fn illum<'l>(&mut self, t: Option<&'l str>) -> Result<(), Problem<'l>> {
        let Some(n) = t.and_then(|t| t.parse::<u8>().ok()) else {
            let message = format!(
                "expected an illumination model 0–10 after 'illum', found {}",
                found(t)
            );
            return Err((t, message));
        };
        if let Some(m) = &mut self.current {
            m.illumination_model = Some(n);
        }
        Ok(())
    }

    /// A texture statement: kept when emray uses the map, else named in a warning.
    fn texture<'l>(
        &mut self,
        kw: &str,
        words: std::str::SplitWhitespace<'l>,
        ln: usize,
    ) -> Result<(), Problem<'l>> {
        let Some(kind) = MapKind::of(kw) else {
            if !self.unsupported.iter().any(|u| u == kw) {
                self.unsupported.push(kw.to_string());
            }
            return Ok(());
        };
        let rest: Vec<&str> = words.collect();
        let material = self.current.as_ref().map_or("", |m| m.name.as_str());
        let map = texmap::read_map(kind, &rest, material, self.path, ln)?;
        self.option_notes.extend(map.note);
        self.lib.maps.push(map.stmt);
        Ok(())
    }

    /// The library, with the notes on texture options and statements after the
    /// statements' warnings.
    fn finish(mut self) -> Library {
        self.lib.materials.extend(self.current.take());
        self.lib.warnings.append(&mut self.option_notes);
        if !self.unsupported.is_empty() {
            self.lib.warnings.push(format!(
                "{}: ignored the texture map statement(s) {}: not supported (map_Kd, map_Ks, \
                 bump, map_bump, norm and refl are)",
                self.path.display(),
                self.unsupported.join(", ")
            ));
        }
        self.lib
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn malformed_statements_are_warnings_and_ignored() {
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
        let lib = parse(src, Path::new("x.mtl"));
        let mats = &lib.materials;
        assert_eq!(mats.len(), 2);
        assert_eq!(mats[0].name, "a");
        assert_eq!(mats[0].diffuse, Some([0.5; 3]));
        assert_eq!(mats[0].ambient, None);
        assert_eq!(mats[0].specular, None);
        assert_eq!(mats[0].dissolve, None);
        assert_eq!(mats[0].illumination_model, None);
        // The nameless material's Kd did not leak into `a`.
        assert_eq!(mats[1].diffuse, Some([0.0, 1.0, 0.0]));
        assert_eq!(mats[1].optical_density, Some(1.5));
        let warnings = &lib.warnings;
        let lines: Vec<&str> = warnings
            .iter()
            .filter_map(|w| w.strip_prefix("x.mtl:"))
            .filter(|w| w.starts_with(|c: char| c.is_ascii_digit()))
            .collect();
        let at: Vec<&str> = lines.iter().map(|w| &w[..w.find(':').unwrap()]).collect();
        assert_eq!(at, ["3", "4", "5", "6", "7", "8", "11"], "{warnings:?}");
        // The texture statements are kept for emray's own loader, with their material.
        let kinds: Vec<(MapKind, &str, &str)> = lib
            .maps
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
        assert_eq!(lib.maps[1].at, "x.mtl:10");
        assert!(lines[1].starts_with("4:7:"), "{}", lines[1]); // `Ks 1 1`: at its end
        assert!(lines[3].starts_with("6:3:"), "{}", lines[3]);
    }

    #[test]
    fn later_values_win_and_statements_before_newmtl_are_dropped() {
        let src = "Kd 1 1 1\nnewmtl m\nd 0.5\nTr 0.1\nTr x\nd 0.25\nKd 1 2 3 4\nillum 300\n\
                   newmtl m\nunknown statement\nmap_Ka a.png\nmap_d d.png\n";
        let lib = parse(src, Path::new("x.mtl"));
        assert_eq!(lib.materials.len(), 2);
        let m = &lib.materials[0];
        assert_eq!(
            (m.dissolve, m.transparency, m.diffuse, m.illumination_model),
            (Some(0.25), Some(0.1), Some([1.0, 2.0, 3.0]), None)
        );
        assert_eq!(
            lib.materials[1],
            MtlMaterial {
                name: "m".into(),
                ..Default::default()
            }
        );
        assert_eq!(lib.warnings.len(), 3, "{:?}", lib.warnings);
        assert!(
            lib.warnings[2].contains("map_Ka, map_d"),
            "{}",
            lib.warnings[2]
        );
    }

    #[test]
    fn names_are_the_rest_of_the_line() {
        let lib = parse("  newmtl  my glass \t\nnewmtl\t\tx\n", Path::new("x.mtl"));
        let names: Vec<&str> = lib.materials.iter().map(|m| m.name.as_str()).collect();
        assert_eq!(names, ["my glass", "x"]);
    }
}
