//! The values of [`super::RenderOptions`] that are written as text (`640x480`, `1/4`,
//! `0,8,0,4`, `8G`, `depth,normal`): each parses from and prints back to that text, on
//! the command line and in a manifest alike, and refuses what it cannot be with a
//! message that names it.

use crate::render::Region;
use crate::render::aov::AovSet;
use serde::{Deserialize, Serialize};
use std::fmt;
use std::str::FromStr;

/// Largest accepted image side; larger sizes are refused before any allocation.
pub const MAX_SIDE: u32 = 65536;
/// Largest accepted pixel count (2^28, 268 megapixels).
pub const MAX_PIXELS: u64 = 1 << 28;

/// Implements `Display`, and serde through the text, for a type with `FromStr`.
macro_rules! as_text {
    ($t:ty) => {
        impl Serialize for $t {
            fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
                s.collect_str(self)
            }
        }

        impl<'de> Deserialize<'de> for $t {
            fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
                let text = String::deserialize(d)?;
                text.parse().map_err(serde::de::Error::custom)
            }
        }
    };
}

/// An image size, `WxH`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Res {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
}

impl FromStr for Res {
    type Err = String;
    fn from_str(s: &str) -> Result<Res, String> {
        let (w, h) = s
            .split_once(['x', 'X'])
            .ok_or_else(|| format!("'{s}' is not WxH (e.g. 640x480)"))?;
        let width: u32 = w
            .trim()
            .parse()
            .map_err(|_| format!("bad width in '{s}'"))?;
        let height: u32 = h
            .trim()
            .parse()
            .map_err(|_| format!("bad height in '{s}'"))?;
        if width == 0 || height == 0 {
            return Err(format!("'{s}': width and height must be at least 1"));
        }
        if width > MAX_SIDE || height > MAX_SIDE || width as u64 * height as u64 > MAX_PIXELS {
            return Err(format!(
                "'{s}' is too large (at most {MAX_SIDE} per side and {MAX_PIXELS} pixels)"
            ));
        }
        Ok(Res { width, height })
    }
}

impl fmt::Display for Res {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}x{}", self.width, self.height)
    }
}
as_text!(Res);

/// `I/N`: part `I` of `N`, counting from 0 (`0 <= I < N`): a band of image rows
/// (`band`), or a shard of a batch.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Band {
    /// Which part, from 0.
    pub index: u32,
    /// How many parts.
    pub count: u32,
}

impl Band {
    /// Parse `I/N` with `0 <= I < N`; `what` (`band`, `shard`) names it in errors.
    pub fn parse(what: &str, s: &str) -> Result<Band, String> {
        let (i, n) = s
            .split_once('/')
            .ok_or_else(|| format!("{what} '{s}' is not I/N (e.g. 0/4)"))?;
        let index: u32 = i
            .trim()
            .parse()
            .map_err(|_| format!("bad {what} index in '{s}'"))?;
        let count: u32 = n
            .trim()
            .parse()
            .map_err(|_| format!("bad {what} count in '{s}'"))?;
        if count == 0 || index >= count {
            return Err(format!("{what} '{s}': need 0 <= I < N"));
        }
        Ok(Band { index, count })
    }
}

impl FromStr for Band {
    type Err = String;
    fn from_str(s: &str) -> Result<Band, String> {
        Band::parse("band", s)
    }
}

impl fmt::Display for Band {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}
as_text!(Band);

/// A rectangle of pixels, `x0,x1,y0,y1` (columns x0..x1 and rows y0..y1, half-open).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Crop(pub Region);

impl FromStr for Crop {
    type Err = String;
    fn from_str(s: &str) -> Result<Crop, String> {
        let not_four = || format!("crop '{s}' is not x0,x1,y0,y1 (four whole numbers)");
        let v: Vec<u32> = s
            .split(',')
            .map(|t| t.trim().parse::<u32>())
            .collect::<Result<_, _>>()
            .map_err(|_| not_four())?;
        let [x0, x1, y0, y1] = v[..] else {
            return Err(not_four());
        };
        if x0 >= x1 || y0 >= y1 {
            return Err(format!("crop '{s}': need x0 < x1 and y0 < y1"));
        }
        Ok(Crop(Region { x0, x1, y0, y1 }))
    }
}

