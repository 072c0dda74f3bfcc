//! Radiosity: diffuse interreflection between the scene's surfaces, view-independent.
//!
//! The phases: `mesh` splits every triangle, and the faces of the analytic shapes
//! `tessellate` handles, into elements of at most the patch size;
//! `formfactor` estimates form factors by ray casting (exact point-to-polygon form
//! factors with visibility from `Accel::occluded`, either backend); `solver` solves
//! the system by progressive refinement (or Gauss–Seidel on the full matrix); a
//! [`Solution`] then holds per-vertex radiosities (area-weighted averages of the
//! adjacent elements) that any camera can look at through ray casting, Gouraud
//! interpolated, and that export as a PLY mesh with vertex colours.
//!
//! Units: an element's radiosity `B` (power per unit area) is what the image shows;
//! the emitters are the surfaces whose material has an `emission`.
//! Elements are one-sided: they emit and receive on the side their triangle's winding
//! makes the front (counterclockwise seen from the front); the back side shows black.

pub(crate) mod formfactor;
pub(crate) mod hemicube;
pub(crate) mod mesh;
pub(crate) mod solver;

#[cfg(test)]
mod tests;

use crate::accel::{Accel, AccelError, Hit};
use crate::geometry::Kind;
/// The tessellation of analytic shapes the mesh starts from, in `geometry`.
use crate::math::Vec3;
use crate::render::color::srgb_encode;
use crate::render::{Film, GlobalIllumination, gi};
use crate::scene::Scene;
use formfactor::Sampling;
use mesh::Mesh;
use serde::Serialize;
use solver::Solve;
use std::time::Instant;

/// Errors of the radiosity pass.
#[derive(Debug, thiserror::Error)]
pub enum RadiosityError {
    /// Bad settings (patch size, mesh too large, ...).
    #[error("{0}")]
    Settings(String),
    /// Nothing emits light.
    #[error("no surface emits light: give a material an `emission` (radiosity needs area lights)")]
    NoEmitters,
    /// The scene has no triangles to mesh.
    #[error("the scene has no polygons or meshes to compute radiosity on")]
    Empty,
    /// The backend failed.
    #[error(transparent)]
    Accel(#[from] AccelError),
}

/// Which solver.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum SolverKind {
    /// Progressive refinement (shooting).
    Progressive,
    /// Gauss–Seidel on the full matrix (small meshes only).
    GaussSeidel,
}

/// How form factors are computed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum FormFactorMethod {
    /// Exact point-to-polygon form factors at sample points on the shooter, times the
    /// visibility from `Accel::occluded` rays (either backend).
    RayCast,
    /// A hemicube of this many pixels across its top face on each shooter's centroid,
    /// visibility from its depth buffer (meshed elements only: analytic shapes that
    /// are not tessellated do not occlude).
    Hemicube(u32),
}

/// How to solve.
#[derive(Clone, Debug, PartialEq)]
pub struct RadiositySettings {
    /// Longest element edge; `None`: 1/12 of the diagonal of the meshed triangles'
    /// bounds.
    pub patch_size: Option<f32>,
    /// Shooter sample points per element: `4^shooter_level`.
    pub shooter_level: u32,
    /// Visibility rays per pair of elements: `4^visibility_level`.
    pub visibility_level: u32,
    /// Stop when the unshot power falls below this fraction of the emitted power
    /// (progressive), or when no radiosity changes by more than this fraction of the
    /// largest emission (Gauss–Seidel).
    pub epsilon: f64,
    /// Most shots (progressive) or sweeps (Gauss–Seidel).
    pub max_iterations: usize,
    /// Solver.
    pub solver: SolverKind,
    /// Form-factor method.
    pub form_factors: FormFactorMethod,
    /// Adaptive subdivision: after a solve, split the elements whose radiosity differs
    /// from a neighbour's by more than this fraction of the largest reflected radiosity,
    /// and solve again; `None`: uniform mesh.
    pub subdiv_threshold: Option<f32>,
    /// Smallest element edge adaptive subdivision makes; `None`: 1/8 of the patch size.
    pub min_patch_size: Option<f32>,
    /// Most rounds of adaptive subdivision.
    pub subdiv_passes: u32,
}

