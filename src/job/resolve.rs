//! [`RenderOptions`] checked and resolved against a scene: every default of a render
//! is applied here and nowhere else. [`RenderOptions::check`] finds, before any work,
//! what no scene can make right (a value out of range, options that cannot go
//! together); [`RenderOptions::resolve`] then turns the options and the scene's own
//! hints into what the stages take: the renderer's [`RenderSettings`], the backend's
//! [`BackendOptions`], the radiosity pass's [`RadiositySettings`] and the outputs'
//! encoding, layers and heat maps.

use super::options::{AaMode, FormFactors, Gi, RadiosityOptions, RenderOptions, Solver};
use super::values::Band;
use crate::accel::{Backend, BackendOptions, DEFAULT_PACKET_WIDTH};
use crate::output::Encoding;
use crate::output::heatmap::Quantity;
use crate::radiosity::{FormFactorMethod, RadiositySettings, SolverKind};
use crate::render::aov::AovSet;
use crate::render::{
    Aa, DEFAULT_AA_DEPTH, DEFAULT_AA_THRESHOLD, DEFAULT_AREA_SAMPLES, DEFAULT_BAILOUT,
    DEFAULT_MAX_DEPTH, DEFAULT_SPP, Region, RenderSettings, SPD_MAX_DEPTH, SPD_SIDE,
};
use crate::scene::Scene;

/// Samples per pixel of the f64 reference when none are asked for (16×16 strata).
pub const DEFAULT_REFERENCE_SPP: u32 = 256;

/// Options that cannot be met, named as the command line and a manifest name them.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum OptionsError {
    /// A number outside its range.
    #[error("{key} must be {range}, not {value}")]
    Range {
        /// The option (`spp`, `max_depth`, ...).
        key: &'static str,
        /// What it may be.
        range: &'static str,
        /// What it was.
        value: String,
    },
    /// Options that cannot go together, or a value that cannot be used.
    #[error("{0}")]
    Conflict(String),
    /// The crop reaches outside the image.
    #[error(
        "crop {},{},{},{} is not inside the {width}x{height} image",
        crop.x0, crop.x1, crop.y0, crop.y1
    )]
    CropOutside {
        /// The crop asked for.
        crop: Region,
        /// Image width.
        width: u32,
        /// Image height.
        height: u32,
    },
    /// More bands than rows: this band has none.
    #[error("--band leaves no rows for this part of a {height}-row image (use fewer bands)")]
    EmptyTile {
        /// Image height.
        height: u32,
    },
}

/// A heat map asked for: what it shows and the template of its file.
#[derive(Clone, Debug, PartialEq)]
pub struct Heatmap {
    /// What it shows.
    pub quantity: Quantity,
    /// Its file, a template as the output's.
    pub template: String,
}

/// Options resolved against a scene: what each stage takes.
#[derive(Clone, Debug, PartialEq)]
pub struct Resolved {
    /// The renderer's settings.
    pub settings: RenderSettings,
    /// The backend and how to build it.
    pub backend: BackendOptions,
    /// The radiosity pass, in two-pass mode (`gi = "radiosity"`).
    pub radiosity: Option<RadiositySettings>,
    /// PNG encoding.
    pub encoding: Encoding,
    /// The output variables written as EXR layers.
    pub layers: AovSet,
    /// The heat maps.
    pub heatmaps: Vec<Heatmap>,
    /// `N` of the f64 reference's `N × N` samples per pixel, when it renders instead.
    pub reference: Option<u32>,
    /// The memory the render may need, in bytes.
    pub max_memory: u64,
}

impl Resolved {
    /// The output variables the render gathers: the layers, and what the heat maps
    /// show (rays are always counted; time is measured only when asked for).
    pub fn gathered(&self) -> AovSet {
        let mut g = self.layers;
        for m in &self.heatmaps {
            match m.quantity {
                Quantity::Rays => {}
                Quantity::Time => g.time = true,
                Quantity::Depth => g.tree_depth = true,
            }
        }
        g
    }

    /// Whether the render gathers output variables.
    pub fn wants_insight(&self) -> bool {
        self.layers.any() || !self.heatmaps.is_empty()
    }
}

