//! The bench report: samples folded into rows (medians and spread), the targets'
//! summary figures, markdown for the terminal, CSV and JSON for files, and per-row
//! ratios against a saved run.

use super::peer::PeerRow;
use super::{Machine, Mode, Rays, Sample};
use crate::spd::Database;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::fmt::Write;

/// One scene × backend × thread count, over the repetitions.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Row {
    /// Scene name.
    pub scene: String,
    /// Primitives.
    pub prims: usize,
    /// Backend.
    pub backend: String,
    /// Threads.
    pub threads: usize,
    /// Median load time, ms.
    pub load_ms: f64,
    /// Median build time, ms.
    pub build_ms: f64,
    /// Median render time, ms.
    pub render_ms: f64,
    /// Render-time spread: (max − min) / median, percent.
    pub spread_pct: f64,
    /// Median raw-casting time of the same rays, ms.
    pub raw_ms: Option<f64>,
    /// Rays by type.
    pub rays: Rays,
    /// Millions of rays per second of median render time.
    pub mrays_per_s: f64,
    /// Largest peak resident memory over the render runs, MiB.
    pub peak_mib: Option<f64>,
    /// This row's render time ÷ Embree's for the same scene and threads.
    pub vs_embree: Option<f64>,
    /// Repetitions.
    pub reps: usize,
    /// The backend's description.
    pub accel: String,
    /// Median CPU time of the process during the render, ms.
    #[serde(default)]
    pub cpu_ms: Option<f64>,
    /// Median time stolen from the machine's processors during the render, ms.
    #[serde(default)]
    pub steal_ms: Option<f64>,
    /// Eye rays only (see [`RunSpec::eye_only`](super::RunSpec::eye_only)).
    #[serde(default)]
    pub eye_only: bool,
    /// Bytes of the backend's structure per primitive of the scene (nodes and leaves
    /// with their primitive data; see [`AccelStats::bytes`](crate::accel::AccelStats::bytes)),
    /// when the backend says.
    #[serde(default)]
    pub bytes_per_prim: Option<f64>,
}

impl Row {
    /// Render time ÷ raw casting time.
    pub fn overhead(&self) -> Option<f64> {
        self.raw_ms.filter(|&r| r > 0.0).map(|r| self.render_ms / r)
    }
}

/// The median of `v` (the mean of the middle two for an even count); 0 when empty.
pub fn median(v: &[f64]) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    let n = s.len();
    if n % 2 == 1 {
        s[n / 2]
    } else {
        (s[n / 2 - 1] + s[n / 2]) / 2.0
    }
}

/// The median of the values, `None` when there are none.
fn median_of(v: impl Iterator<Item = f64>) -> Option<f64> {
    let v: Vec<f64> = v.collect();
    (!v.is_empty()).then(|| median(&v))
}

/// The geometric mean of positive values; `None` when there are none.
pub fn geomean(v: &[f64]) -> Option<f64> {
    let p: Vec<f64> = v.iter().copied().filter(|x| *x > 0.0).collect();
    (!p.is_empty()).then(|| (p.iter().map(|x| x.ln()).sum::<f64>() / p.len() as f64).exp())
}

