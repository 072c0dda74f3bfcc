//! Eye rays from the NFF viewpoint: a right-handed frame from `from`, `at` and `up`,
//! `angle` spanning the centres of the top and bottom rows of samples, square pixels
//! (docs/nff.md, "NFF conventions"; docs/architecture.md, "Camera").

use crate::math::{Ray, Vec3};
use crate::scene::Camera;

/// Precomputed eye-ray generator for one sample grid.
#[derive(Clone, Copy, Debug)]
pub struct RayGen {
    from: Vec3,
    forward: Vec3,
    right: Vec3,
    up: Vec3,
    half_w: f32,
    half_h: f32,
}

impl RayGen {
    /// Rays for a grid of `width × height` sample positions whose outer rows of sample
    /// centres span the camera's full `angle` vertically; pixels are square.
    pub fn new(cam: &Camera, width: u32, height: u32) -> Self {
        let forward = unit(cam.at - cam.from);
        let right = unit(forward.cross(cam.up));
        let up = right.cross(forward);
        let half_angle = (cam.angle_deg.to_radians() * 0.5).tan();
        let scale = half_angle / ((height.max(2) - 1) as f32 * 0.5);
        RayGen {
            from: cam.from,
            forward,
            right: right * scale,
            up: up * scale,
            half_w: width as f32 * 0.5,
            half_h: height as f32 * 0.5,
        }
    }

    /// The ray through continuous position `(px, py)`: pixel `(i, j)` covers
    /// `[i, i+1) × [j, j+1)`, `i` from the left and `j` from the top, so its centre is
    /// `(i + 0.5, j + 0.5)`.
    #[inline]
    pub fn ray(&self, px: f32, py: f32) -> Ray {
        let x = px - self.half_w;
        let y = self.half_h - py;
        let dir = (self.forward + self.right * x + self.up * y).normalize();
        Ray::new(self.from, dir)
    }

    /// How far `p` lies in front of the eye, along the view direction (negative
    /// behind it).
    #[inline]
    pub fn depth(&self, p: Vec3) -> f32 {
        (p - self.from).dot(self.forward)
    }

    /// The continuous position `(px, py)` whose ray passes through `p`: the inverse of
    /// [`RayGen::ray`], so `project(ray(px, py).at(t)) ≈ (px, py)` for every `t > 0`.
    /// `None` for a point not in front of the eye (or a camera without a frame).
    pub fn project(&self, p: Vec3) -> Option<(f32, f32)> {
        let z = self.depth(p);
        if z.is_nan() || z <= 0.0 {
            return None;
        }
        // The ray's direction is `forward + right·x + up·y` (up to its length), with
        // `right` and `up` orthogonal to `forward` and to each other.
        let q = (p - self.from) / z;
        let x = q.dot(self.right) / self.right.length_squared();
        let y = q.dot(self.up) / self.up.length_squared();
        let (px, py) = (x + self.half_w, self.half_h - y);
        (px.is_finite() && py.is_finite()).then_some((px, py))
    }

    /// The segment from `a` to `b` projected: its part at least `near` in front of the
    /// eye (`near > 0`), so a segment that passes behind the camera is cut where it
    /// crosses that plane; `None` when none of it is.
    pub fn project_segment(&self, a: Vec3, b: Vec3, near: f32) -> Option<[(f32, f32); 2]> {
        let (za, zb) = (self.depth(a), self.depth(b));
        if za.is_nan() || zb.is_nan() || (za < near && zb < near) {
            return None;
        }
        let cut = |p: Vec3, zp: f32, q: Vec3, zq: f32| {
            if zp >= near {
                p
            } else {
                p + (q - p) * ((near - zp) / (zq - zp))
            }
        };
        let (a, b) = (cut(a, za, b, zb), cut(b, zb, a, za));
        Some([self.project(a)?, self.project(b)?])
    }
}

