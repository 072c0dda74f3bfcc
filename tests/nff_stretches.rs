//! The NFF loader cuts large files into stretches parsed in parallel: whatever the
//! stretch size, the scene (primitives in order, materials, camera, lights, and where
//! each was defined) and the first error are those of reading the file as one stretch.

use emray::load::LoadError;
use emray::load::nff::{parse_str, parse_str_in_stretches};
use emray::scene::Scene;
use emray::spd::Database;
use std::path::{Path, PathBuf};

/// Stretch sizes from one line to a few entities to the whole file.
const STRETCHES: [usize; 5] = [1, 2, 17, 100, usize::MAX];

const CAMERA: &str = "v\nfrom 0 0 5\nat 0 0 0\nup 0 1 0\nangle 40\nhither 1\nresolution 8 8\n";

fn assert_same_scene(a: &Scene, b: &Scene, what: &str) {
    assert_eq!(a, b, "{what}");
    assert!(
        a.geometry.sources.same_origins(&b.geometry.sources),
        "{what}: primitive origins"
    );
    assert!(
        a.sources.materials.same_origins(&b.sources.materials),
        "{what}: material origins"
    );
    assert!(
        a.sources.lights.same_origins(&b.sources.lights),
        "{what}: light origins"
    );
}

/// Parse `src` in stretches of every size and compare with one stretch.
fn check(src: &str, name: &str) -> Result<Scene, LoadError> {
    let path = Path::new(name);
    let whole = parse_str(src, path);
    for stretch in STRETCHES {
        let cut = parse_str_in_stretches(src, path, stretch);
        let what = format!("{name}, stretches of {stretch} bytes");
        match (&whole, &cut) {
            (Ok(a), Ok(b)) => assert_same_scene(a, b, &what),
            (a, b) => assert_eq!(a, b, "{what}"),
        }
    }
    whole
}

fn nff_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let p = entry.unwrap().path();
        if p.is_dir() {
            nff_files(&p, out);
        } else if p.extension().is_some_and(|e| e == "nff") {
            out.push(p);
        }
    }
}

#[test]
fn sample_files_read_alike_in_stretches() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = Vec::new();
    nff_files(&root.join("tests"), &mut files);
    nff_files(&root.join("scenes"), &mut files);
    assert!(files.len() >= 10, "{files:?}");
    for f in files {
        let text = String::from_utf8_lossy(&std::fs::read(&f).unwrap()).into_owned();
        let _ = check(&text, &f.display().to_string());
    }
}

#[test]
fn generated_databases_read_alike_in_stretches() {
    for db in Database::ALL {
        let scene = check(&db.generate(1), db.name()).expect("a database reads");
        assert!(scene.geometry.prim_count() > 0, "{}", db.name());
    }
}

#[test]
fn material_state_carries_across_stretches() {
    let src = format!(
        "s 0 0 0 1\n{CAMERA}s 0 0 1 1\nf 1 0 0 1 0 0 0 0\ns 0 0 2 1\nl 1 1 1\n\
         s 0 0 3 1\nf 0 1 0 1 0 0 0 0\nl 2 2 2 1 1 1\np 3\n0 0 0\n1 0 0\n0 1 0\n\
         pp 3\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\n# a comment\n  c 0 0 0 1 0 1 0 1\n\
         p 3\n0 0 0\n0 0 0\n0 0 0\nb 0.1 0.2 0.3\ns 0 0 4 1\n{CAMERA}"
    );
    let scene = check(&src, "state.nff").unwrap();
    // The default material for the first spheres, then the two fills.
    assert_eq!(scene.materials.len(), 3);
    assert_eq!(scene.geometry.spheres().material, [0, 0, 1, 1, 2]);
    assert_eq!(scene.geometry.triangles.material, [2, 2]);
    assert_eq!(scene.load_stats.degenerate_dropped, 1);
    assert_eq!(scene.lights.len(), 2);
}

#[test]
fn the_first_error_in_file_order_is_reported() {
    let cases = [
        format!("{CAMERA}s 0 0 0 1\ns 0 0 0 0\ns 0 0 0 x\n"),
        format!("{CAMERA}s 0 0 0 1\np 3\n0 0 0\n1 0 0\ns 1 1 1 1\n"),
        format!("{CAMERA}s 0 0 0 1\n1 2 3\nq 1\n"),
        format!("{CAMERA}s 0 0 0 1\r\ns 1 2\rs 1 2 3 4\r\nf 1 1 1 1 1 -1 0 0\n"),
        format!("{CAMERA}p 99999999\n0 0 0\n"),
        format!("{CAMERA}s 0 0 0 1\nv\nfrom 0 0 5\nat 0 0 5\nup 0 1 0\n"),
        "s 0 0 0 1\nl 1 1 1\n".to_string(),
        format!("{CAMERA}s 0 0 0 1\np 3\n0 0 0\n1 0 0\n"),
        "é s\n".to_string(),
    ];
    for (k, src) in cases.iter().enumerate() {
        let e = check(src, &format!("bad{k}.nff")).unwrap_err();
        assert!(e.to_string().starts_with(&format!("bad{k}.nff")), "{e}");
    }
}
