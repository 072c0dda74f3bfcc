//! The scene of an SPD database ([`scene`]), built from the database's entities
//! ([`NffSink`]) without text: the scene the NFF loader reads from the database's
//! file, bit for bit.
//!
//! Every number takes the value it has once printed with `%g` and read back
//! (`spd::g_f64`, `spd::g_f32`): points in double precision, moved into the frame of the first
//! viewpoint's eye, the rest in single precision; the entities go into the loader's
//! own [`Part`] and are joined by its [`Merger`], with the lines the file would give
//! them. Whatever the loader would refuse or warn about differently (a point before
//! the first viewpoint, a number out of range, a degenerate entity) marks the build
//! as failed: the caller then writes the text and reads it.
//!
//! Spheres, cones and polygons wait in a batch (`super::spd_prims`), made in parallel
//! (polygons rounded and triangulated) when it is full and at the end, and added while
//! the next batch is made, each with the material in effect on its line; one before the first viewpoint fails the build at
//! once (the frame it would be made in, the eye's, is not known yet). Nothing else
//! changes how they are made: later viewpoints keep the first's frame, and lights go
//! to a list of their own. A fill with the numbers of one of the last few made (and
//! no warning) adds that material again without making it.

use super::spd_prims::{Prim, PrimBatch, scene_point};
use crate::load::nff::{MAX_PIXELS, MAX_RESOLUTION_SIDE, Merger, Note, Part, fill, up_is_usable};
use crate::load::{LoadError, LoadProgress};
use crate::math::{DVec3, Vec3};
use crate::scene::{Camera, Light, Material, Scene, range};
use crate::spd::{Database, NffSink, g_f32, g_f64};
use glam::DVec3 as D;
use std::path::Path;
use std::sync::Arc;

/// The scene of database `db` at size factor `size`: the scene the NFF loader reads from
/// [`Database::generate`]'s text (named `path`, the file name of its sources and
/// messages), built without the text when it can be (it nearly always can). `progress`
/// is told how many primitives are made, of the total it expects ([`Database::count`],
/// counted here unless the caller has set it).
///
/// # Errors
/// What the loader reports for the text, if anything.
pub(crate) fn scene(
    db: Database,
    size: u32,
    path: &Path,
    progress: &LoadProgress<'_>,
) -> Result<Scene, LoadError> {
    if progress.is_watched() && progress.total() == 0 {
        progress.expect(db.count(size).prims);
    }
    let mut builder = SceneBuilder::new(path, progress);
    db.emit(size, &mut builder);
    match builder.finish() {
        Some(scene) => scene,
        None => crate::load::nff::parse_str(&db.generate(size), path),
    }
}

/// The most fills [`SceneBuilder`] remembers.
const FILLS: usize = 8;

/// How many primitives are made between two advances of the load's progress.
const PROGRESS_CHUNK: u64 = 1 << 14;

/// Spheres and cones made at once: enough for every thread of a pool to make many,
/// few enough that the batch stays in the processor's caches.
const PRIM_BATCH: usize = 1 << 12;

/// Builds the scene of a database's entities (see the module documentation).
struct SceneBuilder<'p, 'w> {
    path: &'p Path,
    progress: &'p LoadProgress<'w>,
    /// Primitives made since `progress` was last advanced.
    made: u64,
    part: Part,
    /// The first viewpoint's eye, once it is known.
    origin: Option<DVec3>,
    /// The line the next entity starts on.
    line: u32,
    /// Whether an entity could not be made as the loader would make it.
    failed: bool,
    /// Spheres and cones not yet made.
    prims: PrimBatch,
    /// The last fills made without a warning, by their numbers as the database gave
    /// them: a database that writes the same few fills again and again (`lattice`,
    /// one before each primitive) does not make them again.
    fills: Vec<([u64; 8], Material)>,
    /// Where the next fill goes in `fills` once it is full.
    next_fill: usize,
    /// The fill of `fills` added last (a database that cycles through a few fills
    /// adds the one after it next).
    last_fill: usize,
}

impl<'p, 'w> SceneBuilder<'p, 'w> {
    /// No entities yet; `path` names the scene as the loader's file name does.
    fn new(path: &'p Path, progress: &'p LoadProgress<'w>) -> Self {
        Self::with_batch(path, progress, PRIM_BATCH)
    }

