//! Tests of the radiosity pass: form factors against analytic values, reciprocity and closure, energy
//! conservation against the geometric series, solver convergence and agreement, both
//! backends.

use crate::accel::bvh::Bvh;
use crate::geometry::Triangle;
use crate::math::Vec3;
use crate::radiosity::formfactor::{
    Sampling, element_form_factor, parallel_rectangles, perpendicular_rectangles, point_to_disk,
    point_to_polygon,
};
use crate::radiosity::hemicube::Hemicube;
use crate::radiosity::mesh::{Mesh, longest_edge};
use crate::radiosity::{self, FormFactorMethod, RadiositySettings, SolverKind, solver};
use crate::scene::{Camera, Material, Scene};

fn camera() -> Camera {
    Camera {
        from: Vec3::new(0.5, 0.5, 0.95),
        at: Vec3::new(0.5, 0.5, 0.0),
        up: Vec3::Y,
        angle_deg: 60.0,
        hither: 0.0,
        width: 16,
        height: 16,
    }
}

/// A quad `a b c d` (counterclockwise seen from its front) as two triangles.
fn quad(s: &mut Scene, q: [Vec3; 4], material: u32) {
    s.geometry.add_triangle(
        Triangle {
            p: [q[0], q[1], q[2]],
        },
        material,
    );
    s.geometry.add_triangle(
        Triangle {
            p: [q[0], q[2], q[3]],
        },
        material,
    );
}

/// The six inward-facing faces of the box `lo..hi`, all of `material` except the
/// ceiling (`y = hi`), which gets `ceiling`.
fn closed_box(s: &mut Scene, lo: Vec3, hi: Vec3, material: u32, ceiling: u32) {
    let v = |x: usize, y: usize, z: usize| {
        Vec3::new(
            if x == 0 { lo.x } else { hi.x },
            if y == 0 { lo.y } else { hi.y },
            if z == 0 { lo.z } else { hi.z },
        )
    };
    // Each face counterclockwise seen from inside.
    quad(
        s,
        [v(0, 0, 0), v(0, 0, 1), v(1, 0, 1), v(1, 0, 0)],
        material,
    ); // floor
    quad(s, [v(0, 1, 0), v(1, 1, 0), v(1, 1, 1), v(0, 1, 1)], ceiling); // ceiling
    quad(
        s,
        [v(0, 0, 0), v(1, 0, 0), v(1, 1, 0), v(0, 1, 0)],
        material,
    ); // back z=lo
    quad(
        s,
        [v(0, 0, 1), v(0, 1, 1), v(1, 1, 1), v(1, 0, 1)],
        material,
    ); // front z=hi
    quad(
        s,
        [v(0, 0, 0), v(0, 1, 0), v(0, 1, 1), v(0, 0, 1)],
        material,
    ); // left x=lo
    quad(
        s,
        [v(1, 0, 0), v(1, 0, 1), v(1, 1, 1), v(1, 1, 0)],
        material,
    ); // right x=hi
}

/// An outward-facing box (an occluder) `lo..hi`.
fn solid_box(s: &mut Scene, lo: Vec3, hi: Vec3, material: u32) {
    let mut inner = Scene::new(camera());
    closed_box(&mut inner, lo, hi, material, material);
    for t in &inner.geometry.triangles.items {
        s.geometry.add_triangle(
            Triangle {
                p: [t.p[0], t.p[2], t.p[1]],
            },
            material,
        );
    }
}

/// A unit box: reflectance `rho` everywhere, the ceiling also emitting 1.
fn white_box(rho: f32) -> Scene {
    let mut s = Scene::new(camera());
    s.materials.push(Material {
        color: Vec3::splat(rho),
        ..Material::DEFAULT
    });
    s.materials.push(Material {
        color: Vec3::splat(rho),
        emission: Vec3::ONE,
        ..Material::DEFAULT
    });
    closed_box(&mut s, Vec3::ZERO, Vec3::ONE, 0, 1);
    s
}

/// A box with a small emitter patch under the ceiling, coloured walls and an occluding
/// block: shadows, colour bleeding.
fn cornellish() -> Scene {
    let mut s = Scene::new(camera());
    s.ambient = Vec3::ZERO;
    let white = Vec3::splat(0.7);
    for color in [white, Vec3::new(0.7, 0.1, 0.1), Vec3::new(0.1, 0.6, 0.1)] {
        s.materials.push(Material {
            color,
            ..Material::DEFAULT
        });
    }
    s.materials.push(Material {
        color: white,
        emission: Vec3::splat(5.0),
        ..Material::DEFAULT
    });
    closed_box(&mut s, Vec3::ZERO, Vec3::ONE, 0, 0);
    // Recolour the side walls (triangles 8..12 are left and right).
    for k in 8..10 {
        s.geometry.triangles.material[k] = 1;
    }
    for k in 10..12 {
        s.geometry.triangles.material[k] = 2;
    }
    // The light, facing down, just under the ceiling.
    let y = 0.999;
    quad(
        &mut s,
        [
            Vec3::new(0.35, y, 0.35),
            Vec3::new(0.65, y, 0.35),
            Vec3::new(0.65, y, 0.65),
            Vec3::new(0.35, y, 0.65),
        ],
        3,
    );
    // Corners off the element grid's rational points: a visibility ray exactly through
    // an edge may be caught by the watertight BVH and missed by Embree's default
    // triangle test (such a ray joined two centroids for a block at x = 0.31).
    solid_box(
        &mut s,
        Vec3::new(0.3123, 0.1071, 0.3317),
        Vec3::new(0.6189, 0.4277, 0.5843),
        0,
    );
    s
}

