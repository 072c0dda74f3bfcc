//! The TOML scene format: every key round-trips, every object type builds what it says,
//! transforms compose in the documented order, defines are shared, CSG classifies
//! points, NFF files are included, and every malformed file is reported at the right
//! line. Errors are checked against a `# HERE` marker on the line they must name.

mod common;
use emray::geometry::{Intersect, Kind, Primitive, Shape};
use emray::load::LoadError;
use emray::load::toml::{self as scene_toml, SceneSettings, format::SceneFile};
use emray::math::Vec3;
use emray::scene::{Geometry, INHERIT, Scene};
use std::path::{Path, PathBuf};

const CAMERA: &str = "[camera]\nfrom = [0, 0, 10]\nat = [0, 0, 0]\n";

/// Parse in the world's frame (origin 0), so that the scene holds the file's own
/// coordinates; `the_frame_is_the_eye` checks the default frame.
fn parse(src: &str) -> Result<Scene, LoadError> {
    scene_toml::parse_str_at(src, Path::new("test.toml"), glam::DVec3::ZERO)
}

/// A scene made of `CAMERA` followed by `body`.
/// The `i`-th analytic primitive of `g` (kinds in geometry-id order, then each list in
/// order).
fn shape_at(g: &Geometry, i: usize) -> Shape {
    g.shapes().nth(i).expect("no such shape").shape
}

fn build(body: &str) -> Scene {
    let src = format!("{CAMERA}{body}");
    match parse(&src) {
        Ok(s) => s,
        Err(e) => panic!("{e}\n--- in ---\n{src}"),
    }
}

/// The 1-based line of `src` holding the `# HERE` marker.
fn marked_line(src: &str) -> usize {
    let lines: Vec<usize> = src
        .lines()
        .enumerate()
        .filter(|(_, l)| l.contains("# HERE"))
        .map(|(i, _)| i + 1)
        .collect();
    assert_eq!(lines.len(), 1, "exactly one # HERE marker in:\n{src}");
    lines[0]
}

/// Parse `CAMERA + body`, expect an error on the marked line whose message contains
/// every one of `words`.
fn error_at(body: &str, words: &[&str]) -> LoadError {
    let src = format!("{CAMERA}{body}");
    let e = match parse(&src) {
        Ok(_) => panic!("expected an error in:\n{src}"),
        Err(e) => e,
    };
    assert_eq!(e.path, Path::new("test.toml"), "{e}");
    assert_eq!(e.line, marked_line(&src), "wrong line for: {e}\n{src}");
    assert!(e.col >= 1, "{e}");
    for w in words {
        assert!(e.message.contains(w), "`{w}` not in: {e}");
    }
    e
}

fn close(a: Vec3, b: Vec3) -> bool {
    (a - b).length() <= 1e-4 * (1.0 + b.length())
}

fn assert_close(a: Vec3, b: Vec3) {
    assert!(close(a, b), "{a} != {b}");
}

/// A file that uses every key of the format (object keys included, whatever type they
/// belong to).
const EVERY_KEY: &str = r#"
[camera]
from = [0, 2, 8]
at = [0, 0.5, 0]
up = [0, 1, 0]
fov = 40
hither = 0.01
resolution = [640, 480]

[render]
background = [0.1, 0.1, 0.15]
ambient = [0.1, 0.1, 0.1]
max_depth = 8
spp = 4

[materials.glass]
color = [1, 1, 1]
ambient = 0.0
diffuse = 0.1
specular = 0.6
shininess = 120
reflectance = 0.1
transmittance = 0.9
ior = 1.5
filter = [0.9, 1, 0.9]
priority = 1

[materials.red]
color = [0.8, 0.1, 0.1]

[[lights]]
type = "point"
position = [5, 8, 5]
color = [1, 1, 1]
intensity = 0.8
attenuation = [1, 0, 0.01]

[[lights]]
type = "spot"
position = [0, 10, 0]
direction = [0, -1, 0]
cutoff = 25
exponent = 10

[[lights]]
type = "spot"
position = [0, 10, 0]
target = [0, 0, 0]

[define.chair]
type = "group"
material = "red"
children = [
  { type = "sphere", center = [0, 1, 0], radius = 0.5 },
  { type = "instance", of = "leg" },
]

[define.leg]
type = "cone"
base = [0, 0, 0]
base_radius = 0.1
apex = [0, 1, 0]
apex_radius = 0.05

[[objects]]
type = "sphere"
center = [0, 1, 0]
radius = 1
material = "glass"
transform = [
  { translate = [1, 2, 3] },
  { rotate = [0, 1, 0], angle = 30 },
  { scale = 2 },
  { scale = [1, 2, 3] },
  { matrix = [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]] },
]

[[objects]]
type = "cylinder"
base = [0, 0, 0]
axis = [0, 1, 0]
height = 2
radius = 0.5

[[objects]]
type = "capped_cone"
base = [0, 0, 0]
axis = [0, 1, 0]
height = 2
base_radius = 0.5
top_radius = 0.25

[[objects]]
type = "box"
min = [0, 0, 0]
max = [1, 1, 1]

[[objects]]
type = "obox"
center = [0, 0, 0]
size = [1, 2, 3]
rotation = [{ rotate = [0, 0, 1], angle = 45 }]

[[objects]]
type = "obox"
center = [0, 0, 0]
half_size = [1, 2, 3]
axes = [[1, 0, 0], [0, 1, 0], [0, 0, 1]]

[[objects]]
type = "polyhedron"
planes = [[1, 0, 0, 1], [-1, 0, 0, 1], [0, 1, 0, 1], [0, -1, 0, 1], [0, 0, 1, 1], [0, 0, -1, 1]]

[[objects]]
type = "polyhedron"
preset = "icosahedron"
center = [0, 0, 0]
radius = 1

[[objects]]
type = "polyhedron"
sides = 6
radius = 1
height = 2
center = [0, 0, 0]

[[objects]]
type = "quadric"
coefficients = [1, 1, 1, 0, 0, 0, 0, 0, 0, -1]
clip = { min = [-1, -1, -1], max = [1, 1, 1] }

[[objects]]
type = "plane"
point = [0, 0, 0]
normal = [0, 1, 0]

[[objects]]
type = "torus"
center = [0, 0, 0]
axis = [0, 1, 0]
major_radius = 1
minor_radius = 0.25

[[objects]]
type = "triangle"
vertices = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]
normals = [[0, 0, 1], [0, 0, 1], [0, 0, 1]]

[[objects]]
type = "polygon"
vertices = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]

[[objects]]
type = "mesh"
vertices = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]
faces = [[0, 1, 2], [0, 2, 3]]
normals = [[0, 0, 1], [0, 0, 1], [0, 0, 1], [0, 0, 1]]

[[objects]]
type = "bezier"
builtin = "teapot"
tolerance = 0.01

[[objects]]
type = "bezier"
patches = [[
  [0, 0, 0], [1, 0, 0], [2, 0, 0], [3, 0, 0],
  [0, 1, 0], [1, 1, 1], [2, 1, 1], [3, 1, 0],
  [0, 2, 0], [1, 2, 1], [2, 2, 1], [3, 2, 0],
  [0, 3, 0], [1, 3, 0], [2, 3, 0], [3, 3, 0],
]]

[[objects]]
type = "include"
file = "parts/table.nff"
lights = true

[[objects]]
type = "instance"
of = "chair"
material = "glass"

[[objects]]
type = "difference"
children = [
  { type = "union", children = [
      { type = "sphere", center = [0, 0, 0], radius = 1 },
      { type = "sphere", center = [1, 0, 0], radius = 1, material = "red" },
  ] },
  { type = "intersection", children = [
      { type = "sphere", center = [0, 0, 0], radius = 0.5 },
      { type = "sphere", center = [0.2, 0, 0], radius = 0.5 },
  ] },
]
"#;

#[test]
fn every_key_round_trips() {
    let file = scene_toml::parse_file(EVERY_KEY, Path::new("every.toml")).unwrap();
    let text = file.to_toml_string().unwrap();
    let again = scene_toml::parse_file(&text, Path::new("again.toml"))
        .unwrap_or_else(|e| panic!("{e}\n{text}"));
    assert_eq!(file, again, "{text}");
    // And the written form is stable.
    assert_eq!(again.to_toml_string().unwrap(), text);

    // Every object key of the format appears in the file.
    let mut keys = std::collections::BTreeSet::new();
    fn collect(o: &scene_toml::format::ObjectDef, keys: &mut std::collections::BTreeSet<&str>) {
        for (k, _) in o.keys() {
            keys.insert(k);
        }
        if let Some(c) = &o.children {
            for c in c.get_ref() {
                collect(c.get_ref(), keys);
            }
        }
    }
    for o in &file.objects {
        collect(o.get_ref(), &mut keys);
    }
    for o in file.define.values() {
        collect(o.get_ref(), &mut keys);
    }
    for k in scene_toml::format::OBJECT_KEYS {
        assert!(
            *k == "type" || keys.contains(k),
            "`{k}` is not used by the test file"
        );
    }
    // Spot checks that values survived.
    let lights = &again.lights;
    assert_eq!(lights.len(), 3);
    assert_eq!(
        lights[1].get_ref().cutoff.as_ref().unwrap().get_ref().0,
        25.0
    );
    assert_eq!(
        again.materials["glass"]
            .get_ref()
            .priority
            .as_ref()
            .map(|p| *p.get_ref()),
        Some(1)
    );
}

#[test]
fn every_key_file_builds_and_its_rewrite_builds_the_same() {
    let dir = temp_dir();
    write(dir.path(), "parts/table.nff", TABLE_NFF);
    let a = write(dir.path(), "every.toml", EVERY_KEY);
    let file = scene_toml::parse_file(EVERY_KEY, &a).unwrap();
    let b = write(dir.path(), "again.toml", &file.to_toml_string().unwrap());
    let sa = scene_toml::load(&a).unwrap();
    let sb = scene_toml::load(&b).unwrap();
    assert_eq!(sa, sb);
    for kind in Kind::ALL {
        assert!(
            sa.count_with_instances(kind) > 0,
            "no {kind:?} in the every-key scene"
        );
    }
}

#[test]
fn sphere_and_materials() {
    let s = build(
        r#"
[materials.glass]
color = [0.9, 0.95, 1]
ambient = 0.05
diffuse = 0.1
specular = 0.6
shininess = 120
reflectance = 0.1
transmittance = 0.9
ior = 1.5
filter = [0.5, 0.75, 1]
priority = 2

[materials.plain]

[[objects]]
type = "sphere"
center = [1, 2, 3]
radius = 0.5
material = "glass"

[[objects]]
type = "sphere"
center = [0, 0, 0]
radius = 2
"#,
    );
    assert_eq!(s.count_with_instances(Kind::Sphere), 2);
    assert_eq!(s.prim_count_with_instances(), 2);
    let sp = &s.geometry.spheres().items[0];
    assert_eq!(
        (sp.center, sp.radius, sp.inside_only),
        (Vec3::new(1.0, 2.0, 3.0), 0.5, false)
    );
    let glass = s.materials[s.geometry.spheres().material[0] as usize];
    assert_eq!(glass.color, Vec3::new(0.9, 0.95, 1.0));
    assert_eq!(glass.filter, Vec3::new(0.5, 0.75, 1.0));
    assert_eq!(
        (
            glass.ka,
            glass.kd,
            glass.ks,
            glass.shine,
            glass.kr,
            glass.t,
            glass.ior,
            glass.priority
        ),
        (0.05, 0.1, 0.6, 120.0, 0.1, 0.9, 1.5, 2)
    );
    // An empty material takes every default; a primitive without one gets the default
    // material, which is the same.
    let plain = s.materials[1];
    let fallback = s.materials[s.geometry.spheres().material[1] as usize];
    assert_eq!(s.materials.len(), 3);
    for m in [plain, fallback] {
        assert_eq!((m.color, m.filter), (Vec3::ONE, Vec3::ONE));
        assert_eq!(
            (m.ka, m.kd, m.ks, m.shine, m.kr, m.t, m.ior, m.priority),
            (1.0, 1.0, 0.0, 32.0, 0.0, 0.0, 1.0, 0)
        );
    }
    // Ka defaults to Kd.
    let s = build(
        "[materials.m]\ndiffuse = 0.3\n[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"m\"\n",
    );
    assert_eq!(s.materials[0].ka, 0.3);
}

