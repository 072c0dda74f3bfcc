//! Hemicube form factors (Cohen & Greenberg 1985).
//!
//! A half cube of half-width 1 stands on the shooting element's centroid, its top face
//! at height 1 along the normal, its four side faces half-height. Every element of the
//! mesh is projected through the centroid onto the five faces and rasterised with a
//! depth buffer that keeps, per pixel, the nearest element (an item buffer). A pixel
//! at `(x, y)` on the top face carries the delta form factor
//! `ΔA / (π (x² + y² + 1)²)`, one at `(u, z)` on a side face `z ΔA / (π (u² + z² + 1)²)`;
//! the form factor from the centroid to element `j` is the sum of the deltas of the
//! pixels that see `j`. The tables are precomputed once per resolution and scaled so
//! that all deltas sum to exactly one (the midpoint rule misses the integral by
//! `O(1/res²)`), so a closed enclosure's rows sum to one up to pixels no element covers.
//!
//! Elements seen from behind occlude but receive nothing (elements are one-sided, as in
//! the ray-cast estimate). Only the meshed triangles take part: analytic primitives,
//! which the mesh leaves out, do not occlude here (they do with ray casting).
//!
//! The estimate is point-to-area from the centroid: it aliases (an element covering a
//! few pixels gets a count of whole pixels) and assumes the shooter is small against
//! its distance to the receiver; both errors fall with the resolution and the patch
//! size respectively.

use super::RadiosityError;
use super::mesh::Mesh;
use crate::math::{Frame, Vec3};
use rayon::prelude::*;

/// Default pixels across the top face.
pub const DEFAULT_RES: u32 = 128;
/// Largest resolution accepted.
pub const MAX_RES: u32 = 4096;

/// How far outside a triangle (in barycentric weight) a pixel centre may be and still
/// count: a pixel centre on an edge shared by two triangles must not slip between
/// them through rounding; if both take it, the depth test keeps one.
const SLACK: f32 = 1e-5;

/// No element seen through a pixel.
const NONE: u32 = u32::MAX;

/// One face of the hemicube: the local axis it looks along (index and sign) and the
/// two local axes that span it.
#[derive(Clone, Copy, Debug)]
struct Face {
    depth: usize,
    sign: f32,
    u: usize,
    v: usize,
    /// Top face (`v` in `[-1, 1]`) or side face (`v` in `[0, 1]`).
    top: bool,
}

const FACES: [Face; 5] = [
    Face {
        depth: 2,
        sign: 1.0,
        u: 0,
        v: 1,
        top: true,
    },
    Face {
        depth: 0,
        sign: 1.0,
        u: 1,
        v: 2,
        top: false,
    },
    Face {
        depth: 0,
        sign: -1.0,
        u: 1,
        v: 2,
        top: false,
    },
    Face {
        depth: 1,
        sign: 1.0,
        u: 0,
        v: 2,
        top: false,
    },
    Face {
        depth: 1,
        sign: -1.0,
        u: 0,
        v: 2,
        top: false,
    },
];

/// A hemicube of a given resolution with its delta form-factor tables.
#[derive(Clone, Debug)]
pub struct Hemicube {
    res: usize,
    /// Top face, `res × res`, row-major.
    top: Vec<f32>,
    /// One side face, `res` wide and `res / 2` high (row 0 at the horizon).
    side: Vec<f32>,
}

impl Hemicube {
    /// A hemicube with `res × res` pixels on the top face (`res` even, 2..=4096).
    ///
    /// # Errors
    /// A resolution out of range or odd.
    pub fn new(res: u32) -> Result<Hemicube, RadiosityError> {
        if !(2..=MAX_RES).contains(&res) || res % 2 != 0 {
            return Err(RadiosityError::Settings(format!(
                "hemicube resolution {res} must be an even number from 2 to {MAX_RES}"
            )));
        }
        let res = res as usize;
        let h = 2.0 / res as f64;
        let pi = std::f64::consts::PI;
        let centre = |k: usize| -1.0 + (k as f64 + 0.5) * h;
        let mut top = Vec::with_capacity(res * res);
        for py in 0..res {
            for px in 0..res {
                let (x, y) = (centre(px), centre(py));
                let d = x * x + y * y + 1.0;
                top.push(h * h / (pi * d * d));
            }
        }
        let mut side = Vec::with_capacity(res * res / 2);
        for pz in 0..res / 2 {
            for pu in 0..res {
                let (u, z) = (centre(pu), (pz as f64 + 0.5) * h);
                let d = u * u + z * z + 1.0;
                side.push(z * h * h / (pi * d * d));
            }
        }
        let total: f64 = top.iter().sum::<f64>() + 4.0 * side.iter().sum::<f64>();
        Ok(Hemicube {
            res,
            top: top.iter().map(|&d| (d / total) as f32).collect(),
            side: side.iter().map(|&d| (d / total) as f32).collect(),
        })
    }

