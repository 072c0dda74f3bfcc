//! One job from its scene to its written files: [`run`] (or its two halves,
//! [`render`] and [`write`], for a caller that must do something between them, as a
//! batch does). Every command that renders calls it; so does a program embedding the
//! library.
//!
//! The phases, each reported to the [`Observer`]: load the scene (the environment map
//! replaced if asked), resolve the options against it ([`super::resolve`]), check the
//! memory the render needs ([`super::limits`]), build the backend
//! ([`crate::accel::build`], timed), do the task ([`super::work`]: render, explain a
//! pixel, view a radiosity solution; or the f64 reference, which needs no backend),
//! then write the image, its output variables, heat maps, mesh and statistics line.

use super::limits::{self, MemoryLimitError};
use super::options::{Gi, RenderOptions};
use super::report::Report;
use super::resolve::{OptionsError, Resolved};
use super::source::{SceneError, SceneSource};
use super::template::{OUTPUT_KEYS, OutputName, TemplateError, has_placeholder};
use super::work::{Product, Work, reference};
use crate::accel::{self, AccelError, AccelStats};
use crate::load::LoadProgress;
use crate::output::part::PartInfo;
use crate::output::{self, Format, OutputError};
use crate::radiosity::RadiosityError;
use crate::render::aov::AovError;
use crate::render::aov::AovFilm;
use crate::render::explain::ExplainError;
use crate::render::{Film, RayCounts};
use crate::scene::Scene;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// What a job makes.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Task {
    /// An image (with the output variables and heat maps the options ask for).
    Render,
    /// The ray tree of pixel `(x, y)` (`emray explain`).
    Explain {
        /// Column, from 0 at the left.
        x: u32,
        /// Row, from 0 at the top.
        y: u32,
    },
    /// A view of the scene's radiosity solution itself (`emray radiosity`), and its
    /// mesh as PLY when [`Outputs::ply`] names a file.
    RadiosityView,
}

impl Task {
    /// What the task assumes unless the options say otherwise: a radiosity view solves
    /// the radiosity and views it with 4 samples per pixel.
    fn defaults(&self) -> RenderOptions {
        match self {
            Task::RadiosityView => RenderOptions {
                gi: Some(Gi::Radiosity),
                spp: Some(4),
                ..RenderOptions::default()
            },
            _ => RenderOptions::default(),
        }
    }
}

/// The files a job writes.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Outputs {
    /// The image (`.png` or `.exr`; the output variables go into the EXR); `None` keeps
    /// it in memory only.
    pub image: Option<PathBuf>,
    /// The heat maps, one for each `WHAT FILE` pair of the options, in their order.
    pub heatmaps: Vec<PathBuf>,
    /// The radiosity mesh with vertex colours, as PLY.
    pub ply: Option<PathBuf>,
    /// A file the job's report is appended to, as one JSON line.
    pub stats_json: Option<PathBuf>,
}

/// One job: a scene, the options, the task and the files it writes.
#[derive(Clone, Debug, PartialEq)]
pub struct Job {
    /// Its name in reports (a batch's shards hash it).
    pub name: String,
    /// The scene.
    pub scene: SceneSource,
    /// What the render asks for besides the scene.
    pub options: RenderOptions,
    /// What it makes.
    pub task: Task,
    /// The files it writes.
    pub outputs: Outputs,
}

