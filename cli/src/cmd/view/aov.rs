//! The output variables of a render (`emray render --aov`'s) as 8-bit RGB images the
//! page can show, one per variable:
//!
//! - `normal`: each component from [-1, 1] to [0, 255] (a normal facing a camera that
//!   looks down -z is blue); black where no sample hit;
//! - `depth`: the distance, linearly from the nearest (white, 255) to the farthest
//!   (grey, 32) over the finite values; black where no sample hit;
//! - `albedo`: through the 8-bit sRGB encoding the colour's tiles use;
//! - `position`: each axis linearly over its range among the pixels that hit, from 32
//!   to 255; black where no sample hit;
//! - `id`: each primitive's id hashed to a colour; black where no sample hit;
//! - `rays`, `time`: linearly from the least (black) to the most (white).
//!
//! Each comes with the range it maps, when it maps one.

use emray::math::Vec3;
use emray::render::aov::AovFilm;
use emray::render::aov::ids::NO_ID;
use emray::render::color::srgb8;
use serde_json::{Value, json};

/// The output variables the page offers, by their `--aov` names, and their layers.
pub const LAYERS: [(&str, &str); 7] = [
    ("depth", "aov-depth"),
    ("normal", "aov-normal"),
    ("albedo", "aov-albedo"),
    ("position", "aov-position"),
    ("id", "aov-id"),
    ("rays", "aov-rays"),
    ("time", "aov-time"),
];

/// The grey of the farthest hit in the depth layer (the nearest is 255, no hit 0).
pub const FAR: u8 = 32;

/// One variable as an image.
pub struct Layer {
    /// The layer's name (`aov-NAME`).
    pub name: &'static str,
    /// Its RGB bytes, row-major.
    pub rgb: Vec<u8>,
    /// What its greys or channels span: `{"min": …, "max": …}` (per axis for the
    /// position), or null.
    pub range: Value,
}

/// Each variable of [`LAYERS`] of `aov` as an image.
pub fn layers(aov: &AovFilm) -> Vec<Layer> {
    LAYERS
        .iter()
        .map(|&(var, name)| {
            let (rgb, range) = match var {
                "depth" => depth(&aov.depth),
                "normal" => (normal(&aov.normal), Value::Null),
                "albedo" => (albedo(&aov.albedo), Value::Null),
                "position" => position(&aov.position, &aov.depth),
                "id" => (id(&aov.id), Value::Null),
                "rays" => scalar(&aov.rays),
                _ => scalar(&aov.time),
            };
            Layer { name, rgb, range }
        })
        .collect()
}

/// The least and the greatest finite value of `v`, if any.
fn range(v: impl Iterator<Item = f32>) -> Option<(f32, f32)> {
    v.filter(|x| x.is_finite()).fold(None, |r, x| match r {
        None => Some((x, x)),
        Some((lo, hi)) => Some((lo.min(x), hi.max(x))),
    })
}

/// Where `x` lies in `[lo, hi]`, from 0 to 1 (0 for an empty range).
fn unit(x: f32, (lo, hi): (f32, f32)) -> f32 {
    if hi > lo {
        ((x - lo) / (hi - lo)).clamp(0.0, 1.0)
    } else {
        0.0
    }
}

/// `t` in [0, 1] from `a` to `b`, rounded.
fn lerp8(a: u8, b: u8, t: f32) -> u8 {
    (a as f32 + (b as f32 - a as f32) * t).round() as u8
}

fn depth(d: &[f32]) -> (Vec<u8>, Value) {
    let r = range(d.iter().copied());
    let rgb = d
        .iter()
        .flat_map(|&z| {
            let g = match r {
                Some(r) if z.is_finite() => lerp8(255, FAR, unit(z, r)),
                _ => 0,
            };
            [g; 3]
        })
        .collect();
    (rgb, range_json(r))
}

fn scalar(v: &[f32]) -> (Vec<u8>, Value) {
    let r = range(v.iter().copied());
    let rgb = v
        .iter()
        .flat_map(|&x| {
            let g = match r {
                Some(r) if x.is_finite() => lerp8(0, 255, unit(x, r)),
                _ => 0,
            };
            [g; 3]
        })
        .collect();
    (rgb, range_json(r))
}

