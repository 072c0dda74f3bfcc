//! The serde structures of a TOML scene file, exactly as written: nothing is resolved,
//! defaulted or checked here beyond TOML's own types, so that a file read into a
//! [`SceneFile`] and written back with [`SceneFile::to_toml_string`] reads again into an
//! equal value.
//!
//! Every value that a later check may complain about is a [`Spanned`], which remembers
//! the byte range of its text in the file: that is how every error reaches the exact
//! line. Objects are one flat [`ObjectDef`] with an optional field per key rather than
//! an enum tagged by `type`: serde buffers a tagged enum's content before choosing the
//! variant, and the spans of everything inside are lost on the way (every error would
//! point at the object's first line). The keys that a given `type` accepts are checked
//! while building (see the `build` module).
//!
//! Numbers are [`Real`]s: any TOML integer or float that is finite and within the
//! single-precision range, refused otherwise while deserializing, so that `nan`, `inf`
//! and `1e300` are reported at their own position.

use serde::de::{self, Deserializer, SeqAccess, Visitor};
use serde::ser::{SerializeSeq, Serializer};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::fmt;

pub use ::toml::Spanned;

/// A finite number that fits in `f32`, kept as written (`f64`) so that files round-trip
/// exactly.
#[derive(Clone, Copy, Debug, Default, PartialEq, PartialOrd)]
pub struct Real(pub f64);

impl Real {
    /// The value in single precision (always finite).
    pub fn f32(self) -> f32 {
        self.0 as f32
    }
}

impl Serialize for Real {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_f64(self.0)
    }
}

struct RealVisitor;

impl RealVisitor {
    fn check<E: de::Error>(v: f64) -> Result<Real, E> {
        if !v.is_finite() {
            Err(E::custom(format!("{v} is not a finite number")))
        } else if v.abs() > f32::MAX as f64 {
            Err(E::custom(format!(
                "{v} is outside the single-precision range (±3.4e38)"
            )))
        } else {
            Ok(Real(v))
        }
    }
}

impl<'de> Visitor<'de> for RealVisitor {
    type Value = Real;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a number")
    }
    fn visit_f64<E: de::Error>(self, v: f64) -> Result<Real, E> {
        Self::check(v)
    }
    fn visit_i64<E: de::Error>(self, v: i64) -> Result<Real, E> {
        Self::check(v as f64)
    }
    fn visit_u64<E: de::Error>(self, v: u64) -> Result<Real, E> {
        Self::check(v as f64)
    }
}

impl<'de> Deserialize<'de> for Real {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Real, D::Error> {
        d.deserialize_any(RealVisitor)
    }
}

/// Three numbers: a point, a vector or an RGB colour.
pub type V3 = [Real; 3];

/// A whole scene file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    /// `[camera]` (required).
    pub camera: Spanned<CameraDef>,
    /// `[render]`: image-wide settings.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub render: Option<Spanned<RenderDef>>,
    /// `[materials.NAME]`.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub materials: BTreeMap<String, Spanned<MaterialDef>>,
    /// `[[lights]]`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub lights: Vec<Spanned<LightDef>>,
    /// `[define.NAME]`: objects placed by `instance`s.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub define: BTreeMap<String, Spanned<ObjectDef>>,
    /// `[[objects]]`: the scene's content.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub objects: Vec<Spanned<ObjectDef>>,
}

impl SceneFile {
    /// Write the file back as TOML text (spans are not written; comments and the
    /// original layout are not kept).
    ///
    /// # Errors
    /// Only if the TOML serializer refuses the structure (it does not for values read
    /// from a file).
    pub fn to_toml_string(&self) -> Result<String, ::toml::ser::Error> {
        ::toml::to_string(self)
    }
}

/// `[camera]`: either a look-at (`from`, `at`, `up`) or a camera-to-world `matrix`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraDef {
    /// Eye position.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub from: Option<Spanned<V3>>,
    /// Point looked at.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub at: Option<Spanned<V3>>,
    /// Up vector (default `[0, 1, 0]`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub up: Option<Spanned<V3>>,
    /// Camera-to-world matrix, 4 rows of 4; the camera looks down its −Z with +Y up.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub matrix: Option<Spanned<[[Real; 4]; 4]>>,
    /// Full vertical field of view in degrees (default 45).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fov: Option<Spanned<Real>>,
    /// Hither distance (default 0; recorded as in NFF).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub hither: Option<Spanned<Real>>,
    /// `[width, height]` in pixels (default `[640, 480]`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub resolution: Option<Spanned<[u32; 2]>>,
}

