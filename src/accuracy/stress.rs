//! Numerical stress cases, shared by `tests/stability.rs` (which asserts bounds on
//! small counts) and `emray stress` (which prints the measured numbers on full counts).

use crate::accel::{Accel, AccelError, Backend, BackendOptions, WithAccel};
use crate::geometry::precise as r64;
use crate::job::render_scene;
use crate::load::nff::{parse_str, parse_str_at};
use crate::math::{DRay, DVec3, Ray, Rng, Vec3, next_float_down, offset_ray_origin};
use crate::render::{Film, RayGen, RenderSettings};
use crate::scene::Scene;
use std::path::Path;

/// A convex test scene: one sphere and one light (no other surface can shadow it),
/// scaled by `scale` and moved by `offset` (camera, light and sphere alike).
pub fn convex_scene(scale: f64, offset: f64, res: u32) -> Scene {
    let p = |x: f64, y: f64, z: f64| {
        format!(
            "{} {} {}",
            x * scale + offset,
            y * scale + offset,
            z * scale + offset
        )
    };
    let src = format!(
        "v\nfrom {}\nat {}\nup 0 0 1\nangle 30\nhither 0\nresolution {res} {res}\n\
         b 0.1 0.1 0.1\nl {}\nf 0.8 0.6 0.4 0.9 0.3 20 0 1\ns {} {}\n",
        p(0.0, -6.0, 1.0),
        p(0.0, 0.0, 0.0),
        p(3.0, -4.0, 5.0),
        p(0.0, 0.0, 0.0),
        1.5 * scale
    );
    parse_str(&src, Path::new("<stress>")).expect("generated scene parses")
}

/// A sphere over a triangle floor (the shadow falls on the floor), scaled by `scale`.
pub fn floor_scene(scale: f64, res: u32) -> Scene {
    let v = |x: f64, y: f64, z: f64| format!("{} {} {}", x * scale, y * scale, z * scale);
    let src = format!(
        "v\nfrom {}\nat {}\nup 0 0 1\nangle 35\nhither 0\nresolution {res} {res}\n\
         b 0.1 0.2 0.3\nl {}\nf 0.8 0.8 0.7 0.9 0 0 0 1\np 4 {} {} {} {}\n\
         f 0.9 0.3 0.2 0.8 0.4 30 0 1\ns {} {}\n",
        v(0.0, -7.0, 3.0),
        v(0.0, 0.0, 0.5),
        v(3.0, -2.0, 6.0),
        v(-4.0, -4.0, 0.0),
        v(4.0, -4.0, 0.0),
        v(4.0, 4.0, 0.0),
        v(-4.0, 4.0, 0.0),
        v(0.0, 0.0, 1.0),
        scale
    );
    parse_str(&src, Path::new("<stress>")).expect("generated scene parses")
}

/// Render `scene` on `backend` at its resolution, 1 spp.
pub fn render(scene: &Scene, backend: Backend) -> Film {
    let st = RenderSettings::for_scene(scene);
    render_scene("stress", scene, backend, &st, 0.0, None)
        .expect("backend builds")
        .0
}

/// Self-shadowing acne on a convex scene: of the eye-ray hits whose shading normal
/// faces the light (the points that must be lit), how many have their shadow ray,
/// spawned as the renderer spawns it, blocked. Returns `(lit points, acne)`.
pub fn acne<A: Accel>(scene: &Scene, accel: &A) -> (u64, u64) {
    let cam = &scene.camera;
    let raygen = RayGen::new(cam, cam.width, cam.height);
    let (mut lit, mut acne) = (0, 0);
    for j in 0..cam.height {
        for i in 0..cam.width {
            let ray = raygen.ray(i as f32 + 0.5, j as f32 + 0.5);
            let Some(hit) = accel.intersect(&ray) else {
                continue;
            };
            let s = scene.surface(&hit, &ray);
            let d = ray.dir.normalize();
            let ng = if s.point.ng.dot(d) < 0.0 {
                s.point.ng
            } else {
                -s.point.ng
            };
            for light in &scene.lights {
                let to_light = light.pos - s.point.p;
                // Points near the terminator are left out: the f32 normal itself is
                // uncertain there.
                if ng.dot(to_light.normalize()) <= 1e-3 {
                    continue;
                }
                lit += 1;
                let org = offset_ray_origin(s.point.p, s.point.err, ng, to_light);
                let mut shadow = Ray::new(org, light.pos - org);
                shadow.tmax = next_float_down(1.0);
                if accel.occluded(&shadow) {
                    acne += 1;
                }
            }
        }
    }
    (lit, acne)
}

