//! The sample grid of a render cut into square tiles rendered in parallel, the result
//! independent of the schedule: uniform sampling (the pixels, or the pixel corners in
//! SPD mode) and Whitted's adaptive subdivision. Each tile records with its own
//! [`Recorder`]: a plain render's counts, or the per-pixel output variables.

use super::record::Recorder;
use super::whitted::Tracer;
use super::{Film, Progress, RayCounts, RayGen, Region, RenderSettings, TileValues, Watch};
use crate::accel::Accel;
use glam::Vec3;
use rayon::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};

/// The positions a render samples: the pixels of its region, or in SPD mode the
/// region's pixel corners (one more row and column), in the whole image's grid.
pub(super) struct Positions {
    /// The grid's top-left position.
    pub origin: (u32, u32),
    /// Its size.
    pub size: (u32, u32),
    /// The size of the whole image's grid (the eye rays' frame).
    pub full: (u32, u32),
}

impl Positions {
    pub(super) fn of(settings: &RenderSettings) -> Self {
        let (w, h) = (settings.width, settings.height);
        // Only the samples of the region: every pixel and sample keeps its coordinates
        // in the whole image, so a part holds exactly the full render's pixels.
        let r = settings.region.unwrap_or(Region::full(w, h));
        let extra = u32::from(settings.spd);
        Positions {
            origin: (r.x0, r.y0),
            size: (r.width() + extra, r.height() + extra),
            full: (w + extra, h + extra),
        }
    }
}

/// Render `settings`' region with uniform samples (SPD corners averaged into pixels),
/// each tile recording with a recorder from `new`; the recorders are returned in the
/// order of [`tiles`].
pub(super) fn uniform_render<A, R, N>(
    tracer: &Tracer<'_, A>,
    settings: &RenderSettings,
    progress: Option<Progress<'_>>,
    new: N,
) -> (Film, Vec<R>)
where
    A: Accel,
    R: Recorder + Send,
    N: Fn() -> R + Sync,
{
    let at = Positions::of(settings);
    let raygen = RayGen::new(&tracer.scene.camera, at.full.0, at.full.1);
    let (ox, oy) = at.origin;
    let (gw, gh) = at.size;
    let (grid, recs) = sample_grid(
        ox,
        oy,
        gw,
        gh,
        settings.tile_size,
        progress,
        new,
        |t, out, r| {
            tracer.tile(&raygen, t, &mut |v| out.push(v), r);
        },
    );
    let film = if settings.spd {
        grid.average_corners()
    } else {
        grid
    };
    (film, recs)
}

/// Render `settings`' region with Whitted's adaptive subdivision: the rays through
/// every pixel corner, then each pixel refined from its four.
pub(super) fn adaptive_render<A: Accel>(
    tracer: &Tracer<'_, A>,
    settings: &RenderSettings,
    threshold: f32,
    depth: u32,
    progress: Option<Progress<'_>>,
) -> (Film, RayCounts) {
    let (w, h) = (settings.width, settings.height);
    let r = settings.region.unwrap_or(Region::full(w, h));
    let raygen = RayGen::new(&tracer.scene.camera, w, h);
    let (cw, ch) = (r.width() + 1, r.height() + 1);
    let corner = per_position(|i, j, c| tracer.sample(&raygen, i as f32, j as f32, c));
    // The corners are not the image: they are counted as no tiles, but they stop too.
    let stop = progress.map(Stop);
    let (corners, tiles) = sample_grid(
        r.x0,
        r.y0,
        cw,
        ch,
        settings.tile_size,
        stop.as_ref().map(|s| s as &dyn Watch),
        RayCounts::default,
        corner,
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
    let (film, more) = sample_grid(
        r.x0,
        r.y0,
        rw,
        rh,
        settings.tile_size,
        progress,
        RayCounts::default,
        refine,
    );
    let mut rays = RayCounts::default();
    for counts in tiles.into_iter().chain(more) {
        rays += counts;
    }
    (film, rays)
}

/// A [`Watch`] that tells nothing but passes on whether to stop.
struct Stop<'a>(Progress<'a>);

