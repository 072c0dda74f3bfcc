//! The OBJ loader cuts large files into stretches parsed in parallel: whatever the
//! stretch size, the model (triangles and where each was defined, materials,
//! warnings, statistics) and the error (message, line and column) are those of
//! parsing the file as one stretch. Checked on well-formed and malformed models and
//! on a few thousand random mutations of them.

mod obj_models;

use emray::load::obj::{load_geometry, load_geometry_in_stretches};
use obj_models::{Rng, TRI, library_dir, models, mutate, shown};
use std::path::Path;

/// Stretch sizes from one line to a few statements.
const STRETCHES: [usize; 5] = [1, 2, 9, 31, 100];

/// Load `src` from `dir/model.obj` in one stretch and in stretches of every size, and
/// compare. Returns whether it loaded.
fn check(dir: &Path, src: &[u8], what: &str) -> bool {
    let path = dir.join("model.obj");
    std::fs::write(&path, src).unwrap();
    let whole = load_geometry(&path);
    for stretch in STRETCHES {
        let cut = load_geometry_in_stretches(&path, stretch);
        assert_eq!(
            shown(&whole),
            shown(&cut),
            "{what}, stretches of {stretch} bytes"
        );
        if let (Ok(a), Ok(b)) = (&whole, &cut) {
            assert!(
                a.geometry.sources.same_origins(&b.geometry.sources),
                "{what}, stretches of {stretch} bytes: triangle origins"
            );
        }
    }
    whole.is_ok()
}

#[test]
fn models_read_alike_in_stretches() {
    let dir = library_dir();
    let mut loaded = 0;
    for (k, src) in models().iter().enumerate() {
        loaded += usize::from(check(dir.path(), src.as_bytes(), &format!("model {k}")));
    }
    // Both kinds are covered.
    assert!((10..models().len() - 10).contains(&loaded), "{loaded}");
}

#[test]
fn a_byte_order_mark_is_no_part_of_the_first_line() {
    let dir = library_dir();
    let src = format!("\u{feff}{TRI}f 1 2 x\n");
    assert!(!check(dir.path(), src.as_bytes(), "BOM"));
    let e = load_geometry(&dir.path().join("model.obj")).unwrap_err();
    assert_eq!((e.line, e.col), (4, 7));
}

#[test]
fn mutated_models_read_alike_in_stretches() {
    let dir = library_dir();
    let models = models();
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let (mut loaded, mut cases) = (0, 0);
    for round in 0..3000 {
        let mut src = models[rng.below(models.len() - 1)].clone();
        for _ in 0..=rng.below(3) {
            src = mutate(&src, &mut rng);
        }
        let bytes = if rng.below(10) == 0 {
            [b"\xEF\xBB\xBF".as_slice(), src.as_bytes()].concat()
        } else {
            src.into_bytes()
        };
        let ok = check(
            dir.path(),
            &bytes,
            &format!("mutation {round}: {:?}", String::from_utf8_lossy(&bytes)),
        );
        loaded += usize::from(ok);
        cases += 1;
    }
    // Both kinds are common.
    assert!(
        loaded > cases / 5 && loaded < cases * 4 / 5,
        "{loaded} of {cases}"
    );
}