#[test]
fn camera_render_and_lights() {
    let src = r#"
[camera]
from = [0, 2, 8]
at = [0, 0.5, 0]
up = [0, 0, 1]
fov = 40
hither = 0.5
resolution = [320, 200]

[render]
background = [0.1, 0.2, 0.3]
ambient = [0.05, 0.05, 0.05]
max_depth = 8
spp = 16

[[lights]]
position = [5, 8, 5]
color = [1, 0.5, 0.25]
intensity = 0.5
attenuation = [1, 0, 0.01]

[[lights]]
type = "spot"
position = [0, 10, 0]
target = [0, 0, 0]
cutoff = 30
exponent = 4
"#;
    let (s, settings) = scene_toml::parse_str_with_settings(src, Path::new("c.toml")).unwrap();
    let c = s.camera;
    // The scene's frame has its origin at the eye: every point is relative to it.
    assert_eq!(s.origin, glam::DVec3::new(0.0, 2.0, 8.0));
    assert_eq!(
        (c.from, c.at, c.up),
        (Vec3::ZERO, Vec3::new(0.0, -1.5, -8.0), Vec3::Z)
    );
    assert_eq!(
        (c.angle_deg, c.hither, c.width, c.height),
        (40.0, 0.5, 320, 200)
    );
    assert_eq!(s.background, Vec3::new(0.1, 0.2, 0.3));
    assert_eq!(s.ambient, Vec3::splat(0.05));
    assert_eq!(
        settings,
        SceneSettings {
            max_depth: Some(8),
            spp: Some(16)
        }
    );
    assert_eq!(s.render, settings);

    assert_eq!(s.lights.len(), 2);
    let p = s.lights[0];
    assert_eq!(
        (p.pos, p.color, p.attenuation),
        (
            Vec3::new(5.0, 6.0, -3.0),
            Vec3::new(0.5, 0.25, 0.125),
            Vec3::new(1.0, 0.0, 0.01)
        )
    );
    assert!(p.spot.is_none());
    let spot = s.lights[1].spot.unwrap();
    assert_close(spot.dir, Vec3::NEG_Y);
    assert!((spot.cos_cutoff - 30f32.to_radians().cos()).abs() < 1e-6);
    assert_eq!(spot.exponent, 4.0);
    assert_eq!(s.lights[1].color, Vec3::ONE);

    // Defaults.
    let (s, settings) = scene_toml::parse_str_with_settings(CAMERA, Path::new("d.toml")).unwrap();
    assert_eq!(
        (s.camera.up, s.camera.angle_deg, s.camera.hither),
        (Vec3::Y, 45.0, 0.0)
    );
    assert_eq!((s.camera.width, s.camera.height), (640, 480));
    assert_eq!((s.background, s.ambient), (Vec3::ZERO, Vec3::splat(0.1)));
    assert_eq!(settings, SceneSettings::default());
    assert_eq!(s.prim_count_with_instances(), 0);
}

#[test]
fn matrix_camera() {
    // Camera to world: a quarter turn about y, then moved to (10, 1, 0): it looks down
    // the world's −x.
    let s = parse(
        "[camera]\nmatrix = [[0, 0, 1, 10], [0, 1, 0, 1], [-1, 0, 0, 0], [0, 0, 0, 1]]\nfov = 30\n",
    )
    .unwrap();
    assert_eq!(s.camera.from, Vec3::new(10.0, 1.0, 0.0));
    assert_close(s.camera.at - s.camera.from, Vec3::NEG_X);
    assert_close(s.camera.up, Vec3::Y);
    assert_eq!(s.camera.angle_deg, 30.0);
}

#[test]
fn cones() {
    let s = build(
        r#"
[[objects]]
type = "cone"
base = [0, 0, 0]
base_radius = 1
apex = [0, 2, 0]
apex_radius = 0.5

[[objects]]
type = "cone"
base = [0, 0, 0]
base_radius = 1
apex = [0, 0, 3]
"#,
    );
    assert_eq!(s.count_with_instances(Kind::Cone), 2);
    let c = &s.geometry.cones().items[0];
    assert_eq!(
        (c.base, c.base_radius, c.apex, c.apex_radius),
        (Vec3::ZERO, 1.0, Vec3::new(0.0, 2.0, 0.0), 0.5)
    );
    assert_eq!(s.geometry.cones().items[1].apex_radius, 0.0);
}

/// The only analytic shape of a scene, with its transform to world if it is an
/// instance's.
fn only_shape(s: &Scene) -> (Shape, Option<emray::math::Xform>) {
    let mut all: Vec<(Shape, Option<emray::math::Xform>)> =
        s.geometry.shapes().map(|e| (e.shape, None)).collect();
    for inst in &s.instances {
        for e in s.objects[inst.object as usize].shapes() {
            all.push((e.shape, Some(inst.xform)));
        }
    }
    assert_eq!(all.len(), 1, "{all:?}");
    all.pop().unwrap()
}

/// Whether the scene's only shape contains world point `p`.
fn contains(s: &Scene, p: Vec3) -> bool {
    let (shape, xf) = only_shape(s);
    match xf {
        Some(x) => shape.contains(x.to_object.transform_point3(p)),
        None => shape.contains(p),
    }
}

fn check_inside(s: &Scene, inside: &[[f32; 3]], outside: &[[f32; 3]]) {
    for p in inside {
        assert!(contains(s, Vec3::from(*p)), "{p:?} should be inside");
    }
    for p in outside {
        assert!(!contains(s, Vec3::from(*p)), "{p:?} should be outside");
    }
}

#[test]
fn closed_solids() {
    let s = build(
        "[[objects]]\ntype = \"cylinder\"\nbase = [1, 0, 0]\naxis = [0, 2, 0]\nheight = 3\nradius = 0.5\n",
    );
    assert_eq!(s.count_with_instances(Kind::CappedCone), 1);
    let Shape::CappedCone(c) = &shape_at(&s.geometry, 0) else {
        panic!()
    };
    assert_eq!(
        (
            c.base(),
            c.axis(),
            c.height(),
            c.base_radius(),
            c.top_radius()
        ),
        (Vec3::X, Vec3::Y, 3.0, 0.5, 0.5)
    );
    check_inside(
        &s,
        &[[1.0, 2.9, 0.0], [1.4, 0.1, 0.0]],
        &[[1.0, 3.1, 0.0], [1.6, 1.0, 0.0], [1.0, -0.1, 0.0]],
    );

    let s = build(
        "[[objects]]\ntype = \"capped_cone\"\nbase = [0, 0, 0]\naxis = [0, 0, 1]\nheight = 2\nbase_radius = 1\ntop_radius = 0\n",
    );
    let Shape::CappedCone(c) = &shape_at(&s.geometry, 0) else {
        panic!()
    };
    assert_eq!(
        (c.base_radius(), c.top_radius(), c.height()),
        (1.0, 0.0, 2.0)
    );
    check_inside(
        &s,
        &[[0.9, 0.0, 0.05], [0.0, 0.0, 1.9]],
        &[[0.6, 0.0, 1.0], [0.0, 0.0, 2.1]],
    );

    let s = build("[[objects]]\ntype = \"box\"\nmin = [-1, 0, 2]\nmax = [1, 1, 5]\n");
    assert_eq!(s.count_with_instances(Kind::Box), 1);
    let Shape::Box(b) = &shape_at(&s.geometry, 0) else {
        panic!()
    };
    assert_eq!(
        (b.min(), b.max()),
        (Vec3::new(-1.0, 0.0, 2.0), Vec3::new(1.0, 1.0, 5.0))
    );

    // An oriented box three ways: size + rotation steps, half_size + axes, and the
    // same with a default (identity) orientation.
    let s = build(
        "[[objects]]\ntype = \"obox\"\ncenter = [0, 0, 0]\nsize = [4, 2, 2]\nrotation = [{ rotate = [0, 0, 1], angle = 90 }]\n",
    );
    assert_eq!(s.count_with_instances(Kind::OBox), 1);
    let Shape::OBox(b) = &shape_at(&s.geometry, 0) else {
        panic!()
    };
    assert_close(b.half_extents(), Vec3::new(2.0, 1.0, 1.0));
    check_inside(
        &s,
        &[[0.0, 1.9, 0.0], [0.9, 0.0, 0.0]],
        &[[1.1, 0.0, 0.0], [0.0, 2.1, 0.0]],
    );
    let s = build(
        "[[objects]]\ntype = \"obox\"\ncenter = [0, 0, 0]\nhalf_size = [2, 1, 1]\naxes = [[0, 1, 0], [-1, 0, 0], [0, 0, 1]]\n",
    );
    check_inside(&s, &[[0.0, 1.9, 0.0]], &[[1.1, 0.0, 0.0]]);
    let s = build("[[objects]]\ntype = \"obox\"\ncenter = [5, 0, 0]\nhalf_size = [2, 1, 1]\n");
    check_inside(&s, &[[6.9, 0.0, 0.0]], &[[5.0, 1.1, 0.0]]);

    // Polyhedra: planes, a preset, a prism.
    let s = build(
        "[[objects]]\ntype = \"polyhedron\"\nplanes = [[1, 0, 0, 1], [-1, 0, 0, 1], [0, 1, 0, 2], [0, -1, 0, 2], [0, 0, 1, 1], [0, 0, -1, 1]]\n",
    );
    assert_eq!(s.count_with_instances(Kind::Polyhedron), 1);
    check_inside(&s, &[[0.9, 1.9, -0.9]], &[[1.1, 0.0, 0.0], [0.0, 2.1, 0.0]]);
    let s = build(
        "[[objects]]\ntype = \"polyhedron\"\npreset = \"octahedron\"\ncenter = [0, 1, 0]\nradius = 2\n",
    );
    let Shape::Polyhedron(p) = &shape_at(&s.geometry, 0) else {
        panic!()
    };
    assert_eq!(p.face_count(), 8);
    check_inside(
        &s,
        &[[1.9, 1.0, 0.0], [0.0, 2.9, 0.0]],
        &[[1.1, 2.0, 0.0], [0.0, -1.1, 0.0]],
    );
    let s = build("[[objects]]\ntype = \"polyhedron\"\nsides = 6\nradius = 1\nheight = 4\n");
    let Shape::Polyhedron(p) = &shape_at(&s.geometry, 0) else {
        panic!()
    };
    assert_eq!(p.face_count(), 8);
    check_inside(
        &s,
        &[[0.95, 0.0, 1.9]],
        &[[0.0, 0.95, 0.0], [0.0, 0.0, 2.1]],
    );
}

#[test]
fn quadrics_planes_and_tori() {
    // The unit sphere as a quadric, clipped to z ≥ 0.
    let s = build(
        "[[objects]]\ntype = \"quadric\"\ncoefficients = [1, 1, 1, 0, 0, 0, 0, 0, 0, -1]\nclip = { min = [-2, -2, 0], max = [2, 2, 2] }\n",
    );
    assert_eq!(s.count_with_instances(Kind::Quadric), 1);
    check_inside(
        &s,
        &[[0.0, 0.0, 0.9], [0.6, 0.6, 0.1]],
        &[[0.0, 0.0, -0.5], [0.8, 0.8, 0.1]],
    );
    // An unclipped cylinder x² + y² = 1 along z: unbounded, not a solid.
    let s =
        build("[[objects]]\ntype = \"quadric\"\ncoefficients = [1, 1, 0, 0, 0, 0, 0, 0, 0, -1]\n");
    assert!(!shape_at(&s.geometry, 0).is_solid());
    assert!(!shape_at(&s.geometry, 0).bounds().is_finite());

    let s = build("[[objects]]\ntype = \"plane\"\npoint = [0, -1, 0]\nnormal = [0, 2, 0]\n");
    assert_eq!(s.count_with_instances(Kind::Plane), 1);
    let Shape::Plane(p) = &shape_at(&s.geometry, 0) else {
        panic!()
    };
    assert_eq!((p.normal(), p.offset()), (Vec3::Y, -1.0));
    check_inside(&s, &[[100.0, -1.1, 7.0]], &[[0.0, -0.9, 0.0]]);

    let s = build(
        "[[objects]]\ntype = \"torus\"\ncenter = [0, 0, 0]\naxis = [0, 1, 0]\nmajor_radius = 2\nminor_radius = 0.5\n",
    );
    assert_eq!(s.count_with_instances(Kind::Torus), 1);
    let Shape::Torus(t) = &shape_at(&s.geometry, 0) else {
        panic!()
    };
    assert_eq!(
        (t.center(), t.axis(), t.major_radius(), t.minor_radius()),
        (Vec3::ZERO, Vec3::Y, 2.0, 0.5)
    );
    check_inside(
        &s,
        &[[2.4, 0.0, 0.0], [0.0, 0.4, -2.0]],
        &[[0.0, 0.0, 0.0], [2.0, 0.6, 0.0]],
    );
}