/// `[render]`: image-wide settings; command-line flags override `max_depth` and `spp`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RenderDef {
    /// Colour of rays that hit nothing (default black).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub background: Option<Spanned<V3>>,
    /// Ambient light intensity (default `[0.1, 0.1, 0.1]`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ambient: Option<Spanned<V3>>,
    /// Ray-tree depth limit, the eye ray counting as 1.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_depth: Option<Spanned<u32>>,
    /// Samples per pixel.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spp: Option<Spanned<u32>>,
    /// Environment map file for rays that leave the scene (relative to the scene file).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub environment: Option<Spanned<String>>,
}

/// `[materials.NAME]`: every key optional.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialDef {
    /// Surface colour (default white).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub color: Option<Spanned<V3>>,
    /// Ambient weight Ka (default: the diffuse weight).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ambient: Option<Spanned<Real>>,
    /// Diffuse weight Kd (default 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub diffuse: Option<Spanned<Real>>,
    /// Phong highlight weight Ks (default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub specular: Option<Spanned<Real>>,
    /// Phong exponent (default 32).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shininess: Option<Spanned<Real>>,
    /// Mirror weight Kr (default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reflectance: Option<Spanned<Real>>,
    /// Weight of the refracted ray (default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub transmittance: Option<Spanned<Real>>,
    /// Index of refraction (default 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ior: Option<Spanned<Real>>,
    /// Transmission filter colour, applied when a ray enters the medium (default
    /// white).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub filter: Option<Spanned<V3>>,
    /// Nested-dielectric priority (default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub priority: Option<Spanned<u32>>,
    /// Emitted radiosity of an area light (default black).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub emission: Option<Spanned<V3>>,
    /// Texture multiplying `color`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub texture: Option<Spanned<TextureDef>>,
    /// Texture multiplying `specular` and `reflectance` by its mean.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub specular_map: Option<Spanned<TextureDef>>,
    /// Height field for bump mapping (its mean, times `bump_scale`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bump: Option<Spanned<TextureDef>>,
    /// Height of a bump value of 1, in scene units (default 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bump_scale: Option<Spanned<Real>>,
    /// Tangent-space normal map.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub normal_map: Option<Spanned<TextureDef>>,
    /// Texture coordinates are multiplied by `[su, sv]` before every lookup (default
    /// `[1, 1]`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub uv_scale: Option<Spanned<[Real; 2]>>,
}

/// A texture: `{ file = "x.png" }` (with optional `wrap = "repeat" | "clamp"`),
/// `{ type = "checker", a = [..], b = [..], scale = 8 }` or
/// `{ type = "marble", a = [..], b = [..], scale = 4 }`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TextureDef {
    /// `"image"` (default when `file` is given), `"checker"` or `"marble"`.
    #[serde(rename = "type", default, skip_serializing_if = "Option::is_none")]
    pub ty: Option<Spanned<String>>,
    /// Image file (PNG or JPEG), relative to the scene file.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub file: Option<Spanned<String>>,
    /// `"repeat"` (default) or `"clamp"`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wrap: Option<Spanned<String>>,
    /// First colour of a procedural texture (default white).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub a: Option<Spanned<V3>>,
    /// Second colour of a procedural texture (default black).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub b: Option<Spanned<V3>>,
    /// Squares per unit (checker) or frequency (marble) (default 8 and 4).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scale: Option<Spanned<Real>>,
}

/// `[[lights]]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LightDef {
    /// `"point"` (default) or `"spot"`.
    #[serde(rename = "type", default, skip_serializing_if = "Option::is_none")]
    pub ty: Option<Spanned<String>>,
    /// Position (required).
    pub position: Spanned<V3>,
    /// Colour (default white).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub color: Option<Spanned<V3>>,
    /// Multiplies the colour (default 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub intensity: Option<Spanned<Real>>,
    /// Constant, linear and quadratic attenuation (default `[1, 0, 0]`: none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub attenuation: Option<Spanned<V3>>,
    /// Spot: the direction it points to (or give `target`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub direction: Option<Spanned<V3>>,
    /// Spot: a point it points at (or give `direction`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub target: Option<Spanned<V3>>,
    /// Spot: cutoff half-angle in degrees (default 45).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cutoff: Option<Spanned<Real>>,
    /// Spot: falloff exponent (default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub exponent: Option<Spanned<Real>>,
}

