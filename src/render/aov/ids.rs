//! Primitive ids for the `id` output variable: every primitive a ray can meet (each
//! instance's copy apart) gets a number from 1, in a fixed order (the scene's own
//! primitives kind by kind, then each instance's object's), so that the same scene
//! always numbers alike, whichever part of the image is rendered. 0 is no primitive
//! (the ray left the scene). [`IdEntry`] says what an id is and where it was defined,
//! for the `.ids.json` file beside the image.

use crate::geometry::Kind;
use crate::scene::{Geometry, Hit, NO_INSTANCE, Scene};
use serde::{Deserialize, Serialize};

/// The id of a pixel no primitive covers.
pub const NO_ID: u32 = 0;

/// Ids too many for 32 bits.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error(
    "the scene has {0} primitives counting each instance's copies: more than the 4294967295 \
     a 32-bit id can number"
)]
pub struct TooManyIds(pub u64);

/// The numbering of a scene's primitives.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct IdMap {
    /// First id of each kind in the scene's own primitives.
    top: Vec<u64>,
    /// Per instance: the first id of each kind of its object's primitives.
    instances: Vec<Vec<u64>>,
    /// One past the last id.
    end: u64,
}

/// The first id of each kind of `g`'s primitives when its first primitive is `base`,
/// and the id after its last.
fn offsets(g: &Geometry, base: u64) -> (Vec<u64>, u64) {
    let mut next = base;
    let firsts = Kind::ALL
        .iter()
        .map(|&k| {
            let first = next;
            next += g.count(k) as u64;
            first
        })
        .collect();
    (firsts, next)
}

impl IdMap {
    /// Number the primitives of `scene`.
    pub fn new(scene: &Scene) -> Result<IdMap, TooManyIds> {
        let (top, mut next) = offsets(&scene.geometry, 1);
        let mut instances = Vec::with_capacity(scene.instances.len());
        for inst in &scene.instances {
            let (firsts, after) = offsets(&scene.objects[inst.object as usize], next);
            instances.push(firsts);
            next = after;
        }
        if next - 1 > u32::MAX as u64 {
            return Err(TooManyIds(next - 1));
        }
        Ok(IdMap {
            top,
            instances,
            end: next,
        })
    }

    /// The id of the primitive `hit` is on.
    #[inline]
    pub fn id(&self, hit: &Hit) -> u32 {
        let firsts = if hit.inst_id == NO_INSTANCE {
            &self.top
        } else {
            &self.instances[hit.inst_id as usize]
        };
        (firsts[hit.geom_id as usize] + hit.prim_id as u64) as u32
    }

    /// What id `id` is: `(instance, kind, index within the kind's list)`.
    pub fn resolve(&self, id: u32) -> Option<(Option<u32>, Kind, u32)> {
        let id = id as u64;
        if id == 0 || id >= self.end {
            return None;
        }
        // The block (the scene's own, or an instance's) holding the id: the last one
        // that starts at or before it.
        let starts = self.instances.partition_point(|f| f[0] <= id);
        let (instance, firsts) = match starts {
            0 => (None, &self.top),
            k => (Some(k as u32 - 1), &self.instances[k - 1]),
        };
        let k = firsts.partition_point(|&f| f <= id) - 1;
        Some((instance, Kind::ALL[k], (id - firsts[k]) as u32))
    }
}

/// What an id stands for, as the `.ids.json` file lists it.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct IdEntry {
    /// The id (as the `id` channel holds it).
    pub id: u32,
    /// The primitive's kind (`triangle`, `sphere`, ...).
    pub kind: String,
    /// Its index within its kind's list (of the scene, or of the instanced object).
    pub prim: u32,
    /// The instance it belongs to, if any.
    pub instance: Option<u32>,
    /// Where it was defined, `file:line`.
    pub source: Option<String>,
    /// Where the instance was placed, `file:line`.
    pub instance_source: Option<String>,
}

/// The entries of `ids` (ascending, each once; [`NO_ID`] left out).
pub fn entries(scene: &Scene, map: &IdMap, ids: &[u32]) -> Vec<IdEntry> {
    ids.iter()
        .filter_map(|&id| {
            let (instance, kind, prim) = map.resolve(id)?;
            let geometry = match instance {
                None => &scene.geometry,
                Some(i) => &scene.objects[scene.instances[i as usize].object as usize],
            };
            Some(IdEntry {
                id,
                kind: kind.singular().to_string(),
                prim,
                instance,
                source: geometry.sources.get(kind, prim).map(|o| o.to_string()),
                instance_source: instance
                    .and_then(|i| scene.sources.instances.get(i))
                    .map(|o| o.to_string()),
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ids_number_the_primitives_and_resolve_back() {
        let src = "v from 0 0 5 at 0 0 0 up 0 1 0 angle 40 hither 1 resolution 8 8\n\
                   s 0 0 0 1\ns 2 0 0 1\np 3 0 0 0 1 0 0 0 1 0\nc 0 0 0 1 0 1 0 1\n";
        let scene = crate::load::nff::parse_str(src, std::path::Path::new("a.nff")).unwrap();
        let map = IdMap::new(&scene).unwrap();
        let hit = |kind: Kind, prim: u32| Hit {
            t: 1.0,
            geom_id: kind as u32,
            prim_id: prim,
            u: 0.0,
            v: 0.0,
            ng: glam::Vec3::Z,
            inst_id: NO_INSTANCE,
        };
        // Kinds in table order: triangles first.
        assert_eq!(map.id(&hit(Kind::Triangle, 0)), 1);
        let s0 = map.id(&hit(Kind::Sphere, 0));
        let s1 = map.id(&hit(Kind::Sphere, 1));
        let c0 = map.id(&hit(Kind::Cone, 0));
        let mut all = vec![1, s0, s1, c0];
        all.sort();
        assert_eq!(all, vec![1, 2, 3, 4], "dense from 1");
        assert_eq!(map.resolve(s1), Some((None, Kind::Sphere, 1)));
        assert_eq!(map.resolve(0), None);
        assert_eq!(map.resolve(5), None);
        let e = entries(&scene, &map, &[s1]);
        assert_eq!(e[0].kind, "sphere");
        assert_eq!(e[0].source.as_deref(), Some("a.nff:3"));
    }
}