/// `Err` naming `key` unless `value` lies in `lo..=hi`.
fn in_range(
    key: &'static str,
    value: Option<u32>,
    lo: u32,
    hi: u32,
    range: &'static str,
) -> Result<(), OptionsError> {
    match value {
        Some(v) if v < lo || v > hi => Err(OptionsError::Range {
            key,
            range,
            value: v.to_string(),
        }),
        _ => Ok(()),
    }
}

/// `Err` naming `key` unless `value` is one of `allowed`.
fn one_of(
    key: &'static str,
    value: Option<u32>,
    allowed: &[u32],
    range: &'static str,
) -> Result<(), OptionsError> {
    match value {
        Some(v) if !allowed.contains(&v) => Err(OptionsError::Range {
            key,
            range,
            value: v.to_string(),
        }),
        _ => Ok(()),
    }
}

/// `Err` naming `key` unless `value` is finite and at least 0.
fn non_negative(key: &'static str, value: Option<f64>) -> Result<(), OptionsError> {
    match value {
        Some(v) if !v.is_finite() || v < 0.0 => Err(OptionsError::Range {
            key,
            range: "a finite number >= 0",
            value: v.to_string(),
        }),
        _ => Ok(()),
    }
}

/// `4^level = n` for `n` in 1, 4, 16, 64.
fn level_of(n: u32) -> u32 {
    n.trailing_zeros() / 2
}

impl RadiosityOptions {
    /// Values out of range.
    fn check(&self) -> Result<(), OptionsError> {
        const COUNTS: &[u32] = &[1, 4, 16, 64];
        one_of("ff_samples", self.ff_samples, COUNTS, "one of 1, 4, 16, 64")?;
        one_of(
            "vis_samples",
            self.vis_samples,
            COUNTS,
            "one of 1, 4, 16, 64",
        )?;
        in_range(
            "hemicube_res",
            self.hemicube_res,
            2,
            4096,
            "even, 2 to 4096",
        )?;
        if self.hemicube_res.is_some_and(|r| r % 2 == 1) {
            in_range("hemicube_res", self.hemicube_res, 0, 0, "even, 2 to 4096")?;
        }
        for (key, v) in [
            ("patch_size", self.patch_size),
            ("min_patch_size", self.min_patch_size),
            ("subdiv_threshold", self.subdiv_threshold),
        ] {
            non_negative(key, v.map(f64::from))?;
        }
        non_negative("epsilon", self.epsilon)
    }

    /// The solver's settings, with its defaults for what is not set.
    pub fn settings(&self) -> RadiositySettings {
        let d = RadiositySettings::default();
        RadiositySettings {
            patch_size: self.patch_size.or(d.patch_size),
            shooter_level: self.ff_samples.map_or(d.shooter_level, level_of),
            visibility_level: self.vis_samples.map_or(d.visibility_level, level_of),
            epsilon: self.epsilon.unwrap_or(d.epsilon),
            max_iterations: self.max_iterations.unwrap_or(d.max_iterations),
            solver: match self.solver {
                None => d.solver,
                Some(Solver::Progressive) => SolverKind::Progressive,
                Some(Solver::GaussSeidel) => SolverKind::GaussSeidel,
            },
            form_factors: match self.form_factors {
                None => d.form_factors,
                Some(FormFactors::Raycast) => FormFactorMethod::RayCast,
                Some(FormFactors::Hemicube) => FormFactorMethod::Hemicube(
                    self.hemicube_res
                        .unwrap_or(crate::radiosity::hemicube::DEFAULT_RES),
                ),
            },
            subdiv_threshold: self.subdiv_threshold.or(d.subdiv_threshold),
            min_patch_size: self.min_patch_size.or(d.min_patch_size),
            subdiv_passes: self.subdiv_passes.unwrap_or(d.subdiv_passes),
        }
    }
}

/// The camera rays a render with `settings` casts at the least: a sample per pixel
/// position of its region (one more row and column in SPD mode) times the samples per
/// pixel.
fn camera_rays(settings: &RenderSettings) -> u64 {
    let r = settings
        .region
        .unwrap_or(Region::full(settings.width, settings.height));
    let extra = u64::from(settings.spd);
    (r.width() as u64 + extra) * (r.height() as u64 + extra) * u64::from(settings.spp.max(1))
}

