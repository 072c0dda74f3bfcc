//! The NFF loader (Eric Haines' Neutral File Format, SPD 3.14; the conventions are in
//! docs/nff.md and docs/architecture.md).
//!
//! The file is read as a stream of whitespace-separated tokens, each remembering its
//! line and column, so an entity's numbers may be spread over lines as the writer
//! pleases; `#` starts a comment that runs to the end of the line. Tokens are slices of
//! the source: nothing is allocated per token.
//!
//! Entities: `v` (viewpoint: `from`, `at`, `up`, `angle`, `hither`, `resolution` in
//! that order), `b` (background), `l x y z [r g b]` (point light), `f` (material),
//! `c` (open cone/cylinder), `s` (sphere), `p` (polygon), `pp` (polygon with vertex
//! normals). Points (`from`, `at`, light positions, sphere centres, cone ends, polygon
//! vertices) are read in double precision and moved into the scene's frame, whose
//! origin is the eye (see [`Scene::origin`]), before they become single precision.
//! Everything is validated here, so the renderer can trust the scene: every
//! number is finite, sizes are positive where they must be, the resolution is sane, and
//! degenerate polygons are dropped with one warning per file and counted in
//! [`LoadStats::degenerate_dropped`](crate::scene::LoadStats).

use super::{LoadError, text};
use crate::geometry::Kind;
use crate::geometry::polygon::Triangulator;
use crate::geometry::{Cone, Intersect, Sphere, Triangle};
use crate::math::{Aabb, DVec3, Vec3};
use crate::scene::{Camera, Light, Material, Scene, default_light_intensity, range};
use std::path::Path;
use std::sync::Arc;

/// Largest accepted image side.
pub const MAX_RESOLUTION_SIDE: u64 = 65_536;
/// Largest accepted pixel count (2²⁸).
pub const MAX_PIXELS: u64 = 1 << 28;

/// Read and parse the NFF file at `path`; a scene without objects is a warning.
///
/// # Errors
/// `path: cannot read: …` when the file cannot be read, `path: …` when it is not text
/// (gzip-compressed, UTF-16), otherwise whatever [`parse_str`] reports. A leading
/// UTF-8 byte-order mark is skipped, and bytes that are not UTF-8 (in comments, say)
/// are replaced, which leaves line and column numbers intact (see `super::text`).
pub fn load(path: &Path) -> Result<Scene, LoadError> {
    let scene = parse_str(&text::read_lossy(path)?, path)?;
    super::warn_if_empty(&scene, path);
    Ok(scene)
}

/// Parse NFF text; `path` only labels the errors.
///
/// # Errors
/// The first problem found, as `path:line:col: message` with the position of the
/// offending token (1-based; a column counts characters), or `path: no viewpoint ('v')
/// in file` when there is no `v`.
pub fn parse_str(src: &str, path: &Path) -> Result<Scene, LoadError> {
    parse_str_at(src, path, eye_of(src).unwrap_or(DVec3::ZERO))
}

/// [`parse_str`] in the frame whose origin is the world point `origin`: every point of
/// the file, `p`, becomes `p − origin` (computed in double precision) in the scene.
///
/// # Errors
/// As [`parse_str`].
pub fn parse_str_at(src: &str, path: &Path, origin: DVec3) -> Result<Scene, LoadError> {
    let mut p = Parser {
        lex: Lexer::new(src),
        path,
        origin,
        camera: None,
        background: Vec3::ZERO,
        lights: Vec::new(),
        light_has_color: Vec::new(),
        materials: Vec::new(),
        current_material: None,
        scene: Scene::new(PLACEHOLDER_CAMERA),
        pts: Vec::new(),
        nrm: Vec::new(),
        tris: Vec::new(),
        triangulator: Triangulator::new(),
        first_degenerate: None,
        file: Arc::from(path.display().to_string()),
        entity_line: 0,
    };
    p.run()?;
    p.finish()
}

/// The eye (`from`) of the file's first viewpoint, found by a quick scan of the tokens
/// (`None` when there is none or it does not read: the parse then says why).
fn eye_of(src: &str) -> Option<DVec3> {
    let mut lex = Lexer::new(src);
    while lex.next()?.text != "v" {}
    if lex.next()?.text != "from" {
        return None;
    }
    let mut xyz = [0.0; 3];
    for c in &mut xyz {
        *c = lex
            .next()?
            .text
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())?;
    }
    Some(DVec3::from(xyz))
}

/// Stands in until the `v` is read (the scene is built while parsing, and `v` may come
/// anywhere in the file).
const PLACEHOLDER_CAMERA: Camera = Camera {
    from: Vec3::ZERO,
    at: Vec3::NEG_Z,
    up: Vec3::Y,
    angle_deg: 45.0,
    hither: 0.0,
    width: 1,
    height: 1,
};

