use super::{Ray, Vec3};

/// An axis-aligned bounding box. The empty box has `min = +inf`, `max = -inf`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Lower corner.
    pub min: Vec3,
    /// Upper corner.
    pub max: Vec3,
}

impl Default for Aabb {
    fn default() -> Self {
        Self::EMPTY
    }
}

impl Aabb {
    /// The empty box, identity of [`Aabb::union`].
    pub const EMPTY: Aabb = Aabb {
        min: Vec3::splat(f32::INFINITY),
        max: Vec3::splat(f32::NEG_INFINITY),
    };

    /// The box spanning two corners given in any order.
    pub fn from_points(a: Vec3, b: Vec3) -> Self {
        Aabb {
            min: a.min(b),
            max: a.max(b),
        }
    }

    /// True when every coordinate is finite (an empty box is not).
    pub fn is_finite(&self) -> bool {
        self.min.is_finite() && self.max.is_finite()
    }

    /// All of space: the bounds of unbounded primitives.
    pub const INFINITE: Aabb = Aabb {
        min: Vec3::splat(f32::NEG_INFINITY),
        max: Vec3::splat(f32::INFINITY),
    };

    /// True when the box has no points (`min > max` on some axis).
    pub fn is_empty(&self) -> bool {
        self.min.x > self.max.x || self.min.y > self.max.y || self.min.z > self.max.z
    }

    /// Smallest box containing both.
    #[inline]
    pub fn union(&self, o: &Aabb) -> Aabb {
        Aabb {
            min: self.min.min(o.min),
            max: self.max.max(o.max),
        }
    }

    /// Smallest box containing this box and `p`.
    #[inline]
    pub fn grow(&self, p: Vec3) -> Aabb {
        Aabb {
            min: self.min.min(p),
            max: self.max.max(p),
        }
    }

    /// Centre point.
    #[inline]
    pub fn centroid(&self) -> Vec3 {
        (self.min + self.max) * 0.5
    }

    /// Extent along each axis.
    #[inline]
    pub fn extent(&self) -> Vec3 {
        self.max - self.min
    }

    /// Surface area (0 for the empty box).
    #[inline]
    pub fn surface_area(&self) -> f32 {
        if self.is_empty() {
            return 0.0;
        }
        let e = self.extent();
        2.0 * (e.x * e.y + e.y * e.z + e.z * e.x)
    }

    /// Index of the longest axis.
    pub fn longest_axis(&self) -> usize {
        let e = self.extent();
        if e.x >= e.y && e.x >= e.z {
            0
        } else if e.y >= e.z {
            1
        } else {
            2
        }
    }

    /// True when `p` lies inside or on the box.
    pub fn contains(&self, p: Vec3) -> bool {
        p.cmpge(self.min).all() && p.cmple(self.max).all()
    }

    /// Slab test: the entry distance if the ray meets the box within `[tmin, tmax]`.
    ///
    /// `inv_dir` is `1 / ray.dir` per component. The far distance is widened by
    /// `1 + 2 gamma(3)` (pbrt's conservative slab test) so that rounding never culls a
    /// box that the ray truly touches.
    #[inline]
    pub fn hit(&self, org: Vec3, inv_dir: Vec3, tmin: f32, tmax: f32) -> Option<f32> {
        let t0 = (self.min - org) * inv_dir;
        let t1 = (self.max - org) * inv_dir;
        let near = t0.min(t1);
        let far = t0.max(t1) * (1.0 + 2.0 * super::gamma(3));
        let tn = near.max_element().max(tmin);
        let tf = far.min_element().min(tmax);
        if tn <= tf { Some(tn) } else { None }
    }

    /// Convenience form of [`Aabb::hit`] for a whole ray.
    pub fn hit_ray(&self, ray: &Ray) -> Option<f32> {
        self.hit(ray.org, ray.dir.recip(), ray.tmin, ray.tmax)
    }
}
