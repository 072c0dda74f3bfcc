//! A database's size before it is generated: [`PrimCount`], a sink that counts the
//! primitives a generator sends and keeps its image size, so that a job can refuse a
//! scene too large for its memory limit before generating any of it.

use super::NffSink;
use glam::DVec3;

/// What a database would hold: its primitives (spheres, cones, and each polygon as the
/// triangles of a fan) and the resolution its viewpoint asks for.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PrimCount {
    /// Primitives (at most: the loader may drop degenerate polygons).
    pub prims: u64,
    /// The viewpoint's `resolution`, `(0, 0)` before one.
    pub res: (i32, i32),
}

impl NffSink for PrimCount {
    fn viewpoint(&mut self, _: DVec3, _: DVec3, _: DVec3, _: f64, _: f64, res: (i32, i32)) {
        self.res = res;
    }
    fn background(&mut self, _: DVec3) {}
    fn light(&mut self, _: DVec3) {}
    fn fill(&mut self, _: DVec3, _: f64, _: f64, _: f64, _: f64, _: f64) {}
    fn sphere(&mut self, _: DVec3, _: f64) {
        self.prims += 1;
    }
    fn spheres(&mut self, spheres: &[(DVec3, f64)]) {
        self.prims += spheres.len() as u64;
    }
    fn cone(&mut self, _: DVec3, _: f64, _: DVec3, _: f64) {
        self.prims += 1;
    }
    fn polygon(&mut self, verts: &[DVec3]) {
        self.prims += verts.len().saturating_sub(2) as u64;
    }
    fn polypatch(&mut self, verts: &[DVec3], _: &[DVec3]) {
        self.prims += verts.len().saturating_sub(2) as u64;
    }
}

#[cfg(test)]
mod tests {
    use crate::spd::Database;
    use std::path::Path;

    /// The count is the primitives the loader makes of the database's text (the
    /// spheres handed over in batches included), or more where it drops degenerate
    /// polygons.
    #[test]
    fn counts_the_primitives_the_text_makes() {
        for db in Database::ALL {
            for size in [1, 2] {
                let count = db.count(size);
                let scene = crate::load::nff::parse_str(&db.generate(size), Path::new("x"));
                let scene = scene.unwrap();
                let prims = scene.geometry.prim_count() as u64;
                let what = format!("{} size {size}", db.name());
                if scene.load_stats.degenerate_dropped == 0 {
                    assert_eq!(count.prims, prims, "{what}");
                } else {
                    assert!(count.prims > prims, "{what}");
                }
                let camera = &scene.camera;
                assert_eq!(
                    count.res,
                    (camera.width as i32, camera.height as i32),
                    "{what}"
                );
            }
        }
    }
}
