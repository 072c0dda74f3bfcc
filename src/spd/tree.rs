//! The `tree` database: a tree grown by Aono & Kunii's method ("Botanical Tree Image
//! Generation", IEEE CG&A May 1984), standing on a square field under seven lights
//! (SPD `tree.c`).
//!
//! Each branch is the unit segment from the origin along +Z in its own frame, drawn as
//! a cone tapering from radius `0.15 · scale` to `0.67` of that, with a sphere of the
//! apex radius capping the joint. Two children grow from every apex: each child frame
//! is the parent's composed with a fixed matrix — rotate about X by the branching angle
//! (40° and 25°), then about Z by the divergence (90° and 230°), then scale by the
//! contraction (0.65 and 0.70) and move 1 up the parent's axis — and the child's
//! `scale` is the parent's times 0.67. The recursion is depth first, first child first,
//! from depth `size` down to 0, so size factor `n` gives `2ⁿ⁺¹ − 1` cones and as many
//! spheres (4095 of each at the default 11), plus the one field polygon.

use super::NffSink;
use super::tx::{IDENTITY, Matrix, multiply, rotate, transform_point};
use glam::DVec3;
use std::f64::consts::PI;

/// The SPD program's default size factor.
pub const DEFAULT_SIZE: u32 = 11;

/// Branching angles (degrees) of the two children.
const BR_ANGLE: [f64; 2] = [40.0, 25.0];
/// Length contraction of the two children.
const BR_CONTR: [f64; 2] = [0.65, 0.70];
/// Radius ratio of a branch's apex to its base (and of a child's scale to its
/// parent's).
const BR_DIAMETER: f64 = 0.67;
/// Divergence angle (degrees) between the two children about the parent's axis.
const DIV_ANGLE: f64 = 140.0;
/// Base radius of a branch of unit scale.
const WIDTH_HEIGHT_RATIO: f64 = 0.15;

/// The two child frames relative to their parent's.
fn branch_matrices() -> [Matrix; 2] {
    let divergence = [90.0, DIV_ANGLE + 90.0];
    std::array::from_fn(|i| {
        let rx = rotate(0, BR_ANGLE[i] * PI / 180.0);
        let rz = rotate(2, divergence[i] * PI / 180.0);
        let rotate = multiply(&rx, &rz);
        let c = BR_CONTR[i];
        let mut scale_translate = IDENTITY;
        scale_translate[0][0] = c;
        scale_translate[1][1] = c;
        scale_translate[2][2] = c;
        scale_translate[3][2] = 1.0;
        multiply(&rotate, &scale_translate)
    })
}

/// One branch: its cone's base and apex with their radii.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Branch {
    base: DVec3,
    base_radius: f64,
    apex: DVec3,
    apex_radius: f64,
    /// Recursion depth left (0 for the leaves' branches).
    depth: u32,
}

/// Grow the branch in frame `cur` and, depth first, its descendants; `emit` receives
/// each branch before its children.
fn grow_tree(
    rst: &[Matrix; 2],
    cur: &Matrix,
    scale: f64,
    depth: u32,
    emit: &mut impl FnMut(&Branch),
) {
    let base = transform_point(DVec3::ZERO, cur);
    let base_radius = scale * WIDTH_HEIGHT_RATIO;
    let apex = transform_point(DVec3::Z, cur);
    let apex_radius = base_radius * BR_DIAMETER;
    emit(&Branch {
        base,
        base_radius,
        apex,
        apex_radius,
        depth,
    });
    if depth > 0 {
        for m in rst {
            grow_tree(rst, &multiply(m, cur), scale * BR_DIAMETER, depth - 1, emit);
        }
    }
}

/// Every branch of the tree at size factor `size`, in output order.
fn for_each_branch(size: u32, mut emit: impl FnMut(&Branch)) {
    grow_tree(&branch_matrices(), &IDENTITY, 1.0, size, &mut emit);
}

