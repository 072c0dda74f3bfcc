//! Instancing and CSG, end to end on both backends: an instanced object renders like
//! the same object pre-transformed (non-uniform scale included), CSG's span lists
//! classify points like the set expression, and the set identities hold on rendered
//! hit masks.

use emray::Scene;
use emray::accel::Backend;
use emray::geometry::{Csg, CsgOp, CsgTree, Kind, Primitive, Shape, Sphere, Triangle};
use emray::job::render_scene;
use emray::math::{Ray, Rng, Vec3, Xform};
use emray::output::differing_pixels;
use emray::render::{Film, RenderSettings};
use emray::scene::{Camera, Geometry, Instance, Light, Material};
use glam::{Affine3A, Quat};
use std::sync::Arc;

mod common;
use common::backends;

fn base_scene(res: u32) -> Scene {
    let mut s = Scene::new(Camera {
        from: Vec3::new(0.0, 1.0, 9.0),
        at: Vec3::ZERO,
        up: Vec3::Y,
        angle_deg: 40.0,
        hither: 0.1,
        width: res,
        height: res,
    });
    s.background = Vec3::new(0.1, 0.2, 0.3);
    s.lights
        .push(Light::point(Vec3::new(4.0, 6.0, 8.0), Vec3::ONE));
    s.materials.push(Material {
        color: Vec3::new(0.9, 0.6, 0.3),
        kd: 0.8,
        ks: 0.3,
        shine: 20.0,
        ..Default::default()
    });
    s
}

fn render(s: &Scene, b: Backend) -> Film {
    let settings = RenderSettings::for_scene(s);
    render_scene("test", s, b, &settings, 0.0, None)
        .unwrap_or_else(|e| panic!("{e}"))
        .0
}

/// A UV sphere of triangles (flat shaded), radius 1 at the origin.
fn tessellated_sphere(g: &mut Geometry, xf: Option<&Xform>, material: u32) {
    let (nu, nv) = (32, 16);
    let p = |i: u32, j: u32| {
        let phi = i as f32 / nu as f32 * std::f32::consts::TAU;
        let th = j as f32 / nv as f32 * std::f32::consts::PI;
        let v = Vec3::new(th.sin() * phi.cos(), th.cos(), th.sin() * phi.sin());
        match xf {
            Some(x) => x.to_world.transform_point3(v),
            None => v,
        }
    };
    for i in 0..nu {
        for j in 0..nv {
            let (a, b, c, d) = (p(i, j), p(i + 1, j), p(i + 1, j + 1), p(i, j + 1));
            if j > 0 {
                g.add_triangle(Triangle { p: [a, b, c] }, material);
            }
            if j + 1 < nv {
                g.add_triangle(Triangle { p: [a, c, d] }, material);
            }
        }
    }
}

fn skew() -> Xform {
    Xform::new(Affine3A::from_scale_rotation_translation(
        Vec3::new(2.2, 0.7, 1.3),
        Quat::from_rotation_z(0.5) * Quat::from_rotation_y(0.8),
        Vec3::new(0.3, -0.2, 0.5),
    ))
    .unwrap()
}

#[test]
fn instanced_mesh_renders_like_the_pre_transformed_mesh() {
    let xf = skew();
    let mut baked = base_scene(160);
    tessellated_sphere(&mut baked.geometry, Some(&xf), 0);
    let mut inst = base_scene(160);
    let mut object = Geometry::default();
    tessellated_sphere(&mut object, None, emray::scene::INHERIT);
    inst.objects.push(object);
    inst.instances.push(Instance {
        object: 0,
        xform: xf,
        material: 0,
    });
    for b in backends() {
        let a = render(&baked, b);
        let c = render(&inst, b);
        let diff = differing_pixels(&a, &c);
        let covered = a.pixels.iter().filter(|p| **p != baked.background).count();
        assert!(covered > 2000, "{b:?}: the object fills part of the view");
        assert!(
            diff * 1000 <= a.pixels.len(),
            "{b:?}: {diff} of {} pixels differ",
            a.pixels.len()
        );
    }
}

#[test]
fn instanced_sphere_equals_the_transformed_sphere() {
    // Uniform scale, rotation and translation map a sphere to a sphere.
    let xf = Xform::new(Affine3A::from_scale_rotation_translation(
        Vec3::splat(1.7),
        Quat::from_rotation_x(1.1),
        Vec3::new(-0.5, 0.4, 0.2),
    ))
    .unwrap();
    let mut direct = base_scene(160);
    direct.geometry.add_shape(
        Shape::Sphere(Sphere::new(Vec3::new(-0.5, 0.4, 0.2), 1.7)),
        0,
    );
    let mut inst = base_scene(160);
    let mut object = Geometry::default();
    object.add_shape(Shape::Sphere(Sphere::new(Vec3::ZERO, 1.0)), 0);
    inst.objects.push(object);
    inst.instances.push(Instance {
        object: 0,
        xform: xf,
        material: 0,
    });
    for b in backends() {
        let diff = differing_pixels(&render(&direct, b), &render(&inst, b));
        assert!(diff * 1000 <= 160 * 160, "{b:?}: {diff} pixels differ");
    }
}

