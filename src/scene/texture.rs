//! Textures, bump and normal maps, and environment maps.
//!
//! # Image textures
//!
//! Images are stored as linear RGB `f32`. Colour maps (`map_Kd`, `map_Ks`, environment
//! maps) are decoded from sRGB; data maps (bump heights, normal maps) are read as they
//! are. Texture coordinates follow OBJ: `(0, 0)` is the image's bottom-left corner and
//! `(1, 1)` its top-right one, so texel `(i, j)` (column `i` from the left, row `j` from
//! the top) of a `w × h` image has its centre at `u = (i + ½)/w`, `v = 1 − (j + ½)/h`.
//! Lookups are bilinear between the four nearest texel centres; outside `[0, 1]` the
//! coordinates wrap ([`Wrap::Repeat`], the default) or stick to the edge texels
//! ([`Wrap::Clamp`]).
//!
//! # Procedural textures
//!
//! - [`Texture::Checker`]: squares of two colours in `(u, v)`, `scale` squares per unit.
//! - [`Texture::Marble`]: a solid texture of the hit point (world space): veins
//!   `½ + ½·sin(scale·(x + y + z) + 4·turbulence(scale·p))` blending two colours, with
//!   turbulence a sum of octaves of Perlin's gradient noise.
//!
//! # Bump and normal maps
//!
//! A bump map is a height field `h(u, v) = scale · mean(texel)` (world units). Blinn's
//! method displaces the surface by `h` along the normal `n`; to first order the
//! displaced tangents are `∂p/∂u + h_u n` and `∂p/∂v + h_v n`, and the shading normal is
//! their cross product (on the side of `n`). The partials `h_u`, `h_v` are central
//! differences one texel apart (1/1024 for procedural textures).
//!
//! A normal map holds tangent-space normals `2·texel − 1` (linear) in the frame
//! `T = ∂p/∂u` made perpendicular to the shading normal `N`, `B = N × T` (flipped if the
//! parameterisation is left-handed), `N`.
//!
//! # Environment maps
//!
//! Rays that leave the scene take their colour from the environment map instead of the
//! background colour. Axis convention: +y is up; the centre of a latitude-longitude
//! (equirectangular, 2:1) image is the direction −z, its right quarter +x, its top row
//! +y. For a direction `d`: `u = ½ + atan2(d.x, −d.z)/2π`, `v = ½ + asin(d.y)/π`. A cube
//! map is one image in a horizontal cross, 4 × 3 square faces: the middle row holds,
//! left to right, the faces seen looking along −x, −z, +x and +z (each upright, +y up),
//! the face above −z is +y (seen from below, −z at its bottom edge) and the face below
//! −z is −y (−z at its top edge): the cross folds into the cube seen from inside.
//! An image whose width is twice its height is a latitude-longitude map, one with
//! width:height = 4:3 a cube cross; any other shape is an error.
//!
//! A cube map may also come as six square images of one size, the same faces as in
//! the cross: each is the view from the cube's centre along its axis, the four side
//! faces (±x, ±z) upright with +y up, the +y face with −z at its bottom edge and +x to
//! the right, the −y face with −z at its top edge and +x to the right. A directory
//! holding `px`, `nx`, `py`, `ny`, `pz` and `nz` (each `.png`, `.jpg` or `.jpeg`) for
//! +x, −x, +y, −y, +z and −z is read as such a cube map ([`Environment::load`]).

