//! Textures, texture coordinates, bump and normal maps and environment maps: lookups
//! against hand-computed texels, the inverse bilinear map against random quads, the
//! bump normal against the analytic tilt, a mirror sphere against the environment
//! texel behind the camera, OBJ `vt`/MTL maps as documented, and backend agreement.

use emray::Hit;
use emray::accel::Accel;
use emray::accel::WithAccel;
use emray::geometry::{Kind, Primitive, Sphere, Triangle, inverse_bilinear};
use emray::job::render_scene;
use emray::load::obj::{MISSING_TEXTURE, load_geometry};
use emray::math::{Ray, Vec3};
use emray::render::RenderSettings;
use emray::scene::texture::{Image, NO_TEXTURE, Wrap, bump_normal, srgb_to_linear};
use emray::scene::{Camera, Environment, Light, Maps, Material, Scene, Texture};
use glam::Vec2;
use std::path::Path;
use std::sync::Arc;
use tempfile::TempDir;

mod common;
use common::backends;

/// A 3 × 2 image whose texel (i, j) is (i, j, 1) / 4: every texel distinct.
fn grid_image() -> Image {
    let mut t = Vec::new();
    for j in 0..2 {
        for i in 0..3 {
            t.push(Vec3::new(i as f32, j as f32, 1.0) / 4.0);
        }
    }
    Image::new(3, 2, t).unwrap()
}

fn close(a: Vec3, b: Vec3, tol: f32) -> bool {
    (a - b).abs().max_element() <= tol
}

#[test]
fn texel_centres_are_exact() {
    let img = grid_image();
    for j in 0..2 {
        for i in 0..3 {
            let uv = Vec2::new((i as f32 + 0.5) / 3.0, 1.0 - (j as f32 + 0.5) / 2.0);
            assert!(
                close(img.bilinear(uv), img.texel(i, j), 1e-6),
                "texel ({i}, {j}) at {uv}"
            );
        }
    }
}

#[test]
fn bilinear_between_texels() {
    let img = grid_image();
    // Halfway between the centres of (0, 0) and (1, 0): the mean.
    let uv = Vec2::new(1.0 / 3.0, 0.75);
    let want = (img.texel(0, 0) + img.texel(1, 0)) * 0.5;
    assert!(close(img.bilinear(uv), want, 1e-6));
    // A quarter of the way along both axes from (1, 0) to (2, 1).
    let uv = Vec2::new((1.5 + 0.25) / 3.0, 1.0 - (0.5 + 0.25) / 2.0);
    let (a, b, c, d) = (
        img.texel(1, 0),
        img.texel(2, 0),
        img.texel(1, 1),
        img.texel(2, 1),
    );
    let want = (a * 0.75 + b * 0.25) * 0.75 + (c * 0.75 + d * 0.25) * 0.25;
    assert!(close(img.bilinear(uv), want, 1e-6));
}

#[test]
fn wrap_modes_repeat_and_clamp() {
    let mut img = grid_image();
    let centre = |i: f32, j: f32| Vec2::new((i + 0.5) / 3.0, 1.0 - (j + 0.5) / 2.0);
    // Repeat: one period away is the same texel; the edge blends with the far side.
    assert!(close(
        img.bilinear(centre(0.0, 0.0) + Vec2::new(1.0, -2.0)),
        img.texel(0, 0),
        1e-6
    ));
    let edge = Vec2::new(0.0, 0.75);
    let want = (img.texel(2, 0) + img.texel(0, 0)) * 0.5;
    assert!(close(img.bilinear(edge), want, 1e-6));
    // Clamp: beyond the edge, the edge texel.
    img.wrap = Wrap::Clamp;
    assert!(close(img.bilinear(edge), img.texel(0, 0), 1e-6));
    assert!(close(
        img.bilinear(Vec2::new(5.0, -3.0)),
        img.texel(2, 1),
        1e-6
    ));
    assert_eq!(img.texel(-4, 9), img.texel(0, 1));
}