/// [`acne`] on the backend `options` names, built by [`crate::accel::build`].
pub fn acne_on(scene: &Scene, options: &BackendOptions) -> Result<(u64, u64), AccelError> {
    struct Acne<'a>(&'a Scene);
    impl WithAccel for Acne<'_> {
        type Output = (u64, u64);
        fn run<A: Accel>(self, accel: &A, _build_ms: f64) -> (u64, u64) {
            acne(self.0, accel)
        }
    }
    crate::accel::build(scene, options, Acne(scene))
}

/// Share (0..1) of pixels whose 8-bit sRGB value differs.
pub fn differing_share(a: &Film, b: &Film) -> f64 {
    crate::output::differing_pixels(a, b) as f64 / a.pixels.len().max(1) as f64
}

/// A closed mesh and the points of it that rays are aimed at exactly: vertices and
/// points on edges shared by two triangles, each with an outward direction and the
/// least cosine to it of a ray that must enter the mesh there (rays more oblique
/// could only graze the mesh or touch a sharp apex or ridge at that one point).
pub struct Watertight {
    /// The mesh (NFF polygons, shared vertices bit-identical).
    pub scene: Scene,
    /// `(point, outward unit direction, least cosine)`.
    pub targets: Vec<(Vec3, Vec3, f32)>,
    /// The centre the mesh surrounds.
    pub center: Vec3,
}

/// NFF source of the triangles `tris` (counter-clockwise seen from outside), each
/// vertex rounded to f32 once so that shared vertices are bit-identical.
fn mesh_source(tris: &[[Vec3; 3]], center: Vec3) -> String {
    let mut src = format!(
        "v\nfrom {} {} {}\nat {} {} {}\nup 0 1 0\nangle 30\nhither 0\nresolution 8 8\n\
         f 1 1 1 1 0 0 0 1\n",
        center.x,
        center.y,
        center.z + 5.0,
        center.x,
        center.y,
        center.z
    );
    for t in tris {
        src.push_str("p 3");
        for v in t {
            src.push_str(&format!(" {} {} {}", v.x, v.y, v.z));
        }
        src.push('\n');
    }
    src
}

