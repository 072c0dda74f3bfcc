//! Hard triangles against the f64 reference: the cases where an f32 triangle test can
//! lose a hit that is plainly there. Each case is one triangle and rays from one
//! origin aimed at points inside and outside it; both backends must find every hit the
//! f64 reference finds ([`crate::geometry::precise::triangle`], on the same f32
//! numbers) and no hit where it finds none, except for rays within rounding of an edge
//! (where the f32 test is allowed to decide either way, as long as it decides the same
//! way for both triangles sharing the edge).
//!
//! The families ([`Family`]): triangles huge beside their distance from the origin (a
//! floor a million units wide seen from a metre above it, and closer still: the origin
//! within the rounding of the triangle's coordinates from its plane), slivers (one side 10² to 10⁶
//! times the height), grazing views (rays at 10⁻¹ to 10⁻⁵ radians to the plane) and an
//! origin almost on the plane (10⁻² to 10⁻⁷ of the triangle's size away), plus the two
//! triangles that showed the BVH losing hits ([`known_cases`]).

use crate::accel::{Accel, BackendOptions, WithAccel};
use crate::geometry::{Kind, Triangle, precise};
use crate::math::{DRay, DVec3, Ray, Rng, Vec3, gamma};
use crate::scene::{Camera, Scene};

/// The kind of hardness a case is made of.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Family {
    /// Vertices 10³ to 10⁹ from the origin, the origin 4 to 10⁴ units in the last
    /// place of the largest vertex coordinate above the plane (a floor 10⁶ wide seen
    /// from a metre above it is 16 such units).
    Huge,
    /// As [`Family::Huge`] with the origin closer to the plane than one unit in the
    /// last place of the vertex coordinates: which side of the plane the origin lies
    /// on is then decided by the coordinates' own rounding. Exact on the BVH; Embree's
    /// f32 test loses such hits (its count is reported, not required to be 0).
    BelowRounding,
    /// Two vertices 10⁻² to 10³ apart, the third 10⁻⁶ to 10⁻² of that off their line.
    Sliver,
    /// Rays meeting the plane at 10⁻⁵ to 10⁻¹ radians.
    Grazing,
    /// The origin 10⁻⁷ to 10⁻² of the triangle's size from its plane.
    EyeNearPlane,
    /// The triangles that once lost hits on the BVH.
    Known,
}

impl Family {
    /// Every family drawn at random by [`hard_cases`].
    pub const RANDOM: [Family; 5] = [
        Family::Huge,
        Family::BelowRounding,
        Family::Sliver,
        Family::Grazing,
        Family::EyeNearPlane,
    ];

    /// A short name for reports.
    pub fn name(self) -> &'static str {
        match self {
            Family::Huge => "huge",
            Family::BelowRounding => "huge, origin within rounding of the plane",
            Family::Sliver => "sliver",
            Family::Grazing => "grazing",
            Family::EyeNearPlane => "eye near the plane",
            Family::Known => "known",
        }
    }
}

/// One triangle and the rays cast at it from one origin.
#[derive(Clone, Debug)]
pub struct HardCase {
    /// What makes it hard.
    pub family: Family,
    /// The triangle (f32, as a scene holds it).
    pub triangle: Triangle,
    /// The rays (f32 origin and direction, interval `[0, ∞)`).
    pub rays: Vec<Ray>,
}

/// What the f64 reference says of one ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Truth {
    /// It hits at this distance, and its line is clear of every edge.
    Hit(f64),
    /// It misses, clearly: its line passes outside an edge beyond rounding, or the
    /// plane lies behind its origin.
    Miss,
    /// Within rounding of an edge: either answer is right.
    EdgeBand,
}