/// Fold samples into rows, in the order the runs were first made.
pub fn rows(samples: &[Sample]) -> Vec<Row> {
    let mut order: Vec<(String, String, usize)> = Vec::new();
    let mut groups: BTreeMap<(String, String, usize), Vec<&Sample>> = BTreeMap::new();
    for s in samples {
        let key = (
            s.spec.scene.clone(),
            s.spec.backend().to_string(),
            s.spec.threads,
        );
        if !groups.contains_key(&key) {
            order.push(key.clone());
        }
        groups.entry(key).or_default().push(s);
    }
    let mut rows: Vec<Row> = order
        .iter()
        .map(|key| {
            let g = &groups[key];
            let render: Vec<&Sample> = g
                .iter()
                .copied()
                .filter(|s| s.spec.mode == Mode::Render)
                .collect();
            let raw: Vec<f64> = g
                .iter()
                .filter(|s| s.spec.mode == Mode::Raw)
                .map(|s| s.result.ms)
                .collect();
            let pick =
                |f: fn(&Sample) -> f64| median(&render.iter().map(|s| f(s)).collect::<Vec<_>>());
            let times: Vec<f64> = render.iter().map(|s| s.result.ms).collect();
            let render_ms = median(&times);
            let spread_pct = if render_ms > 0.0 {
                let max = times.iter().copied().fold(f64::MIN, f64::max);
                let min = times.iter().copied().fold(f64::MAX, f64::min);
                100.0 * (max - min) / render_ms
            } else {
                0.0
            };
            let first = render.first().map(|s| &s.result);
            let rays = first.map(|r| r.rays).unwrap_or_default();
            Row {
                scene: key.0.clone(),
                prims: g[0].result.prims,
                backend: key.1.clone(),
                threads: key.2,
                load_ms: pick(|s| s.result.load_ms),
                build_ms: pick(|s| s.result.build_ms),
                render_ms,
                spread_pct,
                raw_ms: (!raw.is_empty()).then(|| median(&raw)),
                rays,
                mrays_per_s: if render_ms > 0.0 {
                    rays.total as f64 / (render_ms * 1e3)
                } else {
                    0.0
                },
                peak_mib: render
                    .iter()
                    .filter_map(|s| s.result.peak_kib)
                    .max()
                    .map(|k| k as f64 / 1024.0),
                vs_embree: None,
                reps: render.len(),
                accel: first.map(|r| r.accel.clone()).unwrap_or_default(),
                cpu_ms: median_of(render.iter().filter_map(|s| s.result.cpu_ms)),
                steal_ms: median_of(render.iter().filter_map(|s| s.result.steal_ms)),
                eye_only: g[0].spec.eye_only,
                bytes_per_prim: first
                    .filter(|r| r.accel_bytes > 0 && r.prims > 0)
                    .map(|r| r.accel_bytes as f64 / r.prims as f64),
            }
        })
        .collect();
    let embree: BTreeMap<(String, usize), f64> = rows
        .iter()
        .filter(|r| r.backend == "embree")
        .map(|r| ((r.scene.clone(), r.threads), r.render_ms))
        .collect();
    for r in &mut rows {
        if r.backend != "embree" {
            r.vs_embree = embree
                .get(&(r.scene.clone(), r.threads))
                .filter(|&&e| e > 0.0)
                .map(|e| r.render_ms / e);
        }
    }
    rows
}

/// The figures the performance targets are stated in.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Summary {
    /// Geometric mean of BVH ÷ Embree render time over the default-size SPD scenes,
    /// per thread count.
    pub bvh_vs_embree: BTreeMap<usize, f64>,
    /// Geometric mean of render ÷ raw casting, per backend, at the most threads.
    pub overhead: BTreeMap<String, f64>,
    /// Every row cast eye rays only: `overhead` is the eye-ray pipeline's.
    #[serde(default)]
    pub eye_only: bool,
    /// Per backend: the smallest speed-up of the most threads over one thread, and the
    /// scene it was on.
    pub scaling_min: BTreeMap<String, (f64, String)>,
    /// Per `"BACKEND, N thread(s)"`: exponent `k` in render time ∝ primitives^k
    /// between the smallest and largest balls of the suite.
    pub balls_exponent: BTreeMap<String, f64>,
    /// The most threads against one, per backend and scene.
    #[serde(default)]
    pub scaling: Vec<Scaling>,
}

/// How a render on `threads` threads compares with one thread, in wall time and in
/// CPU time: `speedup = threads × busy ÷ busy₁ ÷ work` (`busy₁` the one-thread run's,
/// near 1), so a speed-up below the thread count comes from threads off the processors
/// (`busy` below 1: emray waiting, or the machine not giving it the processors, which
/// `steal` shows) or from more work (`work` above 1).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Scaling {
    /// Backend.
    pub backend: String,
    /// Scene.
    pub scene: String,
    /// Threads compared with one.
    pub threads: usize,
    /// Render time on one thread ÷ on `threads`.
    pub speedup: f64,
    /// CPU time ÷ (threads × wall time) on `threads`: the share of the processors' time
    /// the render's threads were running.
    pub busy: Option<f64>,
    /// CPU time on `threads` ÷ CPU time on one: how much more work the split made.
    pub work: Option<f64>,
    /// Stolen time ÷ (threads × wall time) on `threads`, over the whole machine.
    pub steal: Option<f64>,
}