use crate::math::Vec3;
use glam::Vec2;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Why an image or environment map cannot be read or used.
#[derive(Debug, thiserror::Error)]
pub enum TextureError {
    /// The size does not match the texels.
    #[error("an image of {width} × {height} texels cannot hold {texels} values")]
    Size {
        /// Width asked for.
        width: u32,
        /// Height asked for.
        height: u32,
        /// Texels given.
        texels: usize,
    },
    /// The file cannot be opened or read.
    #[error("{}: cannot read image: {source}", .path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// What failed.
        source: std::io::Error,
    },
    /// The file is not an image the decoders read.
    #[error("{}: cannot decode image: {source}", .path.display())]
    Decode {
        /// The file.
        path: PathBuf,
        /// What failed.
        source: image::ImageError,
    },
    /// An image is neither a 2:1 latitude-longitude map nor a 4:3 cube cross.
    #[error(
        "an environment map is a 2:1 latitude-longitude image or a 4:3 cube cross, \
         not {width} × {height}"
    )]
    EnvironmentShape {
        /// Width of the image.
        width: u32,
        /// Height of the image.
        height: u32,
    },
    /// A cube map's faces are not square or not of one size.
    #[error(
        "the cube map's faces must be square and of one size: {face} is {} × {}, {} is \
         {} × {}",
        .size.0, .size.1, CUBE_FACES[0], .first.0, .first.1
    )]
    CubeFaces {
        /// The face that differs (`px`, ...).
        face: &'static str,
        /// Its width and height.
        size: (u32, u32),
        /// Width and height of the first face.
        first: (u32, u32),
    },
    /// A cube map directory lacks a face.
    #[error(
        "{}: a cube map directory needs {face}.png (or .jpg, .jpeg), one of the faces px, \
         nx, py, ny, pz, nz",
        .dir.display()
    )]
    MissingFace {
        /// The directory.
        dir: PathBuf,
        /// The face (`px`, ...).
        face: &'static str,
    },
    /// An error about the image or map read from `path`.
    #[error("{}: {source}", .path.display())]
    In {
        /// The file.
        path: PathBuf,
        /// The error.
        source: Box<TextureError>,
    },
}

impl TextureError {
    fn in_file(self, path: &Path) -> TextureError {
        TextureError::In {
            path: path.to_path_buf(),
            source: Box::new(self),
        }
    }
}

/// Texture index meaning "no texture".
pub const NO_TEXTURE: u32 = u32::MAX;

/// A material's texture maps: indices into [`crate::scene::Scene::textures`], or
/// [`NO_TEXTURE`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Maps {
    /// Multiplies the material's colour (MTL `map_Kd`).
    pub color: u32,
    /// Multiplies the highlight and mirror weights by its mean (MTL `map_Ks`).
    pub specular: u32,
    /// Height field for bump mapping (MTL `bump`, `map_bump`).
    pub bump: u32,
    /// Height of a texel value of 1, in world units (MTL `-bm`).
    pub bump_scale: f32,
    /// Tangent-space normal map (MTL `norm`).
    pub normal: u32,
    /// Texture coordinates are multiplied by this before every lookup (MTL `-s u v`,
    /// the scene format's `uv_scale`): `(4, 2)` repeats an image 4 times along `u`.
    pub uv_scale: [f32; 2],
}

impl Maps {
    /// No maps.
    pub const NONE: Maps = Maps {
        color: NO_TEXTURE,
        specular: NO_TEXTURE,
        bump: NO_TEXTURE,
        bump_scale: 1.0,
        normal: NO_TEXTURE,
        uv_scale: [1.0, 1.0],
    };

    /// Whether any map is set.
    #[inline]
    pub fn any(&self) -> bool {
        self.color != NO_TEXTURE
            || self.specular != NO_TEXTURE
            || self.bump != NO_TEXTURE
            || self.normal != NO_TEXTURE
    }

    /// The maps with every texture index moved by `offset` (for materials appended to
    /// a scene whose texture list is appended to another).
    pub fn offset(&self, offset: u32) -> Maps {
        let o = |i: u32| if i == NO_TEXTURE { i } else { i + offset };
        Maps {
            color: o(self.color),
            specular: o(self.specular),
            bump: o(self.bump),
            normal: o(self.normal),
            ..*self
        }
    }
}

impl Default for Maps {
    fn default() -> Self {
        Maps::NONE
    }
}

/// What happens outside `[0, 1]`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Wrap {
    /// The image tiles the plane.
    #[default]
    Repeat,
    /// The edge texels extend outwards.
    Clamp,
}

