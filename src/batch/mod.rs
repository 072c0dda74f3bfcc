//! Batch rendering: many scenes in one run, each job isolated from the others' failures,
//! resumable, and split across machines by shards with no coordination.
//!
//! A batch is a list of [`Job`]s (from scene paths, globs or a TOML manifest,
//! [`manifest`]); [`run`] renders them one after another (or `jobs` at a time sharing
//! the threads), writes a JSON [`BatchReport`] after every job, tells an [`Observer`]
//! how far it is, and stops cleanly when its [`Cancel`] flag is set (the command sets
//! it on Ctrl-C). A job's shard is a stable hash of its name ([`shard_of`]); parts of
//! one image rendered apart are put together by [`merge`].

pub mod manifest;
pub mod merge;
mod runner;

pub use runner::{BatchOptions, BatchReport, Cancel, JobRecord, JobStatus, Observer, run};

use crate::accel::Backend;
use crate::job::template::{OutputName, TemplateError};
use crate::job::{IndexOfError, RenderRequest, parse_index_of};
use crate::output::{Encoding, OutputError};
use crate::spd::Database;
use std::path::{Path, PathBuf};

/// How one job renders.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct JobSettings {
    /// Ray-query backend (default: Embree when built in, else the BVH).
    pub backend: Option<Backend>,
    /// What the render asks for besides the scene (resolution, spp, depth, SPD mode).
    pub render: RenderRequest,
    /// PNG value encoding.
    pub encoding: Encoding,
}

impl JobSettings {
    /// The backend this job uses.
    pub fn backend(&self) -> Backend {
        self.backend.unwrap_or_else(Backend::default_available)
    }
}

/// One render of a batch.
#[derive(Clone, Debug, PartialEq)]
pub struct Job {
    /// Stable name (default: the output path as given); the shard hashes it.
    pub name: String,
    /// Scene file, or a generated `spd:NAME[?size=N]` scene.
    pub scene: PathBuf,
    /// Output image (.png or .exr).
    pub output: PathBuf,
    /// How to render.
    pub settings: JobSettings,
}