impl Default for RadiositySettings {
    fn default() -> Self {
        RadiositySettings {
            patch_size: None,
            shooter_level: 1,
            visibility_level: 0,
            epsilon: 1e-3,
            max_iterations: 1_000_000,
            solver: SolverKind::Progressive,
            form_factors: FormFactorMethod::RayCast,
            subdiv_threshold: None,
            min_patch_size: None,
            subdiv_passes: 3,
        }
    }
}

/// A solved scene: the mesh, element and vertex radiosities.
#[derive(Clone, Debug)]
pub struct Solution {
    /// The mesh.
    pub mesh: Mesh,
    /// The solver's output.
    pub solve: Solve,
    /// Cohen's ambient term: the unshot energy spread uniformly, for display before
    /// convergence (zero once everything is shot).
    pub ambient: Vec3,
    /// Displayed radiosity per element (`B + ρ·ambient`).
    pub element_radiosity: Vec<Vec3>,
    /// Displayed radiosity per vertex: area-weighted mean of the adjacent elements.
    pub vertex_radiosity: Vec<Vec3>,
}

impl Solution {
    /// Display values from a solve.
    pub fn new(mesh: Mesh, solve: Solve) -> Self {
        let total_area = mesh.area().max(f64::MIN_POSITIVE);
        let mut rho_avg = Vec3::ZERO;
        let mut unshot = Vec3::ZERO;
        for (k, e) in mesh.elements.iter().enumerate() {
            rho_avg += mesh.reflectance[e.material as usize] * e.area;
            unshot += solve.unshot[k] * e.area;
        }
        let rho_avg = rho_avg / total_area as f32;
        let ambient = unshot / total_area as f32 / (Vec3::ONE - rho_avg);
        let element_radiosity: Vec<Vec3> = mesh
            .elements
            .iter()
            .zip(&solve.radiosity)
            .map(|(e, &b)| b + mesh.reflectance[e.material as usize] * ambient)
            .collect();
        let mut sum = vec![Vec3::ZERO; mesh.vertices.len()];
        let mut weight = vec![0.0f32; mesh.vertices.len()];
        for (e, &b) in mesh.elements.iter().zip(&element_radiosity) {
            for &v in &e.verts {
                sum[v as usize] += b * e.area;
                weight[v as usize] += e.area;
            }
        }
        let mut vertex_radiosity: Vec<Vec3> = sum
            .iter()
            .zip(&weight)
            .map(|(&s, &w)| if w > 0.0 { s / w } else { Vec3::ZERO })
            .collect();
        // T-junctions: a vertex inside a coarser element's edge takes the value the
        // coarser element interpolates there, so the shading has no crack.
        for (m, a, b) in mesh.hanging_vertices() {
            let v = &mut vertex_radiosity;
            v[m as usize] = (v[a as usize] + v[b as usize]) * 0.5;
        }
        Solution {
            mesh,
            solve,
            ambient,
            element_radiosity,
            vertex_radiosity,
        }
    }

    /// The Gouraud-interpolated radiosity at a hit at point `p` seen along `dir`: on a
    /// meshed triangle, at the hit's barycentric coordinates (zero on its back side); on
    /// a tessellated analytic shape, at the projection of `p` onto the face under it (see
    /// `tessellate`; the back side of an open cone is not meshed: `None`); `None` for
    /// primitives that are not meshed.
    pub fn radiosity_at(&self, hit: &Hit, p: Vec3, dir: Vec3) -> Option<Vec3> {
        let (k, u, v) = match hit.kind() {
            Kind::Triangle => {
                let (k, u, v) = self.mesh.locate(hit.inst_id, hit.prim_id, hit.u, hit.v)?;
                if self.mesh.elements[k].n.dot(dir) >= 0.0 {
                    return Some(Vec3::ZERO);
                }
                (k, u, v)
            }
            _ if hit.inst_id != crate::accel::NO_INSTANCE => return None,
            kind => {
                let (k, u, v, open) = self.mesh.locate_analytic(kind, hit.prim_id, p, hit.ng)?;
                // A closed shape shows only its meshed side; an open one shows both.
                let n = self.mesh.elements[k].n;
                if open && (hit.ng.dot(n) > 0.0) != (hit.ng.dot(dir) < 0.0) {
                    return None;
                }
                (k, u, v)
            }
        };
        let e = &self.mesh.elements[k];
        let c = e.verts.map(|i| self.vertex_radiosity[i as usize]);
        Some(c[0] * (1.0 - u - v) + c[1] * u + c[2] * v)
    }