    /// [`SceneBuilder::new`], making spheres and cones `batch` at a time.
    fn with_batch(path: &'p Path, progress: &'p LoadProgress<'w>, batch: usize) -> Self {
        SceneBuilder {
            path,
            progress,
            made: 0,
            part: Part::new(Arc::from(path.display().to_string())),
            origin: None,
            line: 1,
            failed: false,
            prims: PrimBatch::new(batch),
            fills: Vec::new(),
            next_fill: 0,
            last_fill: 0,
        }
    }

    /// The scene, or `None` when the build failed (the text then decides).
    fn finish(mut self) -> Option<Result<Scene, LoadError>> {
        self.make_prims();
        let drained = self.prims.drain(&mut self.part);
        self.check(drained);
        if self.failed {
            return None;
        }
        let mut merger = Merger::new(self.path, self.origin.unwrap_or(DVec3::ZERO));
        merger.add(self.part);
        Some(merger.finish())
    }

    /// `n` more primitives are made (as [`Database::count`] counts them).
    fn made(&mut self, n: usize) {
        self.made += n as u64;
        if self.made >= PROGRESS_CHUNK {
            self.progress.advance(self.made);
            self.made = 0;
        }
    }

    /// The line of an entity of `lines` lines, the next one's after it.
    fn entity(&mut self, lines: usize) -> u32 {
        let line = self.line;
        self.line = self.line.saturating_add(lines as u32);
        line
    }

    /// Fail unless `ok`.
    fn check(&mut self, ok: bool) {
        self.failed |= !ok;
    }

    /// Queue a sphere or cone of one line, making the batch if it is full.
    fn queue(&mut self, prim: Prim) {
        self.made(1);
        let line = self.entity(1);
        if self.origin.is_none() {
            self.failed = true;
            return;
        }
        let material = self.part.material_index();
        if self.prims.push(prim, line, material) {
            self.make_prims();
        }
    }

    /// Make the queued spheres and cones.
    fn make_prims(&mut self) {
        let made = self.prims.flush(self.origin, &mut self.part);
        self.check(made);
    }

    /// A number read in single precision.
    fn num(&mut self, x: f64) -> f32 {
        let v = g_f32(x);
        self.check(v.is_finite());
        v
    }

    fn vec3(&mut self, v: D) -> Vec3 {
        Vec3::new(self.num(v.x), self.num(v.y), self.num(v.z))
    }

    /// A point, in the scene's frame.
    fn point(&mut self, p: D) -> Vec3 {
        let point = self.origin.and_then(|o| scene_point(o, p));
        self.check(point.is_some());
        point.unwrap_or(Vec3::ZERO)
    }

    /// The material of a remembered fill whose numbers' bits are `key`, looked for
    /// from the one after the last added on.
    fn remembered_fill(&mut self, key: &[u64; 8]) -> Option<Material> {
        let n = self.fills.len();
        let same = |k: &[u64; 8]| k.iter().zip(key).fold(0, |d, (a, b)| d | (a ^ b)) == 0;
        let k = (1..=n)
            .map(|i| (self.last_fill + i) % n)
            .find(|&k| same(&self.fills[k].0))?;
        self.last_fill = k;
        Some(self.fills[k].1)
    }

    /// The loader's warning for a colour written with channels above 1 (the colour is
    /// the entity's first number, at column 3).
    fn warn_above_one(&mut self, line: u32, what: &str, c: Vec3) {
        if c.max_element() > 1.0 {
            let warning = format!(
                "{}:{line}:3: the {what} colour {} {} {} has channels above 1; NFF colours run \
                 from 0 to 1 (a colour on a 0-255 scale is divided by 255)",
                self.path.display(),
                c.x,
                c.y,
                c.z
            );
            self.part.notes.push(Note::Warning(warning));
        }
    }
}

