//! Solvers of the radiosity system `B_j = E_j + ρ_j Σ_i F_ji B_i`, in RGB.
//!
//! - Progressive refinement (Cohen, Chen, Wallace & Greenberg 1988): repeatedly shoot
//!   the unshot energy of the element with the most unshot power; one row of form
//!   factors at a time, so memory stays linear in the number of elements. The residual
//!   is the unshot power over the emitted power.
//! - Gauss–Seidel on the full matrix for small meshes, as a cross-check.

use super::RadiosityError;
use super::formfactor::{Sampling, element_form_factor};
use super::mesh::Mesh;
use crate::accel::Accel;
use crate::math::Vec3;
use rayon::prelude::*;
use std::time::Instant;

/// Largest mesh the full-matrix solver accepts (its matrix has n² entries).
pub const MAX_FULL_MATRIX: usize = 4096;

/// A solved (or partly solved) radiosity system.
#[derive(Clone, Debug, Default)]
pub struct Solve {
    /// Radiosity per element.
    pub radiosity: Vec<Vec3>,
    /// Energy received but not yet shot, per element.
    pub unshot: Vec<Vec3>,
    /// Residual (unshot over emitted power) before each shot and after the last.
    pub residuals: Vec<f64>,
    /// Shots (progressive) or sweeps (Gauss–Seidel) done.
    pub iterations: usize,
    /// Shots or sweeps in all rounds of adaptive subdivision together.
    pub total_iterations: usize,
    /// Milliseconds spent computing form factors.
    pub form_factor_ms: f64,
    /// Milliseconds for the whole solve.
    pub total_ms: f64,
    /// Elements split in each round of adaptive subdivision (each round goes on from
    /// the previous round's solution; the other fields describe the last round, the
    /// times and counts cover all).
    pub refinements: Vec<usize>,
    /// Rows of form factors computed to gather a previous round's solution again on a
    /// refined mesh (progressive refinement only).
    pub regathered: usize,
}

fn power(v: Vec3) -> f64 {
    (v.x + v.y + v.z) as f64
}

/// One row of form factors `F_ij` for all `j`, in parallel.
pub fn form_factor_row<A: Accel>(mesh: &Mesh, accel: &A, s: &Sampling, i: usize) -> Vec<f32> {
    (0..mesh.elements.len())
        .into_par_iter()
        .map(|j| element_form_factor(mesh, accel, s, i, j))
        .collect()
}

fn emitted(mesh: &Mesh) -> Result<Vec<Vec3>, RadiosityError> {
    let e: Vec<Vec3> = mesh
        .elements
        .iter()
        .map(|el| mesh.emission[el.material as usize])
        .collect();
    if e.iter().all(|v| v.max_element() <= 0.0) {
        return Err(RadiosityError::NoEmitters);
    }
    Ok(e)
}

/// Add to `b` and `u` what the receivers of row `f` of element `i` gather from its
/// radiosity `shot`.
fn receive(mesh: &Mesh, i: usize, f: &[f32], shot: Vec3, b: &mut [Vec3], u: &mut [Vec3]) {
    let ai = mesh.elements[i].area;
    for (j, &f) in f.iter().enumerate() {
        if f > 0.0 {
            let el = &mesh.elements[j];
            let rho = mesh.reflectance[el.material as usize];
            let db = rho * shot * (f * ai / el.area);
            b[j] += db;
            u[j] += db;
        }
    }
}

