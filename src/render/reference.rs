//! The reference renderer (`--reference`): the same Whitted model computed entirely in
//! f64 — camera, intersections (the independent intersectors of
//! [`crate::geometry::precise`]), normals, shading — with `n × n` stratified jittered
//! samples per pixel, so that "error" means error against something that shares
//! neither the f32 arithmetic nor either backend's traversal.
//!
//! Traversal is brute force: every ray is tested against every primitive. That is slow
//! (O(primitives) per ray) but has no traversal of its own that could be wrong or
//! imprecise; it is meant for small scenes and small images. Scenes with primitive
//! kinds or features the reference does not model (anything but spheres, open cones
//! and triangles; instances; spot lights; media priorities) are refused, never
//! rendered differently.

use super::RayCounts;
use super::film::Film;
use crate::geometry::Kind;
use crate::geometry::precise as r64;
use crate::math::DRay;
use crate::scene::{Camera, Scene};
use glam::{DVec3, Vec3};
use rayon::prelude::*;

/// What the reference renderer does not model, so cannot render.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
pub enum Unsupported {
    /// A primitive other than spheres, cones and triangles (its kind's plural name).
    #[error("the reference renderer models spheres, cones and triangles only; the scene has {0}")]
    Shape(&'static str),
    /// Instances of objects.
    #[error("the reference renderer does not support instances")]
    Instances,
    /// Spot lights.
    #[error("the reference renderer does not support spot lights")]
    SpotLights,
    /// Nested-dielectric priorities.
    #[error("the reference renderer does not support medium priorities")]
    MediumPriorities,
    /// Texture, bump or normal maps, or an environment map.
    #[error("the reference renderer does not support textures or environment maps")]
    Textures,
}

/// Why a scene cannot be rendered by the reference (the first reason found), or
/// `None` when it can.
pub fn unsupported(scene: &Scene) -> Option<Unsupported> {
    let modelled = [Kind::Triangle, Kind::Sphere, Kind::Cone];
    let other = Kind::ALL
        .into_iter()
        .find(|&k| !modelled.contains(&k) && scene.geometry.count(k) > 0);
    if let Some(kind) = other {
        return Some(Unsupported::Shape(kind.name()));
    }
    if !scene.instances.is_empty() {
        return Some(Unsupported::Instances);
    }
    if scene.lights.iter().any(|l| l.spot.is_some()) {
        return Some(Unsupported::SpotLights);
    }
    if scene.materials.iter().any(|m| m.t > 0.0 && m.priority != 0) {
        return Some(Unsupported::MediumPriorities);
    }
    if scene.materials.iter().any(|m| m.maps.any()) || scene.environment.is_some() {
        return Some(Unsupported::Textures);
    }
    None
}

/// One primitive hit: distance, outward unit geometric normal, unit shading normal,
/// material.
struct Hit64 {
    t: f64,
    ng: DVec3,
    ns: DVec3,
    material: u32,
}

/// The f64 tracer over a supported scene.
pub struct Reference<'a> {
    scene: &'a Scene,
    max_depth: u32,
}

fn d(v: Vec3) -> DVec3 {
    v.as_dvec3()
}

/// A ray spawned at `p` leaves along `dir` from the side of `n` it goes to; the origin
/// is pushed off the surface by far more than f64's rounding error of `p` (about
/// 1e-16 |p|) and far less than f32's (about 6e-8 |p|).
fn spawn(p: DVec3, n: DVec3, dir: DVec3) -> DRay {
    let off = 1e-11 * (1.0 + p.abs().max_element());
    let side = if n.dot(dir) >= 0.0 { n } else { -n };
    DRay {
        org: p + side * off,
        dir,
    }
}

impl<'a> Reference<'a> {
    /// A tracer for `scene` (check [`unsupported`] first) to depth `max_depth`.
    pub fn new(scene: &'a Scene, max_depth: u32) -> Self {
        Reference {
            scene,
            max_depth: max_depth.max(1),
        }
    }