#[test]
fn closed_box_rows_sum_to_one_and_energy_follows_the_series() {
    let rho = 0.5f32;
    let scene = white_box(rho);
    let accel = Bvh::build(&scene);
    let mesh = Mesh::build(&scene, 0.5).unwrap();
    // Diagonals of 1.41 halved twice: 16 elements per triangle.
    assert_eq!(mesh.elements.len(), 12 * 16);
    let s = Sampling::new(1, 0);
    for i in 0..mesh.elements.len() {
        let sum: f32 = solver::form_factor_row(&mesh, &accel, &s, i).iter().sum();
        assert!((sum - 1.0).abs() < 0.01, "row {i} sums to {sum}");
    }
    let settings = RadiositySettings {
        patch_size: Some(0.5),
        epsilon: 1e-5,
        ..Default::default()
    };
    let sol = radiosity::solve(&scene, &accel, &settings).unwrap();
    // Power leaving all surfaces: emitted × (1 + ρ + ρ² + …) = Φ/(1 − ρ).
    let total: f64 = sol
        .mesh
        .elements
        .iter()
        .zip(&sol.solve.radiosity)
        .map(|(e, b)| (b.x * e.area) as f64)
        .sum();
    let expect = 1.0 / (1.0 - rho as f64);
    assert!(
        ((total - expect) / expect).abs() < 0.01,
        "total power {total}, series {expect}"
    );
}

#[test]
fn form_factors_are_reciprocal_on_random_pairs() {
    let scene = cornellish();
    let accel = Bvh::build(&scene);
    let mesh = Mesh::build(&scene, 0.45).unwrap();
    let n = mesh.elements.len();
    let s = Sampling::new(3, 1);
    let mut rng = crate::math::Rng::new(0x1234_5678);
    let mut next = || rng.below(n as u32) as usize;
    let mut checked = 0;
    while checked < 40 {
        let (i, j) = (next(), next());
        let fij = element_form_factor(&mesh, &accel, &s, i, j);
        let fji = element_form_factor(&mesh, &accel, &s, j, i);
        if fij == 0.0 && fji == 0.0 {
            continue;
        }
        let (ai, aj) = (mesh.elements[i].area, mesh.elements[j].area);
        let (x, y) = (ai * fij, aj * fji);
        // Pairs that share an edge or a corner have a singular integrand: they get 3%.
        let touching = mesh.elements[i]
            .p
            .iter()
            .any(|p| mesh.elements[j].p.iter().any(|q| (*p - *q).length() < 1e-6));
        let tol = if touching { 0.03 } else { 0.01 };
        assert!(
            (x - y).abs() <= tol * x.max(y),
            "pair ({i}, {j}): A_i F_ij = {x}, A_j F_ji = {y}"
        );
        checked += 1;
    }
}

/// Form factor from the meshed rectangle made of triangles `from` to the one made of
/// `to`: the area-weighted mean over the source elements of their row sums.
fn rect_to_rect(scene: &Scene, patch: f32, level: u32) -> f64 {
    let accel = Bvh::build(scene);
    let mesh = Mesh::build(scene, patch).unwrap();
    let s = Sampling::new(level, 0);
    rows_to(&mesh, |i| solver::form_factor_row(&mesh, &accel, &s, i))
}

/// The same with the hemicube of resolution `res`.
fn rect_to_rect_hemicube(scene: &Scene, patch: f32, res: u32) -> f64 {
    let mesh = Mesh::build(scene, patch).unwrap();
    let h = Hemicube::new(res).unwrap();
    rows_to(&mesh, |i| h.row(&mesh, i))
}

/// Area-weighted mean over the elements of material 0 of their form factors to the
/// elements of material 1, with the rows from `row`.
fn rows_to(mesh: &Mesh, row: impl Fn(usize) -> Vec<f32>) -> f64 {
    let (mut num, mut den) = (0.0f64, 0.0f64);
    for (i, e) in mesh.elements.iter().enumerate() {
        if e.material != 0 {
            continue;
        }
        let row = row(i);
        let to: f64 = row
            .iter()
            .zip(&mesh.elements)
            .filter(|(_, e)| e.material == 1)
            .map(|(f, _)| *f as f64)
            .sum();
        num += to * e.area as f64;
        den += e.area as f64;
    }
    num / den
}

