//! `emray explain` traces a pixel with the renderer's own code: on random pixels of
//! several scenes (NFF glass and mirrors, in SPD mode too; TOML textures and nested
//! dielectrics; an area light; the radiosity two-pass mode), on every backend, the
//! explained value is the film's value bit for bit, every ray's radiance is its local
//! light plus its children's weighted radiance, summed in the renderer's order, and the
//! hits' contributions add up to the pixel.

use emray::Scene;
use emray::accel::{self, Accel, BackendOptions, WithAccel};
use emray::job::{RenderOptions, load_scene};
use emray::math::Rng;
use emray::radiosity::RadiositySettings;
use emray::render::explain::{Explanation, RayNode, explain, text};
use emray::render::{Film, GlobalIllumination, RenderSettings, render_with_gi};
use std::collections::BTreeSet;
use std::path::Path;

mod common;
use common::backends;

/// Render the scene and explain `count` random pixels with the same backend.
struct Check<'a> {
    scene: &'a Scene,
    settings: &'a RenderSettings,
    radiosity: Option<&'a RadiositySettings>,
    count: u32,
    seed: u64,
}

impl WithAccel for Check<'_> {
    type Output = (Film, Vec<Explanation>);
    fn run<A: Accel>(self, accel: &A, _: f64) -> Self::Output {
        let solution = self
            .radiosity
            .map(|r| emray::radiosity::solve(self.scene, accel, r).unwrap());
        let gi = solution.as_ref().map(|s| s as &dyn GlobalIllumination);
        let (film, _) = render_with_gi(self.scene, accel, self.settings, gi, None);
        let mut rng = Rng::new(self.seed);
        let explained = (0..self.count)
            .map(|_| {
                let x = rng.below(self.settings.width);
                let y = rng.below(self.settings.height);
                explain(self.scene, accel, self.settings, gi, x, y).unwrap()
            })
            .collect();
        (film, explained)
    }
}

fn bits(v: [f32; 3]) -> [u32; 3] {
    v.map(f32::to_bits)
}

/// A ray's radiance from its parts, in the tracer's order: the local light, then each
/// child's weight times its radiance (the refraction before the reflection), saturated.
fn check_sums(node: &RayNode, place: &str) {
    let Some(hit) = &node.hit else {
        let bg = node.background.expect("a ray hits or misses");
        assert_eq!(
            bits(node.radiance),
            bits(bg),
            "{place}: a miss is its background"
        );
        return;
    };
    let mut sum = glam::Vec3::from(hit.local);
    for child in hit.children.iter().filter(|c| !c.discarded) {
        sum += glam::Vec3::from(child.local_weight) * glam::Vec3::from(child.radiance);
        check_sums(child, place);
    }
    let sum = if sum.is_finite() {
        sum
    } else {
        sum.map(|x| {
            if x.is_nan() {
                0.0
            } else {
                x.clamp(-f32::MAX, f32::MAX)
            }
        })
    };
    assert_eq!(
        bits(node.radiance),
        bits(sum.to_array()),
        "{place}: depth {} {:?} radiance {:?} is not local + children",
        node.depth,
        node.kind,
        node.radiance
    );
}

/// What the trees of a scene's explained pixels show: ray kinds, local-light terms,
/// lights' statuses, total internal reflections, surfaces passed through.
fn features(node: &RayNode, seen: &mut BTreeSet<String>) {
    seen.insert(format!("{:?}", node.kind));
    if !node.passed.is_empty() {
        seen.insert("passed".into());
    }
    let Some(hit) = &node.hit else {
        return;
    };
    for t in &hit.terms {
        seen.insert(format!("{:?}", t.term));
    }
    for l in &hit.lights {
        seen.insert(l.status.to_string());
    }
    if hit
        .boundary
        .as_ref()
        .is_some_and(|b| b.total_internal_reflection)
    {
        seen.insert("tir".into());
    }
    if hit.prim.source.is_some() {
        seen.insert("source".into());
    }
    for child in &hit.children {
        features(child, seen);
    }
}