    fn intersect(&self, ray: &DRay, tmax: f64) -> Option<Hit64> {
        let g = &self.scene.geometry;
        let mut best: Option<Hit64> = None;
        let mut tmax = tmax;
        for (k, tri) in g.triangles.items.iter().enumerate() {
            let p = tri.p.map(d);
            if let Some((t, u, v)) = r64::triangle(ray, p, 0.0) {
                if t < tmax {
                    let ng = (p[1] - p[0]).cross(p[2] - p[0]).normalize();
                    let ns = match g.triangle_normals.get(k) {
                        Some(&i) if i != u32::MAX => {
                            let n = g.vertex_normals[i as usize].map(d);
                            (n[0] * (1.0 - u - v) + n[1] * u + n[2] * v).normalize()
                        }
                        _ => ng,
                    };
                    tmax = t;
                    best = Some(Hit64 {
                        t,
                        ng,
                        ns,
                        material: g.triangles.material[k],
                    });
                }
            }
        }
        for (k, s) in g.spheres().items.iter().enumerate() {
            let c = d(s.center);
            let r = s.radius as f64;
            if let Some(t) = r64::sphere(ray, c, r, s.inside_only, 0.0) {
                if t < tmax {
                    let n = (ray.org + ray.dir * t - c) / r;
                    tmax = t;
                    best = Some(Hit64 {
                        t,
                        ng: n,
                        ns: n,
                        material: g.spheres().material[k],
                    });
                }
            }
        }
        for (k, c) in g.cones().items.iter().enumerate() {
            let (base, apex) = (d(c.base), d(c.apex));
            let (rb, ra) = (c.base_radius as f64, c.apex_radius as f64);
            if let Some(t) = r64::cone(ray, base, rb, apex, ra, c.inside_only, 0.0) {
                if t < tmax {
                    let h = (apex - base).length();
                    let w = (apex - base) / h;
                    let slope = (ra - rb) / h;
                    let q = ray.org + ray.dir * t - base;
                    let radial = (q - w * q.dot(w)).normalize_or_zero();
                    let n = (radial - w * slope).normalize();
                    tmax = t;
                    best = Some(Hit64 {
                        t,
                        ng: n,
                        ns: n,
                        material: g.cones().material[k],
                    });
                }
            }
        }
        best
    }

    /// Radiance along `ray` at depth `depth` (eye = 1) inside media of indices `iors`.
    fn trace(&self, ray: &DRay, depth: u32, iors: &[(u32, f64)], c: &mut RayCounts) -> DVec3 {
        let scene = self.scene;
        let Some(hit) = self.intersect(ray, f64::INFINITY) else {
            return d(scene.background);
        };
        if depth == 1 {
            c.eye_hit += 1;
        }
        let m = &scene.materials[hit.material as usize];
        let dir = ray.dir.normalize();
        let p = ray.org + ray.dir * hit.t;
        let entering = hit.ng.dot(dir) < 0.0;
        let ng = if entering { hit.ng } else { -hit.ng };
        let ns = if hit.ns.dot(dir) > 0.0 {
            -hit.ns
        } else {
            hit.ns
        };
        let color = d(m.color);
        let mut out = d(scene.ambient) * color * m.ka as f64;
        for light in &scene.lights {
            let lp = d(light.pos);
            let to_light = lp - p;
            if ns.dot(to_light) <= 0.0 {
                continue;
            }
            let mut intensity = d(light.color);
            if light.attenuation != Vec3::X {
                let a = d(light.attenuation);
                let dist = to_light.length();
                intensity /= a.x + a.y * dist + a.z * dist * dist;
            }
            c.shadow += 1;
            let sray = spawn(p, ng, to_light);
            let sdir = lp - sray.org;
            let probe = DRay {
                org: sray.org,
                dir: sdir,
            };
            if self.intersect(&probe, 1.0).is_some() {
                continue;
            }
            let l = to_light.normalize();
            let mut cc = color * (m.kd as f64 * ns.dot(l));
            if m.ks > 0.0 {
                let rr = -l - ns * (2.0 * (-l).dot(ns));
                let rv = rr.dot(-dir).max(0.0);
                cc += DVec3::splat(m.ks as f64 * rv.powf(m.shine as f64));
            }
            out += intensity * cc;
        }
        if depth >= self.max_depth {
            return out;
        }
        let mut reflect_weight = m.kr as f64;
        if m.t > 0.0 {
            let ior = |media: &[(u32, f64)]| media.last().map_or(1.0, |x| x.1);
            let mut inside = iors.to_vec();
            let (n1, n2) = if entering {
                inside.push((hit.material, m.ior as f64));
                (ior(iors), m.ior as f64)
            } else {
                if let Some(k) = inside.iter().rposition(|x| x.0 == hit.material) {
                    inside.remove(k);
                }
                (m.ior as f64, ior(&inside))
            };
            let eta = n1 / n2;
            let cos_i = (-dir).dot(ns).min(1.0);
            let kk = 1.0 - eta * eta * (1.0 - cos_i * cos_i);
            if kk >= 0.0 {
                c.refraction += 1;
                let tdir = (dir * eta + ns * (eta * cos_i - kk.sqrt())).normalize();
                let filter = inside
                    .last()
                    .map_or(DVec3::ONE, |x| d(scene.materials[x.0 as usize].filter));
                let tr = self.trace(&spawn(p, ng, tdir), depth + 1, &inside, c);
                out += m.t as f64 * filter * tr;
            } else {
                c.tir += 1;
                reflect_weight += m.t as f64;
            }
        }
        if reflect_weight > 0.0 {
            c.reflection += 1;
            let rdir = dir - ns * (2.0 * dir.dot(ns));
            out += reflect_weight * self.trace(&spawn(p, ng, rdir), depth + 1, iors, c);
        }
        out
    }
}

/// The eye rays of the camera in f64 (the same mapping as [`super::RayGen`]).
struct Camera64 {
    from: DVec3,
    forward: DVec3,
    right: DVec3,
    up: DVec3,
    half_w: f64,
    half_h: f64,
}