#[test]
fn parallel_and_perpendicular_rectangles_match_the_analytic_values() {
    // Parallel: a 1 × 2 rectangle facing another one 0.5 above it.
    let mut s = Scene::new(camera());
    s.materials = vec![Material::DEFAULT, Material::DEFAULT];
    let (a, b, c) = (1.0f32, 2.0f32, 0.5f32);
    quad(
        &mut s,
        [
            Vec3::ZERO,
            Vec3::new(a, 0.0, 0.0),
            Vec3::new(a, b, 0.0),
            Vec3::new(0.0, b, 0.0),
        ],
        0,
    );
    quad(
        &mut s,
        [
            Vec3::new(0.0, 0.0, c),
            Vec3::new(0.0, b, c),
            Vec3::new(a, b, c),
            Vec3::new(a, 0.0, c),
        ],
        1,
    );
    let f = rect_to_rect(&s, 0.26, 1);
    let expect = parallel_rectangles(a as f64, b as f64, c as f64);
    assert!(((f - expect) / expect).abs() < 0.01, "{f} vs {expect}");

    // Perpendicular: the l × w floor (z = 0, y in 0..w) to the l × h wall (y = 0).
    let mut s = Scene::new(camera());
    s.materials = vec![Material::DEFAULT, Material::DEFAULT];
    let (l, w, h) = (1.0f32, 1.0f32, 0.6f32);
    quad(
        &mut s,
        [
            Vec3::ZERO,
            Vec3::new(l, 0.0, 0.0),
            Vec3::new(l, w, 0.0),
            Vec3::new(0.0, w, 0.0),
        ],
        0,
    );
    quad(
        &mut s,
        [
            Vec3::ZERO,
            Vec3::new(0.0, 0.0, h),
            Vec3::new(l, 0.0, h),
            Vec3::new(l, 0.0, 0.0),
        ],
        1,
    );
    let f = rect_to_rect(&s, 0.26, 2);
    let expect = perpendicular_rectangles(l as f64, w as f64, h as f64);
    assert!(((f - expect) / expect).abs() < 0.02, "{f} vs {expect}");
}

#[test]
fn point_to_disk_matches_the_analytic_value() {
    // A 256-gon inscribed in the disk has 0.01% less area: 0.1% tolerance.
    for (r, h) in [(1.0f32, 1.0f32), (0.5, 2.0), (3.0, 0.5)] {
        let poly: Vec<Vec3> = (0..256)
            .map(|k| {
                let a = k as f32 / 256.0 * std::f32::consts::TAU;
                Vec3::new(r * a.cos(), r * a.sin(), h)
            })
            .collect();
        let f = point_to_polygon(Vec3::ZERO, Vec3::Z, &poly) as f64;
        let expect = point_to_disk(r as f64, h as f64);
        assert!(
            ((f - expect) / expect).abs() < 1e-3,
            "r {r} h {h}: {f} vs {expect}"
        );
    }
}

#[test]
fn progressive_residual_decreases_and_agrees_with_gauss_seidel() {
    let scene = cornellish();
    let accel = Bvh::build(&scene);
    let base = RadiositySettings {
        patch_size: Some(0.45),
        epsilon: 1e-4,
        ..Default::default()
    };
    let p = radiosity::solve(&scene, &accel, &base).unwrap();
    let r = &p.solve.residuals;
    assert!(r.len() > 10);
    for w in r.windows(2) {
        assert!(w[1] <= w[0], "residual went up: {} -> {}", w[0], w[1]);
    }
    assert!(*r.last().unwrap() < 1e-4);
    let g = radiosity::solve(
        &scene,
        &accel,
        &RadiositySettings {
            solver: SolverKind::GaussSeidel,
            epsilon: 1e-6,
            ..base
        },
    )
    .unwrap();
    let scale = g
        .solve
        .radiosity
        .iter()
        .map(|b| b.max_element())
        .fold(0.0f32, f32::max);
    for (k, (a, b)) in p.solve.radiosity.iter().zip(&g.solve.radiosity).enumerate() {
        assert!(
            (*a - *b).abs().max_element() < 2e-3 * scale,
            "element {k}: progressive {a} vs Gauss-Seidel {b}"
        );
    }
    // Colour bleeding: the floor next to the red wall is redder than next to the green.
    let floor_near = |x: f32| {
        p.mesh
            .elements
            .iter()
            .zip(&p.solve.radiosity)
            .filter(|(e, _)| {
                e.n.y > 0.9 && e.centroid().y < 0.01 && (e.centroid().x - x).abs() < 0.1
            })
            .map(|(_, b)| *b)
            .fold(Vec3::ZERO, |a, b| a + b)
    };
    let (l, r) = (floor_near(0.05), floor_near(0.95));
    assert!(l.x / l.y > r.x / r.y, "red side {l}, green side {r}");
}