/// What a backend did on a set of cases.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct HardStats {
    /// Rays cast.
    pub rays: u64,
    /// Rays the reference hits clear of every edge.
    pub hits: u64,
    /// Of those, the ones the backend missed (nearest hit or any hit).
    pub misses: u64,
    /// Rays the reference misses clearly that the backend hit.
    pub extra: u64,
    /// Rays within rounding of an edge (not counted above).
    pub edge_band: u64,
    /// Worst distance of a hit point (the origin plus the backend's `t` times the
    /// direction, in f64) from the triangle's plane, in units of the triangle's
    /// coordinate precision (`2⁻²⁴ ×` its largest coordinate relative to the origin):
    /// how far the backend's distance is off, measured where it matters, across the
    /// surface rather than along a grazing ray.
    pub worst_plane_ulps: f64,
}

impl HardStats {
    /// Add `other`'s counts (the worst error is the worse of the two).
    pub fn add(&mut self, other: &HardStats) {
        self.rays += other.rays;
        self.hits += other.hits;
        self.misses += other.misses;
        self.extra += other.extra;
        self.edge_band += other.edge_band;
        self.worst_plane_ulps = self.worst_plane_ulps.max(other.worst_plane_ulps);
    }
}

/// The reference's verdict on `ray` and `tri`. The band around each edge is the bound
/// on the f32 test's error in that edge's function (the sheared vertex coordinates'
/// rounding, as [`crate::geometry::Triangle`] bounds it, and the products'), computed
/// with the f64 values.
pub fn truth(tri: &Triangle, ray: &Ray) -> Truth {
    let dray = DRay::from(ray);
    let p = tri.p.map(|v| v.as_dvec3());
    let exact = precise::triangle(&dray, p, 0.0);
    let (edges, band) = sheared_edges(&p, &dray);
    if edges.iter().any(|e| e.abs() <= band) {
        return Truth::EdgeBand;
    }
    let inside = edges.iter().all(|&e| e > 0.0) || edges.iter().all(|&e| e < 0.0);
    match exact {
        Some((t, _, _)) if inside => Truth::Hit(t),
        None if !inside => Truth::Miss,
        // The plane behind the origin (or at it): a clear miss unless at rounding of 0.
        None => {
            let n = (p[1] - p[0]).cross(p[2] - p[0]);
            let t = n.dot(p[0] - dray.org) / n.dot(dray.dir);
            let scale = p.iter().map(|v| (*v - dray.org).abs().max_element());
            let scale = scale.fold(0.0, f64::max) / dray.dir.abs().max_element();
            if t < -1e-9 * scale || !t.is_finite() {
                Truth::Miss
            } else {
                Truth::EdgeBand
            }
        }
        // The reference's Möller–Trumbore and the sheared edge functions disagree
        // about inside: only possible at rounding of an edge.
        Some(_) => Truth::EdgeBand,
    }
}

/// The watertight test's three edge functions in f64 (same permutation and shear as the
/// f32 test) and the bound on their f32 error.
fn sheared_edges(p: &[DVec3; 3], ray: &DRay) -> ([f64; 3], f64) {
    let d = ray.dir.to_array();
    let a = ray.dir.abs().to_array();
    let kz = if a[0] >= a[1] && a[0] >= a[2] {
        0
    } else if a[1] >= a[2] {
        1
    } else {
        2
    };
    let (kx, ky) = ([1, 2, 0][kz], [2, 0, 1][kz]);
    let (sx, sy) = (d[kx] / d[kz], d[ky] / d[kz]);
    let sheared = p.map(|v| {
        let r = (v - ray.org).to_array();
        (r[kx] - sx * r[kz], r[ky] - sy * r[kz], r[kz])
    });
    let [(ax, ay, az), (bx, by, bz), (cx, cy, cz)] = sheared;
    let edges = [cx * by - cy * bx, ax * cy - ay * cx, bx * ay - by * ax];
    let g = |n: u32| f64::from(gamma(n));
    let max_z = az.abs().max(bz.abs()).max(cz.abs());
    let max_x = ax.abs().max(bx.abs()).max(cx.abs());
    let max_y = ay.abs().max(by.abs()).max(cy.abs());
    // The f32 test's error in x and y (translation, shear) and in each edge function,
    // doubled: a margin for the f64 values being themselves rounded.
    let (dx, dy) = (g(5) * (max_x + max_z), g(5) * (max_y + max_z));
    let band = 4.0 * (g(2) * max_x * max_y + dy * max_x + dx * max_y);
    (edges, band)
}

