//! A scene and its mirror image (the TOML `mirror` transform on every object, the
//! camera and lights reflected with it) render as mirror images of each other on both
//! backends: glass (a sphere, a mesh baked into place and an instanced one) and CSG keep their outsides outside, so that
//! refraction enters and leaves where it should.

use emray::accel::Backend;
use emray::accuracy::stress::invariance_of;
use emray::job::render_scene;
use emray::render::{Film, RenderSettings};
use glam::DVec3;
use std::path::Path;

mod common;
use common::backends;

/// A reflection about a plane: a point of it and its unit normal.
#[derive(Clone, Copy)]
struct Plane {
    point: DVec3,
    normal: DVec3,
}

impl Plane {
    fn reflect(&self, p: DVec3) -> DVec3 {
        p - 2.0 * (p - self.point).dot(self.normal) * self.normal
    }

    fn reflect_dir(&self, v: DVec3) -> DVec3 {
        v - 2.0 * v.dot(self.normal) * self.normal
    }
}

fn v(p: DVec3) -> String {
    format!("[{:?}, {:?}, {:?}]", p.x, p.y, p.z)
}

/// The test scene, or its mirror image about `mirror`: every object gets the `mirror`
/// step at the end of its transform, the camera and lights are reflected here.
fn scene(mirror: Option<Plane>) -> String {
    let pt = |p: [f64; 3]| {
        let p = DVec3::from(p);
        v(mirror.map_or(p, |m| m.reflect(p)))
    };
    let dir = |d: [f64; 3]| {
        let d = DVec3::from(d);
        v(mirror.map_or(d, |m| m.reflect_dir(d)))
    };
    let step = mirror.map_or(String::new(), |m| {
        format!(
            ", {{ mirror = {{ point = {}, normal = {} }} }}",
            v(m.point),
            v(m.normal)
        )
    });
    format!(
        r#"
[camera]
from = {from}
at = {at}
up = {up}
fov = 40
resolution = [96, 64]

[render]
background = [0.2, 0.25, 0.3]
max_depth = 6

[materials.glass]
color = [1, 1, 1]
diffuse = 0.05
specular = 0.5
shininess = 60
reflectance = 0.1
transmittance = 0.85
ior = 1.5

[materials.red]
color = [0.8, 0.2, 0.15]
diffuse = 0.8
specular = 0.3
reflectance = 0.2

[materials.floor]
color = [0.7, 0.7, 0.6]
diffuse = 0.8
reflectance = 0.1

[[lights]]
position = {light}
intensity = 0.8

[define.pyramid]
type = "mesh"
vertices = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0.5, 0.5, 1.2]]
faces = [[0, 3, 2, 1], [0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]]

[[objects]]
type = "mesh"
material = "floor"
vertices = [[-6, -3, 0], [6, -3, 0], [6, 6, 0], [-6, 6, 0]]
faces = [[0, 1, 2, 3]]
transform = [{{ translate = [0, 0, 0] }}{step}]

[[objects]]
type = "sphere"
center = [0.9, 0.2, 0.82]
radius = 0.8
material = "glass"
transform = [{{ translate = [0, 0, 0] }}{step}]

[[objects]]
type = "difference"
material = "red"
children = [
  {{ type = "box", min = [-0.6, -0.6, 0], max = [0.6, 0.6, 1.2] }},
  {{ type = "sphere", center = [0.3, -0.6, 1.0], radius = 0.55 }},
]
transform = [{{ rotate = [0, 0, 1], angle = 25 }}, {{ translate = [-1.6, 0.8, 0.02] }}{step}]

[[objects]]
type = "mesh"
material = "glass"
vertices = [[0, 0, 0], [0.9, 0, 0], [0.45, 0.8, 0], [0.45, 0.3, 0.9]]
faces = [[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]]
transform = [{{ rotate = [0, 0, 1], angle = -20 }}, {{ translate = [1.6, -1.9, 0.03] }}{step}]

[[objects]]
type = "instance"
of = "pyramid"
material = "glass"
transform = [{{ rotate = [0, 0, 1], angle = 15 }}, {{ translate = [-0.2, -1.4, 0.05] }}{step}]
"#,
        from = pt([0.4, -6.5, 2.2]),
        at = pt([0.0, 0.0, 0.6]),
        up = dir([0.0, 0.0, 1.0]),
        light = pt([3.0, -4.0, 6.0]),
    )
}

fn render(src: &str, b: Backend) -> Film {
    let s =
        emray::load::toml::parse_str(src, Path::new("<mirror>")).unwrap_or_else(|e| panic!("{e}"));
    let mut settings = RenderSettings::for_scene(&s);
    settings.max_depth = s.render.max_depth.unwrap_or(settings.max_depth);
    render_scene("mirror", &s, b, &settings, 0.0, None)
        .unwrap_or_else(|e| panic!("{e}"))
        .0
}

/// The film flipped left to right.
fn flipped(f: &Film) -> Film {
    let mut out = Film::new(f.width, f.height);
    for j in 0..f.height {
        for i in 0..f.width {
            out.set(f.width - 1 - i, j, f.get(i, j));
        }
    }
    out
}

fn check(plane: Plane) {
    for b in backends() {
        let original = render(&scene(None), b);
        let mirrored = render(&scene(Some(plane)), b);
        let same = invariance_of(&original, &flipped(&mirrored));
        assert!(
            same.within >= 0.999,
            "{b:?}: {:.3}% of pixels within 2/255, largest difference {}",
            same.within * 100.0,
            same.max_diff
        );
        // The glass and the CSG solid are there and lit: the picture is not empty.
        let lit = original
            .pixels
            .iter()
            .filter(|p| p.max_element() > 0.35)
            .count();
        assert!(lit > 200, "{b:?}: {lit} bright pixels");
    }
}

/// The plane x = 0 (which holds the camera): the mirror image is exact in f32.
#[test]
fn mirror_about_the_camera_plane_renders_the_mirror_image() {
    check(Plane {
        point: DVec3::ZERO,
        normal: DVec3::X,
    });
}

/// An oblique plane away from the origin, the camera reflected with the scene (a
/// reflected camera's right is the reflected right reversed, so the picture flips).
#[test]
fn mirror_about_an_oblique_plane_renders_the_mirror_image() {
    check(Plane {
        point: DVec3::new(0.3, 1.0, -0.2),
        normal: DVec3::new(1.0, 0.2, 0.5).normalize(),
    });
}
