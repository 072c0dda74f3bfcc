//! End-to-end renders checked against analytic answers, across thread counts and
//! (with the `embree` feature) across backends.

use emray::Scene;
use emray::accel::Backend;
use emray::job::{Report, render_scene};
use emray::load::nff::parse_str;
use emray::render::{Film, RenderSettings};
use std::path::Path;

mod common;
use common::backends;

fn scene(src: &str) -> Scene {
    parse_str(src, Path::new("<test>")).unwrap_or_else(|e| panic!("{e}"))
}

fn render(s: &Scene, backend: Backend, settings: &RenderSettings) -> (Film, Report) {
    render_scene("test", s, backend, settings, 0.0, None).unwrap()
}

const VIEW: &str = "v\nfrom 0 0 10\nat 0 0 0\nup 0 1 0\nangle 30\nhither 1\nresolution 400 400\n";

/// A sphere of radius r at distance D covers the pixel centres inside a circle of
/// radius tan(asin(r/D)) on the unit image plane: count them.
#[test]
fn sphere_silhouette_matches_the_projected_area() {
    let src = format!("{VIEW}b 0 0 0\nf 1 1 1 1 0 0 0 1\ns 0 0 0 2\n");
    let s = scene(&src);
    let settings = RenderSettings::for_scene(&s);
    let half = (15f64).to_radians().tan();
    let pixel = half / ((400.0 - 1.0) / 2.0);
    let radius_px = (2f64 / 10.0).asin().tan() / pixel;
    let exact = std::f64::consts::PI * radius_px * radius_px;
    for b in backends() {
        let (film, report) = render(&s, b, &settings);
        let hit = report.rays["eye_hit"] as f64;
        let lit = film.pixels.iter().filter(|p| p.max_element() > 0.0).count() as f64;
        assert_eq!(
            hit, lit,
            "{b:?}: every hit pixel is lit (ambient), every miss black"
        );
        let err = (hit - exact).abs() / exact;
        assert!(
            err < 0.005,
            "{b:?}: {hit} pixels vs exact {exact:.1} ({:.3}%)",
            err * 100.0
        );
    }
}

/// A perfect mirror (Kd = 0, Ks = 1) facing the camera shows a diffuse sphere behind
/// the camera with exactly the sphere's own shade, and the background elsewhere.
#[test]
fn mirror_reflects_a_known_colour() {
    // No lights: ambient 0.5 (sqrt(1)/2), so the red sphere shades to 0.5 * (0.8, 0.1, 0.1).
    let src = format!(
        "{VIEW}b 0.2 0.3 0.4\n\
         f 0 0 0 0 1 1 0 1\np 4\n-100 -100 -1\n100 -100 -1\n100 100 -1\n-100 100 -1\n\
         f 0.8 0.1 0.1 1 0 0 0 1\ns 0 0 30 8\n"
    );
    let s = scene(&src);
    let mut settings = RenderSettings::for_scene(&s);
    settings.width = 64;
    settings.height = 64;
    for b in backends() {
        let (film, _) = render(&s, b, &settings);
        let centre = film.get(32, 32);
        let want = glam::Vec3::new(0.4, 0.05, 0.05);
        assert!(
            (centre - want).abs().max_element() < 1e-5,
            "{b:?}: centre {centre}"
        );
        // The sphere subtends asin(8/41) ≈ 11° from the mirror image of the eye (at
        // z = -12): the corners (15° off axis) show the background.
        let corner = film.get(0, 0);
        assert!(
            (corner - glam::Vec3::new(0.2, 0.3, 0.4))
                .abs()
                .max_element()
                < 1e-6,
            "{b:?}: {corner}"
        );
    }
}

/// Shadows: a light above a sphere over a floor; the floor right under the sphere is
/// in shadow (ambient only), the floor far off is lit (ambient + diffuse).
#[test]
fn shadow_rays_darken_what_is_occluded() {
    let src = "v\nfrom 0 -10 10\nat 0 0 0\nup 0 0 1\nangle 60\nhither 1\nresolution 64 64\n\
               l 0 0 20 1 1 1\n\
               f 1 1 1 1 0 0 0 1\np 4\n-50 -50 0\n50 -50 0\n50 50 0\n-50 50 0\n\
               s 0 0 3 1\n";
    let s = scene(src);
    // The floor point straight below the sphere: ambient only.
    let shaded = |b: Backend, from: &str| {
        let src2 = src.replace("from 0 -10 10\nat 0 0 0", from);
        let s2 = scene(&src2);
        let mut st = RenderSettings::for_scene(&s2);
        st.width = 1;
        st.height = 1;
        render(&s2, b, &st).0.get(0, 0)
    };
    let _ = s;
    for b in backends() {
        // Looking straight down from below the sphere is impossible; look at the floor
        // point (0, 0.1, 0) from the side, under the sphere.
        let under = shaded(b, "from 0 -10 0.5\nat 0 0.1 0");
        let open = shaded(b, "from 20 -10 0.5\nat 20 0.1 0");
        // Ambient 1/(2·1)·... with one coloured light the ambient is sqrt(1)/2 = 0.5.
        assert!(
            (under.x - 0.5).abs() < 1e-3,
            "{b:?}: shadowed floor {under}"
        );
        assert!(open.x > 0.55, "{b:?}: lit floor {open}");
    }
}

