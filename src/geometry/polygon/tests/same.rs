//! The triangulator gives exactly the triangles of the quadratic ear clipper it
//! replaced (`reference`), for simple polygons, degenerate ones and self-intersecting
//! ones alike: the images of existing scenes depend on them. The one difference is by
//! design: a convex polygon with straight vertices (on its edges) loses them before it
//! is cut, where the old clipper dropped them one by one as its walk met them.

use super::super::{PolygonError, Triangulator, convex};
use super::reference::Reference;
use super::shapes::*;
use crate::math::Vec3;
use proptest::prelude::*;

/// The two clippers' results for `points`.
fn both(points: &[Vec3]) -> [Result<Vec<[usize; 3]>, PolygonError>; 2] {
    let mut new = Vec::new();
    let mut old = Vec::new();
    let a = Triangulator::new()
        .triangulate(points, &mut new)
        .map(|()| new);
    let b = Reference::new().triangulate(points, &mut old).map(|()| old);
    [a, b]
}

/// Whether `points` is a convex polygon with straight vertices, which the two clippers
/// cut differently by design.
fn convex_with_straight(points: &[Vec3]) -> bool {
    let mut t = Triangulator::new();
    t.distinct(points);
    let n = t.idx.len();
    if n < 4 || t.project(points).is_err() || !convex::is_convex(&t.ring) {
        return false;
    }
    (0..n).any(|i| t.ring.corner((i + n - 1) % n, i, (i + 1) % n) <= 0.0)
}

fn assert_same(points: &[Vec3]) {
    assert!(!convex_with_straight(points));
    let [new, old] = both(points);
    assert_eq!(new, old, "{} vertices", points.len());
}

#[test]
fn the_test_shapes() {
    for p in [
        regular(5, 1.0),
        regular(144, 2.0),
        gear(36, 0.8, 1.0),
        gear(12, 0.5, 1.0),
        comb(20),
        spiral(6),
        exact_star(2000, 0.5),
        exact_star(600, 0.98),
        exact_spiky_star(12, 3),
        exact_comb(20, 1000),
        exact_spiral(4, 150),
        farey(12),
    ] {
        assert_same(&p);
        assert_same(&transform(&p));
        let mut r = p.clone();
        r.reverse();
        assert_same(&r);
    }
}

#[test]
fn a_regular_polygon_rounded_to_f32() {
    // The curvature of a circle of 20 000 vertices is below f32's resolution: rounding
    // makes about half the corners reflex.
    assert_same(&regular(20_000, 1.0));
}

/// A polygon on a small integer grid: collinear, repeated and crossing edges galore.
fn lattice_polygon(max: i32, len: std::ops::Range<usize>) -> impl Strategy<Value = Vec<Vec3>> {
    prop::collection::vec((0..max, 0..max), len).prop_map(|v| {
        v.into_iter()
            .map(|(x, y)| Vec3::new(x as f32, y as f32, 0.0))
            .collect()
    })
}

proptest! {
    #[test]
    fn small_lattice_polygons(p in lattice_polygon(6, 3..24)) {
        prop_assume!(!convex_with_straight(&p));
        let [new, old] = both(&p);
        prop_assert_eq!(new, old);
    }

    /// Long random polygons on a finer grid: many reflex vertices, so the index of
    /// blockers is rebuilt as the ring shrinks.
    #[test]
    fn long_lattice_polygons(p in lattice_polygon(64, 100..1200)) {
        prop_assume!(!convex_with_straight(&p));
        let [new, old] = both(&p);
        prop_assert_eq!(new, old);
    }

    /// Star-shaped polygons (a random radius at each of n equal angles, so simple), in
    /// a random plane, either way round.
    #[test]
    fn star_shaped(
        radii in prop::collection::vec(0.05f32..1.0, 3..400),
        rot in (-3.0f32..3.0, -3.0f32..3.0, -3.0f32..3.0),
        clockwise in any::<bool>(),
    ) {
        let n = radii.len();
        let q = glam::Quat::from_euler(glam::EulerRot::XYZ, rot.0, rot.1, rot.2);
        let mut p: Vec<Vec3> = radii
            .iter()
            .enumerate()
            .map(|(i, &r)| {
                let a = std::f32::consts::TAU * i as f32 / n as f32;
                q * Vec3::new(r * a.cos(), r * a.sin(), 0.0)
            })
            .collect();
        if clockwise {
            p.reverse();
        }
        let [new, old] = both(&p);
        prop_assert_eq!(new, old);
    }
}
