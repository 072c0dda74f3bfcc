//! Tachyon (John Stone's parallel ray tracer, Debian package `tachyon`) as a peer: it
//! reads NFF, so the same scene file renders on both at the same resolution and thread
//! count. Its own "Ray Tracing Time" is compared with emray's render time.
//!
//! Tachyon's NFF reader ignores the viewpoint's `angle` (its camera always spans
//! [`TACHYON_ANGLE_DEG`]), so on a scene written with another angle it renders another
//! picture (jacks, at 25°, 2.26 times smaller, mostly background) and a comparison of
//! times would not be fair. The bench therefore gives both renderers the same file with
//! its `angle` set to Tachyon's, renders it on emray with one ray per pixel centre as
//! Tachyon does, and checks the two pictures frame the scene alike ([`framing`]).

use crate::accel::{Accel, Backend, WithAccel};
use crate::render::RayGen;
use crate::scene::Scene;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::process::Command;

/// The full angle of Tachyon's camera on an NFF scene, whatever its `angle`: a zoom of
/// 1, `2·atan(1/2)` (53.13°), across a square image.
pub const TACHYON_ANGLE_DEG: f64 = 53.130_102_354_155_98;

/// One scene × thread count on Tachyon.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PeerRow {
    /// Scene name.
    pub scene: String,
    /// Threads.
    pub threads: usize,
    /// Median Tachyon ray-tracing time, ms.
    pub tachyon_ms: f64,
    /// emray's median render time of the same file (the angle set to Tachyon's, one ray
    /// per pixel centre) with the same threads.
    pub emray_ms: Option<f64>,
    /// Share of pixels both pictures see alike (background in both, or scene in both):
    /// how far the two frame the scene the same.
    #[serde(default)]
    pub framing: Option<f64>,
    /// Where Tachyon's picture differs.
    pub note: String,
}

/// `nff` with the viewpoint's `angle` set to `deg` (the first `angle` keyword's value).
pub fn with_angle(nff: &str, deg: f64) -> String {
    let mut out = String::with_capacity(nff.len() + 16);
    let mut done = false;
    for line in nff.lines() {
        let mut words = line.split_whitespace();
        if !done && words.next() == Some("angle") {
            out += &format!("angle {deg}\n");
            done = true;
        } else {
            out += line;
            out.push('\n');
        }
    }
    out
}

/// The pixels of a binary PPM (`P6`, 8 bits per channel) as RGB bytes, with its size.
pub fn read_ppm(bytes: &[u8]) -> Option<(u32, u32, Vec<u8>)> {
    // The header: P6, width, height, maxval, each after white space; then one byte.
    let mut fields = Vec::new();
    let mut pos = 0;
    while fields.len() < 4 {
        while bytes.get(pos)?.is_ascii_whitespace() {
            pos += 1;
        }
        let start = pos;
        while !bytes.get(pos)?.is_ascii_whitespace() {
            pos += 1;
        }
        fields.push(std::str::from_utf8(&bytes[start..pos]).ok()?);
    }
    let (w, h): (u32, u32) = (fields[1].parse().ok()?, fields[2].parse().ok()?);
    if fields[0] != "P6" || fields[3] != "255" {
        return None;
    }
    let data = bytes.get(pos + 1..pos + 1 + (w as usize) * (h as usize) * 3)?;
    Some((w, h, data.to_vec()))
}

/// How alike emray and Tachyon frame `scene` at `width × height`: the share of pixels
/// where both see background (Tachyon's pixel is the background colour, within 1/255;
/// emray's eye ray through the pixel centre hits nothing) or both see the scene.
/// `tachyon` is Tachyon's picture as RGB bytes.
pub fn framing(scene: &Scene, width: u32, height: u32, tachyon: &[u8]) -> f64 {
    let work = Framing {
        scene,
        width,
        height,
        tachyon,
    };
    crate::accel::build(scene, &Backend::Bvh.into(), work).unwrap_or(0.0)
}

