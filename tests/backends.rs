//! Embree and the pure-Rust BVH on the same random rays over a scene with every
//! primitive kind: the same hit or miss, the same primitive (ties excepted), and `t`
//! equal for the analytic shapes (both backends run the same intersector) and within
//! a stated relative bound for triangles (Embree's own test against the watertight one).
#![cfg(feature = "embree")]

use emray::accel::Accel;
use emray::accel::bvh::Bvh;
use emray::accel::embree::EmbreeAccel;
use emray::geometry::{Cone, Kind, Sphere, Triangle};
use emray::math::{Ray, Rng, Vec3};
use emray::scene::{Camera, Material, Scene};
use proptest::prelude::*;

/// Relative bound on the difference of triangle hit distances between the backends,
/// away from edges and grazing angles.
const TRI_REL: f32 = 1e-5;

fn scene(seed: u64) -> Scene {
    let mut s = Scene::new(Camera {
        from: Vec3::Z * 30.0,
        at: Vec3::ZERO,
        up: Vec3::Y,
        angle_deg: 40.0,
        hither: 1.0,
        width: 8,
        height: 8,
    });
    s.materials.push(Material::default());
    let mut rng = Rng::new(seed);
    // A point uniform in the cube of edge `s` about the origin.
    let v = |rng: &mut Rng, s: f32| rng.vec3_in(-0.5 * s, 0.5 * s);
    for i in 0..600 {
        let c = v(&mut rng, 20.0);
        match i % 3 {
            0 => {
                let p = [
                    c + v(&mut rng, 2.0),
                    c + v(&mut rng, 2.0),
                    c + v(&mut rng, 2.0),
                ];
                s.geometry.triangles.push(Triangle { p }, 0);
                s.geometry.triangle_normals.push(u32::MAX);
            }
            1 => {
                let r = rng.range(0.1, 1.1);
                let inside_only = rng.next_f32() < 0.2;
                s.geometry
                    .push(Sphere::new(c, if inside_only { -r } else { r }), 0);
            }
            _ => {
                let apex = c + v(&mut rng, 3.0);
                s.geometry.push(
                    Cone::new(c, rng.range(0.0, 0.6), apex, rng.range(0.0, 0.6)),
                    0,
                );
            }
        }
    }
    s
}

fn vec3() -> impl Strategy<Value = Vec3> {
    (-1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0).prop_map(|(x, y, z)| Vec3::new(x, y, z))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(20))]

    #[test]
    fn embree_and_bvh_agree_on_random_rays(seed in any::<u64>(), rays in prop::collection::vec((vec3(), vec3(), 0.0f32..1.0), 2000)) {
        let s = scene(seed);
        let bvh = Bvh::build(&s);
        let emb = EmbreeAccel::build(&s).unwrap();
        let mut hits = 0;
        for (o, target, cut) in rays {
            let org = o * 40.0;
            let mut ray = Ray::new(org, (target * 12.0 - org).normalize_or(Vec3::X));
            if cut < 0.2 {
                ray.tmax = cut * 200.0;
            }
            let a = bvh.intersect(&ray);
            let b = emb.intersect(&ray);
            // A triangle hit within 1e-4 of an edge, or at a grazing angle, is one the two
            // triangle tests may decide differently.
            let edgy = |h: &emray::Hit| {
                h.kind() == Kind::Triangle && {
                    let t = &s.geometry.triangles.items[h.prim_id as usize];
                    let w = 1.0 - h.u - h.v;
                    h.u.min(h.v).min(w) < 1e-4 || t.normal().normalize().dot(ray.dir).abs() < 1e-3
                }
            };
            match (a, b) {
                (Some(a), Some(b)) => {
                    hits += 1;
                    let same = (a.geom_id, a.prim_id) == (b.geom_id, b.prim_id);
                    let near = (a.t - b.t).abs() <= TRI_REL * a.t.max(b.t) + 1e-5;
                    if same && a.kind() != Kind::Triangle {
                        prop_assert_eq!(a.t, b.t, "same shape, same intersector");
                    } else if same {
                        prop_assert!(near, "triangle t {} vs {}", a.t, b.t);
                    } else {
                        // Different primitives: a tie, or the nearer one is an edge hit
                        // the other backend missed.
                        let nearer = if a.t < b.t { &a } else { &b };
                        prop_assert!(near || edgy(nearer), "bvh {a:?} vs embree {b:?}");
                    }
                }
                (None, None) => {}
                (a, b) => {
                    let h = a.or(b).unwrap();
                    prop_assert!(edgy(&h), "bvh {:?} vs embree {:?}", a, b);
                }
            }
            // Within each backend, any-hit agrees with closest-hit.
            prop_assert_eq!(bvh.occluded(&ray), a.is_some(), "bvh occluded");
            prop_assert_eq!(emb.occluded(&ray), b.is_some(), "embree occluded");
        }
        prop_assert!(hits > 200, "rays should hit often ({})", hits);
    }
}