/// An image in linear RGB.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    width: u32,
    height: u32,
    /// Row-major from the top row.
    texels: Vec<Vec3>,
    /// Wrap mode.
    pub wrap: Wrap,
}

/// sRGB-encoded value in [0, 1] to linear.
#[inline]
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

impl Image {
    /// An image from linear texels, row-major from the top row.
    ///
    /// # Errors
    /// When the size is zero or does not match the texels.
    pub fn new(width: u32, height: u32, texels: Vec<Vec3>) -> Result<Image, TextureError> {
        if width == 0 || height == 0 || texels.len() != width as usize * height as usize {
            return Err(TextureError::Size {
                width,
                height,
                texels: texels.len(),
            });
        }
        Ok(Image {
            width,
            height,
            texels,
            wrap: Wrap::Repeat,
        })
    }

    /// Read a PNG or JPEG file; `srgb` decodes colour maps to linear (data maps are
    /// read as they are). Alpha is ignored.
    ///
    /// # Errors
    /// A message naming the file when it cannot be read or decoded.
    pub fn load(path: &Path, srgb: bool) -> Result<Image, TextureError> {
        let unreadable = |source| TextureError::Read {
            path: path.to_path_buf(),
            source,
        };
        let img = image::ImageReader::open(path)
            .map_err(unreadable)?
            .with_guessed_format()
            .map_err(unreadable)?
            .decode()
            .map_err(|source| TextureError::Decode {
                path: path.to_path_buf(),
                source,
            })?;
        let rgb = img.to_rgb32f();
        let (w, h) = rgb.dimensions();
        let lin = |c: f32| if srgb { srgb_to_linear(c) } else { c };
        let texels = rgb
            .pixels()
            .map(|p| Vec3::new(lin(p.0[0]), lin(p.0[1]), lin(p.0[2])))
            .collect();
        Image::new(w, h, texels).map_err(|e| e.in_file(path))
    }

    /// Width in texels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in texels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// Texel `(i, j)`, column `i` from the left, row `j` from the top, after the wrap
    /// mode.
    #[inline]
    pub fn texel(&self, i: i64, j: i64) -> Vec3 {
        let (w, h) = (i64::from(self.width), i64::from(self.height));
        let (i, j) = match self.wrap {
            Wrap::Repeat => (i.rem_euclid(w), j.rem_euclid(h)),
            Wrap::Clamp => (i.clamp(0, w - 1), j.clamp(0, h - 1)),
        };
        self.texels[(j * w + i) as usize]
    }

    /// The bilinear lookup at texture coordinates `uv`.
    #[inline]
    pub fn bilinear(&self, uv: Vec2) -> Vec3 {
        let x = f64::from(uv.x) * f64::from(self.width) - 0.5;
        let y = (1.0 - f64::from(uv.y)) * f64::from(self.height) - 0.5;
        if !(x.is_finite() && y.is_finite()) {
            return self.texel(0, 0);
        }
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = ((x - x0) as f32, (y - y0) as f32);
        // Far outside, repeat lookups only need the coordinates modulo the size.
        let (i, j) = (x0.clamp(-1e15, 1e15) as i64, y0.clamp(-1e15, 1e15) as i64);
        let a = self.texel(i, j).lerp(self.texel(i + 1, j), fx);
        let b = self.texel(i, j + 1).lerp(self.texel(i + 1, j + 1), fx);
        a.lerp(b, fy)
    }
}

/// A texture: an image or a procedural pattern.
#[derive(Clone, Debug, PartialEq)]
pub enum Texture {
    /// An image, looked up bilinearly at the surface's `(u, v)`.
    Image(Arc<Image>),
    /// Squares of colours `a` and `b` in `(u, v)`, `scale` squares per unit.
    Checker {
        /// Colour of the square at the origin.
        a: Vec3,
        /// The other colour.
        b: Vec3,
        /// Squares per unit of `u` and `v`.
        scale: f32,
    },
    /// Marble veins of colour `b` in `a`, a solid texture of the world-space point.
    Marble {
        /// Base colour.
        a: Vec3,
        /// Vein colour.
        b: Vec3,
        /// Spatial frequency (veins per world unit, roughly).
        scale: f32,
    },
}

