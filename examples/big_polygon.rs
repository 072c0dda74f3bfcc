//! Writes an NFF scene of one large polygon, for the load-time measurements of
//! docs/performance.md: `cargo run --release --example big_polygon -- KIND N FILE`.
//!
//! - `circle`: a regular polygon of N vertices on the unit circle (its curvature is
//!   below f32's resolution from about 20 000 vertices on, so rounding makes it
//!   slightly concave);
//! - `star`: N vertices alternating between radius 1 and ½;
//! - `lattice`: a strictly convex polygon of at least N vertices with integer
//!   coordinates (its edges are the primitive integer vectors up to some length, in
//!   order of angle), exact in f32;
//! - `lattice40`: the same shape, of N/40 corners, scaled by 40 with 39 vertices along
//!   each edge: convex, N vertices, most of them exactly on an edge (a convex polygon of
//!   a million vertices cannot have f32 coordinates and no three vertices in a line).
//!
//! Coordinates are written with 9 significant digits (integers as integers); the
//! camera looks down on the polygon from +z.

use std::f64::consts::TAU;
use std::fmt::Write as _;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [kind, n, file] = args.as_slice() else {
        eprintln!("usage: big_polygon circle|star|lattice|lattice40 N FILE");
        std::process::exit(2);
    };
    let n: usize = n.parse().expect("N is a whole number");
    let points = match kind.as_str() {
        "circle" => ring(n, |_| 1.0),
        "star" => ring(n, |i| if i % 2 == 0 { 1.0 } else { 0.5 }),
        "lattice" => lattice(n)
            .into_iter()
            .map(|[x, y]| [x as f64, y as f64])
            .collect(),
        "lattice40" => along_edges(&lattice(n / 40), 40),
        _ => {
            eprintln!("unknown kind {kind}: circle, star, lattice or lattice40");
            std::process::exit(2);
        }
    };
    std::fs::write(file, nff(&points)).expect("write the NFF file");
    eprintln!("wrote {file}: one polygon of {} vertices", points.len());
}

/// `n` vertices at equal angles, vertex `i` at radius `r(i)`.
fn ring(n: usize, r: impl Fn(usize) -> f64) -> Vec<[f64; 2]> {
    (0..n)
        .map(|i| {
            let a = TAU * i as f64 / n as f64;
            [r(i) * a.cos(), r(i) * a.sin()]
        })
        .collect()
}

fn gcd(mut a: i64, mut b: i64) -> i64 {
    while b != 0 {
        (a, b) = (b, a % b);
    }
    a
}

/// A strictly convex lattice polygon of at least `n` vertices, centred on the origin:
/// the primitive vectors of coordinates up to `m` (the least `m` that gives `n`), in
/// order of angle, as its edges.
fn lattice(n: usize) -> Vec<[i64; 2]> {
    let mut m = 1;
    let mut dirs = primitive(m);
    while dirs.len() < n {
        m += 1;
        dirs = primitive(m);
    }
    dirs.sort_by(|a, b| {
        let angle = |d: &[i64; 2]| (d[1] as f64).atan2(d[0] as f64);
        angle(a).total_cmp(&angle(b))
    });
    let mut at = [0i64, 0];
    let mut v = Vec::with_capacity(dirs.len());
    for d in dirs {
        v.push(at);
        at = [at[0] + d[0], at[1] + d[1]];
    }
    let len = v.len() as i64;
    let centre = [
        v.iter().map(|p| p[0]).sum::<i64>() / len,
        v.iter().map(|p| p[1]).sum::<i64>() / len,
    ];
    v.iter()
        .map(|p| [p[0] - centre[0], p[1] - centre[1]])
        .collect()
}

/// The primitive integer vectors of coordinates at most `m` in magnitude, all four
/// quadrants.
fn primitive(m: i64) -> Vec<[i64; 2]> {
    let mut dirs = Vec::new();
    for p in 1..=m {
        for q in 0..=m {
            if gcd(p, q) == 1 {
                dirs.extend([[p, q], [-q, p], [-p, -q], [q, -p]]);
            }
        }
    }
    dirs
}

/// `corners` scaled by `k`, with `k − 1` vertices evenly along each edge.
fn along_edges(corners: &[[i64; 2]], k: i64) -> Vec<[f64; 2]> {
    let mut v = Vec::new();
    for (i, a) in corners.iter().enumerate() {
        let b = corners[(i + 1) % corners.len()];
        for s in 0..k {
            let x = k * a[0] + s * (b[0] - a[0]);
            let y = k * a[1] + s * (b[1] - a[1]);
            assert!(x.abs() < 1 << 24 && y.abs() < 1 << 24, "not exact in f32");
            v.push([x as f64, y as f64]);
        }
    }
    v
}

/// The NFF text: a camera above the polygon, a light, a material, the polygon.
fn nff(points: &[[f64; 2]]) -> String {
    let span = points
        .iter()
        .map(|p| p[0].abs().max(p[1].abs()))
        .fold(0.0, f64::max);
    let mut s = String::new();
    let _ = write!(
        s,
        "v\nfrom 0 0 {}\nat 0 0 0\nup 0 1 0\nangle 60\nhither 0.01\nresolution 64 64\n",
        2.2 * span
    );
    let _ = writeln!(
        s,
        "b 0.1 0.1 0.1\nl 0 0 {}\nf 0.8 0.6 0.3 1 0 1 0 1",
        3.0 * span
    );
    let _ = writeln!(s, "p {}", points.len());
    for [x, y] in points {
        let _ = writeln!(s, "{} {} 0", fmt9(*x), fmt9(*y));
    }
    s
}

/// `v` with 9 significant digits, as C's `%.9g` does for these values.
fn fmt9(v: f64) -> String {
    if v == v.trunc() && v.abs() < 1e15 {
        return format!("{}", v as i64);
    }
    let digits = 8 - v.abs().log10().floor() as i32;
    let s = format!("{:.*}", digits.max(0) as usize, v);
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}