#[cfg(feature = "embree")]
#[test]
fn both_backends_give_the_same_solution() {
    let scene = cornellish();
    let settings = RadiositySettings {
        patch_size: Some(0.45),
        epsilon: 1e-4,
        ..Default::default()
    };
    let bvh = Bvh::build(&scene);
    let embree = crate::accel::embree::EmbreeAccel::build(&scene).unwrap();
    let a = radiosity::solve(&scene, &bvh, &settings).unwrap();
    let b = radiosity::solve(&scene, &embree, &settings).unwrap();
    assert_eq!(a.solve.iterations, b.solve.iterations);
    for (k, (x, y)) in a.solve.radiosity.iter().zip(&b.solve.radiosity).enumerate() {
        let rel = (*x - *y).abs().max_element() / x.max_element().max(1e-6);
        assert!(rel < 1e-3, "element {k}: bvh {x} vs embree {y}");
    }
}

#[test]
fn the_view_shows_the_interpolated_solution() {
    let scene = cornellish();
    let accel = Bvh::build(&scene);
    let sol = radiosity::solve(
        &scene,
        &accel,
        &RadiositySettings {
            patch_size: Some(0.45),
            ..Default::default()
        },
    )
    .unwrap();
    let film = radiosity::render_view(&scene, &accel, &sol, 16, 16, 1);
    // Looking at the back wall from inside: every pixel lit, none black.
    let lo = film
        .pixels
        .iter()
        .map(|p| p.min_element())
        .fold(f32::MAX, f32::min);
    assert!(lo > 0.0, "a black pixel inside the lit box");
    // No pixel brighter than the brightest vertex.
    let hi = sol
        .vertex_radiosity
        .iter()
        .map(|v| v.max_element())
        .fold(0.0f32, f32::max);
    assert!(film.pixels.iter().all(|p| p.max_element() <= hi * 1.0001));
    // The PLY lists every vertex and element.
    let ply = sol.to_ply(1.0, glam::DVec3::ZERO);
    assert!(ply.contains(&format!("element vertex {}", sol.mesh.vertices.len())));
    assert_eq!(
        ply.lines().count(),
        13 + sol.mesh.vertices.len() + sol.mesh.elements.len()
    );
}

#[test]
fn area_light_sampling_matches_the_form_factor_and_softens_shadows() {
    use crate::render::area;
    // A 1 × 1 emitter facing down, 1 above the origin of a floor facing up.
    let mut s = Scene::new(camera());
    s.materials.push(Material::DEFAULT);
    s.materials.push(Material {
        emission: Vec3::splat(2.0),
        ..Material::DEFAULT
    });
    let light = [
        Vec3::new(-0.5, 1.0, -0.5),
        Vec3::new(0.5, 1.0, -0.5),
        Vec3::new(0.5, 1.0, 0.5),
        Vec3::new(-0.5, 1.0, 0.5),
    ];
    quad(&mut s, light, 1);
    let lights = area::collect(&s);
    assert_eq!(lights.len(), 2);
    assert!(
        lights.iter().all(|l| l.n.y < -0.99),
        "the emitter faces down"
    );
    let accel = Bvh::build(&s);
    let p = Vec3::new(0.1, 0.0, -0.2);
    let (e, rays) = area::direct(&accel, &lights, &at(p), 8, 0);
    assert_eq!(rays, 2 * 64);
    // Irradiance/π = E × F(point → light).
    let f = point_to_polygon(p, Vec3::Y, &light);
    assert!(
        (e.x / (2.0 * f) - 1.0).abs() < 0.02,
        "{} vs {}",
        e.x,
        2.0 * f
    );
    // A blocker over half of the light: a penumbra, between none and all.
    let mut blocked = s.clone();
    quad(
        &mut blocked,
        [
            Vec3::new(-2.0, 0.5, -2.0),
            Vec3::new(0.1, 0.5, -2.0),
            Vec3::new(0.1, 0.5, 2.0),
            Vec3::new(-2.0, 0.5, 2.0),
        ],
        0,
    );
    let accel = Bvh::build(&blocked);
    let (h, _) = area::direct(&accel, &lights, &at(p), 8, 0);
    assert!(
        h.x > 0.2 * e.x && h.x < 0.8 * e.x,
        "penumbra {} of {}",
        h.x,
        e.x
    );
}

#[test]
fn two_pass_without_specular_paths_shows_the_radiosity_solution() {
    let scene = cornellish();
    let accel = Bvh::build(&scene);
    let sol = radiosity::solve(
        &scene,
        &accel,
        &RadiositySettings {
            patch_size: Some(0.45),
            ..Default::default()
        },
    )
    .unwrap();
    let view = radiosity::render_view(&scene, &accel, &sol, 16, 16, 1);
    let mut settings = crate::render::RenderSettings::for_scene(&scene);
    settings.width = 16;
    settings.height = 16;
    let (film, stats) = crate::render::render_with_gi(&scene, &accel, &settings, Some(&sol), None);
    // Everything is diffuse and there are no point lights: one diffuse term, counted
    // once, from the solution; no shadow rays.
    assert_eq!(stats.rays.shadow, 0);
    for (a, b) in film.pixels.iter().zip(&view.pixels) {
        assert!((*a - *b).abs().max_element() <= 1e-6 * b.max_element().max(1.0));
    }
    // Without the solution the emitter still lights the room, through area-light
    // sampling, with soft shadows: direct light only, so darker on average.
    let (direct, stats) = crate::render::render(&scene, &accel, &settings, None);
    assert!(stats.rays.shadow > 0);
    let mean = |f: &crate::render::Film| {
        f.pixels.iter().map(|p| p.x + p.y + p.z).sum::<f32>() / f.pixels.len() as f32
    };
    assert!(mean(&direct) > 0.0 && mean(&direct) < mean(&film));
}

