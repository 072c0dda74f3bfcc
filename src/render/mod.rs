//! The Whitted renderer: eye rays, local Phong light with shadow rays, area lights
//! ([`area`]), mirror reflection, Snell refraction with total internal reflection, a
//! depth limit; tiles rendered in parallel, deterministic whatever the thread count.
//! Global illumination comes in through [`GlobalIllumination`] (a radiosity solution
//! implements it); [`color`] turns the film's linear values into encoded 8-bit ones.

pub mod area;
mod camera;
pub mod color;
mod counts;
pub mod explain;
mod film;
pub mod gi;
mod local;
pub mod media;
mod optics;
pub mod record;
pub mod reference;
mod shade;
mod whitted;

pub use camera::RayGen;
pub use counts::RayCounts;
pub use film::Film;
pub use gi::GlobalIllumination;

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
    /// corners; the corner grid's outer rows span the camera's angle.
    pub spd: bool,
    /// Tile edge in pixels.
    pub tile: u32,
    /// Shadow rays per emitting triangle (area light): `area_samples²`, stratified.
    pub area_samples: u32,
    /// Antialiasing: uniform `spp` samples per pixel, or adaptive subdivision.
    pub aa: Aa,
    /// Hall & Greenberg's adaptive ray-tree depth: a reflected or refracted ray whose
    /// accumulated weight (the product of Ks, T and filter colours from the eye, largest
    /// channel) is below this is not cast. 0 turns it off.
    pub bailout: f32,
    /// Skip work that cannot change the image: shadow rays towards lights behind the
    /// shading normal or that send nothing, reflection rays off surfaces with Ks = 0.
    /// Off only to measure what it saves.
    pub skip: bool,
    /// Render only this part of the image (`None`: all of it). The film then holds
    /// the region alone; every pixel comes out as in the full render.
    pub region: Option<Region>,
}

/// A rectangle of pixels, `x0..x1` by `y0..y1` (half-open, from the top-left).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Region {
    /// First column.
    pub x0: u32,
    /// One past the last column.
    pub x1: u32,
    /// First row.
    pub y0: u32,
    /// One past the last row.
    pub y1: u32,
}

impl Region {
    /// The whole `width × height` image.
    pub fn full(width: u32, height: u32) -> Self {
        Region {
            x0: 0,
            x1: width,
            y0: 0,
            y1: height,
        }
    }

    /// Band `index` of `count` horizontal bands of a `width × height` image (rows split
    /// as evenly as they go; the bands cover the image exactly once).
    pub fn band(index: u32, count: u32, width: u32, height: u32) -> Self {
        let row = |k: u32| (k as u64 * height as u64 / count.max(1) as u64) as u32;
        Region {
            x0: 0,
            x1: width,
            y0: row(index),
            y1: row(index + 1),
        }
    }

    /// Width in pixels.
    pub fn width(&self) -> u32 {
        self.x1 - self.x0
    }

    /// Height in pixels.
    pub fn height(&self) -> u32 {
        self.y1 - self.y0
    }

    /// Whether the region is non-empty and inside a `width × height` image.
    pub fn fits(&self, width: u32, height: u32) -> bool {
        self.x0 < self.x1 && self.y0 < self.y1 && self.x1 <= width && self.y1 <= height
    }
}

/// Antialiasing modes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Aa {
    /// `spp` stratified samples per pixel (1 = the pixel centre).
    Uniform,
    /// Whitted's adaptive supersampling: rays through every pixel corner (shared
    /// between neighbouring pixels), a pixel whose four corners differ by more than
    /// `threshold` (in any channel) split into four, recursively down to `depth`
    /// levels; a square's value is the mean of its corners. Deterministic.
    Adaptive {
        /// Largest corner difference left unsplit.
        threshold: f32,
        /// Most subdivision levels (0 = the corners only).
        depth: u32,
    },
}