/// One token: a slice of the source and where it starts.
#[derive(Clone, Copy, Debug)]
struct Tok<'a> {
    text: &'a str,
    /// Byte offset of the token.
    start: usize,
    /// 1-based line.
    line: usize,
    /// Byte offset of the start of its line.
    line_start: usize,
}

/// Splits the source into tokens, skipping whitespace and `#` comments.
struct Lexer<'a> {
    src: &'a str,
    pos: usize,
    line: usize,
    line_start: usize,
    peeked: Option<Tok<'a>>,
    /// The last token handed out by `next`.
    last: Option<Tok<'a>>,
}

#[inline]
fn is_space(b: u8) -> bool {
    matches!(b, b' ' | b'\t' | b'\n' | b'\r' | 0x0b | 0x0c)
}

impl<'a> Lexer<'a> {
    fn new(src: &'a str) -> Self {
        Lexer {
            src,
            pos: 0,
            line: 1,
            line_start: 0,
            peeked: None,
            last: None,
        }
    }

    fn scan(&mut self) -> Option<Tok<'a>> {
        let b = self.src.as_bytes();
        loop {
            match *b.get(self.pos)? {
                b'\n' => {
                    self.pos += 1;
                    self.line += 1;
                    self.line_start = self.pos;
                }
                b'\r' => {
                    self.pos += 1;
                    // CR LF counts once (at the LF); a lone CR ends a line too.
                    if b.get(self.pos) != Some(&b'\n') {
                        self.line += 1;
                        self.line_start = self.pos;
                    }
                }
                b'#' => {
                    while self.pos < b.len() && !matches!(b[self.pos], b'\n' | b'\r') {
                        self.pos += 1;
                    }
                }
                c if is_space(c) => self.pos += 1,
                _ => break,
            }
        }
        let start = self.pos;
        while self.pos < b.len() && !is_space(b[self.pos]) && b[self.pos] != b'#' {
            self.pos += 1;
        }
        // Token boundaries are ASCII bytes, so they are char boundaries.
        Some(Tok {
            text: &self.src[start..self.pos],
            start,
            line: self.line,
            line_start: self.line_start,
        })
    }

    #[inline]
    fn next(&mut self) -> Option<Tok<'a>> {
        let t = match self.peeked.take() {
            Some(t) => Some(t),
            None => self.scan(),
        };
        if t.is_some() {
            self.last = t;
        }
        t
    }

    #[inline]
    fn peek(&mut self) -> Option<Tok<'a>> {
        if self.peeked.is_none() {
            self.peeked = self.scan();
        }
        self.peeked
    }

    /// Bytes of source after the last token handed out.
    fn remaining(&self) -> usize {
        let end = self.last.map_or(0, |t| t.start + t.text.len());
        self.src.len() - end
    }

    /// 1-based column of byte `at` on the line starting at `line_start`.
    fn col(&self, line_start: usize, at: usize) -> usize {
        self.src[line_start..at].chars().count() + 1
    }
}

/// Whether a token is meant as a number (as opposed to an entity keyword): it parses,
/// or starts like one. `nan` and `inf` count, so that they are reported as non-finite.
fn looks_numeric(t: &str) -> bool {
    matches!(t.as_bytes().first(), Some(b'0'..=b'9' | b'+' | b'-' | b'.'))
        || t.parse::<f32>().is_ok()
}

/// A token for a message: quoted, and shortened if long.
fn show(t: &str) -> String {
    const MAX: usize = 40;
    if t.chars().count() <= MAX {
        format!("'{t}'")
    } else {
        let head: String = t.chars().take(MAX).collect();
        format!("'{head}…'")
    }
}

const XYZ: [&str; 3] = ["x", "y", "z"];
const RGB: [&str; 3] = ["red", "green", "blue"];

struct Parser<'a, 'p> {
    lex: Lexer<'a>,
    path: &'p Path,
    /// The world point that is the scene's zero ([`Scene::origin`]).
    origin: DVec3,
    camera: Option<Camera>,
    background: Vec3,
    lights: Vec<Light>,
    light_has_color: Vec<bool>,
    materials: Vec<Material>,
    current_material: Option<u32>,
    /// Primitives go straight into the scene; camera, lights and materials are set in
    /// `finish`.
    scene: Scene,
    /// Scratch: the current polygon's vertices and normals, its triangles.
    pts: Vec<Vec3>,
    nrm: Vec<Vec3>,
    tris: Vec<[usize; 3]>,
    triangulator: Triangulator,
    /// Position of the first degenerate polygon, for the warning.
    first_degenerate: Option<(usize, usize)>,
    /// The file, as the primitives' origins name it.
    file: Arc<str>,
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

