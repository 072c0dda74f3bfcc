//! Loading tells its progress: the bytes of an NFF or OBJ file parsed, the primitives
//! of a generated database made, each report larger than the one before and the last
//! one all of it.

use emray::job::load_scene_with;
use emray::load::LoadProgress;
use emray::spd::Database;
use std::fmt::Write as _;
use std::path::Path;
use std::sync::Mutex;
use std::time::Duration;

/// The reports of loading `spec` with every advance told.
fn reports(spec: &str) -> Vec<(u64, u64)> {
    let seen = Mutex::new(Vec::new());
    let tell = |done, total| seen.lock().unwrap().push((done, total));
    let progress = LoadProgress::new(&tell).every(Duration::ZERO);
    load_scene_with(spec, &progress).unwrap();
    seen.into_inner().unwrap()
}

/// The reports grow, share one total, end at it, and are more than the end alone.
fn check(reports: &[(u64, u64)], total: u64, what: &str) {
    assert!(reports.len() >= 2, "{what}: {reports:?}");
    assert!(
        reports.iter().all(|&(_, t)| t == total),
        "{what}: {reports:?}"
    );
    assert!(
        reports.windows(2).all(|w| w[0].0 < w[1].0),
        "{what}: {reports:?}"
    );
    assert_eq!(reports.last(), Some(&(total, total)), "{what}");
}

#[test]
fn a_generated_database_counts_its_primitives() {
    let total = Database::Balls.count(5).prims;
    check(&reports("spd:balls?size=5"), total, "spd:balls?size=5");
}

#[test]
fn an_nff_file_counts_its_bytes_stretch_by_stretch() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("many.nff");
    // A little over 8 MB: three stretches of about 4 MB.
    let mut src =
        String::from("v\nfrom 0 0 5\nat 0 0 0\nup 0 1 0\nangle 40\nhither 1\nresolution 8 8\n");
    let mut k = 0u32;
    while src.len() < 9 << 20 {
        let x = f64::from(k % 1000) * 0.001;
        writeln!(src, "s {x} {x} -{x} 0.000228624").unwrap();
        k += 1;
    }
    std::fs::write(&path, &src).unwrap();
    let spec = path.to_str().unwrap();
    check(&reports(spec), src.len() as u64, "NFF");
}

#[test]
fn an_obj_file_counts_its_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("many.obj");
    // A little over 8 MB: three stretches of about 4 MB (on more than one thread),
    // each advancing the progress every megabyte.
    let mut src = String::new();
    let mut k = 0u32;
    while src.len() < 9 << 20 {
        let x = f64::from(k % 1000) * 0.001;
        writeln!(src, "v {x} 0 0\nv 0 {x} 1\nv 1 {x} 0\nf -3 -2 -1").unwrap();
        k += 1;
    }
    std::fs::write(&path, &src).unwrap();
    check(&reports(path.to_str().unwrap()), src.len() as u64, "OBJ");
}

/// A silent progress and a TOML scene tell nothing; a failed load does not claim to
/// be done.
#[test]
fn nothing_is_told_without_a_watcher_or_for_a_failed_load() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.nff");
    std::fs::write(&bad, "v\nfrom 0 0 5\nat 0 0 zero\n").unwrap();
    let seen = Mutex::new(Vec::new());
    let tell = |done, total| seen.lock().unwrap().push((done, total));
    let progress = LoadProgress::new(&tell).every(Duration::ZERO);
    assert!(load_scene_with(&bad, &progress).is_err());
    assert!(seen.lock().unwrap().iter().all(|&(d, t)| d < t));
    let silent = LoadProgress::silent();
    load_scene_with(Path::new("spd:balls?size=2"), &silent).unwrap();
}