/// [`Scaling`] of every scene that ran on one thread and on `max_t` on `backend`.
fn scaling(rows: &[Row], backend: &str, max_t: usize) -> Vec<Scaling> {
    let mut out = Vec::new();
    for one in rows
        .iter()
        .filter(|r| r.backend == backend && r.threads == 1)
    {
        let Some(many) = rows
            .iter()
            .find(|r| r.backend == backend && r.threads == max_t && r.scene == one.scene)
        else {
            continue;
        };
        if many.render_ms <= 0.0 {
            continue;
        }
        let slots = max_t as f64 * many.render_ms;
        out.push(Scaling {
            backend: backend.to_string(),
            scene: one.scene.clone(),
            threads: max_t,
            speedup: one.render_ms / many.render_ms,
            busy: many.cpu_ms.map(|c| c / slots),
            work: many.cpu_ms.zip(one.cpu_ms).map(|(m, o)| m / o.max(1e-9)),
            steal: many.steal_ms.map(|s| s / slots),
        });
    }
    out
}

fn is_default_size(scene: &str) -> bool {
    scene.starts_with("spd:") && !scene.contains('?')
}

/// Tachyon's samples folded into rows (median), next to emray's Embree render time
/// for the same scene and threads.
pub fn peer_rows(m: &super::Measured) -> Vec<PeerRow> {
    let mut out: Vec<PeerRow> = Vec::new();
    for p in &m.peers {
        if out
            .iter()
            .any(|r| r.scene == p.scene && r.threads == p.threads)
        {
            continue;
        }
        let same = |q: &&super::PeerSample| q.scene == p.scene && q.threads == p.threads;
        let times: Vec<f64> = m.peers.iter().filter(same).map(|q| q.trace_ms).collect();
        let emray: Vec<f64> = m
            .peers
            .iter()
            .filter(same)
            .filter_map(|q| q.emray_ms)
            .collect();
        out.push(PeerRow {
            scene: p.scene.clone(),
            threads: p.threads,
            tachyon_ms: median(&times),
            emray_ms: (!emray.is_empty()).then(|| median(&emray)),
            framing: m.peer_framing.get(&p.scene).copied(),
            note: m.peer_notes.get(&p.scene).cloned().unwrap_or_default(),
        });
    }
    out
}

/// The summary of `rows`.
pub fn summary(rows: &[Row]) -> Summary {
    let mut s = Summary {
        eye_only: !rows.is_empty() && rows.iter().all(|r| r.eye_only),
        ..Summary::default()
    };
    let max_t = rows.iter().map(|r| r.threads).max().unwrap_or(1);
    let threads: std::collections::BTreeSet<usize> = rows.iter().map(|r| r.threads).collect();
    for &t in &threads {
        let v: Vec<f64> = rows
            .iter()
            .filter(|r| r.backend == "bvh" && r.threads == t && is_default_size(&r.scene))
            .filter_map(|r| r.vs_embree)
            .collect();
        if let Some(g) = geomean(&v) {
            s.bvh_vs_embree.insert(t, g);
        }
    }
    let backends: std::collections::BTreeSet<&str> =
        rows.iter().map(|r| r.backend.as_str()).collect();
    for b in backends {
        let of = |r: &&Row| r.backend == b;
        let v: Vec<f64> = rows
            .iter()
            .filter(of)
            .filter(|r| r.threads == max_t && is_default_size(&r.scene))
            .filter_map(Row::overhead)
            .collect();
        if let Some(g) = geomean(&v) {
            s.overhead.insert(b.to_string(), g);
        }
        if max_t > 1 {
            s.scaling.extend(scaling(rows, b, max_t));
            let mut worst: Option<(f64, String)> = None;
            for r in rows.iter().filter(of).filter(|r| r.threads == 1) {
                let Some(m) = rows
                    .iter()
                    .find(|x| x.backend == b && x.threads == max_t && x.scene == r.scene)
                else {
                    continue;
                };
                if m.render_ms > 0.0 {
                    let k = r.render_ms / m.render_ms;
                    if !matches!(&worst, Some((w, _)) if *w <= k) {
                        worst = Some((k, r.scene.clone()));
                    }
                }
            }
            if let Some(w) = worst {
                s.scaling_min.insert(b.to_string(), w);
            }
        }
        for &t in &threads {
            let mut balls: Vec<(u32, &Row)> = rows
                .iter()
                .filter(|r| r.backend == b && r.threads == t)
                .filter_map(|r| match Database::parse_spec(&r.scene) {
                    Ok(Some((Database::Balls, size))) => Some((size, r)),
                    _ => None,
                })
                .collect();
            balls.sort_by_key(|(size, _)| *size);
            if let (Some((s0, a)), Some((s1, z))) = (balls.first(), balls.last()) {
                if s1 > s0 && a.prims > 0 && a.render_ms > 0.0 {
                    let k =
                        (z.render_ms / a.render_ms).ln() / (z.prims as f64 / a.prims as f64).ln();
                    s.balls_exponent.insert(format!("{b}, {t} thread(s)"), k);
                }
            }
        }
    }
    s
}