    /// The next token as a finite `f32`. `what` names it for errors (built only then).
    #[inline]
    fn num_with(&mut self, what: &dyn Fn() -> String) -> Result<(f32, Tok<'a>), LoadError> {
        let t = self.token(what)?;
        match t.text.parse::<f32>() {
            Ok(v) if v.is_finite() => Ok((v, t)),
            Ok(_) => Err(self.err(
                &t,
                format!(
                    "expected {}, found {} (not a finite number)",
                    what(),
                    show(t.text)
                ),
            )),
            Err(_) => Err(self.err(&t, format!("expected {}, found {}", what(), show(t.text)))),
        }
    }

    /// The next token as an `f64` that is also finite as an `f32` (so that the file's
    /// numbers are refused alike whether they are points or not).
    #[inline]
    fn num64_with(&mut self, what: &dyn Fn() -> String) -> Result<f64, LoadError> {
        let t = self.token(what)?;
        match t.text.parse::<f64>() {
            Ok(v) if v.is_finite() && (v as f32).is_finite() => Ok(v),
            Ok(_) => Err(self.err(
                &t,
                format!(
                    "expected {}, found {} (not a finite number)",
                    what(),
                    show(t.text)
                ),
            )),
            Err(_) => Err(self.err(&t, format!("expected {}, found {}", what(), show(t.text)))),
        }
    }

    /// A point: three numbers read in double precision, checked against the traceable
    /// range in world coordinates, and returned in the scene's frame, with the first
    /// number's token.
    fn point(&mut self, what: &str) -> Result<(Vec3, Tok<'a>), LoadError> {
        let tok = self.lex.peek();
        let mut p = [0.0; 3];
        for (c, name) in p.iter_mut().zip(XYZ) {
            *c = self.num64_with(&|| format!("{what} {name}"))?;
        }
        let world = DVec3::from(p);
        let tok = tok.expect("a number was read");
        self.in_range(&tok, range::check_point(what, world.as_vec3()))?;
        Ok(((world - self.origin).as_vec3(), tok))
    }