    /// The solved mesh as ASCII PLY with sRGB-encoded 8-bit vertex colours (values
    /// scaled by `exposure`), one vertex per element corner so that creases stay sharp.
    /// Positions are the world's: the scene's `origin` ([`crate::scene::Scene::origin`])
    /// added back, in double precision.
    pub fn to_ply(&self, exposure: f32, origin: glam::DVec3) -> String {
        use std::fmt::Write;
        let m = &self.mesh;
        let mut s = String::new();
        let _ = write!(
            s,
            "ply\nformat ascii 1.0\ncomment emray radiosity solution\nelement vertex {}\n\
             property double x\nproperty double y\nproperty double z\n\
             property uchar red\nproperty uchar green\nproperty uchar blue\n\
             element face {}\nproperty list uchar int vertex_indices\nend_header\n",
            m.vertices.len(),
            m.elements.len()
        );
        let byte = |x: f32| (srgb_encode(x * exposure) * 255.0).round() as u8;
        for (p, c) in m.vertices.iter().zip(&self.vertex_radiosity) {
            let p = p.as_dvec3() + origin;
            let _ = writeln!(
                s,
                "{} {} {} {} {} {}",
                p.x,
                p.y,
                p.z,
                byte(c.x),
                byte(c.y),
                byte(c.z)
            );
        }
        for e in &m.elements {
            let _ = writeln!(s, "3 {} {} {}", e.verts[0], e.verts[1], e.verts[2]);
        }
        s
    }
}

/// What the renderer takes from a solution: its Gouraud radiosity where the mesh
/// covers the surface ([`Solution::radiosity_at`]).
impl GlobalIllumination for Solution {
    fn radiosity_at(&self, hit: &Hit, p: Vec3, dir: Vec3) -> Option<Vec3> {
        Solution::radiosity_at(self, hit, p, dir)
    }
}

/// Mesh `scene` and solve its radiosity with visibility from `accel`.
pub fn solve<A: Accel>(
    scene: &Scene,
    accel: &A,
    settings: &RadiositySettings,
) -> Result<Solution, RadiosityError> {
    let patch = match settings.patch_size {
        Some(p) => p,
        None => default_patch_size(scene),
    };
    let mut mesh = Mesh::build(scene, patch)?;
    if mesh.elements.is_empty() {
        return Err(RadiosityError::Empty);
    }
    let mut solve = solve_mesh(&mesh, accel, settings, None)?;
    let (mut form_factor_ms, mut total_ms, mut refinements) =
        (solve.form_factor_ms, solve.total_ms, Vec::new());
    let (mut shots, mut regathered) = (solve.iterations, 0);
    if let Some(threshold) = settings.subdiv_threshold {
        let min = settings.min_patch_size.unwrap_or(patch / 8.0);
        if !(threshold.is_finite() && threshold > 0.0 && min.is_finite() && min > 0.0) {
            return Err(RadiosityError::Settings(format!(
                "subdivision threshold {threshold} and minimum patch size {min} must be positive"
            )));
        }
        for _ in 0..settings.subdiv_passes {
            let marked = marked_for_split(&mesh, &solve.radiosity, threshold, min);
            if marked.is_empty() {
                break;
            }
            // Children inherit their parent's state: the radiosity it has shot
            // (progressive) or holds (Gauss–Seidel). `split` keeps the first child at
            // the parent's index and appends the other three in order.
            let mut state: Vec<Vec3> = match settings.solver {
                SolverKind::Progressive => (solve.radiosity.iter())
                    .zip(&solve.unshot)
                    .map(|(&b, &u)| b - u)
                    .collect(),
                SolverKind::GaussSeidel => solve.radiosity.clone(),
            };
            for &k in &marked {
                state.extend([state[k]; 3]);
            }
            mesh.split(&marked)?;
            refinements.push(marked.len());
            solve = solve_mesh(&mesh, accel, settings, Some(&state))?;
            form_factor_ms += solve.form_factor_ms;
            total_ms += solve.total_ms;
            shots += solve.iterations;
            regathered += solve.regathered;
        }
    }
    solve.form_factor_ms = form_factor_ms;
    solve.total_ms = total_ms;
    solve.refinements = refinements;
    solve.total_iterations = shots;
    solve.regathered = regathered;
    Ok(Solution::new(mesh, solve))
}

