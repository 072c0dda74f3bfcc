//! Tachyon (John Stone's parallel ray tracer, Debian package `tachyon`) as a peer: it
//! reads NFF, so the same scene file renders on both at the same resolution and thread
//! count. Its own "Ray Tracing Time" is compared with emray's render time.

use crate::scene::Scene;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::process::Command;

/// One scene × thread count on Tachyon.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PeerRow {
    /// Scene name.
    pub scene: String,
    /// Threads.
    pub threads: usize,
    /// Median Tachyon ray-tracing time, ms.
    pub tachyon_ms: f64,
    /// emray's median render time on Embree for the same scene and threads.
    pub emray_ms: Option<f64>,
    /// Where Tachyon's picture differs.
    pub note: String,
}

/// Tachyon's three reported phase times, ms.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TachyonTimes {
    /// "Scene Parsing Time".
    pub parse_ms: f64,
    /// "Preprocessing Time".
    pub preprocess_ms: f64,
    /// "Ray Tracing Time".
    pub trace_ms: f64,
}

/// Read the phase times from Tachyon's output; `None` when the trace time is absent.
pub fn parse_times(out: &str) -> Option<TachyonTimes> {
    let find = |key: &str| {
        out.split(['\n', '\r'])
            .find_map(|l| l.trim().strip_prefix(key))
            .and_then(|rest| {
                rest.trim()
                    .trim_end_matches("seconds")
                    .trim()
                    .parse::<f64>()
                    .ok()
            })
            .map(|s| s * 1e3)
    };
    Some(TachyonTimes {
        parse_ms: find("Scene Parsing Time:").unwrap_or(0.0),
        preprocess_ms: find("Preprocessing Time:").unwrap_or(0.0),
        trace_ms: find("Ray Tracing Time:")?,
    })
}

/// Whether a `tachyon` program can be run.
pub fn available() -> bool {
    Command::new("tachyon")
        .arg("-version")
        .output()
        .map(|o| o.status.success() || !o.stdout.is_empty())
        .unwrap_or(false)
}

/// How Tachyon's rendering of `scene` differs from emray's.
pub fn differences(scene: &Scene) -> String {
    let mut notes = Vec::new();
    if scene.materials.iter().any(|m| m.t > 0.0) {
        notes.push("no refraction");
    }
    if scene
        .geometry
        .cones()
        .items
        .iter()
        .any(|c| c.base_radius != c.apex_radius)
    {
        notes.push("cones drawn as cylinders");
    }
    if notes.is_empty() {
        notes.push("same features");
    }
    notes.join("; ")
}

/// Why a Tachyon run gave no time.
#[derive(Debug, thiserror::Error)]
pub enum PeerError {
    /// `tachyon` could not be started.
    #[error("cannot run tachyon: {0}")]
    Spawn(String),
    /// It exited with a failure.
    #[error("tachyon on {} failed ({status}): {stderr}", nff.display())]
    Failed {
        /// The scene.
        nff: PathBuf,
        /// Its exit status.
        status: String,
        /// What it printed on standard error.
        stderr: String,
    },
    /// Its output has no ray-tracing time.
    #[error("tachyon on {}: no 'Ray Tracing Time' in its output", .0.display())]
    NoTime(PathBuf),
}

/// Render the NFF file `nff` with Tachyon at `width × height` on `threads` threads,
/// depth 5, writing its image to `image`.
pub fn run(
    nff: &Path,
    image: &Path,
    width: u32,
    height: u32,
    threads: usize,
) -> Result<TachyonTimes, PeerError> {
    let out = Command::new("tachyon")
        .arg(nff)
        .args(["-res", &width.to_string(), &height.to_string()])
        .args(["-numthreads", &threads.to_string(), "-raydepth", "5"])
        .args(["-format", "PPM", "-o"])
        .arg(image)
        .output()
        .map_err(|e| PeerError::Spawn(e.to_string()))?;
    let text = String::from_utf8_lossy(&out.stdout);
    if !out.status.success() {
        return Err(PeerError::Failed {
            nff: nff.to_path_buf(),
            status: out.status.to_string(),
            stderr: String::from_utf8_lossy(&out.stderr).trim().to_string(),
        });
    }
    parse_times(&text).ok_or_else(|| PeerError::NoTime(nff.to_path_buf()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_tachyon_times() {
        let out = "Scene Parsing Time:     0.0150 seconds\nScene contains 3 objects.\n\
                   Preprocessing Time:     0.0020 seconds\nRendering Progress:  0% complete  \r\
                   Rendering Progress: 100% complete\n  Ray Tracing Time:     0.1074 seconds\n";
        let t = parse_times(out).unwrap();
        assert!((t.parse_ms - 15.0).abs() < 1e-9);
        assert!((t.preprocess_ms - 2.0).abs() < 1e-9);
        assert!((t.trace_ms - 107.4).abs() < 1e-9);
        assert_eq!(parse_times("Scene Parsing Time: 1 seconds"), None);
    }
}
