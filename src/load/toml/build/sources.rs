//! Where each part of the scene was defined, for `emray explain` and the `id` output
//! variable: a primitive, instance, material or light made by an entry of the scene
//! file is recorded at the first line of that entry's table (`[[objects]]`, an inline
//! table in a group's `children`, `[materials.NAME]`, `[[lights]]`); a primitive of an
//! included file keeps its own file and line.

use super::Builder;
use super::objects::Sink;
use crate::geometry::Kind;
use crate::scene::{Geometry, GeometryMark, Origin};
use std::ops::Range;
use std::sync::Arc;

/// What a sink, the scene's objects and its instances held before a node was placed.
pub(super) struct Placed {
    mark: GeometryMark,
    objects: usize,
    instances: usize,
}

impl Builder<'_, '_> {
    /// The 1-based line of the start of `span` in the scene file.
    pub(super) fn line_of(&self, span: Range<usize>) -> u32 {
        u32::try_from(self.src.position(span.start).0).unwrap_or(u32::MAX)
    }

    /// What is placed now, to record what a node adds.
    pub(super) fn placed(&mut self, sink: &mut Sink) -> Placed {
        Placed {
            mark: Self::geometry(&mut self.geometry, sink).mark(),
            objects: self.objects.len(),
            instances: self.instances.len(),
        }
    }

    /// Record `file:line` as the origin of what was placed since `before`: the sink's
    /// new primitives, the new objects' and the new instances (what is recorded already,
    /// by a node inside this one, stays).
    pub(super) fn record(&mut self, sink: &mut Sink, before: &Placed, file: &Arc<str>, line: u32) {
        record_since(
            Self::geometry(&mut self.geometry, sink),
            &before.mark,
            file,
            line,
        );
        for object in &mut self.objects[before.objects..] {
            record_since(object, &GeometryMark::default(), file, line);
        }
        let new = self.instances.len() - before.instances;
        self.sources
            .instances
            .add(before.instances, new, file, line);
    }

    /// [`Builder::record`] at `span` of the scene file.
    pub(super) fn record_at(&mut self, sink: &mut Sink, before: &Placed, span: Range<usize>) {
        let (file, line) = (self.origin_file.clone(), self.line_of(span));
        self.record(sink, before, &file, line);
    }

    /// [`Builder::record`] at `origin`, if there is one.
    pub(super) fn record_origin(
        &mut self,
        sink: &mut Sink,
        before: &Placed,
        origin: Option<Origin>,
    ) {
        if let Some(o) = origin {
            self.record(sink, before, &o.file, o.line);
        }
    }
}

/// Record `file:line` for the primitives of `g` added since `mark`.
fn record_since(g: &mut Geometry, mark: &GeometryMark, file: &Arc<str>, line: u32) {
    for kind in Kind::ALL {
        let first = mark.count(kind);
        let now = g.count(kind);
        if now > first {
            g.sources.add(kind, first, now - first, file, line);
        }
    }
}
