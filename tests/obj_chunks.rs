//! The OBJ loader converts the faces of a model to triangles in parallel, in chunks of
//! consecutive faces joined in face order: whatever the chunk size, the model (the
//! triangles in order, their materials, normals, texture coordinates, quads and
//! origins, the bounds), the statistics, the warnings and the error are those of
//! converting the faces in a row. Checked in pools of several threads, with chunks
//! from one face up, on random models of every kind of face (quads, concave and
//! twisted polygons that need ear clipping, degenerate faces, smoothing groups,
//! materials, texture coordinates, zero-length normals), a large grid, and the
//! hand-written models and random mutations the stretch tests use.

mod obj_models;

use emray::load::LoadError;
use emray::load::obj::{ObjData, load_geometry_in_chunks};
use obj_models::{Rng, grid, library_dir, models, mutate, shown};
use std::fmt::Write as _;
use std::path::Path;

/// Chunk sizes, from one face to a few dozen.
const CHUNKS: [usize; 5] = [1, 2, 3, 7, 40];

/// A pool of `threads` threads.
fn pool(threads: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
}

/// The load of `path` in one stretch with the faces in chunks of `faces`.
fn load(path: &Path, faces: usize) -> Result<ObjData, LoadError> {
    load_geometry_in_chunks(path, usize::MAX, faces)
}

/// Load `src` from `dir/model.obj` with the faces in a row and in chunks of every size
/// (and once with the text in stretches too), in a pool of `threads`, and compare.
/// Returns the load in a row.
fn check(dir: &Path, src: &[u8], threads: usize, what: &str) -> Result<ObjData, LoadError> {
    let path = dir.join("model.obj");
    std::fs::write(&path, src).unwrap();
    pool(threads).install(|| {
        let whole = load(&path, usize::MAX);
        let cuts = CHUNKS.map(|faces| (usize::MAX, faces));
        for (stretch, faces) in cuts.into_iter().chain([(9, 2)]) {
            let cut = load_geometry_in_chunks(&path, stretch, faces);
            let what = format!(
                "{what}, {threads} threads, stretches of {stretch} bytes, chunks of {faces} faces"
            );
            assert_eq!(shown(&whole), shown(&cut), "{what}");
            if let (Ok(a), Ok(b)) = (&whole, &cut) {
                let (a, b) = (&a.geometry.sources, &b.geometry.sources);
                assert!(a.same_origins(b), "{what}: triangle origins");
            }
        }
        whole
    })
}

/// Vertices a random model's faces pick from: a bumpy 8 × 8 grid (some points
/// repeated, so that faces can be degenerate), then a star of 10 points, an L of 6 and
/// a twisted quadrilateral of 4 (concave and non-planar faces for ear clipping).
fn vertices(rng: &mut Rng) -> String {
    let mut s = String::new();
    for k in 0..64 {
        let (i, j) = (k % 8, k / 8);
        let z = [0.0, 0.0, 0.25, -0.5][rng.below(4)];
        // Every ninth point is its predecessor again.
        let (i, j) = if k % 9 == 8 {
            ((k - 1) % 8, (k - 1) / 8)
        } else {
            (i, j)
        };
        writeln!(s, "v {i} {j} {z}").unwrap();
    }
    for k in 0..10 {
        let a = k as f32 * std::f32::consts::TAU / 10.0;
        let r = if k % 2 == 0 { 3.0 } else { 1.0 };
        writeln!(s, "v {} {} 1", 20.0 + r * a.cos(), r * a.sin()).unwrap();
    }
    for (x, y) in [(0, 0), (2, 0), (2, 1), (1, 1), (1, 3), (0, 3)] {
        writeln!(s, "v {} {} -2", x + 30, y).unwrap();
    }
    s.push_str("v 40 0 0\nv 41 0 0\nv 41 1 0.5\nv 40 1 0\n");
    for k in 0..12 {
        writeln!(s, "vt {} {}", k % 4, k / 4).unwrap();
    }
    // Normal 1 is zero-length.
    s.push_str("vn 0 0 0\nvn 0 0 1\nvn 0 1 0\nvn 0.6 0 0.8\n");
    s
}

/// The vertices of a random face (1-based position indices).
fn face_vertices(rng: &mut Rng) -> Vec<usize> {
    let corner = 1 + rng.below(7) + 8 * rng.below(7);
    match rng.below(9) {
        // Grid quads and triangles, either winding.
        0 | 1 => vec![corner, corner + 1, corner + 9, corner + 8],
        2 => vec![corner + 8, corner + 9, corner + 1, corner],
        3 => vec![corner, corner + 1, corner + 9],
        // The star, the L, the twisted quadrilateral.
        4 => (65..75).collect(),
        5 => (75..81).collect(),
        6 => (81..85).collect(),
        // A repeated or missing vertex: degenerate.
        7 => vec![corner, corner, corner + 1][..1 + rng.below(3)].to_vec(),
        // Any vertices: often self-intersecting.
        _ => (0..3 + rng.below(5)).map(|_| 1 + rng.below(84)).collect(),
    }
}

/// A face statement on `v`, each vertex with texture coordinates and a normal or not
/// (all alike, or mixed), with absolute or relative indices.
fn face(rng: &mut Rng, v: &[usize]) -> String {
    let style = rng.below(5);
    let relative = rng.below(4) == 0;
    let mut s = String::from("f");
    for (k, &i) in v.iter().enumerate() {
        let (vt, vn) = (1 + (i + k) % 12, 1 + rng.below(4));
        let (i, vt, vn) = if relative {
            (i as i64 - 85, vt as i64 - 13, vn as i64 - 5)
        } else {
            (i as i64, vt as i64, vn as i64)
        };
        let corner = match if style == 4 { rng.below(4) } else { style } {
            0 => format!(" {i}"),
            1 => format!(" {i}/{vt}"),
            2 => format!(" {i}//{vn}"),
            _ => format!(" {i}/{vt}/{vn}"),
        };
        s.push_str(&corner);
    }
    s
}