impl NffSink for SceneBuilder<'_, '_> {
    fn viewpoint(&mut self, from: D, at: D, up: D, angle: f64, hither: f64, res: (i32, i32)) {
        let line = self.entity(7) as usize;
        self.part.notes.push(Note::Viewpoint { line, col: 1 });
        if self.origin.is_none() {
            self.origin = Some(D::new(g_f64(from.x), g_f64(from.y), g_f64(from.z)));
        }
        let (from, at, up) = (self.point(from), self.point(at), self.vec3(up));
        let (angle, hither) = (self.num(angle), self.num(hither));
        let (w, h) = (i128::from(res.0), i128::from(res.1));
        let side = 1..=MAX_RESOLUTION_SIDE as i128;
        self.check(at != from && up_is_usable(at - from, up));
        self.check(angle > 0.0 && angle < 180.0 && hither >= 0.0);
        self.check(side.contains(&w) && side.contains(&h) && w * h <= MAX_PIXELS as i128);
        if self.failed {
            return;
        }
        self.part.notes.push(Note::Camera(Camera {
            from,
            at,
            up,
            angle_deg: angle,
            hither,
            width: w as u32,
            height: h as u32,
        }));
    }

    fn background(&mut self, rgb: D) {
        let line = self.entity(1);
        let c = self.vec3(rgb);
        self.warn_above_one(line, "background", c);
        self.part.background = Some(c);
    }

    fn light(&mut self, pos: D) {
        let line = self.entity(1);
        let pos = self.point(pos);
        self.part
            .add_light(Light::point(pos, Vec3::ZERO), false, line);
    }

    fn fill(&mut self, rgb: D, kd: f64, ks: f64, shine: f64, t: f64, ior: f64) {
        let line = self.entity(1);
        let key = [rgb.x, rgb.y, rgb.z, kd, ks, shine, t, ior].map(f64::to_bits);
        if let Some(material) = self.remembered_fill(&key) {
            self.part.add_material(material, line);
            return;
        }
        let color = self.vec3(rgb);
        self.warn_above_one(line, "fill", color);
        let [kd, ks, shine, t, ior] = [kd, ks, shine, t, ior].map(|x| self.num(x));
        self.check(shine >= 0.0 && range::check_ior(t, ior).is_ok());
        let material = fill(color, kd, ks, shine, t, ior);
        self.part.add_material(material, line);
        // A fill that warned warns again; one that failed the build ends it.
        if !self.failed && color.max_element() <= 1.0 {
            if self.fills.len() < FILLS {
                self.last_fill = self.fills.len();
                self.fills.push((key, material));
            } else {
                self.last_fill = self.next_fill;
                self.fills[self.next_fill] = (key, material);
                self.next_fill = (self.next_fill + 1) % FILLS;
            }
        }
    }

    fn sphere(&mut self, center: D, radius: f64) {
        self.queue(Prim::Sphere(center, radius));
    }

    /// Made a batch at a time, without queueing them one by one.
    fn spheres(&mut self, spheres: &[(D, f64)]) {
        for batch in spheres.chunks(self.prims.capacity()) {
            self.made(batch.len());
            let first_line = self.entity(batch.len());
            let made = self
                .prims
                .spheres(batch, first_line, self.origin, &mut self.part);
            self.check(made);
        }
    }

    fn cone(&mut self, base: D, base_radius: f64, apex: D, apex_radius: f64) {
        self.queue(Prim::Cone(base, base_radius, apex, apex_radius));
    }

    fn polygon(&mut self, verts: &[D]) {
        self.polygon_with(verts, None);
    }

    fn polypatch(&mut self, verts: &[D], normals: &[D]) {
        self.polygon_with(verts, Some(normals));
    }
}

