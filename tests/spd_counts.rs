//! `--spd` casts and counts the rays the SPD's reference ray tracer does: the seven
//! original databases, generated in memory at their default sizes and rendered at
//! 512×512 from 513×513 corner rays, depth 5, give every count of the table published
//! in the SPD 3.14 README within 2%, on every backend.

use emray::accel::Backend;
use emray::job::{RenderOptions, load_scene, render_scene};
use std::collections::BTreeMap;

mod common;

/// The SPD 3.14 README's ray statistics: database, eye rays that hit, reflection,
/// refraction and shadow rays (513×513 = 263,169 eye rays each).
const PUBLISHED: [(&str, [u64; 4]); 7] = [
    ("balls", [263_169, 175_095, 0, 954_368]),
    ("gears", [245_086, 304_643, 207_564, 2_246_955]),
    ("mount", [173_125, 354_769, 354_769, 412_922]),
    ("rings", [263_169, 315_236, 0, 1_085_002]),
    ("teapot", [161_120, 225_248, 0, 407_656]),
    ("tetra", [49_788, 0, 0, 46_112]),
    ("tree", [169_836, 0, 0, 1_097_419]),
];

/// How far emray may be from a published count, as a fraction of it.
const TOLERANCE: f64 = 0.02;

fn spd_counts(db: &str, backend: Backend) -> BTreeMap<&'static str, u64> {
    let name = format!("spd:{db}");
    let scene = load_scene(&name).unwrap_or_else(|e| panic!("{name}: {e}"));
    let request = RenderOptions {
        spd: Some(true),
        ..RenderOptions::default()
    };
    let settings = request.resolve(&scene).expect("SPD settings").settings;
    let (_, report) = render_scene(&name, &scene, backend, &settings, 0.0, None)
        .unwrap_or_else(|e| panic!("{name}: {e}"));
    report.rays
}

#[test]
fn spd_counts_meet_the_published_statistics() {
    let mut failures = Vec::new();
    for (db, published) in PUBLISHED {
        for backend in common::backends() {
            let counts = spd_counts(db, backend);
            let db = format!("{db} ({})", backend.name());
            assert_eq!(counts["eye"], 513 * 513, "{db}: eye rays");
            let names = ["eye_hit", "reflection", "refraction", "shadow"];
            let got = names.map(|n| counts[n]);
            for ((name, want), got) in names.iter().zip(published).zip(got) {
                let off = got.abs_diff(want) as f64 / want.max(1) as f64;
                println!(
                    "{db:<7} {name:<11} published {want:>9} emray {got:>9} ({:+.2}%)",
                    100.0 * (got as f64 - want as f64) / want.max(1) as f64
                );
                if off > TOLERANCE {
                    failures.push(format!("{db} {name}: published {want}, emray {got}"));
                }
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