fn opt(v: Option<f64>, prec: usize) -> String {
    v.map_or("–".to_string(), |x| format!("{x:.prec$}"))
}

/// The whole report as markdown.
pub fn markdown(
    machine: &Machine,
    rows: &[Row],
    sum: &Summary,
    peers: &[PeerRow],
    peer_note: &str,
) -> String {
    let mut o = String::new();
    md_header(&mut o, machine, rows);
    md_rows(&mut o, rows);
    md_rays_by_type(&mut o, rows);
    md_targets(&mut o, sum);
    md_peers(&mut o, peers, peer_note);
    o
}

/// The machine, the Embree version and how the rows were measured.
fn md_header(o: &mut String, machine: &Machine, rows: &[Row]) {
    let accel = rows
        .iter()
        .find(|r| r.backend == "embree")
        .map(|r| r.accel.clone())
        .unwrap_or_else(|| "not measured".into());
    let _ = writeln!(o, "# emray bench\n");
    let _ = writeln!(
        o,
        "- CPU: {} ({} logical CPUs, best ISA {})\n- Embree: {accel}\n- load average: {} at the start, {} at the end",
        machine.cpu, machine.cpus, machine.isa, machine.load_before, machine.load_after
    );
    let reps = rows.iter().map(|r| r.reps).max().unwrap_or(0);
    let _ = writeln!(
        o,
        "- {reps} repetitions per row, interleaved; times are medians, spread = (max − min) / median"
    );
    if rows.iter().any(|r| r.eye_only) {
        let _ = writeln!(
            o,
            "- eye rays only (--eye-only): one per pixel centre, lights removed, depth 1; render/raw is the eye-ray \
             pipeline (camera, packets, surfaces, shading, film) over casting the same rays"
        );
    }
    let _ = writeln!(o);
}

/// One line per row.
fn md_rows(o: &mut String, rows: &[Row]) {
    let _ = writeln!(
        o,
        "| scene | prims | backend | thr | load ms | build ms | render ms | spread | raw ms | render/raw | rays | Mrays/s | peak MiB | bytes/prim | ÷ embree |"
    );
    let _ = writeln!(
        o,
        "|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
    );
    for r in rows {
        let _ = writeln!(
            o,
            "| {} | {} | {} | {} | {:.1} | {:.1} | {:.1} | {:.0}% | {} | {} | {} | {:.2} | {} | {} | {} |",
            r.scene,
            r.prims,
            r.backend,
            r.threads,
            r.load_ms,
            r.build_ms,
            r.render_ms,
            r.spread_pct,
            opt(r.raw_ms, 1),
            opt(r.overhead(), 2),
            r.rays.total,
            r.mrays_per_s,
            opt(r.peak_mib, 0),
            opt(r.bytes_per_prim, 0),
            opt(r.vs_embree, 2),
        );
    }
}

/// The rays of each scene by kind.
fn md_rays_by_type(o: &mut String, rows: &[Row]) {
    let _ = writeln!(
        o,
        "\nRays by type (eye / reflection / refraction / shadow):\n"
    );
    let mut seen = std::collections::BTreeSet::new();
    for r in rows {
        if seen.insert(r.scene.clone()) {
            let _ = writeln!(
                o,
                "- {}: {} / {} / {} / {}",
                r.scene, r.rays.eye, r.rays.reflection, r.rays.refraction, r.rays.shadow
            );
        }
    }
}

