//! The jobs of `emray render`: each scene with the files its render writes, named by
//! the output templates (`-o`, `--heatmap`; the template language of `emray batch`,
//! [`emray::job::template`]), and the check, made before any work, that no two of them
//! are one file.

use super::insight::HeatmapArg;
use super::render::Args;
use anyhow::{Result, bail};
use emray::accel::Backend;
use emray::job::template::{OUTPUT_KEYS, OutputName, has_placeholder};
use emray::output::heatmap::Quantity;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// The output template when `-o` is not given.
const DEFAULT_OUTPUT: &str = "{stem}.png";
/// The `{stem}` of the built-in default scene.
const DEFAULT_STEM: &str = "emray";

/// One render: the scene (`None` = the built-in default), its image and its heat maps.
#[derive(Clone, Debug, PartialEq)]
pub struct Job {
    /// The scene file or `spd:` spec.
    pub scene: Option<PathBuf>,
    /// The image (with the output variables of `--aov` when it asks for some).
    pub out: PathBuf,
    /// The heat maps of `--heatmap`.
    pub heatmaps: Vec<(Quantity, PathBuf)>,
}

impl Job {
    /// Every file the job writes: the image, its ids file (`--aov id`), the heat maps.
    pub fn files(&self, args: &Args) -> Vec<PathBuf> {
        let mut files = vec![self.out.clone()];
        if args.aov.is_some_and(|s| s.id) {
            files.push(emray::output::aov::ids_path(&self.out));
        }
        files.extend(self.heatmaps.iter().map(|(_, f)| f.clone()));
        files
    }
}

/// The jobs of the scenes of `args` (the default scene when there are none) rendered
/// by `backend`, with their files named by the templates.
pub fn plan(args: &Args, maps: &[HeatmapArg], backend: Backend) -> Result<Vec<Job>> {
    let template = args.output.as_deref().unwrap_or(DEFAULT_OUTPUT);
    let several = args.scenes.len() > 1;
    if several && !has_placeholder("output template", template, OUTPUT_KEYS)? {
        bail!(
            "{} scenes but one output file '{template}': use a template such as '{{stem}}.png'",
            args.scenes.len()
        );
    }
    let scenes: Vec<Option<PathBuf>> = match args.scenes.as_slice() {
        [] => vec![None],
        s => s.iter().cloned().map(Some).collect(),
    };
    scenes
        .into_iter()
        .enumerate()
        .map(|(index, scene)| job(args, template, maps, backend, index, scene))
        .collect()
}

/// The job of `scene`, the `index`th: its files named by `template` and the heat maps'.
fn job(
    args: &Args,
    template: &str,
    maps: &[HeatmapArg],
    backend: Backend,
    index: usize,
    scene: Option<PathBuf>,
) -> Result<Job> {
    let name = OutputName {
        scene: scene.as_deref().unwrap_or(Path::new(DEFAULT_STEM)),
        backend,
        index,
        spp: args.spp,
    };
    let out = PathBuf::from(name.expand(template)?);
    let heatmaps = maps
        .iter()
        .map(|m| Ok((m.quantity, PathBuf::from(name.expand(&m.file)?))))
        .collect::<Result<_>>()?;
    Ok(Job {
        scene,
        out,
        heatmaps,
    })
}

/// Refuse, before any render, two files of the jobs that are one (two scenes, or an
/// image and a heat map, named alike).
pub fn check_distinct(args: &Args, jobs: &[Job]) -> Result<()> {
    let mut seen: HashMap<PathBuf, usize> = HashMap::new();
    for (k, job) in jobs.iter().enumerate() {
        for file in job.files(args) {
            let Some(first) = seen.insert(file.clone(), k) else {
                continue;
            };
            let scene = |j: &Job| match &j.scene {
                Some(s) => s.display().to_string(),
                None => "the default scene".into(),
            };
            if first == k {
                bail!(
                    "{} would write {} twice: give each output a name of its own",
                    scene(job),
                    file.display()
                );
            }
            bail!(
                "{} and {} would both write {}: use an output template that tells them apart",
                scene(&jobs[first]),
                scene(job),
                file.display()
            );
        }
    }
    Ok(())
}
