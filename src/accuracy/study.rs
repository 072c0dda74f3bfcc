//! `emray study`: the f64 reference once, then a sweep of settings (uniform spp,
//! adaptive thresholds, bailout weights, depth limits, backends, f32 against f64),
//! each run's wall time, rays and error metrics to CSV, and error against time on
//! log-log axes to SVG and PNG (plotters), one curve per knob.

use super::metrics::{Metrics, compare};
use crate::accel::{AccelError, Backend};
use crate::job::{render_reference, render_scene};
use crate::output::OutputError;
use crate::render::reference::Unsupported;
use crate::render::{Aa, RenderSettings};
use crate::scene::Scene;
use std::fmt::Write as _;
use std::path::Path;

/// Why the study could not be run or written.
#[derive(Debug, thiserror::Error)]
pub enum StudyError {
    /// The f64 reference does not model something in the scene.
    #[error(transparent)]
    Reference(#[from] Unsupported),
    /// A backend could not be built.
    #[error(transparent)]
    Accel(#[from] AccelError),
    /// The plot could not be drawn.
    #[error("plotting: {0}")]
    Plot(String),
    /// A file could not be written.
    #[error(transparent)]
    Output(#[from] OutputError),
}

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
) -> Result<Vec<Row>, StudyError> {
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
    let b0 = backends[0];
    for spp in [1, 2, 4, 8, 16, 32, 64] {
        let mut st = base.clone();
        st.spp = spp;
        go("spp", spp.to_string(), &st, b0)?;
    }
    for t in [0.2f32, 0.1, 0.05, 0.02, 0.01] {
        let mut st = base.clone();
        st.aa = Aa::Adaptive {
            threshold: t,
            depth: 2,
        };
        go("adaptive", format!("t={t} d=2"), &st, b0)?;
    }
    for wgt in [0.3f32, 0.1, 0.03, 0.01, 0.001] {
        let mut st = base.clone();
        st.spp = 16;
        st.bailout = wgt;
        go("bailout", format!("{wgt} @16spp"), &st, b0)?;
    }
    for depth in [1, 2, 3, 5, 8] {
        let mut st = base.clone();
        st.spp = 16;
        st.max_depth = depth;
        go("depth", format!("{depth} @16spp"), &st, b0)?;
    }
    for &b in backends {
        let mut st = base.clone();
        st.spp = 16;
        go("backend", format!("{} @16spp", b.name()), &st, b)?;
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

/// Plot size in pixels.
const PLOT_SIZE: (u32, u32) = (800, 520);

/// The curves' colours, one per knob (in sweep order).
pub const COLOURS: [(u8, u8, u8); 6] = [
    (31, 119, 180),
    (214, 39, 40),
    (44, 160, 44),
    (148, 103, 189),
    (255, 127, 14),
    (140, 86, 75),
];

/// DejaVu Sans (Bitstream Vera licence, see `assets/DejaVuSans.LICENSE`): the PNG's text
/// is rasterised from it, so no system font is needed.
static FONT: &[u8] = include_bytes!("../../assets/DejaVuSans.ttf");

/// Register the embedded font as plotters' `sans-serif` (once).
fn register_font() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        // The font is valid (a test plots with it); a failure only loses the text.
        let _ =
            plotters::style::register_font("sans-serif", plotters::style::FontStyle::Normal, FONT);
    });
}

/// Draw RMSE against render time on log-log axes, one curve per knob, on `root`.
fn plot<DB: plotters::prelude::DrawingBackend>(
    root: plotters::prelude::DrawingArea<DB, plotters::coord::Shift>,
    rows: &[Row],
    title: &str,
) -> Result<(), StudyError> {
    use plotters::prelude::*;
    register_font();
    let e = |e: DrawingAreaErrorKind<DB::ErrorType>| StudyError::Plot(e.to_string());
    let pts: Vec<(f64, f64)> = rows
        .iter()
        .map(|r| (r.ms.max(1e-3), r.m.rmse.max(1e-9)))
        .collect();
    // Whole decades around the points.
    let decade = |v: f64, up: bool| {
        let l = v.log10();
        10f64.powf(if up { l.ceil() } else { l.floor() })
    };
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for &(x, y) in &pts {
        x0 = x0.min(decade(x, false));
        x1 = x1.max(decade(x, true));
        y0 = y0.min(decade(y, false));
        y1 = y1.max(decade(y, true));
    }
    if pts.is_empty() {
        (x0, x1, y0, y1) = (1.0, 10.0, 1e-3, 1.0);
    }
    if x1 <= x0 {
        x1 = x0 * 10.0;
    }
    if y1 <= y0 {
        y1 = y0 * 10.0;
    }
    root.fill(&WHITE).map_err(e)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 20))
        .margin(12)
        .x_label_area_size(42)
        .y_label_area_size(64)
        .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())
        .map_err(e)?;
    chart
        .configure_mesh()
        .x_desc("render time (ms)")
        .y_desc("RMSE vs f64 reference")
        .x_label_formatter(&|v| format!("{v:.0e}"))
        .y_label_formatter(&|v| format!("{v:.0e}"))
        .label_style(("sans-serif", 13))
        .draw()
        .map_err(e)?;
    let mut knobs: Vec<&str> = rows.iter().map(|r| r.knob).collect();
    knobs.dedup();
    for (k, knob) in knobs.iter().enumerate() {
        let (r, g, b) = COLOURS[k % COLOURS.len()];
        let colour = RGBColor(r, g, b);
        let curve: Vec<(f64, f64)> = rows
            .iter()
            .zip(&pts)
            .filter(|(row, _)| row.knob == *knob)
            .map(|(_, &p)| p)
            .collect();
        chart
            .draw_series(LineSeries::new(curve.clone(), colour.stroke_width(2)))
            .map_err(e)?
            .label(*knob)
            .legend(move |(x, y)| Rectangle::new([(x, y - 2), (x + 18, y + 2)], colour.filled()));
        chart
            .draw_series(curve.iter().map(|&p| Circle::new(p, 3, colour.filled())))
            .map_err(e)?;
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 13))
        .draw()
        .map_err(e)?;
    root.present().map_err(e)
}