/// A unit vector uniform on the sphere.
fn unit(rng: &mut Rng) -> DVec3 {
    let z = rng.range_f64(-1.0, 1.0);
    let a = rng.range_f64(0.0, std::f64::consts::TAU);
    let s = (1.0 - z * z).sqrt();
    DVec3::new(s * a.cos(), s * a.sin(), z)
}

/// `10^x` with `x` uniform in `[lo, hi]`.
fn decade(rng: &mut Rng, lo: f64, hi: f64) -> f64 {
    10f64.powf(rng.range_f64(lo, hi))
}

/// A point with barycentrics drawn uniformly over the triangle (`inside`) or just
/// outside one edge (up to a third of the triangle beyond it).
fn target(rng: &mut Rng, p: &[DVec3; 3], inside: bool) -> DVec3 {
    let (mut s, mut t) = (rng.next_f64(), rng.next_f64());
    if s + t > 1.0 {
        (s, t) = (1.0 - s, 1.0 - t);
    }
    let mut b = [1.0 - s - t, s, t];
    if !inside {
        let k = rng.below(3) as usize;
        let out = rng.range_f64(1e-3, 0.3);
        b[k] = -out;
        let rest = 1.0 + out;
        let (i, j) = ((k + 1) % 3, (k + 2) % 3);
        let f = rng.next_f64();
        (b[i], b[j]) = (rest * f, rest * (1.0 - f));
    }
    p[0] * b[0] + p[1] * b[1] + p[2] * b[2]
}

/// One case: the triangle `p`, the origin at `eye`, and `rays` rays, three in four at
/// points inside, the rest just outside. When the origin's foot on the plane lies
/// inside the triangle, half the inside points are drawn towards it on a logarithmic
/// scale (down to 10⁻⁶ of the way), so that the rays span every angle to the plane as
/// a camera's do, not only the grazing ones that uniform points on a huge triangle
/// would give.
fn case(rng: &mut Rng, family: Family, p: [DVec3; 3], eye: DVec3, rays: usize) -> HardCase {
    let triangle = Triangle {
        p: p.map(|v| v.as_vec3()),
    };
    let p = triangle.p.map(|v| v.as_dvec3());
    let org = eye.as_vec3();
    let foot = foot_inside(&p, org.as_dvec3());
    let rays = (0..rays)
        .map(|i| {
            let inside = i % 4 != 3;
            let mut aim = target(rng, &p, inside);
            if let (Some(foot), true) = (foot, inside && i % 2 == 0) {
                aim = foot + (aim - foot) * decade(rng, -6.0, 0.0);
            }
            Ray::new(org, (aim - org.as_dvec3()).as_vec3())
        })
        .filter(|r| r.dir.length_squared() > 0.0)
        .collect();
    HardCase {
        family,
        triangle,
        rays,
    }
}

/// The foot of `eye` on the triangle's plane, if it lies inside the triangle.
fn foot_inside(p: &[DVec3; 3], eye: DVec3) -> Option<DVec3> {
    let n = (p[1] - p[0]).cross(p[2] - p[0]);
    let foot = eye - n * (n.dot(eye - p[0]) / n.length_squared());
    let side = |a: DVec3, b: DVec3| (b - a).cross(foot - a).dot(n) > 0.0;
    (side(p[0], p[1]) && side(p[1], p[2]) && side(p[2], p[0])).then_some(foot)
}

