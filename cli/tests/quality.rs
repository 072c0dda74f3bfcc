//! Error metrics and the speed/accuracy knobs: `emray compare` and its exit status,
//! adaptive antialiasing, `--bailout`, skipping work that cannot change the image.
//! The tests that measure error need the `quality` feature (FLIP, the study's plots).

use emray::Scene;
use emray::accel::Backend;
#[cfg(feature = "quality")]
use emray::accuracy::metrics::compare;
use emray::job::{Report, render_scene};
use emray::load::nff::parse_str;
#[cfg(feature = "quality")]
use emray::render::Aa;
use emray::render::{Film, RenderSettings};
use std::path::Path;
use std::process::Command;

mod common;

fn scene(src: &str) -> Scene {
    parse_str(src, Path::new("<test>")).unwrap_or_else(|e| panic!("{e}"))
}

fn render(s: &Scene, settings: &RenderSettings) -> (Film, Report) {
    render_scene("test", s, Backend::Bvh, settings, 0.0, None).unwrap()
}

/// Two mirror spheres over a diffuse floor, one light behind the floor's horizon:
/// reflections several levels deep, lights behind surfaces, Ks = 0 surfaces.
const MIRRORS: &str = "v\nfrom 0 -6 2\nat 0 0 0.5\nup 0 0 1\nangle 35\nhither 0.1\n\
resolution 24 24\nb 0.1 0.2 0.3\nl 4 -3 6\nl -5 2 -1\n\
f 0.9 0.8 0.6 0.8 0 0 0 1\np 4 -8 -8 0 8 -8 0 8 8 0 -8 8 0\n\
f 0.7 0.8 0.9 0.3 0.6 30 0 1\ns -0.8 0 1 0.8\ns 0.8 0 1 0.8\n";

fn rays(r: &Report, k: &str) -> u64 {
    r.rays[k]
}

#[test]
#[cfg(feature = "quality")]
fn adaptive_aa_is_deterministic_shares_corners_and_beats_one_sample() {
    let s = scene(MIRRORS);
    let mut st = RenderSettings::for_scene(&s);
    st.spp = 64;
    let (reference, _) = render(&s, &st);
    st.spp = 1;
    let (one, _) = render(&s, &st);

    // With a threshold nothing exceeds, each pixel is the mean of its four corners
    // and only the (w+1)(h+1) shared corner rays are cast.
    st.aa = Aa::Adaptive {
        threshold: f32::MAX,
        depth: 3,
    };
    let (_, r) = render(&s, &st);
    assert_eq!(rays(&r, "eye"), 25 * 25);

    st.aa = Aa::Adaptive {
        threshold: 0.02,
        depth: 2,
    };
    let (a, ra) = render(&s, &st);
    st.tile_size = 5;
    let (b, rb) = render(&s, &st);
    assert_eq!(a, b, "independent of the tiling");
    assert_eq!(ra.rays, rb.rays);
    let eye = rays(&ra, "eye");
    // Some pixels subdivided, fewer rays than 25 per pixel everywhere.
    assert!(eye > 25 * 25 && eye < 24 * 24 * 16, "{eye}");
    let (ea, e1) = (compare(&a, &reference), compare(&one, &reference));
    assert!(ea.rmse < e1.rmse * 0.7, "adaptive {ea:?} vs 1 spp {e1:?}");
}

#[test]
#[cfg(feature = "quality")]
fn bailout_prunes_weak_rays_and_zero_keeps_the_full_tree() {
    let s = scene(MIRRORS);
    let mut st = RenderSettings::for_scene(&s);
    st.max_depth = 8;
    let (full, rf) = render(&s, &st);
    assert_eq!(rays(&rf, "bailed"), 0);
    // Mirror weight 0.6 per bounce: 0.6^2 = 0.36 < 0.4, so only first bounces survive.
    st.bailout = 0.4;
    let (cut, rc) = render(&s, &st);
    assert!(rays(&rc, "bailed") > 0);
    assert!(rays(&rc, "reflection") < rays(&rf, "reflection"));
    let m = compare(&cut, &full);
    assert!(m.rmse > 0.0 && m.max_abs < 0.5, "{m:?}");
    // A threshold no ray reaches changes nothing.
    st.bailout = 1e-9;
    let (same, _) = render(&s, &st);
    assert_eq!(same, full);
}

