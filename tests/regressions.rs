//! Inputs that once crashed emray or gave a NaN pixel (found by fuzzing or by hand),
//! kept in `tests/regressions/{nff,toml,obj}/`: each must load or be refused with a
//! `file:line:col` error, and when it loads, render a tiny image on every backend with
//! no panic, no abort and no NaN pixel. New crashing inputs from a fuzzing run go into
//! the same folders (and seed the fuzzers).

use emray::Scene;
use emray::accel::Backend;
use std::path::{Path, PathBuf};

mod common;
use common::backends;

fn inputs(format: &str) -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/regressions")
        .join(format);
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == format))
        .collect();
    files.sort();
    assert!(
        !files.is_empty(),
        "no .{format} inputs in {}",
        dir.display()
    );
    files
}

/// Render `scene` as the fuzz targets do (6×5, depth ≤ 6, one sample) on every backend.
fn renders_without_nan(path: &Path, scene: &Scene) {
    let mut settings = emray::render::RenderSettings::for_scene(scene);
    settings.width = 6;
    settings.height = 5;
    settings.max_depth = settings.max_depth.min(6);
    settings.spp = 1;
    settings.area_strata = settings.area_strata.min(2);
    for backend in backends() {
        let (film, _) =
            emray::job::render_scene("regression", scene, backend, &settings, 0.0, None)
                .unwrap_or_else(|e| panic!("{}: {} build: {e}", path.display(), backend.name()));
        for (i, p) in film.pixels.iter().enumerate() {
            assert!(
                !p.is_nan(),
                "{}: NaN at pixel {i} on {}: {p:?}",
                path.display(),
                backend.name()
            );
        }
    }
}

/// Load each input of `format` with `load`; the ones that load are rendered. Returns
/// the error messages of the ones refused, by file name.
fn check_all(
    format: &str,
    load: impl Fn(&Path) -> Result<Scene, emray::load::LoadError>,
) -> Vec<(String, String)> {
    let mut refused = Vec::new();
    for path in inputs(format) {
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        match load(&path) {
            Ok(scene) => renders_without_nan(&path, &scene),
            Err(e) => {
                let shown = e.to_string();
                assert!(
                    shown.starts_with(&path.display().to_string()),
                    "{name}: the error names the file: {shown}"
                );
                refused.push((name, shown));
            }
        }
    }
    refused
}

fn refusal<'a>(refused: &'a [(String, String)], name: &str) -> &'a str {
    refused
        .iter()
        .find(|(n, _)| n == name)
        .map(|(_, e)| e.as_str())
        .unwrap_or_else(|| panic!("{name} should be refused; refused: {refused:?}"))
}

#[test]
fn nff_regressions_load_or_fail_cleanly_and_render_without_nan() {
    let refused = check_all("nff", emray::load::nff::load);
    // The fuzzers' first find: a transmitting material with index of refraction 0.
    let e = refusal(&refused, "ior-zero-glass.nff");
    assert!(e.contains(":8:18: index of refraction 0"), "{e}");
    assert!(refusal(&refused, "ior-negative.nff").contains("index of refraction -1.5"));
    let e = refusal(&refused, "far-camera.nff");
    assert!(e.contains(":3:6: the viewpoint 'from'"), "{e}");
    assert!(e.contains("±1e9"), "{e}");
    assert!(refusal(&refused, "far-light.nff").contains("the light position"));
    let e = refusal(&refused, "huge-sphere.nff");
    assert!(e.contains(":9:3: the sphere centre"), "{e}");
    assert!(refusal(&refused, "negative-shine.nff").contains("Shine must not be negative"));
    // Loads, and renders with its overflowing radiance clamped instead of NaN.
    assert!(!refused.iter().any(|(n, _)| n == "overflowing-colour.nff"));
    assert!(!refused.iter().any(|(n, _)| n == "huge-up.nff"));
    // A byte-order mark before the first entity is skipped.
    assert!(!refused.iter().any(|(n, _)| n == "bom.nff"), "{refused:?}");
}

#[test]
fn toml_regressions_load_or_fail_cleanly_and_render_without_nan() {
    let refused = check_all("toml", emray::load::toml::load);
    let e = refusal(&refused, "ior-zero.toml");
    assert!(e.contains(":8:7: index of refraction 1e-30"), "{e}");
    let e = refusal(&refused, "far-scaled-instance.toml");
    assert!(e.contains(":18:8: this instance reaches from"), "{e}");
    assert!(!refused.iter().any(|(n, _)| n == "overflowing-light.toml"));
    assert!(!refused.iter().any(|(n, _)| n == "bom.toml"), "{refused:?}");
    let e = refusal(&refused, "empty-patches.toml");
    assert!(e.contains(":10:11: `patches` is empty"), "{e}");
    let e = refusal(&refused, "spindle-csg.toml");
    assert!(e.contains(":12:12: a spindle torus"), "{e}");
}

#[test]
fn obj_regressions_load_or_fail_cleanly_and_render_without_nan() {
    let refused = check_all("obj", emray::load::obj::load);
    let e = refusal(&refused, "far-vertex.obj");
    assert!(e.contains(":3:5: vertex y 2e30 lies outside"), "{e}");
    let e = refusal(&refused, "weighted-far-vertex.obj");
    assert!(e.contains(":3:9: vertex y / w = 1e30 lies outside"), "{e}");
    // An unusable `Ni` on a transparent MTL material is 1, with a warning.
    assert!(!refused.iter().any(|(n, _)| n == "glass-ni-tiny.obj"));
    // A byte-order mark before the first vertex is skipped: the vertex is kept, so the
    // face is the triangle at the origin.
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/regressions/obj");
    let data = emray::load::obj::load_geometry(&dir.join("bom.obj")).unwrap();
    assert!(data.bounds.max.max_element() <= 1.0, "{:?}", data.bounds);
}

/// The overflowing scenes really overflow: their renders report saturated rays (and
/// still no NaN, checked above).
#[test]
fn overflowing_radiance_is_saturated_and_counted() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/regressions");
    for (path, scene) in [
        (
            dir.join("nff/overflowing-colour.nff"),
            emray::load::nff::load(&dir.join("nff/overflowing-colour.nff")).unwrap(),
        ),
        (
            dir.join("toml/overflowing-light.toml"),
            emray::load::toml::load(&dir.join("toml/overflowing-light.toml")).unwrap(),
        ),
    ] {
        let mut settings = emray::render::RenderSettings::for_scene(&scene);
        (settings.width, settings.height) = (8, 8);
        let (film, report) =
            emray::job::render_scene("overflow", &scene, Backend::Bvh, &settings, 0.0, None)
                .unwrap();
        assert!(report.rays["saturated"] > 0, "{}", path.display());
        assert!(film.pixels.iter().all(|p| !p.is_nan()));
    }
}
