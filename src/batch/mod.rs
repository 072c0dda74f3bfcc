//! Batch rendering: many scenes in one run, each job isolated from the others' failures,
//! resumable, and split across machines by shards with no coordination.
//!
//! A batch is a list of [`Job`]s (from scene paths, globs or a TOML manifest,
//! [`manifest`]); [`run`] renders them one after another (or `jobs` at a time sharing
//! the threads), writes a JSON [`BatchReport`] after every job, and stops cleanly on
//! Ctrl-C. A job's shard is a stable hash of its name ([`shard_of`]).

pub mod limits;
pub mod manifest;
pub mod merge;
mod runner;

pub use runner::{BatchOptions, BatchReport, JobRecord, JobStatus, run};

use crate::Scene;
use crate::accel::Backend;
use crate::load;
use crate::output::Encoding;
use crate::render::{Region, RenderSettings};
use crate::spd::Database;
use std::path::{Path, PathBuf};

/// How one job renders; `None` leaves the scene's or the renderer's default.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct JobSettings {
    /// Ray-query backend (default: Embree when built in, else the BVH).
    pub backend: Option<Backend>,
    /// Image size, overriding the scene's.
    pub res: Option<(u32, u32)>,
    /// Samples per pixel (default: the scene file's, else 1).
    pub spp: Option<u32>,
    /// Maximum ray-tree depth (default: the scene file's, else 5).
    pub max_depth: Option<u32>,
    /// SPD testing mode (512×512 unless `res` is given, 1 spp, depth 5).
    pub spd: bool,
    /// PNG value encoding.
    pub encoding: Encoding,
}

impl JobSettings {
    /// The backend this job uses.
    pub fn backend(&self) -> Backend {
        self.backend.unwrap_or_else(Backend::default_available)
    }

