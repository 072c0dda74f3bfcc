//! Every SPD scene renders on both backends and the two images agree.
//!
//! Needs the SPD files, which are not part of the repository: run with
//! `EMRAY_SPD_DIR=path/to/spd cargo test --release --test spd -- --ignored`
//! (`.ci/spd-check` does this when `../shared/spd` exists).

use emray::accel::Backend;
use emray::render::RenderSettings;
use std::path::PathBuf;

fn spd_files() -> Vec<PathBuf> {
    let dir = std::env::var_os("EMRAY_SPD_DIR").expect("set EMRAY_SPD_DIR to the SPD folder");
    let mut v: Vec<PathBuf> = std::fs::read_dir(&dir)
        .expect("SPD folder readable")
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "nff"))
        .collect();
    v.sort();
    assert!(!v.is_empty(), "no .nff files in {dir:?}");
    v
}

#[test]
#[ignore = "needs the SPD scene files (EMRAY_SPD_DIR)"]
#[cfg(feature = "embree")]
fn spd_scenes_agree_across_backends() {
    for path in spd_files() {
        let scene = emray::load::load_path(&path).unwrap_or_else(|e| panic!("{e}"));
        let mut s = RenderSettings::for_scene(&scene);
        s.width = 256;
        s.height = 256;
        let name = path.display().to_string();
        let (a, ra) =
            emray::job::render_scene(&name, &scene, Backend::Embree, &s, 0.0, None).unwrap();
        let (b, rb) = emray::job::render_scene(&name, &scene, Backend::Bvh, &s, 0.0, None).unwrap();
        let differ = emray::output::differing_pixels(&a, &b);
        let share = 1.0 - differ as f64 / (a.pixels.len() as f64);
        println!(
            "{:<22} agree {:>8.4}%  embree {:>8.1} ms  bvh {:>8.1} ms  rays {}",
            path.file_name().unwrap().to_string_lossy(),
            share * 100.0,
            ra.time_ms.render,
            rb.time_ms.render,
            ra.rays["total"]
        );
        assert!(
            share >= 0.999,
            "{name}: backends agree on only {:.4}%",
            share * 100.0
        );
        let lit = a.pixels.iter().filter(|p| p.max_element() > 0.0).count();
        assert!(lit > a.pixels.len() / 10, "{name}: image is nearly black");
    }
}

#[test]
#[ignore = "needs the SPD scene files (EMRAY_SPD_DIR)"]
#[cfg(not(feature = "embree"))]
fn spd_scenes_render_on_the_bvh() {
    for path in spd_files() {
        let scene = emray::load::load_path(&path).unwrap_or_else(|e| panic!("{e}"));
        let mut s = RenderSettings::for_scene(&scene);
        s.width = 128;
        s.height = 128;
        let (f, _) = emray::job::render_scene("spd", &scene, Backend::Bvh, &s, 0.0, None).unwrap();
        assert!(f.pixels.iter().any(|p| p.max_element() > 0.0));
    }
}

/// `emray gen` output equals what the SPD programs wrote, file by file
/// (`NAME_default.nff` at the default size, `NAME_sN.nff` at size N). Set
/// `EMRAY_SPD_ONLY=balls,tetra` to check some databases only.
#[test]
#[ignore = "needs the SPD scene files (EMRAY_SPD_DIR)"]
fn generated_files_match_the_spd_programs() {
    use emray::spd::{Database, compare_nff};
    let only: Option<Vec<String>> = std::env::var("EMRAY_SPD_ONLY")
        .ok()
        .map(|s| s.split(',').map(str::to_string).collect());
    let mut failures = Vec::new();
    for path in spd_files() {
        let stem = path.file_stem().unwrap().to_string_lossy().into_owned();
        let (name, size) = stem.rsplit_once('_').expect("NAME_SIZE.nff");
        let db = Database::from_name(name).unwrap_or_else(|| panic!("unknown database {name}"));
        if only.as_ref().is_some_and(|o| !o.iter().any(|n| n == name)) {
            continue;
        }
        let size = match size {
            "default" => db.default_size(),
            s => s.trim_start_matches('s').parse().expect("size factor"),
        };
        let theirs = std::fs::read_to_string(&path).unwrap();
        let ours = db.generate(size);
        let c = compare_nff(&ours, &theirs);
        println!(
            "{stem:<18} size {size:>2}  {}  tokens {:>7}  near {:>5}  max rel {:.1e}{}",
            if c.identical {
                "identical"
            } else {
                "differs  "
            },
            c.tokens,
            c.near,
            c.max_rel,
            c.first_difference
                .as_deref()
                .map(|d| format!("  FIRST DIFF {d}"))
                .unwrap_or_default()
        );
        if c.first_difference.is_some() {
            failures.push(stem);
        }
    }
    assert!(failures.is_empty(), "differ: {failures:?}");
}
