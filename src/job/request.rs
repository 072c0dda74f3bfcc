//! What a render asks for besides the scene file (from the command line or a batch
//! manifest), and the one function that turns it and the scene into the
//! [`RenderSettings`]: `emray render`, `batch`, `bench` and `radiosity` all resolve
//! their settings through [`RenderRequest::settings`].

use crate::render::{Aa, DEFAULT_BAILOUT, Region, RenderSettings};
use crate::scene::Scene;

/// Image side in SPD testing mode when no resolution is asked for: 512 × 512 pixels
/// from a 513 × 513 grid of corner rays.
pub const SPD_SIDE: u32 = 512;
/// Ray-tree depth in SPD testing mode, whatever the request or the scene says.
pub const SPD_MAX_DEPTH: u32 = 5;
/// Samples per pixel when neither the request nor the scene file gives them.
pub const DEFAULT_SPP: u32 = 1;
/// Ray-tree depth when neither the request nor the scene file gives one.
pub const DEFAULT_MAX_DEPTH: u32 = 5;

/// The part of the image a render makes, for `emray merge` to put together.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Part {
    /// Horizontal band `index` of `count` (rows split as evenly as they go); `index`
    /// counts from 0.
    Tile {
        /// Which band, from 0.
        index: u32,
        /// How many bands.
        count: u32,
    },
    /// A rectangle of pixels, which must lie inside the image.
    Crop(Region),
}

/// What a render asks for besides the scene; `None` (or `false`) leaves the scene
/// file's `[render]` hint or the renderer's default.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RenderRequest {
    /// Image size, overriding the scene camera's.
    pub res: Option<(u32, u32)>,
    /// Samples per pixel [default: the scene file's, else [`DEFAULT_SPP`]].
    pub spp: Option<u32>,
    /// Maximum ray-tree depth [default: the scene file's, else [`DEFAULT_MAX_DEPTH`]].
    pub max_depth: Option<u32>,
    /// SPD testing mode: [`SPD_SIDE`]² unless `res` is given, one sample per pixel,
    /// depth [`SPD_MAX_DEPTH`], no bailout unless `bailout` is given.
    pub spd: bool,
    /// Bailout weight [default: [`DEFAULT_BAILOUT`], 0 in SPD mode].
    pub bailout: Option<f32>,
    /// Antialiasing [default: uniform].
    pub aa: Option<Aa>,
    /// Cast the rays that cannot change the image too (to measure what skipping
    /// them saves).
    pub cast_skippable: bool,
    /// Shadow rays per emitting triangle, rounded down to a square number (at least
    /// 1) [default: the renderer's, 16].
    pub area_samples: Option<u32>,
    /// Render only this part of the image.
    pub part: Option<Part>,
}

/// A request that cannot be met for this scene.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SettingsError {
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
    /// The tile index is not below the tile count.
    #[error("tile {index}/{count}: need 0 <= I < N")]
    TileOutOfRange {
        /// Band index.
        index: u32,
        /// Band count.
        count: u32,
    },
    /// More tiles than rows: this tile has none.
    #[error("--tile leaves no rows for this part of a {height}-row image (use fewer tiles)")]
    EmptyTile {
        /// Image height.
        height: u32,
    },
}

impl RenderRequest {
    /// The settings for rendering `scene`: the scene's resolution and `[render]`
    /// hints, overridden by this request, with the renderer's defaults for the rest.
    pub fn settings(&self, scene: &Scene) -> Result<RenderSettings, SettingsError> {
        let mut s = RenderSettings::for_scene(scene);
        if let Some((w, h)) = self.res {
            s.width = w;
            s.height = h;
        }
        s.spp = self.spp.or(scene.render.spp).unwrap_or(DEFAULT_SPP);
        s.max_depth = self
            .max_depth
            .or(scene.render.max_depth)
            .unwrap_or(DEFAULT_MAX_DEPTH);
        if self.spd {
            if self.res.is_none() {
                s.width = SPD_SIDE;
                s.height = SPD_SIDE;
            }
            s.spd = true;
            s.spp = 1;
            s.max_depth = SPD_MAX_DEPTH;
        }
        let default_bailout = if self.spd { 0.0 } else { DEFAULT_BAILOUT };
        s.bailout = self.bailout.unwrap_or(default_bailout);
        if let Some(aa) = self.aa {
            s.aa = aa;
        }
        s.skip = !self.cast_skippable;
        if let Some(n) = self.area_samples {
            s.area_samples = (n as f32).sqrt().floor().max(1.0) as u32;
        }
        s.region = self.region(s.width, s.height)?;
        Ok(s)
    }

