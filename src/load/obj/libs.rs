//! The material libraries an OBJ file names (`mtllib`): which files, read in the order
//! named, each problem a warning.
//!
//! A library name is relative to the OBJ file's directory. `mtllib a.mtl b.mtl` names
//! one file when a file of that whole name exists, else one per word.

use super::mtl::{self, MtlMaterial};
use super::parse::MtlLib;
use super::texmap::TexStmt;
use crate::load::text;
use std::path::Path;

/// What the libraries give, in the order read.
#[derive(Debug, Default)]
pub(super) struct Libraries {
    pub materials: Vec<MtlMaterial>,
    /// Per material, the line of the `mtllib` that read it.
    pub read_at: Vec<usize>,
    pub maps: Vec<TexStmt>,
    /// The libraries read, as named in the file.
    pub read: Vec<String>,
    pub warnings: Vec<String>,
}

impl Libraries {
    /// The material names with the line of the `mtllib` that read each.
    pub fn names_read_at(&self) -> Vec<(usize, &str)> {
        self.read_at
            .iter()
            .zip(&self.materials)
            .map(|(&line, m)| (line, m.name.as_str()))
            .collect()
    }
}

/// Read the libraries of the `mtllib` statements of the OBJ file at `obj`.
pub(super) fn read(obj: &Path, mtllibs: &[MtlLib]) -> Libraries {
    let dir = obj.parent().unwrap_or(Path::new(""));
    let mut libs = Libraries::default();
    for lib in mtllibs {
        let at = format!("{}:{}", obj.display(), lib.line);
        if lib.name.is_empty() {
            libs.warnings
                .push(format!("{at}: 'mtllib' without a file name"));
            continue;
        }
        for name in file_names(dir, &lib.name) {
            libs.read_one(dir, name, lib.line, &at);
        }
    }
    libs
}

/// The files an `mtllib` names: the whole name, or each word when no file has the
/// whole name.
fn file_names<'a>(dir: &Path, name: &'a str) -> Vec<&'a str> {
    if !dir.join(name).exists() && name.split_whitespace().nth(1).is_some() {
        name.split_whitespace().collect()
    } else {
        vec![name]
    }
}

impl Libraries {
    /// Read the library `name` of the `mtllib` at `line` (`at`: the OBJ file and line).
    fn read_one(&mut self, dir: &Path, name: &str, line: usize, at: &str) {
        let full = dir.join(name);
        let bytes = match std::fs::read(&full) {
            Ok(b) => b,
            Err(e) => {
                self.warnings.push(format!(
                    "{at}: cannot read material library '{name}' ({}): {e}; faces using its \
                     materials get the default grey material",
                    full.display()
                ));
                return;
            }
        };
        let text = match text::lossy(&bytes, &full) {
            Ok(text) => text,
            Err(e) => {
                self.warnings.push(format!(
                    "{at}: cannot read material library '{name}': {e}; faces using its \
                     materials get the default grey material"
                ));
                return;
            }
        };
        let lib = mtl::parse(&text, &full);
        self.warnings.extend(lib.warnings);
        self.read_at
            .extend(std::iter::repeat_n(line, lib.materials.len()));
        self.materials.extend(lib.materials);
        self.maps.extend(lib.maps);
        self.read.push(name.to_string());
    }
}