#[test]
fn skipping_changes_no_pixel_and_saves_rays() {
    let s = scene(MIRRORS);
    let mut st = RenderSettings::for_scene(&s);
    let (skip, rs) = render(&s, &st);
    st.skip = false;
    let (all, ra) = render(&s, &st);
    assert_eq!(skip, all);
    assert!(rays(&rs, "skipped_shadow") > 0 && rays(&rs, "skipped_reflection") > 0);
    assert_eq!(rays(&ra, "skipped_shadow"), 0);
    assert!(rays(&ra, "reflection") > rays(&rs, "reflection"));
    // Eye rays only: the skipped shadow rays are exactly the extra ones cast.
    st.max_depth = 1;
    let (_, ra) = render(&s, &st);
    st.skip = true;
    let (_, rs) = render(&s, &st);
    assert_eq!(
        rays(&ra, "shadow"),
        rays(&rs, "shadow") + rays(&rs, "skipped_shadow")
    );
}

/// Each backend holds, and so dispatches to, only the kinds the scene contains (with
/// their counts), and `--stats` says which.
#[test]
fn backends_hold_only_the_kinds_present() {
    use emray::accel::{Accel, bvh::Bvh};
    use emray::geometry::Kind;
    let head = "v\nfrom 0 -6 0\nat 0 0 0\nup 0 0 1\nangle 40\nhither 0\nresolution 8 8\n\
        l 2 -3 4\nf 0.8 0.8 0.8 0.9 0.2 10 0 1\n";
    let spheres = scene(&format!("{head}s 0 0 0 1\ns 1 0 0 0.5\ns -1 0 0 0.5\n"));
    let mixed = scene(&format!(
        "{head}s 0 0 0 1\nc\n0 0 -1 0.5\n0 0 1 0.2\np 3 0 0 0 1 0 0 0 1 0\n"
    ));
    let want_spheres = vec![(Kind::Sphere, 3)];
    let want_mixed = vec![(Kind::Triangle, 1), (Kind::Sphere, 1), (Kind::Cone, 1)];
    assert_eq!(Bvh::build(&spheres).stats().kinds, want_spheres);
    assert_eq!(Bvh::build(&mixed).stats().kinds, want_mixed);
    #[cfg(feature = "embree")]
    {
        use emray::accel::embree::EmbreeAccel;
        assert_eq!(
            EmbreeAccel::build(&spheres).unwrap().stats().kinds,
            want_spheres
        );
        assert_eq!(
            EmbreeAccel::build(&mixed).unwrap().stats().kinds,
            want_mixed
        );
    }
    let (_, report) = render(&spheres, &RenderSettings::for_scene(&spheres));
    assert_eq!(report.kinds, "spheres");
    assert!(
        report.summary().contains("kinds      spheres (only"),
        "{}",
        report.summary()
    );
}

fn emray() -> Command {
    Command::new(env!("CARGO_BIN_EXE_emray"))
}