/// [`framing`] with a built backend.
struct Framing<'a> {
    scene: &'a Scene,
    width: u32,
    height: u32,
    tachyon: &'a [u8],
}

impl WithAccel for Framing<'_> {
    type Output = f64;
    fn run<A: Accel>(self, accel: &A, _build_ms: f64) -> f64 {
        let Framing {
            scene,
            width,
            height,
            tachyon,
        } = self;
        alike_share(scene, accel, width, height, tachyon)
    }
}

/// The share of pixels whose background-or-scene `accel` and Tachyon's picture agree on.
fn alike_share<A: Accel>(scene: &Scene, accel: &A, width: u32, height: u32, tachyon: &[u8]) -> f64 {
    let raygen = RayGen::new(&scene.camera, width, height);
    let bg = scene
        .background
        .to_array()
        .map(|c| c.clamp(0.0, 1.0) * 255.0);
    let mut alike = 0usize;
    for j in 0..height {
        for i in 0..width {
            let k = ((j * width + i) * 3) as usize;
            let Some(px) = tachyon.get(k..k + 3) else {
                continue;
            };
            let tachyon_bg = px.iter().zip(bg).all(|(&p, b)| (p as f32 - b).abs() <= 1.0);
            let ray = raygen.ray(i as f32 + 0.5, j as f32 + 0.5);
            let emray_bg = accel.intersect(&ray).is_none();
            alike += usize::from(tachyon_bg == emray_bg);
        }
    }
    alike as f64 / (width as f64 * height as f64).max(1.0)
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
    fn the_angle_is_rewritten_once() {
        let nff = "v\nfrom 0 0 5\nat 0 0 0\nup 0 1 0\nangle 25\nhither 0\nresolution 8 8\n\
                   s 0 0 0 1\nv\nangle 30\n";
        let out = with_angle(nff, TACHYON_ANGLE_DEG);
        assert!(out.contains("\nangle 53.13010235415598\n"), "{out}");
        assert!(
            out.ends_with("angle 30\n") && !out.contains("angle 25"),
            "{out}"
        );
    }

    #[test]
    fn binary_ppm_reads() {
        let mut ppm = b"P6 2 1\n255\n".to_vec();
        ppm.extend([1, 2, 3, 4, 5, 6]);
        assert_eq!(read_ppm(&ppm), Some((2, 1, vec![1, 2, 3, 4, 5, 6])));
        assert_eq!(read_ppm(b"P6 2 1\n255\n\x01"), None, "short");
        assert_eq!(read_ppm(b"P3 1 1\n255\n1 2 3"), None, "ASCII");
    }

    /// A picture of emray's own hit mask frames the scene alike everywhere; the same
    /// scene seen with another angle (as Tachyon saw jacks before the bench set its
    /// angle) does not.
    #[test]
    fn framing_tells_another_view_apart() {
        let scene = |angle: f64| {
            let src = format!(
                "v\nfrom 0 0 8\nat 0 0 0\nup 0 1 0\nangle {angle}\nhither 0\nresolution 32 32\n\
                 b 0.2 0.4 0.6\ns 0 0 0 1\ns 1.5 1 0 0.5\n"
            );
            crate::load::nff::parse_str(&src, Path::new("f.nff")).unwrap()
        };
        let picture = |s: &Scene| {
            let bvh = crate::accel::bvh::Bvh::build(s);
            let raygen = RayGen::new(&s.camera, 32, 32);
            let mut rgb = Vec::new();
            for j in 0..32 {
                for i in 0..32 {
                    let hit = bvh.intersect(&raygen.ray(i as f32 + 0.5, j as f32 + 0.5));
                    rgb.extend(if hit.is_some() {
                        [255, 255, 255]
                    } else {
                        [51, 102, 153]
                    });
                }
            }
            rgb
        };
        let same = scene(40.0);
        assert_eq!(framing(&same, 32, 32, &picture(&same)), 1.0);
        let other = framing(&same, 32, 32, &picture(&scene(20.0)));
        assert!(other < 0.9, "{other}");
    }

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
