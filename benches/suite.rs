//! The SPD scenes under criterion: acceleration-structure build time per scene and
//! backend, the cost of turning a hit into a shading point (`Scene::surface`, per hit),
//! and a small whole render per backend (per ray, shading included). Single-ray
//! intersection per primitive kind is in `benches/intersect.rs`. Run with
//! `cargo bench --bench suite`; `emray bench` is the suite-level measurement.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use emray::Scene;
use emray::accel::bvh::Bvh;
use emray::accel::{Accel, Hit};
use emray::job::load_scene;
use emray::math::Ray;
use emray::render::{RayGen, RenderSettings};
use std::hint::black_box;

const SCENES: [&str; 6] = [
    "spd:balls",
    "spd:balls?size=5",
    "spd:gears",
    "spd:jacks",
    "spd:teapot",
    "spd:tree",
];

fn build(c: &mut Criterion) {
    let mut g = c.benchmark_group("build");
    g.sample_size(10);
    for name in SCENES {
        let scene = load_scene(name).expect("suite scene");
        g.throughput(Throughput::Elements(
            scene.prim_count_with_instances() as u64
        ));
        g.bench_function(format!("bvh/{name}"), |b| {
            b.iter(|| Bvh::build(black_box(&scene)))
        });
        #[cfg(feature = "embree")]
        g.bench_function(format!("embree/{name}"), |b| {
            b.iter(|| emray::accel::embree::EmbreeAccel::build(black_box(&scene)).expect("embree"))
        });
    }
    g.finish();
}

/// The eye rays of a `n × n` image of `scene` and the hits they make.
fn eye_hits<A: Accel>(scene: &Scene, accel: &A, n: u32) -> Vec<(Ray, Hit)> {
    let raygen = RayGen::new(&scene.camera, n, n);
    (0..n * n)
        .filter_map(|k| {
            let ray = raygen.ray((k % n) as f32 + 0.5, (k / n) as f32 + 0.5);
            accel.intersect(&ray).map(|h| (ray, h))
        })
        .collect()
}

fn shading(c: &mut Criterion) {
    let mut g = c.benchmark_group("surface_per_hit");
    for name in SCENES {
        let scene = load_scene(name).expect("suite scene");
        let hits = eye_hits(&scene, &Bvh::build(&scene), 128);
        g.throughput(Throughput::Elements(hits.len() as u64));
        g.bench_function(name, |b| {
            b.iter(|| {
                hits.iter()
                    .map(|(ray, hit)| scene.surface(black_box(hit), ray).material)
                    .fold(0u32, u32::wrapping_add)
            })
        });
    }
    g.finish();
}

fn render_one<A: Accel>(c: &mut Criterion, backend: &str, name: &str, scene: &Scene, accel: &A) {
    let mut s = RenderSettings::for_scene(scene);
    s.width = 64;
    s.height = 64;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("pool");
    let rays = pool.install(|| emray::render::render(scene, accel, &s, None).1.rays.total());
    let mut g = c.benchmark_group(format!("render64/{backend}"));
    g.sample_size(10);
    g.throughput(Throughput::Elements(rays));
    g.bench_function(name, |b| {
        b.iter(|| pool.install(|| emray::render::render(scene, accel, &s, None)))
    });
    g.finish();
}

fn render(c: &mut Criterion) {
    for name in SCENES {
        let scene = load_scene(name).expect("suite scene");
        render_one(c, "bvh", name, &scene, &Bvh::build(&scene));
        #[cfg(feature = "embree")]
        render_one(
            c,
            "embree",
            name,
            &scene,
            &emray::accel::embree::EmbreeAccel::build(&scene).expect("embree"),
        );
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20).measurement_time(std::time::Duration::from_secs(2));
    targets = build, shading, render
}
criterion_main!(benches);