/// One step of a `transform` list: exactly one of `translate`, `rotate` (with `angle`),
/// `scale`, `mirror` or `matrix`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TransformStep {
    /// Translation vector.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub translate: Option<Spanned<V3>>,
    /// Rotation axis (any length but zero), right-handed, with `angle`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rotate: Option<Spanned<V3>>,
    /// Rotation angle in degrees.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub angle: Option<Spanned<Real>>,
    /// Scale: one number (uniform) or three.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scale: Option<Spanned<Scale>>,
    /// A reflection about a plane.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mirror: Option<Spanned<MirrorDef>>,
    /// An affine matrix, 4 rows of 4, the last row `[0, 0, 0, 1]`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub matrix: Option<Spanned<[[Real; 4]; 4]>>,
}

/// The plane a `mirror` step reflects about: through `point` (default the origin), with
/// normal `normal` (any length but zero).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MirrorDef {
    /// A point of the plane.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub point: Option<Spanned<V3>>,
    /// The plane's normal.
    pub normal: Spanned<V3>,
}

/// A scale factor: one number for all axes, or one per axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Scale {
    /// The same factor on every axis.
    Uniform(Real),
    /// Factors for x, y and z.
    Axes(V3),
}

impl Serialize for Scale {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            Scale::Uniform(r) => r.serialize(s),
            Scale::Axes(v) => {
                let mut seq = s.serialize_seq(Some(3))?;
                for r in v {
                    seq.serialize_element(r)?;
                }
                seq.end()
            }
        }
    }
}

struct ScaleVisitor;

impl<'de> Visitor<'de> for ScaleVisitor {
    type Value = Scale;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a number or an array of 3 numbers")
    }
    fn visit_f64<E: de::Error>(self, v: f64) -> Result<Scale, E> {
        RealVisitor::check(v).map(Scale::Uniform)
    }
    fn visit_i64<E: de::Error>(self, v: i64) -> Result<Scale, E> {
        RealVisitor::check(v as f64).map(Scale::Uniform)
    }
    fn visit_u64<E: de::Error>(self, v: u64) -> Result<Scale, E> {
        RealVisitor::check(v as f64).map(Scale::Uniform)
    }
    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Scale, A::Error> {
        let mut v = [Real(0.0); 3];
        for (i, slot) in v.iter_mut().enumerate() {
            *slot = seq
                .next_element()?
                .ok_or_else(|| de::Error::invalid_length(i, &self))?;
        }
        let mut extra = 3;
        while seq.next_element::<de::IgnoredAny>()?.is_some() {
            extra += 1;
        }
        if extra != 3 {
            return Err(de::Error::invalid_length(extra, &self));
        }
        Ok(Scale::Axes(v))
    }
}

impl<'de> Deserialize<'de> for Scale {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Scale, D::Error> {
        d.deserialize_any(ScaleVisitor)
    }
}

/// An axis-aligned box, `{ min = [..], max = [..] }` (a quadric's `clip`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoxDef {
    /// Smallest corner.
    pub min: Spanned<V3>,
    /// Largest corner.
    pub max: Spanned<V3>,
}

/// A list of transform steps, applied in order (the first one first).
pub type TransformList = Vec<Spanned<TransformStep>>;