impl SceneBuilder<'_, '_> {
    /// `p` (no normals) or `pp`: one line for the count, one per vertex; queued with
    /// the spheres and cones, and made with them.
    fn polygon_with(&mut self, verts: &[D], normals: Option<&[D]>) {
        self.made(verts.len().saturating_sub(2));
        let line = self.entity(1 + verts.len());
        self.check(!verts.is_empty() && normals.is_none_or(|n| n.len() >= verts.len()));
        self.check(self.origin.is_some());
        if self.failed {
            return;
        }
        let material = self.part.material_in_effect();
        if self.prims.push_polygon(verts, normals, line, material) {
            self.make_prims();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Kind;
    use crate::load::nff::parse_str;

    static SILENT: std::sync::LazyLock<LoadProgress<'static>> =
        std::sync::LazyLock::new(LoadProgress::silent);

    /// Build `db` at `size` without the text, making spheres and cones `batch` at a
    /// time, and check that it is the scene read from the text, down to every
    /// primitive's, material's and light's line.
    fn assert_builds_as_read(db: Database, size: u32, batch: usize) {
        let path = Path::new("spd:db");
        let what = format!("{} size {size} batch {batch}", db.name());
        let mut builder = SceneBuilder::with_batch(path, &SILENT, batch);
        db.emit(size, &mut builder);
        let built = builder.finish().expect("built directly").unwrap();
        let read = parse_str(&db.generate(size), path).unwrap();
        assert_eq!(built, read, "{what}");
        let origins = &built.geometry.sources;
        assert!(origins.same_origins(&read.geometry.sources), "{what}");
        let materials = &built.sources.materials;
        assert!(materials.same_origins(&read.sources.materials), "{what}");
        let lights = &built.sources.lights;
        assert!(lights.same_origins(&read.sources.lights), "{what}");
    }

    /// The scene built from each database's entities is the scene read from its text,
    /// down to every primitive's line, and it is built without the text.
    #[test]
    fn every_database_builds_the_scene_its_text_reads_as() {
        for db in Database::ALL {
            for size in [1, 2] {
                assert_builds_as_read(db, size, PRIM_BATCH);
                let read = parse_str(&db.generate(size), Path::new("spd:db")).unwrap();
                let generated = scene(db, size, Path::new("spd:db"), &LoadProgress::silent());
                assert_eq!(generated.unwrap(), read, "{} size {size}", db.name());
            }
        }
    }

    /// Spheres and cones made in batches of a few on several threads, so that batches
    /// end anywhere among the entities and split among threads: the same scenes.
    #[test]
    fn small_batches_on_several_threads_build_the_same_scenes() {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(4)
            .build()
            .unwrap();
        pool.install(|| {
            for db in Database::ALL {
                for batch in [1, 3, 64] {
                    assert_builds_as_read(db, 2, batch);
                }
            }
            assert_builds_as_read(Database::Balls, 3, 100);
            assert_builds_as_read(Database::Jacks, 3, 7);
        });
    }

    /// The databases of polygons, made in batches of a few to many (so that batches
    /// and pieces end anywhere among their polygons, flat and smooth mixed in one
    /// piece) on one and on several threads: the scenes their texts read as.
    #[test]
    fn queued_polygons_build_the_same_scenes_in_any_batch_on_any_pool() {
        let polygons = [
            Database::Tetra,
            Database::Gears,
            Database::Teapot,
            Database::Sombrero,
            Database::Mount,
        ];
        for threads in [1, 3] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| {
                for db in polygons {
                    for batch in [1, 2, 5, 100, 4096] {
                        assert_builds_as_read(db, 2, batch);
                    }
                }
                assert_builds_as_read(Database::Teapot, 3, 300);
            });
        }
    }

    /// The same entities to the scene builder, made `batch` at a time, and to the text:
    /// the built scene (or `None`, the build failed) and the scene the text reads as.
    fn built_and_read(
        batch: usize,
        entities: impl Fn(&mut dyn NffSink),
    ) -> (Option<Result<Scene, LoadError>>, Result<Scene, LoadError>) {
        let path = Path::new("x");
        let mut builder = SceneBuilder::with_batch(path, &SILENT, batch);
        entities(&mut builder);
        let mut text = crate::spd::NffWriter::new();
        entities(&mut text);
        (builder.finish(), parse_str(&text.finish(), path))
    }