    #[cfg(test)]
    /// Sum of all delta form factors (one, up to rounding).
    pub fn delta_sum(&self) -> f64 {
        self.top.iter().map(|&d| d as f64).sum::<f64>()
            + 4.0 * self.side.iter().map(|&d| d as f64).sum::<f64>()
    }

    /// The form factors `F_ij` from element `i` to every element `j` of `mesh`, from a
    /// hemicube on `i`'s centroid.
    pub fn row(&self, mesh: &Mesh, i: usize) -> Vec<f32> {
        let e = &mesh.elements[i];
        let near = 1e-3 * e.area.sqrt();
        self.row_from(mesh, e.centroid(), e.n, near, Some(i))
    }

    /// The form factors from a differential area at `x` with unit normal `n` to every
    /// element of `mesh` (element `skip` excluded), clipping geometry nearer than
    /// `near` along each face's axis.
    pub fn row_from(
        &self,
        mesh: &Mesh,
        x: Vec3,
        n: Vec3,
        near: f32,
        skip: Option<usize>,
    ) -> Vec<f32> {
        let frame = Frame::from_z(n);
        // Corners in the hemicube's frame, and whether the element's front faces `x`.
        let local: Vec<([Vec3; 3], bool)> = mesh
            .elements
            .iter()
            .map(|el| {
                let l =
                    el.p.map(|p| p - x)
                        .map(|d| Vec3::new(d.dot(frame.x), d.dot(frame.y), d.dot(frame.z)));
                (l, el.n.dot(x - el.p[0]) > 0.0)
            })
            .collect();
        let per_face: Vec<Vec<f32>> = FACES
            .par_iter()
            .map(|face| self.face(face, &local, near.max(f32::MIN_POSITIVE), skip))
            .collect();
        let mut row = vec![0.0f32; mesh.elements.len()];
        for sums in per_face {
            for (r, f) in row.iter_mut().zip(sums) {
                *r += f;
            }
        }
        row
    }

    /// Rasterise every element onto one face; the delta form factors summed per
    /// visible element.
    fn face(
        &self,
        face: &Face,
        local: &[([Vec3; 3], bool)],
        near: f32,
        skip: Option<usize>,
    ) -> Vec<f32> {
        let width = self.res;
        let height = if face.top { self.res } else { self.res / 2 };
        let mut depth = vec![0.0f32; width * height];
        let mut item = vec![NONE; width * height];
        let scale = self.res as f32 / 2.0;
        let v0 = if face.top { -1.0 } else { 0.0 };
        for (j, (l, front)) in local.iter().enumerate() {
            if Some(j) == skip {
                continue;
            }
            // (depth, u, v) per corner, clipped to depth ≥ near.
            if l.iter().all(|p| p.z <= 0.0) {
                continue;
            }
            let cuv = l.map(|p| {
                let a = p.to_array();
                Vec3::new(face.sign * a[face.depth], a[face.u], a[face.v])
            });
            if cuv.iter().all(|p| p.x < near) {
                continue;
            }
            let mut poly: smallvec::SmallVec<[Vec3; 4]> = smallvec::SmallVec::new();
            for k in 0..3 {
                let (p, q) = (cuv[k], cuv[(k + 1) % 3]);
                if p.x >= near {
                    poly.push(p);
                }
                if (p.x >= near) != (q.x >= near) {
                    let t = (near - p.x) / (q.x - p.x);
                    poly.push(p + (q - p) * t);
                }
            }
            // Pixel coordinates and inverse depth (linear in screen space).
            let scr: smallvec::SmallVec<[Vec3; 4]> = poly
                .iter()
                .map(|p| {
                    let w = 1.0 / p.x;
                    Vec3::new((p.y * w + 1.0) * scale, (p.z * w - v0) * scale, w)
                })
                .collect();
            let id = if *front { j as u32 } else { NONE };
            for k in 1..scr.len().saturating_sub(1) {
                raster(
                    [scr[0], scr[k], scr[k + 1]],
                    width,
                    height,
                    id,
                    &mut depth,
                    &mut item,
                );
            }
        }
        let table = if face.top { &self.top } else { &self.side };
        let mut sums = vec![0.0f32; local.len()];
        for (&j, &d) in item.iter().zip(table) {
            if j != NONE {
                sums[j as usize] += d;
            }
        }
        sums
    }
}