#[test]
fn checker_and_marble() {
    let c = Texture::Checker {
        a: Vec3::ONE,
        b: Vec3::ZERO,
        scale: 4.0,
    };
    assert_eq!(c.eval(Vec2::new(0.1, 0.1), Vec3::ZERO), Vec3::ONE);
    assert_eq!(c.eval(Vec2::new(0.3, 0.1), Vec3::ZERO), Vec3::ZERO);
    assert_eq!(c.eval(Vec2::new(-0.1, 0.1), Vec3::ZERO), Vec3::ZERO);
    let m = Texture::Marble {
        a: Vec3::ONE,
        b: Vec3::ZERO,
        scale: 3.0,
    };
    let vals: Vec<f32> = (0..200)
        .map(|i| m.eval(Vec2::ZERO, Vec3::new(i as f32 * 0.013, 0.2, -0.1)).x)
        .collect();
    assert!(vals.iter().all(|v| (0.0..=1.0).contains(v)));
    let spread =
        vals.iter().fold(0.0f32, |a, v| a.max(*v)) - vals.iter().fold(1.0f32, |a, v| a.min(*v));
    assert!(spread > 0.5, "veins vary: {spread}");
}

#[test]
fn inverse_bilinear_recovers_random_points_in_random_convex_quads() {
    let mut rng = emray::math::Rng::new(0x1234_5678_9abc_def0);
    let mut rnd = move || rng.next_f32();
    let mut tested = 0;
    while tested < 2000 {
        // A convex quad: four points at increasing angles around a centre, in a
        // random plane.
        let mut ang: Vec<f32> = (0..4).map(|_| rnd() * std::f32::consts::TAU).collect();
        ang.sort_by(f32::total_cmp);
        if ang.windows(2).any(|w| w[1] - w[0] < 0.3)
            || ang[0] + std::f32::consts::TAU - ang[3] < 0.3
        {
            continue;
        }
        let n = Vec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5).normalize_or(Vec3::Z);
        let f = emray::math::Frame::from_z(n);
        let o = Vec3::new(rnd(), rnd(), rnd()) * 10.0;
        let q: Vec<Vec3> = ang
            .iter()
            .map(|a| o + (f.x * a.cos() + f.y * a.sin()) * (0.5 + rnd()))
            .collect();
        let q = [q[0], q[1], q[2], q[3]];
        // Convexity check (all turns the same way).
        let turns: Vec<f32> = (0..4)
            .map(|k| {
                (q[(k + 1) % 4] - q[k])
                    .cross(q[(k + 2) % 4] - q[(k + 1) % 4])
                    .dot(n)
            })
            .collect();
        if !(turns.iter().all(|t| *t > 1e-3) || turns.iter().all(|t| *t < -1e-3)) {
            continue;
        }
        let (s, t) = (rnd(), rnd());
        let p = q[0] * ((1.0 - s) * (1.0 - t))
            + q[1] * (s * (1.0 - t))
            + q[2] * (s * t)
            + q[3] * ((1.0 - s) * t);
        let st =
            inverse_bilinear(p, q).unwrap_or_else(|| panic!("no solution for {s} {t} in {q:?}"));
        assert!(
            (st.x - s).abs() < 1e-5 && (st.y - t).abs() < 1e-5,
            "({s}, {t}) came back as {st} in {q:?}"
        );
        tested += 1;
    }
}

fn camera(from: Vec3, at: Vec3, w: u32) -> Camera {
    Camera {
        from,
        at,
        up: Vec3::Y,
        angle_deg: 30.0,
        hither: 0.0,
        width: w,
        height: w,
    }
}

#[test]
fn constant_slope_height_map_tilts_the_normal_by_the_analytic_angle() {
    // Heights rise linearly with the column: h = k·i/(W−1) at texel i, so between texel
    // centres dh/du = k·W/(W−1).
    let w = 16u32;
    let texels: Vec<Vec3> = (0..4)
        .flat_map(|_| (0..w).map(|i| Vec3::splat(i as f32 / (w - 1) as f32)))
        .collect();
    let img = Arc::new(Image::new(w, 4, texels).unwrap());
    let k = 0.3f32;
    let dh_du = k * w as f32 / (w - 1) as f32;
    // Direct: a plane with ∂p/∂u = 2x, ∂p/∂v = 2y.
    let n = bump_normal(
        &Texture::Image(img.clone()),
        k,
        Vec2::new(0.5, 0.5),
        Vec3::ZERO,
        Vec3::Z,
        Vec3::X * 2.0,
        Vec3::Y * 2.0,
    );
    let want = (dh_du / 2.0).atan();
    assert!((n.dot(Vec3::Z).acos() - want).abs() < 1e-5, "{n}");
    assert!(
        n.x < 0.0 && n.y.abs() < 1e-6,
        "tilted away from rising heights: {n}"
    );

    // Through the scene: a triangle with vt, the shading normal at a hit.
    let mut s = Scene::new(camera(Vec3::Z * 5.0, Vec3::ZERO, 8));
    s.textures.push(Texture::Image(img));
    s.materials.push(Material {
        maps: Maps {
            bump: 0,
            bump_scale: k,
            ..Maps::NONE
        },
        ..Material::DEFAULT
    });
    let tri = Triangle {
        p: [
            Vec3::ZERO,
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.0, 2.0, 0.0),
        ],
    };
    s.geometry.add_triangle(tri, 0);
    s.geometry
        .set_triangle_uvs(0, [Vec2::ZERO, Vec2::X, Vec2::Y]);
    let hit = Hit {
        t: 5.0,
        u: 0.25,
        v: 0.25,
        ng: Vec3::Z * 4.0,
        geom_id: Kind::Triangle as u32,
        prim_id: 0,
        inst_id: emray::accel::NO_INSTANCE,
    };
    let ray = Ray::new(Vec3::new(0.5, 0.5, 5.0), -Vec3::Z);
    let surf = s.surface(&hit, &ray);
    let prm = surf
        .param
        .expect("a bump-mapped material gets texture coordinates");
    assert!((prm.uv - Vec2::new(0.25, 0.25)).length() < 1e-6);
    let (_, ns) = s.shading(&surf);
    assert!((ns.dot(Vec3::Z).acos() - want).abs() < 1e-5, "{ns}");
}

