//! The triangulator's tests: what every triangulation must satisfy (this file), that
//! the triangles are those of the quadratic clipper it replaced (`same`), and that
//! large polygons cost linear work and are tiled exactly (`scale`), on the polygons of
//! `shapes`, checked in floating point here and exactly by `cover`.

mod cover;
mod reference;
mod same;
mod scale;
mod shapes;

use super::*;
use proptest::prelude::*;
use shapes::{comb, gear, regular, spiral, transform};
use std::f32::consts::TAU;

/// Everything a correct triangulation of a simple polygon satisfies: indices in
/// range, area preserved, no reversed triangle, every centroid inside.
fn check(points: &[Vec3], tris: &[[usize; 3]]) {
    let n = newell_normal(points);
    let area = 0.5 * n.length();
    let unit = n.normalize();
    let mut sum = 0.0;
    for t in tris {
        assert!(t.iter().all(|&i| i < points.len()), "{t:?} out of range");
        let [a, b, c] = t.map(|i| points[i].as_dvec3());
        let ng = (b - a).cross(c - a);
        assert!(ng.dot(unit) > 0.0, "triangle {t:?} reversed or flat");
        sum += 0.5 * ng.length();
        let centroid = (a + b + c) / 3.0;
        assert!(
            inside(points, unit, centroid),
            "centroid of {t:?} outside the polygon"
        );
    }
    assert!(
        ((sum - area) / area).abs() < 1e-5,
        "area {sum} vs polygon {area}"
    );
}

/// Even-odd point-in-polygon test in the plane of `normal`, using a 2-D basis of
/// the plane (independent of the triangulator's projection).
fn inside(points: &[Vec3], normal: DVec3, p: DVec3) -> bool {
    let e1 = normal.any_orthonormal_vector();
    let e2 = normal.cross(e1);
    let to2 = |q: DVec3| (q.dot(e1), q.dot(e2));
    let (px, py) = to2(p);
    let mut inside = false;
    for i in 0..points.len() {
        let (ax, ay) = to2(points[i].as_dvec3());
        let (bx, by) = to2(points[(i + 1) % points.len()].as_dvec3());
        if (ay > py) != (by > py) {
            let x = ax + (py - ay) / (by - ay) * (bx - ax);
            if px < x {
                inside = !inside;
            }
        }
    }
    inside
}

#[test]
fn triangle_and_fast_paths() {
    let t = [Vec3::ZERO, Vec3::X, Vec3::Y];
    assert_eq!(triangulate(&t).unwrap(), vec![[0, 1, 2]]);
    let quad = [Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y];
    let tris = triangulate(&quad).unwrap();
    assert_eq!(tris.len(), 2);
    check(&quad, &tris);
}

#[test]
fn convex_ngons() {
    for n in [5, 6, 12, 64, 144] {
        let p = regular(n, 2.0);
        let tris = triangulate(&p).unwrap();
        assert_eq!(tris.len(), n - 2, "n = {n}");
        check(&p, &tris);
    }
}

#[test]
fn l_shape() {
    let p: Vec<Vec3> = [(0., 0.), (2., 0.), (2., 1.), (1., 1.), (1., 2.), (0., 2.)]
        .iter()
        .map(|&(x, y)| Vec3::new(x, y, 0.0))
        .collect();
    let tris = triangulate(&p).unwrap();
    assert_eq!(tris.len(), 4);
    check(&p, &tris);
}

#[test]
fn concave_quad_is_not_fanned_from_its_reflex_vertex_wrongly() {
    // Dart: vertex 3 is reflex. A fan from 0 would emit (0,1,2) and (0,2,3), the
    // latter reversed and outside.
    let p = [
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(2.0, 1.0, 0.0),
        Vec3::new(0.0, 2.0, 0.0),
        Vec3::new(0.5, 1.0, 0.0),
    ];
    let tris = triangulate(&p).unwrap();
    assert_eq!(tris.len(), 2);
    check(&p, &tris);
}

#[test]
fn gear_and_star() {
    let g = gear(36, 0.8, 1.0); // 144 vertices, like the SPD gears' faces
    assert_eq!(g.len(), 144);
    let tris = triangulate(&g).unwrap();
    assert_eq!(tris.len(), 142);
    check(&g, &tris);

    let star: Vec<Vec3> = (0..200)
        .map(|i| {
            let a = TAU * i as f32 / 200.0;
            let r = if i % 2 == 0 { 1.0 } else { 0.3 };
            Vec3::new(r * a.cos(), r * a.sin(), 0.0)
        })
        .collect();
    let tris = triangulate(&star).unwrap();
    assert_eq!(tris.len(), 198);
    check(&star, &tris);
}

