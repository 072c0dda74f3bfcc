//! Behaviour of the Embree backend against the installed library (Embree 3.13 on
//! bookworm): ids, triangle parametrisation and normal, agreement with the shared
//! intersectors, intervals, occlusion, empty scenes, errors.

use super::*;
use crate::geometry::{Cone, Intersect, Kind, ShapeHit, Sphere, Triangle};
use crate::math::Vec3;
use crate::scene::{Camera, Material};

fn scene() -> Scene {
    let mut s = Scene::new(Camera {
        from: Vec3::ZERO,
        at: Vec3::Z,
        up: Vec3::Y,
        angle_deg: 45.0,
        hither: 0.0,
        width: 8,
        height: 8,
    });
    s.materials.push(Material::default());
    s
}

fn add_triangle(s: &mut Scene, p0: Vec3, p1: Vec3, p2: Vec3) {
    s.geometry.triangles.push(Triangle { p: [p0, p1, p2] }, 0);
    s.geometry.triangle_normals.push(u32::MAX);
}

fn build(s: &Scene) -> EmbreeAccel<'_> {
    EmbreeAccel::build(s).expect("Embree build")
}

fn ray(org: Vec3, dir: Vec3) -> Ray {
    Ray::new(org, dir)
}

/// Hit and shared-intersector result agree exactly (same t, u, v, ng bits).
fn assert_same(hit: Option<Hit>, reference: Option<ShapeHit>, kind: Kind, prim: u32, r: &Ray) {
    match (hit, reference) {
        (None, None) => {}
        (Some(h), Some(s)) => {
            assert_eq!(
                h.t.to_bits(),
                s.t.to_bits(),
                "t for {r:?}: {} vs {}",
                h.t,
                s.t
            );
            assert_eq!(h.u.to_bits(), s.u.to_bits(), "u for {r:?}");
            assert_eq!(h.v.to_bits(), s.v.to_bits(), "v for {r:?}");
            assert_eq!(
                h.ng.to_array().map(f32::to_bits),
                s.ng.to_array().map(f32::to_bits),
                "ng for {r:?}"
            );
            assert_eq!(h.geom_id, kind as u32);
            assert_eq!(h.prim_id, prim);
        }
        (h, s) => panic!("Embree {h:?} vs shared intersector {s:?} for {r:?}"),
    }
}

/// Directions from `org` over a grid covering a cone of half-angle ~`spread` around
/// `towards`.
fn fan(org: Vec3, towards: Vec3, spread: f32, n: i32) -> Vec<Ray> {
    let f = (towards - org).normalize();
    let frame = crate::math::Frame::from_z(f);
    let mut rays = Vec::new();
    for i in -n..=n {
        for j in -n..=n {
            let a = spread * i as f32 / n as f32;
            let b = spread * j as f32 / n as f32;
            rays.push(ray(org, f + frame.x * a + frame.y * b));
        }
    }
    rays
}

#[test]
fn one_triangle_hit_t_u_v_and_normal() {
    let mut s = scene();
    let (p0, p1, p2) = (
        Vec3::new(-1.0, -1.0, 5.0),
        Vec3::new(2.0, -1.0, 5.5),
        Vec3::new(-1.0, 2.5, 4.5),
    );
    add_triangle(&mut s, p0, p1, p2);
    let tri = s.geometry.triangles.items[0];
    let accel = build(&s);

    for (u, v) in [(0.2f32, 0.3f32), (0.6, 0.1), (0.05, 0.9), (0.33, 0.33)] {
        let target = p0 * (1.0 - u - v) + p1 * u + p2 * v;
        // From the front (origin) and from behind the triangle: both sides are hit.
        for org in [Vec3::ZERO, Vec3::new(0.3, -0.2, 9.0)] {
            let r = ray(org, target - org);
            let h = accel.intersect(&r).expect("hit inside the triangle");
            let reference = tri.intersect(&r).expect("reference hit");
            assert!((h.t - 1.0).abs() < 1e-5, "t = {}", h.t);
            assert!((h.t - reference.t).abs() < 1e-5);
            // p = (1-u-v) p0 + u p1 + v p2
            assert!(
                (h.u - u).abs() < 1e-5 && (h.v - v).abs() < 1e-5,
                "u,v = {},{} want {u},{v}",
                h.u,
                h.v
            );
            assert!((h.u - reference.u).abs() < 1e-5 && (h.v - reference.v).abs() < 1e-5);
            // Ng is (p1 - p0) x (p2 - p0): same direction (and length, up to rounding),
            // whichever side the ray comes from.
            let n = tri.normal();
            assert!(
                h.ng.dot(n) > 0.0,
                "Embree Ng {:?} opposes (p1-p0)x(p2-p0) = {n:?}",
                h.ng
            );
            assert!((h.ng.normalize() - n.normalize()).length() < 1e-5);
            assert!((h.ng.length() / n.length() - 1.0).abs() < 1e-4);
            assert_eq!((h.geom_id, h.prim_id), (Kind::Triangle as u32, 0));
            assert_eq!(h.kind(), Kind::Triangle);
        }
    }

    // Outside the triangle (u + v > 1, u < 0), and pointing away.
    for (u, v) in [(0.8f32, 0.5f32), (-0.1, 0.5), (0.5, -0.05)] {
        let target = p0 * (1.0 - u - v) + p1 * u + p2 * v;
        assert_eq!(
            accel.intersect(&ray(Vec3::ZERO, target)),
            None,
            "({u}, {v})"
        );
        assert!(!accel.occluded(&ray(Vec3::ZERO, target)));
    }
    assert_eq!(accel.intersect(&ray(Vec3::ZERO, -Vec3::Z)), None);
}