#[test]
fn bump_at_the_sphere_poles_is_finite() {
    let sphere = Sphere::new(Vec3::ZERO, 1.0);
    let tex = Texture::Checker {
        a: Vec3::ONE,
        b: Vec3::ZERO,
        scale: 16.0,
    };
    for p in [Vec3::Y, -Vec3::Y] {
        let prm = sphere.param(p, p);
        let n = bump_normal(&tex, 0.05, prm.uv, p, p, prm.dpdu, prm.dpdv);
        assert!(n.is_finite() && (n.length() - 1.0).abs() < 1e-5, "{n}");
    }
}

/// A 6 × 3 latitude-longitude map: direction +x (u = 3/4, v = 1/2) falls exactly on the
/// centre of texel (4, 1).
fn env_grid() -> Image {
    let mut t = Vec::new();
    for j in 0..3 {
        for i in 0..6 {
            t.push(Vec3::new(i as f32 / 5.0, j as f32 / 2.0, 0.5));
        }
    }
    Image::new(6, 3, t).unwrap()
}

fn mirror_scene(from: Vec3, env: Environment) -> Scene {
    let mut s = Scene::new(camera(from, Vec3::ZERO, 5));
    s.ambient = Vec3::ZERO;
    s.materials.push(Material {
        ka: 0.0,
        kd: 0.0,
        kr: 1.0,
        ..Material::DEFAULT
    });
    s.geometry.add_shape(
        emray::geometry::Shape::Sphere(Sphere::new(Vec3::ZERO, 1.0)),
        0,
    );
    s.environment = Some(env);
    s
}

#[test]
fn mirror_sphere_centre_pixel_shows_the_texel_behind_the_camera() {
    let img = env_grid();
    let want = img.texel(4, 1);
    let s = mirror_scene(Vec3::X * 6.0, Environment::from_image(img.clone()).unwrap());
    // A cube cross whose +z face is one colour: seen from +z, the centre pixel.
    let f = 4u32;
    let mut cross = Vec::new();
    for y in 0..3 * f {
        for x in 0..4 * f {
            let face = (x / f, y / f);
            cross.push(match face {
                (3, 1) => Vec3::new(0.9, 0.2, 0.1),
                (1, 1) => Vec3::new(0.0, 0.0, 1.0),
                _ => Vec3::splat(0.3),
            });
        }
    }
    let cube = Environment::from_image(Image::new(4 * f, 3 * f, cross).unwrap()).unwrap();
    let s2 = mirror_scene(Vec3::Z * 6.0, cube);
    for b in backends() {
        let film = render_scene("t", &s, b, &RenderSettings::for_scene(&s), 0.0, None)
            .unwrap()
            .0;
        let got = film.get(2, 2);
        assert!(close(got, want, 1e-5), "{b:?}: {got} vs texel {want}");
        // A pixel off the sphere sees the map straight ahead (direction −x: u = 1/4).
        let corner = film.get(0, 0);
        assert_ne!(corner, got);
        let film = render_scene("t", &s2, b, &RenderSettings::for_scene(&s2), 0.0, None)
            .unwrap()
            .0;
        assert!(
            close(film.get(2, 2), Vec3::new(0.9, 0.2, 0.1), 1e-5),
            "{b:?}"
        );
    }
}

