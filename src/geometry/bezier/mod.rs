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
//!
//! # Tessellation
//!
//! ## The scheme
//!
//! Each patch gets a grid of `2ᵃ × 2ᵇ` parameter cells, and each boundary edge a
//! number `2ᵉ` of segments that is the same for every patch sharing the edge. An edge
//! is identified by its four control points in a canonical orientation (the point
//! sequence or its reverse, whichever sorts first), and its vertices are evaluated on
//! that canonical polygon at dyadic parameters: two patches sharing an edge, in either
//! direction, get bitwise the same vertices.
//!
//! Along its boundary a patch uses exactly the edge's vertices and no others, so the
//! mesh is conforming: no T-junctions, every interior edge is shared by exactly two
//! triangles with identical end points (opposite directions), and a watertight
//! ray/triangle test lets no ray through a seam. The grid is at least as fine as each
//! of its edges, and the ring of cells next to the boundary is stitched: the boundary
//! polyline (coarse) and the first interior grid line (fine) are joined by fans, one
//! polygon per coarse segment, which keeps every triangle inside the parameter
//! rectangle spanned by that segment and the ring's width. The four stitched strips
//! meet on the diagonals from the corners to the first interior grid point; inside,
//! the grid cells are split along their shorter diagonal. A patch one cell wide in `v`
//! (`b = 0`) is a single strip joining its two `u` edges directly (likewise for
//! `a = 0`), so an exactly flat patch becomes two triangles.
//!
//! ## Adaptivity and the error bound
//!
//! The refinement is driven by the flatness of the control nets of the patch
//! subdivided by de Casteljau's algorithm: over a parameter rectangle whose sub-patch
//! has control-net second differences `D_uu`, `D_vv`, `D_uv`, every triangle with
//! vertices on the surface inside it is within `¾(D_uu + D_vv) + 9/4·D_uv` of the
//! surface at the same parameters ([`BezierPatch::triangle_error_bound`]).
//!
//! 1. Each patch on its own: the grid is refined, in the direction that dominates the
//!    failing bound, until every cell is within the tolerance; each edge takes the
//!    coarsest level, at least what the edge's own control polygon needs
//!    (`¾ max|Δ²p| ≤ tolerance` on every piece), at which the stitched strip along it
//!    is within the tolerance. The strip's rectangles are as long as the edge's
//!    segments, so an edge that is straight but borders a surface curving along it
//!    still gets the segments that surface needs.
//! 2. Shared edges: every edge takes the finest level any of its patches asked for
//!    (a table keyed by the canonical control points), and each grid grows to be at
//!    least as fine as its edges. Both only shrink the rectangles the bound was taken
//!    over, so the tolerance still holds.
//!
//! Levels are capped at [`MAX_LEVEL`] per direction.

mod curve;
pub mod newell;
mod patch;
mod tessellate;

pub use curve::BezierCurve;
pub use patch::BezierPatch;
pub use tessellate::{MAX_LEVEL, TriMesh, tessellate};

/// Newell's teapot ([`newell`], the data of the SPD's `teapot` database) as 32
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
    newell::PATCHES
        .iter()
        .map(|patch| {
            let rows = patch.map(|row| row.map(|k| glam::DVec3::from_array(newell::VERTS[k])));
            BezierPatch::new(rows).transposed()
        })
        .collect()
}