#[test]
fn transformed_primitives_are_baked_when_exact() {
    // Each case: the object, whether it stays a top-level shape (baked) rather than
    // becoming an instance, and points inside and outside in world space.
    type Case<'a> = (&'a str, bool, &'a [[f32; 3]], &'a [[f32; 3]]);
    let cases: &[Case] = &[
        // A box under translation and per-axis scale stays a box.
        (
            "type = \"box\"\nmin = [0, 0, 0]\nmax = [1, 1, 1]\ntransform = [{ scale = [2, -3, 1] }, { translate = [0, 0, 5] }]",
            true,
            &[[1.9, -2.9, 5.9]],
            &[[0.5, 0.5, 5.5], [2.1, -1.0, 5.5]],
        ),
        // Rotated, it is an instance.
        (
            "type = \"box\"\nmin = [0, 0, 0]\nmax = [2, 1, 1]\ntransform = [{ rotate = [0, 0, 1], angle = 90 }]",
            false,
            &[[-0.5, 1.9, 0.5]],
            &[[1.5, 0.5, 0.5]],
        ),
        (
            "type = \"obox\"\ncenter = [0, 0, 0]\nhalf_size = [2, 1, 1]\ntransform = [{ rotate = [0, 0, 1], angle = 90 }, { scale = 2 }, { translate = [10, 0, 0] }]",
            true,
            &[[10.0, 3.9, 0.0]],
            &[[12.1, 0.0, 0.0]],
        ),
        (
            "type = \"cylinder\"\nbase = [0, 0, 0]\naxis = [0, 1, 0]\nheight = 1\nradius = 1\ntransform = [{ rotate = [1, 0, 0], angle = 90 }, { scale = 3 }]",
            true,
            &[[0.0, 0.0, 2.9], [2.9, 0.0, 0.1]],
            &[[0.0, 0.0, 3.1], [0.0, 0.0, -0.1]],
        ),
        // A stretched cylinder is an elliptic one: an instance.
        (
            "type = \"cylinder\"\nbase = [0, 0, 0]\naxis = [0, 1, 0]\nheight = 1\nradius = 1\ntransform = [{ scale = [3, 1, 1] }]",
            false,
            &[[2.9, 0.5, 0.0]],
            &[[0.0, 0.5, 1.1]],
        ),
        (
            "type = \"torus\"\ncenter = [0, 0, 0]\naxis = [0, 1, 0]\nmajor_radius = 2\nminor_radius = 0.5\ntransform = [{ rotate = [1, 0, 0], angle = 90 }, { translate = [0, 0, 1] }]",
            true,
            &[[2.0, 0.0, 1.4]],
            &[[2.0, 0.0, 0.0]],
        ),
        // Polyhedra, planes and unclipped quadrics bake under any affine map.
        (
            "type = \"polyhedron\"\npreset = \"cube\"\nradius = 1.7320508\ntransform = [{ matrix = [[1, 1, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]] }]",
            true,
            &[[1.9, 0.95, 0.0]],
            &[[-1.9, 0.95, 0.0], [0.0, 1.1, 0.0]],
        ),
        (
            "type = \"plane\"\npoint = [0, 0, 0]\nnormal = [1, 1, 0]\ntransform = [{ scale = [2, 1, 1] }, { translate = [1, 0, 0] }]",
            true,
            &[[0.0, 0.0, 0.0], [1.0, -0.1, 0.0]],
            &[[1.2, 0.0, 0.0], [0.0, 0.6, 0.0]],
        ),
        (
            "type = \"quadric\"\ncoefficients = [1, 1, 1, 0, 0, 0, 0, 0, 0, -1]\ntransform = [{ scale = [3, 1, 1] }, { translate = [0, 100, 0] }]",
            true,
            &[[2.9, 100.0, 0.0]],
            &[[0.0, 101.1, 0.0], [0.0, 0.0, 0.0]],
        ),
        // A clipped quadric keeps its box: an instance.
        (
            "type = \"quadric\"\ncoefficients = [1, 1, 1, 0, 0, 0, 0, 0, 0, -1]\nclip = { min = [-2, -2, -2], max = [2, 2, 0] }\ntransform = [{ scale = [3, 1, 1] }]",
            false,
            &[[2.9, 0.0, -0.1]],
            &[[2.9, 0.0, 0.1]],
        ),
    ];
    for (obj, baked, inside, outside) in cases {
        let s = build(&format!("[[objects]]\n{obj}\n"));
        assert_eq!(s.instances.is_empty(), *baked, "{obj}");
        check_inside(&s, inside, outside);
    }
}

#[test]
fn csg_of_the_new_solids() {
    // A box with a cylinder drilled through it, cut by a plane at y = 0.5.
    let s = build(
        r#"
[[objects]]
type = "intersection"
children = [
  { type = "difference", children = [
      { type = "box", min = [-1, -1, -1], max = [1, 1, 1] },
      { type = "cylinder", base = [0, 0, -2], axis = [0, 0, 1], height = 4, radius = 0.5 },
  ] },
  { type = "plane", point = [0, 0.5, 0], normal = [0, 1, 0] },
]
"#,
    );
    check_inside(
        &s,
        &[[0.9, 0.4, 0.0], [0.0, -0.9, 0.9]],
        &[[0.0, 0.0, 0.0], [0.9, 0.6, 0.0], [1.1, 0.0, 0.0]],
    );
    // Planes alone bound nothing.
    error_at(
        "[[objects]]\ntype = \"intersection\" # HERE\nchildren = [\n  { type = \"plane\", point = [0, 0, 0], normal = [0, 1, 0] },\n  { type = \"plane\", point = [0, 0, 0], normal = [1, 0, 0] },\n]\n",
        &["unbounded"],
    );
    // An unclipped, unbounded quadric is no operand.
    error_at(
        "[[objects]]\ntype = \"union\"\nchildren = [\n  { type = \"sphere\", center = [0, 0, 0], radius = 1 },\n  { type = \"quadric\", coefficients = [1, 1, 0, 0, 0, 0, 0, 0, 0, -1] }, # HERE\n]\n",
        &["a quadric is not a closed solid"],
    );
}

#[test]
fn errors_of_the_new_primitives() {
    error_at(
        "[[objects]]\ntype = \"box\"\nmin = [0, 0, 0]\nmax = [1, 0, 1] # HERE\n",
        &["must be below max"],
    );
    error_at(
        "[[objects]] # HERE\ntype = \"box\"\nmin = [0, 0, 0]\n",
        &["missing key `max` for a box"],
    );
    error_at(
        "[[objects]]\ntype = \"obox\"\ncenter = [0, 0, 0]\nsize = [1, 1, 0] # HERE\n",
        &["positive components"],
    );
    error_at(
        "[[objects]]\ntype = \"obox\"\ncenter = [0, 0, 0]\nsize = [1, 1, 1]\nhalf_size = [1, 1, 1] # HERE\n",
        &["not both"],
    );
    error_at(
        "[[objects]]\ntype = \"obox\"\ncenter = [0, 0, 0]\nsize = [1, 1, 1]\nrotation = [{ scale = 2 }] # HERE\n",
        &["rotations only"],
    );
    error_at(
        "[[objects]]\ntype = \"obox\"\ncenter = [0, 0, 0]\nsize = [1, 1, 1]\naxes = [[1, 0, 0], [1, 0, 0], [0, 0, 1]] # HERE\n",
        &["not orthonormal"],
    );
    error_at(
        "[[objects]]\ntype = \"cylinder\"\nbase = [0, 0, 0]\naxis = [0, 0, 0] # HERE\nheight = 1\nradius = 1\n",
        &["must not be zero"],
    );
    error_at(
        "[[objects]]\ntype = \"cylinder\"\nbase = [0, 0, 0]\naxis = [0, 1, 0]\nheight = 1\nradius = 0 # HERE\n",
        &["must be positive"],
    );
    error_at(
        "[[objects]]\ntype = \"capped_cone\"\nbase = [0, 0, 0]\naxis = [0, 1, 0]\nheight = 1\nbase_radius = 0\ntop_radius = 0 # HERE\n",
        &["both be zero"],
    );
    error_at(
        "[[objects]]\ntype = \"polyhedron\"\npreset = \"icosahedrn\" # HERE\nradius = 1\n",
        &["unknown polyhedron preset", "did you mean `icosahedron`"],
    );
    error_at(
        "[[objects]]\ntype = \"polyhedron\"\nplanes = [[1, 0, 0, 1], [0, 1, 0, 1], [0, 0, 1, 1], [1, 1, 1, 1]] # HERE\n",
        &["polyhedron"],
    );
    error_at(
        "[[objects]]\ntype = \"polyhedron\"\nplanes = [[1, 0, 0, 1], [0, 0, 0, 1], [0, 0, 1, 1], [1, 1, 1, 1]]\npreset = \"cube\" # HERE\n",
        &["one of `planes`, `preset` or `sides`"],
    );
    error_at(
        "[[objects]]\ntype = \"polyhedron\"\nsides = 2 # HERE\nradius = 1\nheight = 1\n",
        &["sides"],
    );
    error_at(
        "[[objects]]\ntype = \"quadric\"\ncoefficients = [1, 1, 1, 0, 0, 0, 0, 0, 0, 1] # HERE\n",
        &["quadric"],
    );
    error_at(
        "[[objects]]\ntype = \"quadric\"\ncoefficients = [1, 1, 1, 0, 0, 0, 0, 0, 0, -1]\nclip = { min = [0, 0, 0], max = [1, -1, 1] } # HERE\n",
        &["clip box"],
    );
    error_at(
        "[[objects]]\ntype = \"quadric\"\ncoefficients = [1, 1, 1] # HERE\n",
        &["expected an array of 10 values, found an array of 3 values"],
    );
    error_at(
        "[[objects]]\ntype = \"plane\"\npoint = [0, 0, 0]\nnormal = [0, 0, 0] # HERE\n",
        &["must not be zero"],
    );
    error_at(
        "[[objects]]\ntype = \"torus\"\ncenter = [0, 0, 0]\naxis = [0, 1, 0]\nmajor_radius = 1\nminor_radius = 0 # HERE\n",
        &["must be positive"],
    );
    error_at(
        "[[objects]]\ntype = \"torus\"\ncenter = [0, 0, 0]\naxis = [0, 1, 0]\nmajor_radius = 1\nminor_radius = 0.2\nradius = 3 # HERE\n",
        &["`radius` does not apply to a torus"],
    );
}

