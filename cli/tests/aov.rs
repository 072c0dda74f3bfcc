//! Output variables and heat maps end to end: `emray render --aov` files read back with
//! the `exr` crate's generic reader (not emray's) and checked against analytic cases
//! (the depth of a plane seen head-on, the normals of a sphere, the ids of known
//! primitives, the rays of a scene whose count is known, time on hits); parts merged
//! into the whole render's bytes; heat maps the same whatever the thread count.

use emray::render::RayGen;
use exr::prelude::{FlatSamples, read_all_data_from_file};
use glam::Vec3;
use std::collections::HashMap;
use std::path::Path;

mod common;
use common::{backend_names, emray, stderr};

/// A camera at z = 10 looking down −z at a plane z = 0 (a big square) and a sphere of
/// radius 1.5 at (2, 1, 0.5); one light at the eye (it lights whatever the eye sees);
/// all diffuse.
const SCENE: &str = "v\nfrom 0 0 10\nat 0 0 0\nup 0 1 0\nangle 40\nhither 1\nresolution 33 33\n\
                     b 0.1 0.1 0.1\nl 0 0 10\nf 0.8 0.6 0.4 1 0 0 0 1\n\
                     p 4\n-3 -3 0\n3 -3 0\n3 3 0\n-3 3 0\n\
                     f 0.2 0.4 0.9 0.5 0 0 0 1\ns 2 1 0.5 1.5\n";

/// Every channel of the first layer of an EXR, by name, as f64 (ids too).
fn channels(path: &Path) -> (usize, usize, HashMap<String, Vec<f64>>) {
    let image = read_all_data_from_file(path).unwrap_or_else(|e| panic!("{path:?}: {e}"));
    let layer = &image.layer_data[0];
    let mut out = HashMap::new();
    for c in &layer.channel_data.list {
        let samples = c.sample_data.get_level(exr::math::Vec2(0, 0)).unwrap();
        let v: Vec<f64> = match samples {
            FlatSamples::F16(v) => v.iter().map(|x| x.to_f64()).collect(),
            FlatSamples::F32(v) => v.iter().map(|&x| x as f64).collect(),
            FlatSamples::U32(v) => v.iter().map(|&x| x as f64).collect(),
        };
        out.insert(c.name.to_string(), v);
    }
    (layer.size.x(), layer.size.y(), out)
}

fn write_scene(dir: &Path) -> std::path::PathBuf {
    let path = dir.join("scene.nff");
    std::fs::write(&path, SCENE).unwrap();
    path
}

fn run(dir: &Path, args: &[&str]) {
    let o = emray(dir, args);
    assert!(o.status.success(), "{args:?}: {}", stderr(&o));
}

