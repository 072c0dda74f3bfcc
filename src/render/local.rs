//! The local light at a hit: ambient, emission and the area lights' diffuse light
//! ([`Tracer::local_diffuse`]), and each point light's Phong diffuse and highlight
//! after its shadow ray ([`Tracer::direct`]); each term is reported to the
//! [`Recorder`].

use super::area;
use super::optics::reflect;
use super::record::{LightTerm, Recorder, Term};
use super::whitted::Tracer;
use crate::accel::Accel;
use crate::math::{Ray, RayOrigins, Vec3, next_float_down};
use crate::scene::{Light, Material, Surface};

impl<A: Accel> Tracer<'_, A> {
    /// The diffuse and highlight light `light` (number `index`) sends to `surf`
    /// (material `m`, shading normal `ns` facing the ray of unit direction `d`), after
    /// its shadow ray from one of `origins`.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    pub(super) fn direct<R: Recorder>(
        &self,
        index: usize,
        light: &Light,
        surf: &Surface,
        m: &Material,
        origins: &mut RayOrigins,
        ns: Vec3,
        d: Vec3,
        rec: &mut R,
    ) -> Vec3 {
        let p = surf.point.p;
        let to_light = light.pos - p;
        // No shadow ray when the shading normal faces away from the light or the
        // light sends nothing here (with `skip` off the ray is cast and ignored,
        // to measure what skipping saves).
        let intensity = light.intensity_at(p);
        let useless = ns.dot(to_light) <= 0.0 || intensity == Vec3::ZERO;
        let mut term = LightTerm {
            light: index,
            shadow: None,
            useless,
            occluded: false,
            intensity,
            diffuse: Vec3::ZERO,
            specular: 0.0,
            value: Vec3::ZERO,
        };
        if useless && self.skip {
            rec.counts().skipped_shadow += 1;
            rec.light(&term);
            return Vec3::ZERO;
        }
        rec.counts().shadow += 1;
        let org = origins.towards(to_light);
        let mut shadow = Ray::new(org, light.pos - org);
        shadow.tmax = next_float_down(1.0);
        let occluded = self.accel.occluded(&shadow);
        term.shadow = Some(&shadow);
        term.occluded = occluded;
        if occluded || useless {
            rec.light(&term);
            return Vec3::ZERO;
        }
        let l = to_light.normalize();
        let diffuse = m.color * (m.kd * ns.dot(l));
        let mut c = diffuse;
        let mut specular = 0.0;
        if m.ks > 0.0 {
            let rv = reflect(-l, ns).dot(-d).max(0.0);
            specular = m.ks * rv.powf(m.shine);
            c += Vec3::splat(specular);
        }
        let value = intensity * c;
        rec.light(&LightTerm {
            diffuse,
            specular,
            value,
            ..term
        });
        value
    }

    /// Ambient, emission (front side) and the area lights' diffuse light.
    pub(super) fn local_diffuse<R: Recorder>(
        &self,
        at: &area::Receiver,
        m: &Material,
        entering: bool,
        path: u32,
        rec: &mut R,
    ) -> Vec3 {
        let mut color = self.scene.ambient * m.color * m.ka;
        rec.term(Term::Ambient, color);
        if entering && m.is_emitter() {
            rec.term(Term::Emission, m.emission);
            color += m.emission;
        }
        if !self.area_lights.is_empty() && m.kd > 0.0 {
            let (e, rays) = area::direct_recorded(
                self.accel,
                &self.area_lights,
                at,
                self.area_strata,
                path,
                rec,
            );
            rec.counts().shadow += rays;
            let area = m.color * m.kd * e;
            rec.term(Term::Area, area);
            color += area;
        }
        color
    }
}