/// `v` normalised, also when its squared length overflows or underflows f32 (a huge or
/// tiny `up`, `at` a hair from `from`): such a vector is first scaled by its largest
/// component. Zero stays zero (the loaders refuse the cameras that would give it).
fn unit(v: Vec3) -> Vec3 {
    v.try_normalize().unwrap_or_else(|| {
        let m = v.abs().max_element();
        if m > 0.0 && m.is_finite() {
            (v / m).normalize()
        } else {
            Vec3::ZERO
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cam(w: u32, h: u32, angle: f32) -> Camera {
        Camera {
            from: Vec3::new(0.0, 0.0, 5.0),
            at: Vec3::ZERO,
            up: Vec3::new(0.0, 3.0, 0.5),
            angle_deg: angle,
            hither: 1.0,
            width: w,
            height: h,
        }
    }

    #[test]
    fn outer_row_centres_span_the_angle() {
        let c = cam(64, 64, 40.0);
        let g = RayGen::new(&c, 64, 64);
        let top = g.ray(32.0, 0.5).dir;
        let bottom = g.ray(32.0, 63.5).dir;
        let angle = top.angle_between(bottom).to_degrees();
        assert!((angle - 40.0).abs() < 1e-3, "{angle}");
        assert!(top.y > 0.0 && bottom.y < 0.0, "top row looks up");
        let left = g.ray(0.5, 32.0).dir;
        let right = g.ray(63.5, 32.0).dir;
        assert!(
            left.x < 0.0 && right.x > 0.0,
            "right-handed: +x to the right"
        );
        assert!((left.angle_between(right).to_degrees() - 40.0).abs() < 1e-3);
    }

    #[test]
    fn centre_ray_looks_at_target_and_pixels_are_square() {
        let c = cam(200, 100, 30.0);
        let g = RayGen::new(&c, 200, 100);
        let d = g.ray(100.0, 50.0).dir;
        assert!((d - Vec3::new(0.0, 0.0, -1.0)).length() < 1e-6);
        // One pixel step subtends the same angle horizontally and vertically at the centre.
        let dx = g.ray(101.0, 50.0).dir.angle_between(d);
        let dy = g.ray(100.0, 51.0).dir.angle_between(d);
        assert!((dx - dy).abs() < 1e-6);
    }

    /// A point anywhere along a pixel's ray projects back to that pixel.
    #[test]
    fn project_inverts_ray() {
        for (w, h, angle) in [(64, 48, 40.0), (200, 100, 30.0), (17, 301, 90.0)] {
            let g = RayGen::new(&cam(w, h, angle), w, h);
            for (px, py) in [(0.5, 0.5), (w as f32 - 0.5, 3.25), (10.0, h as f32 - 1.0)] {
                let r = g.ray(px, py);
                for t in [0.01f32, 1.0, 4.9, 37.0, 1e4] {
                    let (x, y) = g.project(r.at(t)).expect("in front");
                    let err = (x - px).abs().max((y - py).abs());
                    assert!(err < 1e-2, "({px}, {py}) at t {t}: ({x}, {y})");
                }
                // Behind the eye: nothing.
                assert_eq!(g.project(r.org - r.dir), None);
            }
        }
    }

    /// A segment from behind the eye to a point in front is cut at the near plane,
    /// and its visible end keeps its projection.
    #[test]
    fn segments_are_cut_at_the_near_plane() {
        let c = cam(64, 64, 40.0);
        let g = RayGen::new(&c, 64, 64);
        let hit = g.ray(20.5, 40.5).at(3.0);
        let behind = c.from + (c.from - c.at);
        let [a, b] = g
            .project_segment(behind, hit, 0.1)
            .expect("partly in front");
        assert!(
            (b.0 - 20.5).abs() < 1e-3 && (b.1 - 40.5).abs() < 1e-3,
            "{b:?}"
        );
        assert!(a.0.is_finite() && a.1.is_finite(), "{a:?}");
        assert!(g.depth(behind) < 0.0);
        assert_eq!(g.project_segment(behind, behind * 2.0, 0.1), None);
        // The eye ray itself, from the eye: a point, at its pixel.
        let r = g.ray(7.5, 8.5);
        let [a, b] = g.project_segment(r.org, r.at(2.0), 0.01).unwrap();
        for p in [a, b] {
            assert!(
                (p.0 - 7.5).abs() < 1e-3 && (p.1 - 8.5).abs() < 1e-3,
                "{p:?}"
            );
        }
    }

    /// An `up` whose square overflows f32, or underflows to zero, still gives the
    /// camera frame it points to.
    #[test]
    fn huge_and_tiny_up_vectors_give_the_same_frame() {
        let reference = RayGen::new(&cam(16, 16, 40.0), 16, 16).ray(3.5, 9.5).dir;
        for scale in [1e30f32, 1e-30, 3e38] {
            let mut c = cam(16, 16, 40.0);
            c.up = Vec3::new(0.0, 3.0, 0.5) * (scale / 3.0);
            let d = RayGen::new(&c, 16, 16).ray(3.5, 9.5).dir;
            assert!(
                (d - reference).length() < 1e-6,
                "{scale}: {d} vs {reference}"
            );
        }
    }
}
