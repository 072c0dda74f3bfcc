//! The render the page shows: what the page last asked for, the render under way (its
//! phase, timings and the tiles done so far, as 8-bit sRGB) and the last image that
//! finished (its PNGs, exactly the files `emray render` writes for the same options).
//! A render that compares the backends renders on Embree, then on the BVH, and keeps
//! both images and their [`difference`](super::difference).
//!
//! One thread renders ([`Session::renderer`]); a request for a new render (new options
//! from the page, or the scene file saved) bumps the wanted generation, which stops the
//! render under way between two tiles ([`Observer::cancelled`]) and starts the new
//! one. A render that fails leaves the last image in place, beside the error.

use super::super::explain;
use super::aov;
use super::difference;
use super::rays;
use clap::Parser;
use emray::Backend;
use emray::job::{
    self, AovList, Event, Job, JobError, Observer, Product, RenderOptions, SceneSource,
};
use emray::render::aov::AovSet;
use emray::render::color::srgb8;
use serde_json::{Value, json};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Condvar, Mutex, MutexGuard};
use std::time::Instant;

/// The render options the page sets, by their `emray render` names.
pub const FIELDS: [&str; 5] = ["backend", "res", "spp", "max-depth", "aa"];

/// The heat maps a render with heat maps writes, after the colour: `emray render
/// --heatmap`'s quantities.
pub const HEATMAPS: [&str; 3] = ["rays", "time", "depth"];

/// The backends this build can render on, the default first.
pub fn backends() -> Vec<&'static str> {
    if cfg!(feature = "embree") {
        vec!["embree", "bvh"]
    } else {
        vec!["bvh"]
    }
}

/// Why this build cannot compare the backends.
const NO_EMBREE: &str = "this emray was built without Embree: there is only the BVH, \
                         nothing to compare it with";

/// Most tiles one status answer carries (the page asks again for the rest).
const TILES_PER_STATUS: usize = 256;

/// The page's fields as `emray render` arguments, parsed by the same parser.
#[derive(Parser, Debug)]
#[command(name = "view", no_binary_name = true)]
struct Fields {
    #[command(flatten)]
    options: RenderOptions,
}

/// What a render is asked for.
#[derive(Clone, Debug, Default)]
pub struct Request {
    /// The page's fields, as given (a field left out keeps the command line's value).
    pub fields: BTreeMap<String, String>,
    /// Whether to gather the heat maps too.
    pub heatmaps: bool,
    /// Whether to gather the output variables too (each one a layer, [`aov::LAYERS`]).
    pub aovs: bool,
    /// Whether to render on both backends and show their difference.
    pub compare: bool,
    /// The options: the fields over the command line's.
    pub options: RenderOptions,
}

/// Where a render is.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Phase {
    /// Nothing asked yet.
    #[default]
    Waiting,
    /// Reading the scene.
    Loading,
    /// Building the backend.
    Building,
    /// Tracing.
    Rendering,
    /// Writing the PNGs.
    Writing,
    /// Done: the image is the last one.
    Done,
    /// Failed: see the error.
    Failed,
    /// Stopped for a newer render.
    Stopped,
}

/// A rendered tile, as 8-bit sRGB.
struct Tile {
    x: u32,
    y: u32,
    w: u32,
    h: u32,
    rgb: Vec<u8>,
}

/// The render under way (or the last one).
#[derive(Default)]
struct Progress {
    generation: u64,
    phase: Phase,
    /// The backend rendering, in a render that compares them.
    pass: Option<&'static str>,
    size: Option<(u32, u32)>,
    done: usize,
    total: usize,
    /// The share of the scene loaded, in percent, once the load has told it.
    loaded: Option<u64>,
    tiles: Vec<Tile>,
    /// When loading, building, rendering began and rendering ended.
    marks: [Option<Instant>; 4],
    error: Option<String>,
}

impl Progress {
    /// The milliseconds of each phase so far: load, build, render.
    fn timings(&self) -> Value {
        let now = Instant::now();
        let span = |a: usize| {
            let start = self.marks[a]?;
            let end = self.marks[a + 1..].iter().flatten().next().copied();
            let under_way = (Phase::Loading..=Phase::Writing).contains(&self.phase);
            let end = match end {
                Some(end) => end,
                None if under_way => now,
                None => return None,
            };
            Some(end.duration_since(start).as_secs_f64() * 1e3)
        };
        json!({"load": span(0), "build": span(1), "render": span(2)})
    }
}

