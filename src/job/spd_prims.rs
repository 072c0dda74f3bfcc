//! The spheres and cones of an SPD database as the NFF loader makes them from their
//! printed numbers ([`sphere_of`], [`cone_of`]), and [`PrimBatch`], which gathers
//! them in entity order and makes a batch of them at once on the current rayon pool,
//! so that the scene builder (`super::spd_scene`) makes a large database's primitives
//! in parallel, as the loader parses a large file.
//!
//! Each primitive is made from its own numbers and the frame's origin alone, so the
//! batch's results, added in order with the lines and materials they were queued
//! with, are what making them one at a time would add.

use crate::geometry::{Cone, Intersect, Kind, Sphere};
use crate::load::nff::{Part, world_bounds};
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

/// A sphere's or a cone's numbers, as the database gave them.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Prim {
    /// `s`: centre, radius.
    Sphere(D, f64),
    /// `c`: base, base radius, apex, apex radius.
    Cone(D, f64, D, f64),
}

/// A primitive as the loader makes it.
#[derive(Clone, Copy, Debug)]
enum Made {
    Sphere(Sphere),
    Cone(Cone),
}

impl Prim {
    /// The primitive the loader makes of these numbers in the frame of `origin`.
    fn make(&self, origin: Option<DVec3>) -> Option<Made> {
        match *self {
            Prim::Sphere(c, r) => sphere_of(origin, c, r).map(Made::Sphere),
            Prim::Cone(b, rb, a, ra) => cone_of(origin, b, rb, a, ra).map(Made::Cone),
        }
    }
}

/// A primitive waiting to be made: its numbers, its line and its material (the
/// [`Part::material_index`] on its line).
#[derive(Clone, Copy, Debug)]
struct Queued {
    prim: Prim,
    line: u32,
    material: u32,
}

/// Primitives waiting to be made, in entity order.
#[derive(Debug)]
pub(crate) struct PrimBatch {
    pending: Vec<Queued>,
    /// How many wait before [`PrimBatch::push`] says the batch is full.
    capacity: usize,
    /// Scratch: the primitives made of `pending`.
    made: Vec<Option<Made>>,
    /// Scratch: the spheres made of a batch of them.
    spheres: Vec<Option<Sphere>>,
}

impl PrimBatch {
    /// An empty batch that is full at `capacity` primitives (at least one).
    pub fn new(capacity: usize) -> Self {
        PrimBatch {
            pending: Vec::new(),
            capacity: capacity.max(1),
            made: Vec::new(),
            spheres: Vec::new(),
        }
    }

    /// The fewest primitives made one after the other on one thread.
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
        self.pending.push(Queued {
            prim,
            line,
            material,
        });
        self.pending.len() >= self.capacity
    }

    /// Make the queued primitives in the frame of `origin`, in parallel, and add them
    /// to `part` in order. Returns false, adding none, if the loader would have refused
    /// or warned about one of them (see [`sphere_of`]).
    pub fn flush(&mut self, origin: Option<DVec3>, part: &mut Part) -> bool {
        if self.pending.is_empty() {
            return true;
        }
        let piece = self.piece_len();
        make_all(
            &self.pending,
            piece,
            |q| q.prim.make(origin),
            &mut self.made,
        );
        let all_made = add_all(&self.made, &self.pending, part);
        self.pending.clear();
        all_made
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
        let queued_made = self.flush(origin, part);
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

/// Add every primitive of `made` to `part` with the line and material it was queued
/// with, in order, if all were made; whether they were.
fn add_all(made: &[Option<Made>], queued: &[Queued], part: &mut Part) -> bool {
    if !made.iter().all(Option::is_some) {
        return false;
    }
    for (made, q) in made.iter().zip(queued) {
        match made {
            Some(Made::Sphere(s)) => part.add_analytic_with(*s, Kind::Sphere, q.line, q.material),
            Some(Made::Cone(c)) => part.add_analytic_with(*c, Kind::Cone, q.line, q.material),
            None => {}
        }
    }
    true
}
