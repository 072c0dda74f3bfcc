//! OBJ/MTL loader tests through the public API. Every file is written by the test into
//! a temporary directory.

use emray::Hit;
use emray::geometry::{Kind, Triangle};
use emray::load::obj::{
    AUTO_FOV_DEG, AUTO_RESOLUTION, DEFAULT_MATERIAL, ObjData, frame, load, load_geometry,
};
use emray::load::{LoadError, load_path};
use emray::math::{Aabb, Ray, Vec3};
use emray::scene::Material;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use tempfile::TempDir;

/// Write `files` (name, contents) into a fresh directory.
fn dir_with(files: &[(&str, &str)]) -> TempDir {
    let dir = tempfile::tempdir().unwrap();
    for (name, text) in files {
        std::fs::write(dir.path().join(name), text).unwrap();
    }
    dir
}

fn ok(path: &Path) -> ObjData {
    load_geometry(path).unwrap_or_else(|e| panic!("unexpected error: {e}"))
}

/// Load `obj` (with `mtl` files beside it) from `model.obj`.
fn load_text(obj: &str, mtl: &[(&str, &str)]) -> (TempDir, PathBuf, Result<ObjData, LoadError>) {
    let mut files = vec![("model.obj", obj)];
    files.extend_from_slice(mtl);
    let dir = dir_with(&files);
    let path = dir.path().join("model.obj");
    let r = load_geometry(&path);
    (dir, path, r)
}

fn area(t: &Triangle) -> f32 {
    0.5 * (t.p[1] - t.p[0]).cross(t.p[2] - t.p[0]).length()
}

fn normal(t: &Triangle) -> Vec3 {
    (t.p[1] - t.p[0]).cross(t.p[2] - t.p[0]).normalize()
}

fn close(a: Vec3, b: Vec3) -> bool {
    (a - b).abs().max_element() < 1e-5
}

// ---------------------------------------------------------------------------------
// A cube of quads

const CUBE_OBJ: &str = "\
# unit cube, faces counterclockwise seen from outside
mtllib cube.mtl
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
v 0 0 1
v 1 0 1
v 1 1 1
v 0 1 1
g sides
usemtl red
f 1 4 3 2
f 5 6 7 8
usemtl green
f 1 2 6 5
f 4 8 7 3
g caps
usemtl blue
f 1 5 8 4
f 2 3 7 6
";

const CUBE_MTL: &str = "\
newmtl red
Ka 0.1 0 0
Kd 0.8 0 0
Ks 0.3 0.3 0.3
Ns 50
illum 2

newmtl green
Kd 0 0.6 0
illum 1

newmtl blue
Kd 0 0 0.9
Ks 0.5 0.5 0.5
illum 3
";

