//! The tracer's recording hook: everything the Whitted tracer does for a sample, as
//! it does it, for whoever wants to look inside a render.
//!
//! The tracer ([`super::whitted`], [`super::wavefront`]) is generic over a [`Recorder`]
//! and calls it at each step: a ray cast, what it hit or that it missed, the material
//! and shading normal, each term of the local light (ambient, emission, area lights,
//! radiosity, each point light with its shadow ray), the reflection and refraction rays
//! with their weights, and what each ray brings back.
//!
//! The tracer is a wavefront: the rays of a whole batch (a tile's samples) are cast
//! depth by depth, so the steps of different rays interleave. Every ray is a node of
//! the batch's ray tree, numbered from 0 in the order the rays are spawned (a child
//! after its parent); each hook names the node it is about, and [`Traced`] names the
//! ray's parent (a link, not a nesting of calls) and its position. A ray's radiance is
//! known only once its subtree is cast: [`Recorder::ray_end`] comes for every node
//! after all the batch's rays were cast, children before parents, and then
//! [`Recorder::position`] and [`Recorder::position_end`] for each position, in order. An ordinary render records with [`RayCounts`], whose
//! hooks are empty `#[inline(always)]` functions: the calls compile away and the render
//! is the code it would be without them. `emray explain` ([`super::explain`]) builds the
//! whole ray tree of a pixel from the same calls, and the output variables and heat
//! maps ([`super::aov`]) take the first hit, the rays and the time of each pixel.
//!
//! The values handed to a hook are the ones the tracer computes anyway; a recorder
//! that needs more sets [`Recorder::ACTIVE`], and the few values computed only for it
//! are computed under `if R::ACTIVE`, a constant the compiler folds.

use super::RayCounts;
use super::media::Media;
use crate::math::{Ray, Vec3};
use crate::scene::{Hit, Material, Surface};

/// What a ray is for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum RayKind {
    /// From the eye through the film.
    Eye,
    /// Mirror reflection.
    Reflection,
    /// Refraction (transmission).
    Refraction,
    /// Towards a light, for visibility.
    Shadow,
}

impl RayKind {
    /// The name `emray explain` prints.
    pub fn name(self) -> &'static str {
        match self {
            RayKind::Eye => "eye",
            RayKind::Reflection => "reflection",
            RayKind::Refraction => "refraction",
            RayKind::Shadow => "shadow",
        }
    }
}

/// A ray the tracer is about to follow (an eye, reflection or refraction ray).
#[derive(Clone, Copy, Debug)]
pub struct Traced<'a> {
    /// Its node in the batch's ray tree.
    pub node: u32,
    /// The node of the ray whose hit spawned it (`None` for an eye ray).
    pub parent: Option<u32>,
    /// The sample-grid position it is for.
    pub position: (u32, u32),
    /// What it is for.
    pub kind: RayKind,
    /// Its depth in the ray tree, the eye ray being 1.
    pub depth: u32,
    /// The ray.
    pub ray: &'a Ray,
    /// What its radiance is multiplied by where it was spawned (one for an eye ray, the
    /// refraction weight `T × filter` or the reflection weight `Kr` (plus `T` on total
    /// internal reflection) else).
    pub local_weight: Vec3,
    /// What its radiance is multiplied by in the sample: the product of the local
    /// weights from the eye.
    pub weight: Vec3,
    /// Cast but its light thrown away (weight 0): the SPD testing mode casts it as the
    /// SPD's reference does, or `--no-skip` casts it to measure what skipping saves.
    pub discarded: bool,
}

/// A surface a ray met.
#[derive(Clone, Copy, Debug)]
pub struct Met<'a> {
    /// The backend's hit (kind, primitive, instance).
    pub hit: &'a Hit,
    /// The surface there.
    pub surf: &'a Surface,
    /// Whether the ray enters the solid (hits the front of the geometric normal).
    pub entering: bool,
    /// The media the ray travels in before the surface.
    pub media: &'a Media,
}

/// A term of the local light at a hit, besides the point lights.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Term {
    /// `ambient × colour × Ka`.
    Ambient,
    /// The material's emission (seen from its front).
    Emission,
    /// The area lights' diffuse light, `colour × Kd ×` their direct term.
    Area,
    /// The radiosity solution's diffuse light, which replaces the three above in
    /// two-pass mode (`--gi radiosity`).
    Radiosity,
}

