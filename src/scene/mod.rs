//! The backend-free scene: camera, lights, materials and primitives. No I/O here; the
//! loaders in [`crate::load`] build it and the backends in [`crate::accel`] read it.

use crate::geometry::{Cone, Kind, Shape, Sphere, SurfacePoint, Triangle};
use crate::math::{Ray, Vec3};
use crate::Hit;

/// The NFF viewpoint (`v`): see DESIGN.md §3 for the exact ray construction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Eye position.
    pub from: Vec3,
    /// Point looked at.
    pub at: Vec3,
    /// Up vector (not necessarily unit or perpendicular to the view direction).
    pub up: Vec3,
    /// Full angle in degrees between the centres of the top and bottom pixel rows.
    pub angle_deg: f32,
    /// Hither (near clipping) distance; eye rays start at the origin regardless, as in
    /// the SPD's reference renderers.
    pub hither: f32,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
}

/// A point light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Light {
    /// Position.
    pub pos: Vec3,
    /// Intensity per channel.
    pub color: Vec3,
}

/// NFF fill material (`f r g b Kd Ks Shine T ior`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    /// Surface colour.
    pub color: Vec3,
    /// Ambient weight (NFF has none: Ka = Kd).
    pub ka: f32,
    /// Diffuse weight.
    pub kd: f32,
    /// Phong highlight weight and mirror reflectance.
    pub ks: f32,
    /// Phong exponent.
    pub shine: f32,
    /// Transmittance: the weight of the refracted ray.
    pub t: f32,
    /// Index of refraction.
    pub ior: f32,
}

impl Default for Material {
    /// White, fully diffuse: what a primitive before any `f` gets.
    fn default() -> Self {
        Material {
            color: Vec3::ONE,
            ka: 1.0,
            kd: 1.0,
            ks: 0.0,
            shine: 0.0,
            t: 0.0,
            ior: 1.0,
        }
    }
}

/// Primitives of one kind with a material index each.
#[derive(Clone, Debug, PartialEq)]
pub struct Prims<T> {
    /// The primitives; a primitive's index is its `prim_id`.
    pub items: Vec<T>,
    /// Material index per primitive.
    pub material: Vec<u32>,
}

impl<T> Default for Prims<T> {
    fn default() -> Self {
        Prims {
            items: Vec::new(),
            material: Vec::new(),
        }
    }
}

impl<T> Prims<T> {
    /// Append one primitive.
    pub fn push(&mut self, item: T, material: u32) {
        self.items.push(item);
        self.material.push(material);
    }

    /// Number of primitives.
    pub fn len(&self) -> usize {
        self.items.len()
    }

    /// True when there are none.
    pub fn is_empty(&self) -> bool {
        self.items.is_empty()
    }
}

/// Counts of what the loader saw, for `--stats`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LoadStats {
    /// Polygons read (`p` and `pp`).
    pub polygons: usize,
    /// Degenerate polygons or triangles dropped (zero area, fewer than 3 distinct vertices).
    pub degenerate_dropped: usize,
}

/// A whole scene.
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    /// Camera.
    pub camera: Camera,
    /// Colour of rays that hit nothing.
    pub background: Vec3,
    /// Point lights.
    pub lights: Vec<Light>,
    /// Ambient light intensity.
    pub ambient: Vec3,
    /// Materials, indexed by the primitives.
    pub materials: Vec<Material>,
    /// Triangles.
    pub triangles: Prims<Triangle>,
    /// Per triangle: index into `vertex_normals`, or `u32::MAX` for flat shading.
    pub triangle_normals: Vec<u32>,
    /// Per-vertex shading normals of smooth (`pp`) triangles.
    pub vertex_normals: Vec<[Vec3; 3]>,
    /// Spheres.
    pub spheres: Prims<Sphere>,
    /// Open cones and cylinders.
    pub cones: Prims<Cone>,
    /// What the loader counted.
    pub load_stats: LoadStats,
}

/// Everything shading needs about a hit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Surface {
    /// Accurate point, its error bound and unit geometric normal.
    pub point: SurfacePoint,
    /// Unit shading normal (interpolated for `pp` polygons, else the geometric one),
    /// not yet faced towards the ray.
    pub ns: Vec3,
    /// Material index.
    pub material: u32,
}

/// The NFF convention for lights given without a colour: `√n / (2n)` for `n` lights.
pub fn default_light_intensity(n: usize) -> f32 {
    let n = n.max(1) as f32;
    n.sqrt() / (2.0 * n)
}

impl Scene {
    /// An empty scene with the given camera, a black background and no lights.
    pub fn new(camera: Camera) -> Self {
        Scene {
            camera,
            background: Vec3::ZERO,
            lights: Vec::new(),
            ambient: Vec3::splat(default_light_intensity(0)),
            materials: Vec::new(),
            triangles: Prims::default(),
            triangle_normals: Vec::new(),
            vertex_normals: Vec::new(),
            spheres: Prims::default(),
            cones: Prims::default(),
            load_stats: LoadStats::default(),
        }
    }

    /// Number of primitives of `kind`.
    pub fn count(&self, kind: Kind) -> usize {
        match kind {
            Kind::Triangle => self.triangles.len(),
            Kind::Sphere => self.spheres.len(),
            Kind::Cone => self.cones.len(),
        }
    }

    /// Total number of primitives.
    pub fn prim_count(&self) -> usize {
        Kind::ALL.iter().map(|&k| self.count(k)).sum()
    }

    /// The analytic shape with geometry id `kind` and index `prim`
    /// (`None` for triangles).
    #[inline]
    pub fn shape(&self, kind: Kind, prim: u32) -> Option<Shape> {
        match kind {
            Kind::Triangle => None,
            Kind::Sphere => Some(Shape::Sphere(self.spheres.items[prim as usize])),
            Kind::Cone => Some(Shape::Cone(self.cones.items[prim as usize])),
        }
    }

    /// The surface at a hit reported by a backend for `ray`.
    pub fn surface(&self, hit: &Hit, ray: &Ray) -> Surface {
        let kind = Kind::from_id(hit.geom_id).expect("backend reported an unknown geometry");
        let i = hit.prim_id as usize;
        match kind {
            Kind::Triangle => {
                let tri = &self.triangles.items[i];
                let point = tri.surface(hit.u, hit.v);
                let ns = match self.triangle_normals[i] {
                    u32::MAX => point.ng,
                    k => {
                        let n = self.vertex_normals[k as usize];
                        let w = 1.0 - hit.u - hit.v;
                        (n[0] * w + n[1] * hit.u + n[2] * hit.v).normalize_or(point.ng)
                    }
                };
                Surface {
                    point,
                    ns,
                    material: self.triangles.material[i],
                }
            }
            Kind::Sphere => {
                let point = self.spheres.items[i].surface(ray, hit.t);
                Surface {
                    point,
                    ns: point.ng,
                    material: self.spheres.material[i],
                }
            }
            Kind::Cone => {
                let point = self.cones.items[i].surface(ray, hit.t);
                Surface {
                    point,
                    ns: point.ng,
                    material: self.cones.material[i],
                }
            }
        }
    }
}