/// Rays neither backend can trace (non-finite, or beyond Embree's accepted magnitude):
/// each `(origin, direction, tmin, tmax)`.
fn untraceable_rays() -> Vec<Ray> {
    let nan = f32::NAN;
    let inf = f32::INFINITY;
    let far = 2.226e26;
    let ok = Vec3::new(0.0, 0.0, 40.0);
    let down = Vec3::new(0.0, 0.0, -1.0);
    let mut rays = vec![
        Ray::new(Vec3::new(nan, 0.0, 40.0), down),
        Ray::new(ok, Vec3::new(0.0, nan, -1.0)),
        Ray::new(ok, Vec3::splat(nan)),
        Ray::new(Vec3::new(-1.0, -far, 0.5), Vec3::new(0.0, 1.0, 0.0)),
        Ray::new(ok, Vec3::new(0.0, 0.0, -far)),
        Ray::new(Vec3::new(inf, 0.0, 0.0), down),
        Ray::new(ok, Vec3::new(0.0, 0.0, -inf)),
    ];
    let mut nan_interval = Ray::new(ok, down);
    nan_interval.tmax = nan;
    rays.push(nan_interval);
    let mut nan_start = Ray::new(ok, down);
    nan_start.tmin = nan;
    rays.push(nan_start);
    rays
}

/// Every query of both backends, on a scene with triangles, spheres, cones, a plane
/// (tested outside the hierarchy) and an instance: a ray that cannot be traced hits
/// nothing and occludes nothing, alone and inside a packet of good rays, which keep
/// their hits.
#[test]
fn untraceable_rays_hit_nothing_on_both_backends() {
    use emray::geometry::{Plane, Shape};
    use emray::math::Xform;
    use emray::scene::Instance;
    let mut s = scene(7);
    s.geometry
        .add_shape(Shape::Plane(Plane::new(Vec3::Z, -30.0).unwrap()), 0);
    let mut object = emray::scene::Geometry::default();
    object.add_shape(Shape::Sphere(Sphere::new(Vec3::ZERO, 1.0)), 0);
    s.objects.push(object);
    s.instances.push(Instance {
        object: 0,
        xform: Xform::new(glam::Affine3A::from_translation(Vec3::new(0.0, 0.0, 25.0))).unwrap(),
        material: 0,
    });
    let good = Ray::new(Vec3::new(0.0, 0.0, 40.0), Vec3::new(0.0, 0.0, -1.0));
    let bvh = Bvh::build(&s);
    for width in [0, 4, 8, 16] {
        let emb = EmbreeAccel::build(&s).unwrap().with_packet_width(width);
        let backends: [(&str, &dyn Accel); 2] = [("bvh", &bvh), ("embree", &emb)];
        for (name, accel) in backends {
            let expected = accel.intersect(&good);
            assert!(expected.is_some(), "{name}: the good ray hits the instance");
            assert!(accel.occluded(&good), "{name}");
            for ray in untraceable_rays() {
                assert!(!ray.is_traceable(), "{ray:?}");
                assert_eq!(accel.intersect(&ray), None, "{name}: {ray:?}");
                assert!(!accel.occluded(&ray), "{name}: {ray:?}");
                let rays = vec![good, ray, good, ray, good];
                let mut hits = vec![None; rays.len()];
                accel.intersect_coherent(&rays, &mut hits);
                assert_eq!(hits[0], expected, "{name} width {width}");
                assert_eq!(hits[2], expected, "{name} width {width}");
                assert_eq!(hits[4], expected, "{name} width {width}");
                assert_eq!(hits[1], None, "{name} width {width}: {ray:?}");
                assert_eq!(hits[3], None, "{name} width {width}: {ray:?}");
            }
        }
    }
}

