//! The Standard Procedural Databases (Eric Haines, "A Proposal for Standard Graphics
//! Environments", IEEE CG&A 1987; SPD 3.14) as built-in generators.
//!
//! Each database writes NFF through [`NffWriter`] exactly as the SPD programs' default
//! NFF output does (curved primitives, not tessellated): the same entities in the same
//! order, every number printed with C's `%g` ([`fmt_g`]), computed in double precision.
//! The same entities can also go to any other [`NffSink`] ([`Database::emit`]): the
//! job builds the scene from them without the text (`job::spd_scene`).

mod balls;
mod count;
mod gears;
mod jacks;
mod lattice;
mod mount;
mod printed;
mod rings;
mod shells;
mod sink;
mod sombrero;
mod teapot;
mod tetra;
mod tree;
mod tx;

pub use count::PrimCount;
pub(crate) use printed::{g_f32, g_f64};
pub use sink::NffSink;

use glam::DVec3;
use std::fmt::Write;

/// C's `printf("%g", x)`: six significant digits, trailing zeros removed, exponent
/// form when the exponent is below −4 or at least 6 (two exponent digits at least);
/// `-0` for negative zero, as glibc prints it.
pub fn fmt_g(x: f64) -> String {
    const P: i32 = 6;
    if x == 0.0 {
        return if x.is_sign_negative() {
            "-0".into()
        } else {
            "0".into()
        };
    }
    if !x.is_finite() {
        return if x.is_nan() {
            "nan".into()
        } else if x > 0.0 {
            "inf".into()
        } else {
            "-inf".into()
        };
    }
    // The exponent after rounding to P significant digits.
    let sci = format!("{:.*e}", (P - 1) as usize, x);
    let (mant, exp) = sci.split_once('e').expect("exponent form");
    let exp: i32 = exp.parse().expect("exponent");
    if (-4..P).contains(&exp) {
        let s = format!("{:.*}", (P - 1 - exp) as usize, x);
        strip_zeros(&s).to_string()
    } else {
        let m = strip_zeros(mant);
        let sign = if exp < 0 { '-' } else { '+' };
        format!("{m}e{sign}{:02}", exp.abs())
    }
}

fn strip_zeros(s: &str) -> &str {
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.')
    } else {
        s
    }
}

/// The SPD library's Phong exponent for a highlight of half-angle `ang` degrees: the
/// power whose cosine lobe falls to ½ at `ang` (100000 for 0°, 1 from 90° on).
pub(crate) fn phong_power(ang: f64) -> f64 {
    let a = std::f64::consts::PI * ang / 180.0;
    if a <= 0.0 {
        100_000.0
    } else if a >= std::f64::consts::FRAC_PI_2 {
        1.0
    } else {
        0.5f64.ln() / a.cos().ln()
    }
}

/// Writes NFF entities in the SPD library's formats.
#[derive(Debug, Default)]
pub struct NffWriter {
    out: String,
}

impl NffWriter {
    /// An empty writer.
    pub fn new() -> Self {
        Self::default()
    }

    /// The text written so far.
    pub fn finish(self) -> String {
        self.out
    }

    fn nums(&mut self, v: &[f64]) {
        for (i, x) in v.iter().enumerate() {
            if i > 0 {
                self.out.push(' ');
            }
            self.out.push_str(&fmt_g(*x));
        }
        self.out.push('\n');
    }

    fn vec(&mut self, v: DVec3) {
        self.nums(&[v.x, v.y, v.z]);
    }

    /// `v` block: from, at, up, angle, hither, resolution.
    pub fn viewpoint(
        &mut self,
        from: DVec3,
        at: DVec3,
        up: DVec3,
        angle: f64,
        hither: f64,
        res: (i32, i32),
    ) {
        self.out.push_str("v\nfrom ");
        self.vec(from);
        self.out.push_str("at ");
        self.vec(at);
        self.out.push_str("up ");
        self.vec(up);
        self.out.push_str("angle ");
        self.nums(&[angle]);
        self.out.push_str("hither ");
        self.nums(&[hither]);
        let _ = writeln!(self.out, "resolution {} {}", res.0, res.1);
    }

    /// `b r g b`.
    pub fn background(&mut self, rgb: DVec3) {
        self.out.push_str("b ");
        self.vec(rgb);
    }

    /// `l x y z` (the SPD writes lights without colour).
    pub fn light(&mut self, pos: DVec3) {
        self.out.push_str("l ");
        self.vec(pos);
    }

