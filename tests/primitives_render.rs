//! Every primitive kind rendered on both backends: each is visible where it should be,
//! the two backends agree on the image, and the infinite plane (kept outside both
//! hierarchies) shadows and reflects like any other primitive.

use emray::Scene;
use emray::accel::Backend;
use emray::geometry::{
    AaBox, CappedCone, Cone, Csg, CsgOp, CsgTree, Kind, OBox, Plane, Polyhedron, Quadric, Shape,
    Sphere, Torus,
};
use emray::job::render_scene;
use emray::math::{Aabb, Vec3};
use emray::output::differing_pixels;
use emray::render::{Film, RenderSettings};
use emray::scene::{Camera, Light, Material};
use glam::Quat;
use std::sync::Arc;

mod common;
use common::backends;

/// One of each analytic kind along the x axis, at x = -7.5 + 1.5 k.
fn shapes() -> Vec<Shape> {
    let at = |k: usize| Vec3::new(-7.5 + 1.5 * k as f32, 0.6, 0.0);
    let lens = CsgTree::op(
        CsgOp::Difference,
        CsgTree::leaf(Shape::Box(
            AaBox::new(at(10) - Vec3::splat(0.5), at(10) + Vec3::splat(0.5)).unwrap(),
        )),
        CsgTree::leaf(Shape::Sphere(Sphere::new(
            at(10) + Vec3::new(0.0, 0.5, 0.5),
            0.5,
        ))),
    );
    vec![
        Shape::Sphere(Sphere::new(at(0), 0.6)),
        Shape::Cone(Cone::new(
            at(1) - Vec3::Y * 0.6,
            0.6,
            at(1) + Vec3::Y * 0.6,
            0.1,
        )),
        Shape::Quadric(Arc::new(
            Quadric::ellipsoid(at(2), Vec3::new(0.4, 0.6, 0.3)).unwrap(),
        )),
        Shape::Quadric(Arc::new(
            Quadric::cylinder(at(3), Vec3::Y, 0.4)
                .unwrap()
                .with_clip(Aabb::from_points(
                    at(3) - Vec3::splat(0.6),
                    at(3) + Vec3::splat(0.6),
                ))
                .unwrap(),
        )),
        Shape::CappedCone(Arc::new(
            CappedCone::new(at(4) - Vec3::Y * 0.6, Vec3::Y, 1.2, 0.6, 0.3).unwrap(),
        )),
        Shape::Box(AaBox::new(at(5) - Vec3::splat(0.5), at(5) + Vec3::splat(0.5)).unwrap()),
        Shape::OBox(Arc::new(
            OBox::new(
                at(6),
                Vec3::splat(0.45),
                Quat::from_rotation_y(0.6) * Quat::from_rotation_x(0.4),
            )
            .unwrap(),
        )),
        Shape::Polyhedron(Arc::new(
            Polyhedron::preset("icosahedron", at(7), 0.65).unwrap(),
        )),
        Shape::Polyhedron(Arc::new(Polyhedron::prism(at(8), 5, 0.6, 1.0).unwrap())),
        Shape::Torus(Arc::new(
            Torus::new(at(9), Vec3::new(0.0, 1.0, 1.0), 0.45, 0.18).unwrap(),
        )),
        Shape::Csg(Arc::new(Csg::new(&lens).unwrap())),
    ]
}

fn scene(with: &[Shape], plane: bool) -> Scene {
    let mut s = Scene::new(Camera {
        from: Vec3::new(0.0, 3.0, 12.0),
        at: Vec3::new(0.0, 0.3, 0.0),
        up: Vec3::Y,
        angle_deg: 45.0,
        hither: 0.1,
        width: 320,
        height: 140,
    });
    s.background = Vec3::new(0.2, 0.3, 0.5);
    s.lights
        .push(Light::point(Vec3::new(-3.0, 8.0, 6.0), Vec3::splat(0.8)));
    s.materials.push(Material {
        color: Vec3::new(0.9, 0.5, 0.2),
        kd: 0.8,
        ks: 0.4,
        shine: 30.0,
        ..Default::default()
    });
    s.materials.push(Material {
        color: Vec3::splat(0.7),
        kd: 0.8,
        kr: 0.3,
        ..Default::default()
    });
    for shape in with {
        s.geometry.add_shape(shape.clone(), 0);
    }
    if plane {
        s.geometry
            .add_shape(Shape::Plane(Plane::new(Vec3::Y, -0.6).unwrap()), 1);
    }
    s
}

fn render(s: &Scene, b: Backend) -> Film {
    render_scene("test", s, b, &RenderSettings::for_scene(s), 0.0, None)
        .unwrap_or_else(|e| panic!("{e}"))
        .0
}

#[test]
fn every_kind_is_visible_on_every_backend() {
    for shape in shapes() {
        let s = scene(std::slice::from_ref(&shape), false);
        for b in backends() {
            let film = render(&s, b);
            let covered = film.pixels.iter().filter(|p| **p != s.background).count();
            assert!(
                covered > 100,
                "{b:?}: a {} covers {covered} pixels",
                shape.kind().singular()
            );
        }
    }
}

#[test]
fn backends_agree_on_all_kinds_with_a_reflecting_plane() {
    let all = shapes();
    let s = scene(&all, true);
    for k in [
        Kind::Quadric,
        Kind::Plane,
        Kind::Torus,
        Kind::Csg,
        Kind::Polyhedron,
    ] {
        assert!(s.count_with_instances(k) >= 1, "{k:?} present");
    }
    let films: Vec<Film> = backends().into_iter().map(|b| render(&s, b)).collect();
    // The plane fills the lower half and receives shadows: some floor pixels are
    // darker than the lit floor.
    let floor_row = &films[0].pixels[(130 * 320)..(131 * 320)];
    assert!(
        floor_row.iter().all(|p| *p != s.background),
        "the plane fills the bottom row"
    );
    if films.len() == 2 {
        let diff = differing_pixels(&films[0], &films[1]);
        assert!(
            diff * 1000 <= films[0].pixels.len(),
            "{diff} of {} pixels differ",
            films[0].pixels.len()
        );
    }
}

#[test]
fn the_plane_receives_shadows_and_light() {
    // A unit sphere resting on the plane, a light straight above it: the floor just
    // inside the shadow's rim gets ambient light only, the floor beyond it is lit.
    let mut s = scene(
        &[Shape::Sphere(Sphere::new(Vec3::new(0.0, 0.4, 0.0), 1.0))],
        true,
    );
    s.lights.clear();
    s.lights
        .push(Light::point(Vec3::new(0.0, 10.0, 0.0), Vec3::ONE));
    s.camera.from = Vec3::new(0.0, 3.0, 10.0);
    s.camera.width = 1;
    s.camera.height = 1;
    s.materials[1].kr = 0.0;
    let ambient = s.ambient * s.materials[1].color * s.materials[1].ka;
    // The shadow of a unit sphere 1.0 above the floor (centre at y = 0.4, floor at
    // y = -0.6) from a light 10.6 above the floor has a radius of about 1.11.
    for (target, shadowed) in [(0.9f32, true), (1.5, false), (4.0, false)] {
        s.camera.at = Vec3::new(0.0, -0.6, target);
        for b in backends() {
            let c = render(&s, b).pixels[0];
            if shadowed {
                assert!(
                    (c - ambient).abs().max_element() < 1e-4,
                    "{b:?} at {target}: {c:?}"
                );
            } else {
                assert!(c.x > ambient.x + 0.2, "{b:?} at {target}: lit, {c:?}");
            }
        }
    }
}
