//! NFF loader tests through the public API. Every scene is written inline; the ignored
//! test at the end checks the SPD files in `../shared/spd` when they are present.

use emray::geometry::Kind;
use emray::geometry::polygon::newell_normal;
use emray::load::{LoadError, load_path, nff::parse_str};
use emray::math::Vec3;
use emray::scene::{Material, Scene, default_light_intensity};
use std::path::Path;

/// A viewpoint block, as the SPD programs write it.
const V: &str = "v\nfrom 0 0 -10\nat 0 0 0\nup 0 1 0\nangle 45\nhither 1\nresolution 64 48\n";

/// Parse in the world's frame (origin 0), so that the scene holds the file's own
/// coordinates; `frame_is_the_eye` checks the default frame.
fn parse(src: &str) -> Result<Scene, LoadError> {
    emray::load::nff::parse_str_at(src, Path::new("test.nff"), glam::DVec3::ZERO)
}

fn ok(src: &str) -> Scene {
    parse(src).unwrap_or_else(|e| panic!("unexpected error: {e}"))
}

/// Assert that `src` fails at `line:col` with exactly `message`.
#[track_caller]
fn fails(src: &str, line: usize, col: usize, message: &str) {
    match parse(src) {
        Ok(_) => panic!("expected an error for {src:?}"),
        Err(e) => {
            assert_eq!(
                (e.line, e.col, e.message.as_str()),
                (line, col, message),
                "for {src:?}"
            );
            assert_eq!(e.path, Path::new("test.nff"));
        }
    }
}

// ---------------------------------------------------------------------------------
// Entities

#[test]
fn viewpoint() {
    let s = ok(V);
    let c = s.camera;
    assert_eq!(c.from, Vec3::new(0.0, 0.0, -10.0));
    assert_eq!(c.at, Vec3::ZERO);
    assert_eq!(c.up, Vec3::Y);
    assert_eq!(c.angle_deg, 45.0);
    assert_eq!(c.hither, 1.0);
    assert_eq!((c.width, c.height), (64, 48));
    assert_eq!(s.prim_count_with_instances(), 0);
    assert!(s.lights.is_empty());
    assert!(s.materials.is_empty());
}

#[test]
fn viewpoint_on_one_line_and_up_not_unit() {
    let s = ok("v from 1 2 3 at 4 5 6 up 0 0 7 angle 30.5 hither 0.001 resolution 512 256");
    assert_eq!(s.camera.from, Vec3::new(1.0, 2.0, 3.0));
    assert_eq!(s.camera.at, Vec3::new(4.0, 5.0, 6.0));
    assert_eq!(s.camera.up, Vec3::new(0.0, 0.0, 7.0));
    assert_eq!(s.camera.angle_deg, 30.5);
    assert_eq!((s.camera.width, s.camera.height), (512, 256));
}

#[test]
fn second_viewpoint_replaces_first() {
    let src = format!("{V}v from 1 1 1 at 0 0 0 up 0 0 1 angle 60 hither 0 resolution 8 8\n");
    let s = ok(&src);
    assert_eq!(s.camera.from, Vec3::ONE);
    assert_eq!(s.camera.angle_deg, 60.0);
    assert_eq!(s.camera.width, 8);
}

#[test]
fn background_and_lights_before_the_viewpoint() {
    let s = ok(&format!("b 0.1 0.2 0.3\nl 1 2 3\n{V}"));
    assert_eq!(s.background, Vec3::new(0.1, 0.2, 0.3));
    assert_eq!(s.lights.len(), 1);
    assert_eq!(s.lights[0].pos, Vec3::new(1.0, 2.0, 3.0));
    assert_eq!(s.lights[0].color, Vec3::splat(0.5));
}

#[test]
fn background_defaults_to_black() {
    assert_eq!(ok(V).background, Vec3::ZERO);
}

#[test]
fn lights_without_colour_share_the_spd_intensity() {
    let s = ok(&format!("{V}l 1 0 0\nl 0 1 0\nl 0 0 1\n"));
    let expect = 3f32.sqrt() / 6.0;
    assert_eq!(default_light_intensity(3), expect);
    assert_eq!(s.lights.len(), 3);
    for l in &s.lights {
        assert_eq!(l.color, Vec3::splat(expect));
    }
    assert_eq!(s.ambient, Vec3::splat(expect));
}

#[test]
fn lights_with_colour_keep_it() {
    // The colour is optional: `l` followed directly by another entity on the same
    // line, a coloured light, and an uncoloured one at the very end of the file.
    let s = ok(&format!(
        "{V}l 1 2 3 s 0 0 0 1\nl 4 5 6 0.25 0.5 1\nl 7 8 9"
    ));
    assert_eq!(s.lights.len(), 3);
    assert_eq!(s.geometry.spheres().len(), 1);
    let d = default_light_intensity(3);
    assert_eq!(s.lights[0].color, Vec3::splat(d));
    assert_eq!(s.lights[1].pos, Vec3::new(4.0, 5.0, 6.0));
    assert_eq!(s.lights[1].color, Vec3::new(0.25, 0.5, 1.0));
    assert_eq!(s.lights[2].pos, Vec3::new(7.0, 8.0, 9.0));
    assert_eq!(s.lights[2].color, Vec3::splat(d));
    assert_eq!(s.ambient, Vec3::splat(d));
}

#[test]
fn light_colour_spread_over_lines() {
    let s = ok(&format!("{V}l 1 2 3\n0.5\n0.5 0.5\n"));
    assert_eq!(s.lights[0].color, Vec3::splat(0.5));
    assert_eq!(s.lights.len(), 1);
}

