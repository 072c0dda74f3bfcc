//! The NFF entity parser: reads the entities of one stretch of a file into a
//! [`Part`], validating every number as it goes, and stops at the first entity that
//! starts at or after the stretch's end (it reads an entity that starts before the end
//! to its last token, wherever that is), or at the first error.

use super::lexer::{Lexer, Tok};
use super::number::{parse_f32, parse_f64, plain_f32, plain_f64};
use super::part::{Note, Part};
use super::{MAX_PIXELS, MAX_RESOLUTION_SIDE, looks_numeric, show};
use crate::geometry::{Cone, Intersect, Kind, Sphere};
use crate::load::LoadError;
use crate::math::{Aabb, DVec3, Vec3};
use crate::scene::{Camera, Light, Material, range};
use std::path::Path;
use std::sync::Arc;

const XYZ: [&str; 3] = ["x", "y", "z"];
const RGB: [&str; 3] = ["red", "green", "blue"];

/// A place to start reading: a line start or a token start, and its line.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Place {
    /// Byte offset.
    pub pos: usize,
    /// 1-based line.
    pub line: usize,
    /// Byte offset of the start of that line.
    pub line_start: usize,
}

/// What reading a stretch gave.
pub(super) struct Parsed {
    /// Its entities, up to the error if there is one.
    pub part: Part,
    /// Where its first token starts (`None` when it has none).
    pub first: Option<usize>,
    /// The first entity left unread because it starts at or after the end (`None` when
    /// the file ended, or at an error).
    pub stop: Option<Place>,
    /// The first problem, which ended the reading.
    pub error: Option<LoadError>,
}

/// The file being read and its frame.
#[derive(Clone, Copy)]
pub(super) struct Source<'a, 'p> {
    pub src: &'a str,
    pub path: &'p Path,
    /// The world point that is the scene's zero.
    pub origin: DVec3,
}

/// Read the entities of `source` that start in `from.pos..end` into a part whose
/// sources name `file`.
pub(super) fn parse(source: Source<'_, '_>, file: Arc<str>, from: Place, end: usize) -> Parsed {
    let mut p = Parser {
        lex: Lexer::at(source.src, from.pos, from.line, from.line_start),
        path: source.path,
        origin: source.origin,
        part: Part::new(file),
        pts: Vec::new(),
        nrm: Vec::new(),
        entity_line: 0,
    };
    let first = p.lex.peek().map(|t| t.start);
    let (stop, error) = match p.run(end) {
        Ok(stop) => (stop, None),
        Err(e) => (None, Some(e)),
    };
    Parsed {
        part: p.part,
        first,
        stop,
        error,
    }
}

struct Parser<'a, 'p> {
    lex: Lexer<'a>,
    path: &'p Path,
    /// The world point that is the scene's zero ([`crate::scene::Scene::origin`]).
    origin: DVec3,
    part: Part,
    /// Scratch: the current polygon's vertices and normals.
    pts: Vec<Vec3>,
    nrm: Vec<Vec3>,
    /// The line of the entity being read.
    entity_line: u32,
}

