//! Whitted shading (DESIGN.md §4).

use super::{RayGen, RenderSettings};
use crate::accel::Accel;
use crate::math::{next_float_down, offset_ray_origin, Ray, Vec3};
use crate::scene::Scene;

/// Rays cast, by type.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RayCounts {
    /// Eye (primary) rays.
    pub eye: u64,
    /// Eye rays that hit something.
    pub eye_hit: u64,
    /// Reflection rays.
    pub reflection: u64,
    /// Refraction (transmission) rays.
    pub refraction: u64,
    /// Shadow rays.
    pub shadow: u64,
    /// Total internal reflection events (no refraction ray was cast).
    pub tir: u64,
}

impl RayCounts {
    /// All rays cast.
    pub fn total(&self) -> u64 {
        self.eye + self.reflection + self.refraction + self.shadow
    }
}

impl std::ops::AddAssign for RayCounts {
    fn add_assign(&mut self, o: Self) {
        self.eye += o.eye;
        self.eye_hit += o.eye_hit;
        self.reflection += o.reflection;
        self.refraction += o.refraction;
        self.shadow += o.shadow;
        self.tir += o.tir;
    }
}

pub(super) struct Tracer<'a, A: Accel> {
    scene: &'a Scene,
    accel: &'a A,
    max_depth: u32,
    spp: u32,
}

/// A 32-bit integer hash (Wellons' lowbias32) for per-pixel sample offsets.
#[inline]
fn hash(mut x: u32) -> u32 {
    x ^= x >> 16;
    x = x.wrapping_mul(0x7feb_352d);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846c_a68b);
    x ^= x >> 16;
    x
}