#[test]
fn materials_and_default_material() {
    let s = ok(&format!(
        "{V}s 0 0 0 1\nf 1 0.5 0.25 0.7 0.3 20 0.1 1.5\ns 1 0 0 1\nc 0 0 0 1 0 1 0 1\n"
    ));
    assert_eq!(s.materials.len(), 2);
    assert_eq!(s.materials[0], Material::default());
    let m = s.materials[1];
    assert_eq!(m.color, Vec3::new(1.0, 0.5, 0.25));
    assert_eq!(
        (m.ka, m.kd, m.ks, m.shine, m.t, m.ior),
        (0.7, 0.7, 0.3, 20.0, 0.1, 1.5)
    );
    assert_eq!(s.geometry.spheres().material, vec![0, 1]);
    assert_eq!(s.geometry.cones().material, vec![1]);
}

#[test]
fn no_default_material_when_f_comes_first() {
    let s = ok(&format!(
        "f 1 1 1 1 0 0 0 1\n{V}f 0 1 0 1 0 0 0 1\ns 0 0 0 1\n"
    ));
    assert_eq!(s.materials.len(), 2);
    assert_eq!(s.geometry.spheres().material, vec![1]);
}

#[test]
fn spheres_and_inside_only() {
    let s = ok(&format!("{V}s 1 2 3 4\ns -1 -2 -3 -0.5\n"));
    assert_eq!(s.count_with_instances(Kind::Sphere), 2);
    let a = s.geometry.spheres().items[0];
    assert_eq!(
        (a.center, a.radius, a.inside_only),
        (Vec3::new(1.0, 2.0, 3.0), 4.0, false)
    );
    let b = s.geometry.spheres().items[1];
    assert_eq!(
        (b.center, b.radius, b.inside_only),
        (Vec3::new(-1.0, -2.0, -3.0), 0.5, true)
    );
}

#[test]
fn cones_on_one_line_or_three() {
    let one = ok(&format!("{V}c 0 0 0 1 0 2 0 0.5\n"));
    let three = ok(&format!("{V}c\n0 0 0 1\n0 2 0 0.5\n"));
    let spread = ok(&format!(
        "{V}c 0\n0 # comment inside an entity\n0 1 0\n2\n0\n0.5"
    ));
    assert_eq!(one.geometry.cones(), three.geometry.cones());
    assert_eq!(one.geometry.cones(), spread.geometry.cones());
    let c = one.geometry.cones().items[0];
    assert_eq!(c.base, Vec3::ZERO);
    assert_eq!(c.apex, Vec3::new(0.0, 2.0, 0.0));
    assert_eq!(
        (c.base_radius, c.apex_radius, c.inside_only),
        (1.0, 0.5, false)
    );
    assert_eq!(c.height(), 2.0);
}

#[test]
fn cone_inside_only_and_pointed() {
    let s = ok(&format!("{V}c 0 0 0 -1 0 0 3 -1\nc 0 0 0 1 0 0 1 0\n"));
    let c = s.geometry.cones().items[0];
    assert!(c.inside_only);
    assert_eq!((c.base_radius, c.apex_radius), (1.0, 1.0));
    let p = s.geometry.cones().items[1];
    assert!(!p.inside_only);
    assert_eq!(p.apex_radius, 0.0);
}

#[test]
fn comments_everywhere() {
    let src = "# SPD file\n#comment without space\nb 0 0 0 # trailing\n\
               v # the viewpoint\nfrom 0 0 -10#glued\nat 0 0 0\nup 0 1 0\n\
               angle 45\n# in the middle\nhither 1\nresolution 64 48\n\
               s 0 0 0 1 # sphere\n#\n# s 9 9 9 9\n";
    let s = ok(src);
    assert_eq!(s.geometry.spheres().len(), 1);
    assert_eq!(s.camera.from, Vec3::new(0.0, 0.0, -10.0));
}

#[test]
fn crlf_and_tabs() {
    let src = V.replace('\n', "\r\n").replace(' ', "\t") + "s 0 0 0\r\n\t1\r\n";
    let s = ok(&src);
    assert_eq!(s.geometry.spheres().items[0].radius, 1.0);
    // Positions stay right with CR LF endings: the error is on line 9.
    let e = parse(&(V.replace('\n', "\r\n") + "s 0 0 0\r\n  x")).unwrap_err();
    assert_eq!((e.line, e.col), (9, 3));
}

#[test]
fn flat_polygons_keep_their_winding() {
    let s = ok(&format!(
        "{V}p 3\n0 0 0\n1 0 0\n0 1 0\np 4 0 0 1 1 0 1 1 1 1 0 1 1\n"
    ));
    assert_eq!(s.load_stats.polygons, 2);
    assert_eq!(s.geometry.triangles.len(), 3);
    assert_eq!(s.geometry.triangle_normals, vec![u32::MAX; 3]);
    assert!(s.geometry.vertex_normals.is_empty());
    for t in &s.geometry.triangles.items {
        // Counterclockwise seen from +z: the normal points to +z.
        let n = t.normal();
        assert!(n.z > 0.0 && n.x == 0.0 && n.y == 0.0, "{n:?}");
    }
    assert_eq!(
        s.geometry.triangles.items[0].p,
        [Vec3::ZERO, Vec3::X, Vec3::Y]
    );
    let area: f32 = s.geometry.triangles.items[1..]
        .iter()
        .map(|t| t.area())
        .sum();
    assert!((area - 1.0).abs() < 1e-6);
}

