//! The spheres, cones and polygons of an SPD database as the NFF loader makes them
//! from their printed numbers ([`sphere_of`], [`cone_of`], [`Piece::polygon`]), and
//! [`PrimBatch`], which gathers them in entity order and makes a batch of them at once
//! on the current rayon pool, so that the scene builder (`super::spd_scene`) makes a
//! large database's primitives in parallel, as the loader parses a large file.
//!
//! Each primitive is made from its own numbers and the frame's origin alone (a polygon
//! is rounded and triangulated by the thread that makes it, with a triangulator of its
//! own), so the batch's results, added in order with the lines and materials they were
//! queued with, are what making them one at a time would add. A batch is cut into
//! pieces of about equal work, a polygon counting as many as its triangles, made one
//! piece per task. A full batch is made while the batch before it is added to the
//! scene's lists (which grow, page by page, on the builder's thread): the pool makes
//! the next batch meanwhile instead of waiting, and the last batch is added when the
//! builder drains it ([`PrimBatch::drain`]).

use super::spd_points::PointCache;
use crate::geometry::polygon::Triangulator;
use crate::geometry::{Cone, Intersect, Kind, Sphere, Triangle};
use crate::load::nff::{Part, unit_normal, world_bounds};
use crate::math::{DVec3, Vec3};
use crate::scene::range;
use crate::spd::{g_f32, g_f64};
use glam::DVec3 as D;
use rayon::prelude::*;

/// A full batch is made in at most this many pieces, one after the other in each (a
/// piece of a large batch is large enough that splitting it would cost more than it
/// saves).
const PIECES: usize = 64;

/// Point `p` as the loader reads it once printed, in the frame whose origin (the first
/// viewpoint's eye) is `origin`; `None` where the loader would refuse it (not finite,
/// out of range).
pub(crate) fn scene_point(origin: DVec3, p: D) -> Option<Vec3> {
    let world = D::new(g_f64(p.x), g_f64(p.y), g_f64(p.z));
    let finite = world.is_finite() && world.as_vec3().is_finite();
    (finite && range::check_point("", world.as_vec3()).is_ok()).then(|| (world - origin).as_vec3())
}

/// A number the loader reads in single precision, if it reads as finite.
fn finite_f32(x: f64) -> Option<f32> {
    Some(g_f32(x)).filter(|v| v.is_finite())
}

/// The sphere the loader reads from `s` with `center` and `radius` printed, in the
/// frame of the first viewpoint's eye `origin`; `None` where the loader would refuse
/// or warn (no viewpoint yet, a number out of range, a zero radius).
pub(crate) fn sphere_of(origin: Option<DVec3>, center: D, radius: f64) -> Option<Sphere> {
    let origin = origin?;
    let center = scene_point(origin, center)?;
    let r = finite_f32(radius).filter(|&r| r != 0.0)?;
    let sphere = Sphere::new(center, r);
    let bounds = world_bounds(origin, &sphere.bounds());
    range::check_bounds("the sphere", &bounds)
        .is_ok()
        .then_some(sphere)
}

/// The cone the loader reads from `c` with its numbers printed, as [`sphere_of`];
/// `None` also for two zero radii, radii of opposite signs and a base at the apex.
pub(crate) fn cone_of(
    origin: Option<DVec3>,
    base: D,
    base_radius: f64,
    apex: D,
    apex_radius: f64,
) -> Option<Cone> {
    let origin = origin?;
    let (base, rb) = (scene_point(origin, base)?, finite_f32(base_radius)?);
    let (apex, ra) = (scene_point(origin, apex)?, finite_f32(apex_radius)?);
    let same_side = !((rb < 0.0 && ra > 0.0) || (rb > 0.0 && ra < 0.0));
    if (rb == 0.0 && ra == 0.0) || !same_side || base == apex {
        return None;
    }
    let cone = Cone::new(base, rb, apex, ra);
    let bounds = world_bounds(origin, &cone.bounds());
    range::check_bounds("the cone", &bounds)
        .is_ok()
        .then_some(cone)
}

