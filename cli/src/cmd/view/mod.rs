//! `emray view`: a local web server showing one scene's render as it progresses, with
//! the render options users change most, heat-map and output-variable layers, a
//! pixel's explain tree at a click, and the scene file watched (docs/view.md).
//!
//! - [`http`]: the little HTTP/1.1 it speaks, over `std::net`;
//! - [`auth`]: the token and the `Host` check every request passes;
//! - [`routes`]: what each path answers;
//! - [`session`]: the render, its progress and its last image;
//! - [`rays`]: a pixel's rays projected into the image;
//! - [`difference`]: Embree's render against the BVH's;
//! - [`aov`]: the output variables as images;
//! - [`watch`]: the scene file polled for changes;
//! - [`assets`]: the page, embedded.

mod aov;
mod assets;
mod auth;
mod difference;
mod http;
mod rays;
mod routes;
mod session;
mod watch;

use super::args::LogArgs;
use super::error::{job_error, print};
use super::{Error, interrupt, thread_pool};
use anyhow::{Context, anyhow};
use emray::job::RenderOptions;
use std::net::{SocketAddr, TcpListener};
use std::path::PathBuf;
use std::sync::Arc;

/// `emray view`.
#[derive(clap::Args, Debug, Clone)]
pub struct Args {
    /// Scene file: NFF, TOML (`.toml`), OBJ (`.obj`), or `spd:NAME[?size=N]`.
    #[arg(value_name = "SCENE")]
    pub scene: PathBuf,
    /// Address and port to serve on; port 0 takes a free one. Anything but a loopback
    /// address lets other machines reach the page (they still need the token).
    #[arg(long, value_name = "ADDR:PORT", default_value = "127.0.0.1:0")]
    pub listen: SocketAddr,
    /// Worker threads for the render (default: all cores).
    #[arg(short, long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub threads: Option<u32>,
    /// The first render's options, as `emray render` takes them (the page changes
    /// the backend, resolution, samples, depth and antialiasing).
    #[command(flatten)]
    pub options: RenderOptions,
    /// `-q` and `-v`.
    #[command(flatten)]
    pub log: LogArgs,
}

/// Serve the page until Ctrl-C: print `url http://ADDR:PORT/?token=TOKEN` on standard
/// output, render, and re-render when asked or when the scene file changes.
pub fn run(a: Args) -> Result<(), Error> {
    let stop = interrupt::stop_flag();
    let dir = tempfile::Builder::new()
        .prefix("emray-view-")
        .tempdir()
        .context("cannot create a temporary folder for the rendered images")
        .map_err(Error::Failed)?;
    let pool = thread_pool(a.threads).map_err(Error::Failed)?;
    let session = session::Session::new(a.scene.clone(), a.options, pool, dir.path().into())
        .map_err(job_error)?;
    let session = Arc::new(session);
    let listener = TcpListener::bind(a.listen)
        .with_context(|| format!("cannot listen on {}", a.listen))
        .map_err(Error::Failed)?;
    let addr = listener
        .local_addr()
        .context("cannot read the listening address")
        .map_err(Error::Failed)?;
    let guard = auth::Guard::new(addr.port())
        .map_err(|e| Error::Failed(anyhow!("cannot draw a random token: {e}")))?;
    print(format_args!("url http://{addr}/?token={}\n", guard.token()))?;
    let renderer = session.clone();
    spawn("view-render", move || renderer.renderer())?;
    session.rerender();
    let app = routes::App {
        guard,
        session: session.clone(),
    };
    let handler: Arc<http::Handler> = Arc::new(move |req| routes::handle(&app, req));
    spawn("view-accept", move || {
        if let Err(e) = http::serve(listener, handler) {
            log::error!("the server stopped: {e}");
        }
    })?;
    watch::watch(
        session.scene(),
        || stop.is_cancelled(),
        || {
            log::info!("{} changed: rendering again", session.scene().display());
            session.rerender();
        },
    );
    // The temporary folder goes when `dir` is dropped.
    drop(dir);
    Err(Error::Interrupted(None))
}

/// Start a thread named `name`.
fn spawn(name: &str, f: impl FnOnce() + Send + 'static) -> Result<(), Error> {
    std::thread::Builder::new()
        .name(name.into())
        .spawn(f)
        .with_context(|| format!("cannot start the {name} thread"))
        .map_err(Error::Failed)?;
    Ok(())
}