impl fmt::Display for Crop {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let r = &self.0;
        write!(f, "{},{},{},{}", r.x0, r.x1, r.y0, r.y1)
    }
}
as_text!(Crop);

/// A size in bytes: a number, or one with `K`, `M`, `G` or `T` (binary multiples;
/// `KiB`/`KB`-style suffixes are accepted too).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ByteSize(pub u64);

impl FromStr for ByteSize {
    type Err = String;
    fn from_str(s: &str) -> Result<ByteSize, String> {
        let t = s.trim();
        let bad = || format!("'{s}' is not a size (e.g. 512M, 4G, 1.5G, 1000000)");
        let split = t
            .find(|c: char| !(c.is_ascii_digit() || c == '.'))
            .unwrap_or(t.len());
        let (num, unit) = t.split_at(split);
        let v: f64 = num.parse().map_err(|_| bad())?;
        let unit = unit.trim().to_ascii_uppercase();
        let shift = match unit.trim_end_matches('B').trim_end_matches('I') {
            "" => 0,
            "K" => 10,
            "M" => 20,
            "G" => 30,
            "T" => 40,
            _ => return Err(bad()),
        };
        let bytes = v * (1u64 << shift) as f64;
        if !bytes.is_finite() || bytes < 1.0 || bytes > u64::MAX as f64 / 2.0 {
            return Err(bad());
        }
        Ok(ByteSize(bytes as u64))
    }
}

impl fmt::Display for ByteSize {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.0)
    }
}
as_text!(ByteSize);

/// Output variables, comma-separated names of [`AovSet::NAMES`], or `all`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct AovList(pub AovSet);

impl FromStr for AovList {
    type Err = String;
    fn from_str(s: &str) -> Result<AovList, String> {
        let mut set = AovSet::default();
        for name in s.split(',').map(str::trim) {
            if name == "all" {
                for n in AovSet::NAMES {
                    set.add(n);
                }
            } else if !set.add(name) {
                return Err(format!(
                    "unknown output variable '{name}' (one or more of {}, or all)",
                    AovSet::NAMES.join(", ")
                ));
            }
        }
        Ok(AovList(set))
    }
}

impl fmt::Display for AovList {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let names: Vec<&str> = AovSet::NAMES
            .into_iter()
            .filter(|n| self.0.has(n))
            .collect();
        f.write_str(&names.join(","))
    }
}
as_text!(AovList);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse_print_back_and_refuse() {
        let r: Res = "640x480".parse().unwrap();
        assert_eq!(
            (r.width, r.height, r.to_string()),
            (640, 480, "640x480".into())
        );
        for bad in ["0x10", "abc", "100000x10", "60000x60000"] {
            assert!(bad.parse::<Res>().is_err(), "{bad}");
        }
        assert_eq!("1.5G".parse::<ByteSize>(), Ok(ByteSize(3 << 29)));
        assert!("lots".parse::<ByteSize>().is_err());
    }

    #[test]
    fn bands_crops_and_variables_parse_and_name_themselves() {
        assert_eq!("2/5".parse::<Band>(), Ok(Band { index: 2, count: 5 }));
        assert_eq!(
            "4/4".parse::<Band>().unwrap_err(),
            "band '4/4': need 0 <= I < N"
        );
        assert_eq!(
            Band::parse("shard", "5/5").unwrap_err(),
            "shard '5/5': need 0 <= I < N"
        );
        assert!("1/0".parse::<Band>().is_err() && "x".parse::<Band>().is_err());
        let c: Crop = "1,5,2,9".parse().unwrap();
        assert_eq!(c.to_string(), "1,5,2,9");
        assert!("5,1,2,9".parse::<Crop>().is_err() && "1,2,3".parse::<Crop>().is_err());
        let a: AovList = "depth,normal, id".parse().unwrap();
        assert!(a.0.depth && a.0.normal && a.0.id && !a.0.time);
        assert_eq!(a.to_string(), "depth,normal,id");
        let all: AovList = "all".parse().unwrap();
        assert!(all.0.albedo && all.0.position && all.0.rays && all.0.time);
        let e = "depth,colour".parse::<AovList>().unwrap_err();
        assert!(e.contains("unknown output variable 'colour'"), "{e}");
    }
}