/// Check `count` random pixels of `scene` rendered as `request` asks, on every backend;
/// returns what their trees show.
fn check(
    name: &str,
    scene: &Scene,
    request: RenderOptions,
    radiosity: Option<RadiositySettings>,
) -> BTreeSet<String> {
    let mut seen = BTreeSet::new();
    let settings = request.resolve(scene).unwrap().settings;
    for b in backends() {
        let work = Check {
            scene,
            settings: &settings,
            radiosity: radiosity.as_ref(),
            count: 40,
            seed: 7,
        };
        let (film, explained) = accel::build(scene, &BackendOptions::new(b), work).unwrap();
        let mut rays = 0;
        for e in &explained {
            let place = format!("{name} ({}) pixel ({}, {})", b.name(), e.x, e.y);
            assert_eq!(
                bits(e.value),
                bits(film.get(e.x, e.y).to_array()),
                "{place}: explained {:?}, rendered {}",
                e.value,
                film.get(e.x, e.y)
            );
            for p in &e.positions {
                for s in &p.samples {
                    check_sums(s, &place);
                    features(s, &mut seen);
                    rays += 1;
                }
            }
            let sum = text::contributions(e);
            for c in 0..3 {
                let tol = 1e-4 * e.value[c].abs().max(1e-3);
                assert!(
                    (sum[c] - e.value[c]).abs() <= tol,
                    "{place}: contributions {sum:?} vs {:?}",
                    e.value
                );
            }
            assert!(!text::format(e).is_empty());
        }
        assert!(
            rays >= explained.len(),
            "{name}: every position has its samples"
        );
    }
    seen
}

fn has(seen: &BTreeSet<String>, what: &[&str]) {
    for w in what {
        assert!(seen.contains(*w), "no {w} among {seen:?}");
    }
}

fn request(res: (u32, u32)) -> RenderOptions {
    RenderOptions {
        res: Some(emray::job::Res {
            width: res.0,
            height: res.1,
        }),
        ..RenderOptions::default()
    }
}

/// Glass gears on a mirror floor: refraction, total internal reflection, reflection.
#[test]
fn glass_and_mirrors_of_the_gears() {
    let scene = load_scene("spd:gears?size=1").unwrap();
    let seen = check("gears", &scene, request((40, 40)), None);
    has(
        &seen,
        &["Refraction", "Reflection", "shadowed", "lit", "source"],
    );
    let spd = RenderOptions {
        spd: Some(true),
        ..request((32, 32))
    };
    check("gears --spd", &scene, spd, None);
}

/// Smooth patches, cones, a glass sphere and a mirror, four samples per pixel.
#[test]
fn smooth_patches_cones_and_samples() {
    let src = "v from 0 -6 2 at 0 0 0.5 up 0 0 1 angle 40 hither 1 resolution 32 32\n\
               b 0.1 0.2 0.3\nl 3 -4 6\nl -4 -2 5 0.4 0.4 0.4\n\
               f 0.8 0.8 0.8 0.6 0.4 20 0 1\n\
               pp 4 -3 -3 0 0 0 1  3 -3 0 0 0 1  3 3 0 0.2 0 1  -3 3 0 0 0.2 1\n\
               f 0.9 0.9 1 0.1 0.1 50 0.85 1.5\ns 0 0 1 0.8\n\
               f 1 0.4 0.2 0.7 0.3 10 0 1\nc -1.5 1 0 0.5 -1.5 1 1.5 0.1\n\
               f 0 0 0 0 1 1 0 1\np 3 1.5 1 0 2.5 1 0 2 1 2\n";
    let scene = emray::load::nff::parse_str(src, Path::new("t.nff")).unwrap();
    let req = RenderOptions {
        spp: Some(4),
        ..request((32, 32))
    };
    let seen = check("patches", &scene, req, None);
    has(&seen, &["Refraction", "Reflection", "behind", "source"]);
}