#[test]
fn cube_of_quads_is_twelve_outward_triangles_with_its_materials() {
    let (_dir, path, r) = load_text(CUBE_OBJ, &[("cube.mtl", CUBE_MTL)]);
    let data = r.unwrap_or_else(|e| panic!("{e}"));
    let tris = &data.geometry.triangles;
    assert_eq!(tris.len(), 12);
    assert!(data.warnings.is_empty(), "{:?}", data.warnings);
    assert_eq!(data.stats.polygons, 6);
    assert_eq!(data.stats.degenerate_dropped, 0);
    assert_eq!(
        data.bounds,
        Aabb::from_points(Vec3::ZERO, Vec3::ONE),
        "{path:?}"
    );
    // Flat: no vn in the file.
    assert!(
        data.geometry
            .triangle_normals
            .iter()
            .all(|&n| n == u32::MAX)
    );
    assert!(data.geometry.vertex_normals.is_empty());

    // Outward: every triangle faces away from the centre, and the area is the cube's.
    let centre = Vec3::splat(0.5);
    let mut total = 0.0;
    for t in &tris.items {
        let c = (t.p[0] + t.p[1] + t.p[2]) / 3.0;
        assert!(normal(t).dot(c - centre) > 0.0, "{t:?} faces inward");
        total += area(t);
    }
    assert!((total - 6.0).abs() < 1e-5, "area {total}");

    // Closed and consistently wound: every directed edge once, and its reverse once.
    let key = |p: Vec3| (p * 2.0).round().as_ivec3().to_array();
    let mut edges: HashMap<([i32; 3], [i32; 3]), usize> = HashMap::new();
    for t in &tris.items {
        for i in 0..3 {
            *edges
                .entry((key(t.p[i]), key(t.p[(i + 1) % 3])))
                .or_default() += 1;
        }
    }
    for (&(a, b), &n) in &edges {
        assert_eq!(n, 1, "edge {a:?}→{b:?} used {n} times");
        assert_eq!(edges.get(&(b, a)), Some(&1), "edge {a:?}→{b:?} is a border");
    }

    // Materials: the MTL's three, in order; faces by their normal's axis.
    assert_eq!(data.materials.len(), 3, "no default material needed");
    let red = Material {
        color: Vec3::new(0.8, 0.0, 0.0),
        ka: (0.1 / 3.0) / (0.8 / 3.0),
        kd: 1.0,
        ks: 0.3,
        shine: 50.0,
        kr: 0.0,
        t: 0.0,
        ior: 1.0,
        filter: Vec3::ONE,
        priority: 0,
        ..Material::DEFAULT
    };
    let m = &data.materials;
    assert!(close(m[0].color, red.color) && (m[0].ka - red.ka).abs() < 1e-6);
    assert_eq!(
        (m[0].kd, m[0].shine, m[0].kr, m[0].t),
        (1.0, 50.0, 0.0, 0.0)
    );
    assert!((m[0].ks - red.ks).abs() < 1e-6);
    // green: illum 1, no highlight; no Ka, so ka = 1.
    assert_eq!(m[1].color, Vec3::new(0.0, 0.6, 0.0));
    assert_eq!((m[1].ka, m[1].kd, m[1].ks, m[1].kr), (1.0, 1.0, 0.0, 0.0));
    // blue: illum 3, a mirror of mean(Ks).
    assert_eq!(m[2].color, Vec3::new(0.0, 0.0, 0.9));
    assert_eq!((m[2].ks, m[2].kr), (0.5, 0.5));
    for (t, &mat) in tris.items.iter().zip(&tris.material) {
        let n = normal(t);
        let expected = if n.z.abs() > 0.9 {
            0 // red: the z = 0 and z = 1 faces
        } else if n.y.abs() > 0.9 {
            1 // green
        } else {
            2 // blue: x faces
        };
        assert_eq!(mat, expected, "triangle {t:?} with normal {n}");
    }
}

// ---------------------------------------------------------------------------------
// Concave faces

#[test]
fn concave_l_face_is_ear_clipped_not_fanned() {
    // An L of area 3 listed from (2, 0): a fan from that vertex would cover area 4
    // (one of its triangles reversed, outside the L).
    let obj = "v 2 0 0\nv 2 1 0\nv 1 1 0\nv 1 2 0\nv 0 2 0\nv 0 0 0\nf 1 2 3 4 5 6\n";
    let (_dir, _path, r) = load_text(obj, &[]);
    let data = r.unwrap();
    let tris = &data.geometry.triangles.items;
    assert_eq!(tris.len(), 4);
    let total: f32 = tris.iter().map(area).sum();
    assert!((total - 3.0).abs() < 1e-5, "area {total}, not the L's 3");
    for t in tris {
        // The face's own winding (counterclockwise seen from +z) is kept.
        assert!(normal(t).z > 0.99, "{t:?}");
        // Nothing in the notch (1, 1)–(2, 2).
        let c = (t.p[0] + t.p[1] + t.p[2]) / 3.0;
        assert!(!(c.x > 1.0 && c.y > 1.0), "{t:?} is outside the L");
    }
    // No usemtl: the default material, without a warning.
    assert_eq!(data.materials, vec![DEFAULT_MATERIAL]);
    assert!(data.warnings.is_empty(), "{:?}", data.warnings);
}

// ---------------------------------------------------------------------------------
// Normals

/// The shading normal `geometry.surface` interpolates at barycentrics (u, v) of
/// triangle `i`.
fn shading_normal(data: &ObjData, i: usize, u: f32, v: f32) -> Vec3 {
    let t = &data.geometry.triangles.items[i];
    let hit = Hit {
        t: 1.0,
        geom_id: Kind::Triangle as u32,
        prim_id: i as u32,
        u,
        v,
        ng: (t.p[1] - t.p[0]).cross(t.p[2] - t.p[0]),
        inst_id: emray::accel::NO_INSTANCE,
    };
    let p = t.p[0] * (1.0 - u - v) + t.p[1] * u + t.p[2] * v;
    let ray = Ray::new(p + Vec3::Z, -Vec3::Z);
    data.geometry.surface(&hit, &ray).ns
}