#[test]
fn clockwise_polygon_normal_points_the_other_way() {
    let s = ok(&format!("{V}p 4 0 0 0 0 1 0 1 1 0 1 0 0\n"));
    for t in &s.geometry.triangles.items {
        assert!(t.normal().z < 0.0);
    }
}

#[test]
fn patches_store_normalised_vertex_normals() {
    let s = ok(&format!(
        "{V}pp 3\n0 0 0 0 0 2\n1 0 0 0 3 4\n0 1 0 1 0 0\n\
         p 3 0 0 1 1 0 1 0 1 1\n\
         pp 4\n0 0 2 0 0 1\n1 0 2 0 0 1\n1 1 2 0 1 1\n0 1 2 1 1 1\n"
    ));
    assert_eq!(s.load_stats.polygons, 3);
    assert_eq!(s.geometry.triangles.len(), 4);
    assert_eq!(s.geometry.vertex_normals.len(), 3);
    assert_eq!(s.geometry.triangle_normals[0], 0);
    assert_eq!(s.geometry.triangle_normals[1], u32::MAX);
    assert_eq!(s.geometry.triangle_normals[2], 1);
    assert_eq!(s.geometry.triangle_normals[3], 2);
    assert_eq!(
        s.geometry.vertex_normals[0],
        [Vec3::Z, Vec3::new(0.0, 0.6, 0.8), Vec3::X]
    );
    // Each normal belongs to the vertex it was given with.
    for (t, k) in s
        .geometry
        .triangles
        .items
        .iter()
        .zip(&s.geometry.triangle_normals)
        .skip(2)
    {
        let n = s.geometry.vertex_normals[*k as usize];
        for (p, n) in t.p.iter().zip(n) {
            assert!((n.length() - 1.0).abs() < 1e-6);
            let given = match (p.x, p.y) {
                (0.0, 0.0) | (1.0, 0.0) => Vec3::Z,
                (1.0, 1.0) => Vec3::new(0.0, 1.0, 1.0).normalize(),
                _ => Vec3::ONE.normalize(),
            };
            assert!((n - given).length() < 1e-6, "{p:?}: {n:?}");
        }
    }
}

/// Even-odd point-in-polygon test in the xy plane.
fn inside_xy(poly: &[Vec3], p: Vec3) -> bool {
    let mut inside = false;
    for i in 0..poly.len() {
        let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
        if (a.y > p.y) != (b.y > p.y) && p.x < a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x) {
            inside = !inside;
        }
    }
    inside
}

/// Load one `p` polygon and check its triangles: winding kept (normal towards +z),
/// every centroid inside, area preserved.
fn check_concave(poly: &[Vec3]) -> usize {
    let mut src = format!("{V}p {}\n", poly.len());
    for p in poly {
        src += &format!("{} {} {}\n", p.x, p.y, p.z);
    }
    let s = ok(&src);
    let area = 0.5 * newell_normal(poly).length();
    let mut sum = 0.0f64;
    for t in &s.geometry.triangles.items {
        let n = t.normal();
        assert!(n.z > 0.0, "reversed triangle {t:?}");
        sum += 0.5 * n.as_dvec3().length();
        let c = (t.p[0] + t.p[1] + t.p[2]) / 3.0;
        assert!(inside_xy(poly, c), "triangle {t:?} outside the face");
    }
    assert!(((sum - area) / area).abs() < 1e-5, "{sum} vs {area}");
    s.geometry.triangles.len()
}

#[test]
fn concave_gear_face_is_triangulated_correctly() {
    // 144 vertices, like the SPD gears' faces: 36 teeth of 4 vertices.
    let mut poly = Vec::new();
    for t in 0..36 {
        for (da, r) in [(0.0, 0.8), (0.2, 1.0), (0.5, 1.0), (0.7, 0.8)] {
            let a = std::f32::consts::TAU * (t as f32 + da) / 36.0;
            poly.push(Vec3::new(r * a.cos(), r * a.sin(), 1.0));
        }
    }
    assert_eq!(check_concave(&poly), 142);
}

#[test]
fn concave_comb_is_triangulated_correctly() {
    // A bar with 8 teeth: the bar's corners see the teeth's roots inside their
    // triangles, so a fan or a blind corner cut would cover the gaps.
    let mut poly = vec![Vec3::ZERO, Vec3::new(15.0, 0.0, 0.0)];
    for t in (0..8).rev() {
        let x = 2.0 * t as f32;
        poly.extend([Vec3::new(x + 1.0, 3.0, 0.0), Vec3::new(x, 3.0, 0.0)]);
        if t > 0 {
            poly.extend([Vec3::new(x, 1.0, 0.0), Vec3::new(x - 1.0, 1.0, 0.0)]);
        }
    }
    assert!(check_concave(&poly) >= 8);
}

#[test]
fn degenerate_polygons_are_dropped_and_counted() {
    let s = ok(&format!(
        "{V}p 3 0 0 0 1 0 0 2 0 0\n\
         p 2 0 0 0 1 0 0\n\
         p 1 5 5 5\n\
         p 4 0 0 0 0 0 0 1 1 1 1 1 1\n\
         pp 3 0 0 0 0 0 1 1 0 0 0 0 1 2 0 0 0 0 1\n\
         p 3 0 0 0 1 0 0 0 1 0\n"
    ));
    assert_eq!(s.load_stats.polygons, 6);
    assert_eq!(s.load_stats.degenerate_dropped, 5);
    assert_eq!(s.geometry.triangles.len(), 1);
    assert_eq!(s.geometry.triangle_normals.len(), 1);
    assert!(s.geometry.vertex_normals.is_empty());
}