#[test]
fn sphere_hits_equal_the_shared_intersector() {
    let mut s = scene();
    let sphere = Sphere::new(Vec3::new(0.5, -0.25, 6.0), 1.5);
    s.geometry.push(sphere, 0);
    let accel = build(&s);
    let origins = [
        Vec3::ZERO,
        Vec3::new(3.0, 2.0, -1.0),
        Vec3::new(0.4, -0.2, 6.1),
    ]; // last: inside
    let mut hits = 0;
    for org in origins {
        for r in fan(org, sphere.center, 0.5, 12) {
            let h = accel.intersect(&r);
            hits += usize::from(h.is_some());
            assert_same(h, sphere.intersect(&r), Kind::Sphere, 0, &r);
            assert_eq!(accel.occluded(&r), sphere.occluded(&r), "{r:?}");
        }
    }
    assert!(hits > 100, "too few hits ({hits}) to mean anything");
}

#[test]
fn cone_hits_equal_the_shared_intersector() {
    let cones = [
        Cone::new(
            Vec3::new(0.0, -1.0, 6.0),
            1.0,
            Vec3::new(0.5, 1.5, 6.5),
            0.25,
        ), // cone
        Cone::new(
            Vec3::new(-1.0, 0.0, 5.0),
            0.5,
            Vec3::new(1.0, 0.2, 5.5),
            0.5,
        ), // cylinder
        Cone::new(
            Vec3::new(0.0, -1.0, 6.0),
            -1.0,
            Vec3::new(0.0, 1.0, 6.0),
            -1.0,
        ), // inside only
    ];
    for cone in cones {
        let mut s = scene();
        s.geometry.push(cone, 0);
        let accel = build(&s);
        let centre = (cone.base + cone.apex) * 0.5;
        let mut hits = 0;
        for org in [
            Vec3::ZERO,
            Vec3::new(-2.0, 3.0, 1.0),
            centre + Vec3::new(0.01, 0.02, 0.0),
        ] {
            for r in fan(org, centre, 0.6, 12) {
                let h = accel.intersect(&r);
                hits += usize::from(h.is_some());
                assert_same(h, cone.intersect(&r), Kind::Cone, 0, &r);
                assert_eq!(accel.occluded(&r), cone.occluded(&r), "{r:?}");
            }
        }
        assert!(hits > 50, "too few hits ({hits}) for {cone:?}");
    }
}

#[test]
fn ids_are_kind_and_index_with_several_prims_of_each_kind() {
    let mut s = scene();
    // Three of each kind side by side along x, all at depth ~10; prims are pushed in an
    // order that differs from their x order.
    let xs = [4.0f32, -4.0, 0.0];
    for &x in &xs {
        add_triangle(
            &mut s,
            Vec3::new(x - 0.5, 2.5, 10.0),
            Vec3::new(x + 0.5, 2.5, 10.0),
            Vec3::new(x, 3.5, 10.0),
        );
        s.geometry
            .push(Sphere::new(Vec3::new(x, 0.0, 10.0), 0.5), 0);
        s.geometry.push(
            Cone::new(Vec3::new(x, -3.5, 10.0), 0.5, Vec3::new(x, -2.5, 10.0), 0.5),
            0,
        );
    }
    let accel = build(&s);
    assert_eq!(accel.stats().prims, 9);
    for (i, &x) in xs.iter().enumerate() {
        let cases = [
            (Kind::Triangle, 2.8f32),
            (Kind::Sphere, 0.0),
            (Kind::Cone, -3.0),
        ];
        for (kind, y) in cases {
            let r = ray(Vec3::ZERO, Vec3::new(x, y, 10.0));
            let h = accel
                .intersect(&r)
                .unwrap_or_else(|| panic!("{kind:?} {i} missed"));
            assert_eq!(h.kind(), kind);
            assert_eq!(h.geom_id, kind as u32);
            assert_eq!(h.prim_id, i as u32, "{kind:?} at x = {x}");
            assert!(accel.occluded(&r));
        }
    }
}

