//! `emray stress`: every numerical stress case at full counts, with what was measured
//! and whether the bounds of `tests/stability.rs` hold.

use super::Error;
use super::args::LogArgs;
use super::error::print;
use emray::Backend;
use emray::accuracy::stress::*;

/// `emray stress`.
#[derive(clap::Args, Debug, Clone)]
pub struct Args {
    /// Random rays per far/tiny sphere case.
    #[arg(long, default_value_t = 1_000_000)]
    pub rays: u32,
    /// Random hard triangles (huge, sliver, grazing, eye near the plane), 256 rays
    /// each.
    #[arg(long, default_value_t = 4000)]
    pub triangles: u32,
    /// `-q` and `-v`.
    #[command(flatten)]
    pub log: LogArgs,
}

/// The verdicts so far: each printed as `ok` or `FAIL` with what was measured.
struct Checks {
    ok: bool,
}

impl Checks {
    fn check(&mut self, holds: bool, what: String) {
        // The exit status carries the verdict: a closed standard output loses only
        // the report.
        let _ = print(format_args!(
            "{} {what}\n",
            if holds { "ok  " } else { "FAIL" }
        ));
        self.ok &= holds;
    }
}

/// Run every case; a broken bound is [`Error::CheckFailed`].
pub fn run(a: Args) -> Result<(), Error> {
    let mut checks = Checks { ok: true };
    let mut backends = vec![Backend::Bvh];
    if cfg!(feature = "embree") {
        backends.push(Backend::Embree);
    }
    scale(&mut checks, &backends);
    offset(&mut checks);
    moved(&mut checks, &backends);
    far_spheres(&mut checks, a.rays);
    quadric_roots(&mut checks, a.rays);
    watertight(&mut checks);
    hard_triangles(&mut checks, &backends, a.triangles);
    if checks.ok {
        Ok(())
    } else {
        Err(Error::CheckFailed)
    }
}

/// Scaled scenes render as the unscaled one, without self-shadowing acne.
fn scale(checks: &mut Checks, backends: &[Backend]) {
    for &b in backends {
        let want = render(&floor_scene(1.0, 256), b);
        for e in -4..=4 {
            if e == 0 {
                continue;
            }
            let share = differing_share(&render(&floor_scene(10f64.powi(e), 256), b), &want);
            checks.check(
                share <= 1e-3,
                format!(
                    "scale 1e{e} ({b:?}, 256x256): {:.4}% pixels differ (bound 0.1%)",
                    share * 100.0
                ),
            );
        }
    }
    for e in -4..=4 {
        let c = convex_scene(10f64.powi(e), 0.0, 256);
        let (lit, bad) = acne_on(&c, &Backend::Bvh.into()).expect("the BVH builds");
        checks.check(
            bad == 0,
            format!("scale 1e{e}: acne {bad} of {lit} lit points"),
        );
    }
}

/// Scenes far from the origin: no acne up to 1e5.
fn offset(checks: &mut Checks) {
    let base = render(&convex_scene(1.0, 0.0, 256), Backend::Bvh);
    for e in 3..=6 {
        let s = convex_scene(1.0, 10f64.powi(e), 256);
        let (lit, bad) = acne_on(&s, &Backend::Bvh.into()).expect("the BVH builds");
        let share = differing_share(&render(&s, Backend::Bvh), &base);
        checks.check(
            e > 5 || bad == 0,
            format!(
                "offset 1e{e}: acne {bad} of {lit} lit points, {:.3}% pixels differ",
                share * 100.0
            ),
        );
    }
}

/// The shifts every SPD database is moved by in [`moved`] (far from the origin), and
/// the scales: powers of two from about 10⁻⁴ to 10⁴, which scale every coordinate
/// exactly, so that any change in the picture is the renderer's own.
pub const SHIFTS: [[f64; 3]; 3] = [[1e3, -1e3, 1e3], [1e5, -1e5, 1e5], [1e6, -1e6, 1e6]];
/// See [`SHIFTS`].
pub const SCALES: [f64; 4] = [1.0 / 8192.0, 1.0 / 128.0, 128.0, 8192.0];
/// Decimal scales, measured and printed: their coordinates round differently in f32,
/// and a scene whose rays bounce between curved mirrors magnifies that rounding a few
/// bounces down, as it would any change of the input in its last digit. The last one
/// is that change alone, the control: every coordinate moved by about one unit in the
/// last place of an f32.
pub const DECIMAL_SCALES: [f64; 5] = [1e-4, 1e-2, 1e2, 1e4, 1.0 + f32::EPSILON as f64];