    /// The region of a `width × height` image that [`RenderRequest::part`] asks for.
    fn region(&self, width: u32, height: u32) -> Result<Option<Region>, SettingsError> {
        match self.part {
            None => Ok(None),
            Some(Part::Tile { index, count }) => {
                if index >= count {
                    return Err(SettingsError::TileOutOfRange { index, count });
                }
                let band = Region::band(index, count, width, height);
                if band.height() == 0 {
                    return Err(SettingsError::EmptyTile { height });
                }
                Ok(Some(band))
            }
            Some(Part::Crop(crop)) if crop.fits(width, height) => Ok(Some(crop)),
            Some(Part::Crop(crop)) => Err(SettingsError::CropOutside {
                crop,
                width,
                height,
            }),
        }
    }
}

/// A malformed `I/N` (part `I` of `N`, counting from 0) of `--tile` or `--shard`.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum IndexOfError {
    /// No `/`.
    #[error("{what} '{spec}' is not I/N (e.g. 0/4)")]
    NotIndexOf {
        /// `tile` or `shard`.
        what: &'static str,
        /// As given.
        spec: String,
    },
    /// `I` is not a whole number.
    #[error("bad {what} index in '{spec}'")]
    Index {
        /// `tile` or `shard`.
        what: &'static str,
        /// As given.
        spec: String,
    },
    /// `N` is not a whole number.
    #[error("bad {what} count in '{spec}'")]
    Count {
        /// `tile` or `shard`.
        what: &'static str,
        /// As given.
        spec: String,
    },
    /// Not `0 <= I < N`.
    #[error("{what} '{spec}': need 0 <= I < N")]
    OutOfRange {
        /// `tile` or `shard`.
        what: &'static str,
        /// As given.
        spec: String,
    },
}

/// Parse `I/N` with `0 <= I < N`; `what` (`tile`, `shard`) names it in errors.
pub fn parse_index_of(what: &'static str, s: &str) -> Result<(u32, u32), IndexOfError> {
    let spec = || s.to_string();
    let (i, n) = s
        .split_once('/')
        .ok_or_else(|| IndexOfError::NotIndexOf { what, spec: spec() })?;
    let i: u32 = i
        .trim()
        .parse()
        .map_err(|_| IndexOfError::Index { what, spec: spec() })?;
    let n: u32 = n
        .trim()
        .parse()
        .map_err(|_| IndexOfError::Count { what, spec: spec() })?;
    if n == 0 || i >= n {
        return Err(IndexOfError::OutOfRange { what, spec: spec() });
    }
    Ok((i, n))
}

/// Parse `--tile I/N` (band `I` of `N`, `0 <= I < N`).
pub fn parse_tile(s: &str) -> Result<(u32, u32), IndexOfError> {
    parse_index_of("tile", s)
}

/// A malformed `--crop`.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum CropSpecError {
    /// Not four whole numbers.
    #[error("crop '{0}' is not x0,x1,y0,y1 (four whole numbers)")]
    NotFour(String),
    /// An empty rectangle.
    #[error("crop '{0}': need x0 < x1 and y0 < y1")]
    Empty(String),
}

