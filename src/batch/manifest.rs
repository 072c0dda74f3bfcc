//! Batch manifests: a TOML file whose top-level keys are the defaults of every job and
//! whose `[[job]]` tables are the jobs.
//!
//! ```toml
//! output = "out/{stem}-{backend}.png"   # template, relative to the manifest's folder
//! backend = "bvh"
//! res = "320x240"
//!
//! [[job]]
//! scene = "scenes/spheres.nff"           # relative to the manifest's folder
//!
//! [[job]]
//! name = "gears-hq"                      # default: the output path
//! scene = "spd:gears?size=2"
//! output = "out/gears-hq.exr"
//! spp = 16
//! radiosity = { patch_size = 0.5 }
//! ```
//!
//! A job's keys are `scene` and `name` (a job's own), `output`, and every key of the
//! render options ([`RenderOptions`], the command line's long options with `_` for
//! `-`: `backend`, `res`, `spp`, `max_depth`, `spd`, `encoding`, `aov`, `heatmap`, ...,
//! and the table `radiosity`). A job's own key wins over the default; options given on
//! the command line win over both. Unknown keys and bad values are errors at their
//! `file:line:col`. Relative paths (scenes, outputs, heat maps, environment maps) are
//! relative to the manifest's folder.

use crate::job::template::{OutputName, TemplateError};
use crate::job::{Job, Outputs, RenderOptions, SceneSource, Task};
use crate::load::LoadError;
use crate::load::toml::{Source, read_text, serde_message};
use serde::Deserialize;
use std::path::{Path, PathBuf};
use toml::Spanned;
use toml::de::{DeTable, DeValue};

/// The keys of a job that are not render options.
const JOB_KEYS: [&str; 3] = ["scene", "name", "output"];

/// What the command line gives every job: its output template and options, which win
/// over the manifest's.
#[derive(Clone, Debug, Default)]
pub struct Overrides {
    /// Output template.
    pub output: Option<String>,
    /// Render options.
    pub options: RenderOptions,
}

/// A table of the manifest, each key and value with its place in the file.
type Table<'t> = DeTable<'t>;

/// Read the jobs of the manifest at `path`. Errors are `path:line:col: message`.
pub fn load(path: &Path, cli: &Overrides) -> Result<Vec<Job>, LoadError> {
    let text = read_text(path)?;
    let source = Source::new(path, &text);
    let doc = DeTable::parse(&text)
        .map_err(|e| source.err(e.span().unwrap_or(0..0), serde_message(e.message())))?;
    let (defaults, jobs) = split(&source, doc.into_inner())?;
    if jobs.is_empty() {
        return Err(source.err(0..0, "no [[job]] in the manifest"));
    }
    let base = path.parent().unwrap_or(Path::new(""));
    jobs.into_iter()
        .enumerate()
        .map(|(index, job)| {
            let entry = Entry::read(&source, &defaults, job)?;
            let span = entry.span.clone();
            entry
                .job(base, index, cli)
                .map_err(|e| source.err(span, e.to_string()))
        })
        .collect()
}

/// The defaults (every top-level key but `job`) and the `[[job]]` tables.
fn split<'t>(
    source: &Source,
    doc: Table<'t>,
) -> Result<(Table<'t>, Vec<Spanned<Table<'t>>>), LoadError> {
    let mut defaults = Table::new();
    let mut jobs = Vec::new();
    for (key, value) in doc {
        let span = value.span();
        match (key.get_ref().as_ref(), value.into_inner()) {
            ("job", DeValue::Array(array)) => {
                for item in array {
                    let span = item.span();
                    match item.into_inner() {
                        DeValue::Table(t) => jobs.push(Spanned::new(span, t)),
                        _ => return Err(source.err(span, "each job is a table: use [[job]]")),
                    }
                }
            }
            ("job", _) => return Err(source.err(span, "`job` is an array of tables: use [[job]]")),
            ("scene" | "name", _) => {
                return Err(source.err(
                    key.span(),
                    format!(
                        "`{}` belongs in a [[job]], not with the defaults",
                        key.get_ref()
                    ),
                ));
            }
            (_, v) => {
                defaults.insert(key, Spanned::new(span, v));
            }
        }
    }
    Ok((defaults, jobs))
}

/// One `[[job]]` read: its own keys and its render options over the defaults.
struct Entry {
    /// Where the job's table is.
    span: std::ops::Range<usize>,
    scene: String,
    name: Option<String>,
    output: Option<String>,
    options: RenderOptions,
}

impl Entry {
    /// Read `job` over the `defaults`.
    fn read(
        source: &Source,
        defaults: &Table<'_>,
        job: Spanned<Table<'_>>,
    ) -> Result<Entry, LoadError> {
        let span = job.span();
        let mut merged = defaults.clone();
        for (k, v) in job.into_inner() {
            merged.insert(k, v);
        }
        let mut own = [None, None, None];
        let mut options = Table::new();
        for (k, v) in merged {
            match JOB_KEYS.iter().position(|j| *j == k.get_ref().as_ref()) {
                Some(i) => own[i] = Some(text_value(source, k.get_ref(), v)?),
                None => {
                    options.insert(k, v);
                }
            }
        }
        let [scene, name, output] = own;
        let scene = scene.ok_or_else(|| source.err(span.clone(), "missing key `scene`"))?;
        let de = toml::de::Deserializer::from(Spanned::new(span.clone(), options));
        let options = RenderOptions::deserialize(de)
            .map_err(|e| source.err(e.span().unwrap_or(0..0), serde_message(e.message())))?;
        Ok(Entry {
            span,
            scene,
            name,
            output,
            options,
        })
    }