/// `--stats` counts what a ray can meet, each instance's copy included, names
/// cylinders as cylinders, and its kinds line names the same kinds without counts of
/// its own to disagree with.
#[test]
fn stats_count_instances_and_name_cylinders() {
    let src = r#"
[camera]
from = [0, 0, 8]
at = [0, 0, 0]
resolution = [8, 8]

[define.post]
type = "group"
[[define.post.children]]
type = "cylinder"
base = [0, 0, 0]
axis = [0, 1, 0]
height = 1
radius = 0.2
[[define.post.children]]
type = "capped_cone"
base = [0, 1, 0]
axis = [0, 1, 0]
height = 1
base_radius = 0.2
top_radius = 0.1

[[objects]]
type = "instance"
of = "post"
transform = [{ translate = [-1, 0, 0] }]

[[objects]]
type = "instance"
of = "post"
transform = [{ translate = [1, 0, 0] }]

[[objects]]
type = "sphere"
center = [0, 0, 0]
radius = 0.5
"#;
    let s =
        emray::load::toml::parse_str(src, Path::new("<stats>")).unwrap_or_else(|e| panic!("{e}"));
    let (_, report) = render(&s, &RenderSettings::for_scene(&s));
    let count = |k: &str| report.prims.get(k).copied().unwrap_or(0);
    assert_eq!(count("cylinders"), 2, "{:?}", report.prims);
    assert_eq!(count("capped_cones"), 2, "{:?}", report.prims);
    assert_eq!(count("spheres"), 1, "{:?}", report.prims);
    assert_eq!(report.kinds, "spheres, capped_cones");
    let summary = report.summary();
    assert!(
        summary.contains("prims      2 capped_cones, 2 cylinders, 1 spheres"),
        "{summary}"
    );
}

#[test]
#[cfg(feature = "quality")]
fn compare_reports_metrics_and_exits_by_threshold() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (dir.path().join("a.exr"), dir.path().join("b.exr"));
    let mut fa = Film::new(8, 8);
    fa.pixels.fill(glam::Vec3::splat(0.5));
    let mut fb = fa.clone();
    fb.pixels.fill(glam::Vec3::splat(0.6));
    let enc = emray::output::Encoding::Srgb;
    emray::output::write_image(&a, &fa, enc).unwrap();
    emray::output::write_image(&b, &fb, enc).unwrap();
    let heat = dir.path().join("heat.png");
    let out = emray()
        .args(["compare", "--json", "--diff"])
        .arg(&heat)
        .arg(&b)
        .arg(&a)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0), "{out:?}");
    let m: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!((m["rmse"].as_f64().unwrap() - 0.1).abs() < 1e-6);
    assert!((m["psnr"].as_f64().unwrap() - 20.0).abs() < 1e-4);
    assert!(heat.exists());
    let status = |args: &[&str]| {
        emray()
            .arg("compare")
            .args(args)
            .arg(&b)
            .arg(&a)
            .output()
            .unwrap()
            .status
            .code()
    };
    assert_eq!(status(&["--max-rmse", "0.2"]), Some(0));
    assert_eq!(status(&["--max-rmse", "0.05"]), Some(1));
    assert_eq!(status(&["--max-flip", "0"]), Some(1));
    assert_eq!(status(&["--max-rmse", "-1"]), Some(2));
    // A missing file or a size mismatch is an I/O or usage error, named.
    let small = dir.path().join("small.exr");
    emray::output::write_image(&small, &Film::new(4, 4), enc).unwrap();
    let out = emray().arg("compare").arg(&small).arg(&a).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("small.exr"));
    let out = emray()
        .arg("compare")
        .arg(dir.path().join("none.png"))
        .arg(&a)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("none.png"));
}

#[test]
#[cfg(not(feature = "quality"))]
fn without_the_quality_feature_compare_and_study_say_so() {
    for args in [
        &["compare", "a.png", "b.png"][..],
        &["study", "spd:balls?size=1", "--out", "never"][..],
    ] {
        let out = emray().args(args).output().unwrap();
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.starts_with("emray: error: ") && err.contains("`quality` feature"),
            "{err}"
        );
    }
}

/// A diffuse-and-specular sphere, a mirror, a glass sphere (refraction and total
/// internal reflection) on a triangle floor, one light: the f32 renderer on both
/// backends against the f64 reference, same depth, both supersampled.
#[cfg(feature = "quality")]
const ANALYTIC: &str = "v\nfrom 0 -5 1.6\nat 0 0 0.6\nup 0 0 1\nangle 40\nhither 0.1\n\
resolution 20 20\nb 0.2 0.3 0.5\nl 3 -4 5 0.8 0.8 0.8\nl -4 -1 3 0.5 0.5 0.5\n\
f 0.8 0.7 0.5 0.9 0 0 0 1\np 3 -4 -4 0 4 -4 0 0 4 0\n\
f 0.9 0.2 0.2 0.7 0.3 20 0 1\ns -1.1 0 0.6 0.6\n\
f 0.9 0.9 0.9 0.1 0.8 40 0 1\ns 1.1 0.4 0.7 0.7\n\
f 1 1 1 0.05 0.1 60 0.85 1.5\ns 0 -1.2 0.45 0.45\n";

