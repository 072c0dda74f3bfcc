//! Surfaces in bulk. The wavefront shades a depth's hits kind by kind; here a run of
//! hits on one primitive kind becomes its surfaces together: the kind is matched once
//! for the run (a [`KindVisitor`] at the list's static type) instead of once per hit,
//! and the surfaces go into a structure of arrays ([`Surfaces`]) holding what shading
//! reads: the point, its error bound, the geometric and shading normals, the material
//! and, for textured materials alone, the texture parameters.
//!
//! The values are [`Scene::surface_of`]'s, bit for bit: the same functions compute
//! them (a test checks it on every kind, instances and textures included).

use super::store::{KindVisitor, Prims, analytic_surface};
use super::{Hit, NO_INSTANCE, Scene, Surface};
use crate::geometry::{Analytic, Kind, Param, SurfacePoint};
use crate::math::{Ray, Vec3};

/// [`Surfaces::param`] of a surface without texture parameters.
const NO_PARAM: u32 = u32::MAX;

/// The surfaces of a batch of hits, by the order they were added in.
#[derive(Clone, Debug, Default)]
pub struct Surfaces {
    p: Vec<Vec3>,
    err: Vec<Vec3>,
    ng: Vec<Vec3>,
    ns: Vec<Vec3>,
    material: Vec<u32>,
    /// Per surface: its index into `params`, or [`NO_PARAM`].
    param: Vec<u32>,
    /// The texture parameters of the surfaces whose material has texture maps.
    params: Vec<Param>,
}

impl Surfaces {
    /// Forget every surface, keeping the storage, and make room for `n`.
    pub fn clear(&mut self, n: usize) {
        self.p.clear();
        self.err.clear();
        self.ng.clear();
        self.ns.clear();
        self.material.clear();
        self.param.clear();
        self.params.clear();
        self.p.reserve(n);
        self.err.reserve(n);
        self.ng.reserve(n);
        self.ns.reserve(n);
        self.material.reserve(n);
        self.param.reserve(n);
    }

    /// Number of surfaces.
    pub fn len(&self) -> usize {
        self.p.len()
    }

    /// True when there are none.
    pub fn is_empty(&self) -> bool {
        self.p.is_empty()
    }

    /// Surface `i`.
    #[inline]
    pub fn get(&self, i: usize) -> Surface {
        let param = match self.param[i] {
            NO_PARAM => None,
            k => Some(self.params[k as usize]),
        };
        Surface {
            point: SurfacePoint {
                p: self.p[i],
                err: self.err[i],
                ng: self.ng[i],
            },
            ns: self.ns[i],
            material: self.material[i],
            param,
        }
    }

    #[inline(always)]
    fn push(&mut self, s: &Surface) {
        self.p.push(s.point.p);
        self.err.push(s.point.err);
        self.ng.push(s.point.ng);
        self.ns.push(s.ns);
        self.material.push(s.material);
        let param = match s.param {
            Some(prm) => {
                self.params.push(prm);
                self.params.len() as u32 - 1
            }
            None => NO_PARAM,
        };
        self.param.push(param);
    }
}

impl Scene {
    /// The surfaces at the hits `run` names (indices into `hits` and `rays`, each a
    /// hit of its ray on the same primitive kind), pushed onto `out` in `run`'s order:
    /// what [`Scene::surface_of`] gives for each, with `exact` as it takes it. A hit
    /// in an instance, or of another kind, is handed to [`Scene::surface_of`].
    pub fn surfaces(
        &self,
        run: &[u32],
        hits: &[Option<Hit>],
        rays: &[Ray],
        exact: bool,
        out: &mut Surfaces,
    ) {
        let Some(first) = run.first().and_then(|&i| hits[i as usize]) else {
            return;
        };
        let mut bulk = Bulk {
            scene: self,
            run,
            hits,
            rays,
            exact,
            out,
        };
        match Kind::from_id(first.geom_id) {
            Some(Kind::Triangle) => bulk.triangles(),
            Some(kind) => {
                self.geometry.visit(kind, &mut bulk);
            }
            None => bulk.one_by_one(),
        }
    }

    /// `surf`, a top-level hit's surface, with its texture parameters when its
    /// material has texture maps.
    #[inline(always)]
    fn with_param(&self, hit: &Hit, mut surf: Surface) -> Surface {
        if self.textured(surf.material) {
            surf.param = Some(self.geometry.param(hit, &surf));
        }
        surf
    }
}

/// A run of hits on one kind being turned into surfaces.
struct Bulk<'a> {
    scene: &'a Scene,
    run: &'a [u32],
    hits: &'a [Option<Hit>],
    rays: &'a [Ray],
    exact: bool,
    out: &'a mut Surfaces,
}

impl Bulk<'_> {
    /// Hit `i` of the batch and its ray.
    #[inline(always)]
    fn at(&self, i: u32) -> (&Hit, &Ray) {
        let i = i as usize;
        let hit = self.hits[i].as_ref().expect("a run of hits holds no miss");
        (hit, &self.rays[i])
    }

    /// Every hit of the run through [`Scene::surface_of`].
    fn one_by_one(&mut self) {
        for &i in self.run {
            let (hit, ray) = self.at(i);
            let surf = self.scene.surface_of(hit, ray, self.exact);
            self.out.push(&surf);
        }
    }

    /// A run of triangle hits: each re-tested by the watertight test unless `exact`.
    fn triangles(&mut self) {
        let scene = self.scene;
        let geometry = &scene.geometry;
        for &i in self.run {
            let (hit, ray) = self.at(i);
            let surf = if hit.inst_id != NO_INSTANCE || hit.geom_id != Kind::Triangle as u32 {
                scene.surface_of(hit, ray, self.exact)
            } else {
                let tested;
                let hit = if self.exact {
                    hit
                } else {
                    tested = geometry.exact_hit(hit, ray);
                    &tested
                };
                let surf = geometry.triangle_surface(hit.prim_id as usize, hit);
                scene.with_param(hit, surf)
            };
            self.out.push(&surf);
        }
    }
}

impl KindVisitor<'_> for Bulk<'_> {
    type Output = ();

    /// A run of hits on `prims`' kind.
    #[inline]
    fn visit<P: Analytic>(&mut self, prims: &Prims<P>) {
        let scene = self.scene;
        for &i in self.run {
            let (hit, ray) = self.at(i);
            let surf = if hit.inst_id != NO_INSTANCE || hit.geom_id != P::KIND as u32 {
                scene.surface_of(hit, ray, self.exact)
            } else {
                let surf = analytic_surface(prims, hit.prim_id as usize, hit, ray);
                scene.with_param(hit, surf)
            };
            self.out.push(&surf);
        }
    }
}
