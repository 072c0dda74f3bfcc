//! Everything a render asks for besides the scene, declared once: [`RenderOptions`].
//!
//! The one declaration serves every front end. The command line flattens it into each
//! command that renders (`render`, `explain`, `batch`, `radiosity`; with the `cli`
//! feature it derives `clap::Args`), a batch manifest deserialises it from its tables
//! (unknown keys refused with `file:line:col`), and a program embedding the library
//! fills it in. Every field is optional: `None` (or `false`, or empty) leaves the
//! scene file's `[render]` hint or the default, and the defaults are applied in one
//! place, when a job resolves its options against its scene ([`super::resolve`]).
//! Layers of options (a manifest's defaults, a job's table, the command line) combine
//! with [`RenderOptions::over`], field by field, without listing the fields again.

use super::values::{AovList, Band, ByteSize, Crop, Res};
use crate::accel::{Backend, EmbreeQuality};
use crate::output::Encoding;
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// Antialiasing modes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum AaMode {
    /// `spp` stratified samples per pixel.
    Uniform,
    /// Adaptive corner subdivision (`aa_threshold`, `aa_depth`).
    Adaptive,
}

/// Global-illumination methods.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum Gi {
    /// Two-pass: radiosity for the diffuse term, Whitted for the specular paths.
    Radiosity,
}

/// Radiosity solvers.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum Solver {
    /// Progressive refinement (shoot the most unshot energy first).
    Progressive,
    /// Gauss–Seidel on the full form-factor matrix (small meshes only).
    GaussSeidel,
}

/// Form-factor methods.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum FormFactors {
    /// Exact point-to-polygon form factors with ray-cast visibility (either backend).
    Raycast,
    /// Hemicube (Cohen & Greenberg 1985): item buffers on the five faces.
    Hemicube,
}

/// The radiosity pass (`gi = "radiosity"`, and `emray radiosity`): meshing, form
/// factors and solver. In a manifest, the table `radiosity = { ... }`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
#[cfg_attr(feature = "cli", derive(clap::Args))]
pub struct RadiosityOptions {
    /// Longest element edge, in scene units [default: 1/12 of the scene's diagonal].
    #[cfg_attr(
        feature = "cli",
        arg(long, value_name = "SIZE", help_heading = "Radiosity")
    )]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub patch_size: Option<f32>,
    /// Form-factor sample points per shooting element: 1, 4, 16 or 64 [default: 4].
    #[cfg_attr(
        feature = "cli",
        arg(long, value_name = "N", help_heading = "Radiosity")
    )]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ff_samples: Option<u32>,
    /// Visibility rays per pair of elements: 1, 4, 16 or 64 [default: 1].
    #[cfg_attr(
        feature = "cli",
        arg(long, value_name = "N", help_heading = "Radiosity")
    )]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub vis_samples: Option<u32>,
    /// Solver [default: progressive].
    #[cfg_attr(feature = "cli", arg(long, value_enum, help_heading = "Radiosity"))]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub solver: Option<Solver>,
    /// Form-factor method [default: raycast].
    #[cfg_attr(feature = "cli", arg(long, value_enum, help_heading = "Radiosity"))]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub form_factors: Option<FormFactors>,
    /// Hemicube resolution: pixels across the top face, even, 2 to 4096 [default: 128].
    #[cfg_attr(
        feature = "cli",
        arg(long, value_name = "N", help_heading = "Radiosity")
    )]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub hemicube_res: Option<u32>,
    /// Adaptive subdivision: split elements whose radiosity differs from a neighbour's
    /// by more than this fraction of the largest reflected radiosity, then solve again.
    #[cfg_attr(
        feature = "cli",
        arg(long, value_name = "FRACTION", help_heading = "Radiosity")
    )]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub subdiv_threshold: Option<f32>,
    /// Smallest element edge adaptive subdivision makes [default: patch size / 8].
    #[cfg_attr(
        feature = "cli",
        arg(long, value_name = "SIZE", help_heading = "Radiosity")
    )]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub min_patch_size: Option<f32>,
    /// Most rounds of adaptive subdivision [default: 3].
    #[cfg_attr(
        feature = "cli",
        arg(long, value_name = "N", help_heading = "Radiosity")
    )]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub subdiv_passes: Option<u32>,
    /// Stop when the unshot power is below this fraction of the emitted power
    /// [default: 0.001].
    #[cfg_attr(
        feature = "cli",
        arg(long, value_name = "E", help_heading = "Radiosity")
    )]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub epsilon: Option<f64>,
    /// Most shots (progressive) or sweeps (Gauss–Seidel) [default: 1000000].
    #[cfg_attr(
        feature = "cli",
        arg(long, value_name = "N", help_heading = "Radiosity")
    )]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_iterations: Option<usize>,
}