impl Texture {
    /// The texture's value at texture coordinates `uv` and world point `p`.
    #[inline]
    pub fn eval(&self, uv: Vec2, p: Vec3) -> Vec3 {
        match self {
            Texture::Image(img) => img.bilinear(uv),
            Texture::Checker { a, b, scale } => {
                let i = (uv.x * scale).floor() as i64 + (uv.y * scale).floor() as i64;
                if i.rem_euclid(2) == 0 { *a } else { *b }
            }
            Texture::Marble { a, b, scale } => {
                let q = p * *scale;
                let s = 0.5 + 0.5 * (q.x + q.y + q.z + 4.0 * turbulence(q)).sin();
                a.lerp(*b, s)
            }
        }
    }

    /// The step in `u` and `v` for finite differences: one texel for images.
    fn step(&self) -> Vec2 {
        match self {
            Texture::Image(img) => Vec2::new(1.0 / img.width as f32, 1.0 / img.height as f32),
            _ => Vec2::splat(1.0 / 1024.0),
        }
    }

    /// The height `mean(value)` at `uv`.
    #[inline]
    fn height(&self, uv: Vec2, p: Vec3) -> f32 {
        let c = self.eval(uv, p);
        (c.x + c.y + c.z) / 3.0
    }
}

/// Perlin's improved gradient noise (2002), roughly in `[-1, 1]`.
fn noise(p: Vec3) -> f32 {
    let fl = p.floor();
    let (xi, yi, zi) = (fl.x as i32 & 255, fl.y as i32 & 255, fl.z as i32 & 255);
    let f = p - fl;
    let fade = |t: f32| t * t * t * (t * (t * 6.0 - 15.0) + 10.0);
    let (u, v, w) = (fade(f.x), fade(f.y), fade(f.z));
    let perm = |i: i32| i32::from(PERM[(i & 255) as usize]);
    let grad = |h: i32, x: f32, y: f32, z: f32| {
        let h = h & 15;
        let a = if h < 8 { x } else { y };
        let b = if h < 4 {
            y
        } else if h == 12 || h == 14 {
            x
        } else {
            z
        };
        (if h & 1 == 0 { a } else { -a }) + (if h & 2 == 0 { b } else { -b })
    };
    let a = perm(xi) + yi;
    let (aa, ab) = (perm(a) + zi, perm(a + 1) + zi);
    let b = perm(xi + 1) + yi;
    let (ba, bb) = (perm(b) + zi, perm(b + 1) + zi);
    let (x, y, z) = (f.x, f.y, f.z);
    let lerp = |t: f32, a: f32, b: f32| a + t * (b - a);
    lerp(
        w,
        lerp(
            v,
            lerp(u, grad(perm(aa), x, y, z), grad(perm(ba), x - 1.0, y, z)),
            lerp(
                u,
                grad(perm(ab), x, y - 1.0, z),
                grad(perm(bb), x - 1.0, y - 1.0, z),
            ),
        ),
        lerp(
            v,
            lerp(
                u,
                grad(perm(aa + 1), x, y, z - 1.0),
                grad(perm(ba + 1), x - 1.0, y, z - 1.0),
            ),
            lerp(
                u,
                grad(perm(ab + 1), x, y - 1.0, z - 1.0),
                grad(perm(bb + 1), x - 1.0, y - 1.0, z - 1.0),
            ),
        ),
    )
}

/// Sum of `|noise|` over five octaves.
fn turbulence(p: Vec3) -> f32 {
    let mut sum = 0.0;
    let mut f = 1.0;
    for _ in 0..5 {
        sum += noise(p * f).abs() / f;
        f *= 2.0;
    }
    sum
}