#[test]
fn depth_normals_ids_rays_and_time_match_the_scene() {
    let dir = tempfile::tempdir().unwrap();
    write_scene(dir.path());
    let scene = emray::load::nff::parse_str(SCENE, Path::new("scene.nff")).unwrap();
    let raygen = RayGen::new(&scene.camera, 33, 33);
    let (centre, r) = (Vec3::new(2.0, 1.0, 0.5), 1.5);
    for b in backend_names() {
        let out = format!("{b}.exr");
        run(
            dir.path(),
            &[
                "render",
                "scene.nff",
                "-o",
                &out,
                "--backend",
                b,
                "--aov",
                "all",
            ],
        );
        let (w, h, c) = channels(&dir.path().join(&out));
        assert_eq!((w, h), (33, 33));
        for name in [
            "R", "G", "B", "Z", "N.X", "N.Y", "N.Z", "albedo.R", "P.X", "P.Z", "id", "rays", "time",
        ] {
            assert!(c.contains_key(name), "{b}: no channel {name}");
        }
        let ids_file = dir.path().join(format!("{out}.ids.json"));
        let ids: serde_json::Value =
            serde_json::from_slice(&std::fs::read(&ids_file).unwrap()).unwrap();
        let kind_of: HashMap<u64, (String, String)> = ids["ids"]
            .as_array()
            .unwrap()
            .iter()
            .map(|e| {
                let source = e["source"].as_str().unwrap_or("").to_string();
                (
                    e["id"].as_u64().unwrap(),
                    (e["kind"].as_str().unwrap().to_string(), source),
                )
            })
            .collect();
        let (mut sphere, mut plane) = (0, 0);
        for j in 0..33 {
            for i in 0..33 {
                let k = j * 33 + i;
                let v = |n: &str| c[n][k];
                let p = Vec3::new(v("P.X") as f32, v("P.Y") as f32, v("P.Z") as f32);
                let n = Vec3::new(v("N.X") as f32, v("N.Y") as f32, v("N.Z") as f32);
                let dir = raygen.ray(i as f32 + 0.5, j as f32 + 0.5).dir;
                let id = v("id") as u64;
                assert!(v("time") >= 0.0);
                if id == 0 {
                    // A miss: the documented values, one ray.
                    assert_eq!(v("Z"), f64::INFINITY, "{b} ({i}, {j})");
                    assert_eq!((n, p), (Vec3::ZERO, Vec3::ZERO));
                    assert_eq!(v("rays"), 1.0);
                    continue;
                }
                assert!(v("time") > 0.0, "{b} ({i}, {j}): time on a hit");
                let (kind, source) = &kind_of[&id];
                // The distance along the eye ray, to the point the ray hit.
                let z = v("Z") as f32;
                assert!(((Vec3::new(0.0, 0.0, 10.0) + dir * z) - p).length() < 1e-4 * z);
                assert!(
                    n.dot(dir) < 0.0,
                    "{b} ({i}, {j}): the normal faces the viewer"
                );
                // Eye ray plus one shadow ray: the light is in front of every surface.
                assert_eq!(v("rays"), 2.0, "{b} ({i}, {j})");
                if kind == "sphere" {
                    sphere += 1;
                    assert_eq!(source, "scene.nff:17");
                    let expected = (p - centre) / r;
                    assert!(
                        (n - expected).length() < 1e-4,
                        "{b} ({i}, {j}): {n} vs {expected}"
                    );
                    assert!((v("albedo.B") - 0.45).abs() < 1e-6, "0.9 × Kd 0.5");
                } else {
                    plane += 1;
                    assert_eq!(
                        (kind.as_str(), source.as_str()),
                        ("triangle", "scene.nff:11")
                    );
                    // The plane z = 0 seen head-on: Z is 10 over the cosine of the ray's
                    // angle to the axis, 10 at the centre.
                    let expected = 10.0 / dir.dot(Vec3::NEG_Z);
                    assert!(
                        (z - expected).abs() < 1e-5 * expected,
                        "{b}: {z} vs {expected}"
                    );
                    assert!((n - Vec3::Z).length() < 1e-6);
                    assert!(p.z.abs() < 1e-5);
                }
            }
        }
        let centre_z = c["Z"][16 * 33 + 16];
        assert!(
            (centre_z - 10.0).abs() < 1e-5,
            "{b}: the centre pixel looks straight down"
        );
        assert!(sphere > 20 && plane > 20, "{sphere} {plane}");
        // The colour is the plain render's, bit for bit.
        let plain = format!("{b}-plain.exr");
        run(
            dir.path(),
            &["render", "scene.nff", "-o", &plain, "--backend", b],
        );
        let (_, _, p) = channels(&dir.path().join(&plain));
        for ch in ["R", "G", "B"] {
            assert_eq!(p[ch], c[ch], "{b}: {ch}");
        }
    }
}

