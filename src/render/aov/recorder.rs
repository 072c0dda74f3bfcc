//! The recorder that gathers the output variables of each sample-grid position of a
//! tile from the tracer's hooks: the first surface each eye ray is shaded at (its
//! distance, point, shading normal, albedo and primitive), the rays cast for the
//! position, the deepest of them, and the time spent on it. The wavefront interleaves
//! the positions of a tile, so every ray is filed under its position by its node, and
//! the time between two hooks goes to the position of the first; a batch cast's time
//! is shared among its rays' positions.

use super::ids::{IdMap, NO_ID};
use super::{AovSet, Cell};
use crate::math::Vec3;
use crate::render::RayCounts;
use crate::render::record::{LightTerm, Met, Recorder, Traced};
use crate::scene::Material;
use std::collections::HashMap;
use std::time::Instant;

/// Gathers one [`Cell`] per position of a tile, in the tile's order.
pub(super) struct AovRecorder<'a> {
    ids: &'a IdMap,
    want: AovSet,
    counts: RayCounts,
    /// The finished positions.
    pub(super) cells: Vec<Cell>,
    /// The batch's rays, by node.
    nodes: Vec<RayOf>,
    /// The batch's positions being gathered.
    pending: HashMap<(u32, u32), Pending>,
    /// The position being completed.
    current: (u32, u32),
    /// When the last hook came (only when time is wanted), and for which node.
    clock: Option<(Instant, Option<u32>)>,
}

/// What the recorder keeps of a ray.
#[derive(Clone, Copy, Debug)]
struct RayOf {
    position: (u32, u32),
    depth: u32,
    /// Its origin (an eye ray's: the eye).
    org: Vec3,
}

/// A position being gathered: its cell, and its samples' ids with how many samples
/// saw each.
#[derive(Clone, Debug, Default)]
struct Pending {
    cell: Cell,
    votes: Vec<(u32, u32)>,
}

impl Pending {
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

impl<'a> AovRecorder<'a> {
    pub(super) fn new(ids: &'a IdMap, want: AovSet) -> Self {
        AovRecorder {
            ids,
            want,
            counts: RayCounts::default(),
            cells: Vec::new(),
            nodes: Vec::new(),
            pending: HashMap::new(),
            current: (0, 0),
            clock: None,
        }
    }

    /// The counts of the tile.
    pub(super) fn counts(&self) -> RayCounts {
        self.counts
    }

    /// The cell of ray `node`'s position.
    fn cell(&mut self, node: u32) -> &mut Cell {
        let position = self.nodes[node as usize].position;
        &mut self.pending.entry(position).or_default().cell
    }

    /// A hook about `node` (`None`: no node): the time since the last hook goes to the
    /// last hook's position.
    fn tick(&mut self, node: Option<u32>) {
        let Some((then, last)) = self.clock else {
            return;
        };
        let now = Instant::now();
        if let Some(last) = last {
            self.cell(last).time += (now - then).as_nanos() as f32;
        }
        self.clock = Some((now, node));
    }
}

impl Recorder for AovRecorder<'_> {
    const ACTIVE: bool = true;

    fn counts(&mut self) -> &mut RayCounts {
        &mut self.counts
    }

    fn batch(&mut self) {
        self.nodes.clear();
        self.pending.clear();
        self.clock = self.want.time.then(|| (Instant::now(), None));
    }

    fn cast(&mut self, start: bool, nodes: &[u32]) {
        if start {
            self.tick(None);
            return;
        }
        let Some((then, _)) = self.clock else {
            return;
        };
        let now = Instant::now();
        let share = (now - then).as_nanos() as f32 / nodes.len().max(1) as f32;
        for &node in nodes {
            self.cell(node).time += share;
        }
        self.clock = Some((now, None));
    }

    fn position(&mut self, i: u32, j: u32) {
        self.current = (i, j);
    }

    fn position_end(&mut self, _value: Vec3) {
        let p = self.pending.remove(&self.current).unwrap_or_default();
        let mut cell = p.cell;
        cell.id = p.winner();
        self.cells.push(cell);
    }

    fn ray(&mut self, t: &Traced) {
        debug_assert_eq!(t.node as usize, self.nodes.len());
        self.nodes.push(RayOf {
            position: t.position,
            depth: t.depth,
            org: t.ray.org,
        });
        self.tick(Some(t.node));
        let c = self.cell(t.node);
        c.depth = c.depth.max(t.depth);
        c.rays += 1.0;
    }

    fn miss(&mut self, node: u32, _radiance: Vec3) {
        self.tick(Some(node));
    }

    fn hit(&mut self, node: u32, at: &Met) {
        self.tick(Some(node));
        let ray = self.nodes[node as usize];
        if ray.depth != 1 {
            return;
        }
        let p = at.surf.point.p;
        let id = self.ids.id(at.hit);
        let pending = self.pending.entry(ray.position).or_default();
        let c = &mut pending.cell;
        c.hits += 1;
        c.z += (p - ray.org).length();
        c.p += p;
        match pending.votes.iter_mut().find(|(v, _)| *v == id) {
            Some((_, n)) => *n += 1,
            None => pending.votes.push((id, 1)),
        }
    }

    fn shading(&mut self, node: u32, m: &Material, ns: Vec3) {
        if self.nodes[node as usize].depth != 1 {
            return;
        }
        let c = self.cell(node);
        c.n += ns;
        c.albedo += m.color * m.kd;
    }

    fn area_light(&mut self, node: u32, _light: usize, rays: u32, _visible: u32, _value: Vec3) {
        self.cell(node).rays += rays as f32;
    }

    fn light(&mut self, node: u32, term: &LightTerm) {
        self.tick(Some(node));
        if term.shadow.is_some() {
            self.cell(node).rays += 1.0;
        }
    }

    fn local(&mut self, node: u32, _color: Vec3) {
        self.tick(Some(node));
    }
}