/// A closed triangle mesh: the octahedron subdivided `n` times and pushed onto the
/// unit sphere (every edge shared by two triangles, every vertex by four or six),
/// moved to `center`. Targets: every vertex and edge midpoint.
pub fn tessellated_sphere(n: u32, center: Vec3) -> Watertight {
    let mut tris: Vec<[DVec3; 3]> = Vec::new();
    let (x, y, z) = (DVec3::X, DVec3::Y, DVec3::Z);
    for sx in [1.0, -1.0] {
        for sy in [1.0, -1.0] {
            for sz in [1.0, -1.0] {
                let t = [x * sx, y * sy, z * sz];
                // Counter-clockwise seen from outside.
                if sx * sy * sz > 0.0 {
                    tris.push(t);
                } else {
                    tris.push([t[0], t[2], t[1]]);
                }
            }
        }
    }
    for _ in 0..n {
        let mut next = Vec::with_capacity(tris.len() * 4);
        for [a, b, c] in tris {
            let (ab, bc, ca) = (
                ((a + b) * 0.5).normalize(),
                ((b + c) * 0.5).normalize(),
                ((c + a) * 0.5).normalize(),
            );
            next.extend([[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]);
        }
        tris = next;
    }
    let c64 = center.as_dvec3();
    let tris: Vec<[Vec3; 3]> = tris
        .iter()
        .map(|t| t.map(|v| (v + c64).as_vec3()))
        .collect();
    let mut targets = Vec::new();
    for &[a, b, c] in &tris {
        // Vertices and edge midpoints (computed in f32: exactly on the shared edge up
        // to rounding, which is what a watertight test must survive).
        for p in [a, (a + b) * 0.5, (b + c) * 0.5, (c + a) * 0.5] {
            // 60° from the normal: more than the facets deviate from the sphere.
            targets.push((p, (p - center).normalize(), 0.5));
        }
    }
    // In the world's frame: the targets are world points.
    let scene = parse_str_at(
        &mesh_source(&tris, center),
        Path::new("<stress>"),
        DVec3::ZERO,
    )
    .expect("generated mesh parses");
    Watertight {
        scene,
        targets,
        center,
    }
}

/// A closed bipyramid of `2 n` thin triangles (aspect about `n / 6`): two fans of
/// `n` triangles sharing one apex each (at ±`center.z + 1`) and a rim of `n`
/// vertices on the unit circle, moved to `center`. Targets: both apexes (shared by
/// `n` triangles), every rim vertex, and points at 1/8 … 7/8 along every spoke.
pub fn bipyramid(n: u32, center: Vec3) -> Watertight {
    let c64 = center.as_dvec3();
    let at = |v: DVec3| (v + c64).as_vec3();
    let top = at(DVec3::Z);
    let bottom = at(-DVec3::Z);
    let rim: Vec<Vec3> = (0..n)
        .map(|k| {
            let a = std::f64::consts::TAU * k as f64 / n as f64;
            at(DVec3::new(a.cos(), a.sin(), 0.0))
        })
        .collect();
    let mut tris = Vec::with_capacity(2 * n as usize);
    // The apexes (half-angle 45°) and the rim (a 90° ridge) are entered only by rays
    // within 45° of their axis: 0.8 leaves a margin.
    let mut targets = vec![(top, Vec3::Z, 0.8), (bottom, -Vec3::Z, 0.8)];
    for k in 0..n as usize {
        let (a, b) = (rim[k], rim[(k + 1) % n as usize]);
        tris.push([top, a, b]);
        tris.push([bottom, b, a]);
        let radial = (a - center) * Vec3::new(1.0, 1.0, 0.0);
        // The cone's outward normal along the spoke (rim radius 1, height 1).
        let up = (radial.normalize() + Vec3::Z).normalize();
        let down = (radial.normalize() - Vec3::Z).normalize();
        targets.push((a, radial.normalize(), 0.8));
        for i in 1..8 {
            let f = i as f32 / 8.0;
            targets.push((top + (a - top) * f, up, 0.5));
            targets.push((bottom + (a - bottom) * f, down, 0.5));
        }
    }
    // In the world's frame: the targets are world points.
    let scene = parse_str_at(
        &mesh_source(&tris, center),
        Path::new("<stress>"),
        DVec3::ZERO,
    )
    .expect("generated mesh parses");
    Watertight {
        scene,
        targets,
        center,
    }
}

impl Watertight {
    /// Rays from `n` origins around the mesh at distance `r` (a spiral over the
    /// sphere) aimed exactly at every target that they must enter the mesh at (see
    /// [`Watertight::targets`]).
    pub fn run<A: Accel>(&self, accel: &A, n: u32, r: f32) -> WatertightStats {
        let mut st = WatertightStats::default();
        for o in origins(n, r) {
            let o = o + self.center;
            for &(t, normal, cos_min) in &self.targets {
                let cos = normal.dot((o - t).normalize());
                if cos < cos_min.min(0.5) {
                    continue;
                }
                let miss = accel.intersect(&Ray::new(o, t - o)).is_none();
                if cos >= cos_min {
                    st.rays += 1;
                    st.misses += u64::from(miss);
                } else {
                    st.touching += 1;
                    st.touching_misses += u64::from(miss);
                }
            }
        }
        st
    }
}

impl Watertight {
    /// [`Watertight::run`] on the backend `options` names, built by
    /// [`crate::accel::build`]; also what the backend says of itself.
    pub fn run_on(
        &self,
        options: &BackendOptions,
        n: u32,
        r: f32,
    ) -> Result<(WatertightStats, String), AccelError> {
        struct Run<'a>(&'a Watertight, u32, f32);
        impl WithAccel for Run<'_> {
            type Output = (WatertightStats, String);
            fn run<A: Accel>(self, accel: &A, _build_ms: f64) -> Self::Output {
                (self.0.run(accel, self.1, self.2), accel.stats().detail)
            }
        }
        crate::accel::build(&self.scene, options, Run(self, n, r))
    }
}