/// Face colours of the six-file cube map (+x, −x, +y, −y, +z, −z), sRGB bytes.
const FACE_COLOURS: [[u8; 3]; 6] = [
    [250, 30, 30],
    [30, 250, 30],
    [30, 30, 250],
    [250, 250, 30],
    [30, 250, 250],
    [250, 30, 250],
];
/// The −z face's outer quadrants: top-left, top-right, bottom-left, bottom-right.
const NZ_QUADRANTS: [[u8; 3]; 4] = [[120, 0, 0], [0, 120, 0], [0, 0, 120], [120, 120, 0]];

fn linear(c: [u8; 3]) -> Vec3 {
    Vec3::from(c.map(|v| srgb_to_linear(f32::from(v) / 255.0)))
}

/// A six-file cube map, each face 16 × 16 in its colour; on the −z face only the
/// central 4 × 4 texels, the rest being one colour per quadrant (to check the face's
/// orientation). `ext` per face.
fn write_cube(dir: &Path, ext: [&str; 6]) {
    for (k, name) in emray::scene::texture::CUBE_FACES.iter().enumerate() {
        write_png(&dir.join(format!("{name}.{}", ext[k])), 16, 16, |x, y| {
            let centre = (6..10).contains(&x) && (6..10).contains(&y);
            if k == 5 && !centre {
                NZ_QUADRANTS[usize::from(y >= 8) * 2 + usize::from(x >= 8)]
            } else {
                FACE_COLOURS[k]
            }
        });
    }
}

/// A mirror sphere in a six-file cube map, seen from each axis: its centre pixel shows
/// the face straight behind the camera; the background seen along −z shows the −z
/// face upright (+y up, +x right). The same cube map from a directory (`--envmap DIR`,
/// `[render] environment`), from MTL `refl -type cube_*`, on both backends.
#[test]
fn six_file_cube_map_faces_are_seen_in_their_directions() {
    let dir = TempDir::new().unwrap();
    let sky = dir.path().join("sky");
    std::fs::create_dir(&sky).unwrap();
    write_cube(&sky, ["png"; 6]);
    let env = Environment::load(&sky).unwrap();
    let axes = [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z];
    for (k, a) in axes.into_iter().enumerate() {
        let mut s = mirror_scene(a * 6.0, env.clone());
        s.camera.angle_deg = 60.0;
        if a.y != 0.0 {
            s.camera.up = Vec3::Z;
        }
        for b in backends() {
            let film = render_scene("t", &s, b, &RenderSettings::for_scene(&s), 0.0, None)
                .unwrap()
                .0;
            let want = linear(FACE_COLOURS[k]);
            let got = film.get(2, 2);
            assert!(close(got, want, 1e-4), "{b:?} from {a}: {got} vs {want}");
            if k == 4 {
                // Looking along −z past the sphere: the −z face's quadrants.
                for (q, (i, j)) in [(0, 0), (4, 0), (0, 4), (4, 4)].into_iter().enumerate() {
                    let want = linear(NZ_QUADRANTS[q]);
                    let got = film.get(i, j);
                    assert!(close(got, want, 1e-4), "{b:?} pixel ({i}, {j}): {got}");
                }
            }
        }
    }

    // MTL: the six faces as `refl -type cube_*` give the same map.
    let faces = [
        ("cube_right", "px"),
        ("cube_left", "nx"),
        ("cube_top", "py"),
        ("cube_bottom", "ny"),
        ("cube_back", "pz"),
        ("cube_front", "nz"),
    ];
    let mut mtl = String::from("newmtl m\nKd 1 1 1\n");
    for (t, f) in faces {
        mtl += &format!("refl -type {t} sky/{f}.png\n");
    }
    std::fs::write(dir.path().join("m.mtl"), &mtl).unwrap();
    let obj = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl m\nf 1 2 3\n";
    std::fs::write(dir.path().join("c.obj"), obj).unwrap();
    let data = load_geometry(&dir.path().join("c.obj")).unwrap();
    assert!(data.warnings.is_empty(), "{:?}", data.warnings);
    assert!(
        data.environment.as_ref() == Some(&env),
        "MTL cube map differs"
    );
    // One face missing: a warning naming it, no environment.
    std::fs::write(
        dir.path().join("m.mtl"),
        mtl.replace("refl -type cube_top sky/py.png\n", ""),
    )
    .unwrap();
    let data = load_geometry(&dir.path().join("c.obj")).unwrap();
    assert!(data.environment.is_none());
    assert!(
        data.warnings.iter().any(|w| w.contains("missing cube_top")),
        "{:?}",
        data.warnings
    );

    // The scene format: a directory as `[render] environment`.
    let toml = "[camera]\nfrom = [0, 0, 5]\nat = [0, 0, 0]\nfov = 40\nresolution = [4, 4]\n\n\
                [render]\nenvironment = \"sky\"\n";
    std::fs::write(dir.path().join("s.toml"), toml).unwrap();
    let scene = emray::load::load_path(&dir.path().join("s.toml")).unwrap();
    assert!(
        scene.environment.as_ref() == Some(&env),
        "TOML cube map differs"
    );

    // A face of another size, and a missing face, are errors naming the file.
    write_png(&sky.join("py.png"), 8, 8, |_, _| [0, 0, 0]);
    let e = Environment::load(&sky).unwrap_err().to_string();
    assert!(e.contains("py is 8 × 8"), "{e}");
    std::fs::remove_file(sky.join("py.png")).unwrap();
    let e = Environment::load(&sky).unwrap_err().to_string();
    assert!(e.contains("py.png"), "{e}");
}