/// Statements between faces: materials (one the library lacks), smoothing groups,
/// groups, objects and lines.
const BETWEEN: [&str; 11] = [
    "usemtl a",
    "usemtl b",
    "usemtl c",
    "usemtl zz",
    "s 1",
    "s 2",
    "s off",
    "g part",
    "o thing",
    "l 1 2 3",
    "l 4 5",
];

/// A random model of `faces` faces.
fn random_model(rng: &mut Rng, faces: usize) -> String {
    let mut s = String::from("mtllib m.mtl\n");
    if rng.below(2) == 0 {
        s.push_str("s 1\n");
    }
    s.push_str(&vertices(rng));
    for _ in 0..faces {
        if rng.below(5) == 0 {
            s.push_str(BETWEEN[rng.below(BETWEEN.len())]);
            s.push('\n');
        }
        let v = face_vertices(rng);
        s.push_str(&face(rng, &v));
        s.push('\n');
    }
    s
}

/// What a set of loads showed, to check that the models cover every kind of face.
#[derive(Debug, Default)]
struct Seen {
    smooth: bool,
    textured: bool,
    quads: bool,
    ear_clipped: bool,
    degenerate: bool,
    zero_normal: bool,
    default_material: bool,
    lines: bool,
}

impl Seen {
    fn note(&mut self, d: &ObjData) {
        let g = &d.geometry;
        self.smooth |= !g.vertex_normals.is_empty();
        self.textured |= !g.vertex_uvs.is_empty();
        self.quads |= !g.quads.is_empty();
        // A star makes 8 triangles, a quadrilateral 2.
        self.ear_clipped |= g.triangles.len() > 2 * d.stats.polygons;
        self.degenerate |= d.stats.degenerate_dropped > 0;
        let warned = |what: &str| d.warnings.iter().any(|w| w.contains(what));
        self.zero_normal |= warned("zero-length vertex normal");
        // The library has three materials.
        self.default_material |= d.materials.len() > 3;
        self.lines |= warned("line element");
    }

    fn all(&self) -> bool {
        self.smooth
            && self.textured
            && self.quads
            && self.ear_clipped
            && self.degenerate
            && self.zero_normal
            && self.default_material
            && self.lines
    }
}

#[test]
fn random_models_convert_alike_in_chunks() {
    let dir = library_dir();
    let mut rng = Rng(0x2545_f491_4f6c_dd1d);
    let mut seen = Seen::default();
    for round in 0..40 {
        let faces = 20 + rng.below(200);
        let src = random_model(&mut rng, faces);
        let threads = 2 + round % 3;
        let loaded = check(
            dir.path(),
            src.as_bytes(),
            threads,
            &format!("model {round}"),
        );
        let d = loaded.unwrap_or_else(|e| panic!("model {round}: {e}\n{src}"));
        assert!(!d.geometry.triangles.is_empty(), "model {round}");
        seen.note(&d);
    }
    assert!(seen.all(), "{seen:?}");
}

#[test]
fn a_large_grid_converts_alike_in_many_batches_of_chunks() {
    let dir = library_dir();
    // 1600 textured quadrilaterals with normals: 229 chunks of 7 faces, in batches of
    // 12 chunks.
    let src = grid(40, false);
    let d = check(dir.path(), src.as_bytes(), 3, "grid").unwrap();
    let g = &d.geometry;
    assert_eq!(d.stats.polygons, 1600);
    // The grid is bumpy: some quadrilaterals lose a sliver.
    assert!(g.triangles.len() > 2800, "{}", g.triangles.len());
    assert_eq!(g.vertex_normals.len(), g.triangles.len());
    assert_eq!(g.vertex_uvs.len(), g.triangles.len());
    // Without normals, the grid is smooth by its smoothing group.
    let flat = src.replace("/-1 ", " ").replace("/-1\n", "\n");
    let d = check(dir.path(), flat.as_bytes(), 2, "grid in a smoothing group").unwrap();
    let g = &d.geometry;
    assert!(g.triangles.len() > 2800, "{}", g.triangles.len());
    assert_eq!(g.vertex_normals.len(), g.triangles.len());
}

#[test]
fn models_and_their_errors_convert_alike_in_chunks() {
    let dir = library_dir();
    let models = models();
    let mut loaded = 0;
    for (k, src) in models.iter().enumerate() {
        let ok = check(dir.path(), src.as_bytes(), 2, &format!("model {k}")).is_ok();
        loaded += usize::from(ok);
    }
    assert!((10..models.len() - 10).contains(&loaded), "{loaded}");
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let (mut loaded, mut cases) = (0, 0);
    for round in 0..600 {
        let mut src = models[rng.below(models.len() - 1)].clone();
        for _ in 0..=rng.below(3) {
            src = mutate(&src, &mut rng);
        }
        let what = format!("mutation {round}: {src:?}");
        loaded += usize::from(check(dir.path(), src.as_bytes(), 2, &what).is_ok());
        cases += 1;
    }
    assert!(
        loaded > cases / 5 && loaded < cases * 4 / 5,
        "{loaded} of {cases}"
    );
}