/// SPD mode makes each pixel of its four corners: the rays of a pixel are the mean of
/// its corners'; with spp 4 a pixel's rays are its four samples' sum.
#[test]
fn spd_corners_and_samples_count_their_rays() {
    let dir = tempfile::tempdir().unwrap();
    write_scene(dir.path());
    run(
        dir.path(),
        &[
            "render",
            "scene.nff",
            "-o",
            "spd.exr",
            "--spd",
            "--res",
            "16x16",
            "--aov",
            "rays,depth",
        ],
    );
    let (_, _, c) = channels(&dir.path().join("spd.exr"));
    assert!(c["rays"].iter().all(|&r| (1.0..=2.0).contains(&r)));
    assert!(
        c["rays"]
            .iter()
            .any(|&r| r == 1.25 || r == 1.5 || r == 1.75),
        "edge pixels mix"
    );
    run(
        dir.path(),
        &[
            "render",
            "scene.nff",
            "-o",
            "spp.exr",
            "--spp",
            "4",
            "--aov",
            "rays",
        ],
    );
    let (_, _, c) = channels(&dir.path().join("spp.exr"));
    assert!(c["rays"].iter().all(|&r| (4.0..=8.0).contains(&r)));
    assert_eq!(c["rays"][16 * 33 + 16], 8.0);
}

/// Parts rendered with `--tile` and `--crop` carry their layers and ids; merged, they
/// are the whole render's bytes.
#[test]
fn parts_merge_into_the_whole_render_with_its_layers() {
    let dir = tempfile::tempdir().unwrap();
    write_scene(dir.path());
    let aov = ["--aov", "depth,normal,albedo,position,id,rays"];
    let render = |out: &str, extra: &[&str]| {
        let mut args = vec!["render", "scene.nff", "-o", out];
        args.extend(aov);
        args.extend(extra);
        run(dir.path(), &args);
    };
    render("whole.exr", &[]);
    render("p0.exr", &["--tile", "0/3"]);
    render("p1.exr", &["--tile", "1/3"]);
    render("p2.exr", &["--crop", "0,33,22,33"]);
    run(
        dir.path(),
        &["merge", "p0.exr", "p1.exr", "p2.exr", "-o", "merged.exr"],
    );
    let read = |f: &str| std::fs::read(dir.path().join(f)).unwrap();
    assert!(
        read("whole.exr") == read("merged.exr"),
        "merged bytes differ from the whole render"
    );
    assert_eq!(read("whole.exr.ids.json"), read("merged.exr.ids.json"));
    // A part with other layers is refused, naming both.
    run(
        dir.path(),
        &[
            "render",
            "scene.nff",
            "-o",
            "q2.exr",
            "--tile",
            "2/3",
            "--aov",
            "depth",
        ],
    );
    let o = emray(
        dir.path(),
        &["merge", "p0.exr", "p1.exr", "q2.exr", "-o", "bad.exr"],
    );
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("q2.exr: has the channels Z (float)"),
        "{}",
        stderr(&o)
    );
}

/// Rays and depth heat maps are the same bytes whatever the thread count; a PNG
/// output with --aov is a usage error.
#[test]
fn heat_maps_are_deterministic_and_aov_needs_an_exr() {
    let dir = tempfile::tempdir().unwrap();
    write_scene(dir.path());
    for t in ["1", "3"] {
        let (rays, depth) = (format!("rays{t}.png"), format!("depth{t}.png"));
        run(
            dir.path(),
            &[
                "render",
                "scene.nff",
                "-o",
                "x.png",
                "-t",
                t,
                "--heatmap",
                "rays",
                &rays,
                "--heatmap",
                "depth",
                &depth,
            ],
        );
    }
    let read = |f: &str| std::fs::read(dir.path().join(f)).unwrap();
    assert_eq!(read("rays1.png"), read("rays3.png"));
    assert_eq!(read("depth1.png"), read("depth3.png"));
    let colour = image::open(dir.path().join("x.png")).unwrap();
    assert_eq!(colour.width(), 33, "the image is the colour, as a PNG");
    let img = image::open(dir.path().join("rays1.png")).unwrap();
    assert!(
        img.width() >= 33 && img.height() > 33,
        "the colour bar is below the picture"
    );
    let o = emray(
        dir.path(),
        &["render", "scene.nff", "-o", "x.png", "--aov", "depth"],
    );
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("--aov writes its layers beside the colour in an OpenEXR file"));
    let o = emray(
        dir.path(),
        &[
            "render",
            "scene.nff",
            "-o",
            "x.exr",
            "--aov",
            "depth,colour",
        ],
    );
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("unknown output variable 'colour'"),
        "{}",
        stderr(&o)
    );
}