/// Captures log records for the tests that check warnings (records are told apart by
/// the file name in the message, as tests run in parallel).
struct Capture(std::sync::Mutex<Vec<String>>);

impl log::Log for Capture {
    fn enabled(&self, m: &log::Metadata) -> bool {
        m.level() <= log::Level::Warn
    }
    fn log(&self, r: &log::Record) {
        if self.enabled(r.metadata()) {
            self.0.lock().unwrap().push(r.args().to_string());
        }
    }
    fn flush(&self) {}
}

static CAPTURE: Capture = Capture(std::sync::Mutex::new(Vec::new()));

fn warnings_about(name: &str) -> Vec<String> {
    static INIT: std::sync::Once = std::sync::Once::new();
    INIT.call_once(|| {
        log::set_logger(&CAPTURE).unwrap();
        log::set_max_level(log::LevelFilter::Warn);
    });
    CAPTURE
        .0
        .lock()
        .unwrap()
        .iter()
        .filter(|m| m.contains(name))
        .cloned()
        .collect()
}

#[test]
fn degenerate_polygons_warn_once_per_file() {
    warnings_about("");
    let src = format!("{V}p 2 0 0 0 1 0 0\np 3 0 0 0 1 0 0 2 0 0\np 1 0 0 0\n");
    let s = parse_str(&src, Path::new("warn-once.nff")).unwrap();
    assert_eq!(s.load_stats.degenerate_dropped, 3);
    let w = warnings_about("warn-once.nff");
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(w[0].contains("dropped 3 degenerate polygon(s)"), "{}", w[0]);
    assert!(w[0].contains("the first at 8:1"), "{}", w[0]);
    // A clean file warns about nothing.
    parse_str(V, Path::new("no-warning.nff")).unwrap();
    assert!(warnings_about("no-warning.nff").is_empty());
}

/// Colours above 1 (a 0–255 scale by mistake) are a warning at the colour, for the
/// fill colour and the background; light colours (intensities) may exceed 1.
#[test]
fn colours_above_one_warn() {
    warnings_about("");
    let src = format!("b 0 0 300\n{V}l 0 5 0 2 2 2\nf 255 0 0 1 0 0 0 1\ns 0 0 0 1\n");
    parse_str(&src, Path::new("bytes.nff")).unwrap();
    let w = warnings_about("bytes.nff");
    assert_eq!(w.len(), 2, "{w:?}");
    assert!(
        w[0].contains("bytes.nff:1:3: the background colour 0 0 300"),
        "{}",
        w[0]
    );
    assert!(
        w[1].contains("bytes.nff:10:3: the fill colour 255 0 0"),
        "{}",
        w[1]
    );
    assert!(w[1].contains("0-255 scale"), "{}", w[1]);
    let src = format!("b 0 0 1\n{V}l 0 5 0 2 2 2\nf 1 0.5 0 1 0 0 0 1\ns 0 0 0 1\n");
    parse_str(&src, Path::new("unit.nff")).unwrap();
    assert!(warnings_about("unit.nff").is_empty());
}

#[test]
fn second_viewpoint_warns() {
    warnings_about("");
    let src = format!("{V}{V}");
    parse_str(&src, Path::new("two-views.nff")).unwrap();
    let w = warnings_about("two-views.nff");
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(
        w[0].starts_with("two-views.nff:8:1: a second viewpoint"),
        "{}",
        w[0]
    );
    // The first eye as the file gives it, in its coordinates and in NFF's terms.
    assert!(w[0].ends_with("(from 0 0 -10)"), "{}", w[0]);
}

#[test]
fn numbers_in_all_notations() {
    let s = ok(&format!("{V}s +1 -2. .5e1 1E-1\n"));
    let sp = s.geometry.spheres().items[0];
    assert_eq!(sp.center, Vec3::new(1.0, -2.0, 5.0));
    assert_eq!(sp.radius, 0.1);
    // Integral numbers are accepted for the resolution and vertex counts.
    let s = ok(
        "v from 0 0 1 at 0 0 0 up 0 1 0 angle 45 hither 1 resolution 32.0 16\np 3.0 0 0 0 1 0 0 0 1 0",
    );
    assert_eq!(s.camera.width, 32);
    assert_eq!(s.geometry.triangles.len(), 1);
}

#[test]
fn the_repository_scenes_load() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let mut n = 0;
    for e in std::fs::read_dir(dir).unwrap() {
        let path = e.unwrap().path();
        if path.extension().is_some_and(|x| x == "nff") {
            load_path(&path).unwrap_or_else(|e| panic!("{e}"));
            n += 1;
        }
    }
    assert!(n > 0);
}

#[test]
fn load_path_reads_a_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("scene.nff");
    std::fs::write(&path, format!("{V}s 0 0 0 1\n")).unwrap();
    let s = load_path(&path).unwrap();
    assert_eq!(s.geometry.spheres().len(), 1);
    // Errors name the file.
    std::fs::write(&path, format!("{V}s 0 0 0 0\n")).unwrap();
    let e = load_path(&path).unwrap_err();
    assert_eq!(e.path, path);
    assert_eq!(
        e.to_string(),
        format!("{}:8:9: sphere radius must not be zero", path.display())
    );
}

