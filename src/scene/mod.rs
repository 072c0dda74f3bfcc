//! The backend-free scene: camera, lights, materials and primitives. No I/O here; the
//! loaders in [`crate::load`] build it and the backends in [`crate::accel`] read it.

use crate::geometry::{Kind, Param, SurfacePoint};
use crate::math::{DVec3, Ray, Vec3, Xform};
use glam::Vec2;

mod hit;
pub mod range;
mod sources;
mod store;
pub mod texture;

pub use hit::{Hit, NO_INSTANCE};
pub use sources::{Origin, PrimSources, Sources};
pub use store::{Geometry, GeometryMark, KindVisitor, Prims, ShapeEntry};

pub use texture::{Environment, Maps, NO_TEXTURE, Texture};

/// The NFF viewpoint (`v`); [`crate::render::RayGen`] builds the eye rays from it.
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

/// A point light, optionally a spot light, with OpenGL-style distance attenuation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Light {
    /// Position.
    pub pos: Vec3,
    /// Intensity per channel.
    pub color: Vec3,
    /// Spot-light cone, if any.
    pub spot: Option<Spot>,
    /// Constant, linear and quadratic attenuation coefficients: the intensity at
    /// distance `d` is divided by `c + l·d + q·d²`. `(1, 0, 0)`: none (NFF lights).
    pub attenuation: Vec3,
}

/// The cone of a spot light (OpenGL's `GL_SPOT_*` model).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spot {
    /// Unit direction the spot points to.
    pub dir: Vec3,
    /// Cosine of the cutoff half-angle: no light outside the cone.
    pub cos_cutoff: f32,
    /// Falloff exponent: inside the cone, intensity × `cos(angle)^exponent`.
    pub exponent: f32,
}

impl Light {
    /// A point light without attenuation (NFF's `l`).
    pub fn point(pos: Vec3, color: Vec3) -> Light {
        Light {
            pos,
            color,
            spot: None,
            attenuation: Vec3::X,
        }
    }

    /// The light's intensity arriving at `p` (before shadowing and the surface's
    /// response): colour × attenuation × spot factor.
    #[inline]
    pub fn intensity_at(&self, p: Vec3) -> Vec3 {
        let mut k = 1.0;
        if self.attenuation != Vec3::X {
            let d = (p - self.pos).length();
            let a = self.attenuation;
            k /= a.x + a.y * d + a.z * d * d;
        }
        if let Some(spot) = &self.spot {
            let c = (p - self.pos).normalize_or_zero().dot(spot.dir);
            if c < spot.cos_cutoff {
                return Vec3::ZERO;
            }
            if spot.exponent != 0.0 {
                k *= c.max(0.0).powf(spot.exponent);
            }
        }
        self.color * k
    }
}

/// A Whitted material (NFF's `f r g b Kd Ks Shine T ior`, extended by the scene format
/// with its own ambient weight, a mirror reflectance apart from the highlight and a
/// priority for nested dielectrics).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    /// Surface colour.
    pub color: Vec3,
    /// Ambient weight (NFF has none: Ka = Kd).
    pub ka: f32,
    /// Diffuse weight.
    pub kd: f32,
    /// Phong highlight weight.
    pub ks: f32,
    /// Phong exponent.
    pub shine: f32,
    /// Mirror reflectance: the weight of the reflected ray (NFF: Ks).
    pub kr: f32,
    /// Transmittance: the weight of the refracted ray.
    pub t: f32,
    /// Index of refraction.
    pub ior: f32,
    /// Transmission filter of the medium: light refracted into it is multiplied by it
    /// (a tinted liquid or glass); white for NFF materials.
    pub filter: Vec3,
    /// Nested-dielectric priority (Schmidt & Budge 2002): where transmissive solids
    /// overlap, the one with the highest priority is the medium, and the surfaces of
    /// the others inside it are skipped. Equal priorities: every surface counts.
    pub priority: u32,
    /// Emitted radiosity (power per unit area, per channel) of an area light: surfaces
    /// with a nonzero emission are the lights of the radiosity pass and area lights
    /// of the Whitted renderer. Black for everything else.
    pub emission: Vec3,
    /// Texture, bump and normal maps ([`Maps::NONE`] for a plain material).
    pub maps: Maps,
}