#[test]
fn comb_and_spiral() {
    for teeth in [2, 5, 20] {
        let p = comb(teeth);
        let tris = triangulate(&p).unwrap();
        // Cuts can leave collinear vertices behind, dropped without a triangle.
        assert!(tris.len() <= p.len() - 2);
        check(&p, &tris);
        let p = transform(&p);
        check(&p, &triangulate(&p).unwrap());
    }
    for turns in [1, 3, 6] {
        let p = spiral(turns);
        // A simple corridor: its area is its centre line's length.
        let legs = 4.0 * turns as f64;
        assert!((0.5 * newell_normal(&p).length() - legs * (legs + 1.0)).abs() < 1e-9);
        let tris = triangulate(&p).unwrap();
        check(&p, &tris);
        let mut r = p.clone();
        r.reverse();
        check(&r, &triangulate(&r).unwrap());
    }
}

#[test]
fn arbitrary_plane_and_clockwise() {
    let g = transform(&gear(12, 0.5, 1.0));
    let tris = triangulate(&g).unwrap();
    check(&g, &tris);

    // The same polygon clockwise: the normal flips and every triangle follows.
    let mut rev = g.clone();
    rev.reverse();
    let tris = triangulate(&rev).unwrap();
    check(&rev, &tris);
    let n = newell_normal(&g);
    for t in &tris {
        let [a, b, c] = t.map(|i| rev[i]);
        assert!(((b - a).cross(c - a)).as_dvec3().dot(n) < 0.0);
    }

    // Polygons whose normal is each axis, both ways round.
    let l: Vec<(f32, f32)> = vec![(0., 0.), (2., 0.), (2., 1.), (1., 1.), (1., 2.), (0., 2.)];
    for axis in 0..3 {
        for flip in [false, true] {
            let mut p: Vec<Vec3> = l
                .iter()
                .map(|&(x, y)| {
                    let mut v = [0.0; 3];
                    v[(axis + 1) % 3] = x;
                    v[(axis + 2) % 3] = y;
                    v[axis] = 5.0;
                    Vec3::from(v)
                })
                .collect();
            if flip {
                p.reverse();
            }
            let tris = triangulate(&p).unwrap();
            assert_eq!(tris.len(), 4);
            check(&p, &tris);
        }
    }
}

#[test]
fn collinear_vertices_are_dropped() {
    // A square with extra vertices along its edges: still 2 units of area, no
    // zero-area triangles.
    let p: Vec<Vec3> = [
        (0., 0.),
        (1., 0.),
        (2., 0.),
        (2., 1.),
        (2., 2.),
        (1., 2.),
        (0., 2.),
        (0., 1.),
    ]
    .iter()
    .map(|&(x, y)| Vec3::new(x, y, 0.0))
    .collect();
    let tris = triangulate(&p).unwrap();
    check(&p, &tris);
    for t in &tris {
        let [a, b, c] = t.map(|i| p[i]);
        assert!((b - a).cross(c - a).length() > 0.0);
    }
    assert!(tris.len() <= 6);
}

#[test]
fn a_convex_polygon_loses_its_straight_vertices() {
    // A square with a vertex in the middle of each side: two triangles over its
    // corners, as for the square alone.
    let p: Vec<Vec3> = [
        (0., 0.),
        (1., 0.),
        (2., 0.),
        (2., 1.),
        (2., 2.),
        (1., 2.),
        (0., 2.),
        (0., 1.),
    ]
    .iter()
    .map(|&(x, y)| Vec3::new(x, y, 0.0))
    .collect();
    let tris = triangulate(&p).unwrap();
    assert_eq!(tris.len(), 2);
    assert!(tris.iter().flatten().all(|&i| i % 2 == 0), "{tris:?}");
    check(&p, &tris);
    // A triangle with a vertex on one side: the triangle.
    let p = [Vec3::ZERO, Vec3::X, Vec3::new(2.0, 0.0, 0.0), Vec3::Y];
    assert_eq!(triangulate(&p).unwrap(), vec![[3, 0, 2]]);
}