    /// `bounds`, in the scene's frame, in world coordinates (for the range checks).
    fn world_bounds(&self, bounds: &Aabb) -> Aabb {
        let o = self.origin;
        let w = |p: Vec3| (p.as_dvec3() + o).as_vec3();
        Aabb::from_points(w(bounds.min), w(bounds.max))
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
        match t.text.parse::<f64>() {
            Ok(v) if v.is_finite() && v.fract() == 0.0 => Ok((v as i128, t)),
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

    fn run(&mut self) -> Result<(), LoadError> {
        while let Some(t) = self.lex.next() {
            self.entity_line = u32::try_from(t.line).unwrap_or(u32::MAX);
            match t.text {
                "v" => self.viewpoint(&t)?,
                "b" => {
                    let (c, tok) = self.vec3("the background", RGB)?;
                    self.warn_above_one(&tok, "background", c);
                    self.background = c;
                }
                "l" => self.light()?,
                "f" => self.material()?,
                "c" => self.cone()?,
                "s" => self.sphere()?,
                "p" => self.polygon(&t, false)?,
                "pp" => self.polygon(&t, true)?,
                s if looks_numeric(s) => {
                    return Err(self.err(
                        &t,
                        format!(
                            "expected an entity (v b l f c s p pp), found the number {} \
                             (too many numbers for the entity before it?)",
                            show(s)
                        ),
                    ));
                }
                s => return Err(self.err(&t, format!("unknown entity {}", show(s)))),
            }
        }
        Ok(())
    }

    fn viewpoint(&mut self, v: &Tok<'a>) -> Result<(), LoadError> {
        if let Some(old) = self.camera {
            // The first eye in the file's coordinates, as it wrote them.
            let from = (old.from.as_dvec3() + self.origin).as_vec3();
            log::warn!(
                "{}:{}:{}: a second viewpoint ('v') replaces the first (from {} {} {})",
                self.path.display(),
                v.line,
                self.lex.col(v.line_start, v.start),
                range::number(from.x),
                range::number(from.y),
                range::number(from.z)
            );
        }
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
        // Scale before normalising so that huge but finite values do not overflow.
        let fwd = (forward / forward.abs().max_element()).normalize();
        let upn = if up == Vec3::ZERO {
            Vec3::ZERO
        } else {
            up / up.abs().max_element()
        };
        if fwd.cross(upn).try_normalize().is_none() {
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
        self.camera = Some(Camera {
            from,
            at,
            up,
            angle_deg: angle,
            hither,
            width: w as u32,
            height: h as u32,
        });
        Ok(())
    }

    fn light(&mut self) -> Result<(), LoadError> {
        let (pos, _) = self.point("the light position")?;
        let has_color = self.lex.peek().is_some_and(|t| looks_numeric(t.text));
        let color = if has_color {
            self.vec3("the light colour", RGB)?.0
        } else {
            Vec3::ZERO // set in `finish` once the number of lights is known
        };
        let (index, line) = (self.lights.len(), self.entity_line);
        self.scene.sources.lights.add(index, 1, &self.file, line);
        self.lights.push(Light::point(pos, color));
        self.light_has_color.push(has_color);
        Ok(())
    }

    /// A warning when a colour has a channel above 1, the sign of a colour written on a
    /// 0–255 scale (NFF's colours run from 0 to 1).
    fn warn_above_one(&self, tok: &Tok<'a>, what: &str, c: Vec3) {
        if c.max_element() > 1.0 {
            log::warn!(
                "{}:{}:{}: the {what} colour {} {} {} has channels above 1; NFF colours run \
                 from 0 to 1 (a colour on a 0-255 scale is divided by 255)",
                self.path.display(),
                tok.line,
                self.lex.col(tok.line_start, tok.start),
                c.x,
                c.y,
                c.z
            );
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
        let (index, line) = (self.materials.len(), self.entity_line);
        self.scene.sources.materials.add(index, 1, &self.file, line);
        self.materials.push(Material {
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
        });
        self.current_material = Some(self.materials.len() as u32 - 1);
        Ok(())
    }

    /// The material index for the next primitive (a default material before any `f`).
    fn material_index(&mut self) -> u32 {
        match self.current_material {
            Some(m) => m,
            None => {
                self.materials.push(Material::default());
                let m = self.materials.len() as u32 - 1;
                self.current_material = Some(m);
                m
            }
        }
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
        let m = self.material_index();
        self.record(Kind::Sphere, 1);
        self.scene.geometry.push(sphere, m);
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
        let m = self.material_index();
        self.record(Kind::Cone, 1);
        self.scene.geometry.push(cone, m);
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
        let n = n as usize;
        self.pts.clear();
        self.nrm.clear();
        for _ in 0..n {
            let (p, _) = self.point("the polygon vertex")?;
            self.pts.push(p);
            if with_normals {
                let (nv, n_tok) = self.vec3("the vertex normal", XYZ)?;
                let unit = if nv == Vec3::ZERO {
                    None
                } else {
                    (nv / nv.abs().max_element()).try_normalize()
                };
                match unit {
                    Some(u) => self.nrm.push(u),
                    None => return Err(self.err(&n_tok, "vertex normal is zero".into())),
                }
            }
        }
        self.scene.load_stats.polygons += 1;
        match self.triangulator.triangulate(&self.pts, &mut self.tris) {
            Ok(()) => {
                let m = self.material_index();
                self.record(Kind::Triangle, self.tris.len());
                for &[a, b, c] in &self.tris {
                    self.scene.geometry.triangles.push(
                        Triangle {
                            p: [self.pts[a], self.pts[b], self.pts[c]],
                        },
                        m,
                    );
                    let k = if with_normals {
                        let k = self.scene.geometry.vertex_normals.len();
                        if k >= u32::MAX as usize {
                            return Err(self.err(&n_tok, "too many smooth triangles".into()));
                        }
                        self.scene.geometry.vertex_normals.push([
                            self.nrm[a],
                            self.nrm[b],
                            self.nrm[c],
                        ]);
                        k as u32
                    } else {
                        u32::MAX
                    };
                    self.scene.geometry.triangle_normals.push(k);
                }
            }
            Err(_) => {
                self.scene.load_stats.degenerate_dropped += 1;
                if self.first_degenerate.is_none() {
                    let col = self.lex.col(kw.line_start, kw.start);
                    self.first_degenerate = Some((kw.line, col));
                }
            }
        }
        Ok(())
    }

    /// The next `count` primitives of `kind` come from the entity being read.
    fn record(&mut self, kind: Kind, count: usize) {
        let first = self.scene.geometry.count(kind);
        let g = &mut self.scene.geometry;
        g.sources
            .add(kind, first, count, &self.file, self.entity_line);
    }

    fn finish(mut self) -> Result<Scene, LoadError> {
        let Some(camera) = self.camera else {
            return Err(LoadError {
                path: self.path.to_path_buf(),
                line: 0,
                col: 0,
                message: "no viewpoint ('v') in file".into(),
            });
        };
        if let Some((line, col)) = self.first_degenerate {
            log::warn!(
                "{}: dropped {} degenerate polygon(s) (fewer than 3 distinct vertices or \
                 zero area), the first at {line}:{col}",
                self.path.display(),
                self.scene.load_stats.degenerate_dropped
            );
        }
        let n = self.lights.len();
        let default = default_light_intensity(n);
        for (l, &has) in self.lights.iter_mut().zip(&self.light_has_color) {
            if !has {
                l.color = Vec3::splat(default);
            }
        }
        let mut scene = self.scene;
        scene.camera = camera;
        scene.background = self.background;
        scene.lights = self.lights;
        scene.ambient = Vec3::splat(default);
        scene.materials = self.materials;
        scene.origin = self.origin;
        Ok(scene)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tokens(src: &str) -> Vec<(String, usize, usize)> {
        let mut lx = Lexer::new(src);
        let mut v = Vec::new();
        while let Some(t) = lx.next() {
            v.push((t.text.to_string(), t.line, lx.col(t.line_start, t.start)));
        }
        v
    }

    #[test]
    fn lexer_positions_and_comments() {
        let toks = tokens("# header\nv  from\t1 #x\r\n  2\r3\n#end");
        assert_eq!(
            toks,
            vec![
                ("v".into(), 2, 1),
                ("from".into(), 2, 4),
                ("1".into(), 2, 9),
                ("2".into(), 3, 3),
                ("3".into(), 4, 1),
            ]
        );
        // A comment glued to a token ends it; columns count characters, not bytes.
        let toks = tokens("é 1#c\n2");
        assert_eq!(
            toks,
            vec![("é".into(), 1, 1), ("1".into(), 1, 3), ("2".into(), 2, 1)]
        );
        assert!(tokens("  # only a comment").is_empty());
    }

    #[test]
    fn numeric_detection() {
        for s in [
            "1", "-2", "+3", ".5", "1e3", "nan", "NaN", "inf", "-inf", "infinity",
        ] {
            assert!(looks_numeric(s), "{s}");
        }
        for s in ["v", "b", "l", "f", "c", "s", "p", "pp", "from", "abc"] {
            assert!(!looks_numeric(s), "{s}");
        }
    }

    #[test]
    fn long_tokens_are_shortened_in_messages() {
        let long = "x".repeat(1000);
        let s = show(&long);
        assert!(s.len() < 60, "{s}");
        assert_eq!(show("abc"), "'abc'");
    }

    /// Each primitive, material and light knows the line of its entity; a polygon's
    /// triangles share their `p`'s line; the scene's `Debug` form (the render hash of
    /// `emray merge`) does not depend on the file's name.
    #[test]
    fn primitives_materials_and_lights_know_their_line() {
        let src = "v from 0 0 5 at 0 0 0 up 0 1 0 angle 40 hither 1 resolution 8 8\n\
                   l 1 1 1\n\
                   f 1 0 0 1 0 0 0 0\n\
                   s 0 0 0 1\n\
                   # a quad: two triangles\n\
                   p 4 0 0 0 1 0 0 1 1 0 0 1 0\n\
                   c 0 0 0 1 0 1 0 1\n";
        let scene = parse_str(src, Path::new("dir/a.nff")).unwrap();
        let g = &scene.geometry;
        let at = |o: Option<crate::scene::Origin>| o.unwrap().to_string();
        assert_eq!(at(g.sources.get(Kind::Sphere, 0)), "dir/a.nff:4");
        assert_eq!(g.count(Kind::Triangle), 2);
        assert_eq!(at(g.sources.get(Kind::Triangle, 0)), "dir/a.nff:6");
        assert_eq!(at(g.sources.get(Kind::Triangle, 1)), "dir/a.nff:6");
        assert_eq!(at(g.sources.get(Kind::Cone, 0)), "dir/a.nff:7");
        assert_eq!(at(scene.sources.materials.get(0)), "dir/a.nff:3");
        assert_eq!(at(scene.sources.lights.get(0)), "dir/a.nff:2");
        let elsewhere = parse_str(src, Path::new("b.nff")).unwrap();
        assert_eq!(format!("{scene:?}"), format!("{elsewhere:?}"));
    }

    #[test]
    fn eof_position_is_after_the_last_token() {
        let e = parse_str("v\nfrom 1 2", Path::new("t.nff")).unwrap_err();
        assert_eq!((e.line, e.col), (2, 9));
        assert_eq!(
            e.message,
            "unexpected end of file while reading the viewpoint 'from' z"
        );
    }
}
