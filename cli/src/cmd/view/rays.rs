//! The clicked pixel's rays where they appear in the image: each ray of its explain
//! tree (eye, reflection, refraction, and the shadow rays to the point lights) as a
//! segment in the image's pixels, projected by the render's own eye-ray generator
//! ([`RayGen::project_segment`]): the part in front of the eye, cut to the image.

use emray::math::{DVec3, Vec3};
use emray::render::RayGen;
use emray::render::explain::{Explanation, RayNode};
use emray::scene::Scene;
use serde::Serialize;

/// One ray, projected.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Segment {
    /// Where it is in the tree: the position's and the sample's index, then each
    /// child's (`0.0.1`), and `sN` for the shadow ray of the hit's `N`th point light.
    pub path: String,
    /// `eye`, `reflection`, `refraction` or `shadow`.
    pub kind: &'static str,
    /// Its depth in the tree (the eye ray's is 1; a shadow ray has its hit's).
    pub depth: u32,
    /// How it ends: `hit`, `miss` (it leaves the scene), `light` (a shadow ray that
    /// reached its light) or `blocked` (one that met something).
    pub ends: &'static str,
    /// The part of it that shows, in pixels (`[x, y]`, `(0, 0)` the image's top left
    /// corner), from its origin's side; `None` when none of it does.
    pub line: Option<[[f32; 2]; 2]>,
    /// Where its far end (the hit, the light; far along a miss) projects, inside the
    /// image or not; `None` when that end is not in front of the eye.
    pub end: Option<[f32; 2]>,
}

/// The projection of one render's rays.
struct Projector {
    raygen: RayGen,
    /// From a world point to the scene's frame.
    origin: DVec3,
    /// The sample grid's position of an image point: `-0.5` for SPD's corner rays.
    offset: f32,
    /// The near plane.
    near: f32,
    /// How far a miss is drawn, beyond its distance from the eye.
    reach: f32,
    /// The image's size.
    size: [f32; 2],
}

impl Projector {
    fn point(&self, p: [f64; 3]) -> Vec3 {
        (DVec3::from(p) - self.origin).as_vec3()
    }

    fn pixel(&self, (x, y): (f32, f32)) -> [f32; 2] {
        [x + self.offset, y + self.offset]
    }

    /// The segment from `a` to `b` (scene frame), and where `b` projects.
    fn segment(&self, a: Vec3, b: Vec3) -> (Option<[[f32; 2]; 2]>, Option<[f32; 2]>) {
        let end = (self.raygen.depth(b) >= self.near)
            .then(|| self.raygen.project(b))
            .flatten()
            .map(|p| self.pixel(p));
        let line = self
            .raygen
            .project_segment(a, b, self.near)
            .and_then(|[p, q]| clip(self.pixel(p), self.pixel(q), self.size));
        (line, end)
    }

    /// `ray` and its subtree, at `path`.
    fn ray(&self, ray: &RayNode, path: String, out: &mut Vec<Segment>) {
        let from = self.point(ray.origin);
        let dir = Vec3::from(ray.direction);
        let (to, ends) = match &ray.hit {
            Some(hit) => (self.point(hit.point), "hit"),
            None => {
                let far = self.reach + from.length();
                (from + dir.normalize_or_zero() * far, "miss")
            }
        };
        let (line, end) = self.segment(from, to);
        out.push(Segment {
            path: path.clone(),
            kind: ray.kind.name(),
            depth: ray.depth,
            ends,
            line,
            end,
        });
        let Some(hit) = &ray.hit else { return };
        for (i, light) in hit.lights.iter().enumerate() {
            let Some(s) = &light.shadow_ray else { continue };
            let a = self.point(s.origin);
            let b = a + Vec3::from(s.direction) * s.tmax;
            let (line, end) = self.segment(a, b);
            out.push(Segment {
                path: format!("{path}.s{i}"),
                kind: "shadow",
                depth: ray.depth,
                ends: if s.occluded { "blocked" } else { "light" },
                line,
                end,
            });
        }
        for (i, child) in hit.children.iter().enumerate() {
            self.ray(child, format!("{path}.{i}"), out);
        }
    }
}

/// Every ray of `e`, a pixel of `scene`, projected into its image, in the tree's order.
pub fn segments(scene: &Scene, e: &Explanation) -> Vec<Segment> {
    let cam = &scene.camera;
    let (grid, offset) = if e.spd {
        ((e.width + 1, e.height + 1), -0.5)
    } else {
        ((e.width, e.height), 0.0)
    };
    let scale = (cam.at - cam.from).length();
    let p = Projector {
        raygen: RayGen::new(cam, grid.0, grid.1),
        origin: scene.origin,
        offset,
        near: scale * 1e-3,
        reach: scale * 1e3,
        size: [e.width as f32, e.height as f32],
    };
    let mut out = Vec::new();
    for (i, position) in e.positions.iter().enumerate() {
        for (j, sample) in position.samples.iter().enumerate() {
            p.ray(sample, format!("{i}.{j}"), &mut out);
        }
    }
    out
}

/// The part of the segment `a`–`b` inside `[0, w] × [0, h]` (Liang–Barsky).
fn clip(a: [f32; 2], b: [f32; 2], [w, h]: [f32; 2]) -> Option<[[f32; 2]; 2]> {
    let d = [b[0] - a[0], b[1] - a[1]];
    let (mut t0, mut t1) = (0.0f32, 1.0f32);
    // Each edge as `p·t ≤ q`.
    for (p, q) in [
        (-d[0], a[0]),
        (d[0], w - a[0]),
        (-d[1], a[1]),
        (d[1], h - a[1]),
    ] {
        if p == 0.0 {
            if q < 0.0 {
                return None;
            }
        } else {
            let t = q / p;
            if p < 0.0 {
                t0 = t0.max(t);
            } else {
                t1 = t1.min(t);
            }
        }
    }
    let at = |t: f32| [a[0] + d[0] * t, a[1] + d[1] * t];
    (t0 <= t1).then(|| [at(t0), at(t1)])
}

#[cfg(test)]
mod tests {
    use super::clip;

    #[test]
    fn clip_keeps_the_inside_and_cuts_the_rest() {
        let size = [10.0, 10.0];
        let inside = [[1.0, 2.0], [3.0, 4.0]];
        assert_eq!(clip(inside[0], inside[1], size), Some(inside));
        assert_eq!(
            clip([-5.0, 5.0], [15.0, 5.0], size),
            Some([[0.0, 5.0], [10.0, 5.0]])
        );
        assert_eq!(clip([-5.0, -5.0], [-1.0, 20.0], size), None);
        // A point inside stays a point.
        assert_eq!(
            clip([4.5, 4.5], [4.5, 4.5], size),
            Some([[4.5, 4.5], [4.5, 4.5]])
        );
    }
}