impl RenderOptions {
    /// What no scene can make right: values out of range, options that cannot go
    /// together, heat maps that are not `WHAT FILE.png` pairs.
    pub fn check(&self) -> Result<(), OptionsError> {
        in_range("spp", self.spp, 1, 65536, "1 to 65536")?;
        in_range("max_depth", self.max_depth, 1, 64, "1 to 64")?;
        in_range("aa_depth", self.aa_depth, 0, 8, "0 to 8")?;
        in_range("embree_group", self.embree_group, 1, 64, "1 to 64")?;
        in_range("area_samples", self.area_samples, 1, 4096, "1 to 4096")?;
        one_of(
            "packet_width",
            self.packet_width,
            &[0, 4, 8, 16],
            "0, 4, 8 or 16",
        )?;
        one_of(
            "shadow_packet_width",
            self.shadow_packet_width,
            &[0, 4, 8, 16],
            "0, 4, 8 or 16",
        )?;
        non_negative("bailout", self.bailout.map(f64::from))?;
        non_negative("aa_threshold", self.aa_threshold.map(f64::from))?;
        self.radiosity.check()?;
        self.heatmaps()?;
        let adaptive = self.aa == Some(AaMode::Adaptive);
        let reference = self.reference == Some(true);
        let spd = self.spd == Some(true);
        let conflict = |m: &str| Err(OptionsError::Conflict(m.into()));
        if reference && (spd || adaptive) {
            return conflict(
                "--reference samples N×N stratified: it cannot be combined with --spd or --aa adaptive",
            );
        }
        if self.wants_insight() && (reference || (adaptive && !spd)) {
            return conflict(
                "--aov and --heatmap look inside the Whitted renderer's uniform samples: not with \
                 --reference or --aa adaptive",
            );
        }
        if self.band.is_some() || self.crop.is_some() {
            if reference {
                return conflict("--reference renders whole images: not with --band or --crop");
            }
            if self.gi.is_some() {
                // Each part would solve the radiosity on its own; the hash does not cover it.
                return conflict("--gi renders whole images: not with --band or --crop");
            }
        }
        Ok(())
    }

    /// The heat maps asked for: `WHAT FILE.png` pairs, each a known quantity.
    pub fn heatmaps(&self) -> Result<Vec<Heatmap>, OptionsError> {
        let bad = |m: String| Err(OptionsError::Conflict(m));
        let mut out = Vec::new();
        for pair in self.heatmap.chunks(2) {
            let [what, file] = pair else {
                return bad(
                    "--heatmap takes two values: WHAT (rays, time or depth) and FILE.png".into(),
                );
            };
            let Some(quantity) = Quantity::from_name(what) else {
                return bad(format!(
                    "--heatmap {what}: unknown quantity (one of {})",
                    Quantity::NAMES.join(", ")
                ));
            };
            if !file.to_ascii_lowercase().ends_with(".png") {
                return bad(format!(
                    "--heatmap {what} {file}: a heat map is a PNG (name it FILE.png)"
                ));
            }
            out.push(Heatmap {
                quantity,
                template: file.clone(),
            });
        }
        Ok(out)
    }

    /// The backend and how to build it, the render's camera rays not yet known (see
    /// [`RenderOptions::resolve`]).
    pub fn backend_options(&self) -> BackendOptions {
        BackendOptions {
            backend: self.backend.unwrap_or_else(Backend::default_available),
            embree_quality: self.embree_quality.unwrap_or_default(),
            embree_robust: self.embree_fast != Some(true),
            embree_compact: self.embree_compact,
            embree_group: self.embree_group,
            camera_rays: 0,
            packet_width: self.packet_width.unwrap_or(DEFAULT_PACKET_WIDTH),
            shadow_packet_width: self.shadow_packet_width,
        }
    }