/// The elements to split: those whose radiosity differs from a neighbour's (an element
/// sharing a corner, on any plane) by more than `threshold` times the largest radiosity
/// of a non-emitting element, in some channel, and whose halves would still have edges
/// of at least `min`. Emitters are not split.
pub fn marked_for_split(mesh: &Mesh, radiosity: &[Vec3], threshold: f32, min: f32) -> Vec<usize> {
    let emits = |k: usize| mesh.emission[mesh.elements[k].material as usize].max_element() > 0.0;
    let scale = (0..mesh.elements.len())
        .filter(|&k| !emits(k))
        .map(|k| radiosity[k].max_element())
        .fold(0.0f32, f32::max);
    if scale <= 0.0 {
        return Vec::new();
    }
    let mut at: std::collections::HashMap<[u32; 3], Vec<usize>> = Default::default();
    for (k, e) in mesh.elements.iter().enumerate() {
        if !emits(k) {
            for p in e.p {
                at.entry(p.to_array().map(f32::to_bits))
                    .or_default()
                    .push(k);
            }
        }
    }
    let mut mark = vec![false; mesh.elements.len()];
    for around in at.values() {
        for (x, &i) in around.iter().enumerate() {
            for &j in &around[x + 1..] {
                let d = (radiosity[i] - radiosity[j]).abs().max_element();
                if d > threshold * scale {
                    mark[i] = true;
                    mark[j] = true;
                }
            }
        }
    }
    (0..mesh.elements.len())
        .filter(|&k| mark[k] && mesh::longest_edge(&mesh.elements[k].p) * 0.5 >= min)
        .collect()
}

/// Solve the radiosity system of `mesh` with the settings' form factors and solver,
/// from the emission (`start` `None`) or from a previous state: per element, the
/// radiosity already shot (progressive refinement) or the current radiosity
/// (Gauss–Seidel).
pub fn solve_mesh<A: Accel>(
    mesh: &Mesh,
    accel: &A,
    settings: &RadiositySettings,
    start: Option<&[Vec3]>,
) -> Result<Solve, RadiosityError> {
    let (eps, max) = (settings.epsilon, settings.max_iterations);
    let run = |row: &dyn Fn(usize) -> Vec<f32>| match settings.solver {
        SolverKind::Progressive => solver::progressive_rows_from(mesh, row, eps, max, start),
        SolverKind::GaussSeidel => solver::gauss_seidel_rows_from(mesh, row, eps, max, start),
    };
    match settings.form_factors {
        FormFactorMethod::RayCast => {
            let s = Sampling::new(settings.shooter_level, settings.visibility_level);
            run(&|i| solver::form_factor_row(mesh, accel, &s, i))
        }
        FormFactorMethod::Hemicube(res) => {
            let h = hemicube::Hemicube::new(res)?;
            run(&|i| h.row(mesh, i))
        }
    }
}

/// 1/12 of the diagonal of the bounds of the scene's top-level and instanced
/// triangles.
pub fn default_patch_size(scene: &Scene) -> f32 {
    let mut b = crate::math::Aabb::EMPTY;
    for t in &scene.geometry.triangles.items {
        b = b.union(&t.bounds());
    }
    for inst in &scene.instances {
        for t in &scene.objects[inst.object as usize].triangles.items {
            b = b.union(&inst.xform.bounds_to_world(&t.bounds()));
        }
    }
    let d = b.extent().length();
    if d.is_finite() && d > 0.0 {
        d / 12.0
    } else {
        1.0
    }
}

/// Look at a solution from the scene's camera (`width × height`, `spp²` stratified
/// samples per pixel): Gouraud radiosity on meshed surfaces, the material colour
/// times the scene's ambient on other primitives, the background on misses.
pub fn render_view<A: Accel>(
    scene: &Scene,
    accel: &A,
    sol: &Solution,
    width: u32,
    height: u32,
    spp: u32,
) -> Film {
    gi::view(scene, accel, sol, width, height, spp)
}

