//! Whitted shading at a surface: ambient, emission and area lights, Phong light from
//! point lights with shadow rays, mirror reflection and Snell refraction through nested
//! media. The formula is in docs/architecture.md ("NFF semantics") and docs/nff.md;
//! every term is reported to the [`Recorder`] as it is added.

use super::area;
use super::media::Media;
use super::optics::{reflect, refract};
use super::record::{Boundary, NotCast, RayKind, Recorder, Term, Traced};
use super::whitted::{Tracer, children};
use crate::accel::Accel;
use crate::math::{Ray, RayOrigins, Vec3};
use crate::scene::{Material, Surface};

impl<A: Accel> Tracer<'_, A> {
    /// Whitted shading of a true surface hit seen along unit direction `d`; `gi` is the
    /// radiosity there in two-pass mode, which replaces the ambient, emitted and
    /// area-light terms (the radiosity pass knows only emitters: point lights still
    /// add their direct diffuse and highlights, reflection and refraction stay).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn shade<R: Recorder>(
        &self,
        surf: &Surface,
        d: Vec3,
        entering: bool,
        depth: u32,
        path: u32,
        media: Media,
        weight: Vec3,
        gi: Option<Vec3>,
        rec: &mut R,
    ) -> Vec3 {
        let scene = self.scene;
        // Textured inputs and the bumped shading normal (scene/texture.rs).
        let (m, ns) = scene.shading(surf);
        let m = &m;
        let p = surf.point.p;
        let ng_out = surf.point.ng;
        // Both sides are surfaces: face the normals towards the incoming ray.
        let ng = if entering { ng_out } else { -ng_out };
        let ns = if ns.dot(d) > 0.0 { -ns } else { ns };
        rec.shading(m, ns);
        // Every ray leaving this hit starts from one of the two offset points.
        let mut origins = RayOrigins::new(p, surf.point.err, ng);

        let mut color = match gi {
            Some(b) => {
                rec.term(Term::Radiosity, b);
                b
            }
            None => {
                let at = area::Receiver {
                    p,
                    err: surf.point.err,
                    ng,
                    ns,
                };
                self.local_diffuse(&at, m, entering, path, rec)
            }
        };
        for (index, light) in scene.lights.iter().enumerate() {
            color += self.direct(index, light, surf, m, &mut origins, ns, d, rec);
        }
        rec.local(color);

        if depth >= self.max_depth {
            return color;
        }
        self.secondary(
            color,
            surf,
            m,
            ns,
            d,
            entering,
            &mut origins,
            depth,
            path,
            media,
            weight,
            rec,
        )
    }

    /// `color` plus the light of the reflection and refraction rays from `surf`: Snell
    /// refraction into the next medium (on total internal reflection the transmitted
    /// energy goes to the reflection ray), and mirror reflection weighted by `Kr` (plus
    /// that energy).
    ///
    /// In SPD mode the rays are cast and counted as the SPD's reference does: a
    /// reflection ray from every transmitter, also with `Ks = 0` (cast, its light of
    /// weight 0 not added, so the image does not change), and on total internal
    /// reflection a refraction ray counted though none exists (the reference counts
    /// the refraction it tries). Measured against the SPD's published counts on gears
    /// (glass with `Ks = 0`): without the first, reflection is 71% short; casting the
    /// total internal reflection's ray as a ray of its own overshoots by 2.8% to 4%.
    #[allow(clippy::too_many_arguments)]
    fn secondary<R: Recorder>(
        &self,
        mut color: Vec3,
        surf: &Surface,
        m: &Material,
        ns: Vec3,
        d: Vec3,
        entering: bool,
        origins: &mut RayOrigins,
        depth: u32,
        path: u32,
        media: Media,
        weight: Vec3,
        rec: &mut R,
    ) -> Vec3 {
        let scene = self.scene;
        let (reflected, refracted) = children(path);
        let mut reflect_weight = m.kr;
        let mut total_internal = false;
        if m.t > 0.0 {
            // Snell's law between the medium the ray is in and the one it goes into.
            let (n1, n2, inside) = if entering {
                let inside = media.enter(surf.material);
                (media.ior(scene), m.ior, inside)
            } else {
                let inside = media.leave(surf.material);
                (m.ior, inside.ior(scene), inside)
            };
            let out = refract(d, ns, n1 / n2);
            rec.boundary(&Boundary {
                n1,
                n2,
                tir: out.is_none(),
                inside,
            });
            match out {
                Some(dir) => {
                    // Light is filtered by the medium it goes into.
                    let filter = inside
                        .current(scene)
                        .map_or(Vec3::ONE, |id| scene.materials[id as usize].filter);
                    let w = m.t * filter;
                    if self.worth(weight * w, rec.counts()) {
                        rec.counts().refraction += 1;
                        let ray = Ray::new(origins.towards(dir), dir);
                        let child = Traced {
                            kind: RayKind::Refraction,
                            depth: depth + 1,
                            ray: &ray,
                            local_weight: w,
                            weight: weight * w,
                            discarded: false,
                        };
                        rec.ray(&child);
                        let l = self.trace(&ray, depth + 1, refracted, inside, weight * w, rec);
                        rec.ray_end(l);
                        color += w * l;
                    } else {
                        rec.not_cast(RayKind::Refraction, NotCast::Bailout, weight * w);
                    }
                }
                None => {
                    // Total internal reflection: the transmitted energy is reflected.
                    rec.counts().tir += 1;
                    reflect_weight += m.t;
                    total_internal = true;
                }
            }
        }
        let mirror = Mirror {
            weight: reflect_weight,
            dir: reflect(d, ns),
            transmits: m.t > 0.0,
        };
        color = self.reflection(
            color, &mirror, origins, depth, reflected, media, weight, rec,
        );
        if self.spd && total_internal {
            // The reference counts the refraction ray it tries here as cast.
            rec.counts().refraction += 1;
        }
        color
    }

    /// `color` plus the light of the mirror reflection `mirror` (cast and its light
    /// thrown away when its weight is 0 and the SPD's reference or `--no-skip` casts
    /// it).
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn reflection<R: Recorder>(
        &self,
        mut color: Vec3,
        mirror: &Mirror,
        origins: &mut RayOrigins,
        depth: u32,
        path: u32,
        media: Media,
        weight: Vec3,
        rec: &mut R,
    ) -> Vec3 {
        let reflect_weight = mirror.weight;
        let w = weight * reflect_weight;
        let dir = mirror.dir;
        let weighted = reflect_weight > 0.0;
        let discarded = !weighted;
        if weighted {
            if !self.worth(w, rec.counts()) {
                rec.not_cast(RayKind::Reflection, NotCast::Bailout, w);
                return color;
            }
        } else if self.skip && !(self.spd && mirror.transmits) {
            rec.counts().skipped_reflection += 1;
            rec.not_cast(RayKind::Reflection, NotCast::NoReflectance, w);
            return color;
        }
        rec.counts().reflection += 1;
        let ray = Ray::new(origins.towards(dir), dir);
        rec.ray(&Traced {
            kind: RayKind::Reflection,
            depth: depth + 1,
            ray: &ray,
            local_weight: Vec3::splat(reflect_weight),
            weight: w,
            discarded,
        });
        let l = self.trace(&ray, depth + 1, path, media, w, rec);
        rec.ray_end(l);
        if weighted {
            color += reflect_weight * l;
        }
        color
    }
}

/// The mirror reflection at a hit.
struct Mirror {
    /// Its weight: `Kr`, plus `T` on total internal reflection.
    weight: f32,
    /// Its direction.
    dir: Vec3,
    /// Whether the surface transmits (the SPD's reference casts a reflection ray from
    /// every transmitter).
    transmits: bool,
}
