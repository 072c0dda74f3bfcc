//! The `balls` database, also known as the sphereflake (SPD `balls.c`).
//!
//! A sphere of radius ½ at the origin sprouts nine spheres of a third its radius, each
//! touching it: six around its "equator" and three around its "north pole", the
//! directions being the same for every sphere once rotated so that its own parent
//! direction is +Z. Each child sprouts nine more in turn, `size` levels deep, so size
//! factor `n` gives `1 + 9 + … + 9ⁿ = (9ⁿ⁺¹ − 1)/8` spheres. A square beige floor at
//! `z = −½` and three lights complete the scene.
//!
//! The nine unit directions are built as the SPD does: three vectors in the planes of
//! the axes (`(s, s, 0)`, `(s, 0, −s)`, `(0, s, −s)` with `s = 1/√2`) are rotated
//! about `(1, −1, 0)/√2` by `asin(2/√6)`, and that trio is rotated about +Z by 0°,
//! 120° and 240°. A child's centre is its parent's centre plus the rotated direction
//! times `r·(1 + ⅓)` (so the two spheres touch), and the child's own "up" is that
//! offset divided by the same scale. Everything is computed in double precision in
//! the order the SPD's vector library does, row-vector matrices included, so the
//! printed numbers are the SPD's to the last digit.

use super::tx::{IDENTITY, rotate, rotate_axis, transform_coord_w0};
use super::{NffSink, phong_power};
use glam::DVec3;
use rayon::prelude::*;
use std::f64::consts::PI;

/// The SPD program's default size factor (`balls.c`: `size_factor = 4`, 7381 spheres).
pub const DEFAULT_SIZE: u32 = 4;

/// Ratio of a child's radius to its parent's.
const CHILD_RATIO: f64 = 1.0 / 3.0;

/// `v / |v|`, or `v` unchanged when it is zero (`lib_normalize_vector`).
fn normalize(v: DVec3) -> DVec3 {
    let d = (v.x * v.x + v.y * v.y + v.z * v.z).sqrt();
    if d > 0.0 {
        DVec3::new(v.x / d, v.y / d, v.z / d)
    } else {
        v
    }
}

/// `a × b` term by term as the SPD's `CROSS` macro.
fn cross(a: DVec3, b: DVec3) -> DVec3 {
    DVec3::new(
        a.y * b.z - a.z * b.y,
        a.z * b.x - a.x * b.z,
        a.x * b.y - a.y * b.x,
    )
}

/// The nine unit directions of the children of a sphere whose own direction is +Z.
fn child_directions() -> [DVec3; 9] {
    let s = 1.0 / 2.0f64.sqrt();
    let trio = [
        DVec3::new(s, s, 0.0),
        DVec3::new(s, 0.0, -s),
        DVec3::new(0.0, s, -s),
    ];
    let tilt = rotate_axis(
        normalize(DVec3::new(1.0, -1.0, 0.0)),
        (2.0 / 6.0f64.sqrt()).asin(),
    );
    let trio = trio.map(|v| transform_coord_w0(v, &tilt));
    let mut out = [DVec3::ZERO; 9];
    for set in 0..3 {
        let m = rotate(2, set as f64 * 2.0 * PI / 3.0);
        for (k, v) in trio.iter().enumerate() {
            out[set * 3 + k] = transform_coord_w0(*v, &m);
        }
    }
    out
}

/// A sphere of the flake and what its children are grown from: the (nearly unit)
/// direction from its parent, along which their set is turned, and how many levels
/// grow below it.
#[derive(Clone, Copy, Debug)]
struct Node {
    center: DVec3,
    radius: f64,
    dir: DVec3,
    depth: u32,
}

impl Node {
    /// The flake's first sphere at size factor `size`.
    fn root(size: u32) -> Node {
        Node {
            center: DVec3::ZERO,
            radius: 0.5,
            dir: DVec3::new(0.0, 0.0, 1.0),
            depth: size,
        }
    }