#[test]
fn nearest_hit_across_kinds() {
    let mut s = scene();
    // Along +z: a triangle at z = 3, a sphere spanning z in [5, 7], a cone (cylinder
    // across the ray) at z = 9.
    add_triangle(
        &mut s,
        Vec3::new(-1.0, -1.0, 3.0),
        Vec3::new(1.0, -1.0, 3.0),
        Vec3::new(0.0, 1.0, 3.0),
    );
    s.geometry
        .push(Sphere::new(Vec3::new(0.0, 0.0, 6.0), 1.0), 0);
    s.geometry.push(
        Cone::new(
            Vec3::new(-2.0, 0.0, 9.0),
            0.5,
            Vec3::new(2.0, 0.0, 9.0),
            0.5,
        ),
        0,
    );
    let accel = build(&s);
    let at = |tmin: f32| {
        let mut r = ray(Vec3::ZERO, Vec3::Z);
        r.tmin = tmin;
        accel.intersect(&r).map(|h| (h.kind(), h.t))
    };
    for (tmin, kind, t) in [
        (0.0, Kind::Triangle, 3.0),
        (3.5, Kind::Sphere, 5.0),
        (5.5, Kind::Sphere, 7.0),
        (7.5, Kind::Cone, 8.5),
        (9.0, Kind::Cone, 9.5),
    ] {
        let (k, got) = at(tmin).unwrap_or_else(|| panic!("miss from tmin {tmin}"));
        assert_eq!(k, kind, "from tmin {tmin}");
        assert!((got - t).abs() < 1e-5, "t {got}, want {t}");
    }
    assert_eq!(at(9.6), None);
}

#[test]
fn occluded_true_and_false() {
    let mut s = scene();
    add_triangle(
        &mut s,
        Vec3::new(-1.0, -1.0, 3.0),
        Vec3::new(1.0, -1.0, 3.0),
        Vec3::new(0.0, 1.0, 3.0),
    );
    s.geometry
        .push(Sphere::new(Vec3::new(5.0, 0.0, 6.0), 1.0), 0);
    s.geometry.push(
        Cone::new(
            Vec3::new(-5.0, -1.0, 6.0),
            1.0,
            Vec3::new(-5.0, 1.0, 6.0),
            1.0,
        ),
        0,
    );
    let accel = build(&s);
    for target in [
        Vec3::new(0.0, 0.0, 3.0),
        Vec3::new(5.0, 0.0, 6.0),
        Vec3::new(-5.0, 0.0, 6.0),
    ] {
        let mut r = ray(Vec3::ZERO, target);
        assert!(accel.occluded(&r), "towards {target:?}");
        // A shadow ray that stops before the blocker is not occluded.
        r.tmax = 0.4;
        assert!(!accel.occluded(&r), "towards {target:?} with tmax 0.4");
        // Nor one that starts after it.
        r.tmin = 1.6;
        r.tmax = f32::INFINITY;
        assert!(!accel.occluded(&r), "towards {target:?} from tmin 1.6");
    }
    assert!(!accel.occluded(&ray(Vec3::ZERO, Vec3::Y)));
    assert!(!accel.occluded(&ray(Vec3::ZERO, -Vec3::Z)));
}

#[test]
fn tmin_and_tmax_are_honoured() {
    let mut s = scene();
    s.geometry
        .push(Sphere::new(Vec3::new(0.0, 0.0, 5.0), 1.0), 0);
    add_triangle(
        &mut s,
        Vec3::new(2.0, -1.0, 5.0),
        Vec3::new(4.0, -1.0, 5.0),
        Vec3::new(3.0, 1.0, 5.0),
    );
    let accel = build(&s);
    let sphere = s.geometry.spheres().items[0];
    let with = |dir: Vec3, tmin: f32, tmax: f32| Ray {
        org: Vec3::ZERO,
        dir,
        tmin,
        tmax,
    };
    // Sphere: front at t = 4, back at t = 6.
    for (tmin, tmax, want) in [
        (0.0, 3.0, None),
        (0.0, 3.999, None),
        (0.0, 5.0, Some(4.0)),
        (4.5, f32::INFINITY, Some(6.0)),
        (4.5, 5.5, None),
        (6.5, f32::INFINITY, None),
    ] {
        let r = with(Vec3::Z, tmin, tmax);
        let h = accel.intersect(&r);
        assert_eq!(h.is_some(), want.is_some(), "tmin {tmin} tmax {tmax}");
        if let (Some(h), Some(t)) = (h, want) {
            assert!((h.t - t).abs() < 1e-5, "t {}, want {t}", h.t);
        }
        assert_same(h, sphere.intersect(&r), Kind::Sphere, 0, &r);
        assert_eq!(accel.occluded(&r), want.is_some());
    }
    // Triangle at t = 1 along (3, 0, 5).
    let d = Vec3::new(3.0, 0.0, 5.0);
    assert!(accel.intersect(&with(d, 0.0, 1.001)).is_some());
    assert!(accel.intersect(&with(d, 0.0, 0.999)).is_none());
    assert!(accel.intersect(&with(d, 1.001, f32::INFINITY)).is_none());
    assert!(!accel.occluded(&with(d, 0.0, 0.999)));
    // An empty or invalid interval hits nothing.
    assert!(accel.intersect(&with(Vec3::Z, 5.0, 4.0)).is_none());
    assert!(!accel.occluded(&with(Vec3::Z, 0.0, f32::NAN)));
}