/// The plot as SVG.
pub fn svg(rows: &[Row], title: &str) -> Result<String, StudyError> {
    let mut out = String::new();
    {
        let root = plotters::prelude::SVGBackend::with_string(&mut out, PLOT_SIZE);
        plot(
            plotters::prelude::IntoDrawingArea::into_drawing_area(root),
            rows,
            title,
        )?;
    }
    Ok(out)
}

/// The plot as an RGB image.
pub fn raster(rows: &[Row], title: &str) -> Result<image::RgbImage, StudyError> {
    let (w, h) = PLOT_SIZE;
    let mut buf = vec![0u8; (w * h * 3) as usize];
    {
        let root = plotters::prelude::BitMapBackend::with_buffer(&mut buf, (w, h));
        plot(
            plotters::prelude::IntoDrawingArea::into_drawing_area(root),
            rows,
            title,
        )?;
    }
    image::RgbImage::from_raw(w, h, buf).ok_or_else(|| StudyError::Plot("bad buffer size".into()))
}

/// The files the study writes into its folder.
pub const FILES: [&str; 3] = ["study.csv", "study.svg", "study.png"];

/// Run the study and write `study.csv`, `study.svg` and `study.png` ([`FILES`]) into
/// `dir` (created).
pub fn write(
    scene: &Scene,
    name: &str,
    dir: &Path,
    w: u32,
    h: u32,
    strata: u32,
    backends: &[Backend],
) -> Result<Vec<Row>, StudyError> {
    let rows = run(scene, w, h, strata, backends)?;
    let title = format!("{name}, {w}x{h}: error vs time");
    let [csv_file, svg_file, png_file] = FILES.map(|f| dir.join(f));
    crate::output::write_text(&csv_file, &csv(&rows))?;
    crate::output::write_text(&svg_file, &svg(&rows, &title)?)?;
    let png = raster(&rows, &title)?;
    crate::output::write_atomic(&png_file, |f| {
        let mut f = std::io::BufWriter::new(f);
        png.write_to(&mut f, image::ImageFormat::Png)
            .map_err(|e| e.to_string())?;
        std::io::Write::flush(&mut f).map_err(|e| e.to_string())
    })?;
    Ok(rows)
}