/// Progressive refinement that starts, with `shot`, from a state in which each element
/// has already shot that radiosity (a previous solve on a coarser mesh whose split
/// elements passed theirs to their children): the radiosities are gathered again from
/// it with this mesh's form factors (one row per element that has shot), what each
/// element holds beyond what it has shot is its unshot radiosity (negative where a
/// child received less than its parent), and shooting goes on from there. The
/// invariant `B = E + K·shot` of progressive refinement holds from the start, so the
/// solver converges to the same solution as from the emission alone. `None`: start
/// from the emission. Shooters are picked, and the residual measured, by the absolute
/// unshot power.
pub fn progressive_rows_from<R: Fn(usize) -> Vec<f32>>(
    mesh: &Mesh,
    row: R,
    epsilon: f64,
    max_shots: usize,
    shot: Option<&[Vec3]>,
) -> Result<Solve, RadiosityError> {
    let start = Instant::now();
    let emission = emitted(mesh)?;
    let n = mesh.elements.len();
    let area: Vec<f32> = mesh.elements.iter().map(|e| e.area).collect();
    let total_emitted: f64 = (0..n).map(|i| power(emission[i]) * area[i] as f64).sum();
    let mut out = Solve {
        radiosity: emission.clone(),
        unshot: emission,
        ..Default::default()
    };
    let mut ff_ms = 0.0;
    if let Some(shot) = shot {
        if shot.len() != n {
            return Err(RadiosityError::Settings(format!(
                "a previous solution of {} elements does not fit a mesh of {n}",
                shot.len()
            )));
        }
        let mut u = vec![Vec3::ZERO; n];
        for (i, &s) in shot.iter().enumerate() {
            if s != Vec3::ZERO {
                let t = Instant::now();
                let f = row(i);
                ff_ms += t.elapsed().as_secs_f64() * 1e3;
                receive(mesh, i, &f, s, &mut out.radiosity, &mut u);
                out.regathered += 1;
            }
        }
        for ((u, &b), &s) in out.unshot.iter_mut().zip(&out.radiosity).zip(shot) {
            *u = b - s;
        }
    }
    let abs_power = |v: Vec3| power(v.abs());
    loop {
        let unshot_power: f64 = (0..n)
            .map(|i| abs_power(out.unshot[i]) * area[i] as f64)
            .sum();
        let residual = unshot_power / total_emitted;
        out.residuals.push(residual);
        if residual < epsilon || out.iterations >= max_shots {
            break;
        }
        let i = (0..n)
            .max_by(|&a, &b| {
                let pa = abs_power(out.unshot[a]) * area[a] as f64;
                let pb = abs_power(out.unshot[b]) * area[b] as f64;
                pa.total_cmp(&pb)
            })
            .expect("non-empty mesh");
        let t = Instant::now();
        let row = row(i);
        ff_ms += t.elapsed().as_secs_f64() * 1e3;
        let shot = out.unshot[i];
        out.unshot[i] = Vec3::ZERO;
        receive(mesh, i, &row, shot, &mut out.radiosity, &mut out.unshot);
        out.iterations += 1;
    }
    out.form_factor_ms = ff_ms;
    out.total_ms = start.elapsed().as_secs_f64() * 1e3;
    Ok(out)
}

/// Gauss–Seidel with the rows of form factors from `row(i)`, starting from the
/// radiosities `initial` (a previous round's solution) or from the emission.
pub fn gauss_seidel_rows_from<R: Fn(usize) -> Vec<f32>>(
    mesh: &Mesh,
    row: R,
    tolerance: f64,
    max_sweeps: usize,
    initial: Option<&[Vec3]>,
) -> Result<Solve, RadiosityError> {
    let start = Instant::now();
    let emission = emitted(mesh)?;
    let n = mesh.elements.len();
    if n > MAX_FULL_MATRIX {
        return Err(RadiosityError::Settings(format!(
            "{n} elements: the full-matrix solver takes at most {MAX_FULL_MATRIX}; use a larger --patch-size or the progressive solver"
        )));
    }
    let t = Instant::now();
    // f[i][j] = F_ij, from i to j.
    let f: Vec<Vec<f32>> = (0..n).map(&row).collect();
    let ff_ms = t.elapsed().as_secs_f64() * 1e3;
    let scale = emission
        .iter()
        .map(|e| e.max_element() as f64)
        .fold(0.0, f64::max);
    let mut b = match initial {
        Some(b) if b.len() == n => b.to_vec(),
        _ => emission.clone(),
    };
    let mut out = Solve::default();
    loop {
        let mut change = 0.0f64;
        for j in 0..n {
            let ej = &mesh.elements[j];
            let rho = mesh.reflectance[ej.material as usize];
            let mut gathered = Vec3::ZERO;
            for i in 0..n {
                let fij = f[i][j];
                if fij > 0.0 {
                    // F_ji = F_ij A_i / A_j (reciprocity of the shooting estimate).
                    gathered += b[i] * (fij * mesh.elements[i].area / ej.area);
                }
            }
            let new = emission[j] + rho * gathered;
            change = change.max((new - b[j]).abs().max_element() as f64);
            b[j] = new;
        }
        out.iterations += 1;
        out.residuals.push(change / scale);
        if change / scale < tolerance || out.iterations >= max_sweeps {
            break;
        }
    }
    out.unshot = vec![Vec3::ZERO; n];
    out.radiosity = b;
    out.form_factor_ms = ff_ms;
    out.total_ms = start.elapsed().as_secs_f64() * 1e3;
    Ok(out)
}