    /// The render settings for `scene`: the scene's own, overridden by these, with the
    /// command line's defaults (the default bailout, none in SPD mode).
    pub fn apply(&self, scene: &Scene) -> RenderSettings {
        let mut s = RenderSettings::for_scene(scene);
        if let Some((w, h)) = self.res {
            s.width = w;
            s.height = h;
        }
        s.spp = self.spp.or(scene.render.spp).unwrap_or(1);
        s.bailout = crate::render::DEFAULT_BAILOUT;
        s.max_depth = self.max_depth.or(scene.render.max_depth).unwrap_or(5);
        if self.spd {
            // SPD testing mode: 512x512 from a 513x513 corner grid, depth 5, one sample.
            if self.res.is_none() {
                s.width = 512;
                s.height = 512;
            }
            s.spd = true;
            s.spp = 1;
            s.max_depth = 5;
            s.bailout = 0.0;
        }
        s
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

/// Load a scene file or generate an `spd:NAME[?size=N]` scene; errors name the file
/// (and line and column where there is one).
pub fn load_scene(spec: &Path) -> Result<Scene, String> {
    let name = spec.to_string_lossy();
    match Database::parse_spec(&name)? {
        Some((db, size)) => {
            load::nff::parse_str(&db.generate(size), spec).map_err(|e| e.to_string())
        }
        None => load::load_path(spec).map_err(|e| e.to_string()),
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

/// The placeholders an output template may use.
pub const TEMPLATE_KEYS: &[&str] = &["stem", "backend", "index", "spp"];

/// Expand an output template: `{stem}` (scene file stem), `{backend}`, `{index}` (the
/// job's position in the batch, from 0) and `{spp}`. An unknown `{key}` is an error.
pub fn expand_template(
    template: &str,
    scene: &Path,
    settings: &JobSettings,
    index: usize,
) -> Result<String, String> {
    let mut out = String::with_capacity(template.len() + 16);
    let mut rest = template;
    while let Some(open) = rest.find('{') {
        out.push_str(&rest[..open]);
        let after = &rest[open + 1..];
        let close = after
            .find('}')
            .ok_or_else(|| format!("output template '{template}': '{{' without '}}'"))?;
        let key = &after[..close];
        match key {
            "stem" => out.push_str(&scene_stem(scene)),
            "backend" => out.push_str(settings.backend().name()),
            "index" => out.push_str(&index.to_string()),
            "spp" => out.push_str(&settings.spp.unwrap_or(1).to_string()),
            _ => {
                return Err(format!(
                    "output template '{template}': unknown placeholder '{{{key}}}' (one of {})",
                    TEMPLATE_KEYS
                        .iter()
                        .map(|k| format!("{{{k}}}"))
                        .collect::<Vec<_>>()
                        .join(", ")
                ));
            }
        }
        rest = &after[close + 1..];
    }
    out.push_str(rest);
    Ok(out)
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

/// Parse `I/N` (0 ≤ I < N).
pub fn parse_shard(s: &str) -> Result<(u32, u32), String> {
    let (i, n) = s
        .split_once('/')
        .ok_or_else(|| format!("shard '{s}' is not I/N (e.g. 0/4)"))?;
    let i: u32 = i
        .trim()
        .parse()
        .map_err(|_| format!("bad shard index in '{s}'"))?;
    let n: u32 = n
        .trim()
        .parse()
        .map_err(|_| format!("bad shard count in '{s}'"))?;
    if n == 0 || i >= n {
        return Err(format!("shard '{s}': need 0 <= I < N"));
    }
    Ok((i, n))
}

/// Parse a crop `x0,x1,y0,y1` (pixel columns x0..x1 and rows y0..y1, half-open).
pub fn parse_crop(s: &str) -> Result<Region, String> {
    let v: Vec<u32> = s
        .split(',')
        .map(|t| t.trim().parse::<u32>())
        .collect::<Result<_, _>>()
        .map_err(|_| format!("crop '{s}' is not x0,x1,y0,y1 (four whole numbers)"))?;
    let [x0, x1, y0, y1] = v[..] else {
        return Err(format!(
            "crop '{s}' is not x0,x1,y0,y1 (four whole numbers)"
        ));
    };
    if x0 >= x1 || y0 >= y1 {
        return Err(format!("crop '{s}': need x0 < x1 and y0 < y1"));
    }
    Ok(Region { x0, x1, y0, y1 })
}

/// Expand scene arguments: an argument holding `*`, `?` or `[` is a glob (sorted
/// matches; none is an error), anything else a path or `spd:` spec taken as it is.
pub fn expand_scene_args(args: &[PathBuf]) -> Result<Vec<PathBuf>, String> {
    let mut out = Vec::new();
    for a in args {
        let s = a.to_string_lossy();
        if s.starts_with("spd:") || !s.contains(['*', '?', '[']) {
            out.push(a.clone());
            continue;
        }
        let paths = glob::glob(&s).map_err(|e| format!("bad glob '{s}': {e}"))?;
        let mut matched: Vec<PathBuf> = paths.filter_map(Result::ok).collect();
        if matched.is_empty() {
            return Err(format!("glob '{s}' matches no file"));
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
) -> Result<Vec<Job>, String> {
    scenes
        .iter()
        .enumerate()
        .map(|(i, s)| {
            let out = expand_template(template, s, settings, i)?;
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
pub fn check_jobs(jobs: &[Job]) -> Result<(), String> {
    let mut names = std::collections::HashMap::new();
    let mut outputs = std::collections::HashMap::new();
    for (i, j) in jobs.iter().enumerate() {
        crate::output::Format::from_path(&j.output).map_err(|e| e.to_string())?;
        Database::parse_spec(&j.scene.to_string_lossy())?;
        if let Some(k) = names.insert(j.name.as_str(), i) {
            return Err(format!("jobs {k} and {i} have the same name '{}'", j.name));
        }
        if let Some(k) = outputs.insert(j.output.as_path(), i) {
            return Err(format!(
                "jobs {k} and {i} write the same file '{}' (use {{stem}}, {{backend}} or {{index}} in the template)",
                j.output.display()
            ));
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
    fn templates_expand_and_refuse_unknown_keys() {
        let s = JobSettings {
            backend: Some(Backend::Bvh),
            spp: Some(4),
            ..JobSettings::default()
        };
        let p = Path::new("dir/balls.nff");
        assert_eq!(
            expand_template("out/{stem}-{backend}-{spp}-{index}.exr", p, &s, 3).unwrap(),
            "out/balls-bvh-4-3.exr"
        );
        assert_eq!(
            expand_template("{stem}.png", Path::new("spd:gears?size=2"), &s, 0).unwrap(),
            "gears_s2.png"
        );
        assert!(
            expand_template("{colour}.png", p, &s, 0)
                .unwrap_err()
                .contains("unknown placeholder")
        );
        assert!(expand_template("{stem.png", p, &s, 0).is_err());
    }

    #[test]
    fn shards_and_crops_parse() {
        assert_eq!(parse_shard("2/5"), Ok((2, 5)));
        assert!(parse_shard("5/5").is_err());
        assert!(parse_shard("1/0").is_err());
        assert!(parse_shard("x").is_err());
        assert_eq!(
            parse_crop("1,5,2,9"),
            Ok(Region {
                x0: 1,
                x1: 5,
                y0: 2,
                y1: 9
            })
        );
        assert!(parse_crop("5,1,2,9").is_err());
        assert!(parse_crop("1,2,3").is_err());
    }

    #[test]
    fn bands_cover_every_row_once() {
        for n in 1..=9 {
            let mut next = 0;
            for i in 0..n {
                let r = Region::band(i, n, 7, 23);
                assert_eq!(r.y0, next);
                next = r.y1;
            }
            assert_eq!(next, 23);
        }
    }
}