impl Material {
    /// White, fully diffuse: what a primitive before any `f` gets.
    pub const DEFAULT: Material = Material {
        color: Vec3::ONE,
        ka: 1.0,
        kd: 1.0,
        ks: 0.0,
        shine: 0.0,
        kr: 0.0,
        t: 0.0,
        ior: 1.0,
        filter: Vec3::ONE,
        priority: 0,
        emission: Vec3::ZERO,
        maps: Maps::NONE,
    };

    /// Whether the material emits light.
    pub fn is_emitter(&self) -> bool {
        self.emission.max_element() > 0.0
    }
}

impl Default for Material {
    fn default() -> Self {
        Material::DEFAULT
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

/// Material index meaning "the material of the instance that places this object".
pub const INHERIT: u32 = u32::MAX;

/// An object placed in the scene under an affine transform.
#[derive(Clone, Debug, PartialEq)]
pub struct Instance {
    /// Index into [`Scene::objects`].
    pub object: u32,
    /// Object to world.
    pub xform: Xform,
    /// Material of the object's primitives whose material is [`INHERIT`].
    pub material: u32,
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
    /// The top-level primitives.
    pub geometry: Geometry,
    /// Objects that [`Scene::instances`] place (one level of instancing).
    pub objects: Vec<Geometry>,
    /// Placed objects.
    pub instances: Vec<Instance>,
    /// Render settings the scene file asks for (the command line overrides them).
    pub render: RenderHints,
    /// What the loader counted.
    pub load_stats: LoadStats,
    /// Textures that materials' [`Maps`] index.
    pub textures: Vec<Texture>,
    /// Environment map for rays that leave the scene (replaces `background`).
    pub environment: Option<Environment>,
    /// Where the scene's zero lies in the world its file describes. The loaders read
    /// coordinates in double precision and translate the whole scene (geometry, lights,
    /// camera, instance transforms) by this one origin, the camera's eye, before they
    /// become single precision: the picture then keeps its detail however far from the
    /// world's origin the scene is. Everything in the scene is in this frame; add the
    /// origin back for world coordinates ([`Scene::to_world`]).
    pub origin: DVec3,
    /// Where the materials, lights and instances were defined (the primitives' origins
    /// are in each [`Geometry`]'s `sources`).
    pub sources: SceneSources,
}

/// Where the items of a scene's lists were defined, as far as the loader recorded it.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct SceneSources {
    /// Per material index.
    pub materials: Sources,
    /// Per point light.
    pub lights: Sources,
    /// Per instance.
    pub instances: Sources,
}

/// Render settings a scene file may carry; `None` leaves the renderer's default.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RenderHints {
    /// Samples per pixel.
    pub spp: Option<u32>,
    /// Maximum ray-tree depth.
    pub max_depth: Option<u32>,
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
    /// Texture coordinates and tangents (world space), computed only when the
    /// material has texture maps.
    pub param: Option<Param>,
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
            geometry: Geometry::default(),
            objects: Vec::new(),
            instances: Vec::new(),
            render: RenderHints::default(),
            load_stats: LoadStats::default(),
            textures: Vec::new(),
            environment: None,
            origin: DVec3::ZERO,
            sources: SceneSources::default(),
        }
    }

    /// The world point of `p`, a point of the scene's frame (see [`Scene::origin`]).
    #[inline]
    pub fn to_world(&self, p: Vec3) -> DVec3 {
        p.as_dvec3() + self.origin
    }

    /// Number of primitives of `kind` a ray can meet: the top level's and each
    /// instance's copy of its object's (`self.geometry.count(kind)` counts the top
    /// level only).
    pub fn count_with_instances(&self, kind: Kind) -> usize {
        self.geometry.count(kind)
            + self
                .instances
                .iter()
                .map(|i| self.objects[i.object as usize].count(kind))
                .sum::<usize>()
    }

    /// Total number of primitives a ray can meet: the top level's and each instance's
    /// copy of its object's (`self.geometry.prim_count()` counts the top level only).
    pub fn prim_count_with_instances(&self) -> usize {
        self.geometry.prim_count()
            + self
                .instances
                .iter()
                .map(|i| self.objects[i.object as usize].prim_count())
                .sum::<usize>()
    }

    /// The surface at a hit reported by a backend for `ray` (world space).
    pub fn surface(&self, hit: &Hit, ray: &Ray) -> Surface {
        self.surface_of(hit, ray, false)
    }

    /// [`Scene::surface`], where `exact` says that a top-level triangle hit is the
    /// watertight test's own already (see [`crate::accel::Accel::exact_triangle_hits`]).
    #[inline]
    pub fn surface_of(&self, hit: &Hit, ray: &Ray, exact: bool) -> Surface {
        if hit.inst_id == NO_INSTANCE {
            let tested;
            let hit = if exact {
                hit
            } else {
                tested = self.geometry.exact_hit(hit, ray);
                &tested
            };
            let mut surf = self.geometry.surface(hit, ray);
            if self.textured(surf.material) {
                surf.param = Some(self.geometry.param(hit, &surf));
            }
            return surf;
        }
        let inst = &self.instances[hit.inst_id as usize];
        let object = &self.objects[inst.object as usize];
        let local_ray = inst.xform.ray_to_object(ray);
        let hit = &object.exact_hit(hit, &local_ray);
        let local = object.surface(hit, &local_ray);
        let point = inst.xform.surface_to_world(&local.point);
        let ns = inst.xform.normal_to_world(local.ns).normalize_or(point.ng);
        let material = if local.material == INHERIT {
            inst.material
        } else {
            local.material
        };
        let param = self.textured(material).then(|| {
            let p = object.param(hit, &local);
            let to_world = |v: Vec3| inst.xform.to_world.transform_vector3(v);
            Param {
                uv: p.uv,
                dpdu: to_world(p.dpdu),
                dpdv: to_world(p.dpdv),
            }
        });
        Surface {
            point,
            ns,
            material,
            param,
        }
    }

    /// Whether material `m` has texture maps.
    #[inline]
    fn textured(&self, m: u32) -> bool {
        self.materials.get(m as usize).is_some_and(|m| m.maps.any())
    }

    /// The material at `surf` with its textured inputs resolved (colour, highlight
    /// and mirror weights) and the shading normal after its normal and bump maps
    /// (not yet faced towards the ray). See [`texture`].
    #[inline]
    pub fn shading(&self, surf: &Surface) -> (Material, Vec3) {
        let mut m = self.materials[surf.material as usize];
        match surf.param {
            Some(prm) => {
                let ns = self.apply_maps(&mut m, &prm, surf);
                (m, ns)
            }
            None => (m, surf.ns),
        }
    }

    fn apply_maps(&self, m: &mut Material, prm: &Param, surf: &Surface) -> Vec3 {
        let maps = m.maps;
        // Solid textures are of the world point, wherever the frame's origin lies.
        let p = self.to_world(surf.point.p).as_vec3();
        let [su, sv] = maps.uv_scale;
        let prm = &Param {
            uv: prm.uv * Vec2::new(su, sv),
            dpdu: prm.dpdu / su,
            dpdv: prm.dpdv / sv,
        };
        let tex = |i: u32| self.textures.get(i as usize);
        if let Some(t) = tex(maps.color) {
            m.color *= t.eval(prm.uv, p);
        }
        if let Some(t) = tex(maps.specular) {
            let s = t.eval(prm.uv, p);
            let s = (s.x + s.y + s.z) / 3.0;
            m.ks *= s;
            m.kr *= s;
        }
        let mut ns = surf.ns;
        if let Some(t) = tex(maps.normal) {
            ns = texture::normal_map(t.eval(prm.uv, p), ns, prm.dpdu, prm.dpdv);
        }
        if let Some(t) = tex(maps.bump) {
            ns = texture::bump_normal(t, maps.bump_scale, prm.uv, p, ns, prm.dpdu, prm.dpdv);
        }
        ns
    }

    /// The radiance of a ray that leaves the scene in direction `dir`: the environment
    /// map's, or the background colour.
    #[inline]
    pub fn escape(&self, dir: Vec3) -> Vec3 {
        match &self.environment {
            Some(env) => env.lookup(dir),
            None => self.background,
        }
    }
}
