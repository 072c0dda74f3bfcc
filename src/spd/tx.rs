//! The SPD library's 4×4 transforms (row vectors: `v' = v·M`, translation in the last
//! row), with every sum in the library's order so results match to the last bit,
//! signed zeros included.

use glam::DVec3;

/// A 4×4 matrix applied to row vectors.
pub(super) type Matrix = [[f64; 4]; 4];

/// The identity.
pub(super) const IDENTITY: Matrix = [
    [1.0, 0.0, 0.0, 0.0],
    [0.0, 1.0, 0.0, 0.0],
    [0.0, 0.0, 1.0, 0.0],
    [0.0, 0.0, 0.0, 1.0],
];

/// `a · b`, each element the sum of all four products, zeros included.
pub(super) fn multiply(a: &Matrix, b: &Matrix) -> Matrix {
    let mut r = [[0.0; 4]; 4];
    for (i, row) in r.iter_mut().enumerate() {
        for (j, x) in row.iter_mut().enumerate() {
            *x = a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j] + a[i][3] * b[3][j];
        }
    }
    r
}

/// Rotation by `angle` radians about coordinate axis `axis` (0 = X, 1 = Y, 2 = Z).
pub(super) fn rotate(axis: usize, angle: f64) -> Matrix {
    let (s, c) = (angle.sin(), angle.cos());
    let mut m = [[0.0; 4]; 4];
    let (i, j) = match axis {
        0 => (1, 2),
        1 => (2, 0),
        _ => (0, 1),
    };
    m[axis][axis] = 1.0;
    m[i][i] = c;
    m[j][j] = c;
    m[i][j] = s;
    m[j][i] = -s;
    m[3][3] = 1.0;
    m
}

/// Rotation by `angle` radians about the unit axis `a`.
pub(super) fn rotate_axis(a: DVec3, angle: f64) -> Matrix {
    let (s, c) = (angle.sin(), angle.cos());
    let omc = 1.0 - c;
    [
        [
            a.x * a.x + (1.0 - a.x * a.x) * c,
            a.x * a.y * omc + a.z * s,
            a.x * a.z * omc - a.y * s,
            0.0,
        ],
        [
            a.x * a.y * omc - a.z * s,
            a.y * a.y + (1.0 - a.y * a.y) * c,
            a.y * a.z * omc + a.x * s,
            0.0,
        ],
        [
            a.x * a.z * omc + a.y * s,
            a.y * a.z * omc - a.x * s,
            a.z * a.z + (1.0 - a.z * a.z) * c,
            0.0,
        ],
        [0.0, 0.0, 0.0, 1.0],
    ]
}

/// The point `p` through `m` (`lib_transform_point`).
pub(super) fn transform_point(p: DVec3, m: &Matrix) -> DVec3 {
    DVec3::new(
        p.x * m[0][0] + p.y * m[1][0] + p.z * m[2][0] + m[3][0],
        p.x * m[0][1] + p.y * m[1][1] + p.z * m[2][1] + m[3][1],
        p.x * m[0][2] + p.y * m[1][2] + p.z * m[2][2] + m[3][2],
    )
}

/// The direction `v` through `m`'s upper 3×3 (three products per component).
pub(super) fn transform_vector(v: DVec3, m: &Matrix) -> DVec3 {
    DVec3::new(
        v.x * m[0][0] + v.y * m[1][0] + v.z * m[2][0],
        v.x * m[0][1] + v.y * m[1][1] + v.z * m[2][1],
        v.x * m[0][2] + v.y * m[1][2] + v.z * m[2][2],
    )
}

/// The direction `v` as the homogeneous `(v, 0)` through all of `m`
/// (`lib_transform_coord` with w = 0: the zero term turns −0 into +0).
pub(super) fn transform_coord_w0(v: DVec3, m: &Matrix) -> DVec3 {
    let col = |j: usize| v.x * m[0][j] + v.y * m[1][j] + v.z * m[2][j] + 0.0 * m[3][j];
    DVec3::new(col(0), col(1), col(2))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotations_turn_the_right_way() {
        let q = std::f64::consts::FRAC_PI_2;
        let x = transform_vector(DVec3::X, &rotate(2, q));
        assert!(
            (x - DVec3::Y).length() < 1e-15,
            "z rotation takes x to y: {x}"
        );
        let y = transform_vector(DVec3::Y, &rotate(0, q));
        assert!(
            (y - DVec3::Z).length() < 1e-15,
            "x rotation takes y to z: {y}"
        );
        let z = transform_vector(DVec3::Z, &rotate(1, q));
        assert!(
            (z - DVec3::X).length() < 1e-15,
            "y rotation takes z to x: {z}"
        );
        let a = rotate_axis(DVec3::Z, 0.3);
        let b = rotate(2, 0.3);
        for i in 0..4 {
            for j in 0..4 {
                assert!((a[i][j] - b[i][j]).abs() < 1e-15);
            }
        }
        assert_eq!(multiply(&IDENTITY, &b), b);
        let mut t = IDENTITY;
        t[3] = [1.0, 2.0, 3.0, 1.0];
        assert_eq!(transform_point(DVec3::ONE, &t), DVec3::new(2.0, 3.0, 4.0));
        assert_eq!(
            transform_coord_w0(DVec3::new(-0.0, 1.0, 0.0), &IDENTITY)
                .x
                .to_bits(),
            0.0f64.to_bits()
        );
    }
}