/// Parallel (1 × 2 at 0.5) and perpendicular (1 × 1 floor, 1 × 0.6 wall) rectangles.
fn rectangle_pairs() -> (Scene, Scene) {
    let mut p = Scene::new(camera());
    p.materials = vec![Material::DEFAULT, Material::DEFAULT];
    let (a, b, c) = (1.0f32, 2.0f32, 0.5f32);
    quad(
        &mut p,
        [
            Vec3::ZERO,
            Vec3::new(a, 0.0, 0.0),
            Vec3::new(a, b, 0.0),
            Vec3::new(0.0, b, 0.0),
        ],
        0,
    );
    quad(
        &mut p,
        [
            Vec3::new(0.0, 0.0, c),
            Vec3::new(0.0, b, c),
            Vec3::new(a, b, c),
            Vec3::new(a, 0.0, c),
        ],
        1,
    );
    let mut q = Scene::new(camera());
    q.materials = vec![Material::DEFAULT, Material::DEFAULT];
    let (l, w, h) = (1.0f32, 1.0f32, 0.6f32);
    quad(
        &mut q,
        [
            Vec3::ZERO,
            Vec3::new(l, 0.0, 0.0),
            Vec3::new(l, w, 0.0),
            Vec3::new(0.0, w, 0.0),
        ],
        0,
    );
    quad(
        &mut q,
        [
            Vec3::ZERO,
            Vec3::new(0.0, 0.0, h),
            Vec3::new(l, 0.0, h),
            Vec3::new(l, 0.0, 0.0),
        ],
        1,
    );
    (p, q)
}

#[test]
fn hemicube_matches_the_analytic_rectangles() {
    // Measured errors: parallel +0.16% / +0.44%, perpendicular +0.13% / -0.25% at
    // (patch 0.26, 32²) / (patch 0.5, 64²): the point-to-area estimate from each
    // centroid and the pixel aliasing stay well inside 1%.
    let (p, q) = rectangle_pairs();
    for (patch, res) in [(0.26f32, 32u32), (0.5, 64)] {
        let f = rect_to_rect_hemicube(&p, patch, res);
        let expect = parallel_rectangles(1.0, 2.0, 0.5);
        assert!(
            ((f - expect) / expect).abs() < 0.01,
            "parallel, patch {patch}, {res}²: {f} vs {expect}"
        );
        let f = rect_to_rect_hemicube(&q, patch, res);
        let expect = perpendicular_rectangles(1.0, 1.0, 0.6);
        assert!(
            ((f - expect) / expect).abs() < 0.01,
            "perpendicular, patch {patch}, {res}²: {f} vs {expect}"
        );
    }
}

#[test]
fn hemicube_rows_of_a_closed_box_sum_to_one() {
    // Every pixel of every hemicube sees some element and the delta tables sum to one,
    // so only float rounding in the sums remains.
    let scene = white_box(0.5);
    let mesh = Mesh::build(&scene, 0.5).unwrap();
    let h = Hemicube::new(32).unwrap();
    for i in 0..mesh.elements.len() {
        let row = h.row(&mesh, i);
        let sum: f32 = row.iter().sum();
        assert!((sum - 1.0).abs() < 1e-4, "row {i} sums to {sum}");
        assert_eq!(row[i], 0.0);
    }
}