fn write_png(path: &Path, w: u32, h: u32, f: impl Fn(u32, u32) -> [u8; 3]) {
    let mut img = image::RgbImage::new(w, h);
    for (x, y, p) in img.enumerate_pixels_mut() {
        *p = image::Rgb(f(x, y));
    }
    img.save(path).unwrap();
}

/// A JPEG texture decodes (sRGB to linear for colour maps, as-is for data maps): four
/// flat 16 × 16 blocks (one chroma block each, so subsampling does not mix them) come
/// back within JPEG's loss, read both through `Image::load` and an MTL `map_Kd`.
#[test]
fn jpeg_textures_decode_within_the_codec_loss() {
    use image::codecs::jpeg::JpegEncoder;
    let dir = TempDir::new().unwrap();
    let colours: [[u8; 3]; 4] = [[200, 40, 30], [20, 180, 60], [40, 60, 220], [230, 230, 40]];
    let block = |x: u32, y: u32| colours[(2 * (y / 16) + x / 16) as usize];
    let mut img = image::RgbImage::new(32, 32);
    for (x, y, p) in img.enumerate_pixels_mut() {
        *p = image::Rgb(block(x, y));
    }
    // A `.tex` name: the format is recognised from the content, not the extension.
    let path = dir.path().join("blocks.tex");
    let mut bytes = Vec::new();
    JpegEncoder::new_with_quality(&mut bytes, 95)
        .encode_image(&img)
        .unwrap();
    assert_eq!(&bytes[..2], &[0xFF, 0xD8], "a JPEG stream");
    std::fs::write(&path, &bytes).unwrap();
    let tol = 4.0 / 255.0;
    let colour = Image::load(&path, true).unwrap();
    let data = Image::load(&path, false).unwrap();
    assert_eq!((colour.width(), colour.height()), (32, 32));
    for j in (2..32).step_by(4) {
        for i in (2..32).step_by(4) {
            let want = Vec3::from(block(i, j).map(|c| f32::from(c) / 255.0));
            let got = data.texel(i64::from(i), i64::from(j));
            assert!(
                close(got, want, tol),
                "data texel ({i}, {j}): {got} vs {want}"
            );
            let lin = want.to_array().map(srgb_to_linear);
            let got = colour.texel(i64::from(i), i64::from(j));
            assert!(
                close(got, Vec3::from(lin), tol),
                "colour texel ({i}, {j}): {got} vs {lin:?}"
            );
        }
    }
    // Through an OBJ material: the quad's lower-left corner (vt 0 0) is the bottom-left
    // block, texel (4, 28).
    std::fs::write(
        dir.path().join("m.mtl"),
        "newmtl tex\nKd 1 1 1\nmap_Kd blocks.tex\n",
    )
    .unwrap();
    std::fs::write(
        dir.path().join("q.obj"),
        "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\n\
         vt 0 1\nusemtl tex\nf 1/1 2/2 3/3 4/4\n",
    )
    .unwrap();
    let loaded = load_geometry(&dir.path().join("q.obj")).unwrap();
    assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
    let m = loaded.materials.iter().find(|m| m.maps.color != NO_TEXTURE);
    let index = m.expect("the JPEG map_Kd is loaded").maps.color as usize;
    match &loaded.textures[index] {
        Texture::Image(img) => assert_eq!(img.texel(4, 28), colour.texel(4, 28)),
        t => panic!("not an image texture: {t:?}"),
    }
}