/// A finished render.
pub struct Image {
    generation: u64,
    width: u32,
    height: u32,
    /// Each layer's name and PNG.
    layers: Vec<(&'static str, Vec<u8>)>,
    /// What the job reports.
    report: Value,
    /// The backends' difference, in a render that compares them.
    compare: Option<difference::Difference>,
    /// The range each output variable's layer maps, by variable, in a render that
    /// gathers them.
    aov: Option<BTreeMap<&'static str, Value>>,
}

/// What the renderer and the page share.
struct State {
    request: Request,
    progress: Progress,
    image: Option<Arc<Image>>,
}

/// The viewer's render: its scene, options, worker threads and state.
pub struct Session {
    scene: PathBuf,
    base: RenderOptions,
    dir: PathBuf,
    pool: rayon::ThreadPool,
    /// The generation the page wants; the render of any other stops.
    wanted: AtomicU64,
    state: Mutex<State>,
    wake: Condvar,
}

/// Why a render gave no image.
enum Failure {
    Stopped,
    Error(String),
}

/// An error with its causes, on one line.
fn message(e: impl Into<anyhow::Error>) -> String {
    format!("{:#}", e.into())
}

impl Session {
    /// A session rendering `scene` with the command line's `options` (their heat maps
    /// and output variables become the page's switches) on `pool`, its files in `dir`; the first render is
    /// checked as `emray render` checks it (a usage error before anything is served).
    pub fn new(
        scene: PathBuf,
        mut base: RenderOptions,
        pool: rayon::ThreadPool,
        dir: PathBuf,
    ) -> Result<Session, JobError> {
        let heatmaps = !std::mem::take(&mut base.heatmap).is_empty();
        let aovs = std::mem::take(&mut base.aov).is_some_and(|a| a.0.any());
        let request = Request {
            fields: BTreeMap::new(),
            heatmaps,
            aovs,
            compare: false,
            options: base.clone(),
        };
        let s = Session {
            scene,
            base,
            dir,
            pool,
            wanted: AtomicU64::new(0),
            state: Mutex::new(State {
                request: Request::default(),
                progress: Progress::default(),
                image: None,
            }),
            wake: Condvar::new(),
        };
        s.job(&request, None, "colour", heatmaps, aovs)?;
        s.lock().request = request;
        Ok(s)
    }

    /// The scene, as named on the command line.
    pub fn scene(&self) -> &Path {
        &self.scene
    }

    fn lock(&self) -> MutexGuard<'_, State> {
        self.state.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// The file of layer `name`.
    fn file(&self, name: &str) -> PathBuf {
        self.dir.join(format!("{name}.png"))
    }

    /// The job of `request` (on `backend`, when given) writing its image to layer
    /// `layer` (and the heat maps with `heatmaps`), checked as `emray render` checks it;
    /// with `aovs` it gathers every output variable too, checked as `emray render
    /// --aov all` checks a render to an EXR file (the variables are not written: the
    /// render's [`aov`] layers are made from them).
    fn job(
        &self,
        request: &Request,
        backend: Option<Backend>,
        layer: &str,
        heatmaps: bool,
        aovs: bool,
    ) -> Result<Job, JobError> {
        let mut options = request.options.clone();
        if backend.is_some() {
            options.backend = backend;
        }
        if heatmaps {
            options.heatmap = HEATMAPS
                .iter()
                .flat_map(|q| [q.to_string(), self.file(q).display().to_string()])
                .collect();
        }
        let colour = self.file(layer).display().to_string();
        let source = SceneSource::File(self.scene.clone());
        let mut jobs = job::plan(vec![source.clone()], Some(&colour), &options)?;
        let mut job = jobs.pop().expect("one scene, one job");
        job.check()?;
        if aovs {
            let all = Some(AovList(all_aovs()));
            let exr = self.dir.join("aov.exr").display().to_string();
            let with = RenderOptions {
                aov: all,
                ..options
            };
            for j in job::plan(vec![source], Some(&exr), &with)? {
                j.check()?;
            }
            job.options.aov = all;
        }
        Ok(job)
    }