#[test]
fn hemicube_and_ray_cast_solutions_agree_on_a_cornell_box() {
    let scene = cornellish();
    let accel = Bvh::build(&scene);
    let base = RadiositySettings {
        patch_size: Some(0.45),
        epsilon: 3e-3,
        ..Default::default()
    };
    let r = radiosity::solve(&scene, &accel, &base).unwrap();
    let h = radiosity::solve(
        &scene,
        &accel,
        &RadiositySettings {
            form_factors: FormFactorMethod::Hemicube(32),
            ..base
        },
    )
    .unwrap();
    assert_eq!(r.mesh.elements.len(), h.mesh.elements.len());
    // Power per material (measured: within 0.5%): within 2%.
    let power = |s: &radiosity::Solution, m: u32| -> f64 {
        s.mesh
            .elements
            .iter()
            .zip(&s.solve.radiosity)
            .filter(|(e, _)| e.material == m)
            .map(|(e, b)| ((b.x + b.y + b.z) * e.area) as f64)
            .sum()
    };
    for m in 0..4 {
        let (a, b) = (power(&r, m), power(&h, m));
        assert!(
            ((b - a) / a).abs() < 0.02,
            "material {m}: ray cast {a}, hemicube {b}"
        );
    }
    // Per element (measured: worst 11.5%, mean 2.1% of the largest reflected
    // radiosity): the hemicube sees from the shooter's centroid only, the ray cast
    // from 4 points with one visibility ray per pair, so elements straddling the
    // block's shadow and those near the large light element differ most.
    let scale = r
        .mesh
        .elements
        .iter()
        .zip(&r.solve.radiosity)
        .filter(|(e, _)| e.material != 3)
        .map(|(_, b)| b.max_element())
        .fold(0.0f32, f32::max);
    let mut worst = 0.0f32;
    let mut mean = 0.0f32;
    for (a, b) in r.solve.radiosity.iter().zip(&h.solve.radiosity) {
        let d = (*a - *b).abs().max_element() / scale;
        mean += d / r.solve.radiosity.len() as f32;
        worst = worst.max(d);
    }
    assert!(
        worst < 0.15,
        "worst element differs by {worst} of the largest"
    );
    assert!(
        mean < 0.03,
        "elements differ by {mean} of the largest on average"
    );
}

/// A floor under a small light, half of it shadowed by a horizontal blocker whose edge
/// is over `x = 0.5`: the penumbra on the floor spans about `x` in 0.45..0.55.
fn shadow_scene() -> Scene {
    let mut s = Scene::new(camera());
    s.ambient = Vec3::ZERO;
    s.materials.push(Material {
        color: Vec3::splat(0.6),
        ..Material::DEFAULT
    });
    s.materials.push(Material {
        color: Vec3::splat(0.6),
        emission: Vec3::splat(20.0),
        ..Material::DEFAULT
    });
    let up = |y: f32, x0: f32, x1: f32, z0: f32, z1: f32| {
        [
            Vec3::new(x0, y, z0),
            Vec3::new(x0, y, z1),
            Vec3::new(x1, y, z1),
            Vec3::new(x1, y, z0),
        ]
    };
    quad(&mut s, up(0.0, 0.0, 1.0, 0.0, 1.0), 0); // floor
    quad(&mut s, up(0.5, 0.0, 0.5, 0.0, 1.0), 0); // blocker (its top faces up)
    let mut light = up(0.99, 0.45, 0.55, 0.45, 0.55);
    light.reverse(); // facing down
    quad(&mut s, light, 1);
    s
}

#[test]
fn adaptive_subdivision_refines_the_shadow_boundary_without_cracks() {
    let scene = shadow_scene();
    let accel = Bvh::build(&scene);
    let base = RadiositySettings {
        patch_size: Some(0.26),
        epsilon: 1e-2,
        ..Default::default()
    };
    let uniform = radiosity::solve(&scene, &accel, &base).unwrap();
    let sol = radiosity::solve(
        &scene,
        &accel,
        &RadiositySettings {
            subdiv_threshold: Some(0.2),
            min_patch_size: Some(0.03),
            subdiv_passes: 2,
            ..base
        },
    )
    .unwrap();
    let m = &sol.mesh;
    assert_eq!(
        sol.solve.refinements.len(),
        2,
        "{:?}",
        sol.solve.refinements
    );
    assert!(m.elements.len() > uniform.mesh.elements.len());
    // Floor elements: finer at the shadow boundary than far from it.
    let size = |near: bool| {
        let sizes: Vec<f32> = m
            .elements
            .iter()
            .filter(|e| e.centroid().y < 0.01)
            .filter(|e| ((e.centroid().x - 0.5).abs() < 0.1) == near)
            .filter(|e| near || (e.centroid().x - 0.5).abs() > 0.3)
            .map(|e| longest_edge(&e.p))
            .collect();
        sizes.iter().sum::<f32>() / sizes.len() as f32
    };
    let (near, far) = (size(true), size(false));
    assert!(
        near < 0.5 * far,
        "mean edge {near} at the boundary, {far} away"
    );
    // Power stays put (same light, same surfaces): within 3% of the uniform mesh's.
    let power = |s: &radiosity::Solution| -> f64 {
        s.mesh
            .elements
            .iter()
            .zip(&s.solve.radiosity)
            .map(|(e, b)| (b.x * e.area) as f64)
            .sum()
    };
    let (a, b) = (power(&uniform), power(&sol));
    assert!(
        ((a - b) / a).abs() < 0.03,
        "power {a} uniform, {b} adaptive"
    );
    // No cracks: wherever an element's corner lies inside another element's edge (a
    // T-junction, found here by brute force), the corner's radiosity equals the
    // coarser element's interpolation along that edge.
    let corners: Vec<(Vec3, u32, Vec3)> = m
        .elements
        .iter()
        .flat_map(|e| (0..3).map(move |c| (e.p[c], e.verts[c], e.n)))
        .collect();
    let v = &sol.vertex_radiosity;
    let mut junctions = 0;
    for e in &m.elements {
        for k in 0..3 {
            let (pa, pb) = (e.p[k], e.p[(k + 1) % 3]);
            let (ba, bb) = (v[e.verts[k] as usize], v[e.verts[(k + 1) % 3] as usize]);
            let d = pb - pa;
            for &(q, vert, n) in &corners {
                if n.dot(e.n) < 0.999 {
                    continue;
                }
                let t = (q - pa).dot(d) / d.length_squared();
                if !(0.01..0.99).contains(&t) || (pa + d * t - q).length() > 1e-6 {
                    continue;
                }
                junctions += 1;
                let along = ba * (1.0 - t) + bb * t;
                let here = v[vert as usize];
                assert!(
                    (here - along).abs().max_element() <= 1e-5 * along.max_element().max(1.0),
                    "T-junction at {q}: vertex {here}, edge {along}"
                );
            }
        }
    }
    assert!(junctions > 0, "no T-junction to check");
    // The same through the mesh's own list.
    assert!(!m.hanging_vertices().is_empty());
}

