//! The output variables of `--aov` in the EXR beside the colour, under the channel
//! names compositing tools expect (docs/aov.md), and the `.ids.json` file beside an
//! image with an `id` channel, which says what each id in it stands for.

use super::channels::{Channel, Samples, write_exr_channels};
use super::part::PartInfo;
use super::{OutputError, write_text};
use crate::render::Film;
use crate::render::aov::AovFilm;
use crate::render::aov::ids::{IdEntry, NO_ID};
use glam::Vec3;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The channels of the variables `aov.set` asks for.
pub fn channels(aov: &AovFilm) -> Vec<Channel> {
    let set = aov.set;
    let mut out = Vec::new();
    let vec3 = |out: &mut Vec<Channel>, names: [&str; 3], v: &[Vec3]| {
        for (k, name) in names.into_iter().enumerate() {
            out.push(Channel::f32(name, v.iter().map(|p| p[k]).collect()));
        }
    };
    if set.depth {
        out.push(Channel::f32("Z", aov.depth.clone()));
    }
    if set.normal {
        vec3(&mut out, ["N.X", "N.Y", "N.Z"], &aov.normal);
    }
    if set.albedo {
        vec3(&mut out, ["albedo.R", "albedo.G", "albedo.B"], &aov.albedo);
    }
    if set.position {
        vec3(&mut out, ["P.X", "P.Y", "P.Z"], &aov.position);
    }
    if set.id {
        out.push(Channel {
            name: "id".into(),
            samples: Samples::U32(aov.id.clone()),
        });
    }
    if set.rays {
        out.push(Channel::f32("rays", aov.rays.clone()));
    }
    if set.time {
        out.push(Channel::f32("time", aov.time.clone()));
    }
    out
}

/// The file beside `image` that lists its ids: `IMAGE.ids.json`.
pub fn ids_path(image: &Path) -> PathBuf {
    let mut name = image.as_os_str().to_owned();
    name.push(".ids.json");
    PathBuf::from(name)
}

/// The `.ids.json` file: the id of no primitive, and each id in the image.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct IdFile {
    /// The id of pixels no primitive covers.
    pub none: u32,
    /// The ids in the image, ascending.
    pub ids: Vec<IdEntry>,
}

/// The text of an `.ids.json` file listing `ids`: one id per line.
fn ids_text(ids: &[IdEntry]) -> String {
    let mut text = format!("{{\n  \"none\": {NO_ID},\n  \"ids\": [");
    for (k, e) in ids.iter().enumerate() {
        text += if k == 0 { "\n    " } else { ",\n    " };
        text += &serde_json::to_string(e).expect("an id entry serialises");
    }
    text += if ids.is_empty() {
        "]\n}\n"
    } else {
        "\n  ]\n}\n"
    };
    text
}

/// Write the `.ids.json` file of `image` listing `ids` (ascending).
pub fn write_ids(image: &Path, ids: &[IdEntry]) -> Result<(), OutputError> {
    write_text(&ids_path(image), &ids_text(ids))
}

/// Read the `.ids.json` file of `image`.
pub fn read_ids(image: &Path) -> Result<Vec<IdEntry>, String> {
    let path = ids_path(image);
    let text = std::fs::read_to_string(&path)
        .map_err(|e| format!("{}: cannot read: {e}", path.display()))?;
    let file: IdFile = serde_json::from_str(&text)
        .map_err(|e| format!("{}: not an ids file: {e}", path.display()))?;
    Ok(file.ids)
}

/// Write `film` with the variables of `aov` to the EXR `path` (a part of an image
/// when `part` says so), and its `.ids.json` when it has ids.
pub fn write_exr_aov(
    path: &Path,
    film: &Film,
    aov: &AovFilm,
    part: Option<&PartInfo>,
) -> Result<(), OutputError> {
    write_exr_channels(path, film, &channels(aov), part)?;
    if aov.set.id {
        write_ids(path, &aov.ids)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_ids_file_is_json_one_id_per_line() {
        let e = IdEntry {
            id: 3,
            kind: "sphere".into(),
            prim: 0,
            instance: None,
            source: Some("a.nff:4".into()),
            instance_source: None,
        };
        for ids in [vec![], vec![e.clone(), IdEntry { id: 9, ..e.clone() }]] {
            let text = ids_text(&ids);
            let back: IdFile = serde_json::from_str(&text).unwrap();
            assert_eq!(back.ids, ids);
            assert_eq!(back.none, NO_ID);
            let lines = if ids.is_empty() { 4 } else { 5 + ids.len() };
            assert_eq!(text.lines().count(), lines, "{text}");
        }
    }
}