/// A fixed permutation of 0..=255 (Fisher-Yates with a 64-bit LCG), as Perlin's table.
const PERM: [u8; 256] = {
    let mut p = [0u8; 256];
    let mut i = 0;
    while i < 256 {
        p[i] = i as u8;
        i += 1;
    }
    let mut state: u64 = 0x2545_f491_4f6c_dd1d;
    let mut i = 255;
    while i > 0 {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        let j = ((state >> 33) % (i as u64 + 1)) as usize;
        let t = p[i];
        p[i] = p[j];
        p[j] = t;
        i -= 1;
    }
    p
};

/// Blinn's bump mapping: the shading normal `n` (unit) perturbed by the height field
/// `bump` (scaled by `scale`) at `uv`, `p`, with surface tangents `dpdu`, `dpdv`.
/// Falls back to `n` where the result is degenerate.
pub fn bump_normal(
    bump: &Texture,
    scale: f32,
    uv: Vec2,
    p: Vec3,
    n: Vec3,
    dpdu: Vec3,
    dpdv: Vec3,
) -> Vec3 {
    let step = bump.step();
    let hu = scale
        * (bump.height(uv + Vec2::new(step.x * 0.5, 0.0), p)
            - bump.height(uv - Vec2::new(step.x * 0.5, 0.0), p))
        / step.x;
    let hv = scale
        * (bump.height(uv + Vec2::new(0.0, step.y * 0.5), p)
            - bump.height(uv - Vec2::new(0.0, step.y * 0.5), p))
        / step.y;
    let nu = dpdu + n * hu;
    let nv = dpdv + n * hv;
    let b = nu.cross(nv);
    let b = if b.dot(n) < 0.0 { -b } else { b };
    b.normalize_or(n)
}

/// The shading normal from a tangent-space normal map value `t` (linear, in `[0, 1]`)
/// in the frame of unit normal `n` and tangents `dpdu`, `dpdv`.
pub fn normal_map(t: Vec3, n: Vec3, dpdu: Vec3, dpdv: Vec3) -> Vec3 {
    let m = t * 2.0 - Vec3::ONE;
    let tangent = (dpdu - n * n.dot(dpdu)).normalize_or(crate::math::Frame::from_z(n).x);
    let mut bitangent = n.cross(tangent);
    if bitangent.dot(dpdv) < 0.0 {
        bitangent = -bitangent;
    }
    (tangent * m.x + bitangent * m.y + n * m.z).normalize_or(n)
}

/// An environment map for rays that leave the scene (see the module documentation for
/// the axis convention).
#[derive(Clone, Debug, PartialEq)]
pub enum Environment {
    /// Latitude-longitude (equirectangular) image.
    LatLong(Arc<Image>),
    /// Six faces, in the order +x, −x, +y, −y, +z, −z.
    Cube(Box<[Image; 6]>),
}

impl Environment {
    /// An environment from an image: 2:1 is latitude-longitude, 4:3 a cube cross.
    ///
    /// # Errors
    /// When the image has neither shape.
    pub fn from_image(img: Image) -> Result<Environment, TextureError> {
        let (w, h) = (img.width, img.height);
        if w == 2 * h {
            let mut img = img;
            img.wrap = Wrap::Repeat;
            return Ok(Environment::LatLong(Arc::new(img)));
        }
        if w % 4 == 0 && h % 3 == 0 && w / 4 == h / 3 {
            let f = w / 4;
            // (column, row) of each face in the cross, in the order +x −x +y −y +z −z.
            let at = [(2, 1), (0, 1), (1, 0), (1, 2), (3, 1), (1, 1)];
            let faces = at.map(|(c, r)| {
                let mut t = Vec::with_capacity((f * f) as usize);
                for j in 0..f {
                    let row = ((r * f + j) * w + c * f) as usize;
                    t.extend_from_slice(&img.texels[row..row + f as usize]);
                }
                Image {
                    width: f,
                    height: f,
                    texels: t,
                    wrap: Wrap::Clamp,
                }
            });
            return Ok(Environment::Cube(Box::new(faces)));
        }
        Err(TextureError::EnvironmentShape {
            width: w,
            height: h,
        })
    }