    /// The request of the page's `fields` (the render options of [`FIELDS`], as
    /// `emray render` takes them), `heatmaps`, `aovs` and `compare`, checked as `emray
    /// render` checks its own; a field with an empty value keeps the command line's.
    pub fn parse(
        &self,
        fields: &[(String, String)],
        heatmaps: bool,
        aovs: bool,
        compare: bool,
    ) -> Result<Request, String> {
        if compare && !cfg!(feature = "embree") {
            return Err(NO_EMBREE.into());
        }
        let fields: BTreeMap<String, String> = fields
            .iter()
            .filter(|(k, v)| FIELDS.contains(&k.as_str()) && !v.trim().is_empty())
            .map(|(k, v)| (k.clone(), v.trim().to_string()))
            .collect();
        let args = fields
            .iter()
            .flat_map(|(k, v)| [format!("--{k}"), v.clone()]);
        let parsed = Fields::try_parse_from(args).map_err(|e| {
            let text = e.render().to_string();
            let first = text.lines().next().unwrap_or_default();
            first.trim_start_matches("error: ").to_string()
        })?;
        let request = Request {
            fields,
            heatmaps,
            aovs,
            compare,
            options: parsed.options.over(&self.base),
        };
        for p in self.passes(&request) {
            self.job(&request, p.backend, p.layer, p.heatmaps, p.aovs)
                .map_err(message)?;
        }
        Ok(request)
    }

    /// Render `request` now, stopping the render under way; its generation.
    pub fn submit(&self, request: Request) -> u64 {
        let mut s = self.lock();
        s.request = request;
        self.bump(s)
    }

    /// Render the last request again (the scene changed).
    pub fn rerender(&self) -> u64 {
        self.bump(self.lock())
    }

    fn bump(&self, _state: MutexGuard<'_, State>) -> u64 {
        let g = self.wanted.fetch_add(1, Ordering::SeqCst) + 1;
        self.wake.notify_all();
        g
    }

    /// The renderer: wait for a wanted generation, render it, keep its image or its
    /// error; for ever.
    pub fn renderer(&self) {
        let mut seen = 0;
        loop {
            let (generation, request) = {
                let mut s = self.lock();
                while self.wanted.load(Ordering::SeqCst) == seen {
                    s = self.wake.wait(s).unwrap_or_else(|e| e.into_inner());
                }
                let generation = self.wanted.load(Ordering::SeqCst);
                s.progress = Progress {
                    generation,
                    ..Progress::default()
                };
                (generation, s.request.clone())
            };
            seen = generation;
            let outcome = self.pool.install(|| self.render(generation, &request));
            let mut s = self.lock();
            let p = &mut s.progress;
            match outcome {
                Ok(image) => {
                    p.phase = Phase::Done;
                    s.image = Some(Arc::new(image));
                }
                Err(Failure::Stopped) => p.phase = Phase::Stopped,
                Err(Failure::Error(e)) => {
                    log::warn!("{e}");
                    p.phase = Phase::Failed;
                    p.error = Some(e);
                }
            }
        }
    }

    /// The renders `request` makes: the first one gathers the heat maps and the output
    /// variables asked for; the second, in a comparison, renders on the BVH.
    fn passes(&self, request: &Request) -> Vec<Pass> {
        let first = Pass {
            backend: None,
            layer: "colour",
            heatmaps: request.heatmaps,
            aovs: request.aovs,
        };
        if request.compare {
            vec![
                Pass {
                    backend: Some(Backend::Embree),
                    ..first
                },
                Pass {
                    backend: Some(Backend::Bvh),
                    layer: "bvh",
                    heatmaps: false,
                    aovs: false,
                },
            ]
        } else {
            vec![first]
        }
    }