#[test]
fn triangles_polygons_and_meshes() {
    let s = build(
        r#"
[[objects]]
type = "triangle"
vertices = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]

[[objects]]
type = "triangle"
vertices = [[0, 0, 1], [1, 0, 1], [0, 1, 1]]
normals = [[0, 0, 1], [0, 0, 2], [1, 0, 1]]

# An L: concave, six corners, four triangles.
[[objects]]
type = "polygon"
vertices = [[0, 0, 0], [2, 0, 0], [2, 1, 0], [1, 1, 0], [1, 2, 0], [0, 2, 0]]

# A unit cube of six quads.
[[objects]]
type = "mesh"
vertices = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]]
faces = [[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [2, 3, 7, 6], [1, 2, 6, 5], [0, 4, 7, 3]]

# Degenerate: dropped and counted.
[[objects]]
type = "polygon"
vertices = [[0, 0, 0], [1, 0, 0], [2, 0, 0]]
"#,
    );
    assert_eq!(s.count_with_instances(Kind::Triangle), 1 + 1 + 4 + 12);
    assert_eq!(s.load_stats.polygons, 1 + 1 + 1 + 6 + 1);
    assert_eq!(s.load_stats.degenerate_dropped, 1);
    // Flat, then smooth with unit normals.
    assert_eq!(s.geometry.triangle_normals[0], u32::MAX);
    let k = s.geometry.triangle_normals[1] as usize;
    assert_close(s.geometry.vertex_normals[k][1], Vec3::Z);
    assert_close(
        s.geometry.vertex_normals[k][2],
        Vec3::new(1.0, 0.0, 1.0).normalize(),
    );
    // The L's area is 3 and its triangles face +z as its winding says.
    let l = &s.geometry.triangles.items[2..6];
    let area: f32 = l.iter().map(|t| t.area()).sum();
    assert!((area - 3.0).abs() < 1e-5, "{area}");
    assert!(l.iter().all(|t| t.normal().z > 0.0));
    // The cube's faces point outwards.
    for t in &s.geometry.triangles.items[6..18] {
        let c = (t.p[0] + t.p[1] + t.p[2]) / 3.0;
        assert!(t.normal().dot(c - Vec3::splat(0.5)) > 0.0, "{t:?}");
    }
}

#[test]
fn transforms_apply_in_list_order() {
    let s = build(
        r#"
[[objects]]
type = "sphere"
center = [1, 0, 0]
radius = 1
transform = [{ scale = 2 }, { translate = [0, 5, 0] }]

[[objects]]
type = "sphere"
center = [1, 0, 0]
radius = 1
transform = [{ translate = [0, 5, 0] }, { scale = 2 }]

[[objects]]
type = "sphere"
center = [1, 0, 0]
radius = 1
transform = [{ rotate = [0, 0, 1], angle = 90 }, { translate = [10, 0, 0] }]

# Nesting: the child's own transform first, then the group's.
[[objects]]
type = "group"
transform = [{ rotate = [0, 0, 1], angle = 90 }]
children = [
  { type = "sphere", center = [1, 0, 0], radius = 1, transform = [{ translate = [1, 0, 0] }] },
]

[[objects]]
type = "triangle"
vertices = [[1, 0, 0], [0, 1, 0], [0, 0, 1]]
transform = [
  { matrix = [[1, 0, 0, 3], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]] },
  { rotate = [0, 1, 0], angle = 90 },
]
"#,
    );
    let centers: Vec<Vec3> = s
        .geometry
        .spheres()
        .items
        .iter()
        .map(|s| s.center)
        .collect();
    assert_close(centers[0], Vec3::new(2.0, 5.0, 0.0));
    assert_close(centers[1], Vec3::new(2.0, 10.0, 0.0));
    assert_close(centers[2], Vec3::new(10.0, 1.0, 0.0));
    assert_close(centers[3], Vec3::new(0.0, 2.0, 0.0));
    assert_eq!(s.geometry.spheres().items[0].radius, 2.0);
    assert_eq!(s.geometry.spheres().items[2].radius, 1.0);
    assert!(s.instances.is_empty(), "similarities are baked");
    // (1,0,0) → (4,0,0) → rotated 90° about y: (0,0,−4).
    let t = &s.geometry.triangles.items[0];
    assert_close(t.p[0], Vec3::new(0.0, 0.0, -4.0));
    assert_close(t.p[1], Vec3::new(0.0, 1.0, -3.0));
    assert_close(t.p[2], Vec3::new(1.0, 0.0, -3.0));
}

#[test]
fn non_similar_transforms_make_instances() {
    let s = build(
        r#"
[materials.m]
[[objects]]
type = "sphere"
center = [0, 0, 0]
radius = 1
material = "m"
transform = [{ scale = [2, 1, 1] }, { translate = [0, 3, 0] }]
"#,
    );
    assert_eq!(s.geometry.prim_count(), 0);
    assert_eq!((s.objects.len(), s.instances.len()), (1, 1));
    assert_eq!(s.count_with_instances(Kind::Sphere), 1);
    let inst = &s.instances[0];
    assert_eq!(inst.material, 0);
    assert_eq!(s.objects[0].spheres().material[0], 0);
    let p = inst.xform.to_world.transform_point3(Vec3::X);
    assert_close(p, Vec3::new(2.0, 3.0, 0.0));
}

#[test]
fn mirrors_keep_the_front_side() {
    let s = build(
        r#"
[[objects]]
type = "polygon"
vertices = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]
transform = [{ scale = [1, 1, -1] }]
"#,
    );
    // The square faced +z; mirrored in z it faces −z, and its winding must say so.
    assert!(
        s.geometry
            .triangles
            .items
            .iter()
            .all(|t| t.normal().z < 0.0)
    );
}

#[test]
fn instances_of_a_define_share_one_object() {
    let s = build(
        r#"
[materials.red]
color = [1, 0, 0]
[materials.blue]
color = [0, 0, 1]
[materials.green]
color = [0, 1, 0]

[define.thing]
type = "group"
children = [
  { type = "sphere", center = [0, 1, 0], radius = 0.5 },
  { type = "sphere", center = [0, 2, 0], radius = 0.25, material = "green" },
  { type = "triangle", vertices = [[0, 0, 0], [1, 0, 0], [0, 0, 1]], transform = [{ translate = [0, 7, 0] }] },
]

[[objects]]
type = "instance"
of = "thing"
material = "red"

[[objects]]
type = "instance"
of = "thing"
material = "blue"
transform = [{ translate = [5, 0, 0] }]

[[objects]]
type = "group"
material = "blue"
transform = [{ scale = 2 }]
children = [{ type = "instance", of = "thing", transform = [{ translate = [1, 0, 0] }] }]
"#,
    );
    assert_eq!(s.objects.len(), 1);
    assert_eq!(s.instances.len(), 3);
    assert!(s.instances.iter().all(|i| i.object == 0));
    assert_eq!(s.count_with_instances(Kind::Sphere), 6);
    assert_eq!(s.count_with_instances(Kind::Triangle), 3);
    let obj = &s.objects[0];
    assert_eq!(obj.spheres().material, vec![INHERIT, 2]);
    // The triangle's own transform is baked into the object.
    assert_close(obj.triangles.items[0].p[0], Vec3::new(0.0, 7.0, 0.0));
    assert_eq!(s.instances[0].material, 0);
    assert_eq!(s.instances[1].material, 1);
    // The group's material is inherited; its transform is applied after the instance's.
    assert_eq!(s.instances[2].material, 1);
    let p = s.instances[2].xform.to_world.transform_point3(Vec3::ZERO);
    assert_close(p, Vec3::new(2.0, 0.0, 0.0));
    assert_close(
        s.instances[1].xform.to_world.transform_point3(Vec3::ZERO),
        Vec3::new(5.0, 0.0, 0.0),
    );
}

#[test]
fn defines_copy_nested_instances_and_wrap_transformed_solids() {
    let s = build(
        r#"
[define.ball]
type = "sphere"
center = [0, 0, 0]
radius = 1
transform = [{ scale = [3, 1, 1] }]

[define.pair]
type = "group"
children = [
  { type = "instance", of = "ball" },
  { type = "instance", of = "ball", transform = [{ translate = [0, 10, 0] }] },
]

[[objects]]
type = "instance"
of = "pair"
"#,
    );
    // One object (`ball` is copied into `pair`, not instanced a second level deep).
    assert_eq!(s.objects.len(), 1);
    assert_eq!(s.instances.len(), 1);
    let obj = &s.objects[0];
    // The stretched spheres became one-leaf CSG solids.
    assert_eq!(obj.count(Kind::Csg), 2);
    assert_eq!(obj.count(Kind::Sphere), 0);
    let a = &shape_at(obj, 0);
    let b = &shape_at(obj, 1);
    assert!(a.contains(Vec3::new(2.9, 0.0, 0.0)));
    assert!(!a.contains(Vec3::new(0.0, 1.1, 0.0)));
    assert!(b.contains(Vec3::new(-2.9, 10.0, 0.0)));
    assert!(!b.contains(Vec3::new(0.0, 0.0, 0.0)));
    let bb = b.bounds();
    assert!(
        bb.min.y > 8.9 && bb.max.y < 11.1 && bb.max.x > 2.9,
        "{bb:?}"
    );
}

#[test]
fn defines_wrap_any_transformed_solid_and_bake_exact_maps() {
    let s = build(
        r#"
[define.d]
type = "group"
children = [
  { type = "torus", center = [0, 0, 0], axis = [0, 1, 0], major_radius = 2, minor_radius = 0.5, transform = [{ scale = [1, 3, 1] }] },
  { type = "cone", base = [0, 0, 0], base_radius = 1, apex = [0, 1, 0], transform = [{ rotate = [1, 0, 0], angle = 90 }, { scale = 2 }] },
  { type = "plane", point = [0, 0, 0], normal = [0, 1, 0], transform = [{ scale = [1, 2, 3] }, { translate = [0, -5, 0] }] },
]

[[objects]]
type = "instance"
of = "d"
"#,
    );
    let obj = &s.objects[0];
    assert_eq!(
        (
            obj.count(Kind::Csg),
            obj.count(Kind::Cone),
            obj.count(Kind::Plane)
        ),
        (1, 1, 1)
    );
    let torus = obj
        .shapes()
        .map(|e| e.shape)
        .find(|s| s.kind() == Kind::Csg)
        .unwrap();
    assert!(torus.contains(Vec3::new(2.0, 1.4, 0.0)) && !torus.contains(Vec3::new(2.0, 1.6, 0.0)));
    assert_close(obj.cones().items[0].apex, Vec3::new(0.0, 0.0, 2.0));
    let Some(Shape::Plane(p)) = obj
        .shapes()
        .map(|e| e.shape)
        .find(|s| s.kind() == Kind::Plane)
    else {
        panic!()
    };
    assert_eq!((p.normal(), p.offset()), (Vec3::Y, -5.0));
}

#[test]
fn nested_csg_classifies_points() {
    let s = build(
        r#"
[materials.outer]
[materials.cut]
[materials.inner]

# (A ∪ B) − (C rotated into place), all inside a translated group.
[[objects]]
type = "group"
transform = [{ translate = [100, 0, 0] }]
children = [{ type = "difference", material = "outer", children = [
  { type = "union", material = "inner", children = [
      { type = "sphere", center = [0, 0, 0], radius = 1 },
      { type = "sphere", center = [1.5, 0, 0], radius = 1 },
  ] },
  { type = "sphere", center = [0, 0, 0], radius = 0.5, material = "cut",
    transform = [{ scale = [1, 1, 4] }, { translate = [0, 1, 0] }] },
  { type = "intersection", children = [
      { type = "sphere", center = [1.5, 0, 0], radius = 0.3 },
      { type = "sphere", center = [1.7, 0, 0], radius = 0.3 },
  ] },
] }]
"#,
    );
    // Translated at the top level: the translation goes into the leaves, no instance.
    assert_eq!(s.count_with_instances(Kind::Csg), 1);
    assert_eq!((s.objects.len(), s.instances.len()), (0, 0));
    let shape = &shape_at(&s.geometry, 0);
    let Shape::Csg(csg) = shape else { panic!() };
    assert_eq!(csg.leaf_count(), 5);
    assert_eq!(s.geometry.shapes().next().unwrap().material, 0); // outer
    assert_eq!(csg.leaf_material(0), Some(2)); // inner, from the union
    assert_eq!(csg.leaf_material(2), Some(1)); // cut, its own
    assert_eq!(csg.leaf_material(3), None); // the root's (outer)
    let o = Vec3::new(100.0, 0.0, 0.0);
    let inside = [
        Vec3::new(-0.8, 0.0, 0.0),
        Vec3::new(2.3, 0.0, 0.0),
        Vec3::new(0.0, -0.8, 0.0),
        Vec3::new(1.5, 0.0, 0.6),
    ];
    let outside = [
        Vec3::new(0.0, 0.8, 0.0),     // in the stretched cut
        Vec3::new(0.0, 0.9, 1.5),     // in the cut, far along z
        Vec3::new(1.6, 0.0, 0.0),     // in the intersection lens
        Vec3::new(-1.1, 0.0, 0.0),    // outside the union
        Vec3::new(0.0, 0.0, 0.0) - o, // the untranslated origin
    ];
    let world_contains = |p: Vec3| shape.contains(p);
    for p in inside {
        assert!(world_contains(o + p), "{p} should be inside");
    }
    for p in outside {
        assert!(!world_contains(o + p), "{p} should be outside");
    }

    // Inside a define the same tree carries the transform itself.
    let s = build(&format!(
        "[define.d]\ntype = \"group\"\nchildren = [{{ type = \"instance\", of = \"x\", transform = [{{ translate = [100, 0, 0] }}] }}]\n\
         [define.x]\n{}\n[[objects]]\ntype = \"instance\"\nof = \"d\"\n",
        "type = \"difference\"\nchildren = [\n  { type = \"sphere\", center = [0, 0, 0], radius = 1 },\n  { type = \"sphere\", center = [0, 0, 0], radius = 0.5, transform = [{ scale = [1, 1, 4] }] },\n]"
    ));
    assert_eq!((s.objects.len(), s.instances.len()), (1, 1));
    let shape = &shape_at(&s.objects[0], 0);
    assert!(shape.contains(Vec3::new(100.0, 0.8, 0.0)));
    assert!(!shape.contains(Vec3::new(100.0, 0.0, 0.8)));
    assert!(!shape.contains(Vec3::new(0.0, 0.8, 0.0)));

    // A transformed CSG at the top level is an instance of its own.
    let s = build(
        r#"
[[objects]]
type = "intersection"
transform = [{ scale = [1, 2, 1] }]
children = [
  { type = "sphere", center = [0, 0, 0], radius = 1 },
  { type = "sphere", center = [0.5, 0, 0], radius = 1 },
]
"#,
    );
    assert_eq!((s.objects.len(), s.instances.len()), (1, 1));
    assert_eq!(s.objects[0].count(Kind::Csg), 1);
}

