//! emray: a Whitted-style ray tracer for NFF, OBJ and TOML scenes whose ray queries run
//! on Intel Embree (feature `embree`, default) or on a pure-Rust BVH.
//!
//! # Rendering a file
//!
//! [`render_file`] renders a scene file (or a generated `spd:NAME` database) with
//! [`RenderOptions`], the options of `emray render`, declared once for the command
//! line, batch manifests and programs alike; every option is optional and the
//! defaults are the command's. The result holds the image, the output variables asked
//! for and the render's [`Report`](job::Report):
//!
//! ```no_run
//! use emray::{RenderOptions, render_file};
//!
//! let options = RenderOptions {
//!     res: Some("320x240".parse()?),
//!     aov: Some("depth".parse()?),
//!     ..RenderOptions::default()
//! };
//! let rendered = render_file("scenes/spheres.toml", &options)?;
//! let (film, aov) = rendered.image().expect("a render makes an image");
//! let depth = &aov.expect("asked for").depth;
//! println!(
//!     "{}x{}, centre at depth {}, {:.1} ms",
//!     film.width,
//!     film.height,
//!     depth[(120 * 320 + 160) as usize],
//!     rendered.report.time_ms.render
//! );
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! A [`Job`] says more: the files to write (image, heat maps, statistics), a task
//! other than an image (one pixel's ray tree, a radiosity view), a scene built in
//! code ([`job::SceneSource::Loaded`]); [`job::run`] runs it from load to written
//! files and tells an [`job::Observer`] how far it is.
//!
//! # The layers
//!
//! [`load`] parses a file into a backend-free [`Scene`] ([`scene`], made of the
//! [`geometry`] primitives and [`math`] types), [`accel`] builds an acceleration
//! structure over it ([`Accel`]: Embree or the BVH, chosen by [`Backend`]), [`render`]
//! traces rays through that structure and [`output`] writes the film; [`radiosity`] is
//! the diffuse second pass and [`spd`] the Standard Procedural Databases. [`batch`],
//! [`bench`](mod@bench) and [`accuracy`] are the engines of `emray batch`, `emray bench` and
//! `emray compare`, `stress` and `study`.
#![deny(unsafe_code)]
#![warn(missing_docs)]

pub mod accel;
pub mod accuracy;
pub mod batch;
pub mod bench;
pub mod geometry;
pub mod job;
pub mod load;
pub mod math;
pub mod output;
pub mod radiosity;
pub mod render;
pub mod scene;
pub mod spd;

pub use accel::{Accel, Backend, BackendOptions, Hit};
pub use job::{Job, JobError, RenderOptions, Rendered};
pub use scene::Scene;

/// Render the scene file (NFF, TOML, OBJ) or generated database (`spd:NAME[?size=N]`)
/// at `path` with `options`, in memory: the [`Job`] of one image with no files to write,
/// run on the current rayon pool.
pub fn render_file(
    path: impl AsRef<std::path::Path>,
    options: &RenderOptions,
) -> Result<Rendered, JobError> {
    let scene = job::SceneSource::File(path.as_ref().to_path_buf());
    let job = Job::render(scene, options.clone(), None);
    job.check()?;
    job::render(&job, &())
}