/// A sphere's, a cone's or a polygon's numbers, as the database gave them.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Prim {
    /// `s`: centre, radius.
    Sphere(D, f64),
    /// `c`: base, base radius, apex, apex radius.
    Cone(D, f64, D, f64),
    /// `p` or `pp`: `len` vertices from `first` on in the batch's vertices, and for a
    /// `pp` their normals from `normals` on in its normals.
    Polygon {
        first: usize,
        len: usize,
        normals: Option<usize>,
    },
}

/// A primitive as the loader makes it.
#[derive(Clone, Copy, Debug)]
enum Made {
    Sphere(Sphere),
    Cone(Cone),
    /// A polygon's triangles: `len` of its piece's triangles from `first` on, and for a
    /// `pp` as many of its vertex normals from `normals` on.
    Polygon {
        first: usize,
        len: usize,
        normals: Option<usize>,
    },
    /// A polygon the loader drops as degenerate.
    Degenerate,
}

/// A primitive waiting to be made: its numbers, its line and its material (the
/// [`Part::material_index`] on its line, `INHERITED` before the first `f`).
#[derive(Clone, Copy, Debug)]
struct Queued {
    prim: Prim,
    line: u32,
    material: u32,
}

/// What one thread makes of consecutive queued primitives, and its scratch, kept from
/// batch to batch.
#[derive(Debug, Default)]
struct Piece {
    /// Per primitive: what it made, `None` if the loader would refuse it.
    made: Vec<Option<Made>>,
    /// The polygons' triangles, and the vertex normals of those of `pp`s.
    tris: Vec<Triangle>,
    normals: Vec<[Vec3; 3]>,
    /// Scratch: a polygon's points and unit normals, and its triangles' corners.
    pts: Vec<Vec3>,
    nrm: Vec<Vec3>,
    corners: Vec<[usize; 3]>,
    triangulator: Triangulator,
    /// The points of the last polygons made.
    points: PointCache,
}

impl Piece {
    /// Make `queued` (whose polygons' numbers are in `verts` and `normals`) in the frame
    /// of `origin`.
    fn make(&mut self, queued: &[Queued], verts: &[D], normals: &[D], origin: Option<DVec3>) {
        self.made.clear();
        self.tris.clear();
        self.normals.clear();
        for q in queued {
            let made = match q.prim {
                Prim::Sphere(c, r) => sphere_of(origin, c, r).map(Made::Sphere),
                Prim::Cone(b, rb, a, ra) => cone_of(origin, b, rb, a, ra).map(Made::Cone),
                Prim::Polygon {
                    first,
                    len,
                    normals: n,
                } => {
                    let vs = &verts[first..first + len];
                    let ns = n.map(|n| &normals[n..n + len]);
                    self.polygon(vs, ns, origin)
                }
            };
            self.made.push(made);
        }
    }

    /// The polygon the loader reads from `p` (or `pp`, with `normals`) with its numbers
    /// printed, triangulated into the piece's triangles; `None` where the loader would
    /// refuse it (a point not finite or out of range, a zero normal).
    fn polygon(
        &mut self,
        verts: &[D],
        normals: Option<&[D]>,
        origin: Option<DVec3>,
    ) -> Option<Made> {
        let origin = origin?;
        self.pts.clear();
        self.nrm.clear();
        for (k, &v) in verts.iter().enumerate() {
            self.pts.push(self.points.point(origin, v)?);
            if let Some(n) = normals {
                let n = n[k];
                let n = Vec3::new(finite_f32(n.x)?, finite_f32(n.y)?, finite_f32(n.z)?);
                self.nrm.push(unit_normal(n)?);
            }
        }
        if self
            .triangulator
            .triangulate(&self.pts, &mut self.corners)
            .is_err()
        {
            return Some(Made::Degenerate);
        }
        let first = self.tris.len();
        let first_normal = normals.map(|_| self.normals.len());
        let (pts, nrm) = (&self.pts, &self.nrm);
        self.tris
            .extend(self.corners.iter().map(|&[a, b, c]| Triangle {
                p: [pts[a], pts[b], pts[c]],
            }));
        if normals.is_some() {
            let corners = self.corners.iter();
            self.normals
                .extend(corners.map(|&[a, b, c]| [nrm[a], nrm[b], nrm[c]]));
        }
        let len = self.corners.len();
        Some(Made::Polygon {
            first,
            len,
            normals: first_normal,
        })
    }

