//! Why a primitive cannot be built: [`ShapeError`], returned by the constructors of
//! the analytic primitives (quadrics, planes, tori, boxes, capped cones, polyhedra,
//! CSG). Its messages are written to follow a loader's `file:line:col`.

use super::Kind;
use super::polyhedron::MAX_PLANES;
use crate::math::Vec3;
use glam::Quat;
use std::fmt::Display;

/// An invalid parameter of a primitive's constructor.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ShapeError {
    /// A vector parameter has a non-finite component.
    #[error("{what} ({}, {}, {}) is not finite", .value.x, .value.y, .value.z)]
    NotFinite {
        /// The parameter (`torus centre`, ...).
        what: String,
        /// Its value.
        value: Vec3,
    },
    /// A size that must be positive is not (or is not finite).
    #[error("{what} must be finite and positive, got {value}")]
    NotPositive {
        /// The parameter (`sphere radius`, ...).
        what: String,
        /// Its value.
        value: f32,
    },
    /// A direction is the zero vector.
    #[error("{what} must not be zero")]
    Zero {
        /// The parameter (`plane normal`, ...).
        what: String,
    },
    /// A parameter of a named shape is not finite (`oriented box: centre [..] is not
    /// finite`).
    #[error("{shape}: {what} {value} is not finite")]
    ParameterNotFinite {
        /// The shape (`prism`, `oriented box`, ...).
        shape: String,
        /// The parameter.
        what: &'static str,
        /// Its value, as written in the message.
        value: String,
    },
    /// A size of a named shape is not positive and finite.
    #[error("{shape}: {what} {value} must be positive and finite")]
    ParameterNotPositive {
        /// The shape.
        shape: String,
        /// The parameter.
        what: &'static str,
        /// Its value, as written in the message.
        value: String,
    },

    /// A plane's offset is not finite.
    #[error("plane offset is not finite ({0})")]
    PlaneOffset(f32),

    /// A box corner is not finite.
    #[error("box: corners {min} and {max} must be finite")]
    BoxNotFinite {
        /// Lower corner.
        min: Vec3,
        /// Upper corner.
        max: Vec3,
    },
    /// A box is empty or flat.
    #[error("box: min {min} must be below max {max} on every axis (size {})", *.max - *.min)]
    BoxNotBelow {
        /// Lower corner.
        min: Vec3,
        /// Upper corner.
        max: Vec3,
    },
    /// An oriented box's rotation is the zero quaternion.
    #[error("oriented box: rotation {0} is zero")]
    ZeroRotation(Quat),
    /// An oriented box's axes are not finite.
    #[error("oriented box: axes {} are not finite", show_axes(.0))]
    AxesNotFinite([Vec3; 3]),
    /// An oriented box's axes are not orthonormal.
    #[error("oriented box: axes {} are not orthonormal", show_axes(.0))]
    AxesNotOrthonormal([Vec3; 3]),
    /// An oriented box reaches beyond f32.
    #[error("oriented box: centre {center} and half extents {half_extents} overflow")]
    OBoxOverflow {
        /// Centre.
        center: Vec3,
        /// Half extents.
        half_extents: Vec3,
    },

    /// A capped cone's (or cylinder's) axis is the zero vector.
    #[error("{shape}: the axis direction is zero")]
    ZeroAxis {
        /// `capped cone` or `cylinder`.
        shape: &'static str,
    },
    /// A capped cone's end radius is negative or not finite.
    #[error("{shape}: {end} radius {radius} must be zero or positive and finite")]
    EndRadius {
        /// `capped cone` or `cylinder`.
        shape: &'static str,
        /// `base` or `top`.
        end: &'static str,
        /// The radius.
        radius: f32,
    },
    /// Both end radii of a capped cone are zero.
    #[error("{shape}: both radii are zero (no volume)")]
    NoRadius {
        /// `capped cone` or `cylinder`.
        shape: &'static str,
    },
    /// A capped cone is so flat that its slope overflows.
    #[error("{shape}: height {height} is too small for radii {base_radius} and {top_radius}")]
    TooFlat {
        /// `capped cone` or `cylinder`.
        shape: &'static str,
        /// Height.
        height: f32,
        /// Base radius.
        base_radius: f32,
        /// Top radius.
        top_radius: f32,
    },
    /// A capped cone reaches beyond f32.
    #[error("{shape}: base {base}, height {height} and radii overflow")]
    CappedOverflow {
        /// `capped cone` or `cylinder`.
        shape: &'static str,
        /// Centre of the base.
        base: Vec3,
        /// Height.
        height: f32,
    },

    /// A polyhedron from planes has fewer than four.
    #[error("polyhedron: {0} planes given, at least 4 needed")]
    TooFewPlanes(usize),
    /// A polyhedron has more planes than allowed.
    #[error("{0} planes (at most {MAX_PLANES} allowed)")]
    TooManyPlanes(usize),
    /// A polyhedron's plane (numbered from 1) is not finite.
    #[error("polyhedron: plane {index} ({normal}, {offset}) is not finite")]
    PlaneNotFinite {
        /// The plane's number, from 1.
        index: usize,
        /// Its normal.
        normal: Vec3,
        /// Its offset.
        offset: f32,
    },
    /// A polyhedron's plane (numbered from 1) has a zero normal.
    #[error("polyhedron: plane {0} has a zero normal")]
    PlaneZeroNormal(usize),
    /// No such polyhedron preset.
    #[error("unknown polyhedron {name:?} (known: {})", super::Polyhedron::PRESETS.join(", "))]
    UnknownPolyhedron {
        /// The name asked for.
        name: String,
    },
    /// A prism with too few or too many sides.
    #[error("prism: {sides} sides (between 3 and {} allowed)", MAX_PLANES - 2)]
    PrismSides {
        /// The number of sides asked for.
        sides: u32,
    },
    /// The planes have no common corner.
    #[error("the planes have no common corner: they enclose no volume or an unbounded one")]
    NoCorner,
    /// The planes leave the polyhedron open in a direction.
    #[error("the planes enclose an unbounded region (open towards {towards:.4})")]
    OpenPolyhedron {
        /// A direction in which the region is unbounded.
        towards: Vec3,
    },
    /// The planes enclose no volume.
    #[error("the planes enclose no volume (flat or empty)")]
    FlatPolyhedron,
    /// A polyhedron reaches beyond f32.
    #[error("the polyhedron's bounds overflow")]
    PolyhedronOverflow,

    /// A quadric coefficient (named `a` to `j`) is not finite.
    #[error("quadric coefficient {name} is not finite ({value})")]
    QuadricCoefficient {
        /// `a` to `j`.
        name: char,
        /// Its value.
        value: f64,
    },
    /// A quadric's clip box is not finite.
    #[error("quadric clip box is not finite")]
    ClipNotFinite,
    /// A quadric's clip box is empty or flat.
    #[error(
        "quadric clip box is empty or flat: min ({}, {}, {}) must be below max ({}, {}, {})",
        .min.x, .min.y, .min.z, .max.x, .max.y, .max.z
    )]
    ClipEmpty {
        /// Lower corner.
        min: Vec3,
        /// Upper corner.
        max: Vec3,
    },
    /// A quadric clip box that misses its ellipsoid.
    #[error("quadric clip box does not meet the ellipsoid")]
    ClipMisses,
    /// A quadric without second- or first-order terms.
    #[error("quadric has no second- or first-order terms: no surface")]
    QuadricNoTerms,
    /// A constant quadric.
    #[error("quadric is constant: no surface")]
    QuadricConstant,
    /// A quadric positive everywhere.
    #[error("quadric has no real points (F > 0 everywhere)")]
    QuadricNoPoints,
    /// A quadric whose solid is a point, line or plane.
    #[error("quadric is degenerate: its solid is a single point, line or plane")]
    QuadricDegenerate,
    /// A quadric negative everywhere.
    #[error("quadric fills all space (F ≤ 0 everywhere): no surface")]
    QuadricFillsSpace,

    /// A CSG operand that is not a closed solid.
    #[error(
        "a {} is not a closed solid and cannot be a CSG operand",
        .0.singular()
    )]
    NotSolid(Kind),
    /// A CSG nested deeper than [`super::csg::MAX_DEPTH`].
    #[error("CSG nested deeper than {} levels", super::csg::MAX_DEPTH)]
    CsgTooDeep,
    /// A CSG with more leaves than hit records can name.
    #[error("too many CSG leaves")]
    CsgTooManyLeaves,
    /// A CSG whose result is unbounded.
    #[error("the CSG solid is unbounded (intersect unbounded operands with a bounded solid)")]
    CsgUnbounded,

    /// An error of a shape built from others (a preset polyhedron, a prism), after what
    /// was asked for.
    #[error("{context}: {source}")]
    In {
        /// What was being built (`prism of 6 sides at [..]`).
        context: String,
        /// The error.
        source: Box<ShapeError>,
    },
}

