//! Numerical stress cases, shared by `tests/stability.rs` (which asserts bounds on
//! small counts) and `emray stress` (which prints the measured numbers on full counts).

use crate::accel::Accel;
use crate::geometry::reference as r64;
use crate::load::nff::parse_str;
use crate::math::{next_float_down, offset_ray_origin, DRay, DVec3, Ray, Vec3};
use crate::render::{Film, RayGen, RenderSettings};
use crate::run::render_scene;
use crate::{Backend, Scene};
use std::path::Path;

/// A convex test scene: one sphere and one light (no other surface can shadow it),
/// scaled by `scale` and moved by `offset` (camera, light and sphere alike).
pub fn convex_scene(scale: f64, offset: f64, res: u32) -> Scene {
    let p = |x: f64, y: f64, z: f64| {
        format!(
            "{} {} {}",
            x * scale + offset,
            y * scale + offset,
            z * scale + offset
        )
    };
    let src = format!(
        "v\nfrom {}\nat {}\nup 0 0 1\nangle 30\nhither 0\nresolution {res} {res}\n\
         b 0.1 0.1 0.1\nl {}\nf 0.8 0.6 0.4 0.9 0.3 20 0 1\ns {} {}\n",
        p(0.0, -6.0, 1.0),
        p(0.0, 0.0, 0.0),
        p(3.0, -4.0, 5.0),
        p(0.0, 0.0, 0.0),
        1.5 * scale
    );
    parse_str(&src, Path::new("<stress>")).expect("generated scene parses")
}

/// A sphere over a triangle floor (the shadow falls on the floor), scaled by `scale`.
pub fn floor_scene(scale: f64, res: u32) -> Scene {
    let v = |x: f64, y: f64, z: f64| format!("{} {} {}", x * scale, y * scale, z * scale);
    let src = format!(
        "v\nfrom {}\nat {}\nup 0 0 1\nangle 35\nhither 0\nresolution {res} {res}\n\
         b 0.1 0.2 0.3\nl {}\nf 0.8 0.8 0.7 0.9 0 0 0 1\np 4 {} {} {} {}\n\
         f 0.9 0.3 0.2 0.8 0.4 30 0 1\ns {} {}\n",
        v(0.0, -7.0, 3.0),
        v(0.0, 0.0, 0.5),
        v(3.0, -2.0, 6.0),
        v(-4.0, -4.0, 0.0),
        v(4.0, -4.0, 0.0),
        v(4.0, 4.0, 0.0),
        v(-4.0, 4.0, 0.0),
        v(0.0, 0.0, 1.0),
        scale
    );
    parse_str(&src, Path::new("<stress>")).expect("generated scene parses")
}

/// Render `scene` on `backend` at its resolution, 1 spp.
pub fn render(scene: &Scene, backend: Backend) -> Film {
    let st = RenderSettings::for_scene(scene);
    render_scene("stress", scene, backend, &st, 0.0, None)
        .expect("backend builds")
        .0
}

/// Self-shadowing acne on a convex scene: of the eye-ray hits whose shading normal
/// faces the light (the points that must be lit), how many have their shadow ray,
/// spawned as the renderer spawns it, blocked. Returns `(lit points, acne)`.
pub fn acne<A: Accel>(scene: &Scene, accel: &A) -> (u64, u64) {
    let cam = &scene.camera;
    let gen = RayGen::new(cam, cam.width, cam.height);
    let (mut lit, mut acne) = (0, 0);
    for j in 0..cam.height {
        for i in 0..cam.width {
            let ray = gen.ray(i as f32 + 0.5, j as f32 + 0.5);
            let Some(hit) = accel.intersect(&ray) else {
                continue;
            };
            let s = scene.surface(&hit, &ray);
            let d = ray.dir.normalize();
            let ng = if s.point.ng.dot(d) < 0.0 {
                s.point.ng
            } else {
                -s.point.ng
            };
            for light in &scene.lights {
                let to_light = light.pos - s.point.p;
                // Points near the terminator are left out: the f32 normal itself is
                // uncertain there.
                if ng.dot(to_light.normalize()) <= 1e-3 {
                    continue;
                }
                lit += 1;
                let org = offset_ray_origin(s.point.p, s.point.err, ng, to_light);
                let mut shadow = Ray::new(org, light.pos - org);
                shadow.tmax = next_float_down(1.0);
                if accel.occluded(&shadow) {
                    acne += 1;
                }
            }
        }
    }
    (lit, acne)
}

/// Share (0..1) of pixels whose 8-bit sRGB value differs.
pub fn differing_share(a: &Film, b: &Film) -> f64 {
    crate::output::differing_pixels(a, b) as f64 / a.pixels.len().max(1) as f64
}

