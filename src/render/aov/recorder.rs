//! The recorder that gathers the output variables of each sample-grid position of a
//! tile from the tracer's hooks: the first surface each eye ray is shaded at (its
//! distance, point, shading normal, albedo and primitive), the rays cast for the
//! position, the deepest of them, and the time spent on it.

use super::ids::{IdMap, NO_ID};
use super::{AovSet, Cell};
use crate::math::Vec3;
use crate::render::RayCounts;
use crate::render::record::{Met, RayKind, Recorder, Traced};
use crate::scene::Material;
use std::time::Instant;

/// Gathers one [`Cell`] per position of a tile, in the tile's order.
pub(super) struct AovRecorder<'a> {
    ids: &'a IdMap,
    want: AovSet,
    counts: RayCounts,
    /// The finished positions.
    pub(super) cells: Vec<Cell>,
    /// The position being traced.
    cur: Cell,
    /// Its samples' ids with how many samples saw each.
    votes: Vec<(u32, u32)>,
    /// Rays counted before the position began.
    rays_before: u64,
    /// When the position began (only when time is wanted).
    start: Option<Instant>,
    /// When the tile's coherent eye rays began to be cast.
    coherent_start: Option<Instant>,
    /// Each position's share of that cast, in nanoseconds.
    coherent_share_ns: f64,
    /// How many rays are being followed (1: the eye ray).
    level: u32,
    /// The eye ray's origin.
    eye: Vec3,
    /// The eye ray was shaded at a surface whose material is still to come.
    pending: bool,
}

impl<'a> AovRecorder<'a> {
    pub(super) fn new(ids: &'a IdMap, want: AovSet) -> Self {
        AovRecorder {
            ids,
            want,
            counts: RayCounts::default(),
            cells: Vec::new(),
            cur: Cell::default(),
            votes: Vec::new(),
            rays_before: 0,
            start: None,
            coherent_start: None,
            coherent_share_ns: 0.0,
            level: 0,
            eye: Vec3::ZERO,
            pending: false,
        }
    }

    /// The counts of the tile.
    pub(super) fn counts(&self) -> RayCounts {
        self.counts
    }

    /// The id most of the position's samples saw (the earliest seen among equals).
    fn winner(&self) -> u32 {
        let mut best = (NO_ID, 0);
        for &(id, n) in &self.votes {
            if n > best.1 {
                best = (id, n);
            }
        }
        best.0
    }
}

impl Recorder for AovRecorder<'_> {
    const ACTIVE: bool = true;

    fn counts(&mut self) -> &mut RayCounts {
        &mut self.counts
    }

    fn coherent(&mut self, start: bool, rays: usize) {
        if !self.want.time {
            return;
        }
        if start {
            self.coherent_start = Some(Instant::now());
        } else if let Some(t) = self.coherent_start.take() {
            self.coherent_share_ns = t.elapsed().as_nanos() as f64 / rays.max(1) as f64;
        }
    }

    fn position(&mut self, _i: u32, _j: u32) {
        self.cur = Cell::default();
        self.votes.clear();
        self.rays_before = self.counts.total();
        self.level = 0;
        self.pending = false;
        if self.want.time {
            self.start = Some(Instant::now());
        }
    }

    fn position_end(&mut self, _value: Vec3) {
        self.cur.rays = (self.counts.total() - self.rays_before) as f32;
        if let Some(t) = self.start.take() {
            let ns = t.elapsed().as_nanos() as f64 + self.coherent_share_ns;
            self.cur.time = ns as f32;
        }
        self.cur.id = self.winner();
        self.cells.push(self.cur);
    }

    fn ray(&mut self, t: &Traced) {
        self.level += 1;
        self.cur.depth = self.cur.depth.max(t.depth);
        if t.kind == RayKind::Eye {
            self.eye = t.ray.org;
        }
    }

    fn ray_end(&mut self, _radiance: Vec3) {
        self.level = self.level.saturating_sub(1);
    }

    fn hit(&mut self, at: &Met) {
        if self.level != 1 {
            return;
        }
        let p = at.surf.point.p;
        let c = &mut self.cur;
        c.hits += 1;
        c.z += (p - self.eye).length();
        c.p += p;
        let id = self.ids.id(at.hit);
        match self.votes.iter_mut().find(|(v, _)| *v == id) {
            Some((_, n)) => *n += 1,
            None => self.votes.push((id, 1)),
        }
        self.pending = true;
    }

    fn shading(&mut self, m: &Material, ns: Vec3) {
        if self.level != 1 || !self.pending {
            return;
        }
        self.pending = false;
        self.cur.n += ns;
        self.cur.albedo += m.color * m.kd;
    }
}