#[test]
fn classroom_ceiling_and_desk_undersides_are_lit_only_indirectly_but_lit() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/classroom.toml");
    let scene = crate::load::load_path(&path).unwrap();
    let accel = Bvh::build(&scene);
    let sol = radiosity::solve(
        &scene,
        &accel,
        &RadiositySettings {
            patch_size: Some(4.0),
            epsilon: 0.05,
            ..Default::default()
        },
    )
    .unwrap();
    let m = &sol.mesh;
    let mean = |pick: &dyn Fn(&radiosity::mesh::Element) -> bool| {
        let (mut b, mut a) = (0.0f64, 0.0f64);
        for (e, r) in m.elements.iter().zip(&sol.solve.radiosity) {
            if pick(e) {
                b += (r.max_element() * e.area) as f64;
                a += e.area as f64;
            }
        }
        assert!(a > 0.0);
        b / a
    };
    // Heights in the world (the scene is in the frame of its eye).
    let y = |e: &radiosity::mesh::Element| scene.to_world(e.centroid()).y;
    let ceiling = mean(&|e| e.n.y < -0.9 && y(e) > 2.995);
    let undersides = mean(&|e| e.n.y < -0.9 && (y(e) - 0.7).abs() < 1e-3);
    let floor = mean(&|e| e.n.y > 0.9 && y(e) < 1e-3);
    // The panels face down from just under the ceiling and the desk tops hide them
    // from their undersides: these receive only interreflected light, and get some.
    assert!(
        ceiling > 0.02 * floor && ceiling < floor,
        "ceiling {ceiling}, floor {floor}"
    );
    assert!(
        undersides > 0.02 * floor && undersides < floor,
        "undersides {undersides}, floor {floor}"
    );
}

/// The white box of [`white_box`] with a sphere over the middle of the floor and a
/// small box floating in a corner, all of the walls' reflectance.
fn sphere_in_box(rho: f32) -> Scene {
    use crate::geometry::{AaBox, Shape, Sphere};
    let mut s = white_box(rho);
    s.geometry.add_shape(
        Shape::Sphere(Sphere::new(Vec3::new(0.5, 0.2, 0.5), 0.15)),
        0,
    );
    let b = AaBox::new(Vec3::new(0.75, 0.05, 0.1), Vec3::new(0.9, 0.2, 0.25)).unwrap();
    s.geometry.add_shape(Shape::Box(b), 0);
    s
}

