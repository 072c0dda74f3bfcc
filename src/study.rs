//! `emray study`: the f64 reference once, then a sweep of settings (uniform spp,
//! adaptive thresholds, bailout weights, depth limits, backends, f32 against f64),
//! each run's wall time, rays and error metrics to CSV, and error against time on
//! log-log axes to SVG, one curve per knob.

use crate::accel::{AccelError, Backend};
use crate::metrics::{compare, Metrics};
use crate::render::{Aa, RenderSettings};
use crate::run::{render_reference, render_scene};
use crate::Scene;
use std::fmt::Write as _;
use std::path::Path;

/// One run of the sweep.
#[derive(Clone, Debug)]
pub struct Row {
    /// The knob swept (`spp`, `adaptive`, `bailout`, `depth`, `backend`, `f64`).
    pub knob: &'static str,
    /// Its setting.
    pub setting: String,
    /// Render wall time in milliseconds.
    pub ms: f64,
    /// Rays cast, all types.
    pub rays: u64,
    /// Error against the reference.
    pub m: Metrics,
}

/// Run the study on `scene` at `w × h` with an `strata × strata` reference.
pub fn run(
    scene: &Scene,
    w: u32,
    h: u32,
    strata: u32,
    backends: &[Backend],
) -> Result<Vec<Row>, String> {
    let mut base = RenderSettings::for_scene(scene);
    base.width = w;
    base.height = h;
    let (reference, _) = render_reference("study", scene, &base, strata, 0.0)?;
    let mut rows = Vec::new();
    let mut go = |knob: &'static str,
                  setting: String,
                  st: &RenderSettings,
                  b: Backend|
     -> Result<(), AccelError> {
        let (film, rep) = render_scene("study", scene, b, st, 0.0, None)?;
        rows.push(Row {
            knob,
            setting,
            ms: rep.time_ms.render,
            rays: rep.rays["total"],
            m: compare(&film, &reference),
        });
        Ok(())
    };
    let err = |e: AccelError| e.to_string();
    let b0 = backends[0];
    for spp in [1, 2, 4, 8, 16, 32, 64] {
        let mut st = base.clone();
        st.spp = spp;
        go("spp", spp.to_string(), &st, b0).map_err(err)?;
    }
    for t in [0.2f32, 0.1, 0.05, 0.02, 0.01] {
        let mut st = base.clone();
        st.aa = Aa::Adaptive {
            threshold: t,
            depth: 2,
        };
        go("adaptive", format!("t={t} d=2"), &st, b0).map_err(err)?;
    }
    for wgt in [0.3f32, 0.1, 0.03, 0.01, 0.001] {
        let mut st = base.clone();
        st.spp = 16;
        st.bailout = wgt;
        go("bailout", format!("{wgt} @16spp"), &st, b0).map_err(err)?;
    }
    for depth in [1, 2, 3, 5, 8] {
        let mut st = base.clone();
        st.spp = 16;
        st.max_depth = depth;
        go("depth", format!("{depth} @16spp"), &st, b0).map_err(err)?;
    }
    for &b in backends {
        let mut st = base.clone();
        st.spp = 16;
        go("backend", format!("{} @16spp", b.name()), &st, b).map_err(err)?;
    }
    // f64 against the reference: the reference's own sampling noise.
    for n in [2u32, 4] {
        let t0 = std::time::Instant::now();
        let (film, rep) = render_reference("study", scene, &base, n, 0.0)?;
        rows.push(Row {
            knob: "f64",
            setting: format!("{}spp", n * n),
            ms: t0.elapsed().as_secs_f64() * 1e3,
            rays: rep.rays["total"],
            m: compare(&film, &reference),
        });
    }
    Ok(rows)
}

/// The rows as CSV with a header.
pub fn csv(rows: &[Row]) -> String {
    let mut s =
        String::from("knob,setting,render_ms,rays,rmse,psnr,rel_mse,max_abs,diff_8bit,flip\n");
    for r in rows {
        let m = &r.m;
        let _ = writeln!(
            s,
            "{},{},{:.3},{},{:.6e},{:.4},{:.6e},{:.6e},{:.6},{:.6}",
            r.knob,
            r.setting,
            r.ms,
            r.rays,
            m.rmse,
            m.psnr,
            m.rel_mse,
            m.max_abs,
            m.diff_8bit,
            m.flip
        );
    }
    s
}