/// What [`Watertight::run`] counted.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct WatertightStats {
    /// Rays that must enter the mesh at their target.
    pub rays: u64,
    /// Of those, the ones that hit nothing.
    pub misses: u64,
    /// Rays through a sharp apex or ridge from outside its cone of entry, within 60° of
    /// its outward direction: they may touch the mesh at that one point only, so a miss
    /// is no error (reported, not asserted).
    pub touching: u64,
    /// Of those, the ones that hit nothing.
    pub touching_misses: u64,
}

/// The watertightness cases `emray stress` runs: `(name, mesh, ray origins)`.
pub fn watertight_cases() -> Vec<(String, Watertight, u32)> {
    let far = Vec3::new(1e3, -2e3, 5e2);
    vec![
        (
            "sphere, 2048 triangles".into(),
            tessellated_sphere(4, Vec3::ZERO),
            64,
        ),
        (
            "sphere, 2048 triangles at (1e3, -2e3, 5e2)".into(),
            tessellated_sphere(4, far),
            64,
        ),
        (
            "bipyramid, 1000 thin triangles".into(),
            bipyramid(500, Vec3::ZERO),
            64,
        ),
        (
            "bipyramid, 1000 thin triangles at (1e3, -2e3, 5e2)".into(),
            bipyramid(500, far),
            64,
        ),
        (
            "bipyramid, 10000 thinner triangles at (1e3, -2e3, 5e2)".into(),
            bipyramid(5000, far),
            16,
        ),
    ]
}

/// Origins at distance `r` from the origin, `n` of them (a spiral over the sphere).
pub fn origins(n: u32, r: f32) -> Vec<Vec3> {
    (0..n)
        .map(|k| {
            let z = 1.0 - 2.0 * (k as f32 + 0.5) / n as f32;
            let phi = k as f32 * 2.399_963;
            let s = (1.0 - z * z).sqrt();
            Vec3::new(s * phi.cos(), s * phi.sin(), z) * r
        })
        .collect()
}

/// f32 hit distance against the f64 reference for a sphere of radius `radius` at
/// distance `dist`, over `n` rays from the origin aimed at random points of its
/// projected disk: `(worst relative error of t, misses where f64 hits, hits where
/// f64 misses)`.
pub fn far_sphere(dist: f32, radius: f32, n: u32, seed: u32) -> (f64, u64, u64) {
    let c = Vec3::new(0.0, 0.0, -dist);
    let sphere = crate::geometry::Sphere::new(c, radius);
    let mut worst = 0.0f64;
    let (mut miss, mut extra) = (0, 0);
    let mut rng = Rng::new(u64::from(seed));
    let mut rnd = || rng.next_f32();
    for _ in 0..n {
        // Points up to 1.1 radii from the centre, on the plane through it.
        let (a, b) = (rnd() * std::f32::consts::TAU, rnd().sqrt() * 1.1 * radius);
        let target = c + Vec3::new(a.cos() * b, a.sin() * b, 0.0);
        let ray = Ray::new(Vec3::ZERO, target.normalize());
        let exact = r64::sphere(&DRay::from(&ray), c.as_dvec3(), radius as f64, false, 0.0);
        let got = crate::geometry::Intersect::intersect(&sphere, &ray).map(|h| h.t);
        match (got, exact) {
            (Some(t), Some(e)) => worst = worst.max(((t as f64 - e) / e).abs()),
            (None, Some(_)) => miss += 1,
            (Some(_), None) => extra += 1,
            (None, None) => {}
        }
    }
    (worst, miss, extra)
}