/// Glass: a ray through a glass sphere's centre goes straight through (normal
/// incidence), and SPD-style counting sees refraction rays; a ray inside a glass slab
/// beyond the critical angle is totally reflected.
#[test]
fn refraction_and_total_internal_reflection_are_counted() {
    let src = format!("{VIEW}b 0 0 1\nf 1 1 1 0 0 0 1 1.5\ns 0 0 0 2\n");
    let s = scene(&src);
    let mut st = RenderSettings::for_scene(&s);
    st.width = 1;
    st.height = 1;
    for b in backends() {
        let (film, report) = render(&s, b, &st);
        // Eye ray → refraction into the sphere → refraction out → background.
        assert_eq!(report.rays["refraction"], 2, "{b:?}");
        assert_eq!(report.rays["reflection"], 0, "{b:?}");
        // T = 1 twice, ambient term 0 (Kd = 0): the background comes through unchanged.
        assert!(
            (film.get(0, 0) - glam::Vec3::new(0.0, 0.0, 1.0)).length() < 1e-5,
            "{b:?}"
        );
    }
    // Camera inside a glass slab (two planes with outward normals) looking at its top
    // face 70° off the normal: leaving glass (n = 1.5) beyond the critical angle of
    // 41.8°, the ray is totally reflected.
    let src = "v\nfrom 0 0 0\nat 0.9397 0 0.342\nup 0 0 1\nangle 1\nhither 1\nresolution 1 1\n\
               b 1 1 1\nf 1 1 1 0 0 0 1 1.5\np 4\n-10 -10 -1\n-10 10 -1\n10 10 -1\n10 -10 -1\n\
               p 4\n-10 -10 1\n10 -10 1\n10 10 1\n-10 10 1\n";
    let s = scene(src);
    let st = RenderSettings::for_scene(&s);
    for b in backends() {
        let (_, report) = render(&s, b, &st);
        assert!(report.rays["tir"] >= 1, "{b:?}: {:?}", report.rays);
    }
}

/// The same image whatever the number of threads.
#[test]
fn output_is_deterministic_across_thread_counts() {
    let src = format!(
        "{VIEW}b 0.1 0.1 0.1\nl 5 5 5\nl -5 5 5\n\
         f 1 0.5 0.2 0.6 0.4 20 0.3 1.3\ns 0 0 0 2\ns 2 2 -2 1\n\
         f 0.2 0.9 0.2 0.7 0.3 10 0 1\nc -2 -2 -2 1 -2 2 -2 0.2\n"
    );
    let s = scene(&src);
    let mut st = RenderSettings::for_scene(&s);
    st.width = 96;
    st.height = 64;
    st.spp = 4;
    for b in backends() {
        let one = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        let two = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap();
        let (a, ra) = one.install(|| render(&s, b, &st));
        let (c, rc) = two.install(|| render(&s, b, &st));
        assert_eq!(a, c, "{b:?}: images differ between 1 and 2 threads");
        assert_eq!(ra.rays, rc.rays);
    }
}

/// SPD mode: (w+1)×(h+1) corner rays, each pixel the mean of its four corners.
#[test]
fn spd_mode_casts_corner_rays() {
    let src = format!("{VIEW}b 0 0 0\nl 0 0 10\nf 1 1 1 1 0 0 0 1\ns 0 0 0 2\n");
    let s = scene(&src);
    let mut st = RenderSettings::for_scene(&s);
    st.width = 32;
    st.height = 32;
    st.spd = true;
    let (film, report) = render(&s, Backend::Bvh, &st);
    assert_eq!((film.width, film.height), (32, 32));
    assert_eq!(report.rays["eye"], 33 * 33);
    let mut corner = st.clone();
    corner.spd = false;
    corner.width = 33;
    corner.height = 33;
    let (grid, _) = render(&s, Backend::Bvh, &corner);
    let want = (grid.get(10, 7) + grid.get(11, 7) + grid.get(10, 8) + grid.get(11, 8)) * 0.25;
    assert_eq!(film.get(10, 7), want);
}