    /// A cube map from six square faces of one size, in the order +x, −x, +y, −y, +z,
    /// −z (see the module documentation for their orientation).
    ///
    /// # Errors
    /// When a face is not square or the sizes differ.
    pub fn from_faces(faces: [Image; 6]) -> Result<Environment, TextureError> {
        let (w, h) = (faces[0].width, faces[0].height);
        for (f, name) in faces.iter().zip(CUBE_FACES) {
            if f.width != f.height || (f.width, f.height) != (w, h) {
                return Err(TextureError::CubeFaces {
                    face: name,
                    size: (f.width, f.height),
                    first: (w, h),
                });
            }
        }
        Ok(Environment::Cube(Box::new(faces.map(|mut f| {
            f.wrap = Wrap::Clamp;
            f
        }))))
    }

    /// Read a cube map from six image files (colour, sRGB-decoded), in the order +x,
    /// −x, +y, −y, +z, −z.
    ///
    /// # Errors
    /// A message naming the file that cannot be read, or the faces' mismatch.
    pub fn load_faces(files: &[PathBuf; 6]) -> Result<Environment, TextureError> {
        let mut faces = Vec::with_capacity(6);
        for f in files {
            faces.push(Image::load(f, true)?);
        }
        let faces: [Image; 6] = faces.try_into().expect("six faces");
        Environment::from_faces(faces).map_err(|e| e.in_file(&files[0]))
    }

    /// Read an environment map (colour, sRGB-decoded): an image file (2:1 latitude-
    /// longitude or 4:3 cube cross), or a directory holding the six faces of a cube
    /// map, `px`, `nx`, `py`, `ny`, `pz`, `nz` with the extension `.png`, `.jpg` or
    /// `.jpeg`.
    ///
    /// # Errors
    /// A message naming the file (or the missing face).
    pub fn load(path: &Path) -> Result<Environment, TextureError> {
        if path.is_dir() {
            let mut files: [PathBuf; 6] = Default::default();
            for (file, face) in files.iter_mut().zip(CUBE_FACES) {
                *file = ["png", "jpg", "jpeg"]
                    .iter()
                    .map(|ext| path.join(format!("{face}.{ext}")))
                    .find(|f| f.is_file())
                    .ok_or_else(|| TextureError::MissingFace {
                        dir: path.to_path_buf(),
                        face,
                    })?;
            }
            return Environment::load_faces(&files);
        }
        let img = Image::load(path, true)?;
        Environment::from_image(img).map_err(|e| e.in_file(path))
    }

    /// The radiance arriving from direction `d` (any length).
    pub fn lookup(&self, d: Vec3) -> Vec3 {
        let d = d.normalize_or(Vec3::NEG_Z);
        match self {
            Environment::LatLong(img) => img.bilinear(latlong_uv(d)),
            Environment::Cube(faces) => {
                let (face, uv) = cube_face(d);
                faces[face].bilinear(uv)
            }
        }
    }
}

/// The names of the cube faces +x, −x, +y, −y, +z, −z (files in a cube map directory).
pub const CUBE_FACES: [&str; 6] = ["px", "nx", "py", "ny", "pz", "nz"];

/// The latitude-longitude texture coordinates of unit direction `d`.
pub fn latlong_uv(d: Vec3) -> Vec2 {
    let u = 0.5 + d.x.atan2(-d.z) / std::f32::consts::TAU;
    let v = 0.5 + d.y.clamp(-1.0, 1.0).asin() / std::f32::consts::PI;
    Vec2::new(u, v)
}

