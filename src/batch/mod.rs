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

pub use runner::{
    BatchOptions, BatchReport, Cancel, JobPhase, JobRecord, JobStatus, Observer, run,
};

use crate::job::template::TemplateError;
use crate::job::{Band, Job, JobError, RenderOptions, SceneSource};
use crate::output::OutputError;
use std::path::PathBuf;

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
    /// A job that cannot be done, or two jobs writing one file.
    #[error(transparent)]
    Job(#[from] JobError),
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
pub fn parse_shard(s: &str) -> Result<Band, String> {
    Band::parse("shard", s)
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

/// The jobs rendering `scenes` with `options` to the images `template` names, each
/// named by its image's path.
pub fn jobs_from_scenes(
    scenes: &[PathBuf],
    template: &str,
    options: &RenderOptions,
) -> Result<Vec<Job>, BatchError> {
    let sources = scenes.iter().cloned().map(SceneSource::File).collect();
    let mut jobs = crate::job::plan(sources, Some(template), options)?;
    for job in &mut jobs {
        if let Some(image) = &job.outputs.image {
            job.name = image.display().to_string();
        }
    }
    Ok(jobs)
}

/// Refuse a batch whose jobs share a name or a file, or cannot be done (a scene spec
/// that names no database, options out of range, an unsupported format), before
/// anything runs.
pub fn check_jobs(jobs: &[Job]) -> Result<(), BatchError> {
    let mut names = std::collections::HashMap::new();
    for (i, j) in jobs.iter().enumerate() {
        j.check()?;
        if let Some(k) = names.insert(j.name.as_str(), i) {
            return Err(BatchError::SameName {
                first: k,
                second: i,
                name: j.name.clone(),
            });
        }
    }
    crate::job::check_distinct(jobs)?;
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
    fn jobs_name_their_outputs_with_their_options() {
        let o = RenderOptions {
            backend: Some(crate::accel::Backend::Bvh),
            spp: Some(4),
            ..RenderOptions::default()
        };
        let p = PathBuf::from("dir/balls.nff");
        let jobs = jobs_from_scenes(
            &[p.clone(), p.clone(), p.clone(), p.clone()],
            "out/{stem}-{backend}-{spp}-{index}.exr",
            &o,
        )
        .unwrap();
        assert_eq!(jobs[3].name, "out/balls-bvh-4-3.exr");
        let e = jobs_from_scenes(&[p], "{colour}.png", &o).unwrap_err();
        assert!(
            e.to_string().contains("unknown placeholder '{colour}'"),
            "{e}"
        );
    }

    #[test]
    fn shards_parse() {
        assert_eq!(parse_shard("2/5"), Ok(Band { index: 2, count: 5 }));
        assert_eq!(
            parse_shard("5/5").unwrap_err(),
            "shard '5/5': need 0 <= I < N"
        );
        assert!(parse_shard("1/0").is_err());
        assert!(parse_shard("x").is_err());
    }

    #[test]
    fn duplicate_names_and_outputs_are_refused() {
        let job = |name: &str, out: &str| {
            let mut j = Job::render(
                SceneSource::File("a.nff".into()),
                RenderOptions::default(),
                Some(out.into()),
            );
            j.name = name.into();
            j
        };
        let e = check_jobs(&[job("a", "a.png"), job("a", "b.png")]).unwrap_err();
        assert_eq!(e.to_string(), "jobs 0 and 1 have the same name 'a'");
        let e = check_jobs(&[job("a", "a.png"), job("b", "a.png")]).unwrap_err();
        assert_eq!(
            e.to_string(),
            "a and b would both write a.png: use an output template that tells them apart"
        );
    }
}