/// The draws the random stress rays are made of, in double precision, from the
/// crate's seeded generator.
struct Draws(Rng);

impl Draws {
    fn new(seed: u32) -> Draws {
        Draws(Rng::new(u64::from(seed)))
    }

    /// Uniform in `[0, 1)`.
    fn unit(&mut self) -> f64 {
        self.0.next_f64()
    }

    /// Uniform in `[lo, hi)`.
    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        self.0.range_f64(lo, hi)
    }

    /// A unit vector perpendicular to unit `w`, at a random angle around it.
    fn perpendicular(&mut self, w: DVec3) -> DVec3 {
        let a = self.range(0.0, std::f64::consts::TAU);
        let (u, v) = w.any_orthonormal_pair();
        u * a.cos() + v * a.sin()
    }

    /// `±10^-k` with `k` uniform in `[lo, hi]`, sometimes exactly 0.
    fn tiny(&mut self, lo: f64, hi: f64) -> f64 {
        if self.unit() < 0.02 {
            return 0.0;
        }
        let s = if self.unit() < 0.5 { -1.0 } else { 1.0 };
        s * 10f64.powf(-self.range(lo, hi))
    }
}

/// What a near-degenerate quadric case measured, f32 intersector against the f64
/// reference on the same (f32) rays.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RootStats {
    /// Rays cast.
    pub rays: u64,
    /// Rays the f64 reference hits.
    pub hits: u64,
    /// f32 hits with a NaN or infinite `t` or normal.
    pub nan: u64,
    /// Hit/miss disagreements outside the band around tangency.
    pub disagree: u64,
    /// Rays within the band (hit/miss may differ there; not counted above).
    pub in_band: u64,
    /// Worst `|t₃₂ − t₆₄| / max(t₆₄, 1)` where both hit.
    pub worst_t: f64,
    /// Worst distance of the f32 hit point (evaluated in f64) from the exact surface.
    pub worst_dist: f64,
}

/// Bound on [`RootStats::worst_dist`] (unit-sized surfaces).
pub const ROOT_DIST_BOUND: f64 = 1e-4;

