//! One render job, from its scene to its written files: what every command that
//! renders (`render`, `explain`, `batch`, `radiosity`, the benchmark's runs) calls,
//! and what a program embedding the library calls.
//!
//! - [`RenderOptions`] ([`options`]): everything a render asks for besides the scene,
//!   declared once, with the values written as text in [`values`];
//! - [`resolve`]: the options checked, then resolved against the scene, every default
//!   applied there and nowhere else;
//! - [`Job`], [`run`] (`pipeline`): a scene, options, a task and the files to write,
//!   run from load to written output, reporting each phase to an [`Observer`];
//! - `work`: what the job does with its built backend;
//! - [`Report`] (`report`): what a render reports;
//! - `limits`: the memory a render needs, checked before it starts;
//! - [`template`]: the one template language of output file names.

mod limits;
pub mod options;
mod pipeline;
mod report;
pub mod resolve;
mod source;
mod spd_points;
mod spd_prims;
mod spd_scene;
pub mod template;
pub mod values;
mod work;

pub use limits::{MemoryLimitError, peak_resident_bytes};
pub use options::{AaMode, FormFactors, Gi, RadiosityOptions, RenderOptions, Solver};
pub use pipeline::{
    Event, Job, JobError, Observer, Outputs, Rendered, Task, check_distinct, plan, render, run,
    write,
};
pub use report::{Report, Timings};
pub use resolve::{Heatmap, OptionsError, Resolved};
pub use source::{SceneError, SceneSource, load_scene, load_scene_with};
pub use values::{AovList, Band, ByteSize, Crop, Res};
pub use work::Product;

use crate::accel::{self, AccelError, Backend, BackendOptions};
use crate::render::{Film, Progress, RenderSettings};
use crate::scene::Scene;
use std::fmt::Write as _;

/// Build the backend (a [`Backend`] with the default options, or [`BackendOptions`])
/// over the loaded `scene` and render it with `settings` on the current rayon pool:
/// the render of a [`Job`] without its load, options or files, for programs and tests
/// that hold a scene and settings already.
pub fn render_scene(
    name: &str,
    scene: &Scene,
    backend: impl Into<BackendOptions>,
    settings: &RenderSettings,
    load_ms: f64,
    progress: Option<Progress<'_>>,
) -> Result<(Film, Report), AccelError> {
    let backend = backend.into();
    let resolved = Resolved {
        settings: settings.clone(),
        backend,
        radiosity: None,
        encoding: Default::default(),
        layers: Default::default(),
        heatmaps: Vec::new(),
        reference: None,
        max_memory: u64::MAX,
    };
    let observer = |e: Event<'_>| {
        if let (Event::Tiles { done, total }, Some(p)) = (e, progress) {
            p.tiles(done, total)
        }
    };
    let work = work::Work {
        name,
        scene,
        resolved: &resolved,
        task: &Task::Render,
        load_ms,
        observer: &observer,
    };
    match accel::build(scene, &backend, work)? {
        Ok(work::Made {
            product: Product::Image { film, .. },
            report,
            ..
        }) => Ok((film, report)),
        Ok(other) => unreachable!("a render makes an image, not {other:?}"),
        Err(e) => unreachable!("a plain render cannot fail once built: {e}"),
    }
}

/// Render the loaded `scene` with the f64 reference renderer
/// ([`crate::render::reference`]) using `strata × strata` samples per pixel and the
/// size and depth of `settings`; `Err` names what the reference does not model.
pub fn render_reference(
    name: &str,
    scene: &Scene,
    settings: &RenderSettings,
    strata: u32,
    load_ms: f64,
) -> Result<(Film, Report), crate::render::reference::Unsupported> {
    match work::reference(name, scene, settings, strata, load_ms)? {
        work::Made {
            product: Product::Image { film, .. },
            report,
            ..
        } => Ok((film, report)),
        other => unreachable!("the reference makes an image, not {other:?}"),
    }
}

/// The hash of a render that the parts of one image must share: the whole scene
/// (every value the loader produced), the settings that change pixels (not the region,
/// not the tile size) and the backend, as 16 hex digits (FNV-1a 64).
pub fn render_hash(scene: &Scene, settings: &RenderSettings, backend: Backend) -> String {
    let mut h = Fnv(0xcbf2_9ce4_8422_2325);
    let s = RenderSettings {
        region: None,
        tile_size: 0,
        ..settings.clone()
    };
    let _ = write!(h, "{scene:?}|{s:?}|{}", backend.name());
    format!("{:016x}", h.0)
}

/// FNV-1a 64 over what is written into it.
struct Fnv(u64);

impl std::fmt::Write for Fnv {
    fn write_str(&mut self, s: &str) -> std::fmt::Result {
        for b in s.bytes() {
            self.0 ^= u64::from(b);
            self.0 = self.0.wrapping_mul(0x0100_0000_01b3);
        }
        Ok(())
    }
}