#[test]
fn vertex_normals_are_kept_and_faces_without_them_are_flat() {
    let obj = "\
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
v 5 0 0
v 6 0 0
v 5 1 0
vn 0 0 1
vn 0.6 0 0.8
vn 0 -3 4
vn -1 1 1
# a smooth quad (v/vt/vn and v//vn forms), a flat triangle, a half-smooth one
vt 0 0
f 1/1/1 2/1/2 3//3 4//4
f 5 6 7
f 5//1 6//2 7
";
    let (_dir, _path, r) = load_text(obj, &[]);
    let data = r.unwrap();
    assert_eq!(data.geometry.triangles.len(), 4);
    let file_normals: HashMap<[i32; 3], Vec3> = [
        ([0, 0, 0], Vec3::new(0.0, 0.0, 1.0)),
        ([1, 0, 0], Vec3::new(0.6, 0.0, 0.8)),
        ([1, 1, 0], Vec3::new(0.0, -0.6, 0.8)),
        ([0, 1, 0], Vec3::new(-1.0, 1.0, 1.0).normalize()),
    ]
    .into_iter()
    .collect();
    let tn = &data.geometry.triangle_normals;
    for (i, &n) in tn.iter().enumerate().take(2) {
        assert_ne!(n, u32::MAX, "quad triangle {i} lost its normals");
        let t = data.geometry.triangles.items[i];
        // At each corner the interpolated normal is the file's (made unit length).
        for (k, (u, v)) in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)].into_iter().enumerate() {
            let key = t.p[k].round().as_ivec3().to_array();
            let want = file_normals[&key];
            let got = shading_normal(&data, i, u, v);
            assert!(close(got, want), "corner {:?}: {got} vs {want}", t.p[k]);
        }
        // Inside, it is not the flat normal.
        assert!(!close(shading_normal(&data, i, 0.3, 0.3), Vec3::Z));
    }
    assert_eq!(tn[2], u32::MAX, "a face without vn is flat");
    assert_eq!(
        tn[3],
        u32::MAX,
        "a face with vn on some vertices only is flat"
    );
    assert_eq!(shading_normal(&data, 2, 0.2, 0.2), Vec3::Z);
}

// ---------------------------------------------------------------------------------
// Materials

#[test]
fn missing_mtl_file_warns_and_faces_get_the_default_material() {
    let obj = "mtllib nothere.mtl\nusemtl shiny\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    let (_dir, path, r) = load_text(obj, &[]);
    let data = r.unwrap();
    assert_eq!(data.geometry.triangles.len(), 1);
    let m = data.geometry.triangles.material[0] as usize;
    assert_eq!(data.materials[m], DEFAULT_MATERIAL);
    assert_eq!(DEFAULT_MATERIAL.color, Vec3::splat(0.5));
    assert_eq!(DEFAULT_MATERIAL.kd, 1.0);
    let lib = data
        .warnings
        .iter()
        .find(|w| w.contains("nothere.mtl"))
        .unwrap_or_else(|| panic!("no warning names the library: {:?}", data.warnings));
    assert!(lib.starts_with(&format!("{}:1:", path.display())), "{lib}");
    assert!(
        data.warnings.iter().any(|w| w.contains("'shiny'")),
        "{:?}",
        data.warnings
    );
}

