//! Smoothing groups (`s 1`, `s 2`, ...; `s off` and `s 0` end one): the normals of
//! faces without `vn` in a group, averaged over the group's faces around each position.

use super::in_force::InForce;
use super::parse::{Face, Obj};
use crate::math::Vec3;
use std::collections::HashMap;

/// A position (its bits) in a smoothing group.
pub(super) type GroupKey = ([u32; 3], u32);

/// The key of position `p` in group `group`.
pub(super) fn key(p: Vec3, group: u32) -> GroupKey {
    (p.to_array().map(f32::to_bits), group)
}

/// For faces without `vn` in a smoothing group: the sum of the area-weighted normals
/// of the group's faces around each position (keyed by the position's bits, so groups
/// join across `g`/`o` boundaries, and the group number). The sums are made in face
/// order, on one thread: they are the same whoever uses them.
pub(super) fn group_normals(obj: &Obj) -> HashMap<GroupKey, Vec3> {
    let mut sums: HashMap<GroupKey, Vec3> = HashMap::new();
    if obj.smoothing.iter().all(|&(_, g)| g == 0) {
        return sums;
    }
    let mut pts = Vec::new();
    let mut groups = InForce::from(&obj.smoothing, 0, 0);
    for (k, face) in obj.faces.iter().enumerate() {
        let group = groups.at(k);
        if group == 0 || face.is_line || face.all_normals || face.arity < 3 {
            continue;
        }
        if !positions(obj, face, &mut pts) {
            continue;
        }
        // Newell's normal: twice the vector area of the polygon.
        let mut n = Vec3::ZERO;
        for (k, &a) in pts.iter().enumerate() {
            let b = pts.get(k + 1).or(pts.first()).copied().unwrap_or(a);
            n += a.cross(b);
        }
        if !n.is_finite() {
            continue;
        }
        for &p in &pts {
            *sums.entry(key(p, group)).or_insert(Vec3::ZERO) += n;
        }
    }
    sums
}

/// The positions of `face`'s vertices into `out`; false if an index is out of range.
pub(super) fn positions(obj: &Obj, face: &Face, out: &mut Vec<Vec3>) -> bool {
    out.clear();
    for c in obj.corners_of(face) {
        match obj.positions.get(c.v) {
            Some(&p) => out.push(p),
            None => return false,
        }
    }
    out.len() == face.arity
}

/// `n` made unit length, or `None` when it is zero. Scaled first so that huge finite
/// components do not overflow.
pub(super) fn unit(n: Vec3) -> Option<Vec3> {
    let m = n.abs().max_element();
    if m > 0.0 {
        (n / m).try_normalize()
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::super::stretches::parse;
    use super::*;

    #[test]
    fn groups_sum_area_weighted_normals_at_shared_positions() {
        let src = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\ns 1\nf 1 2 3\nf 1 4 2\ns off\nf 1 3 4\n";
        let obj = parse(src, usize::MAX, &crate::load::LoadProgress::silent()).unwrap();
        let sums = group_normals(&obj);
        // The origin is in both faces of group 1: +z (area 1) and +y (area 1).
        let n = sums[&key(Vec3::ZERO, 1)];
        assert_eq!(n, Vec3::new(0.0, 1.0, 1.0));
        assert_eq!(sums.len(), 4);
        assert!(!sums.contains_key(&key(Vec3::ZERO, 0)));
    }

    #[test]
    fn unit_survives_huge_components() {
        assert_eq!(
            unit(Vec3::splat(f32::MAX)),
            Some(Vec3::splat(1.0 / 3f32.sqrt()))
        );
        assert_eq!(unit(Vec3::ZERO), None);
    }
}
