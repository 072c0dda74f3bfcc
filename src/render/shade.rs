//! Whitted shading at a surface, one hit of the wavefront at a time: ambient, emission
//! and area lights at once, the point lights' shadow rays queued with the depth's
//! (see [`super::local`]), and the mirror reflection and Snell refraction (through
//! nested media) spawned into the next depth's queue, linked to their parent in the
//! batch's tree. The formula is in docs/architecture.md ("NFF semantics") and
//! docs/nff.md; every term is reported to the [`Recorder`] as it is known.

use super::area;
use super::local::Receiver;
use super::media::Media;
use super::optics::{reflect, refract};
use super::path::PathState;
use super::record::{Boundary, NotCast, RayKind, Recorder, Term, Traced};
use super::wavefront::Depth;
use super::whitted::{Tracer, children};
use crate::accel::Accel;
use crate::math::{Ray, RayOrigins, Vec3};
use crate::scene::{Material, Surface};

/// A true surface hit, about to be shaded.
pub(super) struct Arrival<'s> {
    /// The ray's path.
    pub state: &'s PathState,
    /// The surface.
    pub surf: &'s Surface,
    /// The ray's unit direction.
    pub d: Vec3,
    /// Whether the ray enters the solid (hits the front of the geometric normal).
    pub entering: bool,
    /// The radiosity there in two-pass mode.
    pub gi: Option<Vec3>,
}

