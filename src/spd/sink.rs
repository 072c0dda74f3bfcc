//! Where a database's entities go: [`NffSink`], which the NFF text writer
//! ([`super::NffWriter`]) and the scene builder (`spd::scene`, behind
//! [`super::Database::scene`]) both implement, so that one generator makes both the
//! file and the scene.

use super::NffWriter;
use glam::DVec3;

/// Receives the NFF entities of a database, in file order (text or a scene).
pub trait NffSink {
    /// `v`: from, at, up, angle, hither, resolution.
    fn viewpoint(
        &mut self,
        from: DVec3,
        at: DVec3,
        up: DVec3,
        angle: f64,
        hither: f64,
        res: (i32, i32),
    );
    /// `b r g b`.
    fn background(&mut self, rgb: DVec3);
    /// `l x y z` (without colour).
    fn light(&mut self, pos: DVec3);
    /// `f r g b Kd Ks Shine T ior`.
    fn fill(&mut self, rgb: DVec3, kd: f64, ks: f64, shine: f64, t: f64, ior: f64);
    /// `s x y z r`.
    fn sphere(&mut self, center: DVec3, radius: f64);
    /// One `s` per `(centre, radius)`, in order (a sink may make them in parallel).
    fn spheres(&mut self, spheres: &[(DVec3, f64)]) {
        for &(center, radius) in spheres {
            self.sphere(center, radius);
        }
    }
    /// `c`: base, base radius, apex, apex radius.
    fn cone(&mut self, base: DVec3, base_radius: f64, apex: DVec3, apex_radius: f64);
    /// `p n` and its vertices.
    fn polygon(&mut self, verts: &[DVec3]);
    /// `pp n` and its vertices with normals.
    fn polypatch(&mut self, verts: &[DVec3], normals: &[DVec3]);
}

impl NffSink for NffWriter {
    fn viewpoint(
        &mut self,
        from: DVec3,
        at: DVec3,
        up: DVec3,
        angle: f64,
        hither: f64,
        res: (i32, i32),
    ) {
        NffWriter::viewpoint(self, from, at, up, angle, hither, res);
    }

    fn background(&mut self, rgb: DVec3) {
        NffWriter::background(self, rgb);
    }

    fn light(&mut self, pos: DVec3) {
        NffWriter::light(self, pos);
    }

    fn fill(&mut self, rgb: DVec3, kd: f64, ks: f64, shine: f64, t: f64, ior: f64) {
        NffWriter::fill(self, rgb, kd, ks, shine, t, ior);
    }

    fn sphere(&mut self, center: DVec3, radius: f64) {
        NffWriter::sphere(self, center, radius);
    }

    fn cone(&mut self, base: DVec3, base_radius: f64, apex: DVec3, apex_radius: f64) {
        NffWriter::cone(self, base, base_radius, apex, apex_radius);
    }

    fn polygon(&mut self, verts: &[DVec3]) {
        NffWriter::polygon(self, verts);
    }

    fn polypatch(&mut self, verts: &[DVec3], normals: &[DVec3]) {
        NffWriter::polypatch(self, verts, normals);
    }
}
