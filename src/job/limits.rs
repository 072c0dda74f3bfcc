//! Memory limits: a render is refused, with the numbers, before its large buffers and
//! the acceleration structure are allocated, when its estimate exceeds the limit; and
//! the memory the process did use at its peak, for the reports.

use crate::render::{Region, RenderSettings};
use crate::scene::Scene;
use std::path::{Path, PathBuf};

/// This process's peak resident memory so far in bytes (`VmHWM` of
/// `/proc/self/status`), where the system tells it (Linux).
pub fn peak_resident_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let kib: u64 = status
        .lines()
        .find_map(|l| l.strip_prefix("VmHWM:"))?
        .trim()
        .trim_end_matches("kB")
        .trim()
        .parse()
        .ok()?;
    Some(kib * 1024)
}

/// Bytes per primitive allowed for the acceleration structure (either backend's nodes
/// and references, with room to spare).
pub const ACCEL_BYTES_PER_PRIM: u64 = 160;

/// The estimated peak bytes of rendering `scene` with `settings`: the sample grid, the
/// tiles' results, the 8-bit copy for PNG, and the acceleration structure.
pub fn estimate_bytes(scene: &Scene, settings: &RenderSettings) -> u64 {
    let r = settings
        .region
        .unwrap_or(Region::full(settings.width, settings.height));
    let extra = u64::from(settings.spd);
    let samples = (r.width() as u64 + extra) * (r.height() as u64 + extra);
    let prims = scene.prim_count_with_instances() as u64
        + scene
            .objects
            .iter()
            .map(|o| o.prim_count() as u64)
            .sum::<u64>()
        + scene.instances.len() as u64;
    // Grid + per-tile results (12 bytes each) + the averaged film + 3 bytes of PNG.
    samples * 12 * 2 + r.width() as u64 * r.height() as u64 * 15 + prims * ACCEL_BYTES_PER_PRIM
}

/// Bytes per sample-grid position that gathering output variables adds (`--aov`,
/// `--heatmap`): the positions' records and their grid, the variables of each pixel,
/// and their EXR channels, with room to spare.
pub const AOV_BYTES_PER_SAMPLE: u64 = 320;

/// The estimated bytes that gathering output variables adds to a render.
pub fn aov_bytes(settings: &RenderSettings) -> u64 {
    let r = settings
        .region
        .unwrap_or(Region::full(settings.width, settings.height));
    let extra = u64::from(settings.spd);
    (r.width() as u64 + extra) * (r.height() as u64 + extra) * AOV_BYTES_PER_SAMPLE
}

/// The default limit: three quarters of the machine's memory (`/proc/meminfo`), else
/// 16 GiB.
pub fn default_max_memory() -> u64 {
    std::fs::read_to_string("/proc/meminfo")
        .ok()
        .and_then(|t| {
            t.lines()
                .find_map(|l| l.strip_prefix("MemTotal:"))
                .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<u64>().ok())
        })
        .map(|kib| kib * 1024 / 4 * 3)
        .unwrap_or(16 << 30)
}

/// Human-readable bytes.
pub fn format_bytes(b: u64) -> String {
    let gib = b as f64 / (1u64 << 30) as f64;
    if gib >= 1.0 {
        format!("{gib:.1} GiB")
    } else {
        format!("{:.1} MiB", b as f64 / (1u64 << 20) as f64)
    }
}

/// A render refused because its estimated memory is over the limit.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error(
    "{}: rendering {width}x{height} with {prims} primitives needs about {}, over the memory \
     limit of {} (--max-memory)",
    scene.display(), format_bytes(*need), format_bytes(*limit)
)]
pub struct MemoryLimitError {
    /// The scene.
    pub scene: PathBuf,
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Primitives in the scene.
    pub prims: usize,
    /// The estimate in bytes.
    pub need: u64,
    /// The limit in bytes.
    pub limit: u64,
}

/// Refuse the render when its estimate, plus `extra` bytes (output variables:
/// [`aov_bytes`]), is over `max` bytes.
pub fn check(
    scene_path: &Path,
    scene: &Scene,
    settings: &RenderSettings,
    extra: u64,
    max: u64,
) -> Result<(), MemoryLimitError> {
    let need = estimate_bytes(scene, settings).saturating_add(extra);
    if need > max {
        return Err(MemoryLimitError {
            scene: scene_path.to_path_buf(),
            width: settings.width,
            height: settings.height,
            prims: scene.prim_count_with_instances(),
            need,
            limit: max,
        });
    }
    Ok(())
}

/// Bytes per primitive the loaded scene holds besides the acceleration structure: the
/// primitive, its material index and where it was defined, with room to spare.
pub const SCENE_BYTES_PER_PRIM: u64 = 64;

/// Refuse, before generating it, a database whose primitives alone (the scene and the
/// acceleration structure, [`count`](crate::spd::Database::count)ed without
/// generating) would be over `max` bytes; `res` is the image size the render asks for,
/// for the message.
pub fn check_generated(
    spec: &Path,
    count: &crate::spd::PrimCount,
    res: (u32, u32),
    max: u64,
) -> Result<(), MemoryLimitError> {
    let need = count
        .prims
        .saturating_mul(ACCEL_BYTES_PER_PRIM + SCENE_BYTES_PER_PRIM);
    if need > max {
        return Err(MemoryLimitError {
            scene: spec.to_path_buf(),
            width: res.0,
            height: res.1,
            prims: usize::try_from(count.prims).unwrap_or(usize::MAX),
            need,
            limit: max,
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_database_over_the_limit_is_refused_before_it_is_generated() {
        let count = crate::spd::PrimCount {
            prims: 48_427_563,
            res: (512, 512),
        };
        let spec = Path::new("spd:balls?size=8");
        let need = 48_427_563 * (ACCEL_BYTES_PER_PRIM + SCENE_BYTES_PER_PRIM);
        assert!(check_generated(spec, &count, (512, 512), need).is_ok());
        let e = check_generated(spec, &count, (512, 512), need - 1)
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("spd:balls?size=8: rendering 512x512 with 48427563 primitives"),
            "{e}"
        );
        assert!(e.ends_with("(--max-memory)"), "{e}");
    }

    #[test]
    fn big_images_are_refused_with_numbers() {
        let scene = crate::load::nff::parse_str(
            "v\nfrom 0 0 5\nat 0 0 0\nup 0 1 0\nangle 40\nhither 1\nresolution 8 8\ns 0 0 0 1\n",
            Path::new("t.nff"),
        )
        .unwrap();
        let mut s = RenderSettings::for_scene(&scene);
        assert!(check(Path::new("t.nff"), &scene, &s, 0, 1 << 20).is_ok());
        s.width = 30000;
        s.height = 30000;
        let e = check(Path::new("t.nff"), &scene, &s, 0, 1 << 30)
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("t.nff: rendering 30000x30000"), "{e}");
        assert!(
            e.ends_with("over the memory limit of 1.0 GiB (--max-memory)"),
            "{e}"
        );
        // Output variables need more: a render that fits may not with them.
        s.width = 4000;
        s.height = 4000;
        let max = estimate_bytes(&scene, &s) + 1;
        assert!(check(Path::new("t.nff"), &scene, &s, 0, max).is_ok());
        let extra = aov_bytes(&s);
        assert!(check(Path::new("t.nff"), &scene, &s, extra, max).is_err());
    }
}