/// What a render asks for besides the scene (see the module documentation).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
#[cfg_attr(feature = "cli", derive(clap::Args))]
pub struct RenderOptions {
    /// Ray-query backend [default: embree when built with it, else bvh].
    #[cfg_attr(feature = "cli", arg(long, value_enum, help_heading = "Backend"))]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub backend: Option<Backend>,
    /// Image size, overriding the scene's resolution (at most 65536 per side and 2^28
    /// pixels).
    #[cfg_attr(feature = "cli", arg(long, value_name = "WxH", help_heading = "Image"))]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub res: Option<Res>,
    /// Samples per pixel, 1 to 65536 (stratified; 1 = the pixel centre) [default: the
    /// scene file's `[render] spp`, else 1].
    #[cfg_attr(feature = "cli", arg(long, value_name = "N", help_heading = "Image"))]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub spp: Option<u32>,
    /// Maximum ray-tree depth, 1 to 64, the eye ray being depth 1 [default: the scene
    /// file's `[render] max_depth`, else 5].
    #[cfg_attr(feature = "cli", arg(long, value_name = "N", help_heading = "Image"))]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_depth: Option<u32>,
    /// SPD testing mode: 513x513 corner rays for 512x512, depth 5, ray statistics.
    #[cfg_attr(
        feature = "cli",
        arg(long, num_args = 0..=1, default_missing_value = "true", value_name = "BOOL",
            hide_possible_values = true, help_heading = "Image")
    )]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub spd: Option<bool>,
    /// Antialiasing: `uniform` (`--spp` stratified samples) or `adaptive` (corner rays
    /// shared by neighbouring pixels, subdivided where the corners differ) [default:
    /// uniform].
    #[cfg_attr(feature = "cli", arg(long, value_enum, help_heading = "Image"))]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub aa: Option<AaMode>,
    /// Adaptive AA: largest corner difference (linear, any channel) left unsplit
    /// [default: 0.05].
    #[cfg_attr(feature = "cli", arg(long, value_name = "T", help_heading = "Image"))]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub aa_threshold: Option<f32>,
    /// Adaptive AA: most subdivision levels per pixel, 0 to 8 (0 = the four corners
    /// only) [default: 2].
    #[cfg_attr(feature = "cli", arg(long, value_name = "D", help_heading = "Image"))]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub aa_depth: Option<u32>,
    /// No reflected/refracted ray whose accumulated weight (product of Ks, T and filter
    /// colours from the eye) is below W; 0 = the full ray tree [default: 0.001, 0 with
    /// --spd].
    #[cfg_attr(feature = "cli", arg(long, value_name = "W", help_heading = "Image"))]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bailout: Option<f32>,
    /// Cast the rays that cannot change the image too (shadow rays to lights behind the
    /// surface, reflection rays off Ks = 0): only to measure what skipping them saves.
    #[cfg_attr(
        feature = "cli",
        arg(long, num_args = 0..=1, default_missing_value = "true", value_name = "BOOL",
            hide_possible_values = true, help_heading = "Image")
    )]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub no_skip: Option<bool>,
    /// Shadow rays per emitting triangle (area light), 1 to 4096, rounded down to a
    /// square: 16 = 4×4 strata [default: 16].
    #[cfg_attr(feature = "cli", arg(long, value_name = "N", help_heading = "Image"))]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub area_samples: Option<u32>,
    /// Render the f64 reference instead: everything in double precision, brute-force
    /// traversal, N×N stratified samples per pixel with N = floor(sqrt(--spp))
    /// [default --spp 256: 16×16]. Spheres, cones and triangles only.
    #[cfg_attr(
        feature = "cli",
        arg(long, num_args = 0..=1, default_missing_value = "true", value_name = "BOOL",
            hide_possible_values = true, help_heading = "Image")
    )]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reference: Option<bool>,
    /// Environment map for rays that leave the scene (PNG/JPEG: 2:1 latitude-longitude
    /// or a 4:3 cube cross, or a directory of six cube faces px, nx, py, ny, pz, nz),
    /// replacing the scene's own.
    #[cfg_attr(
        feature = "cli",
        arg(long, value_name = "FILE|DIR", help_heading = "Image")
    )]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub envmap: Option<PathBuf>,
    /// Global illumination: `radiosity` solves the diffuse interreflection first and
    /// takes the diffuse term of polygons and meshes from it (two-pass).
    #[cfg_attr(feature = "cli", arg(long, value_enum, help_heading = "Radiosity"))]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub gi: Option<Gi>,
    /// The radiosity pass of `--gi radiosity` and of `emray radiosity`.
    #[cfg_attr(feature = "cli", command(flatten))]
    #[serde(skip_serializing_if = "RadiosityOptions::is_empty")]
    pub radiosity: RadiosityOptions,
    /// PNG value encoding: `srgb` or `linear` (values written as they are) [default:
    /// srgb]. EXR is always linear.
    #[cfg_attr(feature = "cli", arg(long, value_enum, help_heading = "Output"))]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub encoding: Option<Encoding>,
    /// Output variables to write as EXR layers beside the colour, comma-separated:
    /// depth (Z), normal (N.X N.Y N.Z), albedo (albedo.R/G/B), position (P.X P.Y P.Z),
    /// id (with OUT.ids.json), rays, time; or all (docs/aov.md).
    #[cfg_attr(
        feature = "cli",
        arg(long, value_name = "LIST", help_heading = "Output")
    )]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub aov: Option<AovList>,
    /// A heat map of a per-pixel cost: rays (cast), time (spent) or depth (of the
    /// deepest ray), to a PNG with a colour bar; may be repeated. FILE is a template,
    /// as the output's.
    #[cfg_attr(
        feature = "cli",
        arg(long, num_args = 2, value_names = ["WHAT", "FILE.png"],
            action = clap::ArgAction::Append, help_heading = "Output")
    )]
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub heatmap: Vec<String>,
    /// Render only band I of N horizontal bands of rows (I counts from 0: 0 ≤ I < N),
    /// to an EXR part for `emray merge` (`--tile`, its former name, is taken too).
    #[cfg_attr(
        feature = "cli",
        arg(
            long,
            value_name = "I/N",
            visible_alias = "tile",
            conflicts_with = "crop",
            help_heading = "Parts"
        )
    )]
    #[serde(skip_serializing_if = "Option::is_none", alias = "tile")]
    pub band: Option<Band>,
    /// Render only columns x0..x1 and rows y0..y1 (half-open), to an EXR part.
    #[cfg_attr(
        feature = "cli",
        arg(long, value_name = "x0,x1,y0,y1", help_heading = "Parts")
    )]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub crop: Option<Crop>,
    /// Refuse a render estimated to need more memory (e.g. 8G) [default: 3/4 of RAM].
    #[cfg_attr(
        feature = "cli",
        arg(long, value_name = "SIZE", help_heading = "Limits")
    )]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_memory: Option<ByteSize>,
    /// Embree build quality: low (a Morton-code build), medium (binned SAH) or high
    /// (SAH with spatial splits) [default: medium].
    #[cfg_attr(feature = "cli", arg(long, value_enum, help_heading = "Backend"))]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub embree_quality: Option<EmbreeQuality>,
    /// Embree's fast traversal: without RTC_SCENE_FLAG_ROBUST, which emray sets on every
    /// scene by default so that no ray slips between triangles sharing an edge. Faster
    /// on triangle scenes, at the risk of pinholes in meshes.
    #[cfg_attr(
        feature = "cli",
        arg(long, num_args = 0..=1, default_missing_value = "true", value_name = "BOOL",
            hide_possible_values = true, help_heading = "Backend")
    )]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub embree_fast: Option<bool>,
    /// Embree's compact structure (RTC_SCENE_FLAG_COMPACT): less memory and a faster
    /// build, a somewhat slower render [default: on from 4 Mi (4 194 304) primitives].
    #[cfg_attr(
        feature = "cli",
        arg(long, num_args = 0..=1, default_missing_value = "true", value_name = "BOOL",
            hide_possible_values = true, help_heading = "Backend")
    )]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub embree_compact: Option<bool>,
    /// Analytic primitives (spheres, cones, ...) per Embree user primitive, at most,
    /// grouped with their neighbours in space; the same hits, less memory and a faster
    /// build, a somewhat slower render; 1 to 64 [default: 4 from 4 Mi (4 194 304)
    /// primitives with at least 4 per camera ray, 1 otherwise].
    #[cfg_attr(feature = "cli", arg(long, value_name = "N", help_heading = "Backend"))]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub embree_group: Option<u32>,
    /// Cast each tile's primary rays together, as Embree packets of this many rays (4,
    /// 8 or 16: `rtcIntersect4/8/16`); 0 casts them one by one [default: 8]. Used with
    /// one sample per pixel (SPD mode included).
    #[cfg_attr(feature = "cli", arg(long, value_name = "N", help_heading = "Backend"))]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub packet_width: Option<u32>,
    /// Cast the shadow rays of each depth of a tile together, light by light, as
    /// Embree packets of this many rays (4, 8 or 16: `rtcOccluded4/8/16`); 0 casts them
    /// one by one [default: 8 when the scene holds only triangles and spheres, else 0].
    /// The answers are the same either way.
    #[cfg_attr(feature = "cli", arg(long, value_name = "N", help_heading = "Backend"))]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub shadow_packet_width: Option<u32>,
}