#[test]
fn empty_scene_misses_everything() {
    let s = scene();
    let accel = build(&s);
    for r in fan(Vec3::ZERO, Vec3::Z, 1.0, 3) {
        assert_eq!(accel.intersect(&r), None);
        assert!(!accel.occluded(&r));
    }
    let st = accel.stats();
    assert_eq!((st.backend, st.prims), ("embree", 0));
}

#[test]
fn inside_only_sphere_seen_from_outside_shows_its_far_side() {
    let mut s = scene();
    let sphere = Sphere::new(Vec3::new(0.0, 0.0, 5.0), -1.0);
    assert!(sphere.inside_only);
    s.geometry.push(sphere, 0);
    let accel = build(&s);
    let r = ray(Vec3::ZERO, Vec3::Z);
    let h = accel.intersect(&r).expect("far side");
    assert!((h.t - 6.0).abs() < 1e-5, "t = {}", h.t);
    // The normal is the outward one; the ray leaves through it.
    assert!(h.ng.dot(r.dir) > 0.0);
    assert_same(Some(h), sphere.intersect(&r), Kind::Sphere, 0, &r);
    let mut hits = 0;
    for r in fan(Vec3::ZERO, sphere.center, 0.3, 8) {
        let h = accel.intersect(&r);
        if let Some(h) = h {
            hits += 1;
            // Only the far side: where the ray leaves the sphere (outward normal along
            // the ray), never where it enters.
            assert!(h.ng.dot(r.dir) > 0.0, "near side hit for {r:?}");
        }
        assert_same(h, sphere.intersect(&r), Kind::Sphere, 0, &r);
    }
    assert!(hits > 50, "{hits} hits");
}

/// The stats name Embree and its version and count the memory the build allocated. The
/// build runs on a pool of 7 threads, which no other test uses, so that it has a
/// device of its own: Embree's memory monitor counts a device's allocations, and other
/// tests' scenes freed on a shared device during this build would hide this one's.
#[test]
fn stats_report_embree_and_its_version() {
    let mut s = scene();
    s.geometry
        .push(Sphere::new(Vec3::new(0.0, 0.0, 5.0), 1.0), 0);
    add_triangle(&mut s, Vec3::X, Vec3::Y, Vec3::Z);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(7)
        .build()
        .expect("a pool");
    let accel = pool.install(|| build(&s));
    let st = accel.stats();
    assert_eq!(st.backend, "embree");
    assert_eq!(st.prims, 2);
    let v = accel.version();
    assert!(v >= 30000, "version {v}");
    let dotted = format!("Embree {}.{}.{}", v / 10000, v / 100 % 100, v % 100);
    assert!(st.detail.starts_with(&dotted), "{} vs {dotted}", st.detail);
    #[cfg(embree3)]
    assert_eq!(v / 10000, 3);
    #[cfg(embree4)]
    assert_eq!(v / 10000, 4);
    assert!(st.bytes > 0, "memory monitor saw no allocation");
}

#[test]
fn queries_from_many_threads_agree() {
    fn assert_send_sync<T: Send + Sync>() {}
    assert_send_sync::<EmbreeAccel>();

    let mut s = scene();
    for i in 0..20 {
        let x = i as f32 - 10.0;
        s.geometry
            .push(Sphere::new(Vec3::new(x, 0.3 * x, 12.0), 0.6), 0);
        s.geometry.push(
            Cone::new(Vec3::new(x, -3.0, 14.0), 0.4, Vec3::new(x, 3.0, 14.0), 0.1),
            0,
        );
        add_triangle(
            &mut s,
            Vec3::new(x, -1.0, 16.0),
            Vec3::new(x + 1.0, -1.0, 16.0),
            Vec3::new(x, 1.0, 16.0),
        );
    }
    let accel = build(&s);
    let rays = fan(Vec3::ZERO, Vec3::Z, 0.9, 40);
    let serial: Vec<_> = rays
        .iter()
        .map(|r| (accel.intersect(r), accel.occluded(r)))
        .collect();
    assert!(serial.iter().filter(|h| h.0.is_some()).count() > 100);
    std::thread::scope(|scope| {
        for _ in 0..4 {
            scope.spawn(|| {
                for (r, want) in rays.iter().zip(&serial) {
                    assert_eq!((accel.intersect(r), accel.occluded(r)), *want);
                }
            });
        }
    });
}