#[test]
fn bytes_that_are_not_utf8_in_comments_are_harmless() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("latin1.nff");
    let mut bytes = b"# caf\xe9\n".to_vec();
    bytes.extend_from_slice(V.as_bytes());
    bytes.extend_from_slice(b"s 0 0 0 1\n");
    std::fs::write(&path, bytes).unwrap();
    assert_eq!(load_path(&path).unwrap().geometry.spheres().len(), 1);
}

/// A UTF-8 byte-order mark at the start is skipped: the file reads as it does without
/// one, and positions on the first line count from the character after it.
#[test]
fn a_byte_order_mark_is_skipped() {
    let dir = tempfile::tempdir().unwrap();
    let plain = dir.path().join("plain.nff");
    let bom = dir.path().join("bom.nff");
    let src = format!("b 0 0 1\n{V}s 0 0 0 1\n");
    std::fs::write(&plain, &src).unwrap();
    std::fs::write(&bom, [b"\xEF\xBB\xBF", src.as_bytes()].concat()).unwrap();
    assert_eq!(load_path(&bom).unwrap(), load_path(&plain).unwrap());
    std::fs::write(&bom, b"\xEF\xBB\xBFx").unwrap();
    let e = load_path(&bom).unwrap_err();
    assert_eq!(
        (e.line, e.col, e.message.as_str()),
        (1, 1, "unknown entity 'x'")
    );
}

/// A gzip-compressed file (by its first bytes, whatever its name) and UTF-16 text are
/// refused with a message that says what they are.
#[test]
fn compressed_and_utf16_files_are_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let gzip = b"\x1F\x8B\x08\x00\x00\x00\x00\x00\x00\x03\x4B\x04\x00";
    for name in ["scene.nff.gz", "scene.nff"] {
        let path = dir.path().join(name);
        std::fs::write(&path, gzip).unwrap();
        let e = load_path(&path).unwrap_err();
        let shown = path.display().to_string();
        assert_eq!((e.line, e.col), (0, 0), "{e}");
        assert!(
            e.to_string().starts_with(&format!(
                "{shown}: the file is gzip-compressed: decompress it first ("
            )),
            "{e}"
        );
        assert!(e.message.contains(&format!("gunzip {shown}")), "{e}");
    }
    let path = dir.path().join("utf16.nff");
    let utf16: Vec<u8> = [0xFEFF_u16]
        .into_iter()
        .chain(format!("{V}s 0 0 0 1\n").encode_utf16())
        .flat_map(u16::to_le_bytes)
        .collect();
    std::fs::write(&path, utf16).unwrap();
    let e = load_path(&path).unwrap_err();
    assert_eq!(
        e.to_string(),
        format!(
            "{}: the file is UTF-16 text: save it as UTF-8",
            path.display()
        )
    );
}

// ---------------------------------------------------------------------------------
// Errors: each with its own message and position (line 8 is the first after `V`).

#[test]
fn error_missing_file() {
    let e = load_path(Path::new("/nonexistent/dir/scene.nff")).unwrap_err();
    assert_eq!((e.line, e.col), (0, 0));
    assert!(e.message.starts_with("cannot read: "), "{}", e.message);
    assert!(
        e.to_string()
            .starts_with("/nonexistent/dir/scene.nff: cannot read: "),
        "{e}"
    );
}

#[test]
fn error_missing_viewpoint() {
    let e = parse("b 0 0 0\ns 0 0 0 1\n").unwrap_err();
    assert_eq!((e.line, e.col), (0, 0));
    assert_eq!(e.to_string(), "test.nff: no viewpoint ('v') in file");
    assert_eq!(parse("").unwrap_err().message, "no viewpoint ('v') in file");
    assert_eq!(
        parse("# only\n").unwrap_err().message,
        "no viewpoint ('v') in file"
    );
}

#[test]
fn error_truncated() {
    fails(
        &format!("{V}s 0 0 0"),
        8,
        8,
        "unexpected end of file while reading the sphere radius",
    );
    // Trailing whitespace and comments do not move the position.
    fails(
        &format!("{V}c 0 0 0 1\n1 1 1 # no apex radius\n\n"),
        9,
        6,
        "unexpected end of file while reading the cone apex radius",
    );
    fails(
        &format!("{V}p 3\n0 0 0\n1 0 0\n"),
        10,
        6,
        "unexpected end of file while reading the polygon vertex x",
    );
    fails(
        "v from 0 0 1 at 0 0 0",
        1,
        22,
        "unexpected end of file while reading 'up' of the viewpoint",
    );
    fails(
        &format!("{V}f 1 1 1 0.5 0.5"),
        8,
        16,
        "unexpected end of file while reading the Phong exponent Shine",
    );
}

#[test]
fn error_non_numeric() {
    fails(
        &format!("{V}s 0 0 0 abc\n"),
        8,
        9,
        "expected the sphere radius, found 'abc'",
    );
    // A missing number runs into the next entity.
    fails(
        &format!("{V}s 0 0 1\ns 0 0 0 1\n"),
        9,
        1,
        "expected the sphere radius, found 's'",
    );
    fails(
        &format!("{V}l 1 2 3 0.5 0.5\ns 0 0 0 1\n"),
        9,
        1,
        "expected the light colour blue, found 's'",
    );
    fails(
        &format!("{V}b 0 0 1,0\n"),
        8,
        7,
        "expected the background blue, found '1,0'",
    );
}