    /// Add what the piece made of `queued` to `part` in order, with the lines and
    /// materials they were queued with, if the loader would have made all of them;
    /// whether it would.
    fn add(&self, queued: &[Queued], part: &mut Part) -> bool {
        if !self.made.iter().all(Option::is_some) {
            return false;
        }
        for (made, q) in self.made.iter().zip(queued) {
            let (line, material) = (q.line, q.material);
            match *made {
                Some(Made::Sphere(s)) => part.add_analytic_with(s, Kind::Sphere, line, material),
                Some(Made::Cone(c)) => part.add_analytic_with(c, Kind::Cone, line, material),
                Some(Made::Polygon {
                    first,
                    len,
                    normals,
                }) => {
                    let tris = &self.tris[first..first + len];
                    let normals = normals.map(|n| &self.normals[n..n + len]);
                    let added = part.add_triangulated(tris, normals, line, material);
                    if added.is_err() {
                        return false;
                    }
                }
                Some(Made::Degenerate) => part.add_degenerate(|| (line as usize, 1)),
                None => {}
            }
        }
        true
    }
}

/// Queued primitives cut into pieces, and what the pieces made of them.
#[derive(Debug, Default)]
struct Stage {
    pending: Vec<Queued>,
    /// Where the pieces made one after the other on one thread end in `pending`.
    cuts: Vec<usize>,
    /// Scratch: what each piece made.
    pieces: Vec<Piece>,
}

impl Stage {
    /// Make every piece (whose polygons' numbers are in `verts` and `normals`) in the
    /// frame of `origin`, on the current rayon pool.
    fn make(&mut self, verts: &[D], normals: &[D], origin: Option<DVec3>) {
        if self.cuts.last() != Some(&self.pending.len()) {
            self.cuts.push(self.pending.len());
        }
        let n = self.cuts.len();
        if self.pieces.len() < n {
            self.pieces.resize_with(n, Piece::default);
        }
        let (pending, cuts) = (&self.pending[..], &self.cuts[..]);
        self.pieces[..n]
            .par_iter_mut()
            .enumerate()
            .for_each(|(k, piece)| {
                piece.make(&pending[piece_range(cuts, k)], verts, normals, origin)
            });
    }

    /// Add what the pieces made to `part` in order, then empty the stage; whether the
    /// loader would have made all of it (true for an empty stage).
    fn add(&mut self, part: &mut Part) -> bool {
        let (pending, cuts) = (&self.pending[..], &self.cuts[..]);
        let all_made = (self.pieces.iter().enumerate().take(cuts.len()))
            .all(|(k, piece)| piece.add(&pending[piece_range(cuts, k)], part));
        self.pending.clear();
        self.cuts.clear();
        all_made
    }
}

/// The queued primitives of piece `k` of a stage whose pieces end at `cuts`.
fn piece_range(cuts: &[usize], k: usize) -> std::ops::Range<usize> {
    let start = if k == 0 { 0 } else { cuts[k - 1] };
    start..cuts[k]
}

/// Primitives waiting to be made, in entity order, and the batch made last, waiting to
/// be added: a full batch is made on the pool while the one before it is added on the
/// builder's thread ([`PrimBatch::flush`]), so that the pool does not wait for the
/// scene's lists to grow.
#[derive(Debug)]
pub(crate) struct PrimBatch {
    /// The primitives queued since the last flush.
    queued_stage: Stage,
    /// The batch made at the last flush, not yet added.
    made: Stage,
    /// The queued polygons' vertices and the queued `pp`s' normals.
    verts: Vec<D>,
    normals: Vec<D>,
    /// How much work waits before [`PrimBatch::push`] says the batch is full: one for
    /// a sphere or cone, a polygon's triangles (its vertices less two) for a polygon.
    capacity: usize,
    /// The work queued.
    queued: usize,
    /// The work queued since the last cut of `queued_stage`.
    piece_work: usize,
    /// Scratch: the spheres made of a batch of them.
    spheres: Vec<Option<Sphere>>,
}