/// One point light's contribution at a hit.
#[derive(Clone, Copy, Debug)]
pub struct LightTerm<'a> {
    /// The light's index in the scene.
    pub light: usize,
    /// The shadow ray, `None` when it was not cast (the light is behind the shading
    /// normal or sends nothing here).
    pub shadow: Option<&'a Ray>,
    /// Whether the light cannot light the point: it is behind the shading normal or
    /// sends nothing there.
    pub useless: bool,
    /// Whether the shadow ray met something before the light.
    pub occluded: bool,
    /// The light's intensity arriving at the point (colour × attenuation × spot).
    pub intensity: Vec3,
    /// `colour × Kd × (N·L)`, before the intensity (zero when no light arrives).
    pub diffuse: Vec3,
    /// `Ks × (R·V)^Shine`, before the intensity (zero when no light arrives).
    pub specular: f32,
    /// What the light adds: `intensity × (diffuse + specular)`, or zero.
    pub value: Vec3,
}

/// Why a reflection or refraction ray was not cast.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum NotCast {
    /// Its accumulated weight is below `--bailout`.
    Bailout,
    /// A reflection off a surface with no mirror reflectance (`Kr = 0`).
    NoReflectance,
}

/// What happens at a transmissive surface.
#[derive(Clone, Copy, Debug)]
pub struct Boundary {
    /// Index of refraction on the incoming side.
    pub n1: f32,
    /// Index of refraction on the far side.
    pub n2: f32,
    /// Total internal reflection: no refraction, its weight goes to the reflection.
    pub tir: bool,
    /// The media on the far side.
    pub inside: Media,
}

/// The hooks the tracer calls. Every hook but [`Recorder::counts`] does nothing by
/// default; see the module documentation.
pub trait Recorder {
    /// Whether the recorder needs the values that are computed only for it.
    const ACTIVE: bool = false;

    /// The ray counters.
    fn counts(&mut self) -> &mut RayCounts;

    /// A batch of samples begins: its nodes are numbered from 0 again.
    #[inline(always)]
    fn batch(&mut self) {}
    /// A sample-grid position `(i, j)` is complete (its rays all ended); its value
    /// follows in [`Recorder::position_end`].
    #[inline(always)]
    fn position(&mut self, _i: u32, _j: u32) {}
    /// The position's value, as the film gets it.
    #[inline(always)]
    fn position_end(&mut self, _value: Vec3) {}
    /// The rays of `nodes` are about to be cast together (`start`), or were.
    #[inline(always)]
    fn cast(&mut self, _start: bool, _nodes: &[u32]) {}
    /// A ray is spawned (it is cast with the others of its depth).
    #[inline(always)]
    fn ray(&mut self, _ray: &Traced) {}
    /// Ray `node` came back with this radiance (after saturation).
    #[inline(always)]
    fn ray_end(&mut self, _node: u32, _radiance: Vec3) {}
    /// Ray `node` left the scene: the background or environment radiance.
    #[inline(always)]
    fn miss(&mut self, _node: u32, _radiance: Vec3) {}
    /// Ray `node` went on through a surface that is not optically there (a
    /// lower-priority medium inside a higher one).
    #[inline(always)]
    fn pass_through(&mut self, _node: u32, _at: &Met) {}
    /// Ray `node` hit a surface it is shaded at.
    #[inline(always)]
    fn hit(&mut self, _node: u32, _at: &Met) {}
    /// The material after textures and the shading normal after its maps, facing the
    /// ray.
    #[inline(always)]
    fn shading(&mut self, _node: u32, _m: &Material, _ns: Vec3) {}
    /// A term of the local light.
    #[inline(always)]
    fn term(&mut self, _node: u32, _term: Term, _value: Vec3) {}
    /// Area light `light` cast `rays` shadow rays, of which `visible` reached it, and
    /// sends `value` (its direct term, before the surface's `colour × Kd`).
    #[inline(always)]
    fn area_light(&mut self, _node: u32, _light: usize, _rays: u32, _visible: u32, _value: Vec3) {}
    /// A point light's contribution (after its shadow ray was cast with the batch's).
    #[inline(always)]
    fn light(&mut self, _node: u32, _term: &LightTerm) {}
    /// The local light of the hit, every term summed: what the reflection and
    /// refraction are added to.
    #[inline(always)]
    fn local(&mut self, _node: u32, _color: Vec3) {}
    /// A transmissive surface: the indices on either side and whether the ray is
    /// totally reflected.
    #[inline(always)]
    fn boundary(&mut self, _node: u32, _b: &Boundary) {}
    /// A reflection or refraction ray was not cast.
    #[inline(always)]
    fn not_cast(&mut self, _node: u32, _kind: RayKind, _why: NotCast, _weight: Vec3) {}
}

/// An ordinary render records the counts alone.
impl Recorder for RayCounts {
    #[inline(always)]
    fn counts(&mut self) -> &mut RayCounts {
        self
    }
}