#[test]
fn error_nan_and_inf() {
    fails(
        &format!("{V}s 0 nan 0 1\n"),
        8,
        5,
        "expected the sphere centre y, found 'nan' (not a finite number)",
    );
    fails(
        &format!("{V}l 1 1 1\n  inf 1 1\n"),
        9,
        3,
        "expected the light colour red, found 'inf' (not a finite number)",
    );
    fails(
        &format!("{V}f 1 1 1 0.5 0.5 -Infinity 0 1\n"),
        8,
        17,
        "expected the Phong exponent Shine, found '-Infinity' (not a finite number)",
    );
    // Too large for f32: overflows to infinity.
    fails(
        &format!("{V}p 3 0 0 0 1e39 0 0 0 1 0\n"),
        8,
        11,
        "expected the polygon vertex x, found '1e39' (not a finite number)",
    );
    fails(
        "v from 0 0 NaN",
        1,
        12,
        "expected the viewpoint 'from' z, found 'NaN' (not a finite number)",
    );
}

#[test]
fn error_unknown_entity_and_extra_numbers() {
    fails(&format!("{V}xyz 1 2 3\n"), 8, 1, "unknown entity 'xyz'");
    fails(&format!("{V}  S 0 0 0 1\n"), 8, 3, "unknown entity 'S'");
    fails(
        &format!("{V}s 0 0 0 1 2\n"),
        8,
        11,
        "expected an entity (v b l f c s p pp), found the number '2' \
         (too many numbers for the entity before it?)",
    );
    fails(
        &format!("{V}p 3 0 0 0 1 0 0 0 1 0 0\n"),
        8,
        23,
        "expected an entity (v b l f c s p pp), found the number '0' \
         (too many numbers for the entity before it?)",
    );
}

#[test]
fn error_polygon_counts() {
    fails(
        &format!("{V}p 0\n"),
        8,
        3,
        "polygon vertex count must be positive, found '0'",
    );
    fails(
        &format!("{V}pp -3\n"),
        8,
        4,
        "polygon vertex count must be positive, found '-3'",
    );
    fails(
        &format!("{V}p 2.5 0 0 0 1 1 1\n"),
        8,
        3,
        "expected the polygon vertex count (a whole number), found '2.5'",
    );
    fails(
        &format!("{V}p 1000000000\n0 0 0\n"),
        8,
        3,
        "polygon vertex count '1000000000' is absurd: the rest of the file has 7 bytes",
    );
    let huge = "9".repeat(44);
    fails(
        &format!("{V}p {huge}\n"),
        8,
        3,
        &format!(
            "polygon vertex count '{}…' is absurd: the rest of the file has 1 bytes",
            &huge[..40]
        ),
    );
    // The bound is tight enough not to refuse a compact but valid polygon.
    let s = ok(&format!("{V}p 3 0 0 0 1 0 0 0 1 0"));
    assert_eq!(s.geometry.triangles.len(), 1);
}

#[test]
fn error_zero_normal_in_patch() {
    fails(
        &format!("{V}pp 3\n0 0 0 0 0 1\n1 0 0 0 0 0\n0 1 0 0 0 1\n"),
        10,
        7,
        "vertex normal is zero",
    );
}

#[test]
fn error_sphere_radius() {
    fails(
        &format!("{V}s 0 0 0 0\n"),
        8,
        9,
        "sphere radius must not be zero",
    );
    fails(
        &format!("{V}s 0 0 0 -0.0\n"),
        8,
        9,
        "sphere radius must not be zero",
    );
}

#[test]
fn error_cone_radii_and_axis() {
    fails(
        &format!("{V}c 0 0 0 1\n0 0 1 -1\n"),
        9,
        7,
        "cone radii must both be ≥ 0, or both ≤ 0 for an inside-only cone, found base 1 and apex -1",
    );
    // A pointed inside-only cone: one radius negative, the other zero.
    let s = parse_str(&format!("{V}c 0 0 0 -1 0 0 1 0\n"), Path::new("t.nff")).unwrap();
    assert!(s.geometry.cones().items[0].inside_only);
    fails(
        &format!("{V}c 0 0 0 0 0 0 1 0\n"),
        8,
        17,
        "cone radii must not both be zero",
    );
    fails(
        &format!("{V}c 1 2 3 1\n1 2 3 1\n"),
        9,
        1,
        "cone apex equals its base",
    );
}

fn view(resolution: &str, angle: &str) -> String {
    format!(
        "v\nfrom 0 0 -10\nat 0 0 0\nup 0 1 0\nangle {angle}\nhither 1\nresolution {resolution}\n"
    )
}

#[test]
fn error_resolution() {
    fails(
        &view("0 512", "45"),
        7,
        12,
        "image width must be between 1 and 65536, found '0'",
    );
    fails(
        &view("512 -512", "45"),
        7,
        16,
        "image height must be between 1 and 65536, found '-512'",
    );
    fails(
        &view("100000 10", "45"),
        7,
        12,
        "image width must be between 1 and 65536, found '100000'",
    );
    fails(
        &view("30000 30000", "45"),
        7,
        12,
        "resolution 30000x30000 has 900000000 pixels, more than the 268435456 allowed",
    );
    fails(
        &view("512.5 512", "45"),
        7,
        12,
        "expected the image width (a whole number), found '512.5'",
    );
    let huge = "9".repeat(50);
    fails(
        &view(&format!("{huge} 2"), "45"),
        7,
        12,
        &format!(
            "image width must be between 1 and 65536, found '{}…'",
            &huge[..40]
        ),
    );
    // The largest allowed image is accepted (and nothing is allocated for it).
    let s = ok(&view("16384 16384", "45"));
    assert_eq!(s.camera.width, 16384);
    fails(
        &view("512", "45"),
        7,
        15,
        "unexpected end of file while reading the image height",
    );
}