impl PrimBatch {
    /// An empty batch that is full at `capacity` primitives (at least one).
    pub fn new(capacity: usize) -> Self {
        PrimBatch {
            queued_stage: Stage::default(),
            made: Stage::default(),
            verts: Vec::new(),
            normals: Vec::new(),
            capacity: capacity.max(1),
            queued: 0,
            piece_work: 0,
            spheres: Vec::new(),
        }
    }

    /// The least work made one after the other on one thread.
    fn piece_len(&self) -> usize {
        self.capacity.div_ceil(PIECES)
    }

    /// The primitives a batch holds when full.
    pub fn capacity(&self) -> usize {
        self.capacity
    }

    /// Queue `prim` of line `line`, whose material is `material` (the part's
    /// [`Part::material_index`] on that line); true when the batch is full.
    pub fn push(&mut self, prim: Prim, line: u32, material: u32) -> bool {
        self.queue(prim, line, material, 1)
    }

    /// Queue the polygon `verts` (a `pp` with `normals`, one per vertex) of line `line`,
    /// whose material is `material` (the part's [`Part::material_index`] on that line,
    /// `INHERITED` before its first `f`, even if it then inherits nothing); true when
    /// the batch is full.
    pub fn push_polygon(
        &mut self,
        verts: &[D],
        normals: Option<&[D]>,
        line: u32,
        material: u32,
    ) -> bool {
        let prim = Prim::Polygon {
            first: self.verts.len(),
            len: verts.len(),
            normals: normals.map(|_| self.normals.len()),
        };
        self.verts.extend_from_slice(verts);
        if let Some(n) = normals {
            self.normals.extend_from_slice(&n[..verts.len()]);
        }
        self.queue(prim, line, material, verts.len().saturating_sub(2).max(1))
    }

    fn queue(&mut self, prim: Prim, line: u32, material: u32, work: usize) -> bool {
        let piece_len = self.piece_len();
        let stage = &mut self.queued_stage;
        stage.pending.push(Queued {
            prim,
            line,
            material,
        });
        self.queued += work;
        self.piece_work += work;
        if self.piece_work >= piece_len {
            stage.cuts.push(stage.pending.len());
            self.piece_work = 0;
        }
        self.queued >= self.capacity
    }

    /// Make the queued primitives in the frame of `origin`, in parallel, while the
    /// batch made at the last flush is added to `part` in order; the batch made now is
    /// added at the next flush or [`PrimBatch::drain`]. Returns false if the loader
    /// would have refused one of the primitives added (see [`sphere_of`],
    /// [`Piece::polygon`]): the build has failed, and what was added is of no use.
    pub fn flush(&mut self, origin: Option<DVec3>, part: &mut Part) -> bool {
        if self.queued_stage.pending.is_empty() {
            return self.drain(part);
        }
        let (verts, normals) = (&self.verts[..], &self.normals[..]);
        let (made, queued) = (&mut self.made, &mut self.queued_stage);
        let (all_added, ()) =
            rayon::join(|| made.add(part), || queued.make(verts, normals, origin));
        std::mem::swap(&mut self.made, &mut self.queued_stage);
        self.verts.clear();
        self.normals.clear();
        (self.queued, self.piece_work) = (0, 0);
        all_added
    }

    /// Add the batch made at the last flush to `part`, if it is not yet; false as
    /// [`PrimBatch::flush`] returns it.
    pub fn drain(&mut self, part: &mut Part) -> bool {
        self.made.add(part)
    }

    /// The queued primitives, then `spheres` (`(centre, radius)`, on one line each from
    /// `first_line` on), made and added as [`PrimBatch::flush`] does.
    pub fn spheres(
        &mut self,
        spheres: &[(D, f64)],
        first_line: u32,
        origin: Option<DVec3>,
        part: &mut Part,
    ) -> bool {
        let flushed = self.flush(origin, part);
        let queued_made = self.drain(part) && flushed;
        let make = |&(center, radius): &(D, f64)| sphere_of(origin, center, radius);
        let piece = self.piece_len();
        make_all(spheres, piece, make, &mut self.spheres);
        let all_made = self.spheres.iter().all(Option::is_some);
        if all_made {
            let made = self.spheres.iter().flatten().copied();
            part.add_analytic_lines(made, Kind::Sphere, first_line);
        }
        all_made && queued_made
    }
}