const FLAT_PATCH: &str = r#"
[[objects]]
type = "bezier"
patches = [[
  [0, 0, 0], [1, 0, 0], [2, 0, 0], [3, 0, 0],
  [0, 1, 0], [1, 1, 0], [2, 1, 0], [3, 1, 0],
  [0, 2, 0], [1, 2, 0], [2, 2, 0], [3, 2, 0],
  [0, 3, 0], [1, 3, 0], [2, 3, 0], [3, 3, 0],
]]
"#;

#[test]
fn bezier_patches_tessellate_in_final_coordinates() {
    // A flat patch, rows along x stacked along y: front +z, two triangles.
    let s = build(FLAT_PATCH);
    assert_eq!(s.count_with_instances(Kind::Triangle), 2);
    for (i, t) in s.geometry.triangles.items.iter().enumerate() {
        assert!(t.normal().z > 0.0);
        let k = s.geometry.triangle_normals[i] as usize;
        assert!(
            s.geometry.vertex_normals[k]
                .iter()
                .all(|n| close(*n, Vec3::Z))
        );
    }
    let area: f32 = s.geometry.triangles.items.iter().map(|t| t.area()).sum();
    assert!((area - 9.0).abs() < 1e-4);
    // Mirrored, it faces the other way, geometry and shading alike.
    let s = build(&format!(
        "{FLAT_PATCH}transform = [{{ scale = [1, 1, -1] }}, {{ translate = [0, 0, 2] }}]\n"
    ));
    for (i, t) in s.geometry.triangles.items.iter().enumerate() {
        assert!(t.normal().z < 0.0 && t.p.iter().all(|p| p.z == 2.0));
        let k = s.geometry.triangle_normals[i] as usize;
        assert!(
            s.geometry.vertex_normals[k]
                .iter()
                .all(|n| close(*n, Vec3::NEG_Z))
        );
    }

    // The teapot: z up in its data; a finer tolerance gives more triangles.
    let coarse = build("[[objects]]\ntype = \"bezier\"\nbuiltin = \"teapot\"\ntolerance = 0.05\n");
    let fine = build("[[objects]]\ntype = \"bezier\"\nbuiltin = \"teapot\"\ntolerance = 0.005\n");
    let default = build("[[objects]]\ntype = \"bezier\"\nbuiltin = \"teapot\"\n");
    let n = |s: &Scene| s.count_with_instances(Kind::Triangle);
    assert!(
        n(&coarse) > 100 && n(&fine) > n(&coarse),
        "{} {}",
        n(&coarse),
        n(&fine)
    );
    assert!(n(&default) >= n(&coarse));
    assert_eq!(coarse.geometry.vertex_normals.len(), n(&coarse));
    let b = coarse.geometry.bounds();
    assert!(b.max.z > 3.0 && b.min.z > -0.01 && b.min.z < 0.01, "{b:?}");
    // Turned to y up and scaled: the tessellation is of the transformed patches.
    let turned = build(
        "[[objects]]\ntype = \"bezier\"\nbuiltin = \"teapot\"\ntolerance = 0.05\n\
         transform = [{ rotate = [1, 0, 0], angle = -90 }, { scale = 0.5 }]\n",
    );
    let bt = turned.geometry.bounds();
    assert!((bt.max.y - b.max.z * 0.5).abs() < 1e-3, "{bt:?} vs {b:?}");
    assert!(
        n(&turned) < n(&coarse),
        "a smaller teapot needs fewer triangles for the same tolerance"
    );

    error_at(
        "[[objects]]\ntype = \"bezier\"\nbuiltin = \"teapots\" # HERE\n",
        &["unknown built-in", "did you mean `teapot`"],
    );
    error_at(
        "[[objects]]\ntype = \"bezier\"\npatches = [\n  [[0, 0, 0], [1, 0, 0]], # HERE\n]\n",
        &["expected an array of 16 values, found an array of 2 values"],
    );
    error_at(
        "[[objects]]\ntype = \"bezier\"\nbuiltin = \"teapot\"\ntolerance = 0 # HERE\n",
        &["must be positive"],
    );
    error_at(
        "[[objects]] # HERE\ntype = \"bezier\"\n",
        &["missing key `patches`"],
    );
    error_at(
        "[[objects]]\ntype = \"union\"\nchildren = [\n  { type = \"sphere\", center = [0, 0, 0], radius = 1 },\n  { type = \"bezier\", builtin = \"teapot\" }, # HERE\n]\n",
        &["a bezier is not a closed solid"],
    );
}

#[test]
fn the_nff_equivalent_builds_the_same_scene() {
    let nff = "\
v from 1 2 10 at 0 0 0 up 0 1 0 angle 40 hither 0.5 resolution 64 48
b 0.1 0.2 0.3
l 5 5 5 1 0.5 0.5
f 1 0 0 0.7 0.3 12 0.2 1.4
s 0 1 0 0.5
c 0 0 0 1 0 2 0 0.25
pp 3
0 0 0 0 0 1
1 0 0 0 0 1
0 1 0 0 0 1
";
    let toml = r#"
[camera]
from = [1, 2, 10]
at = [0, 0, 0]
up = [0, 1, 0]
fov = 40
hither = 0.5
resolution = [64, 48]

[render]
background = [0.1, 0.2, 0.3]
ambient = [0.5, 0.5, 0.5]

[materials.f]
color = [1, 0, 0]
diffuse = 0.7
specular = 0.3
reflectance = 0.3
shininess = 12
transmittance = 0.2
ior = 1.4

[[lights]]
position = [5, 5, 5]
color = [1, 0.5, 0.5]

[[objects]]
type = "group"
material = "f"
children = [
  { type = "sphere", center = [0, 1, 0], radius = 0.5 },
  { type = "cone", base = [0, 0, 0], base_radius = 1, apex = [0, 2, 0], apex_radius = 0.25 },
  { type = "polygon", vertices = [[0, 0, 0], [1, 0, 0], [0, 1, 0]], normals = [[0, 0, 1], [0, 0, 1], [0, 0, 1]] },
]
"#;
    let a = emray::load::nff::parse_str(nff, Path::new("a.nff")).unwrap();
    let b = scene_toml::parse_str(toml, Path::new("b.toml")).unwrap();
    assert_eq!(a.camera, b.camera);
    assert_eq!(a.background, b.background);
    assert_eq!(a.ambient, b.ambient);
    assert_eq!(a.lights, b.lights);
    assert_eq!(a.materials, b.materials);
    assert_eq!(a.geometry, b.geometry);
    assert_eq!(a.load_stats, b.load_stats);
}

fn temp_dir() -> tempfile::TempDir {
    tempfile::tempdir().unwrap()
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::create_dir_all(p.parent().unwrap()).unwrap();
    std::fs::write(&p, text).unwrap();
    p
}

const TABLE_NFF: &str = "\
v from 0 0 10 at 0 0 0 up 0 1 0 angle 45 hither 0 resolution 8 8
l 1 2 3 0.5 0.5 0.5
f 1 0 0 0.7 0.3 10 0 1
s 1 0 0 0.5
f 0 1 0 0.6 0 0 0 1
p 3
0 0 0
1 0 0
0 1 0
c 0 0 0 0.5 0 1 0 0.25
";

#[test]
fn includes_remap_materials_and_apply_transforms() {
    let dir = temp_dir();
    write(dir.path(), "parts/table.nff", TABLE_NFF);
    let main = write(
        dir.path(),
        "scene.toml",
        &format!(
            r#"{CAMERA}
[materials.mine]
color = [0.5, 0.5, 0.5]

[[objects]]
type = "include"
file = "parts/table.nff"
lights = true
transform = [{{ scale = 2 }}, {{ translate = [0, 0, 5] }}]

[[objects]]
type = "include"
file = "parts/table.nff"
material = "mine"
"#
        ),
    );
    let text = std::fs::read_to_string(&main).unwrap();
    let s = scene_toml::parse_str_at(&text, &main, glam::DVec3::ZERO).unwrap();
    // Our material, then the NFF's two (read once).
    assert_eq!(s.materials.len(), 3);
    assert_eq!(s.materials[1].color, Vec3::X);
    assert_eq!(s.materials[2].color, Vec3::Y);
    assert_eq!(s.count_with_instances(Kind::Sphere), 2);
    assert_eq!(s.count_with_instances(Kind::Triangle), 2);
    assert_eq!(s.count_with_instances(Kind::Cone), 2);
    let sp = &s.geometry.spheres().items[0];
    assert_close(sp.center, Vec3::new(2.0, 0.0, 5.0));
    assert_eq!(sp.radius, 1.0);
    assert_eq!(s.geometry.spheres().material[0], 1);
    assert_eq!(s.geometry.triangles.material[0], 2);
    assert_close(s.geometry.triangles.items[0].p[1], Vec3::new(2.0, 0.0, 5.0));
    assert_close(s.geometry.cones().items[0].apex, Vec3::new(0.0, 2.0, 5.0));
    assert_eq!(s.geometry.cones().items[0].base_radius, 1.0);
    // The second copy, untransformed, in our material.
    assert_eq!(s.geometry.spheres().items[1].center, Vec3::X);
    assert_eq!(s.geometry.spheres().material[1], 0);
    assert_eq!(s.geometry.triangles.material[1], 0);
    // The light came along once, transformed.
    assert_eq!(s.lights.len(), 1);
    assert_close(s.lights[0].pos, Vec3::new(2.0, 4.0, 11.0));
    assert_eq!(s.load_stats.polygons, 1);

    // Through the generic entry point, by extension.
    let (s2, _) = scene_toml::load_with_settings(&main).unwrap();
    assert_eq!(emray::load::load_path(&main).unwrap(), s2);
}

const QUAD_OBJ: &str = "\
mtllib quad.mtl
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
vn 0 0 1
usemtl blue
f 1//1 2//1 3//1 4//1
";

const QUAD_MTL: &str = "newmtl blue\nKd 0 0 1\n";