    /// The sphere as the database writes it: centre, radius.
    fn sphere(&self) -> (DVec3, f64) {
        (self.center, self.radius)
    }

    /// The spheres of the flake grown from this one, itself included.
    fn subtree_len(&self) -> usize {
        subtree_len(self.depth)
    }

    /// The nine children, in the SPD's order (none when `depth` is 0).
    fn children(&self, dirs: &[DVec3; 9]) -> Option<[Node; 9]> {
        if self.depth == 0 {
            return None;
        }
        let dir = self.dir;
        // The rotation taking +Z to `dir` (the SPD allows for `dir` being a hair short).
        let m = if dir.z >= 0.9999 {
            IDENTITY
        } else if dir.z <= -0.9999 {
            rotate(1, PI)
        } else {
            let z = DVec3::new(0.0, 0.0, 1.0);
            let axis = normalize(cross(z, dir));
            let cos = z.x * dir.x + z.y * dir.y + z.z * dir.z;
            rotate_axis(axis, cos.acos())
        };
        let (center, scale) = (self.center, self.radius * (1.0 + CHILD_RATIO));
        Some(dirs.map(|d| {
            let t = transform_coord_w0(d, &m);
            let c = DVec3::new(
                t.x * scale + center.x,
                t.y * scale + center.y,
                t.z * scale + center.z,
            );
            Node {
                center: c,
                radius: self.radius * CHILD_RATIO,
                dir: DVec3::new(
                    (c.x - center.x) / scale,
                    (c.y - center.y) / scale,
                    (c.z - center.z) / scale,
                ),
                depth: self.depth - 1,
            }
        }))
    }
}

/// The spheres of a subtree `depth` levels deep: `1 + 9 + … + 9^depth`.
fn subtree_len(depth: u32) -> usize {
    (0..=depth).map(|k| 9usize.pow(k)).sum()
}

/// Write the spheres of `node`'s subtree into `out`, which holds exactly that many,
/// parents before their children, depth first, in the SPD's order.
fn grow(node: &Node, dirs: &[DVec3; 9], out: &mut [(DVec3, f64)]) {
    let Some((first, rest)) = out.split_first_mut() else {
        return;
    };
    *first = node.sphere();
    let Some(children) = node.children(dirs) else {
        return;
    };
    let child_len = subtree_len(node.depth - 1);
    for (child, out) in children.iter().zip(rest.chunks_mut(child_len)) {
        grow(child, dirs, out);
    }
}

/// A stretch of the flake's spheres, in its order: one sphere alone (its children
/// follow as pieces of their own) or a whole subtree.
#[derive(Clone, Copy, Debug)]
enum Piece {
    Sphere(Node),
    Subtree(Node),
}

impl Piece {
    /// Its spheres.
    fn len(&self) -> usize {
        match self {
            Piece::Sphere(_) => 1,
            Piece::Subtree(node) => node.subtree_len(),
        }
    }

    /// Write its spheres into `out`, which holds [`Piece::len`] of them.
    fn grow(&self, dirs: &[DVec3; 9], out: &mut [(DVec3, f64)]) {
        match self {
            Piece::Sphere(node) => {
                if let Some(first) = out.first_mut() {
                    *first = node.sphere();
                }
            }
            Piece::Subtree(node) => grow(node, dirs, out),
        }
    }
}

/// The flake grown from `node` as pieces in its order, each subtree of at most
/// `subtree` spheres whole, the spheres above them alone.
fn pieces(node: &Node, dirs: &[DVec3; 9], subtree: usize, out: &mut Vec<Piece>) {
    match node.children(dirs) {
        Some(children) if node.subtree_len() > subtree => {
            out.push(Piece::Sphere(*node));
            for child in &children {
                pieces(child, dirs, subtree, out);
            }
        }
        _ => out.push(Piece::Subtree(*node)),
    }
}

/// How the flake is cut for [`emit_flake`]: spheres handed to the sink at once (at
/// least), and the largest subtree grown whole on one thread.
#[derive(Clone, Copy, Debug)]
struct Batching {
    batch: usize,
    subtree: usize,
}