    /// `f r g b Kd Ks Shine T ior`.
    #[allow(clippy::too_many_arguments)]
    pub fn fill(&mut self, rgb: DVec3, kd: f64, ks: f64, shine: f64, t: f64, ior: f64) {
        self.out.push_str("f ");
        self.nums(&[rgb.x, rgb.y, rgb.z, kd, ks, shine, t, ior]);
    }

    /// `s x y z r`.
    pub fn sphere(&mut self, center: DVec3, radius: f64) {
        self.out.push_str("s ");
        self.nums(&[center.x, center.y, center.z, radius]);
    }

    /// `c` on one line: base, base radius, apex, apex radius.
    pub fn cone(&mut self, base: DVec3, base_radius: f64, apex: DVec3, apex_radius: f64) {
        self.out.push_str("c ");
        self.nums(&[
            base.x,
            base.y,
            base.z,
            base_radius,
            apex.x,
            apex.y,
            apex.z,
            apex_radius,
        ]);
    }

    /// `p n` and its vertices, one per line.
    pub fn polygon(&mut self, verts: &[DVec3]) {
        let _ = writeln!(self.out, "p {}", verts.len());
        for v in verts {
            self.vec(*v);
        }
    }

    /// `pp n` and its vertices with normals, one pair per line.
    pub fn polypatch(&mut self, verts: &[DVec3], normals: &[DVec3]) {
        let _ = writeln!(self.out, "pp {}", verts.len());
        for (v, n) in verts.iter().zip(normals) {
            self.nums(&[v.x, v.y, v.z, n.x, n.y, n.z]);
        }
    }

    /// A raw line (for a comment the SPD program prints, if any).
    pub fn raw(&mut self, line: &str) {
        self.out.push_str(line);
        self.out.push('\n');
    }
}

/// How two NFF texts compare, token by token.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct NffComparison {
    /// Whether the texts are byte for byte equal.
    pub identical: bool,
    /// Tokens compared.
    pub tokens: usize,
    /// Numeric tokens whose text differs but whose values agree within the printed
    /// precision.
    pub near: usize,
    /// The first disagreement: `line: ours vs theirs`, if any.
    pub first_difference: Option<String>,
    /// Largest difference between numbers, relative to their magnitude (or absolute
    /// below 1e-9).
    pub max_rel: f64,
}

/// Compare our NFF with a reference, entity by entity: every token equal, or both
/// numbers equal within `%g`'s six significant digits (relative 1e-5, or 1e-9 absolute
/// for values that are rounding noise around zero).
pub fn compare_nff(ours: &str, theirs: &str) -> NffComparison {
    let mut c = NffComparison {
        identical: ours == theirs,
        ..Default::default()
    };
    let tok = |s: &str| -> Vec<(usize, String)> {
        s.lines()
            .enumerate()
            .flat_map(|(i, l)| l.split_whitespace().map(move |t| (i + 1, t.to_string())))
            .collect()
    };
    let (a, b) = (tok(ours), tok(theirs));
    c.tokens = a.len().max(b.len());
    for i in 0..c.tokens {
        let (la, ta) = a.get(i).cloned().unwrap_or((0, "<end>".into()));
        let (lb, tb) = b.get(i).cloned().unwrap_or((0, "<end>".into()));
        if ta == tb {
            continue;
        }
        let same = match (ta.parse::<f64>(), tb.parse::<f64>()) {
            (Ok(x), Ok(y)) => {
                let d = (x - y).abs();
                let rel = if d < 1e-9 {
                    0.0
                } else {
                    d / x.abs().max(y.abs())
                };
                c.max_rel = c.max_rel.max(rel);
                rel <= 1e-5
            }
            _ => false,
        };
        if same {
            c.near += 1;
        } else if c.first_difference.is_none() {
            c.first_difference = Some(format!(
                "token {i}: ours line {la} '{ta}' vs theirs line {lb} '{tb}'"
            ));
        }
    }
    c
}

/// A size factor a database cannot be generated at.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("size factor {size} out of range for {database} (1 to {max})")]
pub struct SizeError {
    /// The database's name.
    pub database: &'static str,
    /// The size asked for.
    pub size: u32,
    /// The largest size it accepts ([`Database::max_size`]).
    pub max: u32,
}

/// An `spd:NAME[?size=N]` scene name that cannot be generated.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{spec}: {reason}")]
pub struct SpecError {
    /// The scene name as given.
    pub spec: String,
    /// What is wrong with it.
    pub reason: SpecReason,
}