/// A triangle of size about `size` around `center` in the plane with normal `n`: a
/// random, well-shaped one (angles far from 0 and 180°).
fn triangle_around(rng: &mut Rng, center: DVec3, n: DVec3, size: f64) -> [DVec3; 3] {
    let (u, v) = n.any_orthonormal_pair();
    let a0 = rng.range_f64(0.0, std::f64::consts::TAU);
    std::array::from_fn(|k| {
        let a = a0 + k as f64 * std::f64::consts::TAU / 3.0 + rng.range_f64(-0.5, 0.5);
        center + (u * a.cos() + v * a.sin()) * size * rng.range_f64(0.6, 1.0)
    })
}

/// One random case of `family`. The origin is near the scene's zero (where the
/// loaders put the eye) or, for a third of the cases, up to 10⁴ away from it.
fn random_case(rng: &mut Rng, family: Family, rays: usize) -> HardCase {
    let eye = if rng.below(3) == 0 {
        unit(rng) * decade(rng, 0.0, 4.0)
    } else {
        DVec3::ZERO
    };
    let n = unit(rng);
    let (u, _) = n.any_orthonormal_pair();
    match family {
        Family::Huge | Family::BelowRounding => {
            let size = decade(rng, 3.0, 9.0);
            // A unit in the last place of the largest coordinate, about.
            let ulp = size * f64::from(f32::EPSILON);
            let height = if family == Family::Huge {
                ulp * decade(rng, 0.6, 4.0)
            } else {
                ulp * decade(rng, -3.0, 0.0)
            };
            let foot = eye - n * height;
            let center = foot + u * size * rng.range_f64(-0.2, 0.2);
            let p = triangle_around(rng, center, n, size);
            case(rng, family, p, eye, rays)
        }
        Family::Sliver => {
            let len = decade(rng, -2.0, 3.0);
            let width = len * decade(rng, -6.0, -2.0);
            let dist = len * decade(rng, -1.0, 1.0);
            let center = eye + unit(rng) * dist;
            let along = unit(rng).cross(n).normalize();
            let side = n.cross(along);
            let t = rng.range_f64(0.1, 0.9);
            let p = [
                center - along * (len * 0.5),
                center + along * (len * 0.5),
                center + along * (len * (t - 0.5)) + side * width,
            ];
            case(rng, family, p, eye, rays)
        }
        Family::Grazing => {
            let dist = decade(rng, -1.0, 3.0);
            let slope = decade(rng, -5.0, -1.0);
            let foot = eye - n * (dist * slope);
            let center = foot + u * dist;
            let size = dist * rng.range_f64(0.05, 0.5);
            let p = triangle_around(rng, center, n, size);
            case(rng, family, p, eye, rays)
        }
        Family::EyeNearPlane => {
            let size = decade(rng, -2.0, 4.0);
            let height = size * decade(rng, -7.0, -2.0);
            let foot = eye - n * height;
            let center = foot + u * size * rng.range_f64(-0.3, 0.3);
            let p = triangle_around(rng, center, n, size);
            case(rng, family, p, eye, rays)
        }
        Family::Known => unreachable!("known cases are not drawn at random"),
    }
}

/// `n` random cases, cycling through [`Family::RANDOM`], `rays` rays each, from
/// `seed`.
pub fn hard_cases(n: u32, rays: usize, seed: u64) -> Vec<HardCase> {
    let mut rng = Rng::new(seed);
    (0..n as usize)
        .map(|i| random_case(&mut rng, Family::RANDOM[i % Family::RANDOM.len()], rays))
        .collect()
}