/// Three axes as plain numbers: `(1, 0, 0), (0, 1, 0), (0, 0, 1)`.
fn show_axes(axes: &[Vec3; 3]) -> String {
    axes.iter()
        .map(|a| format!("({}, {}, {})", a.x, a.y, a.z))
        .collect::<Vec<_>>()
        .join(", ")
}

impl ShapeError {
    /// `shape: what value is not finite`.
    pub(super) fn parameter_not_finite(
        shape: impl Into<String>,
        what: &'static str,
        value: impl Display,
    ) -> Self {
        ShapeError::ParameterNotFinite {
            shape: shape.into(),
            what,
            value: value.to_string(),
        }
    }

    /// `shape: what value must be positive and finite`.
    pub(super) fn parameter_not_positive(
        shape: impl Into<String>,
        what: &'static str,
        value: impl Display,
    ) -> Self {
        ShapeError::ParameterNotPositive {
            shape: shape.into(),
            what,
            value: value.to_string(),
        }
    }

    /// This error after `context` (what was being built).
    pub(super) fn within(self, context: String) -> Self {
        ShapeError::In {
            context,
            source: Box::new(self),
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::geometry::{
        AaBox, CappedCone, Csg, CsgTree, OBox, Plane, Polyhedron, Quadric, Shape, Sphere, Torus,
    };
    use crate::math::Vec3;
    use glam::Quat;

    /// The messages read as they did when the constructors returned strings (the
    /// loaders print them after `file:line:col`).
    #[test]
    fn messages_name_the_shape_and_the_value() {
        let z = Vec3::ZERO;
        let text = |e: super::ShapeError| e.to_string();
        let mut nan = [0.0; 10];
        nan[2] = f64::NAN;
        assert_eq!(
            text(Quadric::new(nan, None).unwrap_err()),
            "quadric coefficient c is not finite (NaN)"
        );
        assert_eq!(
            text(Quadric::sphere(z, -1.0).unwrap_err()),
            "sphere radius must be finite and positive, got -1"
        );
        assert_eq!(
            text(Quadric::cylinder(z, z, 1.0).unwrap_err()),
            "cylinder axis must not be zero"
        );
        assert_eq!(
            text(Torus::new(Vec3::new(f32::NAN, 0.0, 1.5), Vec3::Y, 2.0, 1.0).unwrap_err()),
            "torus centre (NaN, 0, 1.5) is not finite"
        );
        assert_eq!(
            text(Plane::new(Vec3::Y, f32::INFINITY).unwrap_err()),
            "plane offset is not finite (inf)"
        );
        assert_eq!(
            text(AaBox::new(Vec3::ONE, z).unwrap_err()),
            "box: min [1, 1, 1] must be below max [0, 0, 0] on every axis (size [-1, -1, -1])"
        );
        assert_eq!(
            text(OBox::new(z, Vec3::new(1.0, 0.0, 1.0), Quat::IDENTITY).unwrap_err()),
            "oriented box: half extents [1, 0, 1] must be positive and finite"
        );
        assert_eq!(
            text(OBox::new(z, Vec3::ONE, Quat::from_xyzw(0.0, 0.0, 0.0, 0.0)).unwrap_err()),
            "oriented box: rotation [0, 0, 0, 0] is zero"
        );
        assert_eq!(
            text(
                OBox::from_axes(z, Vec3::ONE, [Vec3::X, Vec3::X, Vec3::new(0.0, 0.5, 1.0)])
                    .unwrap_err()
            ),
            "oriented box: axes (1, 0, 0), (1, 0, 0), (0, 0.5, 1) are not orthonormal"
        );
        assert_eq!(
            text(CappedCone::cylinder(z, Vec3::Z, -3.0, 1.0).unwrap_err()),
            "cylinder: height -3 must be positive and finite"
        );
        assert_eq!(
            text(CappedCone::new(z, Vec3::Z, 1.0, 1.0, -0.5).unwrap_err()),
            "capped cone: top radius -0.5 must be zero or positive and finite"
        );
        assert_eq!(
            text(CappedCone::new(z, z, 1.0, 1.0, 1.0).unwrap_err()),
            "capped cone: the axis direction is zero"
        );
        assert_eq!(
            text(Polyhedron::new(vec![(Vec3::X, 1.0); 3]).unwrap_err()),
            "polyhedron: 3 planes given, at least 4 needed"
        );
        assert_eq!(
            text(Polyhedron::prism(z, 2, 1.0, 1.0).unwrap_err()),
            "prism: 2 sides (between 3 and 254 allowed)"
        );
        assert_eq!(
            text(Polyhedron::preset("cube", z, 0.0).unwrap_err()),
            "polyhedron cube: radius 0 must be positive and finite"
        );
        assert_eq!(
            text(Polyhedron::preset("tube", z, 1.0).unwrap_err()),
            "unknown polyhedron \"tube\" (known: cube, box, tetrahedron, octahedron, \
             dodecahedron, icosahedron)"
        );
        assert_eq!(
            text(Polyhedron::prism(z, 6, 3e38, 1.0).unwrap_err()),
            "prism of 6 sides at [0, 0, 0]: the planes enclose no volume (flat or empty)"
        );
        let open = CsgTree::leaf(Shape::Cone(crate::geometry::Cone::new(
            z,
            1.0,
            Vec3::Y,
            1.0,
        )));
        assert_eq!(
            text(Csg::new(&open).unwrap_err()),
            "a open cone is not a closed solid and cannot be a CSG operand"
        );
        let mut deep = CsgTree::leaf(Shape::Sphere(Sphere::new(z, 1.0)));
        for _ in 0..70 {
            deep = CsgTree::Transform {
                xform: crate::math::Xform::IDENTITY,
                child: Box::new(deep),
            };
        }
        assert_eq!(
            text(Csg::new(&deep).unwrap_err()),
            "CSG nested deeper than 64 levels"
        );
    }
}