/// The cube face (+x −x +y −y +z −z as 0..6) of direction `d` and the texture
/// coordinates on it.
pub fn cube_face(d: Vec3) -> (usize, Vec2) {
    let a = d.abs();
    // (face, right coordinate, up coordinate, major magnitude)
    let (face, s, t, m) = if a.x >= a.y && a.x >= a.z {
        if d.x > 0.0 {
            (0, d.z, d.y, a.x)
        } else {
            (1, -d.z, d.y, a.x)
        }
    } else if a.y >= a.z {
        if d.y > 0.0 {
            (2, d.x, d.z, a.y)
        } else {
            (3, d.x, -d.z, a.y)
        }
    } else if d.z > 0.0 {
        (4, -d.x, d.y, a.z)
    } else {
        (5, d.x, d.y, a.z)
    };
    (face, Vec2::new(0.5 + 0.5 * s / m, 0.5 + 0.5 * t / m))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn error_messages_name_the_file_and_the_problem() {
        let image = |w: u32, h: u32| Image::new(w, h, vec![Vec3::ONE; (w * h) as usize]);
        assert_eq!(
            Image::new(2, 2, vec![Vec3::ONE; 3])
                .unwrap_err()
                .to_string(),
            "an image of 2 × 2 texels cannot hold 3 values"
        );
        assert_eq!(
            Environment::from_image(image(3, 3).unwrap())
                .unwrap_err()
                .to_string(),
            "an environment map is a 2:1 latitude-longitude image or a 4:3 cube cross, not \
             3 × 3"
        );
        let mut faces = std::array::from_fn(|_| image(4, 4).unwrap());
        faces[2] = image(8, 8).unwrap();
        assert_eq!(
            Environment::from_faces(faces).unwrap_err().to_string(),
            "the cube map's faces must be square and of one size: py is 8 × 8, px is 4 × 4"
        );
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path();
        assert_eq!(
            Environment::load(dir).unwrap_err().to_string(),
            format!(
                "{}: a cube map directory needs px.png (or .jpg, .jpeg), one of the faces px, \
                 nx, py, ny, pz, nz",
                dir.display()
            )
        );
        let missing = dir.join("missing.png");
        let e = Image::load(&missing, true).unwrap_err().to_string();
        assert!(
            e.starts_with(&format!("{}: cannot read image: ", missing.display())),
            "{e}"
        );
    }

    #[test]
    fn srgb_decode_endpoints() {
        assert_eq!(srgb_to_linear(0.0), 0.0);
        assert!((srgb_to_linear(1.0) - 1.0).abs() < 1e-6);
        assert!((srgb_to_linear(0.5) - 0.214).abs() < 1e-3);
    }

    #[test]
    fn cube_faces_of_the_axes() {
        let cases = [
            (Vec3::X, 0),
            (-Vec3::X, 1),
            (Vec3::Y, 2),
            (-Vec3::Y, 3),
            (Vec3::Z, 4),
            (-Vec3::Z, 5),
        ];
        for (d, f) in cases {
            let (face, uv) = cube_face(d);
            assert_eq!(face, f);
            assert!((uv - Vec2::splat(0.5)).length() < 1e-6);
        }
        // Looking along −z, +x is to the right and +y up.
        let (_, uv) = cube_face(Vec3::new(0.5, 0.25, -1.0));
        assert!((uv - Vec2::new(0.75, 0.625)).length() < 1e-6);
    }

    #[test]
    fn latlong_axes() {
        assert!((latlong_uv(Vec3::NEG_Z) - Vec2::new(0.5, 0.5)).length() < 1e-6);
        assert!((latlong_uv(Vec3::X) - Vec2::new(0.75, 0.5)).length() < 1e-6);
        assert!((latlong_uv(Vec3::Y).y - 1.0).abs() < 1e-6);
    }

    #[test]
    fn noise_is_bounded_and_varies() {
        let mut lo = f32::MAX;
        let mut hi = f32::MIN;
        for i in 0..1000 {
            let p = Vec3::new(i as f32 * 0.37, i as f32 * 0.11, i as f32 * 0.053);
            let n = noise(p);
            lo = lo.min(n);
            hi = hi.max(n);
        }
        assert!(lo >= -1.01 && hi <= 1.01 && hi - lo > 0.5, "{lo} {hi}");
        assert_eq!(
            noise(Vec3::new(1.0, 2.0, 3.0)),
            0.0,
            "zero at lattice points"
        );
    }
}