/// A textured TOML scene (checker, marble) and the nested dielectrics of the ice cube.
#[test]
fn textures_and_nested_dielectrics() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("textured.toml");
    std::fs::write(
        &path,
        r#"
[camera]
from = [0.0, 3.2, 6.0]
at = [0.0, 0.5, 0.0]
up = [0.0, 1.0, 0.0]
fov = 40
resolution = [32, 24]

[render]
background = [0.25, 0.3, 0.38]
max_depth = 6

[materials.marble]
diffuse = 0.8
specular = 0.6
shininess = 80
texture = { type = "marble", a = [0.92, 0.9, 0.85], b = [0.25, 0.22, 0.3], scale = 2.5 }

[materials.floor]
diffuse = 0.8
reflectance = 0.3
texture = { type = "checker", a = [0.8, 0.8, 0.78], b = [0.3, 0.3, 0.3], scale = 1 }

[materials.glass]
diffuse = 0.05
specular = 0.5
shininess = 100
reflectance = 0.05
transmittance = 0.9
ior = 1.5

[[lights]]
position = [-4.0, 6.0, 5.0]
intensity = 0.8

[[objects]]
type = "sphere"
center = [-1.0, 0.6, 0.0]
radius = 0.6
material = "marble"

[[objects]]
type = "sphere"
center = [0.8, 0.6, 0.5]
radius = 0.6
material = "glass"

[[objects]]
type = "plane"
point = [0.0, 0.0, 0.0]
normal = [0.0, 1.0, 0.0]
material = "floor"
"#,
    )
    .unwrap();
    let scene = load_scene(&path).unwrap();
    let seen = check("textured", &scene, RenderOptions::default(), None);
    has(&seen, &["Refraction", "Reflection", "Ambient", "source"]);
    let ice = load_scene(common::repo().join("scenes/ice-cube.toml")).unwrap();
    let seen = check("ice cube", &ice, request((32, 24)), None);
    has(&seen, &["Refraction", "tir"]);
}

/// An area light's soft shadows, and the radiosity of the two-pass mode.
#[test]
fn area_light_and_radiosity() {
    let path = common::repo().join("scenes/cornell-box.toml");
    let scene = load_scene(&path).unwrap();
    let req = RenderOptions {
        area_samples: Some(4),
        ..request((24, 24))
    };
    let seen = check("cornell", &scene, req.clone(), None);
    has(&seen, &["Area"]);
    let rad = RadiositySettings {
        patch_size: Some(150.0),
        ..RadiositySettings::default()
    };
    let seen = check("cornell two-pass", &scene, req, Some(rad));
    has(&seen, &["Radiosity"]);
}

/// The command: text by default, JSON with `--json` (the same value), a pixel outside
/// the image is a usage error.
#[test]
fn the_command_prints_text_or_json_and_refuses_pixels_outside() {
    let dir = tempfile::tempdir().unwrap();
    let args = ["explain", "spd:gears?size=1", "20", "12", "--res", "32x32"];
    let text = common::emray(dir.path(), &args);
    assert!(text.status.success(), "{}", common::stderr(&text));
    let out = String::from_utf8(text.stdout).unwrap();
    assert!(out.contains("pixel (20, 12) of 32x32"), "{out}");
    assert!(out.contains("eye ray, depth 1"), "{out}");
    assert!(
        out.contains("(spd:gears?size=1:"),
        "primitives name their line: {out}"
    );
    let json = common::emray(dir.path(), &[&args[..], &["--json"]].concat());
    assert!(json.status.success(), "{}", common::stderr(&json));
    let v: serde_json::Value = serde_json::from_slice(&json.stdout).unwrap();
    assert_eq!(v["scene"], "spd:gears?size=1");
    assert_eq!((v["x"].as_u64(), v["y"].as_u64()), (Some(20), Some(12)));
    assert_eq!(v["positions"][0]["samples"][0]["kind"], "eye");
    let outside = common::emray(
        dir.path(),
        &["explain", "spd:gears?size=1", "32", "0", "--res", "32x32"],
    );
    assert_eq!(outside.status.code(), Some(2));
    assert!(
        common::stderr(&outside).contains("pixel (32, 0) is outside the 32x32 image"),
        "{}",
        common::stderr(&outside)
    );
}