/// The summary against the targets, with the scaling table.
fn md_targets(o: &mut String, sum: &Summary) {
    let _ = writeln!(o, "\n## Targets\n");
    for (t, g) in &sum.bvh_vs_embree {
        let _ = writeln!(
            o,
            "- BVH ÷ Embree render time, geometric mean over the default-size SPD scenes, {t} thread(s): {g:.2} (target ≤ 1.25)"
        );
    }
    for (b, g) in &sum.overhead {
        let (what, target) = if sum.eye_only {
            ("eye-ray pipeline", "1.5")
        } else {
            ("render", "1.25")
        };
        let _ = writeln!(
            o,
            "- {what} ÷ raw casting on {b}, geometric mean (most threads): {g:.2} (target ≤ {target} on embree)"
        );
    }
    for (b, (k, scene)) in &sum.scaling_min {
        let _ = writeln!(
            o,
            "- smallest speed-up of all threads over one on {b}: {k:.2}× ({scene}) (target ≥ 1.85)"
        );
    }
    md_scaling(o, &sum.scaling);
    for (b, k) in &sum.balls_exponent {
        let _ = writeln!(
            o,
            "- balls render time ∝ primitives^{k:.2} ({b}) (target < 1)"
        );
    }
}

/// The speed-up of all threads over one, explained by CPU time and steal.
fn md_scaling(o: &mut String, scaling: &[Scaling]) {
    if !scaling.is_empty() {
        let _ = writeln!(
            o,
            "\n| scaling | backend | thr | speed-up | CPU busy | CPU work | steal |\n|---|---|---:|---:|---:|---:|---:|"
        );
        let pct = |v: Option<f64>| v.map_or("–".to_string(), |x| format!("{:.0}%", x * 100.0));
        for k in scaling {
            let _ = writeln!(
                o,
                "| {} | {} | {} | {:.2}× | {} | {} | {} |",
                k.scene,
                k.backend,
                k.threads,
                k.speedup,
                pct(k.busy),
                opt(k.work, 2),
                pct(k.steal)
            );
        }
        let _ = writeln!(
            o,
            "\nspeed-up ≈ threads × busy ÷ work: CPU busy is the share of the processors' time the \
             render's threads ran, CPU work the CPU time against one thread's, steal the share \
             the machine's processors were taken by the host. Busy below 100% with no steal is \
             waiting emray causes; with steal, the machine's.\n"
        );
    }
}

/// Tachyon's times beside emray's, or why there are none.
fn md_peers(o: &mut String, peers: &[PeerRow], peer_note: &str) {
    let _ = writeln!(o, "\n## Peer: Tachyon\n");
    if peers.is_empty() {
        let _ = writeln!(o, "{peer_note}");
    } else {
        let _ = writeln!(
            o,
            "| scene | thr | tachyon ms | emray ms | emray ÷ tachyon | same view | note |\n|---|---:|---:|---:|---:|---:|---|"
        );
        for p in peers {
            let _ = writeln!(
                o,
                "| {} | {} | {:.1} | {} | {} | {} | {} |",
                p.scene,
                p.threads,
                p.tachyon_ms,
                opt(p.emray_ms, 1),
                opt(
                    p.emray_ms
                        .filter(|_| p.tachyon_ms > 0.0)
                        .map(|e| e / p.tachyon_ms),
                    2
                ),
                p.framing
                    .map_or("–".to_string(), |f| format!("{:.1}%", f * 100.0)),
                p.note
            );
        }
        let _ = writeln!(
            o,
            "\nThe same view for both: Tachyon ignores the NFF `angle` (its camera spans {:.2}°), \
             so both render the scene's file with its `angle` set to that, at the same \
             resolution and threads, one ray per pixel centre, depth 5. Tachyon's time is its \
             own \"Ray Tracing Time\", emray's its render phase. \"same view\" is the share of \
             pixels both see as background or both as scene.",
            super::peer::TACHYON_ANGLE_DEG
        );
    }
}