#[test]
fn missing_material_in_a_library_warns_once_per_name() {
    let mtl = "newmtl here\nKd 1 1 0\n";
    let obj = "mtllib lib.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\n\
               usemtl gone\nf 1 2 3\nusemtl here\nf 1 2 3\nusemtl gone\nf 1 3 2\n";
    let (_dir, path, r) = load_text(obj, &[("lib.mtl", mtl)]);
    let data = r.unwrap();
    let gone: Vec<_> = data
        .warnings
        .iter()
        .filter(|w| w.contains("'gone'"))
        .collect();
    assert_eq!(gone.len(), 1, "{:?}", data.warnings);
    assert!(
        gone[0].starts_with(&format!("{}:5:", path.display())),
        "{}",
        gone[0]
    );
    assert!(gone[0].contains("lib.mtl"), "{}", gone[0]);
    let mats: Vec<Material> = data
        .geometry
        .triangles
        .material
        .iter()
        .map(|&m| data.materials[m as usize])
        .collect();
    assert_eq!(mats[0], DEFAULT_MATERIAL);
    assert_eq!(mats[1].color, Vec3::new(1.0, 1.0, 0.0));
    assert_eq!(mats[2], DEFAULT_MATERIAL);
}

#[test]
fn usemtl_switches_assign_each_face_its_material() {
    let mtl = "newmtl a\nKd 1 0 0\n\nnewmtl b\nKd 0 0 1\n";
    // Switches within a group, across groups and objects, and back again.
    let obj = "\
mtllib two.mtl
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
usemtl a
f 1 2 3
usemtl b
f 1 3 4
f 1 2 4
g other
f 2 3 4
usemtl a
o thing
f 1 2 3 4
usemtl b
f 3 2 1
";
    let (_dir, _path, r) = load_text(obj, &[("two.mtl", mtl)]);
    let data = r.unwrap();
    assert!(data.warnings.is_empty(), "{:?}", data.warnings);
    let colours: Vec<Vec3> = data
        .geometry
        .triangles
        .material
        .iter()
        .map(|&m| data.materials[m as usize].color)
        .collect();
    let (red, blue) = (Vec3::X, Vec3::Z);
    // The quad (fifth face) is two triangles.
    assert_eq!(colours, vec![red, blue, blue, blue, red, red, blue]);
}

#[test]
fn mtl_mapping_of_glass_mirror_and_odd_statements() {
    let mtl = "\
# glass: illum 7, d and Ni
newmtl glass
Ka 0 0 0
Kd 0 0 0
Ks 0.9 0.9 0.9
Ns 200
Ni 1.5
d 0.25
illum 7
newmtl tr
Kd 0.5 0.5 0.5
Tr 0.4
Ni 0
newmtl grey1
Kd 0.7
Kd 0.1 0.2
map_Kd wood.png
illum 0
";
    let obj = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl glass\nf 1 2 3\n\
               usemtl tr\nf 1 2 3\nusemtl grey1\nf 1 2 3\n";
    let (_dir, _path, r) = load_text(obj, &[("m.mtl", mtl)]);
    let data = r.unwrap();
    let m = &data.materials;
    assert_eq!(m.len(), 3);
    let glass = m[0];
    assert_eq!(
        (glass.kd, glass.ka),
        (0.0, 1.0),
        "black Kd: colour carries Ka"
    );
    assert_eq!(glass.color, Vec3::ZERO);
    assert!((glass.ks - 0.9).abs() < 1e-6 && (glass.kr - 0.9).abs() < 1e-6);
    assert_eq!((glass.t, glass.ior, glass.shine), (0.75, 1.5, 200.0));
    // Tr = 1 − d; Ni 0 is unusable for a transparent material: ior 1 and a warning.
    assert!((m[1].t - 0.4).abs() < 1e-6);
    assert_eq!(m[1].ior, 1.0);
    assert!(
        data.warnings
            .iter()
            .any(|w| w.contains("'tr'") && w.contains("Ni 0"))
    );
    // `Kd 0.7` is grey 0.7; `Kd 0.1 0.2` is malformed and ignored with its line; the
    // texture file is missing (a warning); illum 0 turns the ambient term off.
    assert_eq!(m[2].color, Vec3::splat(0.7));
    assert_eq!((m[2].ka, m[2].ks), (0.0, 0.0));
    let w = data
        .warnings
        .iter()
        .find(|w| w.contains("m.mtl:16:"))
        .unwrap_or_else(|| panic!("{:?}", data.warnings));
    assert!(w.contains("statement ignored"), "{w}");
    assert!(data.warnings.iter().any(|w| w.contains("texture")));
}

// ---------------------------------------------------------------------------------
// Degenerate faces and lines

