//! One pixel's ray tree (`emray explain`): every ray the renderer casts for the pixel,
//! what each hit and where that primitive was defined, each term of the light at each
//! hit, the reflection and refraction weights, and what each ray brings back.
//!
//! The tree is recorded from the renderer's own tracer (`super::whitted`) by an
//! `ExplainRecorder`: the pixel is traced by the code that
//! renders it, through the same tile of eye rays (cast together, as a render casts
//! them), so the value it ends with is the film's value bit for bit. [`text`] prints
//! the tree for people; the types here serialise to the JSON of `--json`
//! (docs/explain.md).

mod recorder;
pub mod text;

use super::film::corner_mean;
use super::whitted::Tracer;
use super::{GlobalIllumination, RayGen, Region, RenderSettings};
use crate::accel::Accel;
use crate::math::Vec3;
use crate::render::record::{NotCast, RayKind, Term};
use crate::scene::Scene;
use recorder::ExplainRecorder;
use serde::Serialize;

/// A pixel that cannot be explained.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum ExplainError {
    /// The pixel lies outside the image.
    #[error("pixel ({x}, {y}) is outside the {width}x{height} image")]
    Outside {
        /// Column asked for.
        x: u32,
        /// Row asked for.
        y: u32,
        /// Image width.
        width: u32,
        /// Image height.
        height: u32,
    },
    /// Adaptive antialiasing shares its samples between pixels.
    #[error("adaptive antialiasing shares rays between pixels: explain renders uniform samples")]
    Adaptive,
}

/// The explanation of one pixel.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Explanation {
    /// Column, from the left.
    pub x: u32,
    /// Row, from the top.
    pub y: u32,
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Samples per pixel.
    pub spp: u32,
    /// Ray-tree depth limit.
    pub max_depth: u32,
    /// SPD testing mode: the pixel is the mean of its four corner rays.
    pub spd: bool,
    /// The pixel's value: linear RGB, as the film holds it before any encoding.
    pub value: [f32; 3],
    /// The sample-grid positions the pixel is made of: itself, or its four corners in
    /// SPD mode (top-left, top-right, bottom-left, bottom-right).
    pub positions: Vec<Position>,
}

/// One sample-grid position and its samples.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Position {
    /// Its column and row in the sample grid.
    pub grid: [u32; 2],
    /// Its value: the mean of its samples.
    pub value: [f32; 3],
    /// What one of its samples weighs in the pixel: `1 / spp`, or `1/4` for a corner.
    pub share: f32,
    /// The eye rays, each with its tree.
    pub samples: Vec<RayNode>,
}

/// A ray and what it met.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RayNode {
    /// What it is for (`eye`, `reflection`, `refraction`).
    pub kind: RayKind,
    /// Depth in the ray tree (the eye ray is 1).
    pub depth: u32,
    /// Origin, in the scene file's coordinates.
    pub origin: [f64; 3],
    /// Direction (unit for eye rays).
    pub direction: [f32; 3],
    /// What its radiance is multiplied by in its parent.
    pub local_weight: [f32; 3],
    /// What its radiance is multiplied by in the sample.
    pub weight: [f32; 3],
    /// Cast, but its light not used (weight 0: SPD mode or `--no-skip`).
    pub discarded: bool,
    /// Surfaces it went through as if they were not there (a lower-priority medium
    /// inside a higher one).
    pub passed: Vec<Passed>,
    /// The surface it is shaded at, if it hit one.
    pub hit: Option<Box<HitNode>>,
    /// The background or environment radiance, if it left the scene.
    pub background: Option<[f32; 3]>,
    /// What the ray itself adds to the pixel, its children apart: `weight × share ×`
    /// the local light of its hit, or the background.
    pub contribution: [f32; 3],
    /// What it brings back: the hit's local light plus its children's weighted
    /// radiance (saturated to f32's range), or the background.
    pub radiance: [f32; 3],
}

/// A primitive of the scene.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Prim {
    /// Its kind (`triangle`, `sphere`, ...).
    pub kind: &'static str,
    /// Its index within the kind's list (of the scene, or of the instanced object).
    pub index: u32,
    /// The instance it belongs to, if any.
    pub instance: Option<u32>,
    /// Where it was defined, `file:line`.
    pub source: Option<String>,
    /// Where the instance was placed, `file:line`.
    pub instance_source: Option<String>,
}

/// A surface a ray went through.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Passed {
    /// The primitive.
    pub prim: Prim,
    /// The point, in the scene file's coordinates.
    pub point: [f64; 3],
    /// Whether the ray entered (else left) that medium.
    pub entering: bool,
}

/// The hit a ray is shaded at.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct HitNode {
    /// Ray parameter of the hit (along the ray as last restarted after passing
    /// surfaces).
    pub t: f32,
    /// The point, in the scene file's coordinates.
    pub point: [f64; 3],
    /// The primitive hit.
    pub prim: Prim,
    /// Whether the ray hits the front of the geometric normal (enters a solid).
    pub entering: bool,
    /// Unit geometric normal, outward.
    pub geometric_normal: [f32; 3],
    /// Unit shading normal after normal and bump maps, facing the ray.
    pub normal: [f32; 3],
    /// The material, after textures.
    pub material: MaterialNode,
    /// The media the ray travels in before the hit, outermost first.
    pub media: Vec<Medium>,
    /// Ambient, emission, area lights or radiosity.
    pub terms: Vec<TermNode>,
    /// Each area light's shadow rays.
    pub area_lights: Vec<AreaNode>,
    /// Each point light.
    pub lights: Vec<LightNode>,
    /// The local light: the terms and lights summed.
    pub local: [f32; 3],
    /// Snell's law at a transmissive surface.
    pub boundary: Option<BoundaryNode>,
    /// Reflection or refraction rays not cast, and why.
    pub not_cast: Vec<NotCastNode>,
    /// The refraction and reflection rays, in the order they were cast.
    pub children: Vec<RayNode>,
}