/// Why a batch cannot be put together: found before any job runs.
#[derive(Debug, thiserror::Error)]
pub enum BatchError {
    /// An output template that cannot be expanded.
    #[error(transparent)]
    Template(#[from] TemplateError),
    /// A scene argument that is not a valid glob.
    #[error("bad glob '{pattern}': {message}")]
    BadGlob {
        /// The argument.
        pattern: String,
        /// What is wrong with it.
        message: String,
    },
    /// A glob that matches nothing.
    #[error("glob '{0}' matches no file")]
    NoMatch(String),
    /// An `spd:` scene spec that names no database or a size it cannot generate.
    #[error("{0}")]
    Spec(#[from] crate::spd::SpecError),
    /// An output file of an unsupported format.
    #[error(transparent)]
    Output(#[from] OutputError),
    /// Two jobs with one name.
    #[error("jobs {first} and {second} have the same name '{name}'")]
    SameName {
        /// The first job's index.
        first: usize,
        /// The second job's index.
        second: usize,
        /// Their name.
        name: String,
    },
    /// Two jobs writing one file.
    #[error(
        "jobs {first} and {second} write the same file '{}' (use {{stem}}, {{backend}} or \
         {{index}} in the template)",
        output.display()
    )]
    SameOutput {
        /// The first job's index.
        first: usize,
        /// The second job's index.
        second: usize,
        /// Their output file.
        output: PathBuf,
    },
}

/// The output file of the job `index` rendering `scene` with `settings`, from
/// `template` (the placeholders of [`OutputName`]).
pub fn job_output(
    template: &str,
    scene: &Path,
    settings: &JobSettings,
    index: usize,
) -> Result<String, TemplateError> {
    OutputName {
        scene,
        backend: settings.backend(),
        index,
        spp: settings.render.spp,
    }
    .expand(template)
}

/// The 64-bit FNV-1a hash of `bytes`: fixed by its definition, the same on every
/// machine, platform and version.
pub fn fnv1a64(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in bytes {
        h ^= b as u64;
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

/// The shard (0..count) of the job named `name`: FNV-1a 64 of the name's UTF-8 bytes,
/// modulo `count`. It depends on the name alone, not on the job's position, so
/// reordering or editing other jobs moves no job between shards.
pub fn shard_of(name: &str, count: u32) -> u32 {
    (fnv1a64(name.as_bytes()) % count.max(1) as u64) as u32
}

/// Parse `--shard I/N` (shard `I` of `N`, `0 <= I < N`).
pub fn parse_shard(s: &str) -> Result<(u32, u32), IndexOfError> {
    parse_index_of("shard", s)
}

/// Expand scene arguments: an argument holding `*`, `?` or `[` is a glob (sorted
/// matches; none is an error), anything else a path or `spd:` spec taken as it is.
pub fn expand_scene_args(args: &[PathBuf]) -> Result<Vec<PathBuf>, BatchError> {
    let mut out = Vec::new();
    for a in args {
        let s = a.to_string_lossy();
        if s.starts_with("spd:") || !s.contains(['*', '?', '[']) {
            out.push(a.clone());
            continue;
        }
        let paths = glob::glob(&s).map_err(|e| BatchError::BadGlob {
            pattern: s.to_string(),
            message: e.to_string(),
        })?;
        let mut matched: Vec<PathBuf> = paths.filter_map(Result::ok).collect();
        if matched.is_empty() {
            return Err(BatchError::NoMatch(s.to_string()));
        }
        matched.sort();
        out.extend(matched);
    }
    Ok(out)
}

/// The jobs for scene arguments rendered to `template` with `settings`.
pub fn jobs_from_scenes(
    scenes: &[PathBuf],
    template: &str,
    settings: &JobSettings,
) -> Result<Vec<Job>, BatchError> {
    scenes
        .iter()
        .enumerate()
        .map(|(i, s)| {
            let out = job_output(template, s, settings, i)?;
            Ok(Job {
                name: out.clone(),
                scene: s.clone(),
                output: PathBuf::from(out),
                settings: settings.clone(),
            })
        })
        .collect()
}

/// Refuse a batch whose jobs share a name or an output file, or write an unsupported
/// format, before anything runs.
pub fn check_jobs(jobs: &[Job]) -> Result<(), BatchError> {
    let mut names = std::collections::HashMap::new();
    let mut outputs = std::collections::HashMap::new();
    for (i, j) in jobs.iter().enumerate() {
        crate::output::Format::from_path(&j.output)?;
        Database::parse_spec(&j.scene.to_string_lossy()).map_err(BatchError::Spec)?;
        if let Some(k) = names.insert(j.name.as_str(), i) {
            return Err(BatchError::SameName {
                first: k,
                second: i,
                name: j.name.clone(),
            });
        }
        if let Some(k) = outputs.insert(j.output.as_path(), i) {
            return Err(BatchError::SameOutput {
                first: k,
                second: i,
                output: j.output.clone(),
            });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fnv_matches_the_published_vectors() {
        assert_eq!(fnv1a64(b""), 0xcbf2_9ce4_8422_2325);
        assert_eq!(fnv1a64(b"a"), 0xaf63_dc4c_8601_ec8c);
        assert_eq!(fnv1a64(b"foobar"), 0x8594_4171_f739_67e8);
    }

    #[test]
    fn jobs_name_their_outputs_with_their_settings() {
        let s = JobSettings {
            backend: Some(Backend::Bvh),
            render: RenderRequest {
                spp: Some(4),
                ..RenderRequest::default()
            },
            ..JobSettings::default()
        };
        let p = Path::new("dir/balls.nff");
        assert_eq!(
            job_output("out/{stem}-{backend}-{spp}-{index}.exr", p, &s, 3).unwrap(),
            "out/balls-bvh-4-3.exr"
        );
        let e = jobs_from_scenes(&[p.to_path_buf()], "{colour}.png", &s).unwrap_err();
        assert!(
            e.to_string().contains("unknown placeholder '{colour}'"),
            "{e}"
        );
    }

    #[test]
    fn shards_parse() {
        assert_eq!(parse_shard("2/5"), Ok((2, 5)));
        assert_eq!(
            parse_shard("5/5").unwrap_err().to_string(),
            "shard '5/5': need 0 <= I < N"
        );
        assert!(parse_shard("1/0").is_err());
        assert!(parse_shard("x").is_err());
    }

    #[test]
    fn duplicate_names_and_outputs_are_refused() {
        let job = |name: &str, out: &str| Job {
            name: name.into(),
            scene: "a.nff".into(),
            output: out.into(),
            settings: JobSettings::default(),
        };
        let e = check_jobs(&[job("a", "a.png"), job("a", "b.png")]).unwrap_err();
        assert_eq!(e.to_string(), "jobs 0 and 1 have the same name 'a'");
        let e = check_jobs(&[job("a", "a.png"), job("b", "a.png")]).unwrap_err();
        assert_eq!(
            e.to_string(),
            "jobs 0 and 1 write the same file 'a.png' (use {stem}, {backend} or {index} in \
             the template)"
        );
    }
}