/// Default `--bailout` outside SPD mode: a ray contributing less than this share of
/// its radiance cannot move an 8-bit pixel of radiance up to about 2.
pub const DEFAULT_BAILOUT: f32 = 1e-3;
/// Default adaptive threshold (largest corner difference, linear).
pub const DEFAULT_AA_THRESHOLD: f32 = 0.05;
/// Default adaptive depth.
pub const DEFAULT_AA_DEPTH: u32 = 2;

impl RenderSettings {
    /// Defaults for `scene`: its resolution, 1 spp, depth 5, 16×16 tiles, uniform
    /// sampling, no bailout (the full ray tree), skips on.
    pub fn for_scene(scene: &Scene) -> Self {
        RenderSettings {
            width: scene.camera.width,
            height: scene.camera.height,
            spp: 1,
            max_depth: 5,
            spd: false,
            tile: 16,
            area_samples: 4,
            aa: Aa::Uniform,
            bailout: 0.0,
            skip: true,
            region: None,
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
    /// The statistics of a render that cast `rays` and started at `start`; warns when
    /// radiance overflowed.
    fn finish(rays: RayCounts, start: std::time::Instant) -> Self {
        if rays.saturated > 0 {
            log::warn!(
                "the radiance of {} ray(s) overflowed single precision and was clamped: the \
                 scene's colours, light intensities or weights are too large",
                rays.saturated
            );
        }
        RenderStats {
            rays,
            render_ms: start.elapsed().as_secs_f64() * 1e3,
        }
    }

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

/// [`render`], two-pass when `gi` is given: the diffuse term of the surfaces it covers
/// (a radiosity solution's meshed surfaces) comes from it, the Whitted recursion adds
/// the specular paths.
pub fn render_with_gi<A: Accel>(
    scene: &Scene,
    accel: &A,
    settings: &RenderSettings,
    gi: Option<&dyn GlobalIllumination>,
    progress: Option<Progress<'_>>,
) -> (Film, RenderStats) {
    let start = std::time::Instant::now();
    let (w, h) = (settings.width, settings.height);
    let tracer = whitted::Tracer::new(scene, accel, settings).with_gi(gi);
    // Only the samples of the region: every pixel and sample keeps its coordinates in
    // the whole image, so a part holds exactly the full render's pixels.
    let r = settings.region.unwrap_or(Region::full(w, h));
    if let (Aa::Adaptive { threshold, depth }, false) = (settings.aa, settings.spd) {
        // The rays through every pixel corner, then each pixel refined from its four.
        let raygen = RayGen::new(&scene.camera, w, h);
        let (cw, ch) = (r.width() + 1, r.height() + 1);
        let (corners, mut rays) = sample_grid(
            r.x0,
            r.y0,
            cw,
            ch,
            settings.tile,
            None,
            per_position(|i, j, c| tracer.sample(&raygen, i as f32, j as f32, c)),
        );
        let (rw, rh) = (r.width(), r.height());
        let refine = per_position(|i, j, c| {
            let (ci, cj) = (i - r.x0, j - r.y0);
            let k = [
                corners.get(ci, cj),
                corners.get(ci + 1, cj),
                corners.get(ci, cj + 1),
                corners.get(ci + 1, cj + 1),
            ];
            let s = |x: f32, y: f32, c: &mut RayCounts| tracer.sample(&raygen, x, y, c);
            adaptive(&s, i as f32, j as f32, 1.0, k, threshold, depth, c)
        });
        let (film, more) = sample_grid(r.x0, r.y0, rw, rh, settings.tile, progress, refine);
        rays += more;
        return (film, RenderStats::finish(rays, start));
    }
    // In SPD mode the sample grid is the pixel corners: one more row and column.
    let (gw, gh) = if settings.spd { (w + 1, h + 1) } else { (w, h) };
    let raygen = RayGen::new(&scene.camera, gw, gh);
    let extra = u32::from(settings.spd);
    let (rw, rh) = (r.width() + extra, r.height() + extra);
    let (grid, rays) = sample_grid(r.x0, r.y0, rw, rh, settings.tile, progress, |t, px, c| {
        tracer.tile(&raygen, t, px, c);
    });
    let film = if settings.spd {
        grid.average_corners()
    } else {
        grid
    };
    (film, RenderStats::finish(rays, start))
}

/// A per-position function `f(i, j, counts)` as a tile function for [`sample_grid`]:
/// the tile's positions row by row.
fn per_position<F>(f: F) -> impl Fn(Region, &mut Vec<glam::Vec3>, &mut RayCounts) + Sync
where
    F: Fn(u32, u32, &mut RayCounts) -> glam::Vec3 + Sync,
{
    move |t, px, counts| {
        for j in t.y0..t.y1 {
            for i in t.x0..t.x1 {
                px.push(f(i, j, counts));
            }
        }
    }
}

/// The tile of edge `tile` holding position `(i, j)` of a `gw × gh` sample grid, cut
/// from the grid's top-left corner as [`sample_grid`] cuts a whole image.
pub(crate) fn tile_of(i: u32, j: u32, gw: u32, gh: u32, tile: u32) -> Region {
    let ts = tile.max(1);
    let (x0, y0) = (i / ts * ts, j / ts * ts);
    Region {
        x0,
        y0,
        x1: (x0 + ts).min(gw),
        y1: (y0 + ts).min(gh),
    }
}

/// Evaluate the `gw × gh` grid whose top-left is `(ox, oy)` in parallel square tiles
/// of edge `tile`, the result independent of the schedule: `f(tile, px, counts)` pushes
/// the values of the tile's grid positions (absolute coordinates, row by row) onto
/// `px`, and the film's pixel `(i, j)` is the value of position `(ox + i, oy + j)`.
fn sample_grid<F>(
    ox: u32,
    oy: u32,
    gw: u32,
    gh: u32,
    tile: u32,
    progress: Option<Progress<'_>>,
    f: F,
) -> (Film, RayCounts)
where
    F: Fn(Region, &mut Vec<glam::Vec3>, &mut RayCounts) + Sync,
{
    let ts = tile.max(1);
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
            let t = Region {
                x0: ox + x0,
                y0: oy + y0,
                x1: ox + x1,
                y1: oy + y1,
            };
            f(t, &mut px, &mut counts);
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
    (grid, rays)
}

/// Whitted's adaptive refinement of the square at `(x, y)` of edge `size` whose corner
/// values are `k` (top-left, top-right, bottom-left, bottom-right): their mean if they
/// agree within `threshold` or `depth` is exhausted, else the mean of its four
/// quarters, the five new points sampled with `sample`.
#[allow(clippy::too_many_arguments)]
fn adaptive<S>(
    sample: &S,
    x: f32,
    y: f32,
    size: f32,
    k: [glam::Vec3; 4],
    threshold: f32,
    depth: u32,
    c: &mut RayCounts,
) -> glam::Vec3
where
    S: Fn(f32, f32, &mut RayCounts) -> glam::Vec3,
{
    let lo = k[0].min(k[1]).min(k[2].min(k[3]));
    let hi = k[0].max(k[1]).max(k[2].max(k[3]));
    // A NaN corner compares false: it is not refined (and shows as NaN).
    if depth == 0 || (hi - lo).max_element() <= threshold {
        return (k[0] + k[1] + k[2] + k[3]) * 0.25;
    }
    let hs = size * 0.5;
    let top = sample(x + hs, y, c);
    let left = sample(x, y + hs, c);
    let mid = sample(x + hs, y + hs, c);
    let right = sample(x + size, y + hs, c);
    let bottom = sample(x + hs, y + size, c);
    let d = depth - 1;
    let q = [
        adaptive(sample, x, y, hs, [k[0], top, left, mid], threshold, d, c),
        adaptive(
            sample,
            x + hs,
            y,
            hs,
            [top, k[1], mid, right],
            threshold,
            d,
            c,
        ),
        adaptive(
            sample,
            x,
            y + hs,
            hs,
            [left, mid, k[2], bottom],
            threshold,
            d,
            c,
        ),
        adaptive(
            sample,
            x + hs,
            y + hs,
            hs,
            [mid, right, bottom, k[3]],
            threshold,
            d,
            c,
        ),
    ];
    (q[0] + q[1] + q[2] + q[3]) * 0.25
}