#[test]
fn degenerate_faces_are_dropped_and_counted() {
    let obj = "\
v 0 0 0
v 1 0 0
v 2 0 0
v 0 1 0
f 1 2 4
f 1 2 3
f 1 1 4
f 1 4
f 1 2 3 2
l 1 2 4
";
    let (_dir, path, r) = load_text(obj, &[]);
    let data = r.unwrap();
    assert_eq!(data.geometry.triangles.len(), 1);
    assert_eq!(data.stats.polygons, 5);
    assert_eq!(data.stats.degenerate_dropped, 4);
    let w = data
        .warnings
        .iter()
        .find(|w| w.contains("degenerate"))
        .unwrap();
    assert!(w.contains("dropped 4") && w.contains("line 6"), "{w}");
    assert!(w.starts_with(&path.display().to_string()), "{w}");
    assert!(data.warnings.iter().any(|w| w.contains("'l'")));
}

// ---------------------------------------------------------------------------------
// Errors

/// Assert that `obj` fails at `line:col` with a message containing `message`.
#[track_caller]
fn fails(obj: &str, line: usize, col: usize, message: &str) {
    let (_dir, path, r) = load_text(obj, &[]);
    match r {
        Ok(_) => panic!("expected an error for {obj:?}"),
        Err(e) => {
            assert_eq!(e.path, path, "for {obj:?}");
            assert_eq!((e.line, e.col), (line, col), "{e} for {obj:?}");
            assert!(e.message.contains(message), "{e} for {obj:?}");
            let shown = e.to_string();
            assert!(
                shown.starts_with(&format!("{}:{line}:{col}: ", path.display())),
                "{shown}"
            );
        }
    }
}

const TRI: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";

#[test]
fn malformed_files_are_errors_at_their_line() {
    // Bad numbers (reported unless a structural problem comes first).
    fails("v 0 0 0\nv 1 x 0\n", 2, 5, "expected vertex y, found 'x'");
    fails("v 0 0 0\nvn 0 0 1.5.2\n", 2, 8, "expected normal z");
    fails("vt 0.5 abc\n", 1, 8, "expected texture v");
    // A bad number before a bad face is the first error.
    fails("v 0 0 zero\nf 1 2 3\n", 1, 7, "expected vertex z");
    // Face indices.
    fails(&format!("{TRI}f 1 0 3\n"), 4, 5, "index 0 is invalid");
    fails(
        &format!("{TRI}f 1 2 4\n"),
        4,
        7,
        "vertex index 4 is out of range",
    );
    fails(
        &format!("{TRI}f -4 -2 -1\n"),
        4,
        3,
        "reaches before the first vertex",
    );
    fails(
        &format!("{TRI}vn 0 0 1\nf 1//1 2//2 3//1\n"),
        5,
        8,
        "normal index 2",
    );
    fails(
        &format!("{TRI}f 1 2 3.5\n"),
        4,
        7,
        "expected a vertex index",
    );
    fails(
        &format!("{TRI}f 1 2/1/1/1 3\n"),
        4,
        5,
        "more than 3 indices",
    );
    fails(
        &format!("{TRI}f 1 2 3 # tri\n"),
        4,
        9,
        "comments must be on a line",
    );
    // Truncated lines.
    fails(
        "v 0 0 0\nv 1 2\n",
        2,
        6,
        "expected 3 vertex coordinates (x y z), found 2",
    );
    fails(&format!("{TRI}f\n"), 4, 2, "face without vertices");
    fails(
        &format!("{TRI}vn 1 0\n"),
        4,
        7,
        "expected 3 normal components",
    );
    fails(&format!("{TRI}usemtl\nf 1 2 3\n"), 4, 7, "material name");
    // Non-finite coordinates, parsed or overflowing.
    fails(
        "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n",
        2,
        3,
        "not a finite number",
    );
    fails(
        "v 0 0 0\nv 1e39 0 0\nv 0 1 0\nf 1 2 3\n",
        2,
        3,
        "not a finite number",
    );
    fails(
        &format!("{TRI}vn 0 inf 0\nf 1//1 2//1 3//1\n"),
        4,
        6,
        "not a finite number",
    );
    fails("v 1 0 0 0\n", 1, 9, "weight w is 0");
    // Five numbers in a vertex.
    fails("v 1 2 3 4 5\n", 1, 9, "found 5 numbers");
}