/// One object: `type` says which; the other keys depend on it (see
/// `docs/scene-format.md`). A key that the type does not take is an error.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObjectDef {
    /// The object type (`"sphere"`, `"group"`, …).
    #[serde(rename = "type")]
    pub ty: Spanned<String>,
    /// Material name (default: inherited from the enclosing object).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub material: Option<Spanned<String>>,
    /// Transform steps, the first applied first.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub transform: Option<Spanned<TransformList>>,

    /// Centre (sphere, torus, obox, polyhedron preset).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub center: Option<Spanned<V3>>,
    /// Radius (sphere, cylinder, polyhedron preset or prism).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radius: Option<Spanned<Real>>,

    /// Centre of the base end (cone, cylinder, capped cone, prism).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub base: Option<Spanned<V3>>,
    /// Radius at the base (cone, capped cone).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub base_radius: Option<Spanned<Real>>,
    /// Centre of the apex end (cone).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub apex: Option<Spanned<V3>>,
    /// Radius at the apex (cone).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub apex_radius: Option<Spanned<Real>>,
    /// Axis direction (cylinder, capped cone, torus, prism).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axis: Option<Spanned<V3>>,
    /// Height along the axis (cylinder, capped cone, prism).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub height: Option<Spanned<Real>>,
    /// Radius at the top (capped cone).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub top_radius: Option<Spanned<Real>>,

    /// Smallest corner (box).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min: Option<Spanned<V3>>,
    /// Largest corner (box).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max: Option<Spanned<V3>>,

    /// Full edge lengths (obox).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub size: Option<Spanned<V3>>,
    /// Half edge lengths (obox).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub half_size: Option<Spanned<V3>>,
    /// Orientation as rotation steps (obox).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rotation: Option<Spanned<TransformList>>,
    /// Orientation as three orthonormal axes (obox).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axes: Option<Spanned<[V3; 3]>>,

    /// Bounding planes `[nx, ny, nz, d]`, inside where `n·p ≤ d` (polyhedron).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub planes: Option<Spanned<Vec<Spanned<[Real; 4]>>>>,
    /// Named regular solid (polyhedron).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub preset: Option<Spanned<String>>,
    /// Number of sides (polyhedron prism).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sides: Option<Spanned<u32>>,

    /// The ten coefficients `a..j` (quadric).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub coefficients: Option<Spanned<[Real; 10]>>,
    /// Clipping box (quadric).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub clip: Option<Spanned<BoxDef>>,

    /// A point on the plane (plane).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub point: Option<Spanned<V3>>,
    /// The plane's normal (plane).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub normal: Option<Spanned<V3>>,

    /// Radius of the centre circle (torus).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub major_radius: Option<Spanned<Real>>,
    /// Radius of the tube (torus).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub minor_radius: Option<Spanned<Real>>,

    /// Vertex positions (triangle, polygon, mesh).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub vertices: Option<Spanned<Vec<Spanned<V3>>>>,
    /// Per-vertex shading normals (triangle, polygon, mesh).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub normals: Option<Spanned<Vec<Spanned<V3>>>>,
    /// Faces as lists of 0-based vertex indices (mesh).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub faces: Option<Spanned<Vec<Spanned<Vec<u32>>>>>,

    /// Bicubic patches of 16 control points each, row by row (bezier).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub patches: Option<Spanned<Vec<Spanned<[V3; 16]>>>>,
    /// A built-in patch set (bezier).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub builtin: Option<Spanned<String>>,
    /// Tessellation tolerance (bezier).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tolerance: Option<Spanned<Real>>,

    /// Path of the included file, relative to the scene file (include).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub file: Option<Spanned<String>>,
    /// Also take the included file's lights (include).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lights: Option<Spanned<bool>>,

    /// Child objects (group, union, intersection, difference).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub children: Option<Spanned<Vec<Spanned<ObjectDef>>>>,

    /// Name of the `define` placed (instance).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub of: Option<Spanned<String>>,
}

/// Name and span of every key present in `$obj` among the listed fields.
macro_rules! present_keys {
    ($obj:expr, $($f:ident),* $(,)?) => {{
        let o = $obj;
        let mut v: Vec<(&'static str, std::ops::Range<usize>)> = Vec::new();
        $( if let Some(x) = &o.$f { v.push((stringify!($f), x.span())); } )*
        v
    }};
}

impl ObjectDef {
    /// Every key present besides `type`, with the span of its value, in declaration
    /// order.
    pub fn keys(&self) -> Vec<(&'static str, std::ops::Range<usize>)> {
        present_keys!(
            self,
            material,
            transform,
            center,
            radius,
            base,
            base_radius,
            apex,
            apex_radius,
            axis,
            height,
            top_radius,
            min,
            max,
            size,
            half_size,
            rotation,
            axes,
            planes,
            preset,
            sides,
            coefficients,
            clip,
            point,
            normal,
            major_radius,
            minor_radius,
            vertices,
            normals,
            faces,
            patches,
            builtin,
            tolerance,
            file,
            lights,
            children,
            of,
        )
    }
}

/// Every key an object table may hold, for suggestions on a misspelt key.
pub const OBJECT_KEYS: &[&str] = &[
    "type",
    "material",
    "transform",
    "center",
    "radius",
    "base",
    "base_radius",
    "apex",
    "apex_radius",
    "axis",
    "height",
    "top_radius",
    "min",
    "max",
    "size",
    "half_size",
    "rotation",
    "axes",
    "planes",
    "preset",
    "sides",
    "coefficients",
    "clip",
    "point",
    "normal",
    "major_radius",
    "minor_radius",
    "vertices",
    "normals",
    "faces",
    "patches",
    "builtin",
    "tolerance",
    "file",
    "lights",
    "children",
    "of",
];
