//! The options of `emray render` that look inside a render: `--aov` (output variables
//! in the EXR beside the colour) and `--heatmap` (a false-colour PNG of a per-pixel
//! cost): parsing, the checks made before any render, and writing what they ask for.

use super::progress::TileBar;
use anyhow::{Result, bail};
use emray::output::Format;
use emray::output::heatmap::{Quantity, write_heatmap};
use emray::render::aov::{AovFilm, AovSet};
use std::path::{Path, PathBuf};

/// `--aov LIST`: comma-separated names of [`AovSet::NAMES`], or `all`.
pub fn parse_aov(s: &str) -> Result<AovSet, String> {
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
    Ok(set)
}

/// One `--heatmap WHAT FILE`: the quantity and the file (a template, as `-o`).
#[derive(Clone, Debug, PartialEq)]
pub struct HeatmapArg {
    /// What it shows.
    pub quantity: Quantity,
    /// Where it goes.
    pub file: String,
}

/// The `--heatmap` pairs (`WHAT FILE` each), checked: a known quantity and a `.png`
/// file.
pub fn heatmaps(values: &[String]) -> Result<Vec<HeatmapArg>> {
    let mut out = Vec::new();
    for pair in values.chunks(2) {
        let [what, file] = pair else {
            bail!("--heatmap takes two values: WHAT (rays, time or depth) and FILE.png");
        };
        let Some(quantity) = Quantity::from_name(what) else {
            bail!(
                "--heatmap {what}: unknown quantity (one of {})",
                Quantity::NAMES.join(", ")
            );
        };
        if Format::from_path(Path::new(file))? != Format::Png {
            bail!("--heatmap {what} {file}: a heat map is a PNG (name it FILE.png)");
        }
        out.push(HeatmapArg {
            quantity,
            file: file.clone(),
        });
    }
    Ok(out)
}

/// Refuse `--aov` whose output cannot hold it: output variables are EXR channels.
pub fn check_aov_output(set: &AovSet, out: &Path) -> Result<()> {
    if set.any() && Format::from_path(out)? != Format::Exr {
        bail!(
            "--aov writes its layers beside the colour in an OpenEXR file, and '{}' is a \
             PNG: name the output NAME.exr",
            out.display()
        );
    }
    Ok(())
}

/// The variables to gather for `set` and the heat maps `maps` (rays are always
/// counted; time is measured only when asked for).
pub fn gathered(set: AovSet, maps: &[HeatmapArg]) -> AovSet {
    let mut g = set;
    for m in maps {
        match m.quantity {
            Quantity::Rays => {}
            Quantity::Time => g.time = true,
            Quantity::Depth => g.tree_depth = true,
        }
    }
    g
}

/// Write the heat maps `files` of a render's variables `aov`, saying so on `bar`.
pub fn write_heatmaps(aov: &AovFilm, files: &[(Quantity, PathBuf)], bar: &TileBar) -> Result<()> {
    for (q, path) in files {
        bar.writing(path);
        let values = match q {
            Quantity::Rays => &aov.rays,
            Quantity::Time => &aov.time,
            Quantity::Depth => &aov.tree_depth,
        };
        write_heatmap(path, values, aov.width, aov.height, *q)?;
        log::info!("wrote {}", path.display());
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn aov_lists_parse_and_unknown_names_are_refused() {
        let s = parse_aov("depth,normal, id").unwrap();
        assert!(s.depth && s.normal && s.id && !s.time);
        let all = parse_aov("all").unwrap();
        assert!(all.albedo && all.position && all.rays && all.time);
        let e = parse_aov("depth,colour").unwrap_err();
        assert!(e.contains("unknown output variable 'colour'"), "{e}");
    }

    #[test]
    fn heatmaps_are_checked() {
        let v = |s: &[&str]| s.iter().map(|x| x.to_string()).collect::<Vec<_>>();
        let h = heatmaps(&v(&["rays", "r.png", "time", "t.png"])).unwrap();
        assert_eq!(h.len(), 2);
        assert_eq!(h[1].quantity, Quantity::Time);
        assert!(heatmaps(&v(&["colour", "r.png"])).is_err());
        assert!(heatmaps(&v(&["rays", "r.exr"])).is_err());
        assert!(heatmaps(&v(&["rays", "{stem}-r.png"])).is_ok());
    }
}