#[test]
fn obj_includes_bring_their_materials_and_bake_transforms() {
    let dir = temp_dir();
    write(dir.path(), "models/quad.obj", QUAD_OBJ);
    write(dir.path(), "models/quad.mtl", QUAD_MTL);
    let body = r#"
[materials.mine]
color = [1, 0, 0]

[[objects]]
type = "include"
file = "models/quad.obj"
transform = [{ rotate = [1, 0, 0], angle = -90 }, { translate = [0, 2, 0] }]

[define.q]
type = "include"
file = "models/QUAD.OBJ"

[[objects]]
type = "instance"
of = "q"
material = "mine"
"#;
    let main = write(dir.path(), "scene.toml", &format!("{CAMERA}{body}"));
    // Case of the extension does not matter; the file system's case does, so give the
    // define a copy under that name.
    write(dir.path(), "models/QUAD.OBJ", QUAD_OBJ);
    let s = scene_toml::load(&main).unwrap();
    assert_eq!(s.count_with_instances(Kind::Triangle), 4);
    assert_eq!(s.geometry.count(Kind::Triangle), 2);
    // `mine`, then the OBJ's `blue` (the two names are two files, read once each).
    assert_eq!(s.materials[0].color, Vec3::X);
    let blue = s.materials[s.geometry.triangles.material[0] as usize];
    assert_eq!(blue.color, Vec3::Z);
    // The quad in the z = 0 plane facing +z, turned to face +y, lifted by 2.
    for t in &s.geometry.triangles.items {
        assert!(t.p.iter().all(|p| (p.y - 2.0).abs() < 1e-5), "{t:?}");
        assert!(t.normal().y > 0.0);
    }
    let k = s.geometry.triangle_normals[0] as usize;
    assert_close(s.geometry.vertex_normals[k][0], Vec3::Y);
    // Inside the define the OBJ keeps its own material (an instance's material only
    // fills primitives that have none).
    let obj = &s.objects[s.instances[0].object as usize];
    assert_eq!(
        s.materials[obj.triangles.material[0] as usize].color,
        Vec3::Z
    );

    // `lights` makes no sense for OBJ; errors inside the OBJ name it.
    let body =
        "[[objects]]\ntype = \"include\"\nfile = \"models/quad.obj\"\nlights = true # HERE\n";
    let bad = write(dir.path(), "bad.toml", &format!("{CAMERA}{body}"));
    let e = scene_toml::load(&bad).unwrap_err();
    assert_eq!(e.line, marked_line(&format!("{CAMERA}{body}")), "{e}");
    write(
        dir.path(),
        "broken.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 nan\nf 1 2 3\n",
    );
    let body = "[[objects]]\ntype = \"include\"\nfile = \"broken.obj\" # HERE\n";
    let bad = write(dir.path(), "bad2.toml", &format!("{CAMERA}{body}"));
    let e = scene_toml::load(&bad).unwrap_err();
    assert_eq!(e.path, dir.path().join("broken.obj"), "{e}");
    assert_eq!(e.line, 3, "{e}");
    assert!(e.message.contains("included from"), "{e}");
    let body = "[[objects]]\ntype = \"include\"\nfile = \"gone.obj\" # HERE\n";
    let bad = write(dir.path(), "bad3.toml", &format!("{CAMERA}{body}"));
    let e = scene_toml::load(&bad).unwrap_err();
    assert_eq!(
        (e.path.clone(), e.line),
        (bad, marked_line(&format!("{CAMERA}{body}"))),
        "{e}"
    );
    assert!(e.message.contains("gone.obj"), "{e}");
}

#[test]
fn include_errors_name_the_right_file_and_line() {
    let dir = temp_dir();
    let body = "[[objects]]\ntype = \"include\"\nfile = \"missing/part.nff\" # HERE\n";
    let main = write(dir.path(), "scene.toml", &format!("{CAMERA}{body}"));
    let e = scene_toml::load(&main).unwrap_err();
    assert_eq!(e.path, main);
    assert_eq!(e.line, marked_line(&format!("{CAMERA}{body}")));
    assert!(e.message.contains("missing/part.nff"), "{e}");
    assert!(e.message.contains("cannot read included file"), "{e}");

    // An error inside the included file: its own path and line, and where it was
    // included from.
    write(
        dir.path(),
        "bad.nff",
        "v from 0 0 1 at 0 0 0 up 0 1 0 angle 45 hither 0 resolution 8 8\ns 0 0 0\nx\n",
    );
    let body = "[[objects]]\ntype = \"include\"\nfile = \"bad.nff\" # HERE\n";
    let main = write(dir.path(), "scene2.toml", &format!("{CAMERA}{body}"));
    let e = scene_toml::load(&main).unwrap_err();
    assert_eq!(e.path, dir.path().join("bad.nff"));
    assert_eq!(e.line, 3);
    let from = format!(
        "included from {}:{}:",
        main.display(),
        marked_line(&format!("{CAMERA}{body}"))
    );
    assert!(e.message.contains(&from), "{e}");

    // Lights cannot come from an include inside a define.
    write(dir.path(), "ok.nff", TABLE_NFF);
    let body = "[define.d]\ntype = \"include\"\nfile = \"ok.nff\"\nlights = true # HERE\n[[objects]]\ntype = \"instance\"\nof = \"d\"\n";
    let main = write(dir.path(), "scene3.toml", &format!("{CAMERA}{body}"));
    let e = scene_toml::load(&main).unwrap_err();
    assert_eq!(e.line, marked_line(&format!("{CAMERA}{body}")), "{e}");
}

/// A UTF-8 byte-order mark is skipped in a scene file (columns on its first line count
/// from the character after it) and in the NFF and OBJ files it includes; a
/// gzip-compressed include is refused, naming it and where it was included from.
#[test]
fn byte_order_marks_are_skipped_in_scenes_and_includes() {
    let dir = temp_dir();
    let bom = "\u{feff}";
    let p = write(dir.path(), "first.toml", &format!("{bom}radius = 1\n"));
    let e = scene_toml::load(&p).unwrap_err();
    assert_eq!((e.line, e.col), (1, 1), "{e}");
    write(dir.path(), "part.nff", &format!("{bom}{TABLE_NFF}"));
    write(
        dir.path(),
        "part.obj",
        &format!("{bom}v 0 0 0\nv 1 0 0\nv 0 1 0\nv 9 9 9\nf 1 2 3\n"),
    );
    let body = "[[objects]]\ntype = \"include\"\nfile = \"part.nff\"\n\
                [[objects]]\ntype = \"include\"\nfile = \"part.obj\"\n";
    let main = write(dir.path(), "scene.toml", &format!("{bom}{CAMERA}{body}"));
    let s = scene_toml::load(&main).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(s.geometry.spheres().len(), 1);
    // The polygon of the NFF file and the OBJ face, whose first vertex is kept.
    assert_eq!(s.geometry.triangles.len(), 2);
    let corners = s.geometry.triangles.items[1].p;
    assert!(
        corners
            .iter()
            .all(|&c| (c.as_dvec3() + s.origin).max_element() < 2.0),
        "{corners:?}: a corner at 9 9 9 means the first vertex was lost"
    );

    std::fs::write(dir.path().join("packed.nff"), b"\x1F\x8B\x08\x00").unwrap();
    let body = "[[objects]]\ntype = \"include\"\nfile = \"packed.nff\" # HERE\n";
    let main = write(dir.path(), "packed.toml", &format!("{CAMERA}{body}"));
    let e = scene_toml::load(&main).unwrap_err();
    assert_eq!(e.path, dir.path().join("packed.nff"), "{e}");
    assert!(e.message.contains("gzip-compressed"), "{e}");
    assert!(
        e.message
            .contains(&format!("included from {}", main.display())),
        "{e}"
    );
}

#[test]
fn settings_come_back_from_files() {
    let dir = temp_dir();
    let p = write(
        dir.path(),
        "s.toml",
        &format!("{CAMERA}[render]\nspp = 3\n"),
    );
    let (_, settings) = scene_toml::load_with_settings(&p).unwrap();
    assert_eq!(
        settings,
        SceneSettings {
            max_depth: None,
            spp: Some(3)
        }
    );
    let e = scene_toml::load(&dir.path().join("none.toml")).unwrap_err();
    assert!(e.message.contains("cannot read"), "{e}");
}

// ---- errors, each at its line ------------------------------------------------------

#[test]
fn error_unknown_key() {
    let e = error_at(
        "[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradus = 1 # HERE\n",
        &["unknown key `radus`", "did you mean `radius`"],
    );
    assert_eq!(e.col, 1);
    error_at("[camera2] # HERE\n", &["unknown key `camera2`"]);
    let src = "[camera]\nfrom = [0, 0, 1]\nat = [0, 0, 0]\nfvo = 3 # HERE\n";
    let e = parse(src).unwrap_err();
    assert_eq!(e.line, 4);
    assert!(e.message.contains("did you mean `fov`"), "{e}");
    error_at(
        "[materials.m]\nshinyness = 3 # HERE\n",
        &["unknown key `shinyness`", "shininess"],
    );
    error_at(
        "[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\ntransform = [{ translate = [1, 0, 0], spin = 3 }] # HERE\n",
        &["unknown key `spin`"],
    );
}

#[test]
fn error_key_of_another_type() {
    error_at(
        "[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nfaces = [[0, 1, 2]] # HERE\n",
        &["`faces` does not apply to a sphere", "center, radius"],
    );
    error_at(
        "[[lights]]\nposition = [0, 0, 0]\ncutoff = 3 # HERE\n",
        &["`cutoff` is for spot lights"],
    );
}

#[test]
fn error_wrong_type() {
    error_at(
        "[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = \"big\" # HERE\n",
        &["expected a number, found the string \"big\""],
    );
    error_at(
        "[[objects]]\ntype = \"sphere\"\ncenter = [0, 0] # HERE\nradius = 1\n",
        &["expected an array of 3 values, found an array of 2 values"],
    );
    error_at(
        "[[objects]]\ntype = \"group\"\nchildren = { type = \"sphere\" } # HERE\n",
        &["expected an array, found a table"],
    );
    error_at(
        "[render]\nspp = -1 # HERE\n",
        &["expected a whole number, 0 or more, found the whole number -1"],
    );
    error_at(
        "[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\ntransform = [{ scale = \"x\" }] # HERE\n",
        &["a number or an array of 3 numbers"],
    );
}

#[test]
fn error_missing_required_key() {
    error_at(
        "[[objects]] # HERE\ntype = \"sphere\"\ncenter = [0, 0, 0]\n",
        &["missing key `radius`", "sphere"],
    );
    error_at("[[objects]] # HERE\nradius = 1\n", &["missing key `type`"]);
    error_at(
        "[[objects]]\ntype = \"group\"\nchildren = [\n  { type = \"cone\", base = [0, 0, 0] }, # HERE\n]\n",
        &["missing key `base_radius`", "a cone"],
    );
    error_at(
        "[[lights]] # HERE\ncolor = [1, 1, 1]\n",
        &["missing key `position`"],
    );
    let e = parse("[[objects]]\ntype = \"sphere\"\n").unwrap_err();
    assert_eq!(e.line, 1);
    assert!(e.message.contains("missing key `camera`"), "{e}");
    let e = parse("[camera] # HERE\nfov = 30\n").unwrap_err();
    assert_eq!(e.line, 1);
    assert!(e.message.contains("`from` and `at`"), "{e}");
}

#[test]
fn error_unknown_names() {
    error_at(
        "[materials.glass]\n[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"glas\" # HERE\n",
        &["unknown material `glas`", "did you mean `glass`"],
    );
    error_at(
        "[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"glass\" # HERE\n",
        &["unknown material `glass`", "defines no"],
    );
    error_at(
        "[define.chair]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\n[[objects]]\ntype = \"instance\"\nof = \"chiar\" # HERE\n",
        &["unknown define `chiar`", "did you mean `chair`"],
    );
    error_at(
        "[[objects]]\ntype = \"spere\" # HERE\n",
        &["unknown object type `spere`", "did you mean `sphere`"],
    );
    error_at(
        "[[lights]]\ntype = \"spto\" # HERE\nposition = [0, 0, 0]\n",
        &["unknown light type", "did you mean `spot`"],
    );
}

#[test]
fn error_define_cycle() {
    let e = error_at(
        r#"
[define.a]
type = "group"
children = [{ type = "instance", of = "b" }]

[define.b]
type = "group"
children = [
  { type = "sphere", center = [0, 0, 0], radius = 1 },
  { type = "instance", of = "a" }, # HERE
]

[[objects]]
type = "instance"
of = "a"
"#,
        &["contains an instance of itself", "a → b → a"],
    );
    assert!(e.col > 1);
    // A define that includes itself directly, never used: still found.
    error_at(
        "[define.self]\ntype = \"union\"\nchildren = [\n  { type = \"sphere\", center = [0, 0, 0], radius = 1 },\n  { type = \"instance\", of = \"self\" }, # HERE\n]\n",
        &["self → self"],
    );
}

