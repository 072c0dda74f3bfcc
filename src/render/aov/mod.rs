//! Output variables (AOVs): per pixel, besides its colour, what the eye rays first hit
//! (distance, shading normal, albedo, point, primitive id) and what the pixel cost
//! (rays cast, the deepest of them, nanoseconds), gathered by an
//! `AovRecorder` from the renderer's own tracer while it
//! renders the colour, which comes out as a plain render's, bit for bit.
//!
//! A pixel's first-hit values are the mean over its samples that hit a surface (the
//! miss value where none did); its id the one most of its samples hit; its rays and
//! time the sums over its samples; its depth the deepest ray. In SPD mode a pixel is
//! made of its four corner rays as its colour is: first-hit values over the corners
//! that hit, rays and time the mean of the corners, depth the deepest. The channels
//! and their units are in docs/aov.md.

pub mod ids;
mod recorder;

use super::grid::{self, Positions};
use super::whitted::Tracer;
use super::{Aa, Film, GlobalIllumination, Progress, RayCounts, RenderSettings, RenderStats};
use crate::accel::Accel;
use crate::math::Vec3;
use crate::scene::Scene;
use glam::DVec3;
use ids::{IdEntry, IdMap, NO_ID, TooManyIds};
use recorder::AovRecorder;

/// Which output variables to gather.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct AovSet {
    /// `Z`: distance from the eye to the first hit.
    pub depth: bool,
    /// `N.X N.Y N.Z`: the shading normal, facing the eye.
    pub normal: bool,
    /// `albedo.R albedo.G albedo.B`: colour × Kd after textures.
    pub albedo: bool,
    /// `P.X P.Y P.Z`: the hit point.
    pub position: bool,
    /// `id`: the primitive's id ([`ids`]).
    pub id: bool,
    /// `rays`: rays cast for the pixel.
    pub rays: bool,
    /// `time`: nanoseconds spent on the pixel.
    pub time: bool,
    /// The ray-tree depth of the pixel's deepest ray (for heat maps).
    pub tree_depth: bool,
}

impl AovSet {
    /// The names `--aov` takes, in the order they are listed.
    pub const NAMES: [&'static str; 7] = [
        "depth", "normal", "albedo", "position", "id", "rays", "time",
    ];

    /// Whether the variable named `name` (one of [`AovSet::NAMES`]) is in the set.
    pub fn has(&self, name: &str) -> bool {
        let mut copy = *self;
        copy.flag(name).is_some_and(|f| *f)
    }

    /// The flag of the variable named `name`.
    fn flag(&mut self, name: &str) -> Option<&mut bool> {
        Some(match name {
            "depth" => &mut self.depth,
            "normal" => &mut self.normal,
            "albedo" => &mut self.albedo,
            "position" => &mut self.position,
            "id" => &mut self.id,
            "rays" => &mut self.rays,
            "time" => &mut self.time,
            _ => return None,
        })
    }

    /// Add the variable named `name` (one of [`AovSet::NAMES`]); `false` if there is
    /// none of that name.
    pub fn add(&mut self, name: &str) -> bool {
        self.flag(name).map(|f| *f = true).is_some()
    }

    /// Whether any variable is wanted.
    pub fn any(&self) -> bool {
        *self != AovSet::default()
    }
}

/// What a position or pixel gathered: sums over the samples that hit, with their
/// count, and the cost.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Cell {
    hits: u32,
    z: f32,
    n: Vec3,
    albedo: Vec3,
    p: Vec3,
    id: u32,
    rays: f32,
    time: f32,
    depth: u32,
}

impl Cell {
    /// An SPD pixel from its corners (top-left, top-right, bottom-left, bottom-right):
    /// the sums of the corners that hit, the id most of them hit (the first among
    /// equals), the mean rays and time, the deepest ray.
    fn corners(k: [Cell; 4]) -> Cell {
        let mut c = Cell::default();
        let mut best = (NO_ID, 0);
        for corner in &k {
            c.hits += corner.hits;
            c.z += corner.z;
            c.n += corner.n;
            c.albedo += corner.albedo;
            c.p += corner.p;
            c.depth = c.depth.max(corner.depth);
            let votes = k.iter().filter(|o| o.id == corner.id).count();
            if corner.id != NO_ID && votes > best.1 {
                best = (corner.id, votes);
            }
        }
        c.id = best.0;
        c.rays = (k[0].rays + k[1].rays + k[2].rays + k[3].rays) * 0.25;
        c.time = (k[0].time + k[1].time + k[2].time + k[3].time) * 0.25;
        c
    }
}