#[test]
fn bad_device_configuration_is_an_error() {
    let e = device::Device::new("threads=1\0").unwrap_err();
    assert_eq!(e.code(), None);
    assert!(e.to_string().contains("NUL"), "{e}");
    // Embree 3.13 fails to create the device on an unparsable value (RTC_ERROR_UNKNOWN).
    let e = device::Device::new("threads=abc").unwrap_err();
    assert!(e.code().is_some_and(|c| c != 0), "{e}");
    assert!(
        e.to_string().contains("rtcNewDevice(\"threads=abc\")"),
        "{e}"
    );
    assert!(device::Device::new("threads=1").is_ok());
}

/// One device for the process's builds on pools of one size: two builds share it.
#[test]
fn builds_share_the_process_device() {
    let mut s = scene();
    add_triangle(&mut s, Vec3::ZERO, Vec3::X, Vec3::Y);
    s.geometry.push(Sphere::new(Vec3::Z * 3.0, 1.0), 0);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(3)
        .build()
        .unwrap();
    let (a, b) = pool.install(|| (build(&s), build(&s)));
    assert!(Arc::ptr_eq(&a.device, &b.device));
    assert!(a.stats().bytes > 0 && b.stats().bytes > 0);
    drop(a);
    assert_eq!(b.stats().prims, s.prim_count_with_instances());
}

#[test]
fn device_errors_carry_embree_code_and_message() {
    let device = device::Device::new("").expect("device");
    assert_eq!(device.check("nothing"), Ok(()));
    // SAFETY: a live device; an unknown geometry type makes Embree report an error and
    // return null (checked below), nothing else.
    let geometry = unsafe { sys::rtcNewGeometry(device.raw(), sys::RTCGeometryType(9999)) };
    assert!(geometry.is_null());
    let e = device.check("rtcNewGeometry(9999)").unwrap_err();
    // Embree 3.13 says RTC_ERROR_UNKNOWN, "invalid geometry type".
    assert!(e.code().is_some_and(|c| c != 0), "{e}");
    assert!(
        !e.message().is_empty(),
        "the error callback recorded no message: {e}"
    );
    let shown = e.to_string();
    assert!(
        shown.starts_with("Embree: rtcNewGeometry(9999) failed: RTC_ERROR_"),
        "{e}"
    );
    assert!(shown.ends_with(e.message()), "{e}");
    // Reported once: the next check is clean.
    assert_eq!(device.check("nothing"), Ok(()));
}

/// Rays from a few origins over everything in `s`, in a count that is no multiple of
/// any packet width, with some empty or NaN intervals and some starting late.
fn packet_rays() -> Vec<Ray> {
    let mut rays = Vec::new();
    for org in [
        Vec3::ZERO,
        Vec3::new(2.0, 1.5, -1.0),
        Vec3::new(-0.3, 0.2, 5.0),
    ] {
        rays.extend(fan(org, Vec3::new(0.0, 0.0, 6.0), 0.6, 9));
    }
    rays.truncate(rays.len() - 3);
    for (i, r) in rays.iter_mut().enumerate() {
        match i % 23 {
            5 => r.tmax = r.tmin,
            11 => r.tmax = f32::NAN,
            17 => r.tmin = 5.5,
            _ => {}
        }
    }
    rays
}

fn triangles_spheres_cones() -> Scene {
    let mut s = scene();
    for i in -3..3 {
        for j in -3..3 {
            let (x, y) = (i as f32, j as f32);
            let z = 8.0 + 0.2 * (x + y);
            add_triangle(
                &mut s,
                Vec3::new(x, y, z),
                Vec3::new(x + 1.0, y, z + 0.2),
                Vec3::new(x, y + 1.0, z + 0.2),
            );
        }
    }
    s.geometry
        .push(Sphere::new(Vec3::new(0.5, -0.25, 6.0), 1.2), 0);
    s.geometry
        .push(Sphere::new(Vec3::new(-1.5, 1.0, 5.0), 0.6), 0);
    s.geometry.push(
        Cone::new(
            Vec3::new(-2.0, -1.5, 5.0),
            0.4,
            Vec3::new(2.0, -1.5, 6.0),
            0.1,
        ),
        0,
    );
    s
}

/// Packets of 4, 8 and 16 rays find what single rays find: bit for bit on the user
/// geometry (the same Rust intersectors run per ray), and on triangles the same
/// triangle at the same distance.
#[test]
fn packets_find_what_single_rays_find() {
    let s = triangles_spheres_cones();
    let rays = packet_rays();
    let single: Vec<Option<Hit>> = {
        let accel = build(&s);
        rays.iter().map(|r| accel.intersect(r)).collect()
    };
    let kinds = |k: Kind| single.iter().flatten().filter(|h| h.kind() == k).count();
    assert!(kinds(Kind::Triangle) > 50 && kinds(Kind::Sphere) > 50 && kinds(Kind::Cone) > 10);
    for width in [0, 4, 8, 16] {
        let accel = build(&s).with_packet_width(width);
        let mut hits = vec![None; rays.len()];
        accel.intersect_coherent(&rays, &mut hits);
        for ((r, a), b) in rays.iter().zip(&single).zip(&hits) {
            match (a, b) {
                (Some(a), Some(b)) if a.kind() == Kind::Triangle => {
                    assert_eq!((a.geom_id, a.prim_id), (b.geom_id, b.prim_id), "{r:?}");
                    assert!((a.t - b.t).abs() <= 1e-5 * a.t, "width {width}: {r:?}");
                }
                _ => assert_eq!(a, b, "width {width}: {r:?}"),
            }
        }
    }
}

