//! `[[lights]]`: point lights and spot lights, with their colour, intensity and
//! attenuation.

use super::super::format::{LightDef, Spanned};
use super::{Builder, R, did_you_mean, f32v, v3};
use crate::math::Vec3;
use crate::scene::{Light, Spot, range};
use glam::DVec3;

/// Spot cutoff half-angle when a light gives none.
const DEFAULT_CUTOFF: f64 = 45.0;

impl Builder<'_, '_> {
    /// Every light of the file, in file order.
    pub(super) fn file_lights(&mut self) -> R<()> {
        let file = self.file;
        for l in &file.lights {
            let light = self.light(l)?;
            let (index, line) = (self.lights.len(), self.line_of(l.span()));
            let origin = self.origin_file.clone();
            self.sources.lights.add(index, 1, &origin, line);
            self.lights.push(light);
        }
        Ok(())
    }

    fn light(&self, def: &Spanned<LightDef>) -> R<Light> {
        let l = def.get_ref();
        let spot = self.is_spot(l)?;
        if !spot {
            self.refuse_spot_keys(l)?;
        }
        let pos = v3(l.position.get_ref());
        range::check_point("the light `position`", f32v(pos))
            .map_err(|e| self.err(l.position.span(), e.to_string()))?;
        let color = match &l.color {
            Some(c) => self.non_negative3(c, "light `color`")?,
            None => Vec3::ONE,
        };
        let intensity = match &l.intensity {
            Some(i) => self.non_negative(i, "light `intensity`")? as f32,
            None => 1.0,
        };
        let attenuation = self.attenuation(l)?;
        let spot = if spot {
            Some(self.spot(def, pos)?)
        } else {
            None
        };
        Ok(Light {
            pos: f32v(pos - self.origin),
            color: color * intensity,
            spot,
            attenuation,
        })
    }

    /// Whether `type` makes the light a spot light (else a point light).
    fn is_spot(&self, l: &LightDef) -> R<bool> {
        let Some(t) = &l.ty else {
            return Ok(false);
        };
        match t.get_ref().as_str() {
            "point" => Ok(false),
            "spot" => Ok(true),
            other => Err(self.err(
                t.span(),
                format!(
                    "unknown light type `{other}`{}; light types: point, spot",
                    did_you_mean(other, ["point", "spot"])
                ),
            )),
        }
    }

    /// Refuse a spot light's keys on a point light.
    fn refuse_spot_keys(&self, l: &LightDef) -> R<()> {
        for (k, v) in [
            ("direction", l.direction.as_ref().map(|v| v.span())),
            ("target", l.target.as_ref().map(|v| v.span())),
            ("cutoff", l.cutoff.as_ref().map(|v| v.span())),
            ("exponent", l.exponent.as_ref().map(|v| v.span())),
        ] {
            if let Some(span) = v {
                return Err(self.err(
                    span,
                    format!("`{k}` is for spot lights (add `type = \"spot\"`)"),
                ));
            }
        }
        Ok(())
    }

    /// The constant, linear and quadratic attenuation (not all zero).
    fn attenuation(&self, l: &LightDef) -> R<Vec3> {
        let Some(a) = &l.attenuation else {
            return Ok(Vec3::X);
        };
        let v = self.non_negative3(a, "`attenuation`")?;
        if v == Vec3::ZERO {
            return Err(self.err(a.span(), "`attenuation` must not be all zero"));
        }
        Ok(v)
    }

    /// The cone of a spot light at `pos`.
    fn spot(&self, def: &Spanned<LightDef>, pos: DVec3) -> R<Spot> {
        let l = def.get_ref();
        let dir = self.spot_direction(def, pos)?;
        let cutoff = match &l.cutoff {
            Some(c) => {
                let a = c.get_ref().0;
                if !(a > 0.0 && a < 180.0) {
                    return Err(self.err(
                        c.span(),
                        format!(
                            "`cutoff` must be between 0 and 180 degrees (exclusive), found {a}"
                        ),
                    ));
                }
                a
            }
            None => DEFAULT_CUTOFF,
        };
        let exponent = match &l.exponent {
            Some(e) => self.non_negative(e, "`exponent`")?,
            None => 0.0,
        };
        Ok(Spot {
            dir: f32v(dir),
            cos_cutoff: cutoff.to_radians().cos() as f32,
            exponent: exponent as f32,
        })
    }

    /// The unit direction of a spot light at `pos`: its `direction`, or towards its
    /// `target`.
    fn spot_direction(&self, def: &Spanned<LightDef>, pos: DVec3) -> R<DVec3> {
        let l = def.get_ref();
        match (&l.direction, &l.target) {
            (Some(d), None) => self.direction(d, "spot `direction`"),
            (None, Some(t)) => {
                let d = v3(t.get_ref()) - pos;
                if d == DVec3::ZERO {
                    return Err(self.err(t.span(), "spot `target` equals its `position`"));
                }
                Ok((d / d.abs().max_element()).normalize())
            }
            (Some(_), Some(t)) => Err(self.err(
                t.span(),
                "a spot light takes `direction` or `target`, not both",
            )),
            (None, None) => Err(self.err(def.span(), "a spot light needs `direction` or `target`")),
        }
    }
}
