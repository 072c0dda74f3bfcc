//! Output file names from templates, the one template language of `emray render` and
//! `emray batch` (their images and heat maps) and of `batch --report`: a `{key}` is
//! replaced by its value, a `{` always opens a placeholder, and a key the template
//! cannot take is refused, listing the ones it can.

use crate::accel::Backend;
use crate::spd::Database;
use std::path::Path;

/// The placeholders of an output file's template.
pub const OUTPUT_KEYS: &[&str] = &["stem", "backend", "index", "spp"];

/// Why a template cannot be expanded.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum TemplateError {
    /// A `{` with no `}` after it.
    #[error("{what} '{template}': '{{' without '}}'")]
    Unclosed {
        /// What the template names (`output template`, `report name`).
        what: &'static str,
        /// The template.
        template: String,
    },
    /// A `{key}` the template cannot take.
    #[error(
        "{what} '{template}': unknown placeholder '{{{key}}}' (one of {})",
        list(known)
    )]
    Unknown {
        /// What the template names.
        what: &'static str,
        /// The template.
        template: String,
        /// The unknown key.
        key: String,
        /// The keys it can take.
        known: &'static [&'static str],
    },
}

/// `{a}, {b}`: the keys, for messages.
fn list(keys: &[&str]) -> String {
    keys.iter()
        .map(|k| format!("{{{k}}}"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// A piece of a template: text, or a placeholder's key.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Piece<'t> {
    Text(&'t str),
    Key(&'t str),
}

/// The pieces of `template`, whose keys must be among `known`; `what` names it in
/// errors.
fn pieces<'t>(
    what: &'static str,
    template: &'t str,
    known: &'static [&'static str],
) -> Result<Vec<Piece<'t>>, TemplateError> {
    let mut out = Vec::new();
    let mut rest = template;
    while let Some(open) = rest.find('{') {
        out.push(Piece::Text(&rest[..open]));
        let after = &rest[open + 1..];
        let close = after.find('}').ok_or_else(|| TemplateError::Unclosed {
            what,
            template: template.to_string(),
        })?;
        let key = &after[..close];
        if !known.contains(&key) {
            return Err(TemplateError::Unknown {
                what,
                template: template.to_string(),
                key: key.to_string(),
                known,
            });
        }
        out.push(Piece::Key(key));
        rest = &after[close + 1..];
    }
    out.push(Piece::Text(rest));
    Ok(out)
}

/// Check `template` (keys among `known`) and tell whether it has a placeholder.
pub fn has_placeholder(
    what: &'static str,
    template: &str,
    known: &'static [&'static str],
) -> Result<bool, TemplateError> {
    let p = pieces(what, template, known)?;
    Ok(p.iter().any(|p| matches!(p, Piece::Key(_))))
}

/// `template` with each `{key}` (one of `known`) replaced by `value(key)`; `what` names
/// the template in errors.
pub fn expand(
    what: &'static str,
    template: &str,
    known: &'static [&'static str],
    value: impl Fn(&str) -> String,
) -> Result<String, TemplateError> {
    let mut out = String::with_capacity(template.len() + 16);
    for p in pieces(what, template, known)? {
        match p {
            Piece::Text(t) => out.push_str(t),
            Piece::Key(k) => out.push_str(&value(k)),
        }
    }
    Ok(out)
}

/// What an output file's name is made of.
#[derive(Clone, Copy, Debug)]
pub struct OutputName<'a> {
    /// The scene file, or `spd:NAME[?size=N]` spec.
    pub scene: &'a Path,
    /// The backend that renders it.
    pub backend: Backend,
    /// The scene's position among those of the command, from 0.
    pub index: usize,
    /// The samples per pixel asked for (1 when none is).
    pub spp: Option<u32>,
}

impl OutputName<'_> {
    /// The value of `key`, one of [`OUTPUT_KEYS`].
    fn value(&self, key: &str) -> String {
        match key {
            "stem" => scene_stem(self.scene),
            "backend" => self.backend.name().to_string(),
            "index" => self.index.to_string(),
            _ => self.spp.unwrap_or(1).to_string(),
        }
    }

    /// The file name `template` gives: `{stem}` (the scene's stem, see [`scene_stem`]),
    /// `{backend}`, `{index}`, `{spp}`.
    pub fn expand(&self, template: &str) -> Result<String, TemplateError> {
        expand("output template", template, OUTPUT_KEYS, |k| self.value(k))
    }
}

/// The file-name stem of a scene: the file's, or `NAME_sN` for a generated one.
pub fn scene_stem(scene: &Path) -> String {
    if let Ok(Some((db, size))) = Database::parse_spec(&scene.to_string_lossy()) {
        return format!("{}_s{size}", db.name());
    }
    scene
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "emray".into())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn output_names_expand_and_unknown_keys_are_refused() {
        let name = |scene: &'static str| OutputName {
            scene: Path::new(scene),
            backend: Backend::Bvh,
            index: 3,
            spp: Some(4),
        };
        let p = name("dir/balls.nff");
        assert_eq!(
            p.expand("out/{stem}-{backend}-{spp}-{index}.exr").unwrap(),
            "out/balls-bvh-4-3.exr"
        );
        assert_eq!(
            name("spd:gears?size=2").expand("{stem}.png").unwrap(),
            "gears_s2.png"
        );
        assert_eq!(OutputName { spp: None, ..p }.expand("{spp}").unwrap(), "1");
        assert_eq!(
            p.expand("{colour}.png").unwrap_err().to_string(),
            "output template '{colour}.png': unknown placeholder '{colour}' (one of {stem}, \
             {backend}, {index}, {spp})"
        );
        assert_eq!(
            p.expand("{stem.png").unwrap_err().to_string(),
            "output template '{stem.png': '{' without '}'"
        );
    }

    #[test]
    fn other_templates_take_their_own_keys() {
        let shard = |t: &str| expand("report name", t, &["shard"], |_| "2".into());
        assert_eq!(shard("r-{shard}.json").unwrap(), "r-2.json");
        assert_eq!(shard("r.json}").unwrap(), "r.json}");
        assert!(shard("r-{stem}.json").is_err());
        assert_eq!(has_placeholder("t", "a.png", OUTPUT_KEYS), Ok(false));
        assert_eq!(has_placeholder("t", "{index}.png", OUTPUT_KEYS), Ok(true));
    }
}