/// Why a job failed.
#[derive(Debug, thiserror::Error)]
pub enum JobError {
    /// The scene could not be had.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// The options cannot be met (for this scene).
    #[error("{scene}: {error}")]
    Options {
        /// The scene's name.
        scene: String,
        /// What is wrong.
        error: OptionsError,
    },
    /// The job's files do not go together.
    #[error("{0}")]
    Outputs(String),
    /// An output template cannot be expanded.
    #[error(transparent)]
    Template(#[from] TemplateError),
    /// A file could not be written.
    #[error(transparent)]
    Output(#[from] OutputError),
    /// The render would need more memory than allowed.
    #[error(transparent)]
    Memory(#[from] MemoryLimitError),
    /// The backend could not be built.
    #[error(transparent)]
    Accel(#[from] AccelError),
    /// The radiosity pass failed.
    #[error(transparent)]
    Radiosity(#[from] RadiosityError),
    /// The output variables cannot be gathered.
    #[error(transparent)]
    Aov(#[from] AovError),
    /// The pixel cannot be explained.
    #[error(transparent)]
    Explain(#[from] ExplainError),
    /// The observer stopped the job ([`Observer::cancelled`]).
    #[error("{0}: the render was stopped")]
    Cancelled(String),
    /// The f64 reference cannot render the scene.
    #[error("{scene}: {why}")]
    Reference {
        /// The scene's name.
        scene: String,
        /// What it does not model.
        why: String,
    },
}

impl JobError {
    /// Whether the job was asked something it cannot do whatever its scene holds
    /// (options out of range or in conflict, files that do not go together, a pixel
    /// outside the image): a usage error, as opposed to a failure of the input or the
    /// machine. A part that does not fit the scene's image is the scene's failure.
    pub fn is_usage(&self) -> bool {
        match self {
            JobError::Options { error, .. } => !matches!(
                error,
                OptionsError::CropOutside { .. } | OptionsError::EmptyTile { .. }
            ),
            JobError::Outputs(_) | JobError::Template(_) => true,
            JobError::Scene(SceneError::Spec(_)) => true,
            JobError::Explain(ExplainError::Outside { .. }) => true,
            _ => false,
        }
    }
}

/// What a job reports as it goes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Event<'a> {
    /// Reading (or generating) the scene.
    Loading,
    /// `done` of `total` units of the scene are loaded: bytes of an NFF or OBJ file,
    /// primitives of a generated database. Told a few dozen times a second at most,
    /// from any thread, `done` growing, and `(total, total)` once the load is done;
    /// never for a TOML scene or the built-in one.
    Loaded {
        /// Units done.
        done: u64,
        /// Units in all.
        total: u64,
    },
    /// The options are resolved against the scene: the image is `width × height`.
    Resolved {
        /// Width in pixels.
        width: u32,
        /// Height in pixels.
        height: u32,
    },
    /// Building the backend.
    Building,
    /// Rendering (solving the radiosity first, in two-pass mode).
    Rendering,
    /// A tile is rendered, with its values (from the worker threads, in any order, each
    /// just before its [`Event::Tiles`]); in SPD mode the values are the pixel
    /// corners', and with adaptive antialiasing only the refined pixels are told.
    Tile(crate::render::TileValues<'a>),
    /// `done` of `total` tiles rendered: `(0, total)` first, then as tiles complete,
    /// from the worker threads in any order.
    Tiles {
        /// Tiles done.
        done: usize,
        /// Tiles in all.
        total: usize,
    },
    /// The render (or explanation, or view) is done.
    Rendered,
    /// Writing this file.
    Writing(&'a Path),
}

/// Told what a job is doing, from the job's thread and the renderer's worker threads.
pub trait Observer: Sync {
    /// `event` happened.
    fn event(&self, event: Event<'_>);

    /// Whether to stop the job: checked between its phases and before each tile; a
    /// job asked to stop ends with [`JobError::Cancelled`]. Never, by default.
    fn cancelled(&self) -> bool {
        false
    }
}

impl Observer for () {
    fn event(&self, _event: Event<'_>) {}
}

impl<F: Fn(Event<'_>) + Sync> Observer for F {
    fn event(&self, event: Event<'_>) {
        self(event)
    }
}

/// A rendered job, not yet written.
#[derive(Debug)]
pub struct Rendered {
    /// What it made.
    pub product: Product,
    /// What it reports.
    pub report: Report,
    /// What the backend reports about itself.
    pub accel: AccelStats,
    /// The rays cast, by type.
    pub rays: RayCounts,
    /// The options resolved against the scene.
    pub resolved: Resolved,
    /// The part of an image (`tile`, `crop`), for `emray merge`.
    pub part: Option<PartInfo>,
    /// Where the scene's zero lies in the world (the PLY mesh is written in world
    /// coordinates).
    pub origin: crate::math::DVec3,
}

impl Rendered {
    /// The image and its output variables, when the job made an image (a render or a
    /// radiosity view).
    pub fn image(&self) -> Option<(&Film, Option<&AovFilm>)> {
        match &self.product {
            Product::Image { film, aov } => Some((film, aov.as_deref())),
            Product::Radiosity { film, .. } => Some((film, None)),
            Product::Explanation(_) => None,
        }
    }
}

impl Job {
    /// A job rendering `scene` with `options` to the image `image`.
    pub fn render(scene: SceneSource, options: RenderOptions, image: Option<PathBuf>) -> Job {
        Job {
            name: scene.name(),
            scene,
            options,
            task: Task::Render,
            outputs: Outputs {
                image,
                ..Outputs::default()
            },
        }
    }

    /// The options with the task's own defaults under them.
    fn options(&self) -> RenderOptions {
        self.options.over(&self.task.defaults())
    }

    /// Every file the job writes (the statistics line is appended, not written): the
    /// image and, with the `id` variable, its ids file; the heat maps; the mesh.
    pub fn files(&self) -> Vec<PathBuf> {
        let o = &self.outputs;
        let mut files: Vec<PathBuf> = o.image.iter().cloned().collect();
        if let (Some(image), true) = (&o.image, self.options.aov.is_some_and(|a| a.0.id)) {
            files.push(output::aov::ids_path(image));
        }
        files.extend(o.heatmaps.iter().cloned());
        files.extend(o.ply.iter().cloned());
        files
    }

    /// What can be refused before any work: the scene spec, the options, and whether
    /// the files can hold what they are asked to.
    pub fn check(&self) -> Result<(), JobError> {
        self.scene.check()?;
        let options = self.options();
        options.check().map_err(|error| JobError::Options {
            scene: self.scene.name(),
            error,
        })?;
        let bad = |m: String| Err(JobError::Outputs(m));
        if options.heatmap.len() / 2 != self.outputs.heatmaps.len() {
            return bad("each --heatmap needs its file".into());
        }
        let Some(image) = &self.outputs.image else {
            return Ok(());
        };
        let format = Format::from_path(image).map_err(|e| JobError::Outputs(e.to_string()))?;
        if options.aov.is_some_and(|a| a.0.any()) && format != Format::Exr {
            return bad(format!(
                "--aov writes its layers beside the colour in an OpenEXR file, and '{}' is a \
                 PNG: name the output NAME.exr",
                image.display()
            ));
        }
        if (options.band.is_some() || options.crop.is_some()) && format != Format::Exr {
            return bad(format!(
                "--band and --crop write an EXR part (for emray merge), not '{}'",
                image.display()
            ));
        }
        Ok(())
    }

    /// Make sure every file can be written, before any work: create the folders, try
    /// each file's temporary file, open the statistics file for appending.
    pub fn prepare(&self) -> Result<(), JobError> {
        for f in self.files() {
            output::prepare(&f)?;
        }
        if let Some(s) = &self.outputs.stats_json {
            output::prepare_append(s)?;
        }
        Ok(())
    }
}

/// The jobs rendering `scenes` with `options`, their images and heat maps named by the
/// templates (`{stem}`, `{backend}`, `{index}`, `{spp}`; `image` `None`: `{stem}.png`).
/// Several scenes need a template with a placeholder.
pub fn plan(
    scenes: Vec<SceneSource>,
    image: Option<&str>,
    options: &RenderOptions,
) -> Result<Vec<Job>, JobError> {
    let template = image.unwrap_or("{stem}.png");
    if scenes.len() > 1 && !has_placeholder("output template", template, OUTPUT_KEYS)? {
        return Err(JobError::Outputs(format!(
            "{} scenes but one output file '{template}': use a template such as '{{stem}}.png'",
            scenes.len()
        )));
    }
    let heatmaps = options.heatmaps().map_err(|error| JobError::Options {
        scene: "--heatmap".into(),
        error,
    })?;
    let backend = options.backend_options().backend;
    scenes
        .into_iter()
        .enumerate()
        .map(|(index, scene)| {
            let path = scene.path().to_path_buf();
            let name = OutputName {
                scene: &path,
                backend,
                index,
                spp: options.spp,
            };
            let image = PathBuf::from(name.expand(template)?);
            let heatmaps = heatmaps
                .iter()
                .map(|h| Ok(PathBuf::from(name.expand(&h.template)?)))
                .collect::<Result<_, JobError>>()?;
            let mut job = Job::render(scene, options.clone(), Some(image));
            job.outputs.heatmaps = heatmaps;
            Ok(job)
        })
        .collect()
}

/// Refuse, before any work, two files of `jobs` that are one (two scenes, or an image
/// and a heat map, named alike).
pub fn check_distinct(jobs: &[Job]) -> Result<(), JobError> {
    let mut seen: HashMap<PathBuf, usize> = HashMap::new();
    for (k, job) in jobs.iter().enumerate() {
        for file in job.files() {
            let Some(first) = seen.insert(file.clone(), k) else {
                continue;
            };
            let message = if first == k {
                format!(
                    "{} would write {} twice: give each output a name of its own",
                    job.name,
                    file.display()
                )
            } else {
                format!(
                    "{} and {} would both write {}: use an output template that tells them apart",
                    jobs[first].name,
                    job.name,
                    file.display()
                )
            };
            return Err(JobError::Outputs(message));
        }
    }
    Ok(())
}

/// Run `job` from its scene to its written files; returns what it made and reports.
pub fn run(job: &Job, observer: &dyn Observer) -> Result<Rendered, JobError> {
    let rendered = render(job, observer)?;
    write(job, &rendered, observer)?;
    Ok(rendered)
}

/// Refuse a generated database too large for the memory limit before generating it
/// (its primitives counted without building them); the full estimate, with the
/// image's buffers, follows once the scene is there. Returns the primitives counted.
fn check_database_size(job: &Job, options: &RenderOptions) -> Result<Option<u64>, JobError> {
    let Some((db, size)) = job.scene.database() else {
        return Ok(None);
    };
    let count = db.count(size);
    let res = options.res.map_or(
        (count.res.0.max(0) as u32, count.res.1.max(0) as u32),
        |r| (r.width, r.height),
    );
    limits::check_generated(job.scene.path(), &count, res, options.memory_limit())?;
    Ok(Some(count.prims))
}

/// Load the job's scene, telling `observer` how far the load has come.
fn load(
    job: &Job,
    options: &RenderOptions,
    observer: &dyn Observer,
) -> Result<std::sync::Arc<Scene>, JobError> {
    let prims = check_database_size(job, options)?;
    let tell = |done, total| observer.event(Event::Loaded { done, total });
    let progress = LoadProgress::new(&tell);
    progress.expect(prims.unwrap_or(0));
    let scene = job.scene.load_with(options.envmap.as_deref(), &progress)?;
    progress.finish();
    Ok(scene)
}

/// The first half of [`run`]: load, resolve, check the memory, build and do the task;
/// nothing is written.
pub fn render(job: &Job, observer: &dyn Observer) -> Result<Rendered, JobError> {
    let name = job.scene.name();
    let options = job.options();
    observer.event(Event::Loading);
    let t0 = Instant::now();
    let scene = load(job, &options, observer)?;
    let load_ms = t0.elapsed().as_secs_f64() * 1e3;
    if observer.cancelled() {
        return Err(JobError::Cancelled(name));
    }
    let resolved = options.resolve(&scene).map_err(|error| JobError::Options {
        scene: name.clone(),
        error,
    })?;
    observer.event(Event::Resolved {
        width: resolved.settings.width,
        height: resolved.settings.height,
    });
    let extra = if resolved.wants_insight() {
        limits::aov_bytes(&resolved.settings)
    } else {
        0
    };
    limits::check(
        job.scene.path(),
        &scene,
        &resolved.settings,
        extra,
        resolved.max_memory,
    )?;
    let made = match resolved.reference {
        Some(strata) => {
            observer.event(Event::Rendering);
            let made =
                reference(&name, &scene, &resolved.settings, strata, load_ms).map_err(|why| {
                    JobError::Reference {
                        scene: name.clone(),
                        why: why.to_string(),
                    }
                })?;
            observer.event(Event::Rendered);
            made
        }
        None => {
            observer.event(Event::Building);
            let work = Work {
                name: &name,
                scene: &scene,
                resolved: &resolved,
                task: &job.task,
                load_ms,
                observer,
            };
            accel::build(&scene, &resolved.backend, work)??
        }
    };
    let part = part_info(&scene, &resolved);
    Ok(Rendered {
        product: made.product,
        report: made.report,
        accel: made.accel,
        rays: made.rays,
        resolved,
        part,
        origin: scene.origin,
    })
}

/// What an image part records for `emray merge`: the whole image's size, the part's
/// pixels and the hash of the render that every part must share.
fn part_info(scene: &Scene, resolved: &Resolved) -> Option<PartInfo> {
    let s = &resolved.settings;
    s.region.map(|region| PartInfo {
        full: (s.width, s.height),
        region,
        hash: Some(super::render_hash(scene, s, resolved.backend.backend)),
    })
}

/// The second half of [`run`]: write what `rendered` made to the job's files.
pub fn write(job: &Job, rendered: &Rendered, observer: &dyn Observer) -> Result<(), JobError> {
    let o = &job.outputs;
    let r = &rendered.resolved;
    match &rendered.product {
        Product::Image { film, aov } => {
            if let Some(path) = &o.image {
                observer.event(Event::Writing(path));
                let part = rendered.part.as_ref();
                match (aov, part) {
                    (Some(aov), _) if aov.set.any() => {
                        output::aov::write_exr_aov(path, film, aov, part)?
                    }
                    (_, Some(info)) => output::part::write_exr(path, film, Some(info))?,
                    (_, None) => output::write_image(path, film, r.encoding)?,
                }
                log::info!("wrote {}", path.display());
            }
            if let Some(aov) = aov {
                for (map, path) in r.heatmaps.iter().zip(&o.heatmaps) {
                    observer.event(Event::Writing(path));
                    output::heatmap::write_aov_heatmap(path, aov, map.quantity)?;
                    log::info!("wrote {}", path.display());
                }
            }
        }
        Product::Radiosity { film, solution, .. } => {
            if let Some(path) = &o.image {
                observer.event(Event::Writing(path));
                output::write_image(path, film, r.encoding)?;
            }
            if let Some(path) = &o.ply {
                observer.event(Event::Writing(path));
                output::write_text(path, &solution.to_ply(1.0, rendered.origin))?;
            }
        }
        Product::Explanation(_) => {}
    }
    if let Some(path) = &o.stats_json {
        match &rendered.product {
            Product::Radiosity { report, .. } => output::append_json_line(path, report)?,
            _ => output::append_json_line(path, &rendered.report)?,
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::Backend;
    use crate::job::values::Res;
    use glam::Vec3;
    use std::sync::Mutex;
    use std::sync::atomic::{AtomicUsize, Ordering};

    /// A 48×40 render of the default scene on the BVH (tiles of 16: 3×3 of them).
    fn job() -> Job {
        let options = RenderOptions {
            backend: Some(Backend::Bvh),
            res: Some(Res {
                width: 48,
                height: 40,
            }),
            ..RenderOptions::default()
        };
        Job::render(SceneSource::Builtin, options, None)
    }

    /// The tiles' values, put together, are the rendered image, pixel for pixel.
    #[test]
    fn the_tiles_told_make_the_image() {
        let told = Mutex::new(Film {
            width: 48,
            height: 40,
            pixels: vec![Vec3::splat(-1.0); 48 * 40],
        });
        let size = Mutex::new(None);
        let observer = |e: Event<'_>| {
            if let Event::Resolved { width, height } = e {
                *size.lock().unwrap() = Some((width, height));
            }
            if let Event::Tile(t) = e {
                let mut film = told.lock().unwrap();
                for (j, row) in (t.region.y0..t.region.y1).zip(t.rows()) {
                    for (i, &v) in (t.region.x0..t.region.x1).zip(row) {
                        film.set(i, j, v);
                    }
                }
            }
        };
        let rendered = render(&job(), &observer).unwrap();
        let (film, _) = rendered.image().unwrap();
        assert_eq!(*film, told.into_inner().unwrap());
        assert_eq!(size.into_inner().unwrap(), Some((48, 40)));
    }

    /// Stops after its first tile.
    struct StopAfterOne(AtomicUsize);

    impl Observer for StopAfterOne {
        fn event(&self, event: Event<'_>) {
            if let Event::Tile(_) = event {
                self.0.fetch_add(1, Ordering::SeqCst);
            }
        }
        fn cancelled(&self) -> bool {
            self.0.load(Ordering::SeqCst) > 0
        }
    }

    /// A job whose observer asks it to stop renders no more tiles and says it stopped.
    #[test]
    fn a_stopped_job_ends_early_with_cancelled() {
        let single = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        for aa in [None, Some(super::super::AaMode::Adaptive)] {
            let mut job = job();
            job.options.aa = aa;
            let stop = StopAfterOne(AtomicUsize::new(0));
            let r = single.install(|| render(&job, &stop));
            assert!(matches!(r, Err(JobError::Cancelled(_))), "{aa:?}: {r:?}");
            assert_eq!(
                stop.0.load(Ordering::SeqCst),
                1,
                "{aa:?}: one tile, then none"
            );
        }
        let stop = StopAfterOne(AtomicUsize::new(1));
        let r = render(&job(), &stop);
        assert!(matches!(r, Err(JobError::Cancelled(_))), "before the build");
    }
}
