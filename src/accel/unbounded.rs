//! The unbounded primitives of a scene (infinite planes, quadrics that are not clipped
//! and not ellipsoids): no hierarchy can hold them, so both backends keep them out of
//! their structures and test them against every ray first, then search their structure
//! only up to the nearest unbounded hit.
//!
//! The list holds the top level's unbounded primitives, then each instance's copy of
//! its object's (with the instance's transform), in a fixed order: the top level's by
//! kind and index, then the instances in order, each object's by kind and index. The
//! nearest hit keeps the first primitive of that order among hits at the same distance.

use crate::accel::{Hit, NO_INSTANCE};
use crate::geometry::{Analytic, Intersect, Kind, Shape};
use crate::math::{Ray, Xform};
use crate::scene::{Geometry, KindVisitor, Prims, Scene};

/// Whether a primitive with these bounds goes to the unbounded list rather than into a
/// backend's hierarchy: any bounds with an infinite (or NaN) coordinate.
pub fn is_unbounded(bounds: &crate::math::Aabb) -> bool {
    !bounds.is_finite()
}

/// One unbounded primitive.
#[derive(Clone, Debug)]
struct Entry {
    shape: Shape,
    kind: Kind,
    prim: u32,
    /// `(instance index, its transform)` for an instance's copy.
    inst: Option<(u32, Xform)>,
}

/// The unbounded primitives of a scene (see the module documentation).
#[derive(Clone, Debug, Default)]
pub struct Unbounded {
    entries: Vec<Entry>,
}

impl Unbounded {
    /// The unbounded primitives of `scene`: the top level's, then each instance's.
    pub fn new(scene: &Scene) -> Unbounded {
        let mut entries = Vec::new();
        for (kind, prim, shape) in of_geometry(&scene.geometry) {
            entries.push(Entry {
                shape,
                kind,
                prim,
                inst: None,
            });
        }
        let objects: Vec<Vec<(Kind, u32, Shape)>> = scene.objects.iter().map(of_geometry).collect();
        for (i, inst) in (0u32..).zip(&scene.instances) {
            for (kind, prim, shape) in &objects[inst.object as usize] {
                entries.push(Entry {
                    shape: shape.clone(),
                    kind: *kind,
                    prim: *prim,
                    inst: Some((i, inst.xform)),
                });
            }
        }
        Unbounded { entries }
    }

    /// True when the scene has none (the Embree backend then skips testing them).
    #[cfg(feature = "embree")]
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// Number of unbounded primitives (each instance's copies counted).
    pub fn len(&self) -> usize {
        self.entries.len()
    }

    /// Bytes of the list.
    pub fn memory_bytes(&self) -> usize {
        self.entries.len() * std::mem::size_of::<Entry>()
    }

    /// The nearest hit in `(ray.tmin, ray.tmax)`; between hits at the same distance,
    /// the first in the list.
    #[inline]
    pub fn nearest(&self, ray: &Ray) -> Option<Hit> {
        let mut best: Option<Hit> = None;
        let mut r = *ray;
        for u in &self.entries {
            let h = match &u.inst {
                None => u.shape.intersect(&r),
                Some((_, x)) => u.shape.intersect(&x.ray_to_object(&r)),
            };
            if let Some(h) = h {
                r.tmax = h.t;
                best = Some(Hit {
                    t: h.t,
                    geom_id: u.kind as u32,
                    prim_id: u.prim,
                    u: h.u,
                    v: h.v,
                    ng: h.ng,
                    inst_id: u.inst.map_or(NO_INSTANCE, |(i, _)| i),
                });
            }
        }
        best
    }

    /// Whether any of them is hit in `(ray.tmin, ray.tmax)`.
    #[inline]
    pub fn any(&self, ray: &Ray) -> bool {
        self.entries.iter().any(|u| match &u.inst {
            None => u.shape.occluded(ray),
            Some((_, x)) => u.shape.occluded(&x.ray_to_object(ray)),
        })
    }
}

/// The unbounded primitives of one store as `(kind, prim_id, shape)`, by kind and index.
fn of_geometry(geometry: &Geometry) -> Vec<(Kind, u32, Shape)> {
    let mut collect = Collect(Vec::new());
    geometry.visit_all(&mut collect);
    collect.0
}

/// Collects the unbounded primitives of the lists it visits.
struct Collect(Vec<(Kind, u32, Shape)>);

impl KindVisitor<'_> for Collect {
    type Output = ();
    fn visit<P: Analytic>(&mut self, list: &Prims<P>) {
        for (i, prim, _) in list.iter() {
            if is_unbounded(&prim.bounds()) {
                self.0.push((P::KIND, i, prim.clone().into()));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Plane, Sphere};
    use crate::math::Vec3;
    use crate::scene::{Camera, Instance};

    fn scene() -> Scene {
        Scene::new(Camera {
            from: Vec3::Z,
            at: Vec3::ZERO,
            up: Vec3::Y,
            angle_deg: 45.0,
            hither: 0.0,
            width: 4,
            height: 4,
        })
    }

    #[test]
    fn top_level_then_instances_nearest_first() {
        let mut s = scene();
        s.geometry.push(Sphere::new(Vec3::ZERO, 1.0), 0);
        s.geometry
            .push(Plane::new(Vec3::Y, -2.0).expect("plane"), 0);
        let mut object = Geometry::default();
        object.push(Plane::new(Vec3::Y, 0.0).expect("plane"), 0);
        s.objects.push(object);
        let lift = |y: f32| Xform::new(glam::Affine3A::from_translation(Vec3::Y * y)).unwrap();
        for y in [-1.0, -3.0] {
            s.instances.push(Instance {
                object: 0,
                xform: lift(y),
                material: 0,
            });
        }
        let u = Unbounded::new(&s);
        assert_eq!(u.len(), 3, "the sphere is bounded");
        let down = Ray::new(Vec3::new(5.0, 10.0, 0.0), -Vec3::Y);
        let h = u.nearest(&down).expect("hit");
        // The plane at y = -1 (instance 0) is the nearest: 11 down.
        assert_eq!(
            (h.t, h.geom_id, h.prim_id, h.inst_id),
            (11.0, Kind::Plane as u32, 0, 0)
        );
        let short = Ray { tmax: 10.5, ..down };
        assert!(u.nearest(&short).is_none() && !u.any(&short));
        assert!(u.any(&down));
        let up = Ray::new(Vec3::new(5.0, -2.5, 0.0), Vec3::Y);
        let h = u.nearest(&up).expect("hit");
        // From between y = -3 and y = -2, going up: the top level's plane at -2.
        assert_eq!((h.t, h.inst_id), (0.5, NO_INSTANCE));
    }
}