#[test]
fn many_instances_of_one_object_agree_across_backends() {
    let mut s = base_scene(120);
    let mut object = Geometry::default();
    tessellated_sphere(&mut object, None, emray::scene::INHERIT);
    object.add_shape(Shape::Sphere(Sphere::new(Vec3::new(0.0, 1.3, 0.0), 0.4)), 0);
    s.objects.push(object);
    s.materials.push(Material {
        color: Vec3::new(0.2, 0.7, 0.3),
        ..Default::default()
    });
    for i in 0..12 {
        let a = i as f32 / 12.0 * std::f32::consts::TAU;
        s.instances.push(Instance {
            object: 0,
            xform: Xform::new(Affine3A::from_scale_rotation_translation(
                Vec3::new(0.5, 0.3 + 0.05 * i as f32, 0.5),
                Quat::from_rotation_y(a),
                Vec3::new(3.0 * a.cos(), 0.0, 3.0 * a.sin()),
            ))
            .unwrap(),
            material: (i % 2) as u32,
        });
    }
    assert_eq!(s.count_with_instances(Kind::Sphere), 12);
    let films: Vec<Film> = backends().into_iter().map(|b| render(&s, b)).collect();
    let covered = films[0]
        .pixels
        .iter()
        .filter(|p| **p != s.background)
        .count();
    assert!(covered > 1000);
    if films.len() == 2 {
        let diff = differing_pixels(&films[0], &films[1]);
        assert!(diff * 1000 <= 120 * 120, "{diff} pixels differ");
    }
}

fn sphere(c: Vec3, r: f32) -> CsgTree {
    CsgTree::leaf(Shape::Sphere(Sphere::new(c, r)))
}

fn csg(tree: &CsgTree) -> Arc<Csg> {
    Arc::new(Csg::new(tree).unwrap())
}

#[test]
fn spans_classify_points_like_the_set_expression() {
    // ((A ∪ B) − C) ∩ D, with a transformed operand; membership computed independently
    // from the spheres' equations.
    let (a, b, c, d) = (
        (Vec3::new(-0.5, 0.0, 0.0), 1.0f32),
        (Vec3::new(0.6, 0.1, 0.0), 0.9f32),
        (Vec3::new(0.0, 0.0, 0.6), 0.7f32),
        (Vec3::new(0.0, 0.3, 0.0), 1.4f32),
    );
    let shift = Xform::new(Affine3A::from_translation(Vec3::new(0.0, 0.0, 0.1))).unwrap();
    let tree = CsgTree::op(
        CsgOp::Intersection,
        CsgTree::op(
            CsgOp::Difference,
            CsgTree::op(CsgOp::Union, sphere(a.0, a.1), sphere(b.0, b.1)),
            CsgTree::Transform {
                xform: shift,
                child: Box::new(sphere(c.0 - Vec3::new(0.0, 0.0, 0.1), c.1)),
            },
        ),
        sphere(d.0, d.1),
    );
    let solid = csg(&tree);
    let inside = |p: Vec3, (c, r): (Vec3, f32)| (p - c).length() < r;
    let expr = |p: Vec3| (inside(p, a) || inside(p, b)) && !inside(p, c) && inside(p, d);
    let mut rng = Rng::new(11);
    let mut checked = 0;
    let mut inside_count = 0;
    for _ in 0..20000 {
        let p = rng.vec3_in(-2.0, 2.0);
        let dir = rng.vec3_in(-0.5, 0.5);
        if dir.length() < 0.1 {
            continue;
        }
        // Skip points within 1e-4 of a sphere's surface: classification there is a
        // matter of rounding.
        if [a, b, c, d]
            .iter()
            .any(|&(cc, r)| ((p - cc).length() - r).abs() < 1e-4)
        {
            continue;
        }
        let ray = Ray::new(p, dir);
        let bounds = solid.boundaries(&ray);
        // Inside iff t = 0 lies between an entry and its exit.
        let by_spans = bounds.chunks(2).any(|s| s[0].0 < 0.0 && s[1].0 > 0.0);
        let want = expr(p);
        assert_eq!(by_spans, want, "point {p:?} dir {dir:?}");
        assert_eq!(solid.contains(p), want, "contains at {p:?}");
        checked += 1;
        inside_count += want as usize;
    }
    assert!(
        checked > 15000 && inside_count > 500,
        "{checked} / {inside_count}"
    );
}

/// The hit mask of a one-object scene: which pixels see the object.
fn mask(shape: Shape, b: Backend) -> Vec<bool> {
    let mut s = base_scene(100);
    s.geometry.add_shape(shape, 0);
    let film = render(&s, b);
    film.pixels.iter().map(|p| *p != s.background).collect()
}