/// A closed triangle mesh: the octahedron subdivided `n` times and pushed onto the
/// unit sphere, as NFF polygons (every edge shared by two triangles, every vertex by
/// four or six).
pub fn tessellated_sphere(n: u32) -> (Scene, Vec<Vec3>) {
    let mut tris: Vec<[DVec3; 3]> = Vec::new();
    let (x, y, z) = (DVec3::X, DVec3::Y, DVec3::Z);
    for sx in [1.0, -1.0] {
        for sy in [1.0, -1.0] {
            for sz in [1.0, -1.0] {
                let t = [x * sx, y * sy, z * sz];
                // Counter-clockwise seen from outside.
                if sx * sy * sz > 0.0 {
                    tris.push(t);
                } else {
                    tris.push([t[0], t[2], t[1]]);
                }
            }
        }
    }
    for _ in 0..n {
        let mut next = Vec::with_capacity(tris.len() * 4);
        for [a, b, c] in tris {
            let (ab, bc, ca) = (
                ((a + b) * 0.5).normalize(),
                ((b + c) * 0.5).normalize(),
                ((c + a) * 0.5).normalize(),
            );
            next.extend([[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]);
        }
        tris = next;
    }
    // Round the vertices to f32 once, so that shared vertices are bit-identical.
    let f = |v: DVec3| v.as_vec3();
    let mut src = String::from(
        "v\nfrom 0 0 5\nat 0 0 0\nup 0 1 0\nangle 30\nhither 0\nresolution 8 8\n\
         f 1 1 1 1 0 0 0 1\n",
    );
    let mut targets = Vec::new();
    for t in &tris {
        src.push_str("p 3");
        for v in t {
            let v = f(*v);
            src.push_str(&format!(" {} {} {}", v.x, v.y, v.z));
        }
        src.push('\n');
        let [a, b, c] = t.map(f);
        // Vertices and edge midpoints (computed in f32: exactly on the shared edge
        // up to rounding, which is what a watertight test must survive).
        targets.extend([a, (a + b) * 0.5, (b + c) * 0.5, (c + a) * 0.5]);
    }
    let scene = parse_str(&src, Path::new("<stress>")).expect("generated mesh parses");
    (scene, targets)
}

/// Rays from several outside origins aimed exactly at `targets` (vertices and edge
/// midpoints of the closed convex mesh around the origin) that it faces: `(rays,
/// misses)`. Targets seen at grazing incidence (within 30° of the sphere's tangent
/// plane, more than the facets deviate from it: the ray could only touch the mesh
/// at that point) are left out.
pub fn watertight<A: Accel>(accel: &A, targets: &[Vec3], origins: &[Vec3]) -> (u64, u64) {
    let (mut rays, mut misses) = (0, 0);
    for &o in origins {
        for &t in targets {
            if t.normalize().dot((o - t).normalize()) < 0.5 {
                continue;
            }
            let ray = Ray::new(o, t - o);
            rays += 1;
            if accel.intersect(&ray).is_none() {
                misses += 1;
            }
        }
    }
    (rays, misses)
}

/// Origins around a closed mesh at distance `r`, `n` of them (a spiral over the sphere).
pub fn origins(n: u32, r: f32) -> Vec<Vec3> {
    (0..n)
        .map(|k| {
            let z = 1.0 - 2.0 * (k as f32 + 0.5) / n as f32;
            let phi = k as f32 * 2.399_963;
            let s = (1.0 - z * z).sqrt();
            Vec3::new(s * phi.cos(), s * phi.sin(), z) * r
        })
        .collect()
}

/// f32 hit distance against the f64 reference for a sphere of radius `radius` at
/// distance `dist`, over `n` rays from the origin aimed at random points of its
/// projected disk: `(worst relative error of t, misses where f64 hits, hits where
/// f64 misses)`.
pub fn far_sphere(dist: f32, radius: f32, n: u32, seed: u32) -> (f64, u64, u64) {
    let c = Vec3::new(0.0, 0.0, -dist);
    let sphere = crate::geometry::Sphere::new(c, radius);
    let mut worst = 0.0f64;
    let (mut miss, mut extra) = (0, 0);
    let mut state = seed.wrapping_mul(0x9e37_79b9) | 1;
    let mut rnd = || {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        (state >> 8) as f32 / (1u32 << 24) as f32
    };
    for _ in 0..n {
        // Points up to 1.1 radii from the centre, on the plane through it.
        let (a, b) = (rnd() * std::f32::consts::TAU, rnd().sqrt() * 1.1 * radius);
        let target = c + Vec3::new(a.cos() * b, a.sin() * b, 0.0);
        let ray = Ray::new(Vec3::ZERO, target.normalize());
        let exact = r64::sphere(&DRay::from(&ray), c.as_dvec3(), radius as f64, false, 0.0);
        let got = crate::geometry::Intersect::intersect(&sphere, &ray).map(|h| h.t);
        match (got, exact) {
            (Some(t), Some(e)) => worst = worst.max(((t as f64 - e) / e).abs()),
            (None, Some(_)) => miss += 1,
            (Some(_), None) => extra += 1,
            (None, None) => {}
        }
    }
    (worst, miss, extra)
}