/// Rasterise one screen-space triangle (`x`, `y` in pixels, `z` = inverse depth) with
/// pixel-centre sampling, keeping the nearest (largest inverse depth) per pixel.
fn raster(t: [Vec3; 3], width: usize, height: usize, id: u32, depth: &mut [f32], item: &mut [u32]) {
    let area = (t[1].x - t[0].x) * (t[2].y - t[0].y) - (t[2].x - t[0].x) * (t[1].y - t[0].y);
    if area == 0.0 || !area.is_finite() {
        return;
    }
    let lo = t[0].min(t[1]).min(t[2]);
    let hi = t[0].max(t[1]).max(t[2]);
    let x0 = (lo.x - 0.5).ceil().max(0.0);
    let y0 = (lo.y - 0.5).ceil().max(0.0);
    let x1 = (hi.x - 0.5).floor().min(width as f32 - 1.0);
    let y1 = (hi.y - 0.5).floor().min(height as f32 - 1.0);
    if x0 > x1 || y0 > y1 {
        return;
    }
    // Barycentric weights as edge functions a (x - o.x) + b (y - o.y) from a corner o
    // of each edge (well conditioned even for huge clipped triangles), normalised by
    // the signed area so that all three are ≥ 0 inside whatever the winding.
    let inv = 1.0 / area;
    let edge = |p: Vec3, q: Vec3| ((p.y - q.y) * inv, (q.x - p.x) * inv, p);
    let e = [edge(t[1], t[2]), edge(t[2], t[0]), edge(t[0], t[1])];
    for py in y0 as usize..=y1 as usize {
        let y = py as f32 + 0.5;
        let row = e.map(|(_, b, o)| b * (y - o.y));
        for px in x0 as usize..=x1 as usize {
            let x = px as f32 + 0.5;
            let w = [
                e[0].0 * (x - e[0].2.x) + row[0],
                e[1].0 * (x - e[1].2.x) + row[1],
                e[2].0 * (x - e[2].2.x) + row[2],
            ];
            if w[0] < -SLACK || w[1] < -SLACK || w[2] < -SLACK {
                continue;
            }
            let z = w[0] * t[0].z + w[1] * t[1].z + w[2] * t[2].z;
            let p = py * width + px;
            if z > depth[p] {
                depth[p] = z;
                item[p] = id;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn delta_tables_sum_to_one_and_match_the_formulas_up_to_the_normalisation() {
        let h = Hemicube::new(64).unwrap();
        assert!((h.delta_sum() - 1.0).abs() < 1e-5, "{}", h.delta_sum());
        // The raw midpoint sum is within 0.1% of one at this resolution, so the
        // normalised entries stay within 0.1% of the formulas.
        let d = 2.0f64 / 64.0;
        let pi = std::f64::consts::PI;
        let (x, y) = (-1.0 + 0.5 * d, -1.0 + 0.5 * d);
        let expect = d * d / (pi * (x * x + y * y + 1.0).powi(2));
        assert!(((h.top[0] as f64 - expect) / expect).abs() < 1e-3);
        let (u, z) = (-1.0 + 0.5 * d, 0.5 * d);
        let expect = z * d * d / (pi * (u * u + z * z + 1.0).powi(2));
        assert!(((h.side[0] as f64 - expect) / expect).abs() < 1e-3);
        assert!(Hemicube::new(3).is_err());
        assert!(Hemicube::new(0).is_err());
    }
}