/// A convex quad that is not a parallelogram, textured (a checker image) with the unit
/// square's `vt`.
const KITE_OBJ: &str = "\
mtllib m.mtl
v 0 0 0
v 4 0 0
v 2 4 0
v 0 2 0
vt 0 0
vt 1 0
vt 1 1
vt 0 1
usemtl checker
f 1/1 2/2 3/3 4/4
";
const KITE: [Vec3; 4] = [
    Vec3::new(0.0, 0.0, 0.0),
    Vec3::new(4.0, 0.0, 0.0),
    Vec3::new(2.0, 4.0, 0.0),
    Vec3::new(0.0, 2.0, 0.0),
];

fn bilinear_point(q: [Vec3; 4], s: f32, t: f32) -> Vec3 {
    (q[0] * (1.0 - s) + q[1] * s) * (1.0 - t) + (q[3] * (1.0 - s) + q[2] * s) * t
}

/// For each ray, the texture coordinates the scene gives its hit, and the ones the hit
/// triangle's own barycentric `vt` interpolation would give.
struct UvAtHits<'a> {
    scene: &'a Scene,
    rays: &'a [Ray],
}

impl WithAccel for UvAtHits<'_> {
    type Output = Vec<(Vec2, Vec2)>;
    fn run<A: Accel>(self, accel: &A, _: f64) -> Self::Output {
        let g = &self.scene.geometry;
        self.rays
            .iter()
            .map(|ray| {
                let hit = accel.intersect(ray).expect("the ray hits the quad");
                let surf = self.scene.surface(&hit, ray);
                let uv = surf.param.expect("a textured material").uv;
                let i = hit.prim_id as usize;
                let vt = &g.vertex_uvs[g.triangle_uvs[i] as usize];
                let bary = g.triangles.items[i].param(hit.u, hit.v, Some(vt)).uv;
                (uv, bary)
            })
            .collect()
    }
}

/// The `(u, v)` of an OBJ quad face come from its bilinear patch: a texture line (here
/// `u = s` for fixed `s`) is the straight segment of the patch, where barycentric `vt`
/// interpolation on the two triangles bends it at the diagonal. Directly and through a
/// transformed TOML include, on both backends.
#[test]
fn quad_faces_take_the_inverse_bilinear_uv() {
    let dir = TempDir::new().unwrap();
    write_png(&dir.path().join("c.png"), 8, 8, |x, y| {
        if (x + y) % 2 == 0 {
            [255, 255, 255]
        } else {
            [0, 0, 0]
        }
    });
    std::fs::write(
        dir.path().join("m.mtl"),
        "newmtl checker\nKd 1 1 1\nmap_Kd c.png\n",
    )
    .unwrap();
    std::fs::write(dir.path().join("q.obj"), KITE_OBJ).unwrap();
    std::fs::write(
        dir.path().join("s.toml"),
        "[camera]\nfrom = [0, 0, 10]\nat = [0, 0, 0]\nfov = 40\nresolution = [8, 8]\n\n\
         [[objects]]\ntype = \"include\"\nfile = \"q.obj\"\n\
         transform = [{ scale = 2 }, { translate = [1, 0, 0] }]\n",
    )
    .unwrap();
    let obj = emray::load::load_path(&dir.path().join("q.obj")).unwrap();
    assert_eq!(obj.geometry.quads.len(), 1, "one quad record");
    let toml = emray::load::load_path(&dir.path().join("s.toml")).unwrap();
    let placed = KITE.map(|p| p * 2.0 + Vec3::X);
    let samples: Vec<(f32, f32)> = [0.25f32, 0.5, 0.8]
        .iter()
        .flat_map(|&s| (1..10).map(move |k| (s, k as f32 / 10.0)))
        .collect();
    for (scene, quad) in [(&obj, KITE), (&toml, placed)] {
        let rays: Vec<Ray> = samples
            .iter()
            .map(|&(s, t)| {
                // Aimed in the world, cast in the scene's frame.
                let org = (bilinear_point(quad, s, t) + Vec3::Z * 5.0).as_dvec3() - scene.origin;
                Ray::new(org.as_vec3(), -Vec3::Z)
            })
            .collect();
        for backend in backends() {
            let work = UvAtHits { scene, rays: &rays };
            let got = emray::accel::build(scene, &backend.into(), work).unwrap();
            let mut bend = 0.0f32;
            for (&(s, t), (uv, bary)) in samples.iter().zip(&got) {
                let err = (*uv - Vec2::new(s, t)).abs().max_element();
                assert!(err < 1e-4, "{backend:?}: ({s}, {t}) got {uv}");
                bend = bend.max((bary.x - s).abs());
            }
            // The barycentric version is off the straight line by far more.
            assert!(bend > 0.05, "{backend:?}: barycentric bend only {bend}");
        }
    }
}

