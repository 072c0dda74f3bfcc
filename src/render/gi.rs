//! Global illumination as an input of the renderer: a view-independent solution
//! (radiosity fills one in) that tells the diffuse light leaving a hit. The Whitted
//! tracer uses it in two-pass mode ([`render_with_gi`](super::render_with_gi)), and
//! [`view`] looks at it alone.

use super::{Film, RayGen};
use crate::accel::{Accel, Hit};
use crate::math::Vec3;
use crate::scene::Scene;
use rayon::prelude::*;

/// A solved diffuse light field the renderer can look up at any hit.
pub trait GlobalIllumination: Sync {
    /// The radiosity (diffuse light leaving the surface, in the units of an area
    /// light's direct term) at a hit at point `p` seen along `dir`; `None` where the
    /// solution does not cover the surface (the renderer then shades it itself).
    fn radiosity_at(&self, hit: &Hit, p: Vec3, dir: Vec3) -> Option<Vec3>;
}

/// Look at `gi` from the scene's camera (`width × height`, `spp²` stratified samples
/// per pixel): its radiosity where it covers the surface, the material colour times
/// the scene's ambient on other primitives, the background on misses.
pub fn view<A: Accel>(
    scene: &Scene,
    accel: &A,
    gi: &dyn GlobalIllumination,
    width: u32,
    height: u32,
    spp: u32,
) -> Film {
    let raygen = RayGen::new(&scene.camera, width, height);
    let n = spp.max(1);
    let rows: Vec<Vec<Vec3>> = (0..height)
        .into_par_iter()
        .map(|j| {
            (0..width)
                .map(|i| {
                    let mut sum = Vec3::ZERO;
                    for sy in 0..n {
                        for sx in 0..n {
                            let ray = raygen.ray(
                                i as f32 + (sx as f32 + 0.5) / n as f32,
                                j as f32 + (sy as f32 + 0.5) / n as f32,
                            );
                            sum += match accel.intersect(&ray) {
                                None => scene.background,
                                Some(hit) => gi
                                    .radiosity_at(&hit, ray.at(hit.t), ray.dir)
                                    .unwrap_or_else(|| {
                                        let surf = scene.surface(&hit, &ray);
                                        scene.materials[surf.material as usize].color
                                            * scene.ambient
                                    }),
                            };
                        }
                    }
                    sum / (n * n) as f32
                })
                .collect()
        })
        .collect();
    let mut film = Film::new(width, height);
    for (j, row) in rows.into_iter().enumerate() {
        for (i, v) in row.into_iter().enumerate() {
            film.set(i as u32, j as u32, v);
        }
    }
    film
}