/// One near-degenerate quadric case: its name, and a function casting `n` rays.
pub type RootCase = (&'static str, fn(u32) -> RootStats);

/// Compare `shape` (f32) against the reference `exact` (nearest `t > 0` in f64) and the
/// surface distance `dist` on `n` rays from `gen`, which also says whether a ray lies
/// within the tangent band.
fn roots<S: crate::geometry::Intersect>(
    n: u32,
    shape: &S,
    mut raygen: impl FnMut(&mut Draws) -> (Ray, bool),
    exact: impl Fn(&DRay) -> Option<f64>,
    dist: impl Fn(DVec3) -> f64,
) -> RootStats {
    let mut rng = Draws::new(n ^ 0x5eed);
    let mut st = RootStats::default();
    for _ in 0..n {
        let (ray, band) = raygen(&mut rng);
        let dray = DRay::from(&ray);
        st.rays += 1;
        let want = exact(&dray);
        let got = shape.intersect(&ray);
        st.hits += u64::from(want.is_some());
        st.in_band += u64::from(band);
        if let Some(h) = got {
            if !h.t.is_finite() || !h.ng.is_finite() {
                st.nan += 1;
                continue;
            }
        }
        match (got, want) {
            (Some(h), Some(e)) => {
                let t = h.t as f64;
                st.worst_t = st.worst_t.max((t - e).abs() / e.max(1.0));
                st.worst_dist = st.worst_dist.max(dist(dray.org + dray.dir * t));
            }
            (Some(_), None) | (None, Some(_)) if !band => st.disagree += 1,
            _ => {}
        }
    }
    st
}

/// An f32 ray from f64 origin and direction.
fn ray32(o: DVec3, d: DVec3) -> Ray {
    Ray::new(o.as_vec3(), d.as_vec3())
}

/// `|F(p)| / |∇F(p)|`: the distance from `p` to the quadric `c` to first order.
fn quadric_dist(c: &[f64; 10], p: DVec3) -> f64 {
    r64::quadric::quadric_value(c, p).abs() / r64::quadric::quadric_gradient(c, p).length()
}

/// The quadric-root stress cases: rays that make the quadratic degenerate (`a → 0`:
/// almost parallel to a paraboloid's axis or a cone's generator) or nearly tangent
/// (discriminant ≈ 0: impact parameter `r (1 ± 10⁻ᵏ)`, k in 1..9, band `|δ| < 1e-5`).
/// On the finite cone primitive the band is the rays meeting its surface within 1e-5
/// of its base or apex, where the clip to its height decides hit or miss.
pub fn quadric_root_cases() -> Vec<RootCase> {
    /// Relative impact-parameter band around tangency where hit or miss may go
    /// either way in f32.
    const BAND: f64 = 1e-5;
    vec![
        ("paraboloid, rays 1e-1..1e-8 rad off its axis", |n| {
            let q = crate::geometry::Quadric::paraboloid(Vec3::ZERO, Vec3::Z, 0.25)
                .expect("valid paraboloid");
            let c = q.coefficients();
            roots(
                n,
                &q,
                |g| {
                    let o = DVec3::new(g.range(-1.0, 1.0), g.range(-1.0, 1.0), -1.0);
                    let e = g.tiny(1.0, 8.0);
                    let d = (DVec3::Z + g.perpendicular(DVec3::Z) * e).normalize();
                    (ray32(o, d), false)
                },
                |r| r64::quadric::quadric(r, &c, None, 0.0),
                |p| quadric_dist(&c, p),
            )
        }),
        ("cone quadric, rays 1e-1..1e-8 rad off a generator", |n| {
            let q = crate::geometry::Quadric::cone(Vec3::ZERO, Vec3::Z, 0.5).expect("valid cone");
            let c = q.coefficients();
            roots(
                n,
                &q,
                |g| {
                    let a = g.range(0.0, std::f64::consts::TAU);
                    let raygen = DVec3::new(0.5 * a.cos(), 0.5 * a.sin(), 1.0).normalize();
                    let o = DVec3::new(g.range(-1.0, 1.0), g.range(-1.0, 1.0), -2.0);
                    let d = (raygen + g.perpendicular(raygen) * g.tiny(1.0, 8.0)).normalize();
                    (ray32(o, d), false)
                },
                |r| r64::quadric::quadric(r, &c, None, 0.0),
                |p| quadric_dist(&c, p),
            )
        }),
        ("cone primitive, rays 1e-1..1e-8 rad off a generator", |n| {
            // Base radius 1 at z = 0, apex radius 0 at z = 2: generators of slope 1/2.
            let cone = crate::geometry::Cone::new(Vec3::ZERO, 1.0, 2.0 * Vec3::Z, 0.0);
            roots(
                n,
                &cone,
                |g| {
                    let a = g.range(0.0, std::f64::consts::TAU);
                    let raygen = DVec3::new(-0.5 * a.cos(), -0.5 * a.sin(), 1.0).normalize();
                    let o = DVec3::new(g.range(-0.5, 0.5), g.range(-0.5, 0.5), -1.0);
                    let d = (raygen + g.perpendicular(raygen) * g.tiny(1.0, 8.0)).normalize();
                    let ray = ray32(o, d);
                    (ray, meets_cone_near_an_end(&DRay::from(&ray), BAND))
                },
                |r| r64::cone(r, DVec3::ZERO, 1.0, 2.0 * DVec3::Z, 0.0, false, 0.0),
                |p| {
                    // Distance to the lateral surface r = 1 − z/2 (half-angle atan ½).
                    let rad = (p.x * p.x + p.y * p.y).sqrt();
                    (rad - (1.0 - 0.5 * p.z)).abs() * (2.0 / 5f64.sqrt())
                },
            )
        }),
        ("sphere primitive, tangent rays", |n| {
            let s = crate::geometry::Sphere::new(Vec3::ZERO, 1.0);
            roots(
                n,
                &s,
                |g| tangent_ray(g, DVec3::ZERO, None, 1.0, BAND),
                |r| r64::sphere(r, DVec3::ZERO, 1.0, false, 0.0),
                |p| (p.length() - 1.0).abs(),
            )
        }),
        ("sphere quadric, tangent rays", |n| {
            let q = crate::geometry::Quadric::sphere(Vec3::ZERO, 1.0).expect("valid sphere");
            let c = q.coefficients();
            roots(
                n,
                &q,
                |g| tangent_ray(g, DVec3::ZERO, None, 1.0, BAND),
                |r| r64::quadric::quadric(r, &c, None, 0.0),
                |p| quadric_dist(&c, p),
            )
        }),
        ("cylinder quadric, tangent rays", |n| {
            let q = crate::geometry::Quadric::cylinder(Vec3::ZERO, Vec3::Z, 1.0)
                .expect("valid cylinder");
            let c = q.coefficients();
            roots(
                n,
                &q,
                |g| tangent_ray(g, DVec3::ZERO, Some(DVec3::Z), 1.0, BAND),
                |r| r64::quadric::quadric(r, &c, None, 0.0),
                |p| quadric_dist(&c, p),
            )
        }),
        ("cylinder primitive, tangent rays", |n| {
            // Radius 1 from z = −2 to z = 2; the rays cross the axis near z = 0.
            let cyl = crate::geometry::Cone::new(-2.0 * Vec3::Z, 1.0, 2.0 * Vec3::Z, 1.0);
            roots(
                n,
                &cyl,
                |g| tangent_ray(g, DVec3::ZERO, Some(DVec3::Z), 1.0, BAND),
                |r| r64::cone(r, -2.0 * DVec3::Z, 1.0, 2.0 * DVec3::Z, 1.0, false, 0.0),
                |p| ((p.x * p.x + p.y * p.y).sqrt() - 1.0).abs(),
            )
        }),
    ]
}

/// Whether `ray` meets the lateral surface of the stress cone (radius `1 − z/2`,
/// extended beyond its ends) within `band` of its base plane `z = 0` or its apex
/// `z = 2`: there the hit is decided by the rounding of the hit's height against the
/// end, not by the roots, and f32 and f64 may differ about hit or miss.
fn meets_cone_near_an_end(ray: &DRay, band: f64) -> bool {
    // |xy(t)|² = (k + m t)² with k = 1 − o.z/2, m = −d.z/2: a t² + b t + c = 0.
    let (o, d) = (ray.org, ray.dir);
    let (k, m) = (1.0 - 0.5 * o.z, -0.5 * d.z);
    let a = d.x * d.x + d.y * d.y - m * m;
    let b = 2.0 * (o.x * d.x + o.y * d.y - k * m);
    let c = o.x * o.x + o.y * o.y - k * k;
    let disc = b * b - 4.0 * a * c;
    if disc < 0.0 {
        return false;
    }
    // The stable pair of roots (one of them far away when a → 0).
    let q = -0.5 * (b + disc.sqrt().copysign(b));
    [q / a, c / q]
        .into_iter()
        .filter(|t| t.is_finite() && *t > 0.0)
        .map(|t| o.z + d.z * t)
        .any(|z| z.abs() < band || (z - 2.0).abs() < band)
}

/// A ray passing at distance `r (1 + δ)` from `center` (from the line through it along
/// `axis` for a cylinder), δ = ±10⁻ᵏ, k in 1..9; whether its exact (f64) distance is
/// within `band` of tangency.
fn tangent_ray(
    g: &mut Draws,
    center: DVec3,
    axis: Option<DVec3>,
    r: f64,
    band: f64,
) -> (Ray, bool) {
    let delta = g.tiny(1.0, 9.0);
    // Direction: any for the sphere, perpendicular to the axis (± 30°) for a cylinder.
    let d = match axis {
        None => {
            let z = g.range(-1.0, 1.0);
            let a = g.range(0.0, std::f64::consts::TAU);
            let s = (1.0 - z * z).sqrt();
            DVec3::new(s * a.cos(), s * a.sin(), z)
        }
        Some(w) => (g.perpendicular(w) + w * g.range(-0.5, 0.5)).normalize(),
    };
    // The offset from the centre (line) to the ray, perpendicular to both.
    let side = match axis {
        None => g.perpendicular(d),
        Some(w) => d.cross(w).normalize(),
    };
    let o = center + side * (r * (1.0 + delta)) - d * g.range(3.0, 6.0);
    let ray = ray32(o, d);
    // The exact distance of the f32 ray actually cast.
    let dr = DRay::from(&ray);
    let u = dr.dir.normalize();
    let f = dr.org - center;
    let dist = match axis {
        None => (f - u * f.dot(u)).length(),
        Some(w) => f.dot(u.cross(w).normalize()).abs(),
    };
    (ray, ((dist - r) / r).abs() < band)
}

/// How closely a moved or scaled scene's picture matches the original's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Invariance {
    /// Share (0..1) of pixels whose 8-bit sRGB channels all lie within
    /// [`INVARIANCE_TOLERANCE`] of the original's.
    pub within: f64,
    /// Largest 8-bit difference of any channel of any pixel.
    pub max_diff: u8,
}