/// A floor 2·10⁶ units wide seen from one unit above it: every eye ray below the
/// horizon hits it on both backends (the BVH once lost 73% of them, its f32 distance
/// being within its own rounding error of zero), and the two pictures are the same in
/// 8 bits.
#[test]
fn a_huge_floor_seen_from_close_by_is_whole_on_both_backends() {
    for (x, z) in [(1e6, 1e6), (5e5, 5e5)] {
        let src = format!(
            "v\nfrom 0 1 0\nat 0 0 -3\nup 0 1 0\nangle 60\nhither 0.001\nresolution 200 150\n\
             b 0.2 0.3 0.8\nl 0 100 0\nf 0.8 0.8 0.8 1 0 0 0 1\n\
             p 4\n-{x} 0 -{z}\n-{x} 0 {z}\n{x} 0 {z}\n{x} 0 -{z}\n"
        );
        let scene = emray::load::nff::parse_str(&src, std::path::Path::new("floor.nff")).unwrap();
        let settings = emray::render::RenderSettings::for_scene(&scene);
        let render = |backend| {
            emray::job::render_scene("floor", &scene, backend, &settings, 0.0, None).unwrap()
        };
        let (bvh, bvh_report) = render(emray::Backend::Bvh);
        let (embree, embree_report) = render(emray::Backend::Embree);
        // The eye is 1 above the floor looking 18.4° down: the horizon lies 18.4° above
        // the view's centre (30° to the top row), and every ray of the 118 rows below
        // it meets the floor.
        let hits = bvh_report.rays["eye_hit"];
        assert_eq!(hits, 200 * 118, "{x}: eye hits on the BVH");
        assert_eq!(hits, embree_report.rays["eye_hit"], "{x}");
        // The same 8-bit picture (the floor's shading may differ in the last bits where
        // Embree's hit lies within rounding of the diagonal).
        assert_eq!(emray::output::differing_pixels(&bvh, &embree), 0, "{x}");
    }
}

/// Coincident primitives (the same spheres and cones defined four times over, each
/// time with another material): at equal distance the primitive defined first wins, on
/// both backends, for single rays and for Embree's packets, so both shade the first
/// copy's material.
#[test]
fn coincident_analytic_primitives_resolve_to_the_one_defined_first() {
    let mut s = Scene::new(Camera {
        from: Vec3::new(0.0, -12.0, 2.0),
        at: Vec3::ZERO,
        up: Vec3::Z,
        angle_deg: 50.0,
        hither: 0.0,
        width: 64,
        height: 48,
    });
    let mut rng = Rng::new(3);
    let shapes: Vec<(Sphere, Cone)> = (0..12)
        .map(|_| {
            let c = rng.vec3_in(-4.0, 4.0);
            let r = rng.range(0.3, 1.0);
            let cone = Cone::new(c + Vec3::Y, r * 0.5, c + Vec3::new(0.5, 2.0, 1.0), r * 0.3);
            (Sphere::new(c, r), cone)
        })
        .collect();
    for copy in 0..4u32 {
        s.materials.push(Material::default());
        for (sphere, cone) in &shapes {
            s.geometry.push(*sphere, copy);
            s.geometry.push(*cone, copy);
        }
    }
    let bvh = Bvh::build(&s);
    let embree = EmbreeAccel::build(&s).unwrap().with_packet_width(8);
    let raygen = emray::render::RayGen::new(&s.camera, 64, 48);
    let rays: Vec<Ray> = (0..48)
        .flat_map(|j| (0..64).map(move |i| (i, j)))
        .map(|(i, j)| raygen.ray(i as f32 + 0.5, j as f32 + 0.5))
        .collect();
    let mut packets = vec![None; rays.len()];
    embree.intersect_coherent(&rays, &mut packets);
    let mut hits = 0;
    for (ray, packet) in rays.iter().zip(&packets) {
        let b = bvh.intersect(ray);
        assert_eq!(b, embree.intersect(ray));
        assert_eq!(b, *packet);
        if let Some(h) = b {
            assert!(h.prim_id < 12, "{h:?}: not the first copy");
            hits += 1;
        }
    }
    assert!(hits > 300, "{hits} hits");
}
