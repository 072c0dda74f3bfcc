//! Parts of one image rendered apart (`emray render --tile I/N` or `--crop`) and put
//! back together: each part is an EXR whose data window is its region and which
//! carries a hash of the scene and the settings; [`merge`] checks that the parts come
//! from one render and cover the image exactly once.

use crate::Scene;
use crate::accel::Backend;
use crate::output::part::{PartInfo, read_exr};
use crate::render::{Film, RenderSettings};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// A `fmt::Write` sink that hashes what is written (FNV-1a 64), so a scene is hashed
/// through its `Debug` form without building the string.
struct Hasher(u64);

impl std::fmt::Write for Hasher {
    fn write_str(&mut self, s: &str) -> std::fmt::Result {
        for &b in s.as_bytes() {
            self.0 ^= b as u64;
            self.0 = self.0.wrapping_mul(0x0000_0100_0000_01b3);
        }
        Ok(())
    }
}

/// The hash of a render that parts must share: the whole scene (every value the
/// loader produced), the settings that change pixels (not the region, not the tile
/// size) and the backend, as 16 hex digits.
pub fn render_hash(scene: &Scene, settings: &RenderSettings, backend: Backend) -> String {
    let mut h = Hasher(0xcbf2_9ce4_8422_2325);
    let s = RenderSettings {
        region: None,
        tile: 0,
        ..settings.clone()
    };
    let _ = write!(h, "{scene:?}|{s:?}|{}", backend.name());
    format!("{:016x}", h.0)
}

/// Read `parts` and stitch them into the whole image, refusing parts of different
/// images or renders, overlapping parts and uncovered pixels.
pub fn merge(parts: &[PathBuf]) -> Result<Film, String> {
    let mut read: Vec<(&Path, Film, PartInfo)> = Vec::with_capacity(parts.len());
    for p in parts {
        let (film, info) = read_exr(p)?;
        if info.hash.is_none() {
            return Err(format!(
                "{}: not a part (no {} attribute; render it with --tile or --crop)",
                p.display(),
                crate::output::part::HASH_ATTRIBUTE
            ));
        }
        read.push((p, film, info));
    }
    let Some((first, _, info0)) = read.first() else {
        return Err("no parts to merge".into());
    };
    for (p, _, info) in &read[1..] {
        if info.full != info0.full {
            return Err(format!(
                "{}: part of a {}x{} image, but {} is of a {}x{} image",
                p.display(),
                info.full.0,
                info.full.1,
                first.display(),
                info0.full.0,
                info0.full.1
            ));
        }
        if info.hash != info0.hash {
            return Err(format!(
                "{}: rendered from another scene or other settings than {} (hash {} vs {})",
                p.display(),
                first.display(),
                info.hash.as_deref().unwrap_or("-"),
                info0.hash.as_deref().unwrap_or("-")
            ));
        }
    }
    let (w, h) = info0.full;
    let mut owner: Vec<u32> = vec![u32::MAX; w as usize * h as usize];
    let mut out = Film::new(w, h);
    for (k, (p, film, info)) in read.iter().enumerate() {
        let r = info.region;
        for j in r.y0..r.y1 {
            for i in r.x0..r.x1 {
                let o = &mut owner[(j * w + i) as usize];
                if *o != u32::MAX {
                    return Err(format!(
                        "{}: pixel ({i}, {j}) is also in {}: the parts overlap",
                        p.display(),
                        read[*o as usize].0.display()
                    ));
                }
                *o = k as u32;
                out.set(i, j, film.get(i - r.x0, j - r.y0));
            }
        }
    }
    if let Some(idx) = owner.iter().position(|&o| o == u32::MAX) {
        let missing = owner.iter().filter(|&&o| o == u32::MAX).count();
        return Err(format!(
            "the parts leave {missing} pixels uncovered, the first at ({}, {})",
            idx as u32 % w,
            idx as u32 / w
        ));
    }
    Ok(out)
}