/// `out[k] = make(&items[k])` for every item, on the current rayon pool, in pieces of
/// at least `piece` items.
fn make_all<T: Sync, U: Send>(
    items: &[T],
    piece: usize,
    make: impl Fn(&T) -> Option<U> + Sync + Send,
    out: &mut Vec<Option<U>>,
) {
    items
        .par_iter()
        .with_min_len(piece)
        .map(make)
        .collect_into_vec(out);
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Arc;

    const ORIGIN: Option<DVec3> = Some(DVec3::ZERO);

    /// The `k`-th of some quadrilaterals, each two triangles.
    fn quad(k: usize) -> [D; 4] {
        let x = k as f64;
        [
            D::new(x, 0.0, 0.0),
            D::new(x + 1.0, 0.0, 0.0),
            D::new(x + 1.0, 1.0, 0.0),
            D::new(x, 1.0, 0.0),
        ]
    }

    /// Queue `n` quadrilaterals, one every five lines, flushing whenever the batch is
    /// full; the part they went to and whether every flush succeeded.
    fn queue_quads(batch: &mut PrimBatch, n: usize, part: &mut Part) -> bool {
        let mut ok = true;
        for k in 0..n {
            let line = 1 + 5 * k as u32;
            if batch.push_polygon(&quad(k), None, line, 0) {
                ok &= batch.flush(ORIGIN, part);
            }
        }
        ok
    }

    /// A flushed batch is made at once and added at the next flush or drain, after
    /// the batches before it.
    #[test]
    fn a_made_batch_is_added_at_the_next_flush_or_drain() {
        let mut part = Part::new(Arc::from("x"));
        let mut batch = PrimBatch::new(4);
        assert!(queue_quads(&mut batch, 2, &mut part));
        assert_eq!(part.geometry.triangles.len(), 0, "the first batch waits");
        assert!(queue_quads(&mut batch, 2, &mut part));
        assert_eq!(
            part.geometry.triangles.len(),
            4,
            "added at the second flush"
        );
        assert!(batch.flush(ORIGIN, &mut part));
        assert_eq!(part.geometry.triangles.len(), 8);
        assert!(batch.drain(&mut part));
        assert!(batch.drain(&mut part), "nothing left to add");
        assert_eq!(part.geometry.triangles.len(), 8);
        assert_eq!(part.polygons, 4);
    }

    /// Batches of any size on one and on three threads add the same triangles in the
    /// same order as one batch holding them all.
    #[test]
    fn overlapped_batches_add_what_one_batch_adds_on_any_pool() {
        let build = |capacity: usize| {
            let mut part = Part::new(Arc::from("x"));
            let mut batch = PrimBatch::new(capacity);
            assert!(queue_quads(&mut batch, 50, &mut part));
            assert!(batch.flush(ORIGIN, &mut part) && batch.drain(&mut part));
            part
        };
        let whole = build(1 << 20);
        assert_eq!(whole.geometry.triangles.len(), 100);
        for threads in [1, 3] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            for capacity in [1, 2, 3, 7, 64] {
                let part = pool.install(|| build(capacity));
                let what = format!("{threads} threads, batches of {capacity}");
                assert_eq!(part.geometry, whole.geometry, "{what}");
                let (got, want) = (&part.geometry.sources, &whole.geometry.sources);
                assert!(got.same_origins(want), "{what}");
            }
        }
    }

    /// A primitive the loader would refuse in the last batch made is reported when
    /// that batch is drained.
    #[test]
    fn a_refusal_in_the_last_batch_is_reported_when_it_is_drained() {
        let mut part = Part::new(Arc::from("x"));
        let mut batch = PrimBatch::new(2);
        assert!(queue_quads(&mut batch, 3, &mut part));
        batch.push(Prim::Sphere(D::ZERO, 0.0), 20, 0);
        assert!(
            batch.flush(ORIGIN, &mut part),
            "the batch before it is made"
        );
        assert!(!batch.drain(&mut part), "a sphere of radius zero");
    }
}