    /// The options resolved against `scene`: its resolution and `[render]` hints,
    /// overridden by these options, with the defaults for the rest.
    pub fn resolve(&self, scene: &Scene) -> Result<Resolved, OptionsError> {
        self.check()?;
        let reference = (self.reference == Some(true)).then(|| {
            let spp = self.spp.unwrap_or(DEFAULT_REFERENCE_SPP);
            (spp as f64).sqrt().floor() as u32
        });
        let settings = self.settings(scene)?;
        Ok(Resolved {
            backend: BackendOptions {
                camera_rays: camera_rays(&settings),
                ..self.backend_options()
            },
            settings,
            radiosity: self.gi.map(|Gi::Radiosity| self.radiosity.settings()),
            encoding: self.encoding.unwrap_or_default(),
            layers: self.aov.map(|a| a.0).unwrap_or_default(),
            heatmaps: self.heatmaps()?,
            reference,
            max_memory: self.memory_limit(),
        })
    }

    /// The memory limit in bytes: `--max-memory`, else three quarters of the machine's.
    pub fn memory_limit(&self) -> u64 {
        self.max_memory
            .map_or_else(super::limits::default_max_memory, |b| b.0)
    }

    /// The renderer's settings for `scene`.
    fn settings(&self, scene: &Scene) -> Result<RenderSettings, OptionsError> {
        let mut s = RenderSettings::for_scene(scene);
        let spd = self.spd == Some(true);
        if let Some(res) = self.res {
            (s.width, s.height) = (res.width, res.height);
        } else if spd {
            (s.width, s.height) = (SPD_SIDE, SPD_SIDE);
        }
        s.spp = self.spp.or(scene.render.spp).unwrap_or(DEFAULT_SPP);
        s.max_depth = self
            .max_depth
            .or(scene.render.max_depth)
            .unwrap_or(DEFAULT_MAX_DEPTH);
        if spd {
            s.spd = true;
            s.spp = 1;
            s.max_depth = SPD_MAX_DEPTH;
        }
        let default_bailout = if spd { 0.0 } else { DEFAULT_BAILOUT };
        s.bailout = self.bailout.unwrap_or(default_bailout);
        if self.aa == Some(AaMode::Adaptive) {
            s.aa = Aa::Adaptive {
                threshold: self.aa_threshold.unwrap_or(DEFAULT_AA_THRESHOLD),
                depth: self.aa_depth.unwrap_or(DEFAULT_AA_DEPTH),
            };
        }
        s.skip = self.no_skip != Some(true);
        let samples = self.area_samples.unwrap_or(DEFAULT_AREA_SAMPLES);
        s.area_strata = (samples as f32).sqrt().floor().max(1.0) as u32;
        s.region = self.region(s.width, s.height)?;
        Ok(s)
    }