impl<'a> Parser<'a, '_> {
    fn err(&self, tok: &Tok<'a>, message: String) -> LoadError {
        LoadError {
            path: self.path.to_path_buf(),
            line: tok.line,
            col: self.lex.col(tok.line_start, tok.start),
            message,
        }
    }

    /// End of file while `what` was expected: reported just after the last token.
    fn err_eof(&self, what: &str) -> LoadError {
        let (line, col) = match self.lex.last {
            Some(t) => (t.line, self.lex.col(t.line_start, t.start + t.text.len())),
            None => (1, 1),
        };
        LoadError {
            path: self.path.to_path_buf(),
            line,
            col,
            message: format!("unexpected end of file while reading {what}"),
        }
    }

    fn token(&mut self, what: &dyn Fn() -> String) -> Result<Tok<'a>, LoadError> {
        match self.lex.next() {
            Some(t) => Ok(t),
            None => Err(self.err_eof(&what())),
        }
    }

    fn not_a_number(&self, t: &Tok<'a>, what: &dyn Fn() -> String, finite: bool) -> LoadError {
        let why = if finite { "" } else { " (not a finite number)" };
        self.err(
            t,
            format!("expected {}, found {}{why}", what(), show(t.text)),
        )
    }

    /// The next token as a finite `f32`. `what` names it for errors (built only then).
    #[inline(always)]
    fn num_with(&mut self, what: &dyn Fn() -> String) -> Result<(f32, Tok<'a>), LoadError> {
        let (t, v) = match self.lex.next_plain() {
            Some((t, p)) => (t, plain_f32(p).or_else(|| parse_f32(t.text))),
            None => {
                let t = self.token(what)?;
                (t, parse_f32(t.text))
            }
        };
        match v {
            Some(v) if v.is_finite() => Ok((v, t)),
            Some(_) => Err(self.not_a_number(&t, what, false)),
            None => Err(self.not_a_number(&t, what, true)),
        }
    }

    /// The next token as an `f64` that is also finite as an `f32` (so that the file's
    /// numbers are refused alike whether they are points or not).
    #[inline(always)]
    fn num64_with(&mut self, what: &dyn Fn() -> String) -> Result<(f64, Tok<'a>), LoadError> {
        let (t, v) = match self.lex.next_plain() {
            Some((t, p)) => (t, plain_f64(p).or_else(|| parse_f64(t.text))),
            None => {
                let t = self.token(what)?;
                (t, parse_f64(t.text))
            }
        };
        match v {
            Some(v) if v.is_finite() && (v as f32).is_finite() => Ok((v, t)),
            Some(_) => Err(self.not_a_number(&t, what, false)),
            None => Err(self.not_a_number(&t, what, true)),
        }
    }

    /// A point: three numbers read in double precision, checked against the traceable
    /// range in world coordinates, and returned in the scene's frame, with the first
    /// number's token.
    #[inline(always)]
    fn point(&mut self, what: &str) -> Result<(Vec3, Tok<'a>), LoadError> {
        let (x, tok) = self.num64_with(&|| format!("{what} x"))?;
        let (y, _) = self.num64_with(&|| format!("{what} y"))?;
        let (z, _) = self.num64_with(&|| format!("{what} z"))?;
        let world = DVec3::new(x, y, z);
        self.in_range(&tok, range::check_point(what, world.as_vec3()))?;
        Ok(((world - self.origin).as_vec3(), tok))
    }

    /// `bounds`, in the scene's frame, in world coordinates (for the range checks).
    fn world_bounds(&self, bounds: &Aabb) -> Aabb {
        world_bounds(self.origin, bounds)
    }

    #[inline]
    fn num(&mut self, what: &str) -> Result<(f32, Tok<'a>), LoadError> {
        self.num_with(&|| what.to_string())
    }

    /// Three numbers, named `"{what} {names[i]}"`. Returns the first one's token.
    #[inline]
    fn vec3(&mut self, what: &str, names: [&str; 3]) -> Result<(Vec3, Tok<'a>), LoadError> {
        let (x, t) = self.num_with(&|| format!("{what} {}", names[0]))?;
        let (y, _) = self.num_with(&|| format!("{what} {}", names[1]))?;
        let (z, _) = self.num_with(&|| format!("{what} {}", names[2]))?;
        Ok((Vec3::new(x, y, z), t))
    }

    /// A whole number (`12`, or an integral number such as `12.0`); huge values
    /// saturate, and the callers' range checks refuse them.
    fn integer(&mut self, what: &str) -> Result<(i128, Tok<'a>), LoadError> {
        let t = self.token(&|| what.to_string())?;
        if let Ok(v) = t.text.parse::<i128>() {
            return Ok((v, t));
        }
        match parse_f64(t.text) {
            Some(v) if v.is_finite() && v.fract() == 0.0 => Ok((v as i128, t)),
            _ => Err(self.err(
                &t,
                format!("expected {what} (a whole number), found {}", show(t.text)),
            )),
        }
    }

    /// A range check's verdict as an error at `tok`.
    fn in_range(
        &self,
        tok: &Tok<'a>,
        verdict: Result<(), range::RangeError>,
    ) -> Result<(), LoadError> {
        verdict.map_err(|e| self.err(tok, e.to_string()))
    }

    fn keyword(&mut self, kw: &str) -> Result<Tok<'a>, LoadError> {
        let t = self.token(&|| format!("'{kw}' of the viewpoint"))?;
        if t.text == kw {
            Ok(t)
        } else {
            Err(self.err(
                &t,
                format!("expected '{kw}' (viewpoint), found {}", show(t.text)),
            ))
        }
    }

    /// Read entities until one starts at or after `end` (returned) or the file ends.
    fn run(&mut self, end: usize) -> Result<Option<Place>, LoadError> {
        while let Some(t) = self.lex.next() {
            if t.start >= end {
                return Ok(Some(Place {
                    pos: t.start,
                    line: t.line,
                    line_start: t.line_start,
                }));
            }
            self.entity_line = u32::try_from(t.line).unwrap_or(u32::MAX);
            self.entity(&t)?;
        }
        Ok(None)
    }

    fn entity(&mut self, t: &Tok<'a>) -> Result<(), LoadError> {
        match t.text {
            "v" => self.viewpoint(t),
            "b" => {
                let (c, tok) = self.vec3("the background", RGB)?;
                self.warn_above_one(&tok, "background", c);
                self.part.background = Some(c);
                Ok(())
            }
            "l" => self.light(),
            "f" => self.material(),
            "c" => self.cone(),
            "s" => self.sphere(),
            "p" => self.polygon(t, false),
            "pp" => self.polygon(t, true),
            s if looks_numeric(s) => Err(self.err(
                t,
                format!(
                    "expected an entity (v b l f c s p pp), found the number {} \
                     (too many numbers for the entity before it?)",
                    show(s)
                ),
            )),
            s => Err(self.err(t, format!("unknown entity {}", show(s)))),
        }
    }

    fn viewpoint(&mut self, v: &Tok<'a>) -> Result<(), LoadError> {
        self.part.notes.push(Note::Viewpoint {
            line: v.line,
            col: self.lex.col(v.line_start, v.start),
        });
        self.keyword("from")?;
        let (from, _) = self.point("the viewpoint 'from'")?;
        self.keyword("at")?;
        let (at, at_tok) = self.point("the viewpoint 'at'")?;
        self.keyword("up")?;
        let (up, up_tok) = self.vec3("the viewpoint 'up'", XYZ)?;
        self.keyword("angle")?;
        let (angle, angle_tok) = self.num("the viewpoint angle")?;
        self.keyword("hither")?;
        let (hither, hither_tok) = self.num("the hither distance")?;
        self.keyword("resolution")?;
        let (w, w_tok) = self.integer("the image width")?;
        let (h, h_tok) = self.integer("the image height")?;

        let forward = at - from;
        if forward == Vec3::ZERO {
            return Err(self.err(&at_tok, "viewpoint 'at' equals 'from'".into()));
        }
        if !up_is_usable(forward, up) {
            return Err(self.err(
                &up_tok,
                "viewpoint 'up' is zero or parallel to the viewing direction".into(),
            ));
        }
        if !(angle > 0.0 && angle < 180.0) {
            return Err(self.err(
                &angle_tok,
                format!(
                    "viewpoint angle must be between 0 and 180 degrees (exclusive), found {angle}"
                ),
            ));
        }
        if hither < 0.0 {
            return Err(self.err(
                &hither_tok,
                format!("hither distance must not be negative, found {hither}"),
            ));
        }
        for (n, tok, name) in [(w, &w_tok, "width"), (h, &h_tok, "height")] {
            if n < 1 || n > MAX_RESOLUTION_SIDE as i128 {
                return Err(self.err(
                    tok,
                    format!(
                        "image {name} must be between 1 and {MAX_RESOLUTION_SIDE}, found {}",
                        show(tok.text)
                    ),
                ));
            }
        }
        if w * h > MAX_PIXELS as i128 {
            return Err(self.err(
                &w_tok,
                format!(
                    "resolution {w}x{h} has {} pixels, more than the {MAX_PIXELS} allowed",
                    w * h
                ),
            ));
        }
        self.part.notes.push(Note::Camera(Camera {
            from,
            at,
            up,
            angle_deg: angle,
            hither,
            width: w as u32,
            height: h as u32,
        }));
        Ok(())
    }

    fn light(&mut self) -> Result<(), LoadError> {
        let (pos, _) = self.point("the light position")?;
        let has_color = self.lex.peek().is_some_and(|t| looks_numeric(t.text));
        let color = if has_color {
            self.vec3("the light colour", RGB)?.0
        } else {
            Vec3::ZERO // set once the number of lights is known
        };
        self.part
            .add_light(Light::point(pos, color), has_color, self.entity_line);
        Ok(())
    }

    /// A warning when a colour has a channel above 1, the sign of a colour written on a
    /// 0–255 scale (NFF's colours run from 0 to 1).
    fn warn_above_one(&mut self, tok: &Tok<'a>, what: &str, c: Vec3) {
        if c.max_element() > 1.0 {
            let warning = format!(
                "{}:{}:{}: the {what} colour {} {} {} has channels above 1; NFF colours run \
                 from 0 to 1 (a colour on a 0-255 scale is divided by 255)",
                self.path.display(),
                tok.line,
                self.lex.col(tok.line_start, tok.start),
                c.x,
                c.y,
                c.z
            );
            self.part.notes.push(Note::Warning(warning));
        }
    }

    fn material(&mut self) -> Result<(), LoadError> {
        let (color, color_tok) = self.vec3("the fill colour", RGB)?;
        self.warn_above_one(&color_tok, "fill", color);
        let (kd, _) = self.num("the diffuse weight Kd")?;
        let (ks, _) = self.num("the specular weight Ks")?;
        let (shine, shine_tok) = self.num("the Phong exponent Shine")?;
        if shine < 0.0 {
            // (R·V)^Shine is infinite where R·V = 0.
            return Err(self.err(
                &shine_tok,
                format!("the Phong exponent Shine must not be negative, found {shine}"),
            ));
        }
        let (t, _) = self.num("the transmittance T")?;
        let (ior, ior_tok) = self.num("the index of refraction")?;
        self.in_range(&ior_tok, range::check_ior(t, ior))?;
        let material = fill(color, kd, ks, shine, t, ior);
        self.part.add_material(material, self.entity_line);
        Ok(())
    }

    fn sphere(&mut self) -> Result<(), LoadError> {
        let (center, _) = self.point("the sphere centre")?;
        let (r, r_tok) = self.num("the sphere radius")?;
        if r == 0.0 {
            return Err(self.err(&r_tok, "sphere radius must not be zero".into()));
        }
        let sphere = Sphere::new(center, r);
        let bounds = self.world_bounds(&sphere.bounds());
        self.in_range(&r_tok, range::check_bounds("the sphere", &bounds))?;
        self.part
            .add_analytic(sphere, Kind::Sphere, self.entity_line);
        Ok(())
    }

    fn cone(&mut self) -> Result<(), LoadError> {
        let (base, _) = self.point("the cone base")?;
        let (rb, _) = self.num("the cone base radius")?;
        let (apex, apex_tok) = self.point("the cone apex")?;
        let (ra, ra_tok) = self.num("the cone apex radius")?;
        if rb == 0.0 && ra == 0.0 {
            return Err(self.err(&ra_tok, "cone radii must not both be zero".into()));
        }
        // Negative radii mark an inside-only cone; a pointed end keeps radius 0.
        if (rb < 0.0 && ra > 0.0) || (rb > 0.0 && ra < 0.0) {
            return Err(self.err(
                &ra_tok,
                format!(
                    "cone radii must both be ≥ 0, or both ≤ 0 for an inside-only cone, \
                     found base {rb} and apex {ra}"
                ),
            ));
        }
        if base == apex {
            return Err(self.err(&apex_tok, "cone apex equals its base".into()));
        }
        let cone = Cone::new(base, rb, apex, ra);
        let bounds = self.world_bounds(&cone.bounds());
        self.in_range(&ra_tok, range::check_bounds("the cone", &bounds))?;
        self.part.add_analytic(cone, Kind::Cone, self.entity_line);
        Ok(())
    }

    fn polygon(&mut self, kw: &Tok<'a>, with_normals: bool) -> Result<(), LoadError> {
        let what = if with_normals {
            "the patch vertex count"
        } else {
            "the polygon vertex count"
        };
        let (n, n_tok) = self.integer(what)?;
        if n < 1 {
            return Err(self.err(
                &n_tok,
                format!(
                    "polygon vertex count must be positive, found {}",
                    show(n_tok.text)
                ),
            ));
        }
        // Refuse a count the rest of the file cannot possibly hold (not even one byte
        // per vertex) before reading on; a plausible count in a truncated file is
        // reported where the file ends.
        let remaining = self.lex.remaining();
        if n > remaining as i128 {
            return Err(self.err(
                &n_tok,
                format!(
                    "polygon vertex count {} is absurd: the rest of the file has {remaining} bytes",
                    show(n_tok.text)
                ),
            ));
        }
        self.pts.clear();
        self.nrm.clear();
        for _ in 0..n {
            let (p, _) = self.point("the polygon vertex")?;
            self.pts.push(p);
            if with_normals {
                let (nv, n_tok) = self.vec3("the vertex normal", XYZ)?;
                match unit_normal(nv) {
                    Some(u) => self.nrm.push(u),
                    None => return Err(self.err(&n_tok, "vertex normal is zero".into())),
                }
            }
        }
        let normals = with_normals.then_some(&self.nrm[..]);
        let at = || (kw.line, self.lex.col(kw.line_start, kw.start));
        let added = self
            .part
            .add_polygon(&self.pts, normals, self.entity_line, at);
        added.map_err(|_| self.err(&n_tok, "too many smooth triangles".into()))
    }
}

