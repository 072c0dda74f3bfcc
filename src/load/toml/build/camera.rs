//! `[camera]`: the field of view, the near plane, the image size and the view, given
//! as `from`, `at` and `up` or as a camera-to-world `matrix`.

use super::super::MAX_SIDE;
use super::super::format::{CameraDef, Real, Spanned};
use super::{Builder, R, f32v, v3};
use crate::scene::{Camera, range};
use glam::DVec3;
use std::ops::Range;

/// Image size when `[camera]` gives none.
const DEFAULT_RESOLUTION: [u32; 2] = [640, 480];
/// Field of view when `[camera]` gives none.
const DEFAULT_FOV: f64 = 45.0;

/// Where the camera is and looks, in double precision, with the span an error about
/// its up vector points at.
struct View {
    from: DVec3,
    at: DVec3,
    up: DVec3,
    up_span: Range<usize>,
}

impl Builder<'_, '_> {
    /// The camera in the scene's frame, and the frame's origin: `origin`, or else the
    /// eye.
    pub(super) fn camera(&self, origin: Option<DVec3>) -> R<(Camera, DVec3)> {
        let cam = &self.file.camera;
        let c = cam.get_ref();
        let fov = match &c.fov {
            Some(f) => self.fov(f)?,
            None => DEFAULT_FOV,
        };
        let hither = match &c.hither {
            Some(h) => self.non_negative(h, "`hither`")?,
            None => 0.0,
        };
        let [width, height] = match &c.resolution {
            Some(r) => self.resolution(r)?,
            None => DEFAULT_RESOLUTION,
        };
        let view = match &c.matrix {
            Some(m) => self.view_from_matrix(c, m)?,
            None => self.view_from_points(cam)?,
        };
        self.check_up(&view)?;
        self.check_view_range(cam, &view)?;
        let origin = origin.unwrap_or(view.from);
        let camera = Camera {
            from: f32v(view.from - origin),
            at: f32v(view.at - origin),
            up: f32v(view.up),
            angle_deg: fov as f32,
            hither: hither as f32,
            width,
            height,
        };
        Ok((camera, origin))
    }

    fn fov(&self, f: &Spanned<Real>) -> R<f64> {
        let a = f.get_ref().0;
        if !(a > 0.0 && a < 180.0) {
            return Err(self.err(
                f.span(),
                format!("`fov` must be between 0 and 180 degrees (exclusive), found {a}"),
            ));
        }
        Ok(a)
    }

    fn resolution(&self, r: &Spanned<[u32; 2]>) -> R<[u32; 2]> {
        let [w, h] = *r.get_ref();
        for (n, name) in [(w, "width"), (h, "height")] {
            if n == 0 || n > MAX_SIDE {
                return Err(self.err(
                    r.span(),
                    format!("image {name} must be between 1 and {MAX_SIDE}, found {n}"),
                ));
            }
        }
        Ok([w, h])
    }

    /// The view of a camera given by its `matrix` (which excludes `from`, `at`, `up`):
    /// it looks down its −z with +y up.
    fn view_from_matrix(&self, c: &CameraDef, m: &Spanned<[[Real; 4]; 4]>) -> R<View> {
        if let Some((k, span)) = [("from", &c.from), ("at", &c.at), ("up", &c.up)]
            .into_iter()
            .find_map(|(k, v)| v.as_ref().map(|v| (k, v.span())))
        {
            return Err(self.err(
                span,
                format!("the camera has a `matrix`, so `{k}` cannot be given too"),
            ));
        }
        let x = self.matrix(m)?;
        let from = x.translation;
        let forward = x.matrix3 * DVec3::NEG_Z;
        Ok(View {
            from,
            at: from + forward,
            up: x.matrix3 * DVec3::Y,
            up_span: m.span(),
        })
    }

    /// The view of a camera given by `from`, `at` and (optionally) `up`.
    fn view_from_points(&self, cam: &Spanned<CameraDef>) -> R<View> {
        let c = cam.get_ref();
        let (Some(from), Some(at)) = (&c.from, &c.at) else {
            return Err(self.err(
                cam.span(),
                "the camera needs `from` and `at` (or a `matrix`)",
            ));
        };
        let up = c.up.as_ref().map_or(DVec3::Y, |u| v3(u.get_ref()));
        let up_span = c.up.as_ref().map_or(cam.span(), |u| u.span());
        let (f, a) = (v3(from.get_ref()), v3(at.get_ref()));
        if f == a {
            return Err(self.err(at.span(), "camera `at` equals `from`"));
        }
        Ok(View {
            from: f,
            at: a,
            up,
            up_span,
        })
    }

    /// Refuse an up vector that is zero or along the viewing direction.
    fn check_up(&self, view: &View) -> R<()> {
        let fwd = view.at - view.from;
        let fwd = (fwd / fwd.abs().max_element()).normalize();
        let up = view.up;
        let upn = if up == DVec3::ZERO {
            up
        } else {
            up / up.abs().max_element()
        };
        if fwd.cross(upn).try_normalize().is_none() {
            return Err(self.err(
                view.up_span.clone(),
                "the camera's up vector is zero or parallel to the viewing direction",
            ));
        }
        Ok(())
    }

    /// Refuse a camera placed or aimed outside the range emray traces.
    fn check_view_range(&self, cam: &Spanned<CameraDef>, view: &View) -> R<()> {
        let c = cam.get_ref();
        let (from_span, at_span) = match (&c.matrix, &c.from, &c.at) {
            (Some(m), _, _) => (m.span(), m.span()),
            (None, Some(f), Some(a)) => (f.span(), a.span()),
            _ => (cam.span(), cam.span()),
        };
        range::check_point("the camera `from`", f32v(view.from))
            .map_err(|e| self.err(from_span, e.to_string()))?;
        range::check_point("the camera `at`", f32v(view.at))
            .map_err(|e| self.err(at_span, e.to_string()))?;
        Ok(())
    }
}