/// A compact scene (`RTC_SCENE_FLAG_COMPACT`) answers every query as the default one:
/// the same hits bit for bit on the user geometry, the same triangle at the same
/// distance (Embree 4's compact triangles round `u` and `v` otherwise; the renderer
/// recomputes a triangle hit's exactly anyway), the same shadow answers; its
/// description says so.
#[test]
fn a_compact_scene_answers_as_the_default_one() {
    let s = triangles_spheres_cones();
    let rays = packet_rays();
    let with = |compact| {
        let options = BackendOptions {
            embree_compact: Some(compact),
            ..BackendOptions::new(Backend::Embree)
        };
        EmbreeAccel::build_with(&s, &options).unwrap()
    };
    let (plain, compact) = (with(false), with(true));
    assert!(compact.stats().detail.contains(", compact"));
    assert!(!plain.stats().detail.contains("compact"));
    for r in &rays {
        match (plain.intersect(r), compact.intersect(r)) {
            (Some(a), Some(b)) if a.kind() == Kind::Triangle => {
                assert_eq!((a.geom_id, a.prim_id), (b.geom_id, b.prim_id), "{r:?}");
                assert!((a.t - b.t).abs() <= 1e-5 * a.t, "{r:?}");
                assert!(
                    (a.u - b.u).abs() <= 1e-5 && (a.v - b.v).abs() <= 1e-5,
                    "{r:?}"
                );
            }
            (a, b) => assert_eq!(a, b, "{r:?}"),
        }
        assert_eq!(plain.occluded(r), compact.occluded(r), "{r:?}");
    }
    assert!(!crate::accel::embree_compact_for(1 << 20));
    assert!(crate::accel::embree_compact_for(1 << 22));
}

/// Shadow rays in packets of 4, 8 and 16 are answered as one by one, with and without
/// an unbounded primitive (then cast one by one), rays with empty or NaN intervals
/// included.
#[test]
fn shadow_packets_answer_as_single_rays() {
    let mut with_plane = triangles_spheres_cones();
    let plane = crate::geometry::Plane::new(Vec3::new(0.0, 0.0, -1.0), -7.0).expect("plane");
    with_plane
        .geometry
        .add_shape(crate::geometry::Shape::Plane(plane), 0);
    let mut rays = packet_rays();
    // Shorter rays too, so that some are occluded and some are not.
    for r in rays.iter_mut().step_by(3) {
        r.tmax = r.tmax.min(5.2);
    }
    for s in [triangles_spheres_cones(), with_plane] {
        let single: Vec<bool> = {
            let accel = build(&s);
            rays.iter().map(|r| accel.occluded(r)).collect()
        };
        let occluded = single.iter().filter(|&&o| o).count();
        assert!(occluded > 50 && occluded + 20 < rays.len(), "{occluded}");
        for width in [0, 4, 8, 16] {
            let accel = build(&s).with_shadow_packet_width(width);
            let mut answers = vec![false; rays.len()];
            accel.occluded_batch(&rays, &mut answers);
            assert_eq!(answers, single, "width {width}");
        }
    }
}

/// With an unbounded primitive (tested outside Embree) the batch falls back to single
/// rays and still finds the plane and everything in front of it.
#[test]
fn packets_with_an_unbounded_plane_fall_back_to_single_rays() {
    let mut s = triangles_spheres_cones();
    let plane = crate::geometry::Plane::new(Vec3::new(0.0, 0.0, -1.0), -7.0).expect("plane");
    s.geometry
        .add_shape(crate::geometry::Shape::Plane(plane), 0);
    let accel = build(&s);
    let rays = packet_rays();
    let mut hits = vec![None; rays.len()];
    accel.intersect_coherent(&rays, &mut hits);
    let mut planes = 0;
    for (r, h) in rays.iter().zip(&hits) {
        assert_eq!(*h, accel.intersect(r), "{r:?}");
        planes += usize::from(h.is_some_and(|h| h.kind() == Kind::Plane));
    }
    assert!(planes > 10, "the plane was hit {planes} times");
}

