//! Every database generates, parses with emray's NFF loader and renders on both
//! backends (at size 2 and 64×64, the backends differ on at most one pixel), with
//! counts per the SPD's formulas at small sizes.

use emray::render::RenderSettings;
use emray::spd::Database;
use std::path::Path;

mod common;

/// (database, size, triangles, spheres, cones) expected after loading: polygons are
/// triangulated, so a `p n` gives n − 2 triangles.
const COUNTS: [(Database, u32, usize, usize, usize); 11] = [
    // 1 + 9 spheres (size 1), the floor square as 2 triangles.
    (Database::Balls, 1, 2, 10, 0),
    // 1 gear: 2 faces of 144 vertices (142 triangles each) + 144 side quads (2 each),
    // plus the floor square.
    (Database::Gears, 1, 2 * 142 + 144 * 2 + 2, 0, 0),
    // 1 jack: 6 spheres, 3 cylinders.
    (Database::Jacks, 1, 0, 6, 3),
    // (n+1)^3 spheres and 3n(n+1)^2 cylinders.
    (Database::Lattice, 1, 0, 8, 12),
    // 2·4 triangles and the four glass spheres.
    (Database::Mount, 1, 8, 4, 0),
    // 5·n(n+1)(2n+1) spheres and as many cylinders, plus the wall square.
    (Database::Rings, 1, 2, 30, 30),
    // 180·2 + 1 spheres.
    (Database::Shells, 1, 0, 361, 0),
    // 2·31² triangles.
    (Database::Sombrero, 1, 1922, 0, 0),
    // 64·4 − 16 patch triangles (size 2) and 4 checker squares.
    (Database::Teapot, 2, 240 + 8, 0, 0),
    // 4^2 triangles.
    (Database::Tetra, 2, 16, 0, 0),
    // 2^(n+1) − 1 cones and spheres, plus the ground square.
    (Database::Tree, 2, 2, 7, 7),
];

#[test]
fn databases_parse_with_the_expected_counts() {
    for (db, size, tris, spheres, cones) in COUNTS {
        let text = db.generate(size);
        let s = emray::load::nff::parse_str(&text, Path::new(db.name()))
            .unwrap_or_else(|e| panic!("{}: {e}", db.name()));
        assert_eq!(
            (
                s.geometry.triangles.len(),
                s.geometry.spheres().len(),
                s.geometry.cones().len()
            ),
            (tris, spheres, cones),
            "{} size {size}",
            db.name()
        );
        assert!(!s.lights.is_empty(), "{} has lights", db.name());
    }
}

/// Counting a database without generating it (`Database::count`, what a job checks
/// against its memory limit first) gives the primitives and resolution its scene has:
/// the same count, or an upper bound where the loader drops degenerate triangles (the
/// teapot's, where a patch closes to a point: 58 counted, 54 loaded at size 1).
#[test]
fn counting_a_database_gives_its_scenes_primitives() {
    for db in Database::ALL {
        for size in [1, 2] {
            let count = db.count(size);
            let text = db.generate(size);
            let s = emray::load::nff::parse_str(&text, Path::new(db.name())).unwrap();
            let prims = s.prim_count_with_instances() as u64;
            assert!(
                count.prims >= prims && count.prims - prims <= prims / 10,
                "{} size {size}: counted {}, loaded {prims}",
                db.name(),
                count.prims
            );
            assert_eq!(
                (count.res.0 as u32, count.res.1 as u32),
                (s.camera.width, s.camera.height),
                "{} size {size}",
                db.name()
            );
        }
    }
    // Balls at size 8 without generating it: Σ 9^k spheres, k = 0..=8, and the floor.
    let balls = Database::Balls.count(8);
    assert_eq!(balls.prims, (9u64.pow(9) - 1) / 8 + 2);
}

#[test]
fn databases_render_on_every_backend() {
    let backends = common::backends();
    for db in Database::ALL {
        let text = db.generate(2);
        let scene = emray::load::nff::parse_str(&text, Path::new(db.name())).unwrap();
        let mut st = RenderSettings::for_scene(&scene);
        st.width = 64;
        st.height = 64;
        let mut films = Vec::new();
        for &b in &backends {
            let (film, report) =
                emray::job::render_scene(db.name(), &scene, b, &st, 0.0, None).unwrap();
            assert!(report.rays["eye_hit"] > 0, "{}: nothing visible", db.name());
            films.push(film);
        }
        if let [a, b] = &films[..] {
            let differ = emray::output::differing_pixels(a, b);
            assert!(
                differ <= 1,
                "{}: {differ} pixels differ between backends",
                db.name()
            );
        }
    }
}

#[test]
fn default_sizes_stay_under_ten_thousand_primitives() {
    for db in Database::ALL {
        let s =
            emray::load::nff::parse_str(&db.generate(db.default_size()), Path::new("x")).unwrap();
        let prims = s.geometry.spheres().len() + s.geometry.cones().len() + s.load_stats.polygons;
        assert!(prims < 10_000, "{}: {prims}", db.name());
    }
}