/// What a radiosity run reports (`--stats`, `--stats-json`).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RadiosityReport {
    /// Backend name.
    pub backend: &'static str,
    /// Solver.
    pub solver: SolverKind,
    /// Form-factor method.
    pub form_factors: FormFactorMethod,
    /// Patch size used.
    pub patch_size: f32,
    /// Elements (after adaptive subdivision).
    pub elements: usize,
    /// Elements split in each round of adaptive subdivision.
    pub refinements: Vec<usize>,
    /// Shared vertices.
    pub vertices: usize,
    /// Analytic primitives left out of the mesh.
    pub unmeshed: usize,
    /// Shooter samples per element.
    pub shooter_samples: usize,
    /// Visibility rays per pair of elements.
    pub visibility_samples: usize,
    /// Shots or sweeps (the last round of adaptive subdivision).
    pub iterations: usize,
    /// Shots or sweeps in all rounds.
    pub total_iterations: usize,
    /// Form-factor rows computed to gather each round's start from the previous one.
    pub regathered: usize,
    /// Residual curve.
    pub residuals: Vec<f64>,
    /// Milliseconds: building the backend, form factors, whole solve, one view.
    pub build_ms: f64,
    /// Form-factor time.
    pub form_factor_ms: f64,
    /// Solve time (form factors included).
    pub solve_ms: f64,
    /// Time to render one view of the solved scene.
    pub view_ms: f64,
}

impl RadiosityReport {
    /// Human-readable summary.
    pub fn summary(&self) -> String {
        let last = self.residuals.last().copied().unwrap_or(0.0);
        let method = match self.form_factors {
            FormFactorMethod::RayCast => format!(
                "ray cast, {} points per shooter, {} visibility rays per element pair",
                self.shooter_samples, self.visibility_samples
            ),
            FormFactorMethod::Hemicube(res) => {
                format!("hemicube, {res}x{res} top face, on each shooter's centroid")
            }
        };
        format!(
            "backend    {}\nmesh       {} elements, {} vertices (patch size {}), {} analytic primitives not meshed\n\
             subdivide  {:?} elements split per round; {} iterations and {} re-gather rows in all rounds\n\
             ff         {}\n\
             solver     {:?}: {} iterations, final residual {:.3e}\n\
             time       build {:.1} ms, form factors {:.1} ms, solve {:.1} ms, view {:.1} ms",
            self.backend,
            self.elements,
            self.vertices,
            self.patch_size,
            self.unmeshed,
            self.refinements,
            self.total_iterations,
            self.regathered,
            method,
            self.solver,
            self.iterations,
            last,
            self.build_ms,
            self.form_factor_ms,
            self.solve_ms,
            self.view_ms,
        )
    }
}

pub(crate) fn solve_and_view<A: Accel>(
    scene: &Scene,
    accel: &A,
    settings: &RadiositySettings,
    view: (u32, u32, u32),
    build_ms: f64,
) -> Result<(Solution, Film, RadiosityReport), RadiosityError> {
    let sol = solve(scene, accel, settings)?;
    let t = Instant::now();
    let film = render_view(scene, accel, &sol, view.0, view.1, view.2);
    let view_ms = t.elapsed().as_secs_f64() * 1e3;
    let report = RadiosityReport {
        backend: accel.stats().backend,
        solver: settings.solver,
        form_factors: settings.form_factors,
        patch_size: settings
            .patch_size
            .unwrap_or_else(|| default_patch_size(scene)),
        elements: sol.mesh.elements.len(),
        refinements: sol.solve.refinements.clone(),
        vertices: sol.mesh.vertices.len(),
        unmeshed: sol.mesh.unmeshed,
        shooter_samples: 1 << (2 * settings.shooter_level),
        visibility_samples: 1 << (2 * settings.visibility_level),
        iterations: sol.solve.iterations,
        total_iterations: sol.solve.total_iterations,
        regathered: sol.solve.regathered,
        residuals: sol.solve.residuals.clone(),
        build_ms,
        form_factor_ms: sol.solve.form_factor_ms,
        solve_ms: sol.solve.total_ms,
        view_ms,
    };
    Ok((sol, film, report))
}