impl Camera64 {
    fn new(cam: &Camera, width: u32, height: u32) -> Self {
        let forward = (d(cam.at) - d(cam.from)).normalize();
        let right = forward.cross(d(cam.up)).normalize();
        let up = right.cross(forward);
        let half = (cam.angle_deg as f64).to_radians() * 0.5;
        let scale = half.tan() / ((height.max(2) - 1) as f64 * 0.5);
        Camera64 {
            from: d(cam.from),
            forward,
            right: right * scale,
            up: up * scale,
            half_w: width as f64 * 0.5,
            half_h: height as f64 * 0.5,
        }
    }

    fn ray(&self, px: f64, py: f64) -> DRay {
        let x = px - self.half_w;
        let y = self.half_h - py;
        DRay {
            org: self.from,
            dir: (self.forward + self.right * x + self.up * y).normalize(),
        }
    }
}

/// A 64-bit hash (splitmix64's finaliser) for the jitter.
fn mix(mut x: u64) -> u64 {
    x ^= x >> 30;
    x = x.wrapping_mul(0xbf58_476d_1ce4_e5b9);
    x ^= x >> 27;
    x = x.wrapping_mul(0x94d0_49bb_1331_11eb);
    x ^ (x >> 31)
}

fn unit64(x: u64) -> f64 {
    (x >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// Render `scene` at `width × height` with `n × n` stratified jittered samples per
/// pixel (deterministic), to depth `max_depth`. The scene must be supported.
pub fn render(scene: &Scene, width: u32, height: u32, n: u32, max_depth: u32) -> (Film, RayCounts) {
    let job = Job::new(scene, width, height, n, max_depth);
    let rows: Vec<(Vec<Vec3>, RayCounts)> = (0..height)
        .into_par_iter()
        .map(|j| {
            let mut c = RayCounts::default();
            let row = (0..width).map(|i| job.pixel(i, j, &mut c)).collect();
            (row, c)
        })
        .collect();
    let mut film = Film::new(width, height);
    let mut counts = RayCounts::default();
    for (j, (row, c)) in rows.into_iter().enumerate() {
        counts += c;
        for (i, v) in row.into_iter().enumerate() {
            film.set(i as u32, j as u32, v);
        }
    }
    (film, counts)
}

/// Pixels [`estimate_ms`] traces: enough to average over the picture, few enough to
/// take a small share of the time of any run worth estimating.
const ESTIMATE_PIXELS: u32 = 64;

/// The time in milliseconds [`render`] would take with the same arguments on
/// `threads` threads, extrapolated from `ESTIMATE_PIXELS` pixels spread over the
/// picture (a diagonal-free lattice, so a scene's empty corners and busy centre both
/// count), traced on this thread.
pub fn estimate_ms(
    scene: &Scene,
    width: u32,
    height: u32,
    n: u32,
    max_depth: u32,
    threads: usize,
) -> f64 {
    let job = Job::new(scene, width, height, n, max_depth);
    let total = width as u64 * height as u64;
    let samples = (ESTIMATE_PIXELS as u64).min(total).max(1);
    let mut c = RayCounts::default();
    let t0 = std::time::Instant::now();
    for k in 0..samples {
        // Pixel number k·total/samples, offset by half a step, of the row-major order.
        let at = (k * total + total / 2) / samples;
        job.pixel(
            (at % width as u64) as u32,
            (at / width as u64) as u32,
            &mut c,
        );
    }
    let per_pixel = t0.elapsed().as_secs_f64() * 1e3 / samples as f64;
    per_pixel * total as f64 / threads.max(1) as f64
}

/// What every pixel of a reference render shares.
struct Job<'a> {
    cam: Camera64,
    tracer: Reference<'a>,
    n: u32,
}

impl<'a> Job<'a> {
    fn new(scene: &'a Scene, width: u32, height: u32, n: u32, max_depth: u32) -> Self {
        Job {
            cam: Camera64::new(&scene.camera, width, height),
            tracer: Reference::new(scene, max_depth),
            n: n.max(1),
        }
    }

    /// Pixel `(i, j)`: the mean of its `n × n` jittered strata.
    fn pixel(&self, i: u32, j: u32, c: &mut RayCounts) -> Vec3 {
        let n = self.n;
        let mut sum = DVec3::ZERO;
        let seed = mix(((j as u64) << 32) | i as u64);
        for a in 0..n {
            for b in 0..n {
                let h = mix(seed ^ ((a * n + b) as u64 + 1));
                let sx = (b as f64 + unit64(h)) / n as f64;
                let sy = (a as f64 + unit64(mix(h))) / n as f64;
                let ray = self.cam.ray(i as f64 + sx, j as f64 + sy);
                c.eye += 1;
                sum += self.tracer.trace(&ray, 1, &[], c);
            }
        }
        (sum / (n * n) as f64).as_vec3()
    }
}
