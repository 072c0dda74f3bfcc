//! Writes the procedural assets of the texture showcase scenes, so that nothing is
//! downloaded: `cargo run --release --example texture_assets -- scenes/textured`.
//!
//! - `sky.png`: a 512 × 256 latitude-longitude environment (sky gradient, a sun, a
//!   checkered ground, and coloured markers on the horizon: red at +x, blue at −z,
//!   green at +z, yellow at −x) and `sky_cross.png`, the same as a 4:3 cube cross;
//! - `tiles.png` (colour) and `tiles_height.png` (height) for bump mapping;
//! - `vase.obj` + `vase.mtl`: a lathed vase with texture coordinates and normals whose
//!   material uses both maps.
//!
//! The same functions make `large.obj` (`-- DIR large N`): an N × N-quad height-field
//! surface (2N² triangles) for load-time measurements; it is not committed.

use std::f32::consts::{PI, TAU};
use std::fmt::Write as _;
use std::path::Path;

type Rgb = [f32; 3];

fn save(path: &Path, w: u32, h: u32, f: impl Fn(u32, u32) -> Rgb) {
    let mut img = image::RgbImage::new(w, h);
    for (x, y, p) in img.enumerate_pixels_mut() {
        let c = f(x, y);
        // Linear to sRGB.
        let enc = |v: f32| {
            let v = v.clamp(0.0, 1.0);
            let s = if v <= 0.003_130_8 {
                12.92 * v
            } else {
                1.055 * v.powf(1.0 / 2.4) - 0.055
            };
            (s * 255.0 + 0.5) as u8
        };
        *p = image::Rgb([enc(c[0]), enc(c[1]), enc(c[2])]);
    }
    img.save(path).expect("write PNG");
    eprintln!("wrote {}", path.display());
}

/// The environment's radiance in unit direction `d` (+y up).
fn sky(d: [f32; 3]) -> Rgb {
    let [x, y, z] = d;
    // Markers on the horizon, one per axis direction.
    let markers: [([f32; 3], Rgb); 4] = [
        ([1.0, 0.0, 0.0], [1.0, 0.1, 0.1]),
        ([0.0, 0.0, -1.0], [0.1, 0.2, 1.0]),
        ([0.0, 0.0, 1.0], [0.1, 0.9, 0.1]),
        ([-1.0, 0.0, 0.0], [1.0, 0.85, 0.1]),
    ];
    for (m, c) in markers {
        let cos = x * m[0] + y * m[1] + z * m[2];
        if cos > 0.985 {
            return c;
        }
    }
    let sun = [0.3f32, 0.8, -0.52];
    let sl = (sun[0] * sun[0] + sun[1] * sun[1] + sun[2] * sun[2]).sqrt();
    if (x * sun[0] + y * sun[1] + z * sun[2]) / sl > 0.995 {
        return [4.0, 3.6, 3.0];
    }
    if y >= 0.0 {
        let t = y.powf(0.6);
        [0.75 - 0.55 * t, 0.82 - 0.45 * t, 0.95 - 0.15 * t]
    } else {
        // A checkered ground plane one unit below the viewer.
        let s = -1.0 / y;
        let (gx, gz) = (x * s, z * s);
        let check = ((gx.floor() as i64 + gz.floor() as i64) & 1) == 0;
        let fade = (-y * 4.0).min(1.0);
        let g = if check { 0.45 } else { 0.12 };
        let v = g * fade + 0.35 * (1.0 - fade);
        [v, v * 0.95, v * 0.85]
    }
}

fn normalize(v: [f32; 3]) -> [f32; 3] {
    let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    [v[0] / l, v[1] / l, v[2] / l]
}

fn tiles(u: f32, v: f32) -> (Rgb, f32) {
    // 4 × 4 tiles per unit with 6 % grout.
    let (fu, fv) = ((u * 4.0).fract(), (v * 4.0).fract());
    let edge = fu.min(1.0 - fu).min(fv.min(1.0 - fv));
    let grout = 0.06;
    let (iu, iv) = ((u * 4.0) as i32, (v * 4.0) as i32);
    let tone = 0.15 * (((iu * 7 + iv * 13) % 5) as f32 / 4.0);
    if edge < grout {
        ([0.55, 0.53, 0.5], 0.0)
    } else {
        // Bevelled tile: height rises over the first 6 % past the grout.
        let h = ((edge - grout) / 0.06).min(1.0);
        ([0.62 + tone, 0.22 + tone * 0.5, 0.12], h)
    }
}