#[inline]
fn unit(x: u32) -> f32 {
    (x >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
}

/// Van der Corput radical inverse in base 2.
#[inline]
fn radical_inverse(i: u32) -> f32 {
    unit(i.reverse_bits())
}

/// Mirror `d` about the unit normal `n`.
#[inline]
fn reflect(d: Vec3, n: Vec3) -> Vec3 {
    d - n * (2.0 * d.dot(n))
}

/// Snell's law: the refracted direction of unit `d` through a surface with unit normal
/// `n` facing the incoming ray, for `eta = n₁/n₂`; `None` on total internal reflection.
#[inline]
fn refract(d: Vec3, n: Vec3, eta: f32) -> Option<Vec3> {
    let cos_i = (-d).dot(n).min(1.0);
    let k = 1.0 - eta * eta * (1.0 - cos_i * cos_i);
    if k < 0.0 {
        return None;
    }
    Some((d * eta + n * (eta * cos_i - k.sqrt())).normalize())
}

impl<'a, A: Accel> Tracer<'a, A> {
    pub(super) fn new(scene: &'a Scene, accel: &'a A, s: &RenderSettings) -> Self {
        Tracer {
            scene,
            accel,
            max_depth: s.max_depth.max(1),
            spp: s.spp.max(1),
        }
    }

    /// The value of sample-grid position `(i, j)`: its centre with one sample, else the
    /// mean of `spp` stratified samples (a Hammersley set rotated per pixel by a hash
    /// of its coordinates, so the result does not depend on the thread schedule).
    pub(super) fn pixel(&self, gen: &RayGen, i: u32, j: u32, counts: &mut RayCounts) -> Vec3 {
        if self.spp == 1 {
            return self.eye(gen.ray(i as f32 + 0.5, j as f32 + 0.5), counts);
        }
        let seed = hash(i.wrapping_mul(0x9e37_79b9) ^ hash(j));
        let (ox, oy) = (unit(hash(seed)), unit(hash(seed ^ 0x5bd1_e995)));
        let n = self.spp;
        let mut sum = Vec3::ZERO;
        for s in 0..n {
            let sx = ((s as f32 + ox) / n as f32).fract();
            let sy = (radical_inverse(s) + oy).fract();
            sum += self.eye(gen.ray(i as f32 + sx, j as f32 + sy), counts);
        }
        sum / n as f32
    }

    fn eye(&self, ray: Ray, counts: &mut RayCounts) -> Vec3 {
        counts.eye += 1;
        self.trace(&ray, 1, counts)
    }

    /// Radiance along `ray` at ray-tree depth `depth` (the eye ray is depth 1).
    fn trace(&self, ray: &Ray, depth: u32, counts: &mut RayCounts) -> Vec3 {
        let scene = self.scene;
        let Some(hit) = self.accel.intersect(ray) else {
            return scene.background;
        };
        if depth == 1 {
            counts.eye_hit += 1;
        }
        let surf = scene.surface(&hit, ray);
        let m = &scene.materials[surf.material as usize];
        let d = ray.dir.normalize();
        let p = surf.point.p;
        let ng_out = surf.point.ng;
        // Both sides are surfaces: face the normals towards the incoming ray.
        let entering = ng_out.dot(d) < 0.0;
        let ng = if entering { ng_out } else { -ng_out };
        let ns = if surf.ns.dot(d) > 0.0 {
            -surf.ns
        } else {
            surf.ns
        };
        let spawn =
            |dir: Vec3| -> Ray { Ray::new(offset_ray_origin(p, surf.point.err, ng, dir), dir) };

        let mut color = scene.ambient * m.color * m.ka;
        let view = -d;
        for light in &scene.lights {
            let to_light = light.pos - p;
            // No shadow ray when the shading normal faces away from the light.
            if ns.dot(to_light) <= 0.0 {
                continue;
            }
            counts.shadow += 1;
            let mut shadow = spawn(to_light);
            shadow.dir = light.pos - shadow.org;
            shadow.tmax = next_float_down(1.0);
            if self.accel.occluded(&shadow) {
                continue;
            }
            let l = to_light.normalize();
            let ndotl = ns.dot(l);
            let mut c = m.color * (m.kd * ndotl);
            if m.ks > 0.0 {
                let r = reflect(-l, ns);
                let rv = r.dot(view).max(0.0);
                c += Vec3::splat(m.ks * rv.powf(m.shine));
            }
            color += light.color * c;
        }

        if depth >= self.max_depth {
            return color;
        }
        let mut reflect_weight = m.kr;
        if m.t > 0.0 {
            // Snell's law; the medium is decided by the geometric normal's side.
            let eta = if entering { 1.0 / m.ior } else { m.ior };
            match refract(d, ns, eta) {
                Some(dir) => {
                    counts.refraction += 1;
                    color += m.t * self.trace(&spawn(dir), depth + 1, counts);
                }
                None => {
                    // Total internal reflection: the transmitted energy is reflected.
                    counts.tir += 1;
                    reflect_weight += m.t;
                }
            }
        }
        if reflect_weight > 0.0 {
            counts.reflection += 1;
            let dir = reflect(d, ns);
            color += reflect_weight * self.trace(&spawn(dir), depth + 1, counts);
        }
        color
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reflect_mirrors_about_the_normal() {
        let r = reflect(Vec3::new(1.0, -1.0, 0.0), Vec3::Y);
        assert_eq!(r, Vec3::new(1.0, 1.0, 0.0));
    }

    #[test]
    fn refraction_obeys_snell_and_total_internal_reflection() {
        let n = Vec3::Z;
        for deg in [0.0f32, 10.0, 30.0, 45.0, 60.0, 80.0] {
            let th = deg.to_radians();
            let d = Vec3::new(th.sin(), 0.0, -th.cos());
            // Air to glass: sin θt = sin θi / 1.5.
            let t = refract(d, n, 1.0 / 1.5).unwrap();
            let sin_t = t.x;
            assert!((sin_t - th.sin() / 1.5).abs() < 1e-6, "{deg}°");
            assert!(t.z < 0.0, "goes through");
            // Glass to air: TIR beyond the critical angle asin(1/1.5) = 41.8°.
            let out = refract(d, n, 1.5);
            assert_eq!(out.is_none(), deg > 41.81, "{deg}°");
            if let Some(o) = out {
                assert!((o.x - th.sin() * 1.5).abs() < 1e-5);
            }
        }
    }

    #[test]
    fn radical_inverse_is_stratified() {
        let mut v: Vec<f32> = (0..8).map(radical_inverse).collect();
        v.sort_by(f32::total_cmp);
        for (k, x) in v.iter().enumerate() {
            assert!((*x - k as f32 / 8.0).abs() < 1e-6);
        }
    }
}