/// Every SPD database moved far from the origin or scaled renders as the original:
/// at least 99.9% of its pixels within 2/255 (256×256, pixel centres).
fn moved(checks: &mut Checks, backends: &[Backend]) {
    for db in emray::spd::Database::ALL {
        let src = db.generate(db.default_size());
        for &b in backends {
            let moves = SHIFTS.iter().map(|&s| (1.0, s, true));
            let scales = SCALES.iter().map(|&k| (k, [0.0; 3], true));
            let decimal = DECIMAL_SCALES.iter().map(|&k| (k, [0.0; 3], false));
            for (scale, shift, checked) in moves.chain(scales).chain(decimal) {
                let inv = invariance(&src, scale, shift.into(), b, 256);
                let what = format!(
                    "{} moved by {shift:?}, scaled by {scale:e} ({b:?}, 256x256): \
                     {:.3}% of pixels within 2/255, largest difference {}",
                    db.name(),
                    inv.within * 100.0,
                    inv.max_diff
                );
                if checked {
                    checks.check(inv.within >= 0.999, format!("{what} (bound 99.9%)"));
                } else {
                    let _ = print(format_args!("info {what}\n"));
                }
            }
        }
    }
}

/// Far and tiny spheres: the hit distance against f64, and the silhouette.
fn far_spheres(checks: &mut Checks, rays: u32) {
    for (dist, radius) in [(1e4f32, 1.0f32), (1e2, 1e-4), (1e6, 1e3), (1e5, 1e-2)] {
        let (worst, miss, extra) = far_sphere(dist, radius, rays, 7);
        checks.check(
            worst < 1e-5,
            format!(
                "sphere r={radius:e} at {dist:e}: worst relative t error {worst:.3e} over {rays} rays; \
                 silhouette: {miss} f32 misses, {extra} f32 extra hits"
            ),
        );
    }
}

/// Quadric roots against f64.
fn quadric_roots(checks: &mut Checks, rays: u32) {
    for (name, case) in quadric_root_cases() {
        let st = case(rays);
        checks.check(
            st.nan == 0 && st.disagree == 0 && st.worst_dist < ROOT_DIST_BOUND,
            format!(
                "{name}: {} rays ({} hit in f64): {} NaN, {} hit/miss disagreements \
                 outside the band ({} rays in it), worst |dt|/max(t,1) {:.3e}, \
                 worst f32 hit point distance from the surface {:.3e}",
                st.rays, st.hits, st.nan, st.disagree, st.in_band, st.worst_t, st.worst_dist
            ),
        );
    }
}

/// Rays through closed meshes: none may slip through on the BVH (Embree's numbers,
/// with and without its robust mode, are printed for information).
fn watertight(checks: &mut Checks) {
    let touching = |st: &WatertightStats| {
        format!(
            "{} misses of {} rays (and {} of {} rays that may only touch an apex or ridge)",
            st.misses, st.rays, st.touching_misses, st.touching
        )
    };
    for (name, case, n) in watertight_cases() {
        match case.run_on(&Backend::Bvh.into(), n, 3.0) {
            Ok((st, _)) => checks.check(
                st.misses == 0,
                format!("watertight ({name}, bvh): {}", touching(&st)),
            ),
            Err(e) => checks.check(false, format!("watertight ({name}, bvh): {e}")),
        }
        #[cfg(feature = "embree")]
        for robust in [false, true] {
            let flag = if robust { "robust" } else { "default flags" };
            let options = emray::accel::BackendOptions {
                embree_robust: robust,
                ..Backend::Embree.into()
            };
            let _ = match case.run_on(&options, n, 3.0) {
                Ok((st, _)) => print(format_args!(
                    "info watertight ({name}, embree {flag}): {}\n",
                    touching(&st)
                )),
                Err(e) => print(format_args!("info embree unavailable: {e}\n")),
            };
        }
    }
}

/// Huge, sliver and grazing triangles and origins near their plane: both backends find
/// every hit of the f64 reference and nothing where it finds none.
fn hard_triangles(checks: &mut Checks, backends: &[Backend], n: u32) {
    use emray::accuracy::hard_triangles::{Family, hard_cases, known_cases, run_cases};
    let mut cases = known_cases(4096);
    cases.extend(hard_cases(n, 256, 2027));
    for &b in backends {
        let by_family = match run_cases(&cases, &b.into()) {
            Ok(r) => r,
            Err(e) => {
                checks.check(false, format!("hard triangles ({b:?}): {e}"));
                continue;
            }
        };
        for (family, st) in by_family {
            // Embree's own f32 test decides the rays whose origin lies within the
            // coordinates' rounding of the plane: reported, not required.
            let exact = st.misses == 0 && st.extra == 0;
            let required = b == Backend::Bvh || family != Family::BelowRounding;
            let what = format!(
                "hard triangles, {} ({b:?}): {} misses of {} hits, {} extra hits; \
                     {} of {} rays within rounding of an edge; hit points at most {:.1} \
                     ulps of the largest coordinate off the plane",
                family.name(),
                st.misses,
                st.hits,
                st.extra,
                st.edge_band,
                st.rays,
                st.worst_plane_ulps
            );
            if required {
                checks.check(exact, what);
            } else {
                let _ = print(format_args!("info {what}\n"));
            }
        }
    }
}