/// [`Batching`] for a pool of any size: batches of 65 536, cut into pieces of at most
/// 1024 spheres (subtrees of 820), so that each thread has several.
const BATCHING: Batching = Batching {
    batch: 1 << 16,
    subtree: 1 << 10,
};

/// Hand the spheres of the flake at size factor `size` to `w` in batches, in the SPD's
/// order; the pieces of a batch are grown in parallel on the current rayon pool.
fn emit_flake(size: u32, w: &mut impl NffSink, batching: Batching) {
    let dirs = child_directions();
    let mut plan = Vec::new();
    pieces(&Node::root(size), &dirs, batching.subtree, &mut plan);
    let mut spheres = Vec::new();
    let mut rest = &plan[..];
    while !rest.is_empty() {
        let (batch, after) = rest.split_at(batch_end(rest, batching.batch));
        grow_batch(batch, &dirs, &mut spheres);
        w.spheres(&spheres);
        rest = after;
    }
}

/// How many of the first pieces make a batch: the fewest that hold `batch` spheres
/// (all of them if they hold fewer), and at least one.
fn batch_end(pieces: &[Piece], batch: usize) -> usize {
    let mut spheres = 0;
    for (k, piece) in pieces.iter().enumerate() {
        spheres += piece.len();
        if spheres >= batch {
            return k + 1;
        }
    }
    pieces.len()
}

/// The spheres of `pieces`, in order, into `out` (its old contents dropped); the
/// pieces are grown in parallel.
fn grow_batch(pieces: &[Piece], dirs: &[DVec3; 9], out: &mut Vec<(DVec3, f64)>) {
    let len = pieces.iter().map(Piece::len).sum();
    out.clear();
    out.resize(len, (DVec3::ZERO, 0.0));
    let mut slots = Vec::with_capacity(pieces.len());
    let mut free = &mut out[..];
    for piece in pieces {
        let (slot, after) = std::mem::take(&mut free).split_at_mut(piece.len());
        slots.push((piece, slot));
        free = after;
    }
    slots
        .into_par_iter()
        .for_each(|(piece, slot)| piece.grow(dirs, slot));
}

