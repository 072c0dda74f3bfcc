//! MTL materials as Whitted materials: the mapping of the module documentation
//! (colours, ambient and specular weights, transparency, index of refraction, and the
//! illumination models).

use super::DEFAULT_MATERIAL;
use super::located::show;
use super::mtl::MtlMaterial;
use super::parse::UseMtl;
use crate::math::Vec3;
use crate::scene::{Environment, Material, Texture, range};
use std::collections::HashMap;
use std::path::Path;

/// Material slot of faces that get [`DEFAULT_MATERIAL`] (appended on first use).
pub(super) const DEFAULT_SLOT: u32 = u32::MAX;

/// The model's materials, textures and environment.
pub(super) struct Materials {
    /// The libraries' materials in the order read, then [`DEFAULT_MATERIAL`] once a
    /// face uses it.
    pub list: Vec<Material>,
    pub textures: Vec<Texture>,
    pub environment: Option<Environment>,
    /// Library material index by name (a later definition wins).
    pub by_name: HashMap<String, u32>,
    default_index: Option<u32>,
}

impl Materials {
    /// The libraries' materials, converted; a warning (naming `path`, the OBJ file) for
    /// each whose `Ni` cannot be used.
    pub fn new(path: &Path, mtl: &[MtlMaterial], warnings: &mut Vec<String>) -> Self {
        let mut list = Vec::with_capacity(mtl.len() + 1);
        let mut by_name = HashMap::new();
        for (i, m) in mtl.iter().enumerate() {
            let (mat, warning) = convert_material(m);
            if let Some(w) = warning {
                warnings.push(format!("{}: {w}", path.display()));
            }
            list.push(mat);
            by_name.insert(m.name.clone(), i as u32);
        }
        Materials {
            list,
            textures: Vec::new(),
            environment: None,
            by_name,
            default_index: None,
        }
    }

    /// The material slot of each `usemtl`, warning once per name that no library
    /// defines. `names_libraries`: whether the file has an `mtllib`; `read`: the
    /// libraries read.
    pub fn slots(
        &self,
        usemtl: &[UseMtl],
        names_libraries: bool,
        read: &[String],
        path: &Path,
        warnings: &mut Vec<String>,
    ) -> Vec<u32> {
        let mut missing: Vec<&str> = Vec::new();
        let mut slots = Vec::with_capacity(usemtl.len());
        for u in usemtl {
            if let Some(&i) = self.by_name.get(&u.name) {
                slots.push(i);
                continue;
            }
            slots.push(DEFAULT_SLOT);
            if missing.contains(&u.name.as_str()) {
                continue;
            }
            missing.push(&u.name);
            let where_ = if !names_libraries {
                "the file names no material library ('mtllib')".to_string()
            } else if read.is_empty() {
                "no material library could be read".to_string()
            } else {
                format!("it is not in {}", read.join(", "))
            };
            warnings.push(format!(
                "{}:{}: material {} not found ({where_}); its faces get the default grey \
                 material",
                path.display(),
                u.line,
                show(&u.name)
            ));
        }
        slots
    }

    /// The index [`DEFAULT_MATERIAL`] has in [`Materials::list`], or will have once a
    /// face uses it ([`Materials::index`] of [`DEFAULT_SLOT`] adds it).
    pub fn default_index(&self) -> u32 {
        self.default_index.unwrap_or(self.list.len() as u32)
    }

    /// The index in [`Materials::list`] of a slot.
    pub fn index(&mut self, slot: u32) -> u32 {
        if slot != DEFAULT_SLOT {
            return slot;
        }
        *self.default_index.get_or_insert_with(|| {
            self.list.push(DEFAULT_MATERIAL);
            self.list.len() as u32 - 1
        })
    }
}

fn mean(c: [f32; 3]) -> f32 {
    (c[0] + c[1] + c[2]) / 3.0
}