impl RadiosityOptions {
    /// Whether no option is set.
    pub fn is_empty(&self) -> bool {
        *self == RadiosityOptions::default()
    }
}

impl RenderOptions {
    /// These options over `under`: each option set here, else `under`'s (the command
    /// line over a manifest's job over its defaults). Options combine through their
    /// serialised form, so that no field is listed twice: an unset option is left out
    /// of it, and a table (`radiosity`) combines key by key.
    pub fn over(&self, under: &RenderOptions) -> RenderOptions {
        let table = |o: &RenderOptions| match toml::Table::try_from(o) {
            Ok(t) => t,
            Err(e) => unreachable!("render options always serialise: {e}"),
        };
        let mut merged = table(under);
        overlay(&mut merged, table(self));
        match toml::Value::Table(merged).try_into() {
            Ok(o) => o,
            Err(e) => unreachable!("combined render options deserialise: {e}"),
        }
    }

    /// Whether the render gathers output variables (`aov` or `heatmap`).
    pub fn wants_insight(&self) -> bool {
        self.aov.is_some_and(|a| a.0.any()) || !self.heatmap.is_empty()
    }
}

/// Put every key of `over` into `under`, tables key by key.
fn overlay(under: &mut toml::Table, over: toml::Table) {
    for (key, value) in over {
        match (under.get_mut(&key), value) {
            (Some(toml::Value::Table(u)), toml::Value::Table(o)) => overlay(u, o),
            (_, value) => {
                under.insert(key, value);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn options_over_others_take_each_set_field_and_keep_the_rest() {
        let under = RenderOptions {
            spp: Some(4),
            backend: Some(Backend::Bvh),
            spd: Some(true),
            heatmap: vec!["rays".into(), "r.png".into()],
            radiosity: RadiosityOptions {
                patch_size: Some(0.5),
                epsilon: Some(1e-4),
                ..RadiosityOptions::default()
            },
            ..RenderOptions::default()
        };
        let over = RenderOptions {
            spp: Some(16),
            spd: Some(false),
            radiosity: RadiosityOptions {
                epsilon: Some(1e-2),
                ..RadiosityOptions::default()
            },
            ..RenderOptions::default()
        };
        let got = over.over(&under);
        assert_eq!(got.spp, Some(16));
        assert_eq!(got.backend, Some(Backend::Bvh));
        assert_eq!(got.spd, Some(false));
        assert_eq!(got.heatmap, under.heatmap);
        assert_eq!(got.radiosity.patch_size, Some(0.5));
        assert_eq!(got.radiosity.epsilon, Some(1e-2));
        assert_eq!(RenderOptions::default().over(&under), under);
        assert_eq!(under.over(&RenderOptions::default()), under);
    }

    #[test]
    fn every_value_type_survives_the_round_trip() {
        let all = RenderOptions {
            backend: Some(Backend::Embree),
            res: Some("64x32".parse().unwrap()),
            spp: Some(9),
            max_depth: Some(3),
            spd: Some(true),
            aa: Some(AaMode::Adaptive),
            aa_threshold: Some(0.1),
            aa_depth: Some(3),
            bailout: Some(0.01),
            no_skip: Some(true),
            area_samples: Some(4),
            reference: Some(false),
            envmap: Some("sky.png".into()),
            gi: Some(Gi::Radiosity),
            radiosity: RadiosityOptions {
                solver: Some(Solver::GaussSeidel),
                form_factors: Some(FormFactors::Hemicube),
                hemicube_res: Some(64),
                ..RadiosityOptions::default()
            },
            encoding: Some(Encoding::Linear),
            aov: Some("depth,id".parse().unwrap()),
            heatmap: vec!["time".into(), "t.png".into()],
            band: Some("1/4".parse().unwrap()),
            crop: Some("0,8,0,4".parse().unwrap()),
            max_memory: Some("2G".parse().unwrap()),
            embree_quality: Some(EmbreeQuality::High),
            embree_fast: Some(true),
            embree_compact: Some(false),
            embree_group: Some(8),
            packet_width: Some(16),
            shadow_packet_width: Some(4),
        };
        assert_eq!(all.over(&RenderOptions::default()), all);
        let text = toml::to_string(&all).unwrap();
        let back: RenderOptions = toml::from_str(&text).unwrap();
        assert_eq!(back, all, "{text}");
    }

    #[test]
    fn unknown_keys_are_refused() {
        let e = toml::from_str::<RenderOptions>("spp = 4\nspq = 2\n").unwrap_err();
        assert!(e.message().contains("unknown field `spq`"), "{e}");
        let e = toml::from_str::<RenderOptions>("radiosity = { patch = 1 }\n").unwrap_err();
        assert!(e.message().contains("unknown field `patch`"), "{e}");
    }
}