#[test]
fn error_angle() {
    for a in ["0", "180", "-10", "400"] {
        fails(
            &view("8 8", a),
            5,
            7,
            &format!(
                "viewpoint angle must be between 0 and 180 degrees (exclusive), found {}",
                a.parse::<f32>().unwrap()
            ),
        );
    }
    assert_eq!(ok(&view("8 8", "179.5")).camera.angle_deg, 179.5);
}

#[test]
fn error_viewpoint_keywords_and_geometry() {
    fails(
        "v\nfrom 0 0 1\nup 0 1 0\n",
        3,
        1,
        "expected 'at' (viewpoint), found 'up'",
    );
    fails(
        "v from 0 0 1 at 0 0 0 up 0 1 0 angle 45 resolution 8 8",
        1,
        41,
        "expected 'hither' (viewpoint), found 'resolution'",
    );
    fails(
        "v s 0 0 0 1",
        1,
        3,
        "expected 'from' (viewpoint), found 's'",
    );
    fails(
        "v from 1 1 1 at 1 1 1 up 0 1 0 angle 45 hither 1 resolution 8 8",
        1,
        17,
        "viewpoint 'at' equals 'from'",
    );
    fails(
        "v from 0 0 1 at 0 0 0 up 0 0 5 angle 45 hither 1 resolution 8 8",
        1,
        26,
        "viewpoint 'up' is zero or parallel to the viewing direction",
    );
    fails(
        "v from 0 0 1 at 0 0 0 up 0 0 0 angle 45 hither 1 resolution 8 8",
        1,
        26,
        "viewpoint 'up' is zero or parallel to the viewing direction",
    );
    fails(
        "v from 0 0 1 at 0 0 0 up 0 1 0 angle 45 hither -1 resolution 8 8",
        1,
        48,
        "hither distance must not be negative, found -1",
    );
}

#[test]
fn error_display_format() {
    let e = parse(&format!("{V}s 0 0 0 abc\n")).unwrap_err();
    assert_eq!(
        e.to_string(),
        "test.nff:8:9: expected the sphere radius, found 'abc'"
    );
}

#[test]
fn error_column_counts_characters() {
    // A multi-byte character before the offending token on its line.
    let e = parse(&format!("{V}s 0 0 0 é")).unwrap_err();
    assert_eq!((e.line, e.col), (8, 9));
    let e = parse(&format!("{V}é")).unwrap_err();
    assert_eq!(e.message, "unknown entity 'é'");
}

// ---------------------------------------------------------------------------------
// The SPD files (run by hand: `cargo test --release --no-default-features --test nff
// -- --ignored --nocapture`; the folder is `$EMRAY_SPD_DIR`, else `../shared/spd`).

/// (file, spheres, cones, polygons read (p + pp), lights). The `_default` rows are
/// /work/shared/spd/README.md's table; the others are counts of entity keywords.
const SPD: &[(&str, usize, usize, usize, usize)] = &[
    ("balls_default", 7381, 0, 1, 3),
    ("gears_default", 0, 0, 9345, 5),
    ("jacks_s4", 3510, 1755, 0, 1),
    ("mount_default", 4, 0, 8192, 1),
    ("rings_default", 4200, 4200, 1, 3),
    ("teapot_default", 0, 0, 144 + 9120, 2),
    ("tetra_default", 0, 0, 4096, 1),
    ("tree_default", 4095, 4095, 1, 7),
    ("balls_s2", 91, 0, 1, 3),
    ("gears_s1", 0, 0, 147, 5),
    ("jacks_s2", 54, 27, 0, 1),
    ("lattice_s3", 64, 144, 0, 6),
    ("mount_s3", 4, 0, 128, 1),
    ("rings_s2", 150, 150, 1, 3),
    ("shells_s3", 1441, 0, 0, 1),
    ("sombrero_s1", 0, 0, 1922, 1),
    ("teapot_s2", 0, 0, 4 + 240, 2),
    ("tetra_s3", 0, 0, 64, 1),
    ("tree_s4", 31, 31, 1, 7),
];

/// Total area of the non-degenerate polygons of an NFF file, read independently of
/// the loader (whitespace split; no polygon keyword can be a number).
fn polygon_area(src: &str) -> f64 {
    let text: String = src
        .lines()
        .map(|l| l.split('#').next().unwrap())
        .collect::<Vec<_>>()
        .join("\n");
    let mut toks = text.split_whitespace();
    let mut area = 0.0;
    while let Some(t) = toks.next() {
        let per = match t {
            "p" => 3,
            "pp" => 6,
            _ => continue,
        };
        let n: usize = toks.next().unwrap().parse().unwrap();
        let mut pts = Vec::with_capacity(n);
        for _ in 0..n {
            let v: Vec<f32> = (0..per)
                .map(|_| toks.next().unwrap().parse().unwrap())
                .collect();
            pts.push(Vec3::new(v[0], v[1], v[2]));
        }
        area += 0.5 * newell_normal(&pts).length();
    }
    area
}

