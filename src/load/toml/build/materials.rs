//! `[materials.NAME]`: materials with their texture maps (image files or procedural
//! checker and marble textures), references to them by name, and the default material
//! of objects that name none.

use super::super::format::{MaterialDef, Real, Spanned, TextureDef, V3};
use super::Sink;
use super::{Builder, R, did_you_mean};
use crate::math::Vec3;
use crate::scene::texture::{Image, Wrap};
use crate::scene::{INHERIT, Maps, Material, Texture, range};
use std::sync::Arc;

/// Phong exponent when a material gives none.
const DEFAULT_SHININESS: f64 = 32.0;

impl<'a> Builder<'a, '_> {
    /// Every named material, numbered in file order (the map itself is sorted by name).
    pub(super) fn named_materials(&mut self) -> R<()> {
        let file = self.file;
        let mut materials: Vec<_> = file.materials.iter().collect();
        materials.sort_by_key(|(_, d)| d.span().start);
        for (name, def) in materials {
            let mut m = self.material(def)?;
            m.maps = self.maps(def)?;
            let index = self.materials.len();
            let (file, line) = (self.origin_file.clone(), self.line_of(def.span()));
            self.sources.materials.add(index, 1, &file, line);
            self.material_names.insert(name, index as u32);
            self.materials.push(m);
        }
        Ok(())
    }

    /// The texture maps of a material definition (images read now).
    fn maps(&mut self, def: &Spanned<MaterialDef>) -> R<Maps> {
        let d = def.get_ref();
        let mut maps = Maps::NONE;
        for (t, slot, srgb) in [
            (&d.texture, &mut maps.color, true),
            (&d.specular_map, &mut maps.specular, true),
            (&d.bump, &mut maps.bump, false),
            (&d.normal_map, &mut maps.normal, false),
        ] {
            if let Some(t) = t {
                let tex = self.texture(t, srgb)?;
                self.textures.push(tex);
                *slot = self.textures.len() as u32 - 1;
            }
        }
        if let Some(s) = &d.bump_scale {
            maps.bump_scale = s.get_ref().0 as f32;
        }
        if let Some(s) = &d.uv_scale {
            let [a, b] = s.get_ref();
            if !(a.0 != 0.0 && b.0 != 0.0) {
                return Err(self.err(s.span(), "`uv_scale` must not be zero"));
            }
            maps.uv_scale = [a.0 as f32, b.0 as f32];
        }
        Ok(maps)
    }

    /// A texture: an image file (`srgb` for colours, linear for bump and normal maps),
    /// or a procedural `checker` or `marble`.
    fn texture(&self, def: &Spanned<TextureDef>, srgb: bool) -> R<Texture> {
        let t = def.get_ref();
        let ty = t.ty.as_ref().map(|s| (s.get_ref().as_str(), s.span()));
        match (ty, &t.file) {
            (None | Some(("image", _)), Some(file)) => self.image_texture(t, file, srgb),
            (Some((kind @ ("checker" | "marble"), _)), None) => self.procedural_texture(t, kind),
            (None | Some(("image", _)), None) => {
                Err(self.err(def.span(), "an image texture needs a `file`"))
            }
            (Some((other, span)), _) if !matches!(other, "image" | "checker" | "marble") => {
                Err(self.err(
                    span,
                    format!(
                        "unknown texture type `{other}` (expected `image`, `checker` or `marble`)"
                    ),
                ))
            }
            (_, Some(file)) => Err(self.err(
                file.span(),
                "`file` is for image textures (remove `type` or set it to \"image\")",
            )),
            (Some((_, span)), None) => Err(self.err(span, "an image texture needs a `file`")),
        }
    }

    /// An image texture read from `file` (relative to the scene file), with its wrap mode.
    fn image_texture(&self, t: &TextureDef, file: &Spanned<String>, srgb: bool) -> R<Texture> {
        let path = self.relative_path(file.get_ref());
        let mut img = Image::load(&path, srgb).map_err(|e| self.err(file.span(), e.to_string()))?;
        img.wrap = match t.wrap.as_ref().map(|w| (w.get_ref().as_str(), w.span())) {
            None | Some(("repeat", _)) => Wrap::Repeat,
            Some(("clamp", _)) => Wrap::Clamp,
            Some((w, span)) => {
                return Err(self.err(
                    span,
                    format!("unknown wrap mode `{w}` (expected `repeat` or `clamp`)"),
                ));
            }
        };
        Ok(Texture::Image(Arc::new(img)))
    }

    /// A `checker` or `marble` texture between colours `a` and `b`.
    fn procedural_texture(&self, t: &TextureDef, kind: &str) -> R<Texture> {
        let colour = |v: &Option<Spanned<V3>>, default: Vec3| -> R<Vec3> {
            v.as_ref()
                .map_or(Ok(default), |c| self.non_negative3(c, "a texture colour"))
        };
        let a = colour(&t.a, Vec3::ONE)?;
        let b = colour(&t.b, Vec3::ZERO)?;
        let default = if kind == "checker" { 8.0 } else { 4.0 };
        let scale = match &t.scale {
            Some(s) => self.positive(s, "`scale`")? as f32,
            None => default,
        };
        Ok(if kind == "checker" {
            Texture::Checker { a, b, scale }
        } else {
            Texture::Marble { a, b, scale }
        })
    }

    /// A material's colours and coefficients (its maps apart).
    fn material(&self, def: &Spanned<MaterialDef>) -> R<Material> {
        let d = def.get_ref();
        let weight = |v: &Option<Spanned<Real>>, name: &str, default: f64| -> R<f32> {
            match v {
                Some(v) => Ok(self.non_negative(v, &format!("`{name}`"))? as f32),
                None => Ok(default as f32),
            }
        };
        let color = match &d.color {
            Some(c) => self.colour(c, "`color`")?,
            None => Vec3::ONE,
        };
        let kd = weight(&d.diffuse, "diffuse", 1.0)?;
        let ior = match &d.ior {
            Some(v) => self.positive(v, "`ior`")? as f32,
            None => 1.0,
        };
        let t = weight(&d.transmittance, "transmittance", 0.0)?;
        if let Err(e) = range::check_ior(t, ior) {
            let at = d.ior.as_ref().map_or(def.span(), |v| v.span());
            return Err(self.err(at, e.to_string()));
        }
        Ok(Material {
            color,
            ka: weight(&d.ambient, "ambient", kd as f64)?,
            kd,
            ks: weight(&d.specular, "specular", 0.0)?,
            shine: weight(&d.shininess, "shininess", DEFAULT_SHININESS)?,
            kr: weight(&d.reflectance, "reflectance", 0.0)?,
            t,
            ior,
            filter: match &d.filter {
                Some(f) => self.colour(f, "`filter`")?,
                None => Vec3::ONE,
            },
            priority: d.priority.as_ref().map_or(0, |p| *p.get_ref()),
            emission: match &d.emission {
                Some(e) => self.non_negative3(e, "`emission`")?,
                None => Vec3::ZERO,
            },
            ..Material::DEFAULT
        })
    }

    /// The index of the material named `name`.
    pub(super) fn material_ref(&self, name: &Spanned<String>) -> R<u32> {
        let n = name.get_ref().as_str();
        self.material_names.get(n).copied().ok_or_else(|| {
            let hint = if self.material_names.is_empty() {
                " (the file defines no `[materials.NAME]`)".to_string()
            } else {
                did_you_mean(n, self.file.materials.keys().map(String::as_str))
            };
            self.err(name.span(), format!("unknown material `{n}`{hint}"))
        })
    }

    /// `material` if given, else the material of primitives given none: inherited
    /// inside a define, else the default material (added on first use).
    pub(super) fn material_or_fallback(&mut self, material: Option<u32>, sink: &Sink) -> u32 {
        match material {
            Some(m) => m,
            None => self.fallback_material(sink),
        }
    }

    fn fallback_material(&mut self, sink: &Sink) -> u32 {
        if sink.in_define() {
            return INHERIT;
        }
        match self.default_material {
            Some(m) => m,
            None => {
                let m = self.materials.len() as u32;
                let def = Spanned::new(0..0, MaterialDef::default());
                let mat = self.material(&def).expect("the default material is valid");
                self.materials.push(mat);
                self.default_material = Some(m);
                m
            }
        }
    }
}