const QUAD_OBJ: &str = "\
mtllib m.mtl
v -1 -1 0
v 1 -1 0
v 1 1 0
v -1 1 0
vt 0 0
vt 1 0
vt 1 1
vt 0 1
usemtl tex
f -4/-4 -3/-3 -2/-2 -1/-1
";

#[test]
fn obj_vt_and_map_kd_decode_srgb_and_negative_indices() {
    let dir = TempDir::new().unwrap();
    std::fs::write(dir.path().join("q.obj"), QUAD_OBJ).unwrap();
    std::fs::write(
        dir.path().join("m.mtl"),
        "newmtl tex\nKd 1 1 1\nmap_Kd -s 2 2 t.png\nbump -bm 0.5 h.png\n",
    )
    .unwrap();
    // Left half sRGB 128 (linear 0.2158), right half 255.
    write_png(&dir.path().join("t.png"), 2, 1, |x, _| {
        if x == 0 { [128; 3] } else { [255; 3] }
    });
    write_png(&dir.path().join("h.png"), 2, 1, |x, _| {
        if x == 0 { [128; 3] } else { [255; 3] }
    });
    let data = load_geometry(&dir.path().join("q.obj")).unwrap();
    assert!(data.warnings.is_empty(), "{:?}", data.warnings);
    assert_eq!(data.geometry.triangles.len(), 2);
    assert_eq!(
        data.geometry.vertex_uvs.len(),
        2,
        "each triangle has its vt"
    );
    let m = &data.materials[0];
    assert_eq!(m.maps.uv_scale, [2.0, 2.0]);
    assert_eq!(m.maps.bump_scale, 0.5);
    let Texture::Image(colour) = &data.textures[m.maps.color as usize] else {
        panic!("an image")
    };
    let Texture::Image(height) = &data.textures[m.maps.bump as usize] else {
        panic!("an image")
    };
    // Colour maps are decoded from sRGB, height maps read as they are.
    assert!((colour.texel(0, 0).x - 0.215_861).abs() < 1e-4);
    assert!((height.texel(0, 0).x - 128.0 / 255.0).abs() < 1e-6);
    // Texture coordinates of each triangle corner follow its vertex.
    for (t, uv) in data
        .geometry
        .triangles
        .items
        .iter()
        .zip(&data.geometry.vertex_uvs)
    {
        for (p, uv) in t.p.iter().zip(uv) {
            assert!((*uv - Vec2::new((p.x + 1.0) / 2.0, (p.y + 1.0) / 2.0)).length() < 1e-6);
        }
    }
}

#[test]
fn obj_without_vt_has_no_texture_coordinates_and_missing_texture_is_visible() {
    let dir = TempDir::new().unwrap();
    let obj = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 1 2 3\n";
    std::fs::write(dir.path().join("a.obj"), obj).unwrap();
    std::fs::write(
        dir.path().join("m.mtl"),
        "newmtl a\nKd 1 1 1\nmap_Kd nothere.png\nbump gone.png\n",
    )
    .unwrap();
    let data = load_geometry(&dir.path().join("a.obj")).unwrap();
    assert!(data.geometry.vertex_uvs.is_empty());
    let w: Vec<&String> = data
        .warnings
        .iter()
        .filter(|w| w.contains("nothere.png"))
        .collect();
    assert_eq!(w.len(), 1, "{:?}", data.warnings);
    assert!(
        w[0].contains("m.mtl:3") && w[0].contains("checkerboard"),
        "{}",
        w[0]
    );
    assert!(
        data.warnings
            .iter()
            .any(|w| w.contains("gone.png") && w.contains("left out"))
    );
    let m = &data.materials[0];
    assert_eq!(data.textures[m.maps.color as usize], MISSING_TEXTURE);
    assert_eq!(m.maps.bump, emray::scene::NO_TEXTURE);
}

#[test]
fn smoothing_groups_give_shared_normals_without_vn() {
    // Two triangles folded along the shared edge x = 0; in group 1 both get the mean
    // normal at the shared vertices, with `s off` they are flat.
    let body = "v 0 0 0\nv 0 1 0\nv 1 0 1\nv -1 0 1\n";
    for (s, smooth) in [("s 1\n", true), ("s off\n", false)] {
        let dir = TempDir::new().unwrap();
        let text = format!("{body}{s}f 1 2 3\nf 2 1 4\n");
        std::fs::write(dir.path().join("f.obj"), text).unwrap();
        let data = load_geometry(&dir.path().join("f.obj")).unwrap();
        let g = &data.geometry;
        if smooth {
            assert_eq!(g.vertex_normals.len(), 2);
            let n0 = g.vertex_normals[0][0];
            let n1 = g.vertex_normals[1][1];
            assert!((n0 - n1).length() < 1e-6, "shared vertex, same normal");
            assert!(n0.x.abs() < 1e-6, "the mean of the mirrored faces: {n0}");
        } else {
            assert!(g.vertex_normals.is_empty());
        }
    }
}