    /// Render generation `generation` of `request` and read its PNGs.
    fn render(&self, generation: u64, request: &Request) -> Result<Image, Failure> {
        let watcher = Watcher {
            session: self,
            generation,
        };
        let failed = |e: JobError| match e {
            JobError::Cancelled(_) => Failure::Stopped,
            e => Failure::Error(message(e)),
        };
        let mut renders = Vec::new();
        let mut names = Vec::new();
        let mut ranges = None;
        for p in self.passes(request) {
            if request.compare {
                self.pass(generation, p.backend.map(Backend::name));
            }
            let job = self
                .job(request, p.backend, p.layer, p.heatmaps, p.aovs)
                .map_err(|e| Failure::Error(message(e)))?;
            let mut rendered = job::render(&job, &watcher).map_err(failed)?;
            names.push(p.layer);
            if p.heatmaps {
                names.extend(HEATMAPS);
            }
            if p.aovs {
                ranges = Some(self.aov_layers(&mut rendered, &mut names)?);
            }
            job::write(&job, &rendered, &watcher).map_err(failed)?;
            renders.push(rendered);
        }
        let rendered = &renders[0];
        let (film, _) = rendered.image().expect("a render makes an image");
        let compare = match &renders[..] {
            [a, b] => {
                let (other, _) = b.image().expect("a render makes an image");
                let d = difference::of(film, other, a.resolved.encoding).map_err(Failure::Error)?;
                let path = self.file("difference");
                emray::output::write_png_rgb8(&path, d.width, d.height, &d.rgb)
                    .map_err(|e| Failure::Error(message(e)))?;
                names.push("difference");
                Some(d)
            }
            _ => None,
        };
        let layers = names
            .into_iter()
            .map(|name| {
                let path = self.file(name);
                std::fs::read(&path)
                    .map(|png| (name, png))
                    .map_err(|e| Failure::Error(format!("{}: {e}", path.display())))
            })
            .collect::<Result<_, _>>()?;
        Ok(Image {
            generation,
            width: film.width,
            height: film.height,
            layers,
            report: serde_json::to_value(&rendered.report).unwrap_or(Value::Null),
            compare,
            aov: ranges,
        })
    }

    /// Write the layers of the output variables `rendered` gathered, adding their names
    /// to `names`; the variables are then left out of what the job writes (its colour
    /// is the PNG `emray render` writes); the range of each variable's layer.
    fn aov_layers(
        &self,
        rendered: &mut job::Rendered,
        names: &mut Vec<&'static str>,
    ) -> Result<BTreeMap<&'static str, Value>, Failure> {
        let Product::Image {
            aov: Some(film), ..
        } = &mut rendered.product
        else {
            return Err(Failure::Error(
                "this render gathers no output variables".into(),
            ));
        };
        let mut ranges = BTreeMap::new();
        for (layer, (var, _)) in aov::layers(film).into_iter().zip(aov::LAYERS) {
            let path = self.file(layer.name);
            emray::output::write_png_rgb8(&path, film.width, film.height, &layer.rgb)
                .map_err(|e| Failure::Error(message(e)))?;
            names.push(layer.name);
            ranges.insert(var, layer.range);
        }
        film.set = AovSet::default();
        Ok(ranges)
    }

    /// Render `generation` goes on with `backend`: its tiles are counted afresh.
    fn pass(&self, generation: u64, backend: Option<&'static str>) {
        let mut s = self.lock();
        let p = &mut s.progress;
        if p.generation == generation {
            p.pass = backend;
            p.done = 0;
            p.total = 0;
        }
    }

    /// The PNG of layer `name` of the last image.
    pub fn layer(&self, name: &str) -> Option<Vec<u8>> {
        let image = self.lock().image.clone()?;
        let (_, png) = image.layers.iter().find(|(n, _)| *n == name)?;
        Some(png.clone())
    }

    /// The explain JSON of pixel `(x, y)` of the render last asked for, as `emray
    /// explain --json` prints it.
    pub fn explain(&self, x: u32, y: u32) -> Result<String, (bool, String)> {
        let options = self.lock().request.options.clone();
        explain::json(&self.scene, &options, x, y).map_err(|e| (e.is_usage(), message(e)))
    }

    /// The rays of pixel `(x, y)` of the render last asked for, where they appear in
    /// the image, and its explain tree: `{"segments": [...], "tree": {...}}`, the tree
    /// exactly as `emray explain --json` prints it. The scene is loaded once for both.
    pub fn rays(&self, x: u32, y: u32) -> Result<String, (bool, String)> {
        let options = self.lock().request.options.clone();
        let fail = |e: JobError| (e.is_usage(), message(e));
        let scene = job::load_scene(&self.scene).map_err(|e| fail(e.into()))?;
        let scene = Arc::new(scene);
        let source = SceneSource::Loaded {
            name: self.scene.display().to_string(),
            scene: scene.clone(),
        };
        let (tree, explanation) =
            explain::explained(&self.scene, source, &options, x, y).map_err(fail)?;
        let segments = rays::segments(&scene, &explanation);
        let segments = serde_json::to_string(&segments).expect("segments serialise");
        Ok(format!("{{\"segments\": {segments},\n\"tree\": {tree}}}\n"))
    }

