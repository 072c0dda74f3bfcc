//! The media a ray travels in: the transmissive solids it is inside, innermost last,
//! for Snell's law with the right indices when dielectrics nest (a liquid in a glass)
//! and for Schmidt & Budge's priorities when they overlap.

use crate::scene::Scene;

/// Most lower-priority surfaces one ray may pass through.
pub(super) const MAX_SKIPS: u32 = 64;

/// The transmissive solids a ray is inside (material indices, innermost last), for
/// Snell's law with the right indices when media nest (a liquid in a glass) and for
/// Schmidt & Budge's priorities when they overlap.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Media {
    ids: [u32; MEDIA_DEPTH],
    len: u8,
}

/// Nesting depth tracked; deeper entries are not recorded (the ray then sees the
/// innermost recorded medium).
const MEDIA_DEPTH: usize = 8;

impl Media {
    /// Outside everything.
    pub const AIR: Media = Media {
        ids: [0; MEDIA_DEPTH],
        len: 0,
    };

    /// The material indices of the media, outermost first.
    pub fn iter(&self) -> impl Iterator<Item = u32> + '_ {
        self.ids[..self.len as usize].iter().copied()
    }

    /// The medium in force: the highest priority, the innermost among equals.
    pub fn current(&self, scene: &Scene) -> Option<u32> {
        let mut best: Option<u32> = None;
        for id in self.iter() {
            let p = scene.materials[id as usize].priority;
            match best {
                Some(b) if p < scene.materials[b as usize].priority => {}
                _ => best = Some(id),
            }
        }
        best
    }

    /// Index of refraction of the medium in force (1 outside everything).
    pub fn ior(&self, scene: &Scene) -> f32 {
        self.current(scene)
            .map_or(1.0, |id| scene.materials[id as usize].ior)
    }

    /// Whether the boundary of `material` is not optically there: entering it while a
    /// higher-priority medium is in force, or leaving it while one it is inside of is.
    pub fn is_false_boundary(&self, scene: &Scene, material: u32, entering: bool) -> bool {
        let p = scene.materials[material as usize].priority;
        let higher = |id: u32| id != material && scene.materials[id as usize].priority > p;
        if entering {
            self.iter().any(higher)
        } else {
            self.iter().any(|id| id == material) && self.iter().any(higher)
        }
    }

    /// Inside `material` too, as the innermost medium.
    pub fn enter(&self, material: u32) -> Media {
        let mut m = *self;
        if (m.len as usize) < MEDIA_DEPTH {
            m.ids[m.len as usize] = material;
            m.len += 1;
        }
        m
    }

    /// Without the innermost entry of `material` (unchanged if the ray was not in it:
    /// an open transmissive surface seen from its back).
    pub fn leave(&self, material: u32) -> Media {
        let mut m = *self;
        if let Some(k) = m.ids[..m.len as usize]
            .iter()
            .rposition(|&id| id == material)
        {
            m.ids.copy_within(k + 1..m.len as usize, k);
            m.len -= 1;
            m.ids[m.len as usize] = 0;
        }
        m
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Vec3;

    fn dielectrics(priorities: [u32; 3]) -> Scene {
        let cam = crate::scene::Camera {
            from: Vec3::Z,
            at: Vec3::ZERO,
            up: Vec3::Y,
            angle_deg: 40.0,
            hither: 0.0,
            width: 1,
            height: 1,
        };
        let mut s = Scene::new(cam);
        for (k, ior) in [1.5f32, 1.31, 1.33].into_iter().enumerate() {
            s.materials.push(crate::scene::Material {
                t: 1.0,
                ior,
                priority: priorities[k],
                ..Default::default()
            });
        }
        s
    }

    #[test]
    fn nested_media_use_the_enclosing_index() {
        let s = dielectrics([0, 0, 0]);
        let air = Media::AIR;
        assert_eq!(air.ior(&s), 1.0);
        // Into the ice (1), then into the liquid (2) inside it: the liquid is in force;
        // leaving the liquid returns to the ice, not to air.
        let ice = air.enter(1);
        let liquid = ice.enter(2);
        assert_eq!(liquid.ior(&s), 1.33);
        assert_eq!(liquid.leave(2).ior(&s), 1.31);
        assert_eq!(liquid.leave(2).leave(1), air);
        // Leaving a medium the ray was never in (an open surface's back) changes nothing.
        assert_eq!(ice.leave(0), ice);
        // With equal priorities every boundary is real.
        assert!(!liquid.is_false_boundary(&s, 2, false));
        assert!(!ice.is_false_boundary(&s, 2, true));
    }

    #[test]
    fn priorities_skip_the_lower_medium_inside_the_higher() {
        // Ice (priority 2) overlaps the liquid (priority 1) in the cavity walls.
        let s = dielectrics([0, 2, 1]);
        let in_ice = Media::AIR.enter(1);
        // Entering the liquid inside the ice: a false boundary; the ice stays in force.
        assert!(in_ice.is_false_boundary(&s, 2, true));
        let both = in_ice.enter(2);
        assert_eq!(both.ior(&s), 1.31);
        // Leaving the ice into the cavity, below the liquid level: a real boundary into
        // the liquid (1.31 -> 1.33), not into air.
        assert!(!both.is_false_boundary(&s, 1, false));
        assert_eq!(both.leave(1).ior(&s), 1.33);
        // Entering the ice from the liquid is real (higher priority).
        assert!(!Media::AIR.enter(2).is_false_boundary(&s, 1, true));
        // Leaving the liquid while inside the ice: false.
        assert!(both.is_false_boundary(&s, 2, false));
    }

    #[test]
    fn media_depth_is_bounded() {
        let mut m = Media::AIR;
        for i in 0..20 {
            m = m.enter(i);
        }
        assert_eq!(m.len as usize, MEDIA_DEPTH);
    }
}