/// Write the database at size factor `size`.
pub fn generate(size: u32, w: &mut impl NffSink) {
    // UNC sky blue.
    w.background(DVec3::new(0.078, 0.361, 0.753));
    w.viewpoint(
        DVec3::new(4.5, 0.4, 2.0),
        DVec3::new(0.0, 0.0, 1.5),
        DVec3::new(0.0, 0.0, 1.0),
        45.0,
        1.0,
        (512, 512),
    );
    for l in [
        [-5.0, 5.0, 50.0],
        [30.0, -30.0, 30.0],
        [-40.0, -30.0, 20.0],
        [10.0, 30.0, 40.0],
        [-30.0, 40.0, 10.0],
        [50.0, 25.0, 20.0],
        [-10.0, -60.0, 30.0],
    ] {
        w.light(DVec3::from_array(l));
    }

    // Green field; a Phong angle of 0 is written as the exponent 100000.
    w.fill(DVec3::new(0.2, 0.7, 0.2), 1.0, 0.0, 100_000.0, 0.0, 0.0);
    w.polygon(&[
        DVec3::new(50.0, 50.0, 0.0),
        DVec3::new(-50.0, 50.0, 0.0),
        DVec3::new(-50.0, -50.0, 0.0),
        DVec3::new(50.0, -50.0, 0.0),
    ]);

    // Brown tree.
    w.fill(DVec3::new(0.55, 0.4, 0.2), 1.0, 0.0, 100_000.0, 0.0, 0.0);
    for_each_branch(size, |b| {
        w.cone(b.base, b.base_radius, b.apex, b.apex_radius);
        w.sphere(b.apex, b.apex_radius);
    });
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spd::NffWriter;
    use std::path::Path;

    fn nff(size: u32) -> String {
        let mut w = NffWriter::new();
        generate(size, &mut w);
        w.finish()
    }

    #[test]
    fn counts_follow_two_to_the_size_plus_one_minus_one() {
        for size in 0..=6 {
            let text = nff(size);
            let n = (1usize << (size + 1)) - 1;
            assert_eq!(text.lines().filter(|l| l.starts_with("c ")).count(), n);
            assert_eq!(text.lines().filter(|l| l.starts_with("s ")).count(), n);
            assert_eq!(text.lines().filter(|l| l.starts_with("p ")).count(), 1);
            assert_eq!(text.lines().filter(|l| l.starts_with("l ")).count(), 7);
        }
        // The SPD's table: size 11 gives 4095 of each.
        let mut count = 0;
        for_each_branch(DEFAULT_SIZE, |_| count += 1);
        assert_eq!(count, 4095);
    }

    #[test]
    fn branches_grow_from_their_parents_apex_and_taper() {
        let mut branches = Vec::new();
        for_each_branch(5, |b| branches.push(*b));
        let root = branches[0];
        assert_eq!(root.base, DVec3::ZERO);
        assert_eq!(root.apex, DVec3::Z);
        assert_eq!(root.base_radius, 0.15);
        // Walk the depth-first order with a stack of open parents.
        let mut stack: Vec<(Branch, usize)> = Vec::new();
        for b in &branches {
            assert!(b.apex_radius < b.base_radius, "a branch tapers");
            while stack.last().is_some_and(|(_, left)| *left == 0) {
                stack.pop();
            }
            if let Some((parent, left)) = stack.last_mut() {
                *left -= 1;
                assert_eq!(b.depth + 1, parent.depth);
                // The base sits exactly on the parent's apex (the joint's sphere).
                assert_eq!(b.base, parent.apex);
                // No thicker than the parent's apex (equal up to rounding).
                assert!(b.base_radius <= parent.apex_radius * (1.0 + 1e-12));
                assert!((b.base_radius - parent.apex_radius).abs() < 1e-15);
                // Shorter than the parent, by one of the two contractions.
                let ratio = b.base.distance(b.apex) / parent.base.distance(parent.apex);
                assert!(
                    BR_CONTR.iter().any(|c| (ratio - c).abs() < 1e-12),
                    "{ratio}"
                );
                // Bent away from the parent's axis by one of the branching angles.
                let cos = (b.apex - b.base)
                    .normalize()
                    .dot((parent.apex - parent.base).normalize());
                let angle = cos.clamp(-1.0, 1.0).acos().to_degrees();
                assert!(BR_ANGLE.iter().any(|a| (angle - a).abs() < 1e-9), "{angle}");
            } else {
                assert_eq!(*b, root);
            }
            if b.depth > 0 {
                stack.push((*b, 2));
            }
        }
    }

    #[test]
    fn spheres_cap_every_joint() {
        let text = nff(3);
        let lines: Vec<&str> = text.lines().collect();
        let mut cones = 0;
        for (i, l) in lines.iter().enumerate() {
            if let Some(c) = l.strip_prefix("c ") {
                cones += 1;
                // The sphere after each cone sits on its apex with the apex radius.
                let s = lines[i + 1].strip_prefix("s ").expect("sphere after cone");
                let apex: Vec<&str> = c.split(' ').skip(4).collect();
                assert_eq!(apex, s.split(' ').collect::<Vec<_>>());
            }
        }
        assert_eq!(cones, 15);
    }

    #[test]
    fn output_parses_with_the_expected_counts() {
        let text = nff(3);
        let scene = crate::load::nff::parse_str(&text, Path::new("x")).unwrap();
        assert_eq!(scene.geometry.cones().len(), 15);
        assert_eq!(scene.geometry.spheres().len(), 15);
        assert_eq!(scene.load_stats.polygons, 1);
        assert_eq!(scene.geometry.triangles.len(), 2);
        assert_eq!(scene.lights.len(), 7);
    }
}