/// Parse a crop `x0,x1,y0,y1` (pixel columns x0..x1 and rows y0..y1, half-open).
pub fn parse_crop(s: &str) -> Result<Region, CropSpecError> {
    let not_four = || CropSpecError::NotFour(s.to_string());
    let v: Vec<u32> = s
        .split(',')
        .map(|t| t.trim().parse::<u32>())
        .collect::<Result<_, _>>()
        .map_err(|_| not_four())?;
    let [x0, x1, y0, y1] = v[..] else {
        return Err(not_four());
    };
    if x0 >= x1 || y0 >= y1 {
        return Err(CropSpecError::Empty(s.to_string()));
    }
    Ok(Region { x0, x1, y0, y1 })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene(hints: &str) -> Scene {
        let mut s = crate::load::nff::parse_str(
            "v\nfrom 0 0 5\nat 0 0 0\nup 0 1 0\nangle 40\nhither 1\nresolution 40 30\n\
             s 0 0 0 1\n",
            std::path::Path::new("t.nff"),
        )
        .unwrap();
        if hints == "hints" {
            s.render.spp = Some(9);
            s.render.max_depth = Some(3);
        }
        s
    }

    #[test]
    fn defaults_hints_and_overrides() {
        let plain = RenderRequest::default().settings(&scene("")).unwrap();
        assert_eq!((plain.width, plain.height), (40, 30));
        assert_eq!((plain.spp, plain.max_depth), (1, 5));
        assert_eq!(plain.bailout, DEFAULT_BAILOUT);
        assert!(plain.skip && !plain.spd && plain.region.is_none());
        let hinted = RenderRequest::default().settings(&scene("hints")).unwrap();
        assert_eq!((hinted.spp, hinted.max_depth), (9, 3));
        let asked = RenderRequest {
            res: Some((8, 6)),
            spp: Some(4),
            max_depth: Some(7),
            bailout: Some(0.5),
            cast_skippable: true,
            area_samples: Some(10),
            ..RenderRequest::default()
        };
        let s = asked.settings(&scene("hints")).unwrap();
        assert_eq!((s.width, s.height, s.spp, s.max_depth), (8, 6, 4, 7));
        assert_eq!((s.bailout, s.skip, s.area_samples), (0.5, false, 3));
    }

    #[test]
    fn spd_mode_wins_over_the_scene_and_keeps_an_explicit_size_and_bailout() {
        let spd = RenderRequest {
            spd: true,
            spp: Some(16),
            ..RenderRequest::default()
        };
        let s = spd.settings(&scene("hints")).unwrap();
        assert_eq!((s.width, s.height), (SPD_SIDE, SPD_SIDE));
        assert_eq!((s.spp, s.max_depth, s.bailout), (1, SPD_MAX_DEPTH, 0.0));
        assert!(s.spd);
        let sized = RenderRequest {
            res: Some((64, 32)),
            bailout: Some(0.01),
            ..spd
        };
        let s = sized.settings(&scene("")).unwrap();
        assert_eq!((s.width, s.height, s.bailout), (64, 32, 0.01));
    }

    #[test]
    fn tiles_and_crops_become_regions_or_clear_errors() {
        let part = |p: Part| {
            RenderRequest {
                part: Some(p),
                ..RenderRequest::default()
            }
            .settings(&scene(""))
        };
        let tile = part(Part::Tile { index: 1, count: 3 }).unwrap();
        assert_eq!(tile.region, Some(Region::band(1, 3, 40, 30)));
        assert_eq!(
            part(Part::Tile { index: 3, count: 3 }).unwrap_err(),
            SettingsError::TileOutOfRange { index: 3, count: 3 }
        );
        let e = part(Part::Tile {
            index: 0,
            count: 31,
        })
        .unwrap_err();
        assert_eq!(
            e.to_string(),
            "--tile leaves no rows for this part of a 30-row image (use fewer tiles)"
        );
        let inside = Region {
            x0: 1,
            x1: 40,
            y0: 0,
            y1: 2,
        };
        assert_eq!(part(Part::Crop(inside)).unwrap().region, Some(inside));
        let outside = Region { x1: 41, ..inside };
        assert_eq!(
            part(Part::Crop(outside)).unwrap_err().to_string(),
            "crop 1,41,0,2 is not inside the 40x30 image"
        );
    }

    #[test]
    fn index_of_and_crop_parse_and_name_themselves() {
        assert_eq!(parse_tile("2/5"), Ok((2, 5)));
        assert_eq!(
            parse_tile("4/4").unwrap_err().to_string(),
            "tile '4/4': need 0 <= I < N"
        );
        assert_eq!(
            parse_index_of("shard", "5/5").unwrap_err().to_string(),
            "shard '5/5': need 0 <= I < N"
        );
        assert!(parse_tile("1/0").is_err());
        assert!(parse_tile("x").is_err());
        assert_eq!(
            parse_crop("1,5,2,9"),
            Ok(Region {
                x0: 1,
                x1: 5,
                y0: 2,
                y1: 9
            })
        );
        assert!(parse_crop("5,1,2,9").is_err());
        assert!(parse_crop("1,2,3").is_err());
    }

    #[test]
    fn bands_cover_every_row_once() {
        for n in 1..=9 {
            let mut next = 0;
            for i in 0..n {
                let r = Region::band(i, n, 7, 23);
                assert_eq!(r.y0, next);
                next = r.y1;
            }
            assert_eq!(next, 23);
        }
    }
}