/// The rows as CSV, one line per row.
pub fn csv(rows: &[Row]) -> String {
    let mut o = String::from(
        "scene,prims,backend,threads,reps,load_ms,build_ms,render_ms,spread_pct,raw_ms,render_over_raw,eye,reflection,refraction,shadow,total_rays,mrays_per_s,peak_mib,bytes_per_prim,vs_embree\n",
    );
    let f = |v: Option<f64>| v.map_or(String::new(), |x| format!("{x:.4}"));
    for r in rows {
        let _ = writeln!(
            o,
            "{},{},{},{},{},{:.3},{:.3},{:.3},{:.2},{},{},{},{},{},{},{},{:.4},{},{},{}",
            r.scene,
            r.prims,
            r.backend,
            r.threads,
            r.reps,
            r.load_ms,
            r.build_ms,
            r.render_ms,
            r.spread_pct,
            f(r.raw_ms),
            f(r.overhead()),
            r.rays.eye,
            r.rays.reflection,
            r.rays.refraction,
            r.rays.shadow,
            r.rays.total,
            r.mrays_per_s,
            f(r.peak_mib),
            f(r.bytes_per_prim),
            f(r.vs_embree),
        );
    }
    o
}

/// Everything one run of the suite produced, as saved to a JSON file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Saved {
    /// The machine.
    pub machine: Machine,
    /// The rows.
    pub rows: Vec<Row>,
    /// The summary.
    pub summary: Summary,
    /// Tachyon rows.
    pub peers: Vec<PeerRow>,
    /// Every sample.
    pub samples: Vec<Sample>,
}