/// Write the database at size factor `size`.
pub fn generate(size: u32, w: &mut impl NffSink) {
    // Radius of the sphere that would enclose the whole flake.
    let radius = 1.0;
    w.background(DVec3::new(0.078, 0.361, 0.753));
    w.viewpoint(
        DVec3::new(2.1, 1.3, 1.7),
        DVec3::ZERO,
        DVec3::new(0.0, 0.0, 1.0),
        45.0,
        0.01,
        (512, 512),
    );
    w.light(DVec3::new(4.0, 3.0, 2.0));
    w.light(DVec3::new(1.0, -4.0, 4.0));
    w.light(DVec3::new(-3.0, 1.0, 5.0));
    // Beige floor.
    w.fill(
        DVec3::new(1.0, 0.75, 0.33),
        0.8,
        0.0,
        phong_power(0.0),
        0.0,
        1.0,
    );
    let (x, y, z) = (12.0 * radius, 12.0 * radius, -radius / 2.0);
    w.polygon(&[
        DVec3::new(x, y, z),
        DVec3::new(-x, y, z),
        DVec3::new(-x, -y, z),
        DVec3::new(x, -y, z),
    ]);
    // Mirrored spheres.
    w.fill(
        DVec3::new(1.0, 0.9, 0.7),
        0.5,
        0.5,
        phong_power(37.0),
        0.0,
        1.0,
    );
    // In batches, which a scene builder makes in parallel.
    emit_flake(size, w, BATCHING);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spd::NffWriter;
    use std::path::Path;

    fn sphere_count(n: u32) -> usize {
        (9usize.pow(n + 1) - 1) / 8
    }

    /// The spheres a generator hands over, and how many in each call.
    #[derive(Default)]
    struct Collected {
        spheres: Vec<(DVec3, f64)>,
        calls: Vec<usize>,
    }

    impl NffSink for Collected {
        fn viewpoint(&mut self, _: DVec3, _: DVec3, _: DVec3, _: f64, _: f64, _: (i32, i32)) {}
        fn background(&mut self, _: DVec3) {}
        fn light(&mut self, _: DVec3) {}
        fn fill(&mut self, _: DVec3, _: f64, _: f64, _: f64, _: f64, _: f64) {}
        fn sphere(&mut self, center: DVec3, radius: f64) {
            self.spheres.push((center, radius));
        }
        fn spheres(&mut self, spheres: &[(DVec3, f64)]) {
            self.spheres.extend_from_slice(spheres);
            self.calls.push(spheres.len());
        }
        fn cone(&mut self, _: DVec3, _: f64, _: DVec3, _: f64) {}
        fn polygon(&mut self, _: &[DVec3]) {}
        fn polypatch(&mut self, _: &[DVec3], _: &[DVec3]) {}
    }

    /// The flake at size factor `size` as [`generate`] hands it over.
    fn flake(size: u32, batching: Batching) -> Collected {
        let mut out = Collected::default();
        emit_flake(size, &mut out, batching);
        out
    }

    /// The SPD's recursion as `balls.c` writes it, one sphere after the other: what
    /// the flake's batches must hand over, bit for bit.
    fn spd_flake(size: u32) -> Vec<(DVec3, f64)> {
        fn recurse(node: &Node, dirs: &[DVec3; 9], out: &mut Vec<(DVec3, f64)>) {
            out.push(node.sphere());
            for child in node.children(dirs).iter().flatten() {
                recurse(child, dirs, out);
            }
        }
        let mut out = Vec::new();
        recurse(&Node::root(size), &child_directions(), &mut out);
        out
    }

    /// Each sphere's nesting depth (0 for the root), in the flake's order.
    fn levels(size: u32) -> Vec<u32> {
        fn recurse(depth: u32, level: u32, out: &mut Vec<u32>) {
            out.push(level);
            if depth > 0 {
                for _ in 0..9 {
                    recurse(depth - 1, level + 1, out);
                }
            }
        }
        let mut out = Vec::new();
        recurse(size, 0, &mut out);
        out
    }

    fn bits(spheres: &[(DVec3, f64)]) -> Vec<[u64; 4]> {
        spheres
            .iter()
            .map(|(c, r)| [c.x, c.y, c.z, *r].map(f64::to_bits))
            .collect()
    }

    #[test]
    fn sphere_counts_follow_the_geometric_series() {
        assert_eq!(sphere_count(4), 7381);
        for n in 0..=4 {
            assert_eq!(subtree_len(n), sphere_count(n), "size {n}");
            assert_eq!(
                flake(n, BATCHING).spheres.len(),
                sphere_count(n),
                "size {n}"
            );
        }
    }

    /// However the flake is cut into batches and pieces, and however many threads grow
    /// them, the spheres are the recursion's, in its order, bit for bit.
    #[test]
    fn batches_grown_in_parallel_hand_over_the_spd_order() {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(4)
            .build()
            .unwrap();
        for size in 0..=4 {
            let want = bits(&spd_flake(size));
            for (batch, subtree) in [
                (1, 1),
                (1, 10),
                (7, 1),
                (30, 10),
                (100, 91),
                (1 << 16, 1 << 10),
            ] {
                let got = pool.install(|| flake(size, Batching { batch, subtree }));
                let what = format!("size {size}, batch {batch}, subtree {subtree}");
                assert_eq!(bits(&got.spheres), want, "{what}");
                // Every call but the last holds a batch, and less than a piece more.
                let (last, full) = got.calls.split_last().unwrap();
                assert!(
                    full.iter().all(|&n| n >= batch && n < batch + subtree),
                    "{what}"
                );
                assert!(*last > 0 && *last < batch + subtree, "{what}");
            }
        }
        // Several batches of several pieces each.
        let got = pool.install(|| {
            flake(
                4,
                Batching {
                    batch: 100,
                    subtree: 91,
                },
            )
        });
        // The root, its first child and two subtrees of 91; two subtrees; ...; the
        // second child and a subtree after four pairs of subtrees.
        assert_eq!(got.calls[..5], [184, 182, 182, 182, 183]);
        assert_eq!(got.calls.len(), 41);
    }

    #[test]
    fn pieces_are_whole_subtrees_below_the_limit_and_single_spheres_above() {
        let dirs = child_directions();
        let mut plan = Vec::new();
        pieces(&Node::root(3), &dirs, 10, &mut plan);
        // The root and its nine children alone, then 81 subtrees of 10.
        let alone = plan
            .iter()
            .filter(|p| matches!(p, Piece::Sphere(_)))
            .count();
        assert_eq!((alone, plan.len()), (10, 91));
        assert_eq!(plan.iter().map(Piece::len).sum::<usize>(), sphere_count(3));
        assert!(plan.iter().all(|p| p.len() <= 10));
        assert_eq!(batch_end(&plan, 25), 5); // 1 + 1 + 10 + 10 + 10 spheres
        assert_eq!(batch_end(&plan, 1 << 20), plan.len());
    }

    #[test]
    fn child_directions_are_unit_and_distinct() {
        let d = child_directions();
        for (i, a) in d.iter().enumerate() {
            assert!((a.length() - 1.0).abs() < 1e-12, "{a}");
            for b in &d[i + 1..] {
                assert!(a.distance(*b) > 0.5, "{a} {b}");
            }
        }
        // Six around the equator, three on the upper hemisphere.
        assert_eq!(d.iter().filter(|v| v.z.abs() < 1e-12).count(), 6);
        assert_eq!(d.iter().filter(|v| v.z > 0.5).count(), 3);
    }

    #[test]
    fn every_child_touches_its_parent() {
        let balls = flake(3, BATCHING).spheres;
        let levels = levels(3);
        assert_eq!(balls.len(), levels.len());
        // Depth-first order: a sphere's parent is the last sphere one level up.
        let mut stack: Vec<(DVec3, f64)> = Vec::new();
        for (&(center, radius), &level) in balls.iter().zip(&levels) {
            stack.truncate(level as usize);
            if let Some(&(pc, pr)) = stack.last() {
                assert!((radius - pr / 3.0).abs() <= 1e-15 * pr);
                let d = center.distance(pc);
                let want = pr + radius;
                assert!((d - want).abs() <= 1e-9 * want, "{d} vs {want}");
                // Children grow away from the grandparent: never back into it.
                if stack.len() >= 2 {
                    let (gc, gr) = stack[stack.len() - 2];
                    assert!(center.distance(gc) > gr + radius);
                }
            }
            stack.push((center, radius));
        }
    }

    #[test]
    fn output_parses_with_the_expected_counts() {
        for n in 1..=2 {
            let mut w = NffWriter::new();
            generate(n, &mut w);
            let text = w.finish();
            let scene = crate::load::nff::parse_str(&text, Path::new("x")).unwrap();
            assert_eq!(scene.geometry.spheres().len(), sphere_count(n));
            assert_eq!(scene.load_stats.polygons, 1);
            assert_eq!(scene.lights.len(), 3);
            assert_eq!(scene.materials.len(), 2);
        }
    }

    #[test]
    fn phong_power_follows_the_half_angle() {
        assert_eq!(phong_power(0.0), 100_000.0);
        assert_eq!(phong_power(90.0), 1.0);
        // cos(ang)^power = 1/2.
        for ang in [5.0, 10.0, 37.0, 60.0] {
            let p = phong_power(ang);
            let half = (ang * PI / 180.0f64).cos().powf(p);
            assert!((half - 0.5).abs() < 1e-12, "{ang}: {p}");
        }
        assert_eq!(crate::spd::fmt_g(phong_power(37.0)), "3.0827");
    }
}