const TOML_SCENE: &str = r#"
[camera]
from = [0, 0, 4]
at = [0, 0, 0]
up = [0, 1, 0]
fov = 40
resolution = [24, 24]

[materials.t]
texture = { file = "t.png" }
bump = { type = "checker", scale = 4 }
bump_scale = 0.01
uv_scale = [2, 3]

[[lights]]
position = [2, 3, 5]

[[objects]]
type = "sphere"
center = [0, 0, 0]
radius = 1
material = "t"
"#;

#[test]
fn toml_materials_take_textures_and_report_bad_ones_at_their_line() {
    let dir = TempDir::new().unwrap();
    write_png(&dir.path().join("t.png"), 4, 4, |x, y| {
        [(x * 60) as u8, (y * 60) as u8, 200]
    });
    let path = dir.path().join("s.toml");
    std::fs::write(&path, TOML_SCENE).unwrap();
    let scene = emray::load::load_path(&path).unwrap();
    let m = &scene.materials[0];
    assert_eq!(m.maps.uv_scale, [2.0, 3.0]);
    assert!(matches!(
        scene.textures[m.maps.color as usize],
        Texture::Image(_)
    ));
    assert!(matches!(
        scene.textures[m.maps.bump as usize],
        Texture::Checker { .. }
    ));

    for (bad, line, what) in [
        (
            "texture = { file = \"t.png\" }",
            "texture = { file = \"missing.png\" }",
            "missing.png",
        ),
        (
            "texture = { file = \"t.png\" }",
            "texture = { type = \"wood\" }",
            "unknown texture type",
        ),
    ] {
        std::fs::write(&path, TOML_SCENE.replace(bad, line)).unwrap();
        let e = emray::load::load_path(&path).unwrap_err();
        assert_eq!(e.line, 10, "{e}");
        assert!(e.to_string().contains(what), "{e}");
    }
}

#[test]
fn backends_agree_on_a_textured_obj_scene() {
    let dir = TempDir::new().unwrap();
    // A checkered quad, bump-mapped, behind a textured triangle fan.
    let obj = "mtllib m.mtl\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nv 0 0 0.5\n\
               vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvt 0.5 0.5\n\
               usemtl tex\nf 1/1 2/2 3/3 4/4\nusemtl bumpy\nf 1/1 2/2 5/5\nf 3/3 4/4 5/5\n";
    std::fs::write(dir.path().join("s.obj"), obj).unwrap();
    std::fs::write(
        dir.path().join("m.mtl"),
        "newmtl tex\nKd 1 1 1\nKs 0.3 0.3 0.3\nNs 20\nmap_Kd c.png\n\
         newmtl bumpy\nKd 0.8 0.6 0.3\nbump -bm 0.05 c.png\n",
    )
    .unwrap();
    write_png(&dir.path().join("c.png"), 8, 8, |x, y| {
        if (x + y) % 2 == 0 {
            [230, 40, 40]
        } else {
            [30, 30, 220]
        }
    });
    let mut scene = emray::load::load_path(&dir.path().join("s.obj")).unwrap();
    scene
        .lights
        .push(Light::point(Vec3::new(-3.0, 3.0, 4.0), Vec3::splat(0.5)));
    let mut settings = RenderSettings::for_scene(&scene);
    settings.width = 48;
    settings.height = 48;
    let films: Vec<_> = backends()
        .into_iter()
        .map(|b| {
            render_scene("t", &scene, b, &settings, 0.0, None)
                .unwrap()
                .0
        })
        .collect();
    let film = &films[0];
    let distinct: std::collections::HashSet<[u32; 3]> = film
        .pixels
        .iter()
        .map(|p| p.to_array().map(f32::to_bits))
        .collect();
    assert!(
        distinct.len() > 20,
        "the textures show: {} distinct values",
        distinct.len()
    );
    for other in &films[1..] {
        let differ = film
            .pixels
            .iter()
            .zip(&other.pixels)
            .filter(|(a, b)| (**a - **b).abs().max_element() > 1e-3)
            .count();
        assert!(differ <= film.pixels.len() / 100, "{differ} pixels differ");
    }
}