#[test]
fn forward_references_within_the_file_are_accepted() {
    // Indices are checked when a run of faces ends (at `g`, `o`, a `usemtl` that
    // changes the material, or the end of the file), so a face may name a vertex
    // defined after it in its run. An index beyond the whole file is an error at its
    // line; one beyond its run, an error for the whole file.
    let (_dir, _path, r) = load_text("f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n", &[]);
    assert_eq!(r.unwrap().geometry.triangles.len(), 1);
    fails(
        "f 1 2 3\nf 1 2 9\nv 0 0 0\nv 1 0 0\nv 0 1 0\n",
        2,
        7,
        "index 9",
    );
    let (_dir, path, r) = load_text("f 1 2 3\ng next\nv 0 0 0\nv 1 0 0\nv 0 1 0\n", &[]);
    let e = r.unwrap_err();
    assert_eq!((e.path, e.line), (path, 0));
    assert_eq!(
        e.message,
        "malformed OBJ file (face vertex index out of bounds)"
    );
}

#[test]
fn missing_file_is_an_error_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("absent.obj");
    let e = load_geometry(&path).unwrap_err();
    assert_eq!(e.path, path);
    assert_eq!(e.line, 0);
    assert!(e.message.starts_with("cannot read"), "{e}");
    assert!(e.to_string().contains("absent.obj"));
    let e = load(&path).unwrap_err();
    assert_eq!(e.path, path);
}

#[test]
fn a_model_without_faces_has_nothing_to_frame() {
    let (_dir, path, _) = load_text(TRI, &[]);
    let e = load(&path).unwrap_err();
    assert_eq!((e.path.as_path(), e.line), (path.as_path(), 0));
    assert!(e.message.contains("no faces"), "{e}");
}

// ---------------------------------------------------------------------------------
// Whole scenes

#[test]
fn load_path_dispatches_on_the_obj_extension_in_any_case() {
    let dir = dir_with(&[("Cube.OBJ", CUBE_OBJ), ("cube.mtl", CUBE_MTL)]);
    let scene = load_path(&dir.path().join("Cube.OBJ")).unwrap();
    assert_eq!(scene.geometry.triangles.len(), 12);
    assert_eq!(scene.materials.len(), 3);
    assert_eq!(scene.lights.len(), 1);
    assert_eq!(scene.camera.width, AUTO_RESOLUTION);
    assert_eq!(scene.load_stats.polygons, 6);
    // The same text under another name is read as NFF, which refuses it.
    let dir = dir_with(&[("cube.nff", CUBE_OBJ)]);
    let e = load_path(&dir.path().join("cube.nff")).unwrap_err();
    assert!(e.message.contains("unknown entity"), "{e}");
}

#[test]
fn automatic_camera_sees_the_whole_model() {
    // A long box far from the origin.
    let (lo, hi) = (Vec3::new(10.0, -3.0, 5.0), Vec3::new(14.0, 9.0, 6.0));
    let mut obj = String::new();
    for i in 0..8 {
        let p = Vec3::new(
            if i & 1 == 0 { lo.x } else { hi.x },
            if i & 2 == 0 { lo.y } else { hi.y },
            if i & 4 == 0 { lo.z } else { hi.z },
        );
        obj += &format!("v {} {} {}\n", p.x, p.y, p.z);
    }
    obj += "f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n";
    let dir = dir_with(&[("box.obj", &obj)]);
    let scene = load(&dir.path().join("box.obj")).unwrap();
    let c = scene.camera;
    assert_eq!(c.angle_deg, AUTO_FOV_DEG);
    assert_eq!((c.width, c.height), (512, 512));
    assert!(
        scene.to_world(c.from).z > hi.z as f64,
        "camera on the +z side"
    );
    assert!(c.from.y > c.at.y, "camera above the centre");
    // The model alone is re-centred: its centre is the frame's origin.
    assert!((scene.origin - ((lo + hi) * 0.5).as_dvec3()).length() < 1e-6);
    assert!(close(c.at, Vec3::ZERO));

    // The camera's basis, as the eye rays are built.
    let forward = (c.at - c.from).normalize();
    let right = forward.cross(c.up).normalize();
    let up = right.cross(forward);
    let tan_half = (c.angle_deg.to_radians() * 0.5).tan();
    let mut widest: f32 = 0.0;
    for i in 0..8 {
        let p = Vec3::new(
            if i & 1 == 0 { lo.x } else { hi.x },
            if i & 2 == 0 { lo.y } else { hi.y },
            if i & 4 == 0 { lo.z } else { hi.z },
        );
        let v = (p.as_dvec3() - scene.origin).as_vec3() - c.from;
        let z = v.dot(forward);
        assert!(z > 0.0, "corner {p} behind the camera");
        let (x, y) = (v.dot(right) / z, v.dot(up) / z);
        assert!(
            x.abs() <= tan_half && y.abs() <= tan_half,
            "corner {p} out of view"
        );
        widest = widest.max(x.abs()).max(y.abs());
    }
    // And the model is not lost in the distance: it fills a good part of the view.
    assert!(widest > 0.5 * tan_half, "{widest} vs {tan_half}");

    // One white light near the camera, up and to the left.
    assert_eq!(scene.lights.len(), 1);
    let l = scene.lights[0];
    assert_eq!(l.color, Vec3::ONE);
    let d = l.pos - c.from;
    assert!(
        d.dot(up) > 0.0 && d.dot(right) < 0.0,
        "light at {d} from the eye"
    );
    assert!(
        d.length() < (c.at - c.from).length(),
        "light near the camera"
    );
}