/// The triangles that once lost hits on the BVH: half of the quad (±10⁶, 0, ±10⁶) seen
/// from one unit above it (beside the diagonal), and a long triangle seen from 0.024 above its plane (rays
/// within 10⁻⁴ radians of it), with `rays` rays each.
pub fn known_cases(rays: usize) -> Vec<HardCase> {
    let mut rng = Rng::new(27);
    let quad = [
        DVec3::new(-1e6, -1.0, -1e6),
        DVec3::new(-1e6, -1.0, 1e6),
        DVec3::new(1e6, -1.0, 1e6),
    ];
    let long = [
        DVec3::new(2.27965, 5.22625, 3.77965),
        DVec3::new(-500.0, 1.0, 0.0),
        DVec3::new(0.0, 0.5, 0.2),
    ];
    let n = (long[1] - long[0]).cross(long[2] - long[0]).normalize();
    let eye = (long[0] + long[1] * 0.2 + long[2]) / 2.2 + n * 0.024;
    vec![
        case(
            &mut rng,
            Family::Known,
            quad,
            DVec3::new(-3.0, 0.0, 3.0),
            rays,
        ),
        case(&mut rng, Family::Known, long, eye, rays),
    ]
}

/// Cast `case`'s rays on `accel` (built over the case's [`HardCase::scene`]) and count
/// against the reference. Each ray is cast both for its nearest hit and as an any-hit
/// (shadow) query; a hit must be the case's triangle.
pub fn run_case<A: Accel>(case: &HardCase, accel: &A) -> HardStats {
    let mut st = HardStats::default();
    let p = case.triangle.p.map(|v| v.as_dvec3());
    let n = (p[1] - p[0]).cross(p[2] - p[0]).normalize();
    for ray in &case.rays {
        st.rays += 1;
        let near = accel.intersect(ray);
        let any = accel.occluded(ray);
        match truth(&case.triangle, ray) {
            Truth::Hit(_) => {
                st.hits += 1;
                match near {
                    Some(h) if any && h.geom_id == Kind::Triangle as u32 => {
                        let dray = DRay::from(ray);
                        let point = dray.org + dray.dir * f64::from(h.t);
                        let scale = p
                            .iter()
                            .map(|v| (*v - dray.org).abs().max_element())
                            .fold(0.0, f64::max);
                        let ulp = scale * f64::from(f32::EPSILON) * 0.5;
                        let off = n.dot(point - p[0]).abs() / ulp;
                        st.worst_plane_ulps = st.worst_plane_ulps.max(off);
                    }
                    _ => st.misses += 1,
                }
            }
            Truth::Miss => st.extra += u64::from(near.is_some() || any),
            Truth::EdgeBand => st.edge_band += 1,
        }
    }
    st
}

impl HardCase {
    /// A scene holding the triangle alone (its camera is never used).
    pub fn scene(&self) -> Scene {
        let camera = Camera {
            from: Vec3::ZERO,
            at: Vec3::NEG_Z,
            up: Vec3::Y,
            angle_deg: 45.0,
            hither: 0.0,
            width: 1,
            height: 1,
        };
        let mut scene = Scene::new(camera);
        scene.materials.push(Default::default());
        scene.geometry.triangles.push(self.triangle, 0);
        scene.geometry.triangle_normals.push(u32::MAX);
        scene
    }
}

/// [`run_case`] as work for [`crate::accel::build`].
struct RunCase<'a>(&'a HardCase);

impl WithAccel for RunCase<'_> {
    type Output = HardStats;
    fn run<A: Accel>(self, accel: &A, _build_ms: f64) -> HardStats {
        run_case(self.0, accel)
    }
}

/// Every case of `cases` on the backend `options` names, by family (in the order of
/// first appearance), with the total last.
pub fn run_cases(
    cases: &[HardCase],
    options: &BackendOptions,
) -> Result<Vec<(Family, HardStats)>, crate::accel::AccelError> {
    let mut by_family: Vec<(Family, HardStats)> = Vec::new();
    for case in cases {
        let st = crate::accel::build(&case.scene(), options, RunCase(case))?;
        match by_family.iter_mut().find(|(f, _)| *f == case.family) {
            Some((_, total)) => total.add(&st),
            None => by_family.push((case.family, st)),
        }
    }
    Ok(by_family)
}