/// Per-row ratios (this run ÷ the baseline) of render, build and raw time, for the
/// rows present in both, as markdown.
pub fn compare(rows: &[Row], base: &[Row]) -> String {
    let mut o = String::from(
        "| scene | backend | thr | render ms | baseline ms | render ratio | build ratio | raw ratio |\n|---|---|---:|---:|---:|---:|---:|---:|\n",
    );
    let mut ratios = Vec::new();
    for r in rows {
        let Some(b) = base
            .iter()
            .find(|b| b.scene == r.scene && b.backend == r.backend && b.threads == r.threads)
        else {
            continue;
        };
        let ratio = |a: f64, b: f64| (b > 0.0).then(|| a / b);
        let rr = ratio(r.render_ms, b.render_ms);
        ratios.extend(rr);
        let raw = r.raw_ms.zip(b.raw_ms).and_then(|(a, b)| ratio(a, b));
        let _ = writeln!(
            o,
            "| {} | {} | {} | {:.1} | {:.1} | {} | {} | {} |",
            r.scene,
            r.backend,
            r.threads,
            r.render_ms,
            b.render_ms,
            opt(rr, 3),
            opt(ratio(r.build_ms, b.build_ms), 3),
            opt(raw, 3),
        );
    }
    match geomean(&ratios) {
        Some(g) => {
            let _ = writeln!(
                o,
                "\nGeometric mean render ratio (this run ÷ baseline): {g:.3} over {} rows",
                ratios.len()
            );
        }
        None => o.push_str("\nNo row of this run is in the baseline.\n"),
    }
    o
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bench::{RunResult, RunSpec};

    fn sample(
        scene: &str,
        backend: &str,
        threads: usize,
        mode: Mode,
        ms: f64,
        prims: usize,
    ) -> Sample {
        Sample {
            spec: RunSpec {
                scene: scene.into(),
                threads,
                mode,
                eye_only: false,
                options: crate::job::RenderOptions {
                    backend: Some(match backend {
                        "bvh" => crate::accel::Backend::Bvh,
                        _ => crate::accel::Backend::Embree,
                    }),
                    ..Default::default()
                },
            },
            rep: 0,
            result: RunResult {
                prims,
                load_ms: 1.0,
                build_ms: 2.0,
                ms,
                rays: Rays {
                    eye: 64,
                    total: 100,
                    ..Default::default()
                },
                peak_kib: Some(2048),
                accel: backend.into(),
                accel_bytes: 50 * prims,
                // Threads 90% busy, the host taking 5% of one processor.
                cpu_ms: Some(ms * threads as f64 * 0.9),
                steal_ms: Some(ms * 0.05),
            },
        }
    }

    #[test]
    fn medians_and_geomeans() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&[4.0, 1.0, 2.0, 3.0]), 2.5);
        assert_eq!(median(&[]), 0.0);
        assert!((geomean(&[2.0, 8.0]).unwrap() - 4.0).abs() < 1e-12);
        assert_eq!(geomean(&[]), None);
    }

    #[test]
    fn rows_fold_repetitions_and_ratios() {
        let s = vec![
            sample("spd:balls", "embree", 1, Mode::Render, 10.0, 100),
            sample("spd:balls", "bvh", 1, Mode::Render, 30.0, 100),
            sample("spd:balls", "embree", 1, Mode::Render, 12.0, 100),
            sample("spd:balls", "bvh", 1, Mode::Render, 14.0, 100),
            sample("spd:balls", "embree", 1, Mode::Raw, 8.0, 100),
            sample("spd:balls", "embree", 1, Mode::Raw, 8.0, 100),
            sample("spd:balls", "embree", 2, Mode::Render, 5.5, 100),
            sample("spd:balls?size=2", "embree", 2, Mode::Render, 1.0, 10),
        ];
        let r = rows(&s);
        assert_eq!(r.len(), 4);
        assert_eq!(
            (r[0].backend.as_str(), r[0].render_ms, r[0].reps),
            ("embree", 11.0, 2)
        );
        assert!((r[0].spread_pct - 100.0 * 2.0 / 11.0).abs() < 1e-9);
        assert_eq!(r[0].raw_ms, Some(8.0));
        assert_eq!(r[0].overhead(), Some(11.0 / 8.0));
        assert_eq!(r[1].vs_embree, Some(22.0 / 11.0));
        assert_eq!(r[0].peak_mib, Some(2.0));
        assert_eq!(r[0].bytes_per_prim, Some(50.0));
        let sum = summary(&r);
        assert_eq!(sum.bvh_vs_embree.get(&1), Some(&2.0));
        assert_eq!(sum.scaling_min["embree"], (2.0, "spd:balls".to_string()));
        // Both runs 90% busy, the same CPU time: speed-up 2 = 2 threads x 0.9 / 0.9 / 1.
        let k = &sum.scaling[0];
        assert_eq!(
            (k.backend.as_str(), k.scene.as_str(), k.threads),
            ("embree", "spd:balls", 2)
        );
        assert!((k.speedup - 2.0).abs() < 1e-12);
        assert!((k.busy.unwrap() - 0.9).abs() < 1e-12, "{k:?}");
        assert!((k.work.unwrap() - 1.0).abs() < 1e-12, "{k:?}");
        assert!((k.steal.unwrap() - 0.025).abs() < 1e-12, "{k:?}");
        // 10 -> 100 primitives, 1 ms -> 5.5 ms: exponent log10(5.5).
        let k = sum.balls_exponent["embree, 2 thread(s)"];
        assert!((k - 5.5f64.log10()).abs() < 1e-12, "{k}");
        let md = markdown(&Machine::default(), &r, &sum, &[], "tachyon not installed");
        assert!(md.contains("| spd:balls | 100 | bvh | 1 |"));
        assert!(md.contains("tachyon not installed"));
        assert!(
            md.contains("| spd:balls | embree | 2 | 2.00× | 90% | 1.00 | 2% |"),
            "{md}"
        );
        let c = csv(&r);
        assert_eq!(c.lines().count(), 5);
        assert!(c.lines().nth(2).unwrap().ends_with(",2.0000"));
    }

    #[test]
    fn baseline_ratios_match_rows() {
        let new = rows(&[sample("spd:tetra", "bvh", 2, Mode::Render, 20.0, 10)]);
        let old = rows(&[
            sample("spd:tetra", "bvh", 2, Mode::Render, 40.0, 10),
            sample("spd:gears", "bvh", 2, Mode::Render, 40.0, 10),
        ]);
        let c = compare(&new, &old);
        assert!(
            c.contains("| spd:tetra | bvh | 2 | 20.0 | 40.0 | 0.500 |"),
            "{c}"
        );
        assert!(!c.contains("gears"));
        assert!(c.contains("0.500 over 1 rows"));
        assert!(compare(&new, &[]).contains("No row"));
    }
}
