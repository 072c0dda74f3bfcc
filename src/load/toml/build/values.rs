//! The checks of single values that every part of a scene shares: numbers that must be
//! positive or not negative, colours and sizes, directions that must not be zero, lists
//! that must not be empty. Each error is at the value's span and names it.

use super::super::format::{Real, Spanned, V3};
use super::types::Ty;
use super::{Builder, DisplayPrefix, R, article, f32v, v3};
use crate::math::Vec3;
use glam::DVec3;

impl Builder<'_, '_> {
    pub(super) fn positive(&self, v: &Spanned<Real>, what: &str) -> R<f64> {
        let x = v.get_ref().0;
        if x > 0.0 {
            Ok(x)
        } else {
            Err(self.err(v.span(), format!("{what} must be positive, found {x}")))
        }
    }

    pub(super) fn non_negative(&self, v: &Spanned<Real>, what: &str) -> R<f64> {
        let x = v.get_ref().0;
        if x >= 0.0 {
            Ok(x)
        } else {
            Err(self.err(v.span(), format!("{what} must not be negative, found {x}")))
        }
    }

    pub(super) fn non_negative3(&self, v: &Spanned<V3>, what: &str) -> R<Vec3> {
        let x = v3(v.get_ref());
        if x.min_element() >= 0.0 {
            Ok(f32v(x))
        } else {
            Err(self.err(
                v.span(),
                format!("{what} must not have negative components, found {x}"),
            ))
        }
    }

    /// A reflectance-like colour (a material's `color` or `filter`, the background, the
    /// ambient light): not negative, and a warning when a channel is above 1, the sign
    /// of colours written on a 0–255 scale.
    pub(super) fn colour(&self, v: &Spanned<V3>, what: &str) -> R<Vec3> {
        let c = self.non_negative3(v, what)?;
        if c.max_element() > 1.0 {
            log::warn!(
                target: super::LOG_TARGET,
                "{}: {what} {} has channels above 1; colours are linear, 1 is full \
                 intensity (a colour on a 0-255 scale is divided by 255)",
                self.at(v.span()).display_prefix(),
                {
                    let x = v3(v.get_ref());
                    format!("[{}, {}, {}]", x.x, x.y, x.z)
                }
            );
        }
        Ok(c)
    }

    pub(super) fn positive3(&self, v: &Spanned<V3>, what: &str) -> R<Vec3> {
        let x = v3(v.get_ref());
        if x.min_element() > 0.0 {
            Ok(f32v(x))
        } else {
            Err(self.err(
                v.span(),
                format!("{what} must have positive components, found {x}"),
            ))
        }
    }

    /// The list `list`, the value of the key `key` of an object of type `ty`, unless it
    /// is empty: such an object would be nothing. `needs` says what it needs (`at
    /// least one patch`).
    pub(super) fn non_empty<'v, T>(
        &self,
        list: &'v Spanned<Vec<T>>,
        key: &str,
        ty: Ty,
        needs: &str,
    ) -> R<&'v [T]> {
        let items = list.get_ref();
        if items.is_empty() {
            return Err(self.err(
                list.span(),
                format!("`{key}` is empty: {} needs {needs}", article(ty.name())),
            ));
        }
        Ok(items)
    }

    /// A non-zero vector, normalised.
    pub(super) fn direction(&self, v: &Spanned<V3>, what: &str) -> R<DVec3> {
        let x = v3(v.get_ref());
        let scaled = x / x.abs().max_element();
        match scaled.try_normalize() {
            Some(u) if x != DVec3::ZERO => Ok(u),
            _ => Err(self.err(v.span(), format!("{what} must not be zero"))),
        }
    }
}