/// What is wrong with an `spd:` scene name.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum SpecReason {
    /// No database has this name.
    #[error("unknown database '{0}' (one of {names})", names = Database::ALL.map(|d| d.name()).join(", "))]
    UnknownDatabase(String),
    /// Something other than `?size=N` follows the name.
    #[error("expected '?size=N' after the database name")]
    NoSize,
    /// The size is not a whole number.
    #[error("size '{0}' is not a whole number")]
    SizeNotWhole(String),
    /// The size is out of the database's range.
    #[error(transparent)]
    Size(SizeError),
}

/// The databases.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Database {
    /// Sphereflake.
    Balls,
    /// Meshed gears.
    Gears,
    /// Jacks (cylinders and spheres).
    Jacks,
    /// Lattice of spheres and cylinders.
    Lattice,
    /// Fractal mountain with four glass spheres.
    Mount,
    /// Rings of spheres and cylinders.
    Rings,
    /// Spiral shell of spheres.
    Shells,
    /// Sombrero height field.
    Sombrero,
    /// Utah teapot on a checkerboard.
    Teapot,
    /// Sierpinski tetrahedron.
    Tetra,
    /// Tree of cones and spheres.
    Tree,
}

impl Database {
    /// Every database, in alphabetical order.
    pub const ALL: [Database; 11] = [
        Database::Balls,
        Database::Gears,
        Database::Jacks,
        Database::Lattice,
        Database::Mount,
        Database::Rings,
        Database::Shells,
        Database::Sombrero,
        Database::Teapot,
        Database::Tetra,
        Database::Tree,
    ];

