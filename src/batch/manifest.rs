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
//! ```
//!
//! Keys of a job (and defaults): `scene` (job only), `name` (job only), `output`,
//! `backend` (`embree`/`bvh`), `res` (`"WxH"`), `spp`, `max_depth`, `spd`, `encoding`
//! (`srgb`/`linear`). A job's own key wins over the default; settings given on the
//! command line win over both.

use super::{Job, JobSettings, job_output};
use crate::accel::Backend;
use crate::job::RenderRequest;
use crate::load::LoadError;
use crate::output::Encoding;
use serde::Deserialize;
use std::path::{Path, PathBuf};

/// Largest image side a manifest may ask for.
pub const MAX_SIDE: u32 = 65536;

#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
enum BackendName {
    Embree,
    Bvh,
}

#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
enum EncodingName {
    Srgb,
    Linear,
}

/// `"WxH"`, checked when read.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq)]
#[serde(try_from = "String")]
struct Res(u32, u32);

impl TryFrom<String> for Res {
    type Error = String;
    fn try_from(s: String) -> Result<Self, String> {
        let bad = || format!("res '{s}' is not WxH with sides 1..={MAX_SIDE} (e.g. \"640x480\")");
        let (w, h) = s.split_once(['x', 'X']).ok_or_else(bad)?;
        let (w, h): (u32, u32) = (
            w.trim().parse().map_err(|_| bad())?,
            h.trim().parse().map_err(|_| bad())?,
        );
        if w == 0 || h == 0 || w > MAX_SIDE || h > MAX_SIDE {
            return Err(bad());
        }
        Ok(Res(w, h))
    }
}

/// The settings keys, shared by the defaults and the jobs (serde cannot refuse unknown
/// keys through `flatten`, so each table lists them).
#[derive(Clone, Debug, Default)]
struct Keys {
    output: Option<String>,
    backend: Option<BackendName>,
    res: Option<Res>,
    spp: Option<u32>,
    max_depth: Option<u32>,
    spd: Option<bool>,
    encoding: Option<EncodingName>,
}