#[test]
fn error_non_finite_numbers() {
    error_at(
        "[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = nan # HERE\n",
        &["not a finite number"],
    );
    let e = error_at(
        "[[objects]]\ntype = \"sphere\"\ncenter = [\n  0,\n  -inf, # HERE\n  0,\n]\nradius = 1\n",
        &["not a finite number"],
    );
    assert_eq!(e.col, 3);
    error_at(
        "[render]\nbackground = [0, 1e39, 0] # HERE\n",
        &["single-precision range"],
    );
}

#[test]
fn error_bad_sizes() {
    error_at(
        "[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 0 # HERE\n",
        &["sphere `radius` must be positive, found 0"],
    );
    error_at(
        "[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = -2 # HERE\n",
        &["must be positive"],
    );
    error_at(
        "[[objects]]\ntype = \"cone\"\nbase = [0, 0, 0]\nbase_radius = 0 # HERE\napex = [0, 1, 0]\n",
        &["both be zero"],
    );
    let bad_res = "[camera]\nfrom = [0, 0, 1]\nat = [0, 0, 0]\nresolution = [20000, 10] # HERE\n";
    let e = parse(bad_res).unwrap_err();
    assert_eq!(e.line, 4);
    assert!(e.message.contains("between 1 and 16384"), "{e}");
    let e =
        parse("[camera]\nfrom = [0, 0, 1]\nat = [0, 0, 0]\nresolution = [0, 10]\n").unwrap_err();
    assert_eq!(e.line, 4);
    error_at(
        "[materials.m]\nior = 0 # HERE\n",
        &["`ior` must be positive"],
    );
    error_at(
        "[materials.m]\ndiffuse = -0.5 # HERE\n",
        &["must not be negative"],
    );
    error_at("[render]\nmax_depth = 0 # HERE\n", &["between 1 and"]);
    error_at(
        "[[objects]]\ntype = \"mesh\"\nvertices = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]\nfaces = [\n  [0, 1, 2],\n  [0, 1, 3], # HERE\n]\n",
        &["vertex index 3 is out of range"],
    );
    error_at(
        "[[objects]]\ntype = \"triangle\"\nvertices = [[0, 0, 0], [1, 0, 0]] # HERE\n",
        &["exactly 3 vertices"],
    );
    error_at(
        "[[objects]]\ntype = \"union\"\nchildren = [{ type = \"sphere\", center = [0, 0, 0], radius = 1 }] # HERE\n",
        &["at least 2 children"],
    );
}

/// An empty list that leaves an object meaningless is an error at the list, naming
/// its key: with it, a bezier once panicked (its default tolerance came from the
/// bounds of no control points) or drew nothing, and a mesh or group drew nothing
/// without a word.
#[test]
fn error_empty_lists() {
    let patch = "[[0, 0, 0], [1, 0, 0], [2, 0, 0], [3, 0, 0], [0, 1, 0], [1, 1, 1], [2, 1, 1], \
                 [3, 1, 0], [0, 2, 0], [1, 2, 1], [2, 2, 1], [3, 2, 0], [0, 3, 0], [1, 3, 0], \
                 [2, 3, 0], [3, 3, 0]]";
    let cases: &[(&str, &[&str])] = &[
        (
            "[[objects]]\ntype = \"bezier\"\npatches = [] # HERE\n",
            &["`patches` is empty", "a bezier needs at least one patch"],
        ),
        (
            "[[objects]]\ntype = \"bezier\"\ntolerance = 0.1\npatches = [] # HERE\n",
            &["`patches` is empty"],
        ),
        (
            "[[objects]]\ntype = \"mesh\"\nvertices = [] # HERE\nfaces = []\n",
            &["`vertices` is empty", "a mesh needs at least one vertex"],
        ),
        (
            "[[objects]]\ntype = \"mesh\"\nvertices = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]\nfaces = [] # HERE\n",
            &["`faces` is empty", "a mesh needs at least one face"],
        ),
        (
            "[[objects]]\ntype = \"group\"\nchildren = [] # HERE\n",
            &["`children` is empty", "a group needs at least one child"],
        ),
        (
            "[[objects]]\ntype = \"group\"\nchildren = [\n  { type = \"group\", children = [] }, # HERE\n]\n",
            &["`children` is empty"],
        ),
        (
            "[define.d]\ntype = \"group\"\nchildren = [] # HERE\n[[objects]]\ntype = \"instance\"\nof = \"d\"\n",
            &["`children` is empty"],
        ),
        (
            "[define.unused]\ntype = \"mesh\"\nvertices = [] # HERE\nfaces = [[0, 1, 2]]\n",
            &["`vertices` is empty"],
        ),
        (
            "[[objects]]\ntype = \"polygon\"\nvertices = [] # HERE\n",
            &["`vertices` is empty", "a polygon needs at least 3 vertices"],
        ),
        (
            "[[objects]]\ntype = \"triangle\"\nvertices = [] # HERE\n",
            &["`vertices` is empty", "a triangle needs exactly 3 vertices"],
        ),
        (
            "[[objects]]\ntype = \"polyhedron\"\nplanes = [] # HERE\n",
            &["`planes` is empty", "at least 4"],
        ),
        (
            "[[objects]]\ntype = \"union\"\nchildren = [] # HERE\n",
            &["`children` is empty", "a union needs at least 2 children"],
        ),
    ];
    for (body, words) in cases {
        error_at(body, words);
    }
    // A bezier with patches still builds.
    let s = build(&format!(
        "[[objects]]\ntype = \"bezier\"\npatches = [{patch}]\n"
    ));
    assert!(s.geometry.triangles.len() > 1);
}

/// A bezier whose control points overflow under its transforms is refused at its
/// `type` (its default tolerance, relative to their extent, was once infinite and
/// panicked), as is every other object that leaves the traceable range.
#[test]
fn error_bezier_overflowing_under_transforms() {
    let points: Vec<String> = (0..16)
        .map(|i| format!("[{}e8, {}, 0]", i % 4, i / 4))
        .collect();
    let mut node = format!(
        "{{ type = \"bezier\", patches = [[{}]] }}",
        points.join(", ")
    );
    for _ in 0..25 {
        node = format!(
            "{{ type = \"group\", transform = [{{ scale = 1e12 }}], children = [{node}] }}"
        );
    }
    let e = parse(&format!(
        "{CAMERA}[[objects]]\ntype = \"group\"\nchildren = [{node}]\n"
    ))
    .unwrap_err();
    assert!(e.message.contains("this bezier"), "{e}");
    assert_eq!(e.line, 6, "{e}");
}

#[test]
fn error_bad_transforms() {
    error_at(
        "[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\ntransform = [\n  { translate = [1, 0, 0] },\n  { matrix = [[1, 0, 0, 0], [0, 1, 0, 0], [1, 1, 0, 0], [0, 0, 0, 1]] }, # HERE\n]\n",
        &["bad transform", "singular"],
    );
    error_at(
        "[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\ntransform = [{ scale = [1, 0, 1] }] # HERE\n",
        &["must not be zero"],
    );
    error_at(
        "[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\ntransform = [{ rotate = [0, 1, 0] }] # HERE\n",
        &["`rotate` needs `angle`"],
    );
    error_at(
        "[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\ntransform = [{ translate = [1, 0, 0], scale = 2 }] # HERE\n",
        &["exactly one of", "translate, scale"],
    );
    error_at(
        "[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\ntransform = [{ matrix = [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 1, 1]] }] # HERE\n",
        &["last row"],
    );
    error_at(
        "[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\ntransform = [{ rotate = [0, 0, 0], angle = 3 }] # HERE\n",
        &["rotation axis must not be zero"],
    );
}

#[test]
fn error_csg_of_open_surfaces() {
    error_at(
        "[[objects]]\ntype = \"union\"\nchildren = [\n  { type = \"sphere\", center = [0, 0, 0], radius = 1 },\n  { type = \"cone\", base = [0, 0, 0], base_radius = 1, apex = [0, 1, 0] }, # HERE\n]\n",
        &["open cone is not a closed solid", "CSG operand"],
    );
    error_at(
        "[[objects]]\ntype = \"difference\"\nchildren = [\n  { type = \"sphere\", center = [0, 0, 0], radius = 1 },\n  { type = \"triangle\", vertices = [[0, 0, 0], [1, 0, 0], [0, 1, 0]] }, # HERE\n]\n",
        &["a triangle is not a closed solid"],
    );
    error_at(
        "[[objects]]\ntype = \"intersection\"\nchildren = [\n  { type = \"sphere\", center = [0, 0, 0], radius = 1 },\n  { type = \"group\", children = [] }, # HERE\n]\n",
        &["a group is not a solid"],
    );
    // An open surface under a non-similar transform inside a define: one instancing
    // level.
    error_at(
        "[define.d]\ntype = \"group\"\nchildren = [\n  { type = \"cone\", base = [0, 0, 0], base_radius = 1, apex = [0, 1, 0], transform = [{ scale = [1, 2, 1] }] }, # HERE\n]\n[[objects]]\ntype = \"instance\"\nof = \"d\"\n",
        &["one instancing level"],
    );
}

/// A spindle torus (minor radius above the major one) intersects itself: what is
/// inside it is not clear, so it is refused as a CSG operand, directly or through an
/// instance, at its `type`.
#[test]
fn error_spindle_torus_in_csg() {
    let torus = "type = \"torus\", center = [0, 0, 0], axis = [0, 1, 0], major_radius = 1";
    error_at(
        &format!(
            "[[objects]]\ntype = \"union\"\nchildren = [\n  {{ type = \"sphere\", center = [0, 0, 0], radius = 1 }},\n  {{ {torus}, minor_radius = 2 }}, # HERE\n]\n"
        ),
        &[
            "a spindle torus (minor radius 2 > major radius 1)",
            "cannot be a CSG operand",
        ],
    );
    error_at(
        "[define.lemon]\ntype = \"torus\" # HERE\ncenter = [0, 0, 0]\naxis = [0, 1, 0]\nmajor_radius = 1\nminor_radius = 1.5\n\
         [[objects]]\ntype = \"difference\"\nchildren = [\n  { type = \"sphere\", center = [0, 0, 0], radius = 3 },\n  { type = \"instance\", of = \"lemon\" },\n]\n",
        &["spindle torus", "CSG operand"],
    );
    // A horn torus (equal radii) and a ring torus are operands as before.
    let s = build(&format!(
        "[[objects]]\ntype = \"union\"\nchildren = [\n  {{ type = \"sphere\", center = [0, 0, 0], radius = 1 }},\n  {{ {torus}, minor_radius = 1 }},\n  {{ {torus}, minor_radius = 0.5 }},\n]\n"
    ));
    assert_eq!(s.geometry.count(Kind::Csg), 1);
}

/// Outside CSG a spindle torus is drawn (its outer surface), with a warning at its
/// `type`.
#[test]
fn spindle_torus_warns() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("s.toml"),
        "[camera]\nfrom = [0, 0, 9]\nat = [0, 0, 0]\nresolution = [8, 8]\n\
         [[objects]]\ntype = \"torus\"\ncenter = [0, 0, 0]\naxis = [0, 1, 0]\nmajor_radius = 1\nminor_radius = 2\n\
         [[objects]]\ntype = \"torus\"\ncenter = [0, 3, 0]\naxis = [0, 1, 0]\nmajor_radius = 1\nminor_radius = 1\n",
    )
    .unwrap();
    let out = common::emray(dir.path(), &["render", "s.toml", "-o", "s.png"]);
    let err = common::stderr(&out);
    assert!(out.status.success(), "{err}");
    assert_eq!(err.matches("spindle").count(), 1, "{err}");
    assert!(
        err.contains("s.toml:6:8: a spindle torus (minor radius 2 > major radius 1)"),
        "{err}"
    );
}