#[test]
#[cfg(feature = "quality")]
fn f32_render_agrees_with_the_f64_reference() {
    let s = scene(ANALYTIC);
    assert_eq!(emray::render::reference::unsupported(&s), None);
    let (reference, rr) = emray::render::reference::render(&s, 20, 20, 8, 5);
    assert_eq!(rr.eye, 20 * 20 * 64);
    assert!(rr.refraction > 0 && rr.reflection > 0);
    let mut st = RenderSettings::for_scene(&s);
    st.spp = 64;
    let backends = common::backends();
    for b in backends {
        let (f32_film, _) = render_scene("t", &s, b, &st, 0.0, None).unwrap();
        let m = compare(&f32_film, &reference);
        // Different sample patterns: the bound is the sampling noise of 64 samples on
        // the edges, not arithmetic (measured 0.008 RMSE here).
        assert!(m.rmse < 0.02 && m.psnr > 34.0, "{b:?}: {m:?}");
        // Away from edges the two agree far more closely: the flat floor centre.
        let (p, q) = (f32_film.get(10, 18), reference.get(10, 18));
        assert!((p - q).abs().max_element() < 1e-3, "{p} vs {q}");
    }
}

#[test]
fn the_reference_refuses_what_it_does_not_model() {
    let prims = common::repo().join("scenes/primitives.toml");
    let out = emray()
        .args(["render", "--reference", "--res", "8x8", "-q", "-o"])
        .arg(std::env::temp_dir().join("emray-never-written.png"))
        .arg(&prims)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("reference renderer"), "{err}");
    let out = emray()
        .args(["render", "--reference", "--spd", "spd:balls?size=1"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
}

#[test]
#[cfg(feature = "quality")]
fn study_writes_a_row_per_setting_and_a_curve_per_knob() {
    let s = scene(ANALYTIC);
    let dir = tempfile::tempdir().unwrap();
    let rows = emray::accuracy::study::write(&s, "analytic", dir.path(), 8, 8, 2, &[Backend::Bvh])
        .unwrap();
    let csv = std::fs::read_to_string(dir.path().join("study.csv")).unwrap();
    assert_eq!(csv.lines().count(), rows.len() + 1);
    assert!(csv.starts_with("knob,setting,render_ms,rays,rmse,psnr"));
    // More samples, less error: 64 spp beats 1 spp against the reference.
    let spp = |k: &str| {
        rows.iter()
            .find(|r| r.knob == "spp" && r.setting == k)
            .unwrap()
    };
    assert!(spp("64").m.rmse < spp("1").m.rmse);
    let svg = std::fs::read_to_string(dir.path().join("study.svg")).unwrap();
    for knob in ["spp", "adaptive", "bailout", "depth", "backend", "f64"] {
        assert!(rows.iter().any(|r| r.knob == knob), "{knob}");
        assert!(svg.contains(&format!(">\n{knob}\n</text>")), "{knob}");
    }
    // One 2-pixel curve per knob (axes and ticks are 1 pixel wide).
    assert_eq!(svg.matches("stroke-width=\"2\"").count(), 6);
    // The PNG: the plot's size, with every curve's colour and dark (text) pixels.
    let png = image::open(dir.path().join("study.png")).unwrap().to_rgb8();
    assert_eq!(png.dimensions(), (800, 520));
    for (r, g, b) in emray::accuracy::study::COLOURS {
        assert!(png.pixels().any(|p| p.0 == [r, g, b]), "{r} {g} {b}");
    }
    let dark = png.pixels().filter(|p| p.0.iter().all(|&c| c < 80)).count();
    assert!(dark > 500, "{dark} dark pixels: no text?");
}
