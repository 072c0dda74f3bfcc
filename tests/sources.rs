//! Every loader records where it made each primitive (and the TOML and NFF loaders each
//! material, light and instance): the NFF entity's line, the TOML table's first line
//! (a group's children their own), an OBJ face's line, and for an included file its own
//! name and line.

use emray::geometry::Kind;
use emray::load::load_path;
use emray::scene::{Geometry, Scene};
use std::path::Path;

fn at(g: &Geometry, kind: Kind, prim: u32) -> String {
    g.sources
        .get(kind, prim)
        .map(|o| o.to_string())
        .unwrap_or_else(|| format!("no origin for {kind:?} {prim}"))
}

/// The file name of an origin, without the folder the test wrote it to.
fn short(origin: String, dir: &Path) -> String {
    origin.replace(&format!("{}/", dir.display()), "")
}

const TOML: &str = r#"[camera]
from = [0.0, 0.0, 8.0]
at = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
fov = 40
resolution = [16, 16]

[materials.red]
color = [1.0, 0.0, 0.0]

[[lights]]
position = [0.0, 5.0, 5.0]

[define.pair]
type = "group"
children = [
  { type = "sphere", center = [0, 0, 0], radius = 0.5 },
  { type = "sphere", center = [1, 0, 0], radius = 0.5 },
]

[[objects]]
type = "sphere"
center = [0.0, 0.0, 0.0]
radius = 1.0
material = "red"

[[objects]]
type = "group"
children = [
  { type = "triangle", vertices = [[0, 0, 0], [1, 0, 0], [0, 1, 0]] },
  { type = "sphere", center = [3, 0, 0], radius = 0.5 },
]

[[objects]]
type = "instance"
of = "pair"

[[objects]]
type = "include"
file = "part.nff"

[[objects]]
type = "include"
file = "quad.obj"
"#;

const NFF: &str = "# a part\nf 0 1 0 1 0 0 0 1\ns 5 0 0 1\n\np 3 0 0 1 1 0 1 0 1 1\n\
                   v from 0 0 9 at 0 0 0 up 0 1 0 angle 40 hither 1 resolution 8 8\n";

const OBJ: &str =
    "v 0 0 2\nv 1 0 2\nv 1 1 2\nv 0 1 2\n# one quad, two triangles\nf 1 2 3 4\nf 1 3 4\n";

#[test]
fn toml_objects_groups_instances_and_includes_name_their_lines() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("scene.toml"), TOML).unwrap();
    std::fs::write(dir.path().join("part.nff"), NFF).unwrap();
    std::fs::write(dir.path().join("quad.obj"), OBJ).unwrap();
    let scene: Scene = load_path(&dir.path().join("scene.toml")).unwrap();
    let g = &scene.geometry;
    let s = |o: String| short(o, dir.path());
    // Spheres in order: the red one, the group's, the included file's.
    assert_eq!(s(at(g, Kind::Sphere, 0)), "scene.toml:21");
    assert_eq!(s(at(g, Kind::Sphere, 1)), "scene.toml:31");
    assert_eq!(s(at(g, Kind::Sphere, 2)), "part.nff:3");
    // Triangles: the group's, then the included NFF polygon, then the OBJ faces (the
    // quad's two triangles on one line).
    assert_eq!(s(at(g, Kind::Triangle, 0)), "scene.toml:30");
    assert_eq!(s(at(g, Kind::Triangle, 1)), "part.nff:5");
    assert_eq!(s(at(g, Kind::Triangle, 2)), "quad.obj:6");
    assert_eq!(s(at(g, Kind::Triangle, 3)), "quad.obj:6");
    assert_eq!(s(at(g, Kind::Triangle, 4)), "quad.obj:7");
    // The define's spheres at their own lines, the instance at its `type`.
    let object = &scene.objects[scene.instances[0].object as usize];
    assert_eq!(s(at(object, Kind::Sphere, 0)), "scene.toml:17");
    assert_eq!(s(at(object, Kind::Sphere, 1)), "scene.toml:18");
    let origin = |o: Option<emray::scene::Origin>| s(o.unwrap().to_string());
    assert_eq!(origin(scene.sources.instances.get(0)), "scene.toml:34");
    assert_eq!(origin(scene.sources.lights.get(0)), "scene.toml:11");
    let red = scene
        .materials
        .iter()
        .position(|m| m.color.y == 0.0 && m.color.x == 1.0);
    assert_eq!(
        origin(scene.sources.materials.get(red.unwrap() as u32)),
        "scene.toml:8"
    );
    // The included NFF's material keeps its own line.
    let green = scene
        .materials
        .iter()
        .position(|m| m.color.y == 1.0 && m.color.x == 0.0);
    assert_eq!(
        origin(scene.sources.materials.get(green.unwrap() as u32)),
        "part.nff:2"
    );
}

#[test]
fn an_obj_model_names_its_faces() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("quad.obj");
    std::fs::write(&path, OBJ).unwrap();
    let scene = load_path(&path).unwrap();
    let g = &scene.geometry;
    assert_eq!(short(at(g, Kind::Triangle, 1), dir.path()), "quad.obj:6");
    assert_eq!(short(at(g, Kind::Triangle, 2), dir.path()), "quad.obj:7");
}