/// A render whose eye rays go in packets is the render whose eye rays go one by one,
/// byte for byte, on a scene of analytic shapes.
#[test]
fn packet_width_does_not_change_a_render_of_spheres() {
    let nff = crate::spd::Database::Balls.generate(1);
    let s = crate::load::nff::parse_str(&nff, std::path::Path::new("balls.nff")).expect("balls");
    let mut settings = crate::render::RenderSettings::for_scene(&s);
    (settings.width, settings.height, settings.spd) = (48, 40, true);
    let images: Vec<Vec<f32>> = [0, 4, 8, 16]
        .iter()
        .map(|&w| {
            let accel = build(&s).with_packet_width(w);
            let (film, stats) = crate::render::render(&s, &accel, &settings, None);
            assert_eq!(stats.rays.eye, 49 * 41);
            film.pixels.iter().flat_map(|p| p.to_array()).collect()
        })
        .collect();
    for img in &images[1..] {
        assert!(
            img.iter()
                .zip(&images[0])
                .all(|(a, b)| a.to_bits() == b.to_bits())
        );
    }
}

/// The text of a caught panic.
fn panic_text(payload: Box<dyn std::any::Any + Send>) -> String {
    match payload.downcast::<String>() {
        Ok(s) => *s,
        Err(payload) => payload
            .downcast_ref::<&str>()
            .map_or_else(|| "(no message)".into(), |s| s.to_string()),
    }
}

#[test]
fn a_panic_in_a_callback_comes_back_after_the_query_instead_of_aborting() {
    use super::user::{Callback, inject};
    use std::panic::{AssertUnwindSafe, catch_unwind};
    let mut s = scene();
    s.geometry
        .push(Sphere::new(Vec3::new(0.0, 0.0, 5.0), 1.0), 0);
    let accel = build(&s).with_packet_width(8);
    let r = ray(Vec3::ZERO, Vec3::Z);
    let rays = vec![r; 8];
    let mut hits = vec![None; 8];
    let cases: [(Callback, &str, &dyn Fn()); 3] = [
        (Callback::Intersect, "intersect", &|| {
            accel.intersect(&r);
        }),
        (Callback::Occluded, "occluded", &|| {
            accel.occluded(&r);
        }),
        (Callback::Intersect, "intersect", &|| {
            accel.intersect_coherent(&rays, &mut vec![None; 8]);
        }),
    ];
    for (callback, name, query) in cases {
        inject::panic_next(callback);
        let caught = catch_unwind(AssertUnwindSafe(query)).expect_err("the query panics");
        assert_eq!(
            panic_text(caught),
            format!("the Embree {name} callback of the spheres panicked: injected panic")
        );
        // Nothing is left over: the next queries on this thread are as usual.
        assert_eq!(accel.intersect(&r).map(|h| h.t), Some(4.0));
        assert!(accel.occluded(&r));
        accel.intersect_coherent(&rays, &mut hits);
        assert!(hits.iter().all(|h| h.is_some_and(|h| h.t == 4.0)));
    }
    // The bounds callback runs on Embree's build threads: its panic comes back from
    // the build.
    inject::panic_next(Callback::Bounds);
    let caught = catch_unwind(|| EmbreeAccel::build(&s)).expect_err("the build panics");
    assert_eq!(
        panic_text(caught),
        "the Embree bounds callback of the spheres panicked: injected panic"
    );
    assert!(build(&s).intersect(&r).is_some());
}

/// A kind whose list mixes bounded and unbounded primitives: Embree holds the bounded
/// ones under their own indices in the scene's list (the unbounded one between them
/// is tested outside Embree), and every hit names the primitive the BVH names.
#[test]
fn bounded_and_unbounded_of_one_kind_keep_their_prim_ids() {
    use crate::geometry::{Quadric, Shape};
    let ball = |c: Vec3, r: f64| {
        let (x, y, z) = (f64::from(c.x), f64::from(c.y), f64::from(c.z));
        let j = x * x + y * y + z * z - r * r;
        let coeffs = [
            1.0,
            1.0,
            1.0,
            0.0,
            0.0,
            0.0,
            -2.0 * x,
            -2.0 * y,
            -2.0 * z,
            j,
        ];
        Shape::Quadric(Quadric::new(coeffs, None).expect("ball").into())
    };
    // The cylinder x² + y² = 36 around the view, unbounded along z.
    let cylinder = [1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -36.0];
    let mut s = scene();
    s.geometry.add_shape(ball(Vec3::new(0.5, 0.0, 6.0), 1.0), 0);
    s.geometry.add_shape(
        Shape::Quadric(Quadric::new(cylinder, None).unwrap().into()),
        0,
    );
    s.geometry
        .add_shape(ball(Vec3::new(-1.0, 1.0, 5.0), 0.5), 0);
    let embree = build(&s);
    let bvh = crate::accel::bvh::Bvh::build(&s);
    let mut seen = [0; 3];
    for org in [Vec3::ZERO, Vec3::new(0.3, -0.2, 1.0)] {
        for r in fan(org, Vec3::new(0.0, 0.0, 6.0), 1.5, 15) {
            let (a, b) = (embree.intersect(&r), bvh.intersect(&r));
            assert_eq!(
                a.map(|h| (h.kind(), h.prim_id)),
                b.map(|h| (h.kind(), h.prim_id))
            );
            assert_eq!(embree.occluded(&r), bvh.occluded(&r), "{r:?}");
            if let Some(h) = a {
                seen[h.prim_id as usize] += 1;
            }
        }
    }
    assert!(seen.iter().all(|&n| n > 0), "every quadric hit: {seen:?}");
    assert!(embree.stats().bytes > 0);
}