#[test]
fn frame_refuses_empty_bounds() {
    assert!(frame(&Aabb::EMPTY).is_none());
    assert!(frame(&Aabb::INFINITE).is_none());
    let point = Aabb::from_points(Vec3::ONE, Vec3::ONE);
    assert!(frame(&point).is_none());
}

#[test]
fn a_large_grid_loads_every_triangle() {
    // 200 × 200 quads sharing vertices, with normals: 80 000 smooth triangles.
    let n = 200;
    let mut obj = String::new();
    for j in 0..=n {
        for i in 0..=n {
            obj += &format!("v {i} {j} 0\n");
        }
    }
    obj += "vn 0 0 1\n";
    for j in 0..n {
        for i in 0..n {
            let a = j * (n + 1) + i + 1;
            obj += &format!("f {a}//1 {}//1 {}//1 {}//1\n", a + 1, a + n + 2, a + n + 1);
        }
    }
    let dir = dir_with(&[("grid.obj", &obj)]);
    let data = ok(&dir.path().join("grid.obj"));
    assert_eq!(data.geometry.triangles.len(), 2 * n * n);
    assert_eq!(data.geometry.vertex_normals.len(), 2 * n * n);
    let total: f32 = data.geometry.triangles.items.iter().map(area).sum();
    assert!((total - (n * n) as f32).abs() < 1e-2, "{total}");
    assert_eq!(
        data.bounds,
        Aabb::from_points(Vec3::ZERO, Vec3::new(n as f32, n as f32, 0.0))
    );
}

#[test]
fn several_libraries_on_one_line_and_usemtl_before_mtllib() {
    let obj = "usemtl late\nmtllib a.mtl b.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\n\
               f 1 2 3\nusemtl early\nf 1 3 2\n";
    let a = "newmtl early\nKd 0 1 0\n";
    let b = "newmtl late\nKd 1 0 0\n";
    let (_dir, _path, r) = load_text(obj, &[("a.mtl", a), ("b.mtl", b)]);
    let data = r.unwrap();
    assert!(data.warnings.is_empty(), "{:?}", data.warnings);
    let colours: Vec<Vec3> = data
        .geometry
        .triangles
        .material
        .iter()
        .map(|&m| data.materials[m as usize].color)
        .collect();
    assert_eq!(colours, [Vec3::X, Vec3::Y]);
}

