//! The Whitted renderer: eye rays, local Phong light with shadow rays, mirror
//! reflection, Snell refraction with total internal reflection, a depth limit; tiles
//! rendered in parallel, deterministic whatever the thread count.

mod camera;
mod film;
mod whitted;

pub use camera::RayGen;
pub use film::Film;
pub use whitted::RayCounts;

use crate::accel::Accel;
use crate::scene::Scene;
use rayon::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};

/// How to render.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderSettings {
    /// Image width (defaults to the scene camera's).
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Samples per pixel (1 = the pixel centre).
    pub spp: u32,
    /// Maximum ray-tree depth, counting the eye ray as depth 1.
    pub max_depth: u32,
    /// SPD testing mode: `(w+1) × (h+1)` corner rays, each pixel the mean of its four
    /// corners (DESIGN.md §3).
    pub spd: bool,
    /// Tile edge in pixels.
    pub tile: u32,
    /// Shadow rays per emitting triangle (area light): `area_samples²`, stratified.
    pub area_samples: u32,
}

impl RenderSettings {
    /// Defaults for `scene`: its resolution, 1 spp, depth 5, 16×16 tiles.
    pub fn for_scene(scene: &Scene) -> Self {
        RenderSettings {
            width: scene.camera.width,
            height: scene.camera.height,
            spp: 1,
            max_depth: 5,
            spd: false,
            tile: 16,
            area_samples: 4,
        }
    }
}

/// What a render counted.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RenderStats {
    /// Rays cast by type.
    pub rays: RayCounts,
    /// Wall time of the render phase in milliseconds.
    pub render_ms: f64,
}

impl RenderStats {
    /// Millions of rays (of every type) per second of render time.
    pub fn mrays_per_s(&self) -> f64 {
        if self.render_ms <= 0.0 {
            return 0.0;
        }
        self.rays.total() as f64 / (self.render_ms * 1e3)
    }
}

/// Called as tiles complete: `(done, total)`.
pub type Progress<'a> = &'a (dyn Fn(usize, usize) + Sync);

/// Render `scene` through `accel` on the current rayon pool.
pub fn render<A: Accel>(
    scene: &Scene,
    accel: &A,
    settings: &RenderSettings,
    progress: Option<Progress<'_>>,
) -> (Film, RenderStats) {
    render_with_gi(scene, accel, settings, None, progress)
}

/// [`render`], two-pass when `gi` is given: the diffuse term of the meshed surfaces
/// comes from the radiosity solution, the Whitted recursion adds the specular paths.
pub fn render_with_gi<A: Accel>(
    scene: &Scene,
    accel: &A,
    settings: &RenderSettings,
    gi: Option<&crate::radiosity::Solution>,
    progress: Option<Progress<'_>>,
) -> (Film, RenderStats) {
    let start = std::time::Instant::now();
    let (w, h) = (settings.width, settings.height);
    // In SPD mode the sample grid is the pixel corners: one more row and column.
    let (gw, gh) = if settings.spd { (w + 1, h + 1) } else { (w, h) };
    let gen = RayGen::new(&scene.camera, gw, gh);
    let tracer = whitted::Tracer::new(scene, accel, settings).with_gi(gi);
    let ts = settings.tile.max(1);
    let tiles: Vec<(u32, u32)> = (0..gh.div_ceil(ts))
        .flat_map(|ty| (0..gw.div_ceil(ts)).map(move |tx| (tx * ts, ty * ts)))
        .collect();
    let done = AtomicUsize::new(0);
    let total = tiles.len();
    let results: Vec<(Vec<glam::Vec3>, RayCounts)> = tiles
        .par_iter()
        .map(|&(x0, y0)| {
            let x1 = (x0 + ts).min(gw);
            let y1 = (y0 + ts).min(gh);
            let mut counts = RayCounts::default();
            let mut px = Vec::with_capacity(((x1 - x0) * (y1 - y0)) as usize);
            for j in y0..y1 {
                for i in x0..x1 {
                    px.push(tracer.pixel(&gen, i, j, &mut counts));
                }
            }
            if let Some(p) = progress {
                p(done.fetch_add(1, Ordering::Relaxed) + 1, total);
            }
            (px, counts)
        })
        .collect();
    let mut grid = Film::new(gw, gh);
    let mut rays = RayCounts::default();
    for (&(x0, y0), (px, counts)) in tiles.iter().zip(results) {
        rays += counts;
        let x1 = (x0 + ts).min(gw);
        let mut it = px.into_iter();
        for j in y0..(y0 + ts).min(gh) {
            for i in x0..x1 {
                grid.set(i, j, it.next().expect("tile size"));
            }
        }
    }
    let film = if settings.spd {
        grid.average_corners()
    } else {
        grid
    };
    let stats = RenderStats {
        rays,
        render_ms: start.elapsed().as_secs_f64() * 1e3,
    };
    (film, stats)
}