    /// Its name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Database::Balls => "balls",
            Database::Gears => "gears",
            Database::Jacks => "jacks",
            Database::Lattice => "lattice",
            Database::Mount => "mount",
            Database::Rings => "rings",
            Database::Shells => "shells",
            Database::Sombrero => "sombrero",
            Database::Teapot => "teapot",
            Database::Tetra => "tetra",
            Database::Tree => "tree",
        }
    }

    /// The database called `name`.
    pub fn from_name(name: &str) -> Option<Database> {
        Database::ALL.into_iter().find(|d| d.name() == name)
    }

    /// The SPD program's default size factor.
    pub fn default_size(self) -> u32 {
        match self {
            Database::Balls => balls::DEFAULT_SIZE,
            Database::Gears => gears::DEFAULT_SIZE,
            Database::Jacks => jacks::DEFAULT_SIZE,
            Database::Lattice => lattice::DEFAULT_SIZE,
            Database::Mount => mount::DEFAULT_SIZE,
            Database::Rings => rings::DEFAULT_SIZE,
            Database::Shells => shells::DEFAULT_SIZE,
            Database::Sombrero => sombrero::DEFAULT_SIZE,
            Database::Teapot => teapot::DEFAULT_SIZE,
            Database::Tetra => tetra::DEFAULT_SIZE,
            Database::Tree => tree::DEFAULT_SIZE,
        }
    }

    /// The largest size factor emray accepts: the largest whose scene renders in less
    /// than 2 GB (peak resident memory of `emray render spd:NAME?size=N --res 64x64` on
    /// the BVH backend, which needs more than Embree; measured, see docs/nff.md), except
    /// balls, whose size 8 (48.4 million spheres) is the production-scale test; a job
    /// refuses a database over its memory limit before generating it.
    pub fn max_size(self) -> u32 {
        match self {
            Database::Balls => 8,
            Database::Gears => 24,
            Database::Jacks => 7,
            Database::Lattice => 118,
            Database::Mount => 11,
            Database::Rings => 72,
            Database::Shells => 15,
            Database::Sombrero => 7,
            Database::Teapot => 340,
            Database::Tetra => 11,
            Database::Tree => 21,
        }
    }

    /// Parse a scene name of the form `spd:NAME` or `spd:NAME?size=N`; `Ok(None)` when
    /// `spec` does not start with `spd:`.
    pub fn parse_spec(spec: &str) -> Result<Option<(Database, u32)>, SpecError> {
        let Some(rest) = spec.strip_prefix("spd:") else {
            return Ok(None);
        };
        let (name, query) = match rest.split_once('?') {
            Some((n, q)) => (n, Some(q)),
            None => (rest, None),
        };
        let spec_error = |reason| SpecError {
            spec: spec.to_string(),
            reason,
        };
        let db = Database::from_name(name)
            .ok_or_else(|| spec_error(SpecReason::UnknownDatabase(name.to_string())))?;
        let size = match query {
            None => db.default_size(),
            Some(q) => {
                let v = q
                    .strip_prefix("size=")
                    .ok_or_else(|| spec_error(SpecReason::NoSize))?;
                v.parse::<u32>()
                    .map_err(|_| spec_error(SpecReason::SizeNotWhole(v.to_string())))?
            }
        };
        db.check_size(size)
            .map_err(|e| spec_error(SpecReason::Size(e)))?;
        Ok(Some((db, size)))
    }

    /// Refuse size factors outside `1..=max_size()`.
    pub fn check_size(self, size: u32) -> Result<(), SizeError> {
        if size == 0 || size > self.max_size() {
            return Err(SizeError {
                database: self.name(),
                size,
                max: self.max_size(),
            });
        }
        Ok(())
    }

    /// The NFF text of the database at size factor `size`.
    pub fn generate(self, size: u32) -> String {
        let mut w = NffWriter::new();
        self.emit(size, &mut w);
        w.finish()
    }

    /// What the database holds at size factor `size` (its primitives and resolution),
    /// counted by running the generator into a [`PrimCount`]: no text, no scene.
    pub fn count(self, size: u32) -> PrimCount {
        let mut count = PrimCount::default();
        self.emit(size, &mut count);
        count
    }

    /// Send the database's entities at size factor `size` to `sink`.
    pub fn emit(self, size: u32, sink: &mut impl NffSink) {
        match self {
            Database::Balls => balls::generate(size, sink),
            Database::Gears => gears::generate(size, sink),
            Database::Jacks => jacks::generate(size, sink),
            Database::Lattice => lattice::generate(size, sink),
            Database::Mount => mount::generate(size, sink),
            Database::Rings => rings::generate(size, sink),
            Database::Shells => shells::generate(size, sink),
            Database::Sombrero => sombrero::generate(size, sink),
            Database::Teapot => teapot::generate(size, sink),
            Database::Tetra => tetra::generate(size, sink),
            Database::Tree => tree::generate(size, sink),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fmt_g_matches_c() {
        let cases: [(f64, &str); 16] = [
            (0.0, "0"),
            (-0.0, "-0"),
            (1.0, "1"),
            (0.5, "0.5"),
            (100000.0, "100000"),
            (1000000.0, "1e+06"),
            (123456789.0, "1.23457e+08"),
            (0.0001, "0.0001"),
            (0.00001, "1e-05"),
            (1.1102230246251565e-16, "1.11022e-16"),
            (0.272166, "0.272166"),
            (0.0555556, "0.0555556"),
            (3.0827, "3.0827"),
            (-0.816497, "-0.816497"),
            (999999.5, "1e+06"),
            (0.166666666, "0.166667"),
        ];
        for (x, want) in cases {
            assert_eq!(fmt_g(x), want, "{x:e}");
        }
    }

    #[test]
    fn spd_specs_parse_and_refuse() {
        assert_eq!(Database::parse_spec("scene.nff"), Ok(None));
        assert_eq!(
            Database::parse_spec("spd:balls"),
            Ok(Some((Database::Balls, Database::Balls.default_size())))
        );
        assert_eq!(
            Database::parse_spec("spd:tetra?size=3"),
            Ok(Some((Database::Tetra, 3)))
        );
        let reason = |spec: &str| Database::parse_spec(spec).unwrap_err().reason;
        assert_eq!(
            reason("spd:nope"),
            SpecReason::UnknownDatabase("nope".into())
        );
        assert_eq!(
            reason("spd:balls?size=x"),
            SpecReason::SizeNotWhole("x".into())
        );
        assert!(matches!(reason("spd:balls?size=0"), SpecReason::Size(e) if e.size == 0));
        assert!(matches!(reason("spd:balls?size=99"), SpecReason::Size(e) if e.max == 8));
        assert_eq!(reason("spd:balls?depth=2"), SpecReason::NoSize);
        assert_eq!(
            Database::parse_spec("spd:balls?size=99")
                .unwrap_err()
                .to_string(),
            "spd:balls?size=99: size factor 99 out of range for balls (1 to 8)"
        );
        assert!(
            Database::parse_spec("spd:nope")
                .unwrap_err()
                .to_string()
                .starts_with("spd:nope: unknown database 'nope' (one of balls, gears,")
        );
    }

    #[test]
    fn writer_formats_entities_like_the_spd() {
        let mut w = NffWriter::new();
        w.background(DVec3::new(0.078, 0.361, 0.753));
        w.cone(
            DVec3::new(0.0, -0.649519, 0.375),
            0.075,
            DVec3::new(0.0, 0.649519, -0.375),
            0.075,
        );
        w.polygon(&[DVec3::ZERO, DVec3::X, DVec3::Y]);
        assert_eq!(
            w.finish(),
            "b 0.078 0.361 0.753\nc 0 -0.649519 0.375 0.075 0 0.649519 -0.375 0.075\np 3\n0 0 0\n1 0 0\n0 1 0\n"
        );
    }
}