#[test]
fn duplicates_removed() {
    let a = Vec3::ZERO;
    let b = Vec3::X;
    let c = Vec3::new(1.0, 1.0, 0.0);
    let d = Vec3::Y;
    // Repeated vertices and a closing copy of the first.
    let p = [a, a, b, b, b, c, d, d, a];
    let tris = triangulate(&p).unwrap();
    assert_eq!(tris.len(), 2);
    check(&p, &tris);
    // Indices point at the input, never at the dropped copies' positions wrongly.
    for t in &tris {
        let [x, y, z] = t.map(|i| p[i]);
        assert!(x != y && y != z && x != z);
    }
}

#[test]
fn degenerate_inputs() {
    assert_eq!(
        triangulate(&[]),
        Err(PolygonError::TooFewVertices { distinct: 0 })
    );
    assert_eq!(
        triangulate(&[Vec3::ONE, Vec3::ONE, Vec3::ONE]),
        Err(PolygonError::TooFewVertices { distinct: 1 })
    );
    assert_eq!(
        triangulate(&[Vec3::ZERO, Vec3::X, Vec3::X, Vec3::ZERO]),
        Err(PolygonError::TooFewVertices { distinct: 2 })
    );
    // Collinear: zero area.
    assert_eq!(
        triangulate(&[Vec3::ZERO, Vec3::X, Vec3::X * 2.0]),
        Err(PolygonError::ZeroArea)
    );
    assert_eq!(
        triangulate(&[Vec3::ZERO, Vec3::X, Vec3::X * 3.0, Vec3::X * 2.0]),
        Err(PolygonError::ZeroArea)
    );
    // Non-finite input never produces triangles.
    assert_eq!(
        triangulate(&[Vec3::ZERO, Vec3::X, Vec3::new(f32::NAN, 1.0, 0.0)]),
        Err(PolygonError::ZeroArea)
    );
}

#[test]
fn reuse_of_buffers() {
    let mut tr = Triangulator::new();
    let mut out = Vec::new();
    let big = gear(36, 0.8, 1.0);
    tr.triangulate(&big, &mut out).unwrap();
    assert_eq!(out.len(), 142);
    let small = [Vec3::ZERO, Vec3::X, Vec3::Y];
    tr.triangulate(&small, &mut out).unwrap();
    assert_eq!(out, vec![[0, 1, 2]]);
}

#[test]
fn self_intersecting_input_terminates() {
    // A bowtie-like pentagram: not simple. Only termination and winding are
    // promised.
    let p: Vec<Vec3> = (0..5)
        .map(|i| {
            let a = TAU * (2 * i) as f32 / 5.0;
            Vec3::new(a.cos(), a.sin(), 0.0)
        })
        .collect();
    if let Ok(tris) = triangulate(&p) {
        let n = newell_normal(&p);
        for t in &tris {
            let [a, b, c] = t.map(|i| p[i]);
            assert!((b - a).cross(c - a).as_dvec3().dot(n) > 0.0);
        }
    }
}

proptest! {
    /// Convex lattice polygons with vertices along their edges, started anywhere and
    /// either way round: their corners alone are cut, and tile them exactly.
    #[test]
    fn convex_with_straight_vertices(
        m in 1i64..6,
        k in 1usize..5,
        start in 0usize..1000,
        clockwise in any::<bool>(),
    ) {
        let corners = shapes::farey(m);
        let mut p = shapes::subdivided(&corners, k);
        let s = start % p.len();
        p.rotate_left(s);
        if clockwise {
            p.reverse();
        }
        let tris = triangulate(&p).unwrap();
        prop_assert_eq!(tris.len(), corners.len() - 2);
        cover::assert_tiles(&p, &tris);
    }

    /// Random star-shaped polygons (random radius at increasing angles, so always
    /// simple), in a random plane.
    #[test]
    fn random_star_shaped(
        radii in prop::collection::vec(0.05f32..1.0, 3..80),
        rot in (-3.0f32..3.0, -3.0f32..3.0, -3.0f32..3.0),
        clockwise in any::<bool>(),
    ) {
        let n = radii.len();
        let q = glam::Quat::from_euler(glam::EulerRot::XYZ, rot.0, rot.1, rot.2);
        let mut p: Vec<Vec3> = radii
            .iter()
            .enumerate()
            .map(|(i, &r)| {
                let a = TAU * i as f32 / n as f32;
                q * Vec3::new(r * a.cos(), r * a.sin(), 0.0)
            })
            .collect();
        if clockwise {
            p.reverse();
        }
        let tris = triangulate(&p).unwrap();
        prop_assert!(tris.len() <= n - 2);
        check(&p, &tris);
    }
}