#[test]
fn set_identities_hold_on_rendered_masks() {
    let a = sphere(Vec3::new(-0.4, 0.0, 0.0), 1.2);
    let bb = sphere(Vec3::new(0.5, 0.2, 0.3), 1.0);
    for b in backends() {
        let empty = mask(
            Shape::Csg(csg(&CsgTree::op(CsgOp::Difference, a.clone(), a.clone()))),
            b,
        );
        assert!(empty.iter().all(|&m| !m), "{b:?}: A − A is empty");
        let plain = mask(Shape::Csg(csg(&a)), b);
        let union = mask(
            Shape::Csg(csg(&CsgTree::op(CsgOp::Union, a.clone(), a.clone()))),
            b,
        );
        assert!(plain.iter().filter(|&&m| m).count() > 1000);
        assert_eq!(plain, union, "{b:?}: A ∪ A = A");
        let ab = mask(
            Shape::Csg(csg(&CsgTree::op(
                CsgOp::Intersection,
                a.clone(),
                bb.clone(),
            ))),
            b,
        );
        let ba = mask(
            Shape::Csg(csg(&CsgTree::op(
                CsgOp::Intersection,
                bb.clone(),
                a.clone(),
            ))),
            b,
        );
        assert!(ab.iter().filter(|&&m| m).count() > 300);
        assert_eq!(ab, ba, "{b:?}: A ∩ B = B ∩ A");
        // A − B ∪ A ∩ B covers exactly A.
        let split = mask(
            Shape::Csg(csg(&CsgTree::op(
                CsgOp::Union,
                CsgTree::op(CsgOp::Difference, a.clone(), bb.clone()),
                CsgTree::op(CsgOp::Intersection, a.clone(), bb.clone()),
            ))),
            b,
        );
        let diff = plain.iter().zip(&split).filter(|(x, y)| x != y).count();
        assert!(
            diff <= 10,
            "{b:?}: (A − B) ∪ (A ∩ B) = A up to {diff} edge pixels"
        );
    }
}

#[test]
fn subtracted_surfaces_face_out_of_the_result() {
    // A sphere with a spherical bite: the ray into the bite meets the bite's surface,
    // whose normal must point out of the result (towards the ray).
    let tree = CsgTree::op(
        CsgOp::Difference,
        sphere(Vec3::ZERO, 1.0),
        sphere(Vec3::new(0.0, 0.0, 1.0), 0.5),
    );
    let solid = csg(&tree);
    use emray::geometry::Intersect;
    let ray = Ray::new(Vec3::new(0.0, 0.0, 5.0), -Vec3::Z);
    let h = solid.intersect(&ray).expect("hit");
    // The bite spans z ∈ [0.5, 1.5]: the result starts where the bite ends.
    assert!((h.t - 4.5).abs() < 1e-5, "t = {}", h.t);
    assert!(h.ng.dot(ray.dir) < 0.0, "normal faces the ray");
    let sp = solid.surface(&ray, &h);
    assert!((sp.p - Vec3::new(0.0, 0.0, 0.5)).length() < 1e-5);
    assert!((sp.ng - Vec3::Z).length() < 1e-5, "{:?}", sp.ng);
    // The exit is the big sphere's far side.
    let all = solid.boundaries(&ray);
    assert_eq!(all.len(), 2);
    assert!((all[1].0 - 6.0).abs() < 1e-5);
    // A CSG of an open surface is refused.
    let open = CsgTree::leaf(Shape::Cone(emray::geometry::Cone::new(
        Vec3::ZERO,
        1.0,
        Vec3::Y,
        1.0,
    )));
    assert!(
        Csg::new(&open)
            .unwrap_err()
            .to_string()
            .contains("not a closed solid")
    );
}

#[test]
fn refraction_through_a_csg_lens_agrees_across_backends() {
    // A biconvex lens (intersection of two spheres) in glass before a checker of
    // spheres: refraction through CSG must give the same image on both backends.
    let mut s = base_scene(120);
    s.materials.push(Material {
        color: Vec3::ONE,
        kd: 0.05,
        ks: 0.5,
        shine: 80.0,
        kr: 0.05,
        t: 0.9,
        ior: 1.5,
        ..Default::default()
    });
    let lens = CsgTree::op(
        CsgOp::Intersection,
        sphere(Vec3::new(0.0, 0.0, -1.5), 2.0),
        sphere(Vec3::new(0.0, 0.0, 1.5), 2.0),
    );
    s.geometry.add_shape(Shape::Csg(csg(&lens)), 1);
    for i in -3..=3 {
        for j in -3..=3 {
            s.geometry.add_shape(
                Shape::Sphere(Sphere::new(
                    Vec3::new(i as f32 * 0.8, j as f32 * 0.8, -4.0),
                    0.3,
                )),
                0,
            );
        }
    }
    let films: Vec<Film> = backends().into_iter().map(|b| render(&s, b)).collect();
    if films.len() == 2 {
        let diff = differing_pixels(&films[0], &films[1]);
        assert!(diff * 1000 <= 120 * 120, "{diff} pixels differ");
    }
    // The lens magnifies: the middle row of spheres seen through it covers more
    // pixels than without it.
    let mut bare = s.clone();
    bare.geometry = Default::default();
    for e in s.geometry.shapes().filter(|e| e.kind != Kind::Csg) {
        bare.geometry.add_shape(e.shape, e.material);
    }
    let through = render(&s, Backend::Bvh);
    let without = render(&bare, Backend::Bvh);
    assert_ne!(differing_pixels(&through, &without), 0);
}