#[test]
fn crlf_line_endings_and_latin1_comments() {
    let crlf = CUBE_OBJ.replace('\n', "\r\n");
    let dir = dir_with(&[("cube.obj", &crlf), ("cube.mtl", CUBE_MTL)]);
    let mut bytes = std::fs::read(dir.path().join("cube.obj")).unwrap();
    bytes.extend_from_slice(b"# caf\xe9\r\nv 0 0 x\r\n");
    std::fs::write(dir.path().join("cube.obj"), &bytes).unwrap();
    let e = load_geometry(&dir.path().join("cube.obj")).unwrap_err();
    // Line numbers survive both: the bad vertex is on the last line.
    let last = CUBE_OBJ.lines().count() + 2;
    assert_eq!((e.line, e.col), (last, 7), "{e}");
    bytes.truncate(bytes.len() - b"v 0 0 x\r\n".len());
    std::fs::write(dir.path().join("cube.obj"), &bytes).unwrap();
    let data = ok(&dir.path().join("cube.obj"));
    assert_eq!(data.geometry.triangles.len(), 12);
    assert!(data.warnings.is_empty(), "{:?}", data.warnings);
}

/// A UTF-8 byte-order mark before the first statement of an OBJ or MTL file is
/// skipped: the first vertex and the first material are kept, and the indices do not
/// shift.
#[test]
fn byte_order_marks_are_skipped_in_obj_and_mtl_files() {
    let bom = "\u{feff}";
    let obj =
        format!("{bom}v 0 0 0\nv 1 0 0\nv 0 1 0\nv 5 5 5\nmtllib lib.mtl\nusemtl red\nf 1 2 3\n");
    let mtl = format!("{bom}newmtl red\nKd 1 0 0\n");
    let (_dir, _path, r) = load_text(&obj, &[("lib.mtl", &mtl)]);
    let data = r.unwrap();
    assert!(data.warnings.is_empty(), "{:?}", data.warnings);
    assert_eq!(data.geometry.triangles.len(), 1);
    assert_eq!(
        data.geometry.triangles.items[0].p,
        [Vec3::ZERO, Vec3::X, Vec3::Y]
    );
    let m = data.geometry.triangles.material[0] as usize;
    assert_eq!(data.materials[m].color, Vec3::X);
}

/// A gzip-compressed OBJ file is refused, naming the file; a compressed material
/// library is a warning that says so.
#[test]
fn compressed_obj_and_mtl_files_are_named_as_such() {
    let gzip = b"\x1F\x8B\x08\x00\x00\x00\x00\x00";
    let obj = "mtllib lib.mtl\nusemtl red\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    let dir = dir_with(&[("model.obj", obj)]);
    std::fs::write(dir.path().join("lib.mtl"), gzip).unwrap();
    let data = ok(&dir.path().join("model.obj"));
    assert!(
        data.warnings
            .iter()
            .any(|w| w.contains("lib.mtl") && w.contains("gzip-compressed")),
        "{:?}",
        data.warnings
    );
    let path = dir.path().join("model.obj");
    std::fs::write(&path, gzip).unwrap();
    let e = load_geometry(&path).unwrap_err();
    assert!(
        e.to_string().starts_with(&format!(
            "{}: the file is gzip-compressed: decompress it first",
            path.display()
        )),
        "{e}"
    );
}

/// Positions are read in double precision and a model rendered alone is re-centred on
/// the centre of its bounds: the same model a million units away loads into the same
/// single-precision triangles, where single precision alone would have kept about a
/// tenth of a unit.
#[test]
fn far_models_keep_their_detail() {
    let model = |s: f64| {
        let mut obj = String::new();
        for (x, y, z) in [
            (0.1, 0.2, 0.3),
            (1.3, 0.2, 0.3),
            (0.7, 1.1, 0.35),
            (0.7, 0.5, 1.2),
        ] {
            obj += &format!("v {:?} {:?} {:?}\n", x + s, y - s, z + s);
        }
        obj + "f 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n"
    };
    let dir = dir_with(&[("near.obj", &model(0.0)), ("far.obj", &model(1e6))]);
    let a = load(&dir.path().join("near.obj")).unwrap();
    let b = load(&dir.path().join("far.obj")).unwrap();
    assert!((b.origin - a.origin - glam::DVec3::new(1e6, -1e6, 1e6)).length() < 1e-6);
    assert_eq!(a.camera, b.camera);
    assert_eq!(a.lights, b.lights);
    for (ta, tb) in a
        .geometry
        .triangles
        .items
        .iter()
        .zip(&b.geometry.triangles.items)
    {
        for k in 0..3 {
            let d = (ta.p[k] - tb.p[k]).abs().max_element();
            assert!(d < 1e-6, "{} {}", ta.p[k], tb.p[k]);
        }
    }
}