/// The backends agree on a scene with every primitive kind, pixel by pixel.
#[cfg(feature = "embree")]
#[test]
fn backends_agree_on_every_primitive_kind() {
    let src = format!(
        "{VIEW}b 0.2 0.2 0.3\nl 5 5 5\nl -5 5 8 0.5 0.5 0.5\n\
         f 0.9 0.9 0.9 0.8 0.2 10 0 1\np 4\n-6 -3 -3\n6 -3 -3\n6 -3 6\n-6 -3 6\n\
         f 1 0.3 0.3 0.5 0.5 30 0 1\ns -1.5 0 0 1.2\n\
         f 1 1 1 0 0.1 40 0.85 1.5\ns 1.5 0.5 1 1\n\
         f 0.3 1 0.3 0.7 0.3 20 0 1\nc 2 -3 -2 0.8 2.5 1 -2 0.1\nc -3 -3 1 0.4 -3 2 1 0.4\n\
         f 0.3 0.3 1 0.9 0.1 5 0 1\npp 3\n-2 1.5 0 0 0 1\n0 2.5 0 0.3 0 1\n-1 3 1 0 0.5 1\n"
    );
    let s = scene(&src);
    let mut st = RenderSettings::for_scene(&s);
    st.width = 200;
    st.height = 200;
    let (a, ra) = render(&s, Backend::Embree, &st);
    let (b, rb) = render(&s, Backend::Bvh, &st);
    let differ = emray::output::differing_pixels(&a, &b);
    assert!(
        differ * 1000 <= a.pixels.len(),
        "{differ} of {} pixels differ",
        a.pixels.len()
    );
    assert_eq!(ra.rays["eye_hit"], rb.rays["eye_hit"]);
}

/// Area-light shadow rays are jittered from the ray-tree path, not from the hit point,
/// so a last-bit difference between the backends' hit points does not reshuffle the
/// noise: the showcase scenes with area lights render alike on both.
#[test]
fn area_light_noise_is_the_same_on_every_backend() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    for name in ["cornell-box.toml", "cornell-spheres.toml", "classroom.toml"] {
        let scene = emray::load::load_path(&root.join("scenes").join(name))
            .unwrap_or_else(|e| panic!("{e}"));
        let mut s = RenderSettings::for_scene(&scene);
        s.width = 64;
        s.height = 64;
        s.spp = 1;
        let films: Vec<_> = backends()
            .into_iter()
            .map(|b| render_scene(name, &scene, b, &s, 0.0, None).unwrap().0)
            .collect();
        for other in &films[1..] {
            let differ = emray::output::differing_pixels(&films[0], other);
            assert!(
                differ <= 4,
                "{name}: {differ} of 4096 pixels differ between backends"
            );
        }
    }
}

/// A progress bar starts at 0 of the render's tile count: the callback is told the
/// count before any tile is done, then once per tile, for uniform and adaptive
/// sampling.
#[test]
fn progress_hears_the_tile_count_before_the_first_tile() {
    use emray::render::Aa;
    use std::sync::Mutex;
    let s = scene(&format!("{VIEW}b 0 0 0\nf 1 1 1 1 0 0 0 1\ns 0 0 0 2\n"));
    let uniform = RenderSettings::for_scene(&s);
    let adaptive = RenderSettings {
        aa: Aa::Adaptive {
            threshold: 0.1,
            depth: 1,
        },
        ..uniform.clone()
    };
    for settings in [uniform, adaptive] {
        let calls = Mutex::new(Vec::new());
        let progress = |done: usize, total: usize| calls.lock().unwrap().push((done, total));
        render_scene("test", &s, Backend::Bvh, &settings, 0.0, Some(&progress)).unwrap();
        let calls = calls.into_inner().unwrap();
        let total = calls[0].1;
        assert!(total > 1, "{calls:?}");
        assert_eq!(calls[0], (0, total), "{:?}", settings.aa);
        assert_eq!(calls.len(), total + 1);
        assert!(calls.iter().all(|&(d, t)| t == total && d <= total));
    }
}

/// The embedding facade: a file rendered in memory with an output variable, as the
/// `render_file` example does; the image is the command line's (`render_scene` of the
/// same settings) and the depth layer holds the eye-to-surface distance where the
/// centre ray meets a sphere of `scenes/spheres.toml`.
#[test]
fn render_file_renders_in_memory_with_its_output_variables() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/spheres.toml");
    let options = emray::RenderOptions {
        res: Some("40x30".parse().unwrap()),
        aov: Some("depth,normal".parse().unwrap()),
        backend: Some(emray::Backend::Bvh),
        ..emray::RenderOptions::default()
    };
    let rendered = emray::render_file(&path, &options).unwrap();
    let (film, aov) = rendered.image().unwrap();
    let aov = aov.unwrap();
    assert_eq!((film.width, film.height), (40, 30));
    assert_eq!(aov.depth.len(), 40 * 30);
    let centre = aov.depth[15 * 40 + 20];
    assert!(centre.is_finite() && centre > 0.0, "{centre}");
    assert!(aov.depth.iter().any(|d| d.is_infinite()), "some rays miss");
    let scene = emray::load::load_path(&path).unwrap();
    let settings = options.resolve(&scene).unwrap().settings;
    let (plain, _) =
        emray::job::render_scene("spheres", &scene, emray::Backend::Bvh, &settings, 0.0, None)
            .unwrap();
    assert_eq!(plain.pixels, film.pixels);
    // The options' errors come back typed, before any work.
    let bad = emray::RenderOptions {
        spp: Some(0),
        ..emray::RenderOptions::default()
    };
    assert!(emray::render_file(&path, &bad).unwrap_err().is_usage());
}