#[test]
fn tessellated_shapes_receive_reflect_and_shadow() {
    use crate::accel::{Accel, Hit};
    use crate::math::Ray;
    let rho = 0.5;
    let scene = sphere_in_box(rho);
    let bvh = Bvh::build(&scene);
    let base = RadiositySettings {
        patch_size: Some(0.36),
        epsilon: 3e-3,
        ..Default::default()
    };
    let hemicube = RadiositySettings {
        form_factors: FormFactorMethod::Hemicube(32),
        ..base.clone()
    };
    #[allow(unused_mut)]
    let mut runs = vec![
        (
            "ray cast, bvh",
            radiosity::solve(&scene, &bvh, &base).unwrap(),
        ),
        // The hemicube does not use the backend for its form factors.
        (
            "hemicube",
            radiosity::solve(&scene, &bvh, &hemicube).unwrap(),
        ),
    ];
    #[cfg(feature = "embree")]
    {
        let embree = crate::accel::embree::EmbreeAccel::build(&scene).unwrap();
        let sol = radiosity::solve(&scene, &embree, &base).unwrap();
        // Both backends agree.
        for (x, y) in runs[0].1.solve.radiosity.iter().zip(&sol.solve.radiosity) {
            assert!((*x - *y).abs().max_element() <= 1e-3 * x.max_element().max(1e-3));
        }
        runs.push(("ray cast, embree", sol));
    }
    for (name, sol) in &runs {
        let m = &sol.mesh;
        assert_eq!(m.unmeshed, 0, "{name}: sphere and box are meshed");
        let b = |k: usize| sol.solve.radiosity[k].x;
        let mean = |pick: &dyn Fn(&crate::radiosity::mesh::Element) -> bool| {
            let (mut sum, mut area) = (0.0, 0.0);
            for (k, e) in m.elements.iter().enumerate() {
                if pick(e) {
                    sum += b(k) * e.area;
                    area += e.area;
                }
            }
            assert!(area > 0.0, "{name}: no elements picked");
            sum / area
        };
        let on_sphere = |e: &crate::radiosity::mesh::Element| {
            (e.centroid() - Vec3::new(0.5, 0.2, 0.5)).length() < 0.16
        };
        let floor = |e: &crate::radiosity::mesh::Element| e.centroid().y < 1e-3 && e.n.y > 0.9;
        let xz = |e: &crate::radiosity::mesh::Element| {
            let c = e.centroid();
            (c.x - 0.5).hypot(c.z - 0.5)
        };
        let underside = mean(&|e| on_sphere(e) && e.n.y < -0.7);
        let top = mean(&|e| on_sphere(e) && e.n.y > 0.7);
        let under = mean(&|e| floor(e) && xz(e) < 0.12);
        let far = mean(&|e| floor(e) && xz(e) > 0.35);
        assert!(
            underside > 0.02 * far,
            "{name}: the sphere's underside gets {underside} (floor {far})"
        );
        assert!(
            top > underside,
            "{name}: top {top} vs underside {underside}"
        );
        eprintln!("{name}: underside {underside} top {top} floor under {under} far {far}");
        assert!(under < 0.8 * far, "{name}: no shadow: {under} vs {far}");
        // Every element of the closed scene has the same reflectance: the power leaving
        // all surfaces is the emitted power times 1/(1 − ρ).
        let total: f64 = m
            .elements
            .iter()
            .zip(&sol.solve.radiosity)
            .map(|(e, b)| (b.x * e.area) as f64)
            .sum();
        let expect = 1.0 / (1.0 - rho as f64);
        eprintln!(
            "{name}: total power {total}, series {expect}, {} elements",
            m.elements.len()
        );
        assert!(
            ((total - expect) / expect).abs() < 0.01,
            "{name}: total power {total}, series {expect}"
        );
        // The display maps hits on the true sphere to its elements: brighter on top.
        let look = |from: Vec3, dir: Vec3| {
            let ray = Ray::new(from, dir);
            let hit: Hit = bvh.intersect(&ray).unwrap();
            assert_eq!(hit.geom_id, crate::geometry::Kind::Sphere as u32);
            sol.radiosity_at(&hit, ray.at(hit.t), dir).unwrap().x
        };
        let shown_top = look(Vec3::new(0.5, 0.9, 0.5), -Vec3::Y);
        let shown_under = look(Vec3::new(0.5, 0.01, 0.5), Vec3::Y);
        assert!(shown_under > 0.0 && shown_top > 1.5 * shown_under);
        let lo = sol
            .vertex_radiosity
            .iter()
            .map(|v| v.x)
            .fold(f32::MAX, f32::min);
        let hi = sol.vertex_radiosity.iter().map(|v| v.x).fold(0.0, f32::max);
        assert!((lo..=hi).contains(&shown_under) && (lo..=hi).contains(&shown_top));
    }
}

#[test]
fn adaptive_rounds_go_on_from_the_previous_solution() {
    let scene = shadow_scene();
    let accel = Bvh::build(&scene);
    for solver in [SolverKind::Progressive, SolverKind::GaussSeidel] {
        let settings = RadiositySettings {
            patch_size: Some(0.26),
            epsilon: 1e-5,
            subdiv_threshold: Some(0.2),
            min_patch_size: Some(0.03),
            subdiv_passes: 2,
            solver,
            ..Default::default()
        };
        let sol = radiosity::solve(&scene, &accel, &settings).unwrap();
        assert_eq!(sol.solve.refinements.len(), 2);
        if solver == SolverKind::Progressive {
            assert!(sol.solve.regathered > 0);
            assert!(sol.solve.total_iterations > sol.solve.iterations);
        }
        // A solve from the emission alone on the same final mesh.
        let fresh = radiosity::solve_mesh(&sol.mesh, &accel, &settings, None).unwrap();
        let m = &sol.mesh;
        let scale = (m.elements.iter().zip(&fresh.radiosity))
            .filter(|(e, _)| m.emission[e.material as usize] == Vec3::ZERO)
            .map(|(_, b)| b.max_element())
            .fold(0.0, f32::max);
        for (k, (a, b)) in sol.solve.radiosity.iter().zip(&fresh.radiosity).enumerate() {
            let d = (*a - *b).abs().max_element();
            assert!(d <= 1e-3 * scale, "{solver:?} element {k}: {a} vs {b}");
        }
    }
}

/// A receiver at `p` facing +y.
fn at(p: Vec3) -> crate::render::area::Receiver {
    crate::render::area::Receiver {
        p,
        err: Vec3::ZERO,
        ng: Vec3::Y,
        ns: Vec3::Y,
    }
}