/// RMSE against render time on log-log axes, one polyline per knob, as SVG.
pub fn svg(rows: &[Row], title: &str) -> String {
    let pts: Vec<(f64, f64)> = rows
        .iter()
        .map(|r| (r.ms.max(1e-3).log10(), r.m.rmse.max(1e-9).log10()))
        .collect();
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for &(x, y) in &pts {
        x0 = x0.min(x.floor());
        x1 = x1.max(x.ceil());
        y0 = y0.min(y.floor());
        y1 = y1.max(y.ceil());
    }
    if x1 <= x0 {
        x1 = x0 + 1.0;
    }
    if y1 <= y0 {
        y1 = y0 + 1.0;
    }
    let (w, h, l, r, t, b) = (720.0, 480.0, 70.0, 160.0, 40.0, 50.0);
    let px = |x: f64| l + (x - x0) / (x1 - x0) * (w - l - r);
    let py = |y: f64| h - b - (y - y0) / (y1 - y0) * (h - t - b);
    let mut s = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" \
         font-family=\"sans-serif\" font-size=\"12\">\n\
         <rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n\
         <text x=\"{}\" y=\"22\" text-anchor=\"middle\" font-size=\"15\">{}</text>\n",
        w / 2.0,
        xml(title)
    );
    for k in x0 as i32..=x1 as i32 {
        let x = px(k as f64);
        let _ = writeln!(
            s,
            "<line x1=\"{x}\" y1=\"{t}\" x2=\"{x}\" y2=\"{}\" stroke=\"#ddd\"/>\
             <text x=\"{x}\" y=\"{}\" text-anchor=\"middle\">1e{k}</text>",
            h - b,
            h - b + 16.0
        );
    }
    for k in y0 as i32..=y1 as i32 {
        let y = py(k as f64);
        let _ = writeln!(
            s,
            "<line x1=\"{l}\" y1=\"{y}\" x2=\"{}\" y2=\"{y}\" stroke=\"#ddd\"/>\
             <text x=\"{}\" y=\"{}\" text-anchor=\"end\">1e{k}</text>",
            w - r,
            l - 6.0,
            y + 4.0
        );
    }
    let _ = writeln!(
        s,
        "<text x=\"{}\" y=\"{}\" text-anchor=\"middle\">render time (ms)</text>\
         <text x=\"16\" y=\"{}\" text-anchor=\"middle\" transform=\"rotate(-90 16 {})\">RMSE vs f64 reference</text>",
        (l + w - r) / 2.0,
        h - 12.0,
        h / 2.0,
        h / 2.0
    );
    const COLOURS: [&str; 6] = [
        "#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b",
    ];
    let mut knobs: Vec<&str> = rows.iter().map(|r| r.knob).collect();
    knobs.dedup();
    for (k, knob) in knobs.iter().enumerate() {
        let c = COLOURS[k % COLOURS.len()];
        let line: Vec<String> = rows
            .iter()
            .zip(&pts)
            .filter(|(r, _)| r.knob == *knob)
            .map(|(_, &(x, y))| format!("{:.1},{:.1}", px(x), py(y)))
            .collect();
        let _ = writeln!(
            s,
            "<polyline fill=\"none\" stroke=\"{c}\" stroke-width=\"2\" points=\"{}\"/>",
            line.join(" ")
        );
        for p in &line {
            let (x, y) = p.split_once(',').expect("x,y");
            let _ = writeln!(s, "<circle cx=\"{x}\" cy=\"{y}\" r=\"3\" fill=\"{c}\"/>");
        }
        let ly = t + 10.0 + 18.0 * k as f64;
        let _ = writeln!(
            s,
            "<line x1=\"{}\" y1=\"{ly}\" x2=\"{}\" y2=\"{ly}\" stroke=\"{c}\" stroke-width=\"3\"/>\
             <text x=\"{}\" y=\"{}\">{}</text>",
            w - r + 10.0,
            w - r + 30.0,
            w - r + 36.0,
            ly + 4.0,
            xml(knob)
        );
    }
    s.push_str("</svg>\n");
    s
}

fn xml(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// Run the study and write `study.csv` and `study.svg` into `dir` (created).
pub fn write(
    scene: &Scene,
    name: &str,
    dir: &Path,
    w: u32,
    h: u32,
    strata: u32,
    backends: &[Backend],
) -> Result<Vec<Row>, String> {
    let rows = run(scene, w, h, strata, backends)?;
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: cannot create: {e}", dir.display()))?;
    let title = format!("{name}, {w}x{h}: error vs time");
    crate::output::write_text(&dir.join("study.csv"), &csv(&rows)).map_err(|e| e.to_string())?;
    crate::output::write_text(&dir.join("study.svg"), &svg(&rows, &title))
        .map_err(|e| e.to_string())?;
    Ok(rows)
}