/// A material as shading used it (textures applied).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MaterialNode {
    /// Index in the scene's materials.
    pub index: u32,
    /// Where it was defined, `file:line`.
    pub source: Option<String>,
    /// Surface colour.
    pub color: [f32; 3],
    /// Ambient weight.
    pub ka: f32,
    /// Diffuse weight.
    pub kd: f32,
    /// Highlight weight.
    pub ks: f32,
    /// Phong exponent.
    pub shine: f32,
    /// Mirror reflectance.
    pub kr: f32,
    /// Transmittance.
    pub t: f32,
    /// Index of refraction.
    pub ior: f32,
    /// Emission.
    pub emission: [f32; 3],
}

/// A medium a ray is in.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Medium {
    /// Its material index.
    pub material: u32,
    /// Its index of refraction.
    pub ior: f32,
}

/// A term of the local light.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TermNode {
    /// Which.
    pub term: Term,
    /// Its value.
    pub value: [f32; 3],
}

/// One area light's share.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct AreaNode {
    /// The area light (emitting triangle) number.
    pub light: usize,
    /// Shadow rays cast to it.
    pub rays: u32,
    /// Of which reached it.
    pub visible: u32,
    /// Its direct term (before the surface's `colour × Kd`).
    pub value: [f32; 3],
}

/// What a point light did.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LightNode {
    /// The light's index.
    pub light: usize,
    /// Where it was defined, `file:line`.
    pub source: Option<String>,
    /// `lit`, `shadowed` (the shadow ray met something), `behind` (no shadow ray: the
    /// light is behind the shading normal or sends nothing), or `unlit` (the shadow
    /// ray was cast with `--no-skip` but the light cannot light the point).
    pub status: &'static str,
    /// The shadow ray, if cast.
    pub shadow_ray: Option<ShadowRay>,
    /// Its intensity at the point (colour × attenuation × spot).
    pub intensity: [f32; 3],
    /// `intensity / colour` (largest channels): the attenuation and spot factor.
    pub attenuation: f32,
    /// `colour × Kd × (N·L)`.
    pub diffuse: [f32; 3],
    /// `Ks × (R·V)^Shine`.
    pub specular: f32,
    /// What it adds.
    pub value: [f32; 3],
}

/// A shadow ray.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ShadowRay {
    /// Origin (offset from the surface), in the scene file's coordinates.
    pub origin: [f64; 3],
    /// Direction: to the light, unnormalised.
    pub direction: [f32; 3],
    /// End of its interval (just short of the light, at 1).
    pub tmax: f32,
    /// Whether it met something.
    pub occluded: bool,
}

/// Snell's law at a transmissive surface.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BoundaryNode {
    /// Index on the incoming side.
    pub n1: f32,
    /// Index on the far side.
    pub n2: f32,
    /// Total internal reflection (the transmitted weight goes to the reflection).
    pub total_internal_reflection: bool,
    /// The media on the far side.
    pub media_beyond: Vec<Medium>,
}

/// A reflection or refraction ray not cast.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct NotCastNode {
    /// Which.
    pub kind: RayKind,
    /// Why.
    pub why: NotCast,
    /// The weight it would have had in the sample.
    pub weight: [f32; 3],
}

/// As an array, for the JSON.
pub(crate) fn arr(v: Vec3) -> [f32; 3] {
    v.to_array()
}

/// Explain pixel `(x, y)` of `scene` rendered with `settings` (and `gi` in two-pass
/// mode) through `accel`: trace the tiles that hold its sample-grid positions exactly as
/// a render does, and keep the record of those positions.
pub fn explain<A: Accel>(
    scene: &Scene,
    accel: &A,
    settings: &RenderSettings,
    gi: Option<&dyn GlobalIllumination>,
    x: u32,
    y: u32,
) -> Result<Explanation, ExplainError> {
    let (w, h) = (settings.width, settings.height);
    if x >= w || y >= h {
        return Err(ExplainError::Outside {
            x,
            y,
            width: w,
            height: h,
        });
    }
    if settings.aa != super::Aa::Uniform && !settings.spd {
        return Err(ExplainError::Adaptive);
    }
    let tracer = Tracer::new(scene, accel, settings).with_gi(gi);
    let (wanted, share, grid) = if settings.spd {
        let corners = vec![(x, y), (x + 1, y), (x, y + 1), (x + 1, y + 1)];
        (corners, 0.25, (w + 1, h + 1))
    } else {
        (vec![(x, y)], 1.0 / settings.spp.max(1) as f32, (w, h))
    };
    let raygen = RayGen::new(&scene.camera, grid.0, grid.1);
    let mut rec = ExplainRecorder::new(scene, wanted.clone(), share);
    let mut tiles: Vec<Region> = Vec::new();
    for &(i, j) in &wanted {
        let t = super::tile_of(i, j, grid.0, grid.1, settings.tile_size);
        if !tiles.contains(&t) {
            tiles.push(t);
        }
    }
    for t in tiles {
        tracer.tile(&raygen, t, &mut |_| {}, &mut rec);
    }
    let positions = rec.into_positions(&wanted);
    let values: Vec<Vec3> = positions.iter().map(|p| Vec3::from(p.value)).collect();
    let value = match values[..] {
        [a, b, c, d] if settings.spd => corner_mean([a, b, c, d]),
        _ => values[0],
    };
    Ok(Explanation {
        x,
        y,
        width: w,
        height: h,
        spp: if settings.spd { 1 } else { settings.spp.max(1) },
        max_depth: settings.max_depth,
        spd: settings.spd,
        value: arr(value),
        positions,
    })
}