    /// A polygon the loader refuses (a vertex or a normal not finite, out of range,
    /// a zero normal) fails the build, queued among others or not: the scene is then
    /// the text's, whose error is the loader's.
    #[test]
    fn a_refused_polygon_fails_the_build_with_the_texts_error() {
        let tri = [D::ZERO, D::X, D::Y];
        let nan = D::new(f64::NAN, 0.0, 0.0);
        let far = D::new(1e30, 0.0, 0.0);
        // A polygon's vertices, its normals if it is a patch, and the loader's error.
        type Refused<'a> = (&'a [D], Option<&'a [D]>, &'a str);
        let refused: [Refused; 5] = [
            (&[D::ZERO, nan, D::Y], None, "the polygon vertex x"),
            (
                &[D::ZERO, D::X, far],
                None,
                "the polygon vertex (1e30, 0, 0) lies outside",
            ),
            (&tri, Some(&[D::Z, D::Z, nan]), "the vertex normal x"),
            (&tri, Some(&[D::Z, D::ZERO, D::Z]), "vertex normal is zero"),
            (
                &tri,
                Some(&[D::Z, D::Z, D::new(0.0, 0.0, 1e300)]),
                "the vertex normal z",
            ),
        ];
        for (verts, normals, message) in refused {
            for batch in [1, 2, 4096] {
                let (built, read) = built_and_read(batch, |w| {
                    w.viewpoint(D::Z * 5.0, D::ZERO, D::Y, 45.0, 0.0, (8, 8));
                    w.polygon(&tri);
                    match normals {
                        Some(n) => w.polypatch(verts, n),
                        None => w.polygon(verts),
                    }
                    w.sphere(D::ZERO, 1.0);
                    w.polygon(&tri);
                });
                let what = format!("{verts:?} {normals:?} batch {batch}");
                assert!(built.is_none(), "{what}");
                let error = read.unwrap_err();
                assert!((12..=15).contains(&error.line), "{what}: {error}");
                assert!(error.to_string().contains(message), "{what}: {error}");
            }
        }
    }

    /// A degenerate polygon is dropped and counted as the loader drops it, with the
    /// first one's line; one before the first fill does not make the default material
    /// (nothing uses it), one after does not change the materials of the others.
    #[test]
    fn degenerate_polygons_are_dropped_as_the_text_drops_them() {
        let line = [D::ZERO, D::X, D::X * 2.0];
        let point = [D::ZERO, D::ZERO, D::ZERO];
        for batch in [1, 3, 4096] {
            let (built, read) = built_and_read(batch, |w| {
                w.viewpoint(D::Z * 5.0, D::ZERO, D::Y, 45.0, 0.0, (8, 8));
                w.polygon(&line);
                w.polypatch(&point, &[D::Z, D::Z, D::Z]);
                w.fill(D::X, 1.0, 0.0, 0.0, 0.0, 1.0);
                w.polygon(&[D::ZERO, D::X, D::X + D::Y, D::Y]);
                w.polygon(&line);
                w.polypatch(&[D::ZERO, D::X, D::Y], &[D::Z, D::X, D::Y]);
            });
            let (built, read) = (built.expect("built").unwrap(), read.unwrap());
            assert_eq!(built, read, "batch {batch}");
            assert_eq!(built.materials.len(), 1, "batch {batch}");
            assert_eq!(built.load_stats.polygons, 5);
            assert_eq!(built.load_stats.degenerate_dropped, 3);
            let lines = built.geometry.sources.get(Kind::Triangle, 2).unwrap().line;
            assert_eq!(lines, 26, "batch {batch}");
        }
        let (built, read) = built_and_read(2, |w| {
            w.viewpoint(D::Z * 5.0, D::ZERO, D::Y, 45.0, 0.0, (8, 8));
            w.polygon(&line);
            w.polygon(&[D::ZERO, D::X, D::Y]);
        });
        let (built, read) = (built.expect("built").unwrap(), read.unwrap());
        assert_eq!(built, read);
        assert_eq!(built.materials.len(), 1, "the default, for the triangle");
    }

    /// Fills written again and again, more kinds than are remembered, one with a
    /// colour above 1: the materials and warnings the text gives.
    #[test]
    fn repeated_fills_make_the_materials_of_their_text() {
        let emit = |w: &mut dyn NffSink| {
            w.viewpoint(D::Z * 5.0, D::ZERO, D::Y, 45.0, 0.0, (8, 8));
            for round in 0..3 {
                for k in 0..FILLS + 3 {
                    let color = D::new(0.1 * k as f64, 0.5, round as f64 * 0.0);
                    w.fill(color, 0.5, 0.5, 3.0, 0.0, 1.0);
                    w.sphere(D::X * k as f64, 0.5);
                }
                for _ in 0..2 {
                    w.fill(D::splat(2.0), 0.5, 0.5, 3.0, 0.0, 1.0);
                    w.cone(D::ZERO, 0.5, D::Y, 0.5);
                }
            }
        };
        let (built, read) = built_and_read(5, emit);
        let (built, read) = (built.expect("built").unwrap(), read.unwrap());
        assert_eq!(built, read);
        assert_eq!(built.materials.len(), 3 * (FILLS + 5));
        let materials = &built.sources.materials;
        assert!(materials.same_origins(&read.sources.materials));
        let mut builder = SceneBuilder::new(Path::new("x"), &SILENT);
        emit(&mut builder);
        let warnings = (builder.part.notes.iter())
            .filter(|n| matches!(n, Note::Warning(w) if w.contains("channels above 1")));
        assert_eq!(warnings.count(), 6);
    }

    /// A fill after queued spheres is their material's end: each sphere keeps the
    /// material in effect on its line.
    #[test]
    fn queued_spheres_keep_the_material_of_their_line() {
        let mut builder = SceneBuilder::new(Path::new("x"), &SILENT);
        builder.viewpoint(D::Z, D::ZERO, D::Y, 45.0, 0.0, (8, 8));
        builder.fill(D::X, 1.0, 0.0, 0.0, 0.0, 1.0);
        builder.sphere(D::ZERO, 1.0);
        builder.cone(D::ZERO, 0.5, D::X, 0.25);
        builder.fill(D::Y, 1.0, 0.0, 0.0, 0.0, 1.0);
        builder.spheres(&[(D::X, 1.0), (D::Y, 2.0)]);
        let scene = builder.finish().unwrap().unwrap();
        assert_eq!(scene.geometry.spheres().material, [0, 1, 1]);
        assert_eq!(scene.geometry.cones().material, [0]);
        let line = |kind, k| scene.geometry.sources.get(kind, k).unwrap().line;
        assert_eq!(
            [9, 12, 13].map(|l| l as u32),
            [0, 1, 2].map(|k| line(Kind::Sphere, k))
        );
        assert_eq!(line(Kind::Cone, 0), 10);
    }

    /// A sphere or cone the loader would refuse fails the build, queued or not.
    #[test]
    fn a_refused_sphere_or_cone_fails_the_build() {
        let start = || {
            let mut builder = SceneBuilder::with_batch(Path::new("x"), &SILENT, 2);
            builder.viewpoint(D::Z, D::ZERO, D::Y, 45.0, 0.0, (8, 8));
            builder
        };
        let mut builder = start();
        builder.sphere(D::ZERO, 0.0);
        assert!(builder.finish().is_none(), "zero radius");
        let mut builder = start();
        builder.cone(D::ZERO, 0.5, D::X, -0.5);
        builder.sphere(D::ZERO, 1.0);
        builder.sphere(D::X, 1.0);
        assert!(builder.finish().is_none(), "radii of opposite signs");
        let mut builder = start();
        builder.spheres(&[(D::ZERO, 1.0), (D::new(1e30, 0.0, 0.0), 1.0), (D::X, 1.0)]);
        assert!(builder.finish().is_none(), "out of range");
        let mut builder = start();
        builder.cone(D::ZERO, 0.5, D::X, 0.5);
        builder.spheres(&[(D::ZERO, 1.0), (D::X, 1.0), (D::Y, 1.0)]);
        let scene = builder.finish().unwrap().unwrap();
        assert_eq!(scene.geometry.count(Kind::Sphere), 3);
        assert_eq!(scene.geometry.count(Kind::Cone), 1);
    }

    /// A point before the first viewpoint is in a frame not yet known: the text decides.
    #[test]
    fn a_point_before_the_viewpoint_fails_the_build() {
        let mut builder = SceneBuilder::new(Path::new("x"), &SILENT);
        builder.sphere(D::ZERO, 1.0);
        builder.viewpoint(D::Z, D::ZERO, D::Y, 45.0, 0.0, (8, 8));
        assert!(builder.finish().is_none());
        let mut builder = SceneBuilder::new(Path::new("x"), &SILENT);
        builder.viewpoint(D::Z, D::ZERO, D::Y, 45.0, 0.0, (8, 8));
        builder.sphere(D::ZERO, 1.0);
        builder.polygon(&[D::ZERO, D::X, D::Y]);
        let scene = builder.finish().unwrap().unwrap();
        assert_eq!(scene.geometry.count(Kind::Triangle), 1);
        assert_eq!(
            scene.geometry.sources.get(Kind::Triangle, 0).unwrap().line,
            9
        );
    }
}