/// A cloud of touching, overlapping and coincident spheres (an inside-only one among
/// them) and cones, in list order unrelated to space.
fn sphere_cloud() -> Scene {
    let mut s = triangles_spheres_cones();
    let mut seed = 12345u32;
    let mut next = || {
        seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        (seed >> 8) as f32 / (1u32 << 24) as f32
    };
    for i in 0..300 {
        let c = Vec3::new(next() * 6.0 - 3.0, next() * 6.0 - 3.0, 4.0 + next() * 4.0);
        let r = 0.05 + 0.3 * next();
        let signed = if i == 7 { -r } else { r };
        s.geometry.push(Sphere::new(c, signed), 0);
        if i % 50 == 0 {
            // The same sphere twice: ties go to the lower primitive id.
            s.geometry.push(Sphere::new(c, r), 0);
        }
        if i % 3 == 0 {
            let tip = c + Vec3::new(next() - 0.5, next() - 0.5, next() - 0.5);
            s.geometry.push(Cone::new(c, r * 0.5, tip, 0.02), 0);
        }
    }
    s
}

/// Analytic primitives in groups (`--embree-group`) give every query's answer as one
/// Embree primitive each, bit for bit (which primitive, its id, t, u, v, normal),
/// single rays, packets and shadow rays alike; and as the BVH.
#[test]
fn grouped_primitives_answer_as_one_by_one() {
    let s = sphere_cloud();
    let mut rays = packet_rays();
    for org in [Vec3::new(0.2, 0.1, 0.0), Vec3::new(0.0, 0.0, 6.0)] {
        rays.extend(fan(org, Vec3::new(0.1, -0.2, 6.5), 1.2, 31));
    }
    // A pool of 6 threads, which no other test uses, gives the builds a device of
    // their own, whose memory monitor counts only them.
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(6)
        .build()
        .expect("a pool");
    let with = |group| {
        let options = BackendOptions {
            embree_group: Some(group),
            ..BackendOptions::new(Backend::Embree)
        };
        pool.install(|| EmbreeAccel::build_with(&s, &options).unwrap())
    };
    let bvh = crate::accel::bvh::Bvh::build(&s);
    let one = with(1);
    assert!(!one.stats().detail.contains("groups"));
    let single: Vec<Option<Hit>> = rays.iter().map(|r| one.intersect(r)).collect();
    let spheres = single.iter().flatten().filter(|h| h.kind() == Kind::Sphere);
    let distinct: std::collections::HashSet<u32> = spheres.map(|h| h.prim_id).collect();
    assert!(distinct.len() > 100, "{} spheres hit", distinct.len());
    for group in [2, 3, 16] {
        let grouped = with(group);
        assert!(
            grouped
                .stats()
                .detail
                .contains(&format!("groups of at most {group}")),
            "{}",
            grouped.stats().detail
        );
        assert!(grouped.stats().bytes < one.stats().bytes, "group {group}");
        let mut packets = vec![None; rays.len()];
        grouped.intersect_coherent(&rays, &mut packets);
        let mut shadows = vec![false; rays.len()];
        grouped.occluded_batch(&rays, &mut shadows);
        for (i, r) in rays.iter().enumerate() {
            let hit = grouped.intersect(r);
            assert_eq!(hit, single[i], "group {group}: {r:?}");
            if hit.is_some_and(|h| h.kind() != Kind::Triangle) {
                assert_eq!(hit, bvh.intersect(r), "group {group}, BVH: {r:?}");
                assert_eq!(packets[i], hit, "group {group}, packets: {r:?}");
            }
            assert_eq!(grouped.occluded(r), one.occluded(r), "group {group}: {r:?}");
            assert_eq!(shadows[i], one.occluded(r), "group {group}, batch: {r:?}");
        }
    }
    // Large scenes rendered with few camera rays per primitive are grouped.
    assert_eq!(crate::accel::embree_group_for(1 << 20, 1 << 10), 1);
    assert!(crate::accel::embree_group_for(1 << 22, 1 << 18) > 1);
    assert!(crate::accel::embree_group_for(1 << 22, 1 << 20) > 1);
    assert_eq!(crate::accel::embree_group_for(1 << 22, 1 << 21), 1);
    assert_eq!(crate::accel::embree_group_for(1 << 22, 0), 1);
}