/// Messages show numbers as the file writes them, never in Rust's terms (`Vec3(1.0,
/// 0.0, 0.0)`, `0.0`, `` ` as i128 ``).
#[test]
fn messages_show_plain_numbers() {
    let rust_terms = ["Vec3", "i128", "0.0", "`"];
    let plain = |e: LoadError| {
        for w in rust_terms {
            assert!(!e.message.contains(w), "`{w}` in: {e}");
        }
        e
    };
    let e = plain(error_at(
        "[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 99999999999999999999 # HERE\n",
        &["number too large: 99999999999999999999"],
    ));
    assert!(e.message.contains("99999999999999999999.0"), "{e}");
    plain(error_at(
        "[render]\nspp = 99999999999999999999 # HERE\n",
        &["number too large: 99999999999999999999", "whole number"],
    ));
    plain(error_at(
        "[[objects]]\ntype = \"obox\"\ncenter = [0, 0, 0]\nsize = [1, 1, 1]\naxes = [[1, 0, 0], [1, 0, 0], [0, 0.5, 1]] # HERE\n",
        &["axes (1, 0, 0), (1, 0, 0), (0, 0.5, 1) are not orthonormal"],
    ));
    plain(error_at(
        "[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\ntransform = [{ matrix = [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 1.5, 1]] }] # HERE\n",
        &["found [0, 0, 1.5, 1]"],
    ));
}

#[test]
fn error_toml_syntax() {
    error_at(
        "[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0\nradius = 1 # HERE\n",
        &[],
    );
    error_at("[render]\nspp = 1\nspp = 2 # HERE\n", &["duplicate key"]);
}

#[test]
fn valid_but_surprising_inputs() {
    // Integers and floats are both numbers; a define used by nothing is still checked
    // (and fine).
    let s = build("[define.unused]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\n");
    assert_eq!(s.prim_count_with_instances(), 0);
    error_at(
        "[define.unused]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 0 # HERE\n",
        &["must be positive"],
    );
}

/// Every ```toml block of the format's reference builds (blocks without `[camera]`
/// get one, and the materials the examples use).
#[test]
fn documentation_examples_build() {
    let doc = std::fs::read_to_string(common::repo().join("docs/scene-format.md")).unwrap();
    let dir = temp_dir();
    write(dir.path(), "parts/table.nff", TABLE_NFF);
    write(dir.path(), "table.nff", TABLE_NFF);
    let prelude = format!(
        "{CAMERA}[materials.red]\ncolor = [0.8, 0.1, 0.1]\n[materials.white]\n[materials.glass]\ntransmittance = 0.9\nior = 1.5\n"
    );
    let mut blocks = 0;
    let mut rest = doc.as_str();
    while let Some(start) = rest.find("```toml\n") {
        let body = &rest[start + 8..];
        let end = body.find("```").expect("closed block");
        let block = &body[..end];
        rest = &body[end + 3..];
        blocks += 1;
        let src = if block.contains("[camera]") {
            block.to_string()
        } else {
            format!("{prelude}{block}")
        };
        let path = write(dir.path(), &format!("doc{blocks}.toml"), &src);
        if let Err(e) = scene_toml::load(&path) {
            panic!("docs example {blocks} fails: {e}\n{src}");
        }
    }
    assert!(blocks >= 10, "only {blocks} examples found");
    for ty in [
        "sphere",
        "cone",
        "cylinder",
        "capped_cone",
        "box",
        "obox",
        "polyhedron",
        "quadric",
        "plane",
        "torus",
        "triangle",
        "polygon",
        "mesh",
        "include",
        "group",
        "instance",
        "union",
        "intersection",
        "difference",
    ] {
        assert!(
            doc.contains(&format!("### `{ty}`"))
                || doc.contains(&format!(", `{ty}`"))
                || doc.contains(&format!("`{ty}`, ")),
            "`{ty}` undocumented"
        );
    }
}

#[test]
fn round_trip_of_a_built_scene_file_is_stable() {
    // Scene file → structures → text → structures → scene: the same scene.
    let src = format!(
        "{CAMERA}{}",
        r#"
[materials.a]
color = [0.25, 0.5, 1]
[[objects]]
type = "group"
transform = [{ rotate = [1, 1, 0], angle = 33 }]
children = [
  { type = "sphere", center = [0.1, 0.2, 0.3], radius = 0.7, material = "a" },
  { type = "polygon", vertices = [[0, 0, 0], [2, 0, 0], [2, 1, 0], [1, 1, 0], [1, 2, 0], [0, 2, 0]] },
]
"#
    );
    let file: SceneFile = scene_toml::parse_file(&src, Path::new("a.toml")).unwrap();
    let text = file.to_toml_string().unwrap();
    let a = parse(&src).unwrap();
    let b = parse(&text).unwrap();
    assert_eq!(a, b);
}

#[test]
fn children_as_arrays_of_tables() {
    let s = build(
        r#"
[[objects]]
type = "group"
material = "m"

[[objects.children]]
type = "sphere"
center = [1, 0, 0]
radius = 1

[[objects.children]]
type = "union"

[[objects.children.children]]
type = "sphere"
center = [0, 5, 0]
radius = 1

[[objects.children.children]]
type = "sphere"
center = [0, 6, 0]
radius = 1
transform = [{ translate = [0, 0, 1] }]

[materials.m]
color = [0, 0, 1]
"#,
    );
    assert_eq!(s.count_with_instances(Kind::Sphere), 1);
    assert_eq!(s.count_with_instances(Kind::Csg), 1);
    assert_eq!(s.geometry.spheres().material[0], 0);
    assert_eq!(s.geometry.csg().material[0], 0);
    let csg = s.geometry.shape(Kind::Csg, 0).unwrap();
    assert!(csg.contains(Vec3::new(0.0, 6.0, 1.0)));
    assert!(!csg.contains(Vec3::new(0.0, 6.9, 0.0)));
    // An error in such a table points into it.
    error_at(
        "[[objects]]\ntype = \"group\"\n[[objects.children]]\ntype = \"sphere\"\ncenter = [1, 0, 0]\nradius = 0 # HERE\n",
        &["must be positive"],
    );
}

/// A material colour or the background above 1 (a 0–255 scale by mistake) is a
/// warning at the value; light intensities may exceed 1.
#[test]
fn colours_above_one_warn() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("s.toml"),
        "[camera]\nfrom = [0, 0, 5]\nat = [0, 0, 0]\nresolution = [8, 8]\n\
         [render]\nbackground = [0.1, 0.2, 0.3]\n\
         [materials.red]\ncolor = [200, 30, 30]\n\
         [[lights]]\nposition = [0, 5, 5]\nintensity = 3\n\
         [[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"red\"\n",
    )
    .unwrap();
    let out = common::emray(dir.path(), &["render", "s.toml", "-o", "s.png"]);
    let err = common::stderr(&out);
    assert!(out.status.success(), "{err}");
    assert_eq!(err.matches("above 1").count(), 1, "{err}");
    assert!(
        err.contains("s.toml:8:9: `color` [200, 30, 30] has channels above 1"),
        "{err}"
    );
}

/// A define that an instance names anywhere (at the top level, as a CSG operand, inside
/// another define, even one nothing places) is not warned about; one that no instance
/// names is, once. Polygons of a define copied into another are counted once.
#[test]
fn only_defines_no_instance_names_are_warned_about() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("d.toml"),
        "[camera]\nfrom = [0, 0, 9]\nat = [0, 0, 0]\nresolution = [8, 8]\n\
         [define.ball]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\n\
         [define.leaf]\ntype = \"polygon\"\nvertices = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]\n\
         [define.tree]\ntype = \"group\"\nchildren = [{ type = \"instance\", of = \"leaf\" }]\n\
         [define.inner]\ntype = \"sphere\"\ncenter = [5, 0, 0]\nradius = 1\n\
         [define.unplaced]\ntype = \"group\"\nchildren = [{ type = \"instance\", of = \"inner\" }]\n\
         [define.alone]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 2\n\
         [[objects]]\ntype = \"difference\"\nchildren = [\n  { type = \"sphere\", center = [0, 0, 0], radius = 2 },\n  { type = \"instance\", of = \"ball\" },\n]\n\
         [[objects]]\ntype = \"instance\"\nof = \"tree\"\n",
    )
    .unwrap();
    let out = common::emray(dir.path(), &["render", "d.toml", "-o", "d.png", "--stats"]);
    let err = common::stderr(&out);
    assert!(out.status.success(), "{err}");
    for used in ["ball", "leaf", "tree", "inner"] {
        assert!(!err.contains(&format!("`{used}`")), "{used}: {err}");
    }
    assert_eq!(err.matches("is never instanced").count(), 2, "{err}");
    assert!(
        err.contains("define `unplaced` is never instanced"),
        "{err}"
    );
    assert!(err.contains("define `alone` is never instanced"), "{err}");
    let s = scene_toml::load(&dir.path().join("d.toml")).unwrap();
    assert_eq!(s.load_stats.polygons, 1);
}

/// A TOML scene's frame has its origin at the eye, and its points are read in double
/// precision: the same scene a million units away (its coordinates shifted, not a
/// transform) builds into the same single-precision numbers, primitives placed in
/// place, by a rotation (an instance) or inside a CSG alike.
#[test]
fn the_frame_is_the_eye_and_far_scenes_keep_their_detail() {
    let scene = |s: f64| {
        let p = |x: f64, y: f64, z: f64| format!("[{:?}, {:?}, {:?}]", x + s, y - s, z + s);
        format!(
            "[camera]\nfrom = {}\nat = {}\n\
             [[lights]]\nposition = {}\n\
             [[objects]]\ntype = \"sphere\"\ncenter = {}\nradius = 0.7\n\
             [[objects]]\ntype = \"quadric\"\ncoefficients = [1, 1, 1, 0, 0, 0, 0, 0, 0, -0.25]\n\
             transform = [{{ translate = {} }}]\n\
             [[objects]]\ntype = \"mesh\"\nvertices = [{}, {}, {}]\nfaces = [[0, 1, 2]]\n\
             [[objects]]\ntype = \"union\"\nchildren = [\n\
               {{ type = \"sphere\", center = {}, radius = 0.3 }},\n\
               {{ type = \"box\", min = {}, max = {} }},\n]\n",
            p(0.1, -5.3, 1.7),
            p(0.0, 0.0, 0.5),
            p(3.0, -2.0, 5.0),
            p(0.3, 0.2, 0.1),
            p(-1.0, 0.5, 0.25),
            p(0.0, 0.0, 0.0),
            p(1.0, 0.0, 0.0),
            p(0.0, 1.0, 0.3),
            p(2.0, 0.0, 0.0),
            p(2.1, -0.1, -0.1),
            p(2.4, 0.2, 0.2),
        )
    };
    let a = scene_toml::parse_str(&scene(0.0), Path::new("near.toml")).unwrap();
    let b = scene_toml::parse_str(&scene(1e6), Path::new("far.toml")).unwrap();
    assert_eq!(a.camera.from, Vec3::ZERO);
    assert_eq!(a.camera, b.camera);
    assert_eq!(a.lights, b.lights);
    assert_eq!(a.count_with_instances(Kind::Csg), 1);
    assert!(a.instances.is_empty(), "translations stay in place");
    // Every primitive in the same place, and hit by the same ray at the same distance.
    let ray = emray::math::Ray::new(Vec3::ZERO, a.camera.at);
    for (sa, sb) in a.geometry.shapes().zip(b.geometry.shapes()) {
        let (ba, bb) = (sa.shape.bounds(), sb.shape.bounds());
        let d = (ba.min - bb.min)
            .abs()
            .max(ba.max - bb.max)
            .abs()
            .max_element();
        assert!(d < 1e-6, "{:?}: {ba:?} {bb:?}", sa.kind);
        let (ha, hb) = (sa.shape.intersect(&ray), sb.shape.intersect(&ray));
        let (ta, tb) = (ha.map(|h| h.t), hb.map(|h| h.t));
        match (ta, tb) {
            (Some(x), Some(y)) => assert!((x - y).abs() <= 1e-6 * x, "{:?}: {x} {y}", sa.kind),
            _ => assert_eq!(ta, tb, "{:?}", sa.kind),
        }
    }
    let (ta, tb) = (a.geometry.triangles.items[0], b.geometry.triangles.items[0]);
    for k in 0..3 {
        assert!(
            (ta.p[k] - tb.p[k]).abs().max_element() < 1e-6,
            "{} {}",
            ta.p[k],
            tb.p[k]
        );
    }
}