fn lathe_obj(dir: &Path) {
    // Profile r(t), y(t) of a vase, t in [0, 1].
    let profile = |t: f32| -> (f32, f32) {
        let y = 2.0 * t;
        let r = 0.55 + 0.3 * (PI * (t * 1.6 - 0.15)).sin() - 0.12 * t;
        (r, y)
    };
    let (nu, nv) = (64usize, 48usize);
    let mut obj = String::from("# A lathed vase with texture coordinates and normals.\n");
    obj.push_str("mtllib vase.mtl\n");
    for j in 0..=nv {
        let t = j as f32 / nv as f32;
        let (r, y) = profile(t);
        for i in 0..=nu {
            let a = TAU * i as f32 / nu as f32;
            let _ = writeln!(obj, "v {} {} {}", r * a.sin(), y, r * a.cos());
        }
    }
    for j in 0..=nv {
        for i in 0..=nu {
            let _ = writeln!(obj, "vt {} {}", i as f32 / nu as f32, j as f32 / nv as f32);
        }
    }
    for j in 0..=nv {
        let t = j as f32 / nv as f32;
        let e = 1e-3;
        let (r0, y0) = profile((t - e).max(0.0));
        let (r1, y1) = profile((t + e).min(1.0));
        // Outward normal of the profile: (dy, -dr) in the (r, y) plane.
        let (dr, dy) = (r1 - r0, y1 - y0);
        for i in 0..=nu {
            let a = TAU * i as f32 / nu as f32;
            let n = normalize([dy * a.sin(), -dr, dy * a.cos()]);
            let _ = writeln!(obj, "vn {} {} {}", n[0], n[1], n[2]);
        }
    }
    obj.push_str("usemtl tiles\n");
    let id = |i: usize, j: usize| j * (nu + 1) + i + 1;
    for j in 0..nv {
        for i in 0..nu {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            let _ = writeln!(obj, "f {a}/{a}/{a} {b}/{b}/{b} {c}/{c}/{c} {d}/{d}/{d}");
        }
    }
    std::fs::write(dir.join("vase.obj"), obj).expect("write OBJ");
    std::fs::write(
        dir.join("vase.mtl"),
        "# Terracotta tiles with bevelled edges.\nnewmtl tiles\nKa 1 1 1\nKd 1 1 1\n\
         Ks 0.25 0.25 0.25\nNs 40\nillum 2\nmap_Kd -s 3 2 tiles.png\n\
         bump -bm 0.008 -s 3 2 tiles_height.png\n",
    )
    .expect("write MTL");
    eprintln!("wrote {}", dir.join("vase.obj").display());
}

/// An n × n-quad height field over [-1, 1]², 2n² triangles, with `vt`.
fn large_obj(dir: &Path, n: usize) {
    use std::io::Write;
    let path = dir.join("large.obj");
    let mut f = std::io::BufWriter::new(std::fs::File::create(&path).expect("create"));
    let h = |x: f32, z: f32| 0.1 * (6.0 * x).sin() * (5.0 * z).cos();
    for j in 0..=n {
        for i in 0..=n {
            let (x, z) = (
                2.0 * i as f32 / n as f32 - 1.0,
                2.0 * j as f32 / n as f32 - 1.0,
            );
            writeln!(f, "v {x} {} {z}", h(x, z)).unwrap();
        }
    }
    for j in 0..=n {
        for i in 0..=n {
            writeln!(f, "vt {} {}", i as f32 / n as f32, j as f32 / n as f32).unwrap();
        }
    }
    let id = |i: usize, j: usize| j * (n + 1) + i + 1;
    for j in 0..n {
        for i in 0..n {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            writeln!(f, "f {a}/{a} {d}/{d} {c}/{c}").unwrap();
            writeln!(f, "f {a}/{a} {c}/{c} {b}/{b}").unwrap();
        }
    }
    f.flush().unwrap();
    eprintln!("wrote {} ({} triangles)", path.display(), 2 * n * n);
}

fn main() {
    let mut args = std::env::args().skip(1);
    let dir = args.next().unwrap_or_else(|| "scenes/textured".into());
    let dir = Path::new(&dir);
    std::fs::create_dir_all(dir).expect("create the directory");
    if args.next().as_deref() == Some("large") {
        let n = args.next().map_or(710, |s| s.parse().expect("N"));
        large_obj(dir, n);
        return;
    }
    let (w, h) = (512u32, 256u32);
    save(&dir.join("sky.png"), w, h, |x, y| {
        let u = (x as f32 + 0.5) / w as f32;
        let v = 1.0 - (y as f32 + 0.5) / h as f32;
        // Inverse of u = ½ + atan2(x, −z)/2π, v = ½ + asin(y)/π.
        let phi = (u - 0.5) * TAU;
        let lat = (v - 0.5) * PI;
        sky([lat.cos() * phi.sin(), lat.sin(), -lat.cos() * phi.cos()])
    });
    let f = 128u32;
    save(&dir.join("sky_cross.png"), 4 * f, 3 * f, |x, y| {
        let (c, r) = (x / f, y / f);
        let s = 2.0 * ((x % f) as f32 + 0.5) / f as f32 - 1.0;
        let t = 1.0 - 2.0 * ((y % f) as f32 + 0.5) / f as f32;
        // (right, up, forward) of each face; see emray::scene::texture.
        let d = match (c, r) {
            (0, 1) => [-1.0, t, -s],
            (1, 1) => [s, t, -1.0],
            (2, 1) => [1.0, t, s],
            (3, 1) => [-s, t, 1.0],
            (1, 0) => [s, 1.0, t],
            (1, 2) => [s, -1.0, -t],
            _ => return [0.0; 3],
        };
        sky(normalize(d))
    });
    let n = 256u32;
    let uv = |x: u32, y: u32| {
        (
            (x as f32 + 0.5) / n as f32,
            1.0 - (y as f32 + 0.5) / n as f32,
        )
    };
    save(&dir.join("tiles.png"), n, n, |x, y| {
        let (u, v) = uv(x, y);
        tiles(u, v).0
    });
    // Heights are data: stored so that the sRGB encoding of `save` is undone by the
    // linear read (the value written is the height itself).
    let mut img = image::GrayImage::new(n, n);
    for (x, y, p) in img.enumerate_pixels_mut() {
        let (u, v) = uv(x, y);
        *p = image::Luma([(tiles(u, v).1 * 255.0 + 0.5) as u8]);
    }
    img.save(dir.join("tiles_height.png")).expect("write PNG");
    lathe_obj(dir);
}