fn normal(n: &[Vec3]) -> Vec<u8> {
    n.iter()
        .flat_map(|v| {
            if *v == Vec3::ZERO {
                [0; 3]
            } else {
                v.to_array()
                    .map(|c| lerp8(0, 255, ((c + 1.0) * 0.5).clamp(0.0, 1.0)))
            }
        })
        .collect()
}

fn albedo(a: &[Vec3]) -> Vec<u8> {
    a.iter().flat_map(|v| v.to_array().map(srgb8)).collect()
}

fn position(p: &[Vec3], depth: &[f32]) -> (Vec<u8>, Value) {
    let hit = |k: usize| {
        p.iter()
            .zip(depth)
            .filter(|(_, z)| z.is_finite())
            .map(move |(v, _)| v[k])
    };
    let r = [0, 1, 2].map(|k| range(hit(k)));
    let rgb = p
        .iter()
        .zip(depth)
        .flat_map(|(v, z)| {
            let mut c = [0; 3];
            if z.is_finite() {
                for (k, c) in c.iter_mut().enumerate() {
                    *c = r[k].map_or(0, |r| lerp8(FAR, 255, unit(v[k], r)));
                }
            }
            c
        })
        .collect();
    let range = match r {
        [Some(x), Some(y), Some(z)] => json!({"min": [x.0, y.0, z.0], "max": [x.1, y.1, z.1]}),
        _ => Value::Null,
    };
    (rgb, range)
}

fn id(ids: &[u32]) -> Vec<u8> {
    ids.iter()
        .flat_map(|&i| if i == NO_ID { [0; 3] } else { id_colour(i) })
        .collect()
}

/// A colour for id `i`: its hash's bytes, lifted off black.
fn id_colour(i: u32) -> [u8; 3] {
    // A 32-bit integer hash (lowbias32): neighbouring ids get unrelated colours.
    let mut h = i;
    h ^= h >> 16;
    h = h.wrapping_mul(0x7feb_352d);
    h ^= h >> 15;
    h = h.wrapping_mul(0x846c_a68b);
    h ^= h >> 16;
    let b = h.to_le_bytes();
    [b[0], b[1], b[2]].map(|c| 64 + c / 4 * 3)
}

fn range_json(r: Option<(f32, f32)>) -> Value {
    match r {
        Some((lo, hi)) => json!({"min": lo, "max": hi}),
        None => Value::Null,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn depth_runs_from_white_near_to_grey_far_and_black_for_misses() {
        let (rgb, r) = depth(&[2.0, 4.0, f32::INFINITY, 3.0]);
        assert_eq!(rgb, [255, 255, 255, FAR, FAR, FAR, 0, 0, 0, 144, 144, 144]);
        assert_eq!(r, json!({"min": 2.0, "max": 4.0}));
        assert_eq!(depth(&[f32::INFINITY]), (vec![0, 0, 0], Value::Null));
    }

    #[test]
    fn normals_map_minus_one_to_one_onto_bytes() {
        let rgb = normal(&[
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(-1.0, 1.0, 0.0),
            Vec3::ZERO,
        ]);
        assert_eq!(rgb, [128, 128, 255, 0, 255, 128, 0, 0, 0]);
    }

    #[test]
    fn ids_differ_and_miss_is_black() {
        let rgb = id(&[NO_ID, 1, 2]);
        assert_eq!(rgb[..3], [0, 0, 0]);
        assert_ne!(rgb[3..6], rgb[6..9]);
        assert!(rgb[3..].iter().all(|&c| c >= 64));
    }

    #[test]
    fn every_variable_is_a_layer_of_the_films_size() {
        let aov = AovFilm {
            width: 2,
            height: 1,
            depth: vec![1.0, f32::INFINITY],
            normal: vec![Vec3::Z, Vec3::ZERO],
            albedo: vec![Vec3::ONE, Vec3::ZERO],
            position: vec![Vec3::ONE, Vec3::ZERO],
            id: vec![1, NO_ID],
            rays: vec![1.0, 3.0],
            time: vec![0.0, 0.0],
            ..AovFilm::default()
        };
        let layers = layers(&aov);
        assert_eq!(layers.len(), LAYERS.len());
        for l in &layers {
            assert_eq!(l.rgb.len(), 6, "{}", l.name);
        }
        assert_eq!(layers[2].rgb, [255, 255, 255, 0, 0, 0]);
    }
}