    /// Where things are, with the tiles of render `generation` from the `since`th on
    /// (all of them when the render under way is another).
    pub fn status(&self, generation: u64, since: usize) -> Value {
        let s = self.lock();
        let p = &s.progress;
        let from = if generation == p.generation {
            since.min(p.tiles.len())
        } else {
            0
        };
        let to = (from + TILES_PER_STATUS).min(p.tiles.len());
        let tiles: Vec<Value> = p.tiles[from..to]
            .iter()
            .map(|t| json!({"x": t.x, "y": t.y, "w": t.w, "h": t.h, "rgb": super::http::base64(&t.rgb)}))
            .collect();
        let image = s.image.as_ref().map(|i| {
            json!({
                "generation": i.generation,
                "width": i.width,
                "height": i.height,
                "layers": i.layers.iter().map(|(n, _)| *n).collect::<Vec<_>>(),
                "report": i.report,
                "compare": i.compare,
                "aov": i.aov,
            })
        });
        json!({
            "scene": self.scene.display().to_string(),
            "backends": backends(),
            "wanted": self.wanted.load(Ordering::SeqCst),
            "request": {
                "fields": s.request.fields,
                "heatmaps": s.request.heatmaps,
                "aovs": s.request.aovs,
                "compare": s.request.compare,
            },
            "render": {
                "generation": p.generation,
                "phase": p.phase,
                "pass": p.pass,
                "width": p.size.map(|s| s.0),
                "height": p.size.map(|s| s.1),
                "done": p.done,
                "total": p.total,
                "loaded": p.loaded,
                "timings": p.timings(),
                "error": p.error,
                "tiles": tiles,
                "next": to,
            },
            "image": image,
        })
    }
}

/// One render of a request.
#[derive(Clone, Copy)]
struct Pass {
    /// Its backend (`None`: the options').
    backend: Option<Backend>,
    /// The layer of its colour.
    layer: &'static str,
    /// Whether it gathers the heat maps.
    heatmaps: bool,
    /// Whether it gathers the output variables.
    aovs: bool,
}

/// Every output variable `--aov all` gathers.
fn all_aovs() -> AovSet {
    let mut set = AovSet::default();
    for (name, _) in aov::LAYERS {
        set.add(name);
    }
    set
}

/// The observer of render `generation`: phases, tiles and whether to stop.
struct Watcher<'a> {
    session: &'a Session,
    generation: u64,
}

impl Observer for Watcher<'_> {
    fn event(&self, e: Event<'_>) {
        // Encoded before the lock is taken: the other workers go on meanwhile.
        let tile = match e {
            Event::Tile(t) => Some(Tile {
                x: t.region.x0,
                y: t.region.y0,
                w: t.region.x1 - t.region.x0,
                h: t.region.y1 - t.region.y0,
                rgb: t
                    .rows()
                    .flatten()
                    .flat_map(|v| v.to_array().map(srgb8))
                    .collect(),
            }),
            _ => None,
        };
        let mut s = self.session.lock();
        let p = &mut s.progress;
        if p.generation != self.generation {
            return;
        }
        let mut mark = |k: usize, phase: Phase| {
            p.marks[k] = Some(Instant::now());
            p.phase = phase;
        };
        match e {
            Event::Loading => mark(0, Phase::Loading),
            Event::Building => mark(1, Phase::Building),
            Event::Rendering => mark(2, Phase::Rendering),
            Event::Rendered => mark(3, Phase::Writing),
            Event::Loaded { done, total } if total > 0 => {
                p.loaded = Some(done.min(total) * 100 / total);
            }
            Event::Resolved { width, height } => p.size = Some((width, height)),
            Event::Tiles { done, total } => {
                p.done = p.done.max(done);
                p.total = total;
            }
            _ => {}
        }
        if let Some(t) = tile {
            p.tiles.push(t);
        }
    }

    fn cancelled(&self) -> bool {
        self.session.wanted.load(Ordering::SeqCst) != self.generation
    }
}