#[test]
#[ignore = "needs ../shared/spd; run by hand"]
fn spd_files_load_with_the_published_counts() {
    let dir = std::env::var_os("EMRAY_SPD_DIR")
        .map(std::path::PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/spd"));
    if !dir.is_dir() {
        eprintln!("{} not found: skipped", dir.display());
        return;
    }
    println!(
        "{:<16} {:>8} {:>8} {:>7} {:>7} {:>9} {:>6} {:>6} {:>9} {:>10}",
        "file",
        "bytes",
        "spheres",
        "cones",
        "polys",
        "triangles",
        "degen",
        "lights",
        "parse ms",
        "area err"
    );
    for &(name, spheres, cones, polys, lights) in SPD {
        let path = dir.join(format!("{name}.nff"));
        let bytes = std::fs::metadata(&path).unwrap().len();
        let src = std::fs::read_to_string(&path).unwrap();
        // Best of three parses from memory (the read is not the parser's cost).
        let mut best = f64::INFINITY;
        let mut scene = None;
        for _ in 0..3 {
            let t = std::time::Instant::now();
            let s = parse_str(&src, &path).unwrap_or_else(|e| panic!("{e}"));
            best = best.min(t.elapsed().as_secs_f64() * 1e3);
            scene = Some(s);
        }
        let s = scene.unwrap();
        assert_eq!(load_path(&path).unwrap(), s);
        assert_eq!(s.geometry.spheres().len(), spheres, "{name} spheres");
        assert_eq!(s.geometry.cones().len(), cones, "{name} cones");
        assert_eq!(s.load_stats.polygons, polys, "{name} polygons");
        assert_eq!(s.lights.len(), lights, "{name} lights");
        assert_eq!(
            s.geometry.triangle_normals.len(),
            s.geometry.triangles.len()
        );
        for t in &s.geometry.triangles.items {
            assert!(
                t.normal().length() > 0.0,
                "{name}: zero-normal triangle {t:?}"
            );
        }
        let tri_area: f64 = s
            .geometry
            .triangles
            .items
            .iter()
            .map(|t| t.normal().as_dvec3().length() * 0.5)
            .sum();
        let poly_area = polygon_area(&src);
        let rel = if poly_area > 0.0 {
            (tri_area - poly_area).abs() / poly_area
        } else {
            0.0
        };
        println!(
            "{name:<16} {bytes:>8} {:>8} {:>7} {:>7} {:>9} {:>6} {:>6} {best:>9.2} {rel:>10.2e}",
            s.geometry.spheres().len(),
            s.geometry.cones().len(),
            s.load_stats.polygons,
            s.geometry.triangles.len(),
            s.load_stats.degenerate_dropped,
            s.lights.len(),
        );
        if name.starts_with("gears") || name.starts_with("tetra") {
            // Planar polygons: the triangulation covers exactly their area.
            assert!(rel < 1e-5, "{name}: area off by {rel:e}");
        }
    }
}

/// Two vectors equal to within a relative 2⁻²² (an ulp or two of single precision).
fn same_f32(a: Vec3, b: Vec3) -> bool {
    (a - b).abs().max_element() <= 2.4e-7 * a.abs().max_element().max(b.abs().max_element())
}

/// The scene's frame has its origin at the eye, and points are read in double
/// precision: the same scene a million units away reads into the same numbers, where
/// single precision alone would have kept about a tenth of a unit.
#[test]
fn the_frame_is_the_eye_and_far_scenes_keep_their_detail() {
    let near = "v\nfrom 0.1 -5.3 1.7\nat 0 0 0.5\nup 0 0 1\nangle 40\nhither 0\n\
        resolution 8 8\nl 3 -2 5\ns 0.3 0.2 0.1 0.7\nc 0 0 0 0.2 0 0 1 0.1\n\
        p 3 0 0 0 1 0 0 0 1 0.3\n";
    let shift = glam::DVec3::new(1e6, -1e6, 1e6);
    let far = emray::accuracy::moved::move_nff(near, 1.0, shift).unwrap();
    let a = parse_str(near, Path::new("near.nff")).unwrap();
    let b = parse_str(&far, Path::new("far.nff")).unwrap();
    assert_eq!(a.origin, glam::DVec3::new(0.1, -5.3, 1.7));
    assert!((b.origin - (a.origin + shift)).abs().max_element() < 1e-9);
    assert_eq!((a.camera.from, b.camera.from), (Vec3::ZERO, Vec3::ZERO));
    assert!(same_f32(a.camera.at, b.camera.at));
    assert!(same_f32(a.camera.at, Vec3::new(-0.1, 5.3, -1.2)));
    assert!(same_f32(a.lights[0].pos, b.lights[0].pos));
    let (sa, sb) = (a.geometry.spheres().items[0], b.geometry.spheres().items[0]);
    assert!(
        same_f32(sa.center, sb.center),
        "{} {}",
        sa.center,
        sb.center
    );
    assert!(same_f32(sa.center, Vec3::new(0.2, 5.5, -1.6)));
    let (ca, cb) = (a.geometry.cones().items[0], b.geometry.cones().items[0]);
    assert!(same_f32(ca.base, cb.base) && same_f32(ca.apex, cb.apex));
    for k in 0..3 {
        let (pa, pb) = (
            a.geometry.triangles.items[0].p[k],
            b.geometry.triangles.items[0].p[k],
        );
        assert!(same_f32(pa, pb), "{pa} {pb}");
    }
    // World points come back through the origin.
    assert!((a.to_world(sa.center) - glam::DVec3::new(0.3, 0.2, 0.1)).length() < 1e-6);
}
