//! Bézier curves, bicubic Bézier patches and their crack-free adaptive tessellation
//! into smooth triangles, with Newell's teapot built in.
//!
//! * [`BezierCurve`]: any degree; de Casteljau evaluation, hodograph, subdivision,
//!   degree elevation, flatness.
//! * [`BezierPatch`]: bicubic; evaluation, partial derivatives, normals (with the
//!   limit taken where an edge collapses to a point), subdivision in `u` and `v`.
//! * [`tessellate`]: patches to a [`TriMesh`] within a distance tolerance, refined
//!   where the surface curves, without cracks between patches refined differently.
//! * [`teapot_patches`]: the 32 patches of the Utah teapot.
//!
//! The mathematics is in `f64`; only the mesh is `f32`.

mod curve;
mod patch;
mod tessellate;

pub use curve::BezierCurve;
pub use patch::BezierPatch;
pub use tessellate::{tessellate, TriMesh, MAX_LEVEL};

/// Newell's teapot (the data of the `teapot` database in [`crate::gen`]) as 32
/// bicubic patches: rim 0–3, body 4–11, handle 12–15, spout 16–19, lid 20–27, bottom
/// 28–31.
///
/// The parameters are laid out so that the normals point out of the teapot: `u` runs
/// along the data's columns and `v` along its rows (`p[i][j]` is the data's row `j`,
/// column `i`). The lid's knob (20–23) and the bottom (28–31) have their `v = 0` edge
/// collapsed to a point on the axis. The surface is open along the rim's `v = 0` edge
/// (the pot's mouth), the lid's `v = 1` edge, and both ends of the handle and of the
/// spout (`v = 0` and `v = 1` of 12–19).
pub fn teapot_patches() -> Vec<BezierPatch> {
    BezierPatch::newell_teapot_control_points()
        .into_iter()
        .map(|p| BezierPatch::new(p).transposed())
        .collect()
}
