//! Single-ray throughput per primitive kind and backend: the same random rays into the
//! same scene of 10 000 primitives of one kind, on the BVH and (with the `embree`
//! feature) on Embree. Run with `cargo bench --bench intersect`.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use emray::accel::Accel;
use emray::accel::bvh::Bvh;
use emray::geometry::{
    AaBox, CappedCone, Cone, Csg, CsgOp, CsgTree, Kind, OBox, Plane, Polyhedron, Quadric, Shape,
    Sphere, Torus, Triangle,
};
use emray::math::{Ray, Rng, Vec3};
use emray::scene::{Camera, Material, Scene};
use glam::Quat;
use std::hint::black_box;
use std::sync::Arc;

/// The draws the scenes and rays are made of.
trait Draws {
    /// Uniform in `[0, 1)`.
    fn f(&mut self) -> f32;
    /// A point uniform in the cube of edge `s` about the origin.
    fn v(&mut self, s: f32) -> Vec3;
}

impl Draws for Rng {
    fn f(&mut self) -> f32 {
        self.next_f32()
    }
    fn v(&mut self, s: f32) -> Vec3 {
        self.vec3_in(-0.5 * s, 0.5 * s)
    }
}

fn scene(kind: Kind, n: usize) -> Scene {
    let cam = Camera {
        from: Vec3::Z * 30.0,
        at: Vec3::ZERO,
        up: Vec3::Y,
        angle_deg: 40.0,
        hither: 1.0,
        width: 64,
        height: 64,
    };
    let mut s = Scene::new(cam);
    s.materials.push(Material::default());
    let mut r = Rng::new(42);
    for _ in 0..n {
        let c = r.v(20.0);
        match kind {
            Kind::Triangle => {
                s.geometry.triangles.push(
                    Triangle {
                        p: [c + r.v(0.6), c + r.v(0.6), c + r.v(0.6)],
                    },
                    0,
                );
                s.geometry.triangle_normals.push(u32::MAX);
            }
            Kind::Sphere => s.geometry.push(Sphere::new(c, 0.1 + 0.2 * r.f()), 0),
            Kind::Cone => s
                .geometry
                .push(Cone::new(c, 0.2 * r.f(), c + r.v(1.0), 0.2 * r.f()), 0),
            Kind::Csg => {
                // A lens: the intersection of two overlapping spheres.
                let (d, rad) = (r.v(0.3), 0.1 + 0.2 * r.f());
                let lens = CsgTree::op(
                    CsgOp::Intersection,
                    CsgTree::leaf(Shape::Sphere(Sphere::new(c + d, rad))),
                    CsgTree::leaf(Shape::Sphere(Sphere::new(c - d, rad))),
                );
                let csg = Csg::new(&lens).expect("valid CSG");
                s.geometry.add_shape(Shape::Csg(Arc::new(csg)), 0);
            }
            other => {
                let size = 0.1 + 0.2 * r.f();
                let axis = r.v(1.0) + Vec3::splat(0.01);
                let shape = match other {
                    Kind::Quadric => Shape::Quadric(Arc::new(
                        Quadric::ellipsoid(c, Vec3::new(size, size * 0.6, size * 1.3)).unwrap(),
                    )),
                    Kind::CappedCone => Shape::CappedCone(Arc::new(
                        CappedCone::new(c, axis, size * 3.0, size, size * 0.5).unwrap(),
                    )),
                    Kind::Box => Shape::Box(AaBox::new(c, c + r.v(0.6).abs() + 0.05).unwrap()),
                    Kind::OBox => Shape::OBox(Arc::new(
                        OBox::new(
                            c,
                            Vec3::splat(size),
                            Quat::from_axis_angle(axis.normalize(), 0.7),
                        )
                        .unwrap(),
                    )),
                    Kind::Polyhedron => Shape::Polyhedron(Arc::new(
                        Polyhedron::preset("dodecahedron", c, size * 1.5).unwrap(),
                    )),
                    Kind::Torus => Shape::Torus(Arc::new(
                        Torus::new(c, axis, size * 1.5, size * 0.5).unwrap(),
                    )),
                    // Unbounded: one plane per scene is plenty.
                    _ => Shape::Plane(Plane::new(Vec3::Y, -25.0 - 0.01 * r.f()).unwrap()),
                };
                s.geometry.add_shape(shape, 0);
            }
        }
    }
    s
}

fn rays(n: usize) -> Vec<Ray> {
    let mut r = Rng::new(7);
    (0..n)
        .map(|_| {
            let org = r.v(60.0);
            Ray::new(org, (r.v(20.0) - org).normalize())
        })
        .collect()
}

fn run<A: Accel>(c: &mut Criterion, name: &str, accel: &A, rays: &[Ray]) {
    let mut g = c.benchmark_group(name);
    g.throughput(Throughput::Elements(rays.len() as u64));
    g.bench_function("intersect", |b| {
        b.iter(|| {
            rays.iter()
                .filter(|r| accel.intersect(black_box(r)).is_some())
                .count()
        })
    });
    g.bench_function("occluded", |b| {
        b.iter(|| rays.iter().filter(|r| accel.occluded(black_box(r))).count())
    });
    g.finish();
}

fn bench(c: &mut Criterion) {
    let rays = rays(10_000);
    for kind in Kind::ALL {
        // Planes are unbounded: tested against every ray outside the hierarchy, so
        // one is the meaningful case.
        let n = if kind == Kind::Plane { 1 } else { 10_000 };
        let s = scene(kind, n);
        run(c, &format!("bvh/{}", kind.name()), &Bvh::build(&s), &rays);
        #[cfg(feature = "embree")]
        run(
            c,
            &format!("embree/{}", kind.name()),
            &emray::accel::embree::EmbreeAccel::build(&s).expect("embree"),
            &rays,
        );
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20).measurement_time(std::time::Duration::from_secs(2));
    targets = bench
}
criterion_main!(benches);