impl Watch for Stop<'_> {
    fn tiles(&self, _done: usize, _total: usize) {}

    fn cancelled(&self) -> bool {
        self.0.cancelled()
    }
}

/// A per-position function `f(i, j, counts)` as a tile function for [`sample_grid`]:
/// the tile's positions row by row.
fn per_position<F>(f: F) -> impl Fn(Region, &mut TileRows<'_>, &mut RayCounts) + Sync
where
    F: Fn(u32, u32, &mut RayCounts) -> Vec3 + Sync,
{
    move |t, out, counts| {
        for j in t.y0..t.y1 {
            for i in t.x0..t.x1 {
                out.push(f(i, j, counts));
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

/// The tiles of edge `tile` of a `gw × gh` grid, as the top-left position of each
/// relative to the grid's, row by row.
pub(super) fn tiles(gw: u32, gh: u32, tile: u32) -> Vec<(u32, u32)> {
    let ts = tile.max(1);
    (0..gh.div_ceil(ts))
        .flat_map(|ty| (0..gw.div_ceil(ts)).map(move |tx| (tx * ts, ty * ts)))
        .collect()
}

/// Put per-tile values (each tile's positions row by row, tiles in the order of
/// [`tiles`]) into a `gw × gh` row-major grid.
pub(super) fn scatter<T: Copy + Default>(
    gw: u32,
    gh: u32,
    tile: u32,
    per_tile: impl IntoIterator<Item = Vec<T>>,
) -> Vec<T> {
    let ts = tile.max(1);
    let mut grid = vec![T::default(); gw as usize * gh as usize];
    for ((x0, y0), values) in tiles(gw, gh, tile).into_iter().zip(per_tile) {
        let x1 = (x0 + ts).min(gw);
        let mut it = values.into_iter();
        for j in y0..(y0 + ts).min(gh) {
            for i in x0..x1 {
                grid[(j * gw + i) as usize] = it.next().expect("tile size");
            }
        }
    }
    grid
}

/// Evaluate the `gw × gh` grid whose top-left is `(ox, oy)` in parallel square tiles
/// of edge `tile`, the result independent of the schedule: `f(tile, out, rec)` gives
/// the values of the tile's grid positions (absolute coordinates, row by row) to
/// `out`, recording with a recorder `new` makes for the tile, and the film's pixel
/// `(i, j)` is the value of position `(ox + i, oy + j)`. Each tile writes straight into
/// its rows of the film: no buffer per tile, nothing left to assemble after the
/// parallel part. The recorders come back in the order of [`tiles`].
#[allow(clippy::too_many_arguments)]
fn sample_grid<R, N, F>(
    ox: u32,
    oy: u32,
    gw: u32,
    gh: u32,
    tile: u32,
    progress: Option<Progress<'_>>,
    new: N,
    f: F,
) -> (Film, Vec<R>)
where
    R: Send,
    N: Fn() -> R + Sync,
    F: Fn(Region, &mut TileRows<'_>, &mut R) + Sync,
{
    let ts = tile.max(1);
    let tiles = tiles(gw, gh, tile);
    let done = AtomicUsize::new(0);
    let total = tiles.len();
    let mut film = Film::new(gw, gh);
    let rows = tile_rows(&mut film.pixels, gw, ts);
    // The count first, so that a progress bar starts at 0 of it.
    if let Some(p) = progress {
        p.tiles(0, total);
    }
    // One task per tile: rayon otherwise splits the list only as far as it sees
    // threads steal, and a run of costly tiles (glass, mirrors) left in one thread's
    // last piece keeps it busy while the other waits with nothing to take.
    let recs: Vec<R> = rows
        .into_par_iter()
        .zip(tiles.par_iter())
        .with_max_len(1)
        .map(|(rows, &(x0, y0))| {
            let mut rec = new();
            let t = Region {
                x0: ox + x0,
                y0: oy + y0,
                x1: ox + (x0 + ts).min(gw),
                y1: oy + (y0 + ts).min(gh),
            };
            if progress.is_some_and(|p| p.cancelled()) {
                return rec;
            }
            let mut out = TileRows::new(rows);
            f(t, &mut out, &mut rec);
            debug_assert!(out.is_full(), "a tile function gave too few values");
            if let Some(p) = progress {
                p.tile(TileValues::new(t, &out.rows));
                p.tiles(done.fetch_add(1, Ordering::Relaxed) + 1, total);
            }
            rec
        })
        .collect();
    (film, recs)
}

/// The rows of each tile of edge `ts` of a `gw`-wide row-major grid, as disjoint
/// slices of `pixels`, tiles in the order of [`tiles`].
fn tile_rows(pixels: &mut [Vec3], gw: u32, ts: u32) -> Vec<Vec<&mut [Vec3]>> {
    let (gw, ts) = (gw as usize, ts as usize);
    let across = gw.div_ceil(ts);
    let down = (pixels.len() / gw.max(1)).div_ceil(ts);
    let mut out: Vec<Vec<&mut [Vec3]>> =
        (0..across * down).map(|_| Vec::with_capacity(ts)).collect();
    for (j, row) in pixels.chunks_mut(gw.max(1)).enumerate() {
        let first = j / ts * across;
        for (k, part) in row.chunks_mut(ts).enumerate() {
            out[first + k].push(part);
        }
    }
    out
}

/// Where a tile function puts its values: the tile's rows of the film, filled
/// position by position, row by row.
pub(super) struct TileRows<'a> {
    rows: Vec<&'a mut [Vec3]>,
    row: usize,
    col: usize,
}

impl<'a> TileRows<'a> {
    fn new(rows: Vec<&'a mut [Vec3]>) -> Self {
        TileRows {
            rows,
            row: 0,
            col: 0,
        }
    }

    /// The value of the next position.
    #[inline]
    pub(super) fn push(&mut self, v: Vec3) {
        let row = &mut self.rows[self.row];
        row[self.col] = v;
        self.col += 1;
        if self.col == row.len() {
            self.col = 0;
            self.row += 1;
        }
    }

    /// Whether every position has its value.
    fn is_full(&self) -> bool {
        self.row == self.rows.len()
    }
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
    k: [Vec3; 4],
    threshold: f32,
    depth: u32,
    c: &mut RayCounts,
) -> Vec3
where
    S: Fn(f32, f32, &mut RayCounts) -> Vec3,
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_tile_writes_its_own_positions_into_the_film() {
        for (gw, gh, tile) in [(1, 1, 16), (7, 5, 2), (33, 17, 16), (16, 16, 16), (5, 9, 1)] {
            let (ox, oy) = (3, 11);
            let (film, recs) = sample_grid(
                ox,
                oy,
                gw,
                gh,
                tile,
                None,
                Vec::new,
                |t, out, rec: &mut Vec<Region>| {
                    rec.push(t);
                    for j in t.y0..t.y1 {
                        for i in t.x0..t.x1 {
                            out.push(Vec3::new(i as f32, j as f32, 1.0));
                        }
                    }
                },
            );
            for j in 0..gh {
                for i in 0..gw {
                    let want = Vec3::new((ox + i) as f32, (oy + j) as f32, 1.0);
                    assert_eq!(film.get(i, j), want, "{gw}×{gh} tile {tile}: ({i}, {j})");
                }
            }
            let origins: Vec<(u32, u32)> =
                recs.iter().map(|r| (r[0].x0 - ox, r[0].y0 - oy)).collect();
            assert_eq!(
                origins,
                tiles(gw, gh, tile),
                "recorders in the order of the tiles"
            );
        }
    }
}