impl<A: Accel> Tracer<'_, A> {
    /// Whitted shading of `at`: its local light goes into its node (the point lights'
    /// once their shadow rays are cast), its reflection and refraction rays into
    /// `depth`'s next queue. In two-pass mode the radiosity replaces the ambient,
    /// emitted and area-light terms (the radiosity pass knows only emitters: point
    /// lights still add their direct diffuse and highlights, reflection and
    /// refraction stay).
    pub(super) fn shade<R: Recorder>(&self, at: &Arrival, depth: &mut Depth, rec: &mut R) {
        let (surf, d, s) = (at.surf, at.d, at.state);
        // Textured inputs and the bumped shading normal (scene/texture.rs).
        let (m, ns) = self.scene.shading(surf);
        let m = &m;
        let p = surf.point.p;
        let ng_out = surf.point.ng;
        // Both sides are surfaces: face the normals towards the incoming ray.
        let ng = if at.entering { ng_out } else { -ng_out };
        let ns = if ns.dot(d) > 0.0 { -ns } else { ns };
        rec.shading(s.node, m, ns);
        // Every ray leaving this hit starts from one of the two offset points.
        let mut origins = RayOrigins::new(p, surf.point.err, ng);
        depth.tree.node(s.node).local = match at.gi {
            Some(b) => {
                rec.term(s.node, Term::Radiosity, b);
                b
            }
            None => {
                let receiver = area::Receiver {
                    p,
                    err: surf.point.err,
                    ng,
                    ns,
                };
                self.local_diffuse(s.node, &receiver, m, at.entering, s.path, rec)
            }
        };
        let receiver = Receiver {
            node: s.node,
            p,
            ns,
            d,
            origins: &mut origins,
        };
        self.queue_lights(receiver, m, &mut depth.lights, rec);
        if s.depth < self.max_depth {
            let hit = Bounce {
                at,
                m,
                ns,
                origins: &mut origins,
            };
            self.secondary(hit, depth, rec);
        }
    }

    /// Spawn the reflection and refraction rays of `hit`: Snell refraction into the
    /// next medium (on total internal reflection the transmitted energy goes to the
    /// reflection ray), and mirror reflection weighted by `Kr` (plus that energy).
    ///
    /// In SPD mode the rays are cast and counted as the SPD's reference does: a
    /// reflection ray from every transmitter, also with `Ks = 0` (cast, its light of
    /// weight 0 not added, so the image does not change), and on total internal
    /// reflection a refraction ray counted though none exists (the reference counts
    /// the refraction it tries). Measured against the SPD's published counts on gears
    /// (glass with `Ks = 0`): without the first, reflection is 71% short; casting the
    /// total internal reflection's ray as a ray of its own overshoots by 2.8% to 4%.
    fn secondary<R: Recorder>(&self, mut hit: Bounce, depth: &mut Depth, rec: &mut R) {
        let (s, m, d) = (hit.at.state, hit.m, hit.at.d);
        let (reflected, refracted) = children(s.path);
        let mut reflect_weight = m.kr;
        let mut total_internal = false;
        if m.t > 0.0 {
            match self.refraction(&hit, rec) {
                Some((dir, w, inside)) => {
                    if self.worth(s.weight * w, rec.counts()) {
                        rec.counts().refraction += 1;
                        let ray = Ray::new(hit.origins.towards(dir), dir);
                        let child = Child {
                            kind: RayKind::Refraction,
                            ray,
                            path: refracted,
                            media: inside,
                            local_weight: w,
                            discarded: false,
                        };
                        let node = depth.spawn(s, child, rec);
                        depth.tree.node(s.node).refraction = Some((node, w));
                    } else {
                        rec.not_cast(s.node, RayKind::Refraction, NotCast::Bailout, s.weight * w);
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
            dir: reflect(d, hit.ns),
            transmits: m.t > 0.0,
            path: reflected,
        };
        self.reflection(&mut hit, &mirror, depth, rec);
        if self.spd && total_internal {
            // The reference counts the refraction ray it tries here as cast.
            rec.counts().refraction += 1;
        }
    }

    /// The refraction at transmissive `hit`: its direction, its weight `T × filter`
    /// and the media beyond, or `None` on total internal reflection (told to `rec`).
    fn refraction<R: Recorder>(&self, hit: &Bounce, rec: &mut R) -> Option<(Vec3, Vec3, Media)> {
        let scene = self.scene;
        let (s, m) = (hit.at.state, hit.m);
        let material = hit.at.surf.material;
        // Snell's law between the medium the ray is in and the one it goes into.
        let (n1, n2, inside) = if hit.at.entering {
            let inside = s.media.enter(material);
            (s.media.ior(scene), m.ior, inside)
        } else {
            let inside = s.media.leave(material);
            (m.ior, inside.ior(scene), inside)
        };
        let out = refract(hit.at.d, hit.ns, n1 / n2);
        let boundary = Boundary {
            n1,
            n2,
            tir: out.is_none(),
            inside,
        };
        rec.boundary(s.node, &boundary);
        let dir = out?;
        // Light is filtered by the medium it goes into.
        let filter = inside
            .current(scene)
            .map_or(Vec3::ONE, |id| scene.materials[id as usize].filter);
        Some((dir, m.t * filter, inside))
    }

    /// Spawn the mirror reflection `mirror` of `hit` (cast and its light thrown away
    /// when its weight is 0 and the SPD's reference or `--no-skip` casts it).
    #[inline(always)]
    fn reflection<R: Recorder>(
        &self,
        hit: &mut Bounce,
        mirror: &Mirror,
        depth: &mut Depth,
        rec: &mut R,
    ) {
        let s = hit.at.state;
        let reflect_weight = mirror.weight;
        let w = s.weight * reflect_weight;
        let weighted = reflect_weight > 0.0;
        if weighted {
            if !self.worth(w, rec.counts()) {
                rec.not_cast(s.node, RayKind::Reflection, NotCast::Bailout, w);
                return;
            }
        } else if self.skip && !(self.spd && mirror.transmits) {
            rec.counts().skipped_reflection += 1;
            rec.not_cast(s.node, RayKind::Reflection, NotCast::NoReflectance, w);
            return;
        }
        rec.counts().reflection += 1;
        let child = Child {
            kind: RayKind::Reflection,
            ray: Ray::new(hit.origins.towards(mirror.dir), mirror.dir),
            path: mirror.path,
            media: s.media,
            local_weight: Vec3::splat(reflect_weight),
            discarded: !weighted,
        };
        let node = depth.spawn(s, child, rec);
        if weighted {
            depth.tree.node(s.node).reflection = Some((node, reflect_weight));
        }
    }
}

/// A shaded hit about to spawn its reflection and refraction.
struct Bounce<'a, 's, 'o> {
    at: &'a Arrival<'s>,
    /// The material after textures.
    m: &'a Material,
    /// The shading normal facing the ray.
    ns: Vec3,
    origins: &'o mut RayOrigins,
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
    /// Its path identity.
    path: u32,
}

/// A reflection or refraction ray about to be spawned.
pub(super) struct Child {
    pub kind: RayKind,
    pub ray: Ray,
    /// Its path identity.
    pub path: u32,
    /// The media it travels in.
    pub media: Media,
    /// What its radiance is multiplied by in its parent.
    pub local_weight: Vec3,
    /// Cast, its light not used.
    pub discarded: bool,
}

impl<'a> Traced<'a> {
    /// The record of `child`, spawned as `node` at the hit of `parent`.
    #[inline(always)]
    pub(super) fn child(
        parent: &PathState,
        child: &'a Child,
        node: u32,
        position: (u32, u32),
    ) -> Self {
        Traced {
            node,
            parent: Some(parent.node),
            position,
            kind: child.kind,
            depth: parent.depth + 1,
            ray: &child.ray,
            local_weight: child.local_weight,
            weight: parent.weight * child.local_weight,
            discarded: child.discarded,
        }
    }
}