/// The 8-bit difference a pixel of a moved scene may show and still count as the same.
pub const INVARIANCE_TOLERANCE: u8 = 2;

/// Share of pixels of `b` within [`INVARIANCE_TOLERANCE`] of `a` (8-bit sRGB), and the
/// largest difference.
pub fn invariance_of(a: &Film, b: &Film) -> Invariance {
    use crate::render::color::{Encoding, to_rgb8};
    let (pa, pb) = (to_rgb8(a, Encoding::Srgb), to_rgb8(b, Encoding::Srgb));
    let mut within = 0usize;
    let mut max_diff = 0u8;
    for (x, y) in pa.chunks(3).zip(pb.chunks(3)) {
        let d = x
            .iter()
            .zip(y)
            .map(|(p, q)| p.abs_diff(*q))
            .max()
            .unwrap_or(0);
        max_diff = max_diff.max(d);
        within += usize::from(d <= INVARIANCE_TOLERANCE);
    }
    Invariance {
        within: within as f64 / (pa.len() / 3).max(1) as f64,
        max_diff,
    }
}

/// Render the NFF scene `src` and the same scene moved by `shift` and scaled by `scale`
/// ([`move_nff`](super::moved::move_nff)) on `backend` at `res × res`, one ray per
/// pixel centre, and compare the pictures.
pub fn invariance(src: &str, scale: f64, shift: DVec3, backend: Backend, res: u32) -> Invariance {
    let moved = super::moved::move_nff(src, scale, shift).expect("an NFF scene that loads");
    let render_at = |text: &str| {
        let scene = parse_str(text, Path::new("<invariance>")).expect("the scene loads");
        let mut st = RenderSettings::for_scene(&scene);
        st.width = res;
        st.height = res;
        render_scene("invariance", &scene, backend, &st, 0.0, None)
            .expect("backend builds")
            .0
    };
    invariance_of(&render_at(src), &render_at(&moved))
}