/// `bounds`, in the frame whose origin is the world point `origin`, in world
/// coordinates (for the range checks).
pub(crate) fn world_bounds(origin: DVec3, bounds: &Aabb) -> Aabb {
    let w = |p: Vec3| (p.as_dvec3() + origin).as_vec3();
    Aabb::from_points(w(bounds.min), w(bounds.max))
}

/// Whether `up` is neither zero nor parallel to `forward` (not zero).
pub(crate) fn up_is_usable(forward: Vec3, up: Vec3) -> bool {
    // Scale before normalising so that huge but finite values do not overflow.
    let fwd = (forward / forward.abs().max_element()).normalize();
    let upn = if up == Vec3::ZERO {
        Vec3::ZERO
    } else {
        up / up.abs().max_element()
    };
    fwd.cross(upn).try_normalize().is_some()
}

/// A vertex normal made unit length (`None` when it is zero).
pub(crate) fn unit_normal(n: Vec3) -> Option<Vec3> {
    if n == Vec3::ZERO {
        None
    } else {
        (n / n.abs().max_element()).try_normalize()
    }
}

/// The material of `f r g b Kd Ks Shine T ior`.
pub(crate) fn fill(color: Vec3, kd: f32, ks: f32, shine: f32, t: f32, ior: f32) -> Material {
    Material {
        color,
        ka: kd,
        kd,
        ks,
        shine,
        kr: ks,
        t,
        ior,
        filter: Vec3::ONE,
        priority: 0,
        ..Material::DEFAULT
    }
}
