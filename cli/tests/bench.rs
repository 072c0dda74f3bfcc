//! `emray bench`: a tiny suite end to end (child processes, markdown, CSV, JSON,
//! baseline), both modes of a run, and bad input.

use emray::bench::{self, Mode, RunSpec};

mod common;
use common::emray;

/// The backends the suite runs by default: both, or the BVH alone without Embree.
fn backends() -> usize {
    if cfg!(feature = "embree") { 2 } else { 1 }
}

#[test]
fn tiny_suite_writes_its_reports_and_compares_with_a_baseline() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let args = [
        "bench",
        "spd:tetra?size=1",
        "-t",
        "1",
        "--reps",
        "1",
        "--res",
        "16x16",
        "--no-peer",
        "--json",
        "base.json",
        "--csv",
        "base.csv",
    ];
    let o = emray(d, &args);
    let md = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(md.contains("| spd:tetra?size=1 | 4 | bvh | 1 |"), "{md}");
    assert!(md.contains("Tachyon not run"), "{md}");
    // 17 x 17 corner rays, all of them eye rays.
    assert!(md.contains("- spd:tetra?size=1: 289 / 0 / 0 /"), "{md}");
    let csv = std::fs::read_to_string(d.join("base.csv")).unwrap();
    let n_backends = backends();
    assert_eq!(csv.lines().count(), 1 + n_backends);
    let saved = bench::read_saved(&d.join("base.json")).unwrap();
    assert_eq!(saved.rows.len(), n_backends);
    // One render and one raw run per row.
    assert_eq!(saved.samples.len(), 2 * n_backends);
    for r in &saved.rows {
        assert_eq!(r.rays.eye, 289);
        assert!(r.render_ms > 0.0 && r.raw_ms.unwrap() > 0.0);
        assert!(r.peak_mib.unwrap() > 1.0);
    }

    let o = emray(
        d,
        &[
            "bench",
            "spd:tetra?size=1",
            "--backend",
            "bvh",
            "-t",
            "1",
            "--reps",
            "1",
            "--res",
            "16x16",
            "--no-peer",
            "--no-raw",
            "--baseline",
            "base.json",
        ],
    );
    let md = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(md.contains("## Against the baseline"), "{md}");
    assert!(md.contains("over 1 rows"), "{md}");
}

#[test]
fn bad_input_is_refused_clearly() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("bad.json"), "{\"rows\": 3}").unwrap();
    let o = emray(d, &["bench", "spd:tetra?size=1", "--baseline", "bad.json"]);
    assert_eq!(o.status.code(), Some(1));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("bad.json:1:"), "{err}");
    assert!(err.contains("not an `emray bench --json` file"), "{err}");
    let o = emray(d, &["bench", "spd:nosuch"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("unknown database"));
    let o = emray(d, &["bench", "missing.nff", "--no-peer"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("missing.nff: no such scene file"));
    assert!(!d.join("missing.json").exists());
}

#[test]
fn child_runs_report_the_same_rays_on_both_modes() {
    let spec = RunSpec {
        scene: "spd:jacks?size=1".into(),
        threads: 1,
        mode: Mode::Raw,
        eye_only: false,
        options: emray::job::RenderOptions {
            backend: Some(emray::Backend::Bvh),
            res: Some("10x10".parse().unwrap()),
            spd: Some(false),
            ..bench::Config::rules()
        },
    };
    let raw = bench::run_child(&spec).unwrap();
    let render = bench::run_child(&RunSpec {
        mode: Mode::Render,
        ..spec
    })
    .unwrap();
    assert_eq!(raw.rays, render.rays);
    assert_eq!(render.rays.eye, 100);
}