macro_rules! table {
    ($(#[$m:meta])* $name:ident { $($extra:ident : $t:ty),* }) => {
        $(#[$m])*
        #[derive(Debug, Deserialize)]
        #[serde(deny_unknown_fields)]
        struct $name {
            $($extra: $t,)*
            output: Option<String>,
            backend: Option<BackendName>,
            res: Option<Res>,
            spp: Option<u32>,
            max_depth: Option<u32>,
            spd: Option<bool>,
            encoding: Option<EncodingName>,
        }

        impl $name {
            fn keys(&self) -> Keys {
                Keys {
                    output: self.output.clone(),
                    backend: self.backend,
                    res: self.res,
                    spp: self.spp,
                    max_depth: self.max_depth,
                    spd: self.spd,
                    encoding: self.encoding,
                }
            }
        }
    };
}

table!(
    /// One `[[job]]`.
    JobEntry { scene: String, name: Option<String> }
);
table!(
    /// The whole file: the defaults and the jobs.
    File { job: Option<Vec<JobEntry>> }
);

/// Command-line settings that override every job's.
#[derive(Clone, Debug, Default)]
pub struct Overrides {
    /// Output template.
    pub output: Option<String>,
    /// Backend.
    pub backend: Option<Backend>,
    /// Image size.
    pub res: Option<(u32, u32)>,
    /// Samples per pixel.
    pub spp: Option<u32>,
    /// Maximum depth.
    pub max_depth: Option<u32>,
    /// SPD mode (only `true` overrides).
    pub spd: bool,
    /// PNG encoding.
    pub encoding: Option<Encoding>,
}

/// Read the jobs of the manifest at `path`. Errors are `path:line:col: message`.
pub fn load(path: &Path, cli: &Overrides) -> Result<Vec<Job>, LoadError> {
    let file: File = crate::load::toml::parse_toml_file(path)?;
    let whole = |message: String| LoadError {
        path: path.to_path_buf(),
        line: 0,
        col: 0,
        message,
    };
    let entries = file.job.as_deref().unwrap_or_default();
    if entries.is_empty() {
        return Err(whole("no [[job]] in the manifest".into()));
    }
    let base = path.parent().unwrap_or(Path::new(""));
    let d = &file.keys();
    let mut jobs = Vec::with_capacity(entries.len());
    for (i, j) in entries.iter().enumerate() {
        let k = &j.keys();
        for (what, v) in [
            ("spp", k.spp.or(d.spp)),
            ("max_depth", k.max_depth.or(d.max_depth)),
        ] {
            let max = if what == "spp" { 65536 } else { 64 };
            if v.is_some_and(|v| v == 0 || v > max) {
                return Err(whole(format!("job {i}: {what} must be in 1..={max}")));
            }
        }
        let settings = JobSettings {
            backend: cli.backend.or(k.backend.or(d.backend).map(|b| match b {
                BackendName::Embree => Backend::Embree,
                BackendName::Bvh => Backend::Bvh,
            })),
            render: RenderRequest {
                res: cli.res.or(k.res.or(d.res).map(|r| (r.0, r.1))),
                spp: cli.spp.or(k.spp).or(d.spp),
                max_depth: cli.max_depth.or(k.max_depth).or(d.max_depth),
                spd: cli.spd || k.spd.or(d.spd).unwrap_or(false),
                ..RenderRequest::default()
            },
            encoding: cli.encoding.unwrap_or(match k.encoding.or(d.encoding) {
                Some(EncodingName::Linear) => Encoding::Linear,
                _ => Encoding::Srgb,
            }),
        };
        let scene = if j.scene.starts_with("spd:") {
            PathBuf::from(&j.scene)
        } else {
            base.join(&j.scene)
        };
        let template = cli
            .output
            .clone()
            .or_else(|| k.output.clone())
            .or_else(|| d.output.clone())
            .unwrap_or_else(|| "{stem}.png".into());
        let out = job_output(&template, &scene, &settings, i)
            .map_err(|e| whole(format!("job {i}: {e}")))?;
        let output = if cli.output.is_some() {
            PathBuf::from(&out)
        } else {
            base.join(&out)
        };
        jobs.push(Job {
            name: j
                .name
                .clone()
                .unwrap_or_else(|| output.to_string_lossy().into_owned()),
            scene,
            output,
            settings,
        });
    }
    Ok(jobs)
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
             [[job]]\nname = \"g\"\nscene = \"spd:gears?size=1\"\nspp = 4\noutput = \"g.exr\"\n",
        );
        let jobs = load(&p, &Overrides::default()).unwrap();
        assert_eq!(jobs.len(), 2);
        assert_eq!(jobs[0].scene, dir.path().join("a.nff"));
        assert_eq!(jobs[0].output, dir.path().join("out/a-bvh.png"));
        assert_eq!(jobs[0].name, jobs[0].output.to_string_lossy());
        assert_eq!(jobs[0].settings.render.res, Some((32, 16)));
        assert_eq!(jobs[1].name, "g");
        assert_eq!(jobs[1].scene, PathBuf::from("spd:gears?size=1"));
        assert_eq!(jobs[1].settings.render.spp, Some(4));
        let cli = Overrides {
            spp: Some(2),
            ..Overrides::default()
        };
        assert!(
            load(&p, &cli)
                .unwrap()
                .iter()
                .all(|j| j.settings.render.spp == Some(2))
        );
    }

    #[test]
    fn errors_name_the_line() {
        let dir = tempfile::tempdir().unwrap();
        let p = write(dir.path(), "[[job]]\nscene = \"a.nff\"\nres = \"big\"\n");
        let e = load(&p, &Overrides::default()).unwrap_err().to_string();
        assert!(e.contains("jobs.toml:3:"), "{e}");
        assert!(e.contains("WxH"), "{e}");
        let p = write(dir.path(), "[[job]]\nscene = \"a.nff\"\nspeed = 3\n");
        let e = load(&p, &Overrides::default()).unwrap_err().to_string();
        assert!(e.contains("jobs.toml:"), "{e}");
        assert!(e.contains("speed"), "{e}");
        let p = write(dir.path(), "output = \"x.png\"\n");
        assert!(
            load(&p, &Overrides::default())
                .unwrap_err()
                .to_string()
                .contains("no [[job]]")
        );
    }
}