/// The output variables of a render (its region), row-major like the [`Film`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct AovFilm {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// What was asked for (the rest is gathered too, and not written).
    pub set: AovSet,
    /// Distance from the eye to the first hit; `+∞` where no sample hit.
    pub depth: Vec<f32>,
    /// Shading normal facing the eye (the mean of the samples'); 0 where none hit.
    pub normal: Vec<Vec3>,
    /// Colour × Kd after textures; 0 where none hit.
    pub albedo: Vec<Vec3>,
    /// Hit point in the scene file's coordinates ([`Scene::to_world`]); 0 where none hit.
    pub position: Vec<Vec3>,
    /// Primitive id; [`NO_ID`] where none hit.
    pub id: Vec<u32>,
    /// Rays cast, every kind.
    pub rays: Vec<f32>,
    /// Nanoseconds spent (0 unless asked for).
    pub time: Vec<f32>,
    /// The deepest ray's depth (the eye ray is 1).
    pub tree_depth: Vec<f32>,
    /// What the ids in the image stand for, ascending.
    pub ids: Vec<IdEntry>,
}

impl AovFilm {
    /// The film of `cells`, a `width × height` grid.
    fn from_cells(width: u32, height: u32, set: AovSet, cells: &[Cell], origin: DVec3) -> Self {
        let mean = |sum: Vec3, c: &Cell| {
            if c.hits > 0 {
                sum / c.hits as f32
            } else {
                Vec3::ZERO
            }
        };
        AovFilm {
            width,
            height,
            set,
            depth: cells
                .iter()
                .map(|c| {
                    if c.hits > 0 {
                        c.z / c.hits as f32
                    } else {
                        f32::INFINITY
                    }
                })
                .collect(),
            normal: cells.iter().map(|c| mean(c.n, c)).collect(),
            albedo: cells.iter().map(|c| mean(c.albedo, c)).collect(),
            position: cells
                .iter()
                .map(|c| match c.hits {
                    0 => Vec3::ZERO,
                    _ => (mean(c.p, c).as_dvec3() + origin).as_vec3(),
                })
                .collect(),
            id: cells.iter().map(|c| c.id).collect(),
            rays: cells.iter().map(|c| c.rays).collect(),
            time: cells.iter().map(|c| c.time).collect(),
            tree_depth: cells.iter().map(|c| c.depth as f32).collect(),
            ids: Vec::new(),
        }
    }
}

/// Why the output variables cannot be gathered.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum AovError {
    /// Adaptive antialiasing shares its corner rays between pixels.
    #[error(
        "output variables and heat maps need uniform samples: adaptive antialiasing shares \
         its rays between pixels"
    )]
    Adaptive,
    /// The render was stopped ([`Watch::cancelled`](super::Watch::cancelled)).
    #[error("the render was stopped")]
    Cancelled,
    /// Too many primitives for 32-bit ids.
    #[error(transparent)]
    TooManyIds(#[from] TooManyIds),
}

/// [`render_with_gi`](super::render_with_gi) that also gathers the output variables
/// `set`: the same film, bit for bit, and the variables of its pixels.
pub fn render_aov<A: Accel>(
    scene: &Scene,
    accel: &A,
    settings: &RenderSettings,
    gi: Option<&dyn GlobalIllumination>,
    progress: Option<Progress<'_>>,
    set: AovSet,
) -> Result<(Film, AovFilm, RenderStats), AovError> {
    if settings.aa != Aa::Uniform && !settings.spd {
        return Err(AovError::Adaptive);
    }
    let start = std::time::Instant::now();
    let map = IdMap::new(scene)?;
    let tracer = Tracer::new(scene, accel, settings).with_gi(gi);
    let new = || AovRecorder::new(&map, set);
    let (film, recs) = grid::uniform_render(&tracer, settings, progress, new);
    if progress.is_some_and(|p| p.cancelled()) {
        // The skipped tiles recorded nothing.
        return Err(AovError::Cancelled);
    }
    let mut rays = RayCounts::default();
    for r in &recs {
        rays += r.counts();
    }
    let at = Positions::of(settings);
    let (gw, gh) = at.size;
    let cells = grid::scatter(
        gw,
        gh,
        settings.tile_size,
        recs.into_iter().map(|r| r.cells),
    );
    let cells = if settings.spd {
        corner_cells(&cells, gw, gh)
    } else {
        cells
    };
    let mut aov = AovFilm::from_cells(film.width, film.height, set, &cells, scene.origin);
    if set.id {
        let mut present = aov.id.clone();
        present.sort_unstable();
        present.dedup();
        aov.ids = ids::entries(scene, &map, &present);
    }
    Ok((film, aov, RenderStats::finish(rays, start)))
}

/// The `(gw − 1) × (gh − 1)` pixels of a `gw × gh` grid of corners.
fn corner_cells(cells: &[Cell], gw: u32, gh: u32) -> Vec<Cell> {
    let at = |i: u32, j: u32| cells[(j * gw + i) as usize];
    let mut out = Vec::with_capacity(((gw - 1) * (gh - 1)) as usize);
    for j in 0..gh - 1 {
        for i in 0..gw - 1 {
            out.push(Cell::corners([
                at(i, j),
                at(i + 1, j),
                at(i, j + 1),
                at(i + 1, j + 1),
            ]));
        }
    }
    out
}