/// An MTL material as a Whitted material (the mapping of the module documentation),
/// with a warning when its `Ni` cannot be used for a transmissive material.
pub(super) fn convert_material(m: &MtlMaterial) -> (Material, Option<String>) {
    let clamp = |c: [f32; 3]| c.map(|v| v.max(0.0));
    let ka_rgb = m.ambient.map(clamp);
    let kd_rgb = m.diffuse.map(clamp);
    let ks_rgb = m.specular.map(clamp).unwrap_or([0.0; 3]);
    let tr = m.transparency.filter(|v| v.is_finite());
    let d = m
        .dissolve
        .filter(|v| v.is_finite())
        .or(tr.map(|t| 1.0 - t))
        .unwrap_or(1.0)
        .clamp(0.0, 1.0);
    let illum = m.illumination_model.unwrap_or(2);

    let (color, kd, mut ka) = match kd_rgb {
        Some(kd) if mean(kd) > 0.0 => {
            let ka = ka_rgb.map_or(1.0, |ka| mean(ka) / mean(kd));
            (Vec3::from(kd), 1.0, ka)
        }
        // A black or missing Kd: the diffuse term is zero whatever the colour, which
        // can then carry Ka exactly.
        _ => (Vec3::from(ka_rgb.unwrap_or([0.0; 3])), 0.0, 1.0),
    };
    let mut ks = mean(ks_rgb);
    let mut kr = 0.0;
    match illum {
        0 => {
            ka = 0.0;
            ks = 0.0;
        }
        1 => ks = 0.0,
        3 | 5 | 7 => kr = mean(ks_rgb),
        _ => {}
    }
    let t = 1.0 - d;
    let ni = m.optical_density.filter(|n| range::IOR_RANGE.contains(n));
    let warning = (t > 0.0 && ni.is_none()).then(|| {
        let found = m
            .optical_density
            .map_or("no 'Ni'".to_string(), |n| format!("Ni {n}"));
        format!(
            "material '{}' is transparent (d = {d}) but has {found}: index of refraction 1 \
             used",
            m.name
        )
    });
    let material = Material {
        color,
        ka,
        kd,
        ks,
        shine: m
            .shininess
            .filter(|s| s.is_finite())
            .unwrap_or(1.0)
            .max(0.0),
        kr,
        t,
        ior: ni.unwrap_or(1.0),
        filter: Vec3::ONE,
        priority: 0,
        ..Material::DEFAULT
    };
    (material, warning)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mtl(name: &str, f: impl FnOnce(&mut MtlMaterial)) -> MtlMaterial {
        let mut m = MtlMaterial {
            name: name.into(),
            diffuse: Some([0.2, 0.4, 0.6]),
            specular: Some([0.3, 0.6, 0.9]),
            shininess: Some(20.0),
            ..Default::default()
        };
        f(&mut m);
        m
    }

    #[test]
    fn illumination_models() {
        // (illum, ka, ks, kr) with Kd = (0.2 0.4 0.6), Ks mean 0.6, no Ka.
        let ks = 0.6;
        let table: [(Option<u8>, f32, f32, f32); 12] = [
            (Some(0), 0.0, 0.0, 0.0),
            (Some(1), 1.0, 0.0, 0.0),
            (Some(2), 1.0, ks, 0.0),
            (Some(3), 1.0, ks, ks),
            (Some(4), 1.0, ks, 0.0),
            (Some(5), 1.0, ks, ks),
            (Some(6), 1.0, ks, 0.0),
            (Some(7), 1.0, ks, ks),
            (Some(8), 1.0, ks, 0.0),
            (Some(9), 1.0, ks, 0.0),
            (Some(10), 1.0, ks, 0.0),
            (None, 1.0, ks, 0.0),
        ];
        for (illum, ka, ks, kr) in table {
            let (m, w) = convert_material(&mtl("m", |m| m.illumination_model = illum));
            assert!(w.is_none());
            let got = (m.ka, m.ks, m.kr);
            assert!(
                (got.0 - ka).abs() < 1e-6 && (got.1 - ks).abs() < 1e-6 && (got.2 - kr).abs() < 1e-6,
                "illum {illum:?}: {got:?}"
            );
            assert_eq!(
                (m.color, m.kd, m.shine),
                (Vec3::new(0.2, 0.4, 0.6), 1.0, 20.0)
            );
            assert_eq!(
                (m.t, m.ior),
                (0.0, 1.0),
                "illum {illum:?}: opaque without d"
            );
        }
    }

    #[test]
    fn ambient_transparency_and_defaults() {
        // Ka relative to Kd.
        let (m, _) = convert_material(&mtl("m", |m| m.ambient = Some([0.1, 0.2, 0.3])));
        assert!((m.ka - 0.5).abs() < 1e-6, "{}", m.ka);
        // No Kd: the colour carries Ka, no diffuse term.
        let (m, _) = convert_material(&mtl("m", |m| {
            m.diffuse = None;
            m.ambient = Some([0.1, 0.2, 0.3]);
        }));
        assert_eq!((m.color, m.kd, m.ka), (Vec3::new(0.1, 0.2, 0.3), 0.0, 1.0));
        // Nothing at all: black, Ns 1.
        let (m, _) = convert_material(&MtlMaterial::default());
        assert_eq!((m.color, m.kd, m.ks, m.shine), (Vec3::ZERO, 0.0, 0.0, 1.0));
        // d wins over Tr, transmittance for any illum; negative colours clamped.
        let (m, w) = convert_material(&mtl("glass", |m| {
            m.dissolve = Some(0.3);
            m.transparency = Some(0.9);
            m.optical_density = Some(1.33);
            m.illumination_model = Some(2);
            m.diffuse = Some([-1.0, 0.5, 0.5]);
        }));
        assert!(w.is_none());
        assert!((m.t - 0.7).abs() < 1e-6 && m.ior == 1.33 && m.kr == 0.0);
        assert_eq!(m.color, Vec3::new(0.0, 0.5, 0.5));
        let (m, w) = convert_material(&mtl("tr", |m| {
            m.transparency = Some(0.25);
        }));
        assert_eq!((m.t, m.ior), (0.25, 1.0));
        assert!(w.unwrap().contains("no 'Ni'"));
        // An opaque material's unusable Ni is no concern.
        let (m, w) = convert_material(&mtl("m", |m| m.optical_density = Some(0.0)));
        assert!(w.is_none() && m.ior == 1.0);
    }
}