    /// The job, the `index`th of the manifest in the folder `base`, with the command
    /// line's overrides.
    fn job(self, base: &Path, index: usize, cli: &Overrides) -> Result<Job, TemplateError> {
        let scene = if self.scene.starts_with("spd:") {
            PathBuf::from(&self.scene)
        } else {
            base.join(&self.scene)
        };
        let mut own = self.options;
        if let Some(env) = &own.envmap {
            own.envmap = Some(base.join(env));
        }
        let relative_maps = cli.options.heatmap.is_empty();
        let options = cli.options.over(&own);
        let name = OutputName {
            scene: &scene,
            backend: options.backend_options().backend,
            index,
            spp: options.spp,
        };
        let from_manifest = cli.output.is_none();
        let template = cli
            .output
            .clone()
            .or(self.output)
            .unwrap_or_else(|| "{stem}.png".into());
        let place = |t: &str, relative: bool| -> Result<PathBuf, TemplateError> {
            let file = PathBuf::from(name.expand(t)?);
            Ok(if relative { base.join(file) } else { file })
        };
        let image = place(&template, from_manifest)?;
        let heatmaps = options
            .heatmap
            .chunks(2)
            .filter_map(|pair| pair.get(1))
            .map(|t| place(t, relative_maps))
            .collect::<Result<_, _>>()?;
        Ok(Job {
            name: self
                .name
                .unwrap_or_else(|| image.to_string_lossy().into_owned()),
            scene: SceneSource::File(scene),
            options,
            task: Task::Render,
            outputs: Outputs {
                image: Some(image),
                heatmaps,
                ..Outputs::default()
            },
        })
    }
}

/// The string value of the job key `key`.
fn text_value(
    source: &Source,
    key: &str,
    value: Spanned<DeValue<'_>>,
) -> Result<String, LoadError> {
    let span = value.span();
    match value.into_inner() {
        DeValue::String(s) => Ok(s.into_owned()),
        _ => Err(source.err(span, format!("`{key}` must be a string"))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write(dir: &Path, text: &str) -> PathBuf {
        let p = dir.join("jobs.toml");
        std::fs::write(&p, text).unwrap();
        p
    }

    #[test]
    fn defaults_jobs_and_overrides() {
        let dir = tempfile::tempdir().unwrap();
        let p = write(
            dir.path(),
            "output = \"out/{stem}-{backend}.png\"\nbackend = \"bvh\"\nres = \"32x16\"\n\
             [[job]]\nscene = \"a.nff\"\n\
             [[job]]\nname = \"g\"\nscene = \"spd:gears?size=1\"\nspp = 4\noutput = \"g.exr\"\n\
             radiosity = { patch_size = 0.5 }\n",
        );
        let jobs = load(&p, &Overrides::default()).unwrap();
        assert_eq!(jobs.len(), 2);
        let image = |j: &Job| j.outputs.image.clone().unwrap();
        assert_eq!(jobs[0].scene, SceneSource::File(dir.path().join("a.nff")));
        assert_eq!(image(&jobs[0]), dir.path().join("out/a-bvh.png"));
        assert_eq!(jobs[0].name, image(&jobs[0]).to_string_lossy());
        assert_eq!(jobs[0].options.res, Some("32x16".parse().unwrap()));
        assert_eq!(jobs[1].name, "g");
        assert_eq!(jobs[1].scene, SceneSource::File("spd:gears?size=1".into()));
        assert_eq!(jobs[1].options.spp, Some(4));
        assert_eq!(jobs[1].options.radiosity.patch_size, Some(0.5));
        let cli = Overrides {
            options: RenderOptions {
                spp: Some(2),
                ..RenderOptions::default()
            },
            ..Overrides::default()
        };
        assert!(
            load(&p, &cli)
                .unwrap()
                .iter()
                .all(|j| j.options.spp == Some(2) && j.options.backend.is_some())
        );
    }

    #[test]
    fn errors_name_the_line() {
        let dir = tempfile::tempdir().unwrap();
        let err = |text: &str| {
            let p = write(dir.path(), text);
            load(&p, &Overrides::default()).unwrap_err().to_string()
        };
        let e = err("[[job]]\nscene = \"a.nff\"\nres = \"big\"\n");
        assert!(e.contains("jobs.toml:3:"), "{e}");
        assert!(e.contains("WxH"), "{e}");
        let e = err("[[job]]\nscene = \"a.nff\"\nspeed = 3\n");
        assert!(e.contains("jobs.toml:3:"), "{e}");
        assert!(e.contains("unknown key `speed`"), "{e}");
        let e = err("spq = 3\n[[job]]\nscene = \"a.nff\"\n");
        assert!(e.contains("jobs.toml:1:"), "{e}");
        let e = err("[[job]]\nscene = \"a.nff\"\nradiosity = { patch = 1 }\n");
        assert!(e.contains("jobs.toml:3:") && e.contains("`patch`"), "{e}");
        let e = err("[[job]]\nname = \"x\"\n");
        assert!(
            e.contains("jobs.toml:1:") && e.contains("missing key `scene`"),
            "{e}"
        );
        let e = err("scene = \"a.nff\"\n[[job]]\nscene = \"b.nff\"\n");
        assert!(
            e.contains("jobs.toml:1:") && e.contains("belongs in a [[job]]"),
            "{e}"
        );
        assert!(err("output = \"x.png\"\n").contains("no [[job]]"));
        let e = err("[[job]]\nscene = \"a.nff\"\noutput = \"{colour}.png\"\n");
        assert!(
            e.contains("jobs.toml:1:") && e.contains("'{colour}'"),
            "{e}"
        );
    }
}