    /// The region of a `width × height` image that `band` or `crop` asks for.
    fn region(&self, width: u32, height: u32) -> Result<Option<Region>, OptionsError> {
        if let Some(Band { index, count }) = self.band {
            let band = Region::band(index, count, width, height);
            if band.height() == 0 {
                return Err(OptionsError::EmptyTile { height });
            }
            return Ok(Some(band));
        }
        match self.crop {
            None => Ok(None),
            Some(crop) if crop.0.fits(width, height) => Ok(Some(crop.0)),
            Some(crop) => Err(OptionsError::CropOutside {
                crop: crop.0,
                width,
                height,
            }),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene(hints: bool) -> Scene {
        let mut s = crate::load::nff::parse_str(
            "v\nfrom 0 0 5\nat 0 0 0\nup 0 1 0\nangle 40\nhither 1\nresolution 40 30\n\
             s 0 0 0 1\n",
            std::path::Path::new("t.nff"),
        )
        .unwrap();
        if hints {
            s.render.spp = Some(9);
            s.render.max_depth = Some(3);
        }
        s
    }

    fn settings(o: &RenderOptions, hints: bool) -> RenderSettings {
        o.resolve(&scene(hints)).unwrap().settings
    }

    #[test]
    fn defaults_hints_and_overrides() {
        let plain = settings(&RenderOptions::default(), false);
        assert_eq!((plain.width, plain.height), (40, 30));
        assert_eq!((plain.spp, plain.max_depth), (1, 5));
        assert_eq!(plain.bailout, DEFAULT_BAILOUT);
        assert!(plain.skip && !plain.spd && plain.region.is_none());
        let hinted = settings(&RenderOptions::default(), true);
        assert_eq!((hinted.spp, hinted.max_depth), (9, 3));
        let asked = RenderOptions {
            res: Some("8x6".parse().unwrap()),
            spp: Some(4),
            max_depth: Some(7),
            bailout: Some(0.5),
            no_skip: Some(true),
            area_samples: Some(10),
            ..RenderOptions::default()
        };
        let s = settings(&asked, true);
        assert_eq!((s.width, s.height, s.spp, s.max_depth), (8, 6, 4, 7));
        assert_eq!((s.bailout, s.skip, s.area_strata), (0.5, false, 3));
    }

    #[test]
    fn spd_mode_wins_over_the_scene_and_keeps_an_explicit_size_and_bailout() {
        let spd = RenderOptions {
            spd: Some(true),
            spp: Some(16),
            ..RenderOptions::default()
        };
        let s = settings(&spd, true);
        assert_eq!((s.width, s.height), (SPD_SIDE, SPD_SIDE));
        assert_eq!((s.spp, s.max_depth, s.bailout), (1, SPD_MAX_DEPTH, 0.0));
        assert!(s.spd);
        let sized = RenderOptions {
            res: Some("64x32".parse().unwrap()),
            bailout: Some(0.01),
            ..spd
        };
        let s = settings(&sized, false);
        assert_eq!((s.width, s.height, s.bailout), (64, 32, 0.01));
    }

    #[test]
    fn bands_and_crops_become_regions_or_clear_errors() {
        let part = |band: Option<&str>, crop: Option<&str>| {
            RenderOptions {
                band: band.map(|t| t.parse().unwrap()),
                crop: crop.map(|c| c.parse().unwrap()),
                ..RenderOptions::default()
            }
            .resolve(&scene(false))
            .map(|r| r.settings.region)
        };
        assert_eq!(
            part(Some("1/3"), None),
            Ok(Some(Region::band(1, 3, 40, 30)))
        );
        assert_eq!(
            part(Some("0/31"), None).unwrap_err().to_string(),
            "--band leaves no rows for this part of a 30-row image (use fewer bands)"
        );
        let inside = Region {
            x0: 1,
            x1: 40,
            y0: 0,
            y1: 2,
        };
        assert_eq!(part(None, Some("1,40,0,2")), Ok(Some(inside)));
        assert_eq!(
            part(None, Some("1,41,0,2")).unwrap_err().to_string(),
            "crop 1,41,0,2 is not inside the 40x30 image"
        );
    }

    #[test]
    fn ranges_and_conflicts_are_named() {
        let err = |o: RenderOptions| o.check().unwrap_err().to_string();
        assert_eq!(
            err(RenderOptions {
                spp: Some(0),
                ..RenderOptions::default()
            }),
            "spp must be 1 to 65536, not 0"
        );
        assert_eq!(
            err(RenderOptions {
                packet_width: Some(3),
                ..RenderOptions::default()
            }),
            "packet_width must be 0, 4, 8 or 16, not 3"
        );
        assert!(
            err(RenderOptions {
                bailout: Some(f32::NAN),
                ..RenderOptions::default()
            })
            .starts_with("bailout must be a finite number >= 0")
        );
        assert!(
            err(RenderOptions {
                reference: Some(true),
                spd: Some(true),
                ..RenderOptions::default()
            })
            .contains("--reference")
        );
        assert!(
            err(RenderOptions {
                heatmap: vec!["colour".into(), "c.png".into()],
                ..RenderOptions::default()
            })
            .contains("unknown quantity")
        );
        assert_eq!(
            err(RenderOptions {
                radiosity: RadiosityOptions {
                    ff_samples: Some(8),
                    ..RadiosityOptions::default()
                },
                ..RenderOptions::default()
            }),
            "ff_samples must be one of 1, 4, 16, 64, not 8"
        );
    }

    #[test]
    fn radiosity_defaults_are_the_solvers() {
        assert_eq!(
            RadiosityOptions::default().settings(),
            RadiositySettings::default()
        );
        let hemicube = RadiosityOptions {
            form_factors: Some(FormFactors::Hemicube),
            ff_samples: Some(16),
            ..RadiosityOptions::default()
        }
        .settings();
        assert_eq!(
            hemicube.form_factors,
            FormFactorMethod::Hemicube(crate::radiosity::hemicube::DEFAULT_RES)
        );
        assert_eq!(hemicube.shooter_level, 2);
    }
}
