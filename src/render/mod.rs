//! The Whitted renderer: eye rays, local Phong light with shadow rays, area lights
//! (`area`), mirror reflection, Snell refraction with total internal reflection, a
//! depth limit; tiles rendered in parallel, deterministic whatever the thread count.
//! Global illumination comes in through [`GlobalIllumination`] (a radiosity solution
//! implements it); [`color`] turns the film's linear values into encoded 8-bit ones.

pub mod aov;
pub(crate) mod area;
mod camera;
pub mod color;
mod counts;
pub mod explain;
mod film;
pub(crate) mod gi;
mod grid;
mod local;
pub(crate) mod media;
mod optics;
mod path;
pub(crate) mod record;
pub mod reference;
mod shade;
mod wavefront;
mod whitted;

pub use camera::RayGen;
pub use counts::RayCounts;
pub use film::Film;
pub use gi::GlobalIllumination;
pub(crate) use grid::tile_of;

use crate::accel::Accel;
use crate::scene::Scene;
use glam::Vec3;

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
    /// The edge of the square tiles the image is rendered in, in pixels.
    pub tile_size: u32,
    /// Shadow rays per emitting triangle (area light): `area_strata²`, stratified
    /// (`area_strata` per axis).
    pub area_strata: u32,
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

/// Samples per pixel when neither the options nor the scene file give them.
pub const DEFAULT_SPP: u32 = 1;
/// Ray-tree depth when neither the options nor the scene file give one.
pub const DEFAULT_MAX_DEPTH: u32 = 5;
/// Tile edge in pixels.
pub const DEFAULT_TILE_SIZE: u32 = 16;
/// Shadow rays per emitting triangle (area light) when none are asked for: 4 × 4
/// strata.
pub const DEFAULT_AREA_SAMPLES: u32 = 16;
/// Image side in SPD testing mode when no resolution is asked for: 512 × 512 pixels
/// from a 513 × 513 grid of corner rays.
pub const SPD_SIDE: u32 = 512;
/// Ray-tree depth in SPD testing mode, whatever the options or the scene say.
pub const SPD_MAX_DEPTH: u32 = 5;

/// Default `--bailout` outside SPD mode: a ray contributing less than this share of
/// its radiance cannot move an 8-bit pixel of radiance up to about 2.
pub const DEFAULT_BAILOUT: f32 = 1e-3;
/// Default adaptive threshold (largest corner difference, linear).
pub const DEFAULT_AA_THRESHOLD: f32 = 0.05;
/// Default adaptive depth.
pub const DEFAULT_AA_DEPTH: u32 = 2;

impl RenderSettings {
    /// Defaults for `scene`: its resolution, [`DEFAULT_SPP`], [`DEFAULT_MAX_DEPTH`],
    /// tiles of [`DEFAULT_TILE_SIZE`], [`DEFAULT_AREA_SAMPLES`], uniform sampling, no
    /// bailout (the full ray tree), skips on.
    pub fn for_scene(scene: &Scene) -> Self {
        RenderSettings {
            width: scene.camera.width,
            height: scene.camera.height,
            spp: DEFAULT_SPP,
            max_depth: DEFAULT_MAX_DEPTH,
            spd: false,
            tile_size: DEFAULT_TILE_SIZE,
            area_strata: DEFAULT_AREA_SAMPLES.isqrt(),
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

/// What a render tells as it goes, from the worker threads, and asks whether to stop
/// ([`Progress`]). A plain `Fn(done, total)` is one that counts tiles alone.
pub trait Watch: Sync {
    /// `(0, total)` before the first tile, then `(done, total)` as tiles complete (in
    /// any order).
    fn tiles(&self, done: usize, total: usize);

    /// A tile is complete, with its values (called just before its
    /// [`tiles`](Watch::tiles)); nothing by default.
    fn tile(&self, tile: TileValues<'_>) {
        let _ = tile;
    }

    /// Whether to stop: once it says yes, tiles not yet started are skipped (their
    /// pixels stay black) and the render returns early; the caller, who asked, knows
    /// to discard the film. Checked before each tile; never, by default.
    fn cancelled(&self) -> bool {
        false
    }
}

impl<F: Fn(usize, usize) + Sync> Watch for F {
    fn tiles(&self, done: usize, total: usize) {
        self(done, total)
    }
}

/// What a render tells as it goes: tiles done, tiles' values, and whether to stop.
pub type Progress<'a> = &'a dyn Watch;

/// A complete tile of a render: its positions in the render's sample grid (the
/// image's pixels, or in SPD mode its pixel corners, one more row and column) and
/// their linear values, row by row.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TileValues<'a> {
    /// The tile's positions in the grid.
    pub region: Region,
    rows: &'a [&'a mut [Vec3]],
}

impl<'a> TileValues<'a> {
    pub(crate) fn new(region: Region, rows: &'a [&'a mut [Vec3]]) -> Self {
        TileValues { region, rows }
    }

    /// The values, one slice per row of the region, top to bottom.
    pub fn rows(&self) -> impl Iterator<Item = &[Vec3]> + '_ {
        self.rows.iter().map(|r| &**r)
    }
}

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
    let tracer = whitted::Tracer::new(scene, accel, settings).with_gi(gi);
    if let (Aa::Adaptive { threshold, depth }, false) = (settings.aa, settings.spd) {
        let (film, rays) = grid::adaptive_render(&tracer, settings, threshold, depth, progress);
        return (film, RenderStats::finish(rays, start));
    }
    let (film, tiles) = grid::uniform_render(&tracer, settings, progress, RayCounts::default);
    let mut rays = RayCounts::default();
    for counts in tiles {
        rays += counts;
    }
    (film, RenderStats::finish(rays, start))
}
