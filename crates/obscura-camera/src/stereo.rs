//! Off-axis stereo: two cameras side by side whose frusta are shifted, not toed in, so that
//! they agree on one plane (zero parallax) and their image planes stay parallel.
//!
//! The rig's centre is the mono camera. Each eye moves along the camera's +x (its `right`) by
//! `e = -b/2` (left) or `+b/2` (right), `b` the interaxial distance, with eye and target moved
//! alike so the view directions stay parallel. A point at camera-space `(x, y, z)` of the rig
//! is at `x - e` in the eye's frame, which a perspective camera of scale
//! `s = h / tan(fov / 2)` puts at screen x `s (x - e) / z`. Shifting that eye's screen window by
//! `-s e / C` (`C` the convergence distance) makes the two screen positions equal at `z = C`:
//! points on the convergence plane have zero parallax. A point at infinity keeps the offset
//! `s b / C` between the eyes, in screen units; over the window's width `W_s` that is the
//! fraction `s b / (C W_s) = b / W_C` of the image, `W_C = C W_s / s` the width the frustum
//! spans at the convergence distance: the interaxial over the screen width, as stereographers
//! put it (Lipton, "Foundations of the Stereoscopic Cinema", 1982, ch. 4).

use crate::camera::LookAt;
use crate::error::{CameraError, finite};
use crate::film::{FovAxis, ScreenWindow};
use obscura_space::Vector3;

/// One eye of a stereo pair.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StereoEye {
    /// The left eye: the rig's centre moved by `-interaxial / 2` along camera +x.
    Left,
    /// The right eye: moved by `+interaxial / 2`.
    Right,
}

/// An off-axis stereo rig: the interaxial distance and the distance of the zero-parallax plane.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StereoRig {
    /// Distance between the two eyes, world units (>= 0).
    pub interaxial: f32,
    /// Camera-space z of the plane both eyes see at the same raster position (> 0).
    pub convergence: f32,
}

impl StereoRig {
    /// A rig. Errors: non-finite numbers, a negative interaxial, a convergence that is not
    /// positive.
    pub fn new(interaxial: f32, convergence: f32) -> Result<StereoRig, CameraError> {
        finite("interaxial", interaxial)?;
        finite("convergence", convergence)?;
        if interaxial < 0.0 {
            return Err(CameraError::Interaxial { got: interaxial });
        }
        if convergence <= 0.0 {
            return Err(CameraError::Convergence { got: convergence });
        }
        Ok(StereoRig {
            interaxial,
            convergence,
        })
    }

    /// The eye's offset along camera +x: `-interaxial / 2` for the left eye, `+` for the right.
    pub fn offset(&self, eye: StereoEye) -> f32 {
        match eye {
            StereoEye::Left => -0.5 * self.interaxial,
            StereoEye::Right => 0.5 * self.interaxial,
        }
    }

    /// The eye's look-at: eye and target moved by [`StereoRig::offset`] along the look-at's
    /// `right = normalize(cross(target - eye, up))`. Errors: a degenerate look-at.
    pub fn eye_look_at(&self, eye: StereoEye, look: LookAt) -> Result<LookAt, CameraError> {
        look.pose()?;
        let dir = (look.target - look.eye).to_glam();
        let right = dir.cross(look.up.to_glam()).normalize();
        let shift = Vector3::from_glam(right * self.offset(eye));
        Ok(LookAt {
            eye: look.eye + shift,
            target: look.target + shift,
            up: look.up,
        })
    }

    /// The eye's screen window: the rig's window shifted by `-s e / C` in screen x, with the
    /// perspective scale `s = h / tan(fov / 2)` of a camera of `fov_degrees` along `fov_axis`
    /// on a film of `resolution` (`h` the default window's half-extent along the axis, as
    /// [`PerspectiveCamera`](crate::PerspectiveCamera) takes it).
    pub fn eye_window(
        &self,
        eye: StereoEye,
        window: ScreenWindow,
        fov_degrees: f32,
        fov_axis: FovAxis,
        resolution: [u32; 2],
    ) -> Result<ScreenWindow, CameraError> {
        let scale = fov_axis.perspective_scale(resolution, fov_degrees);
        let shift = (-scale * f64::from(self.offset(eye)) / f64::from(self.convergence)) as f32;
        ScreenWindow::new(
            window.x_min + shift,
            window.x_max + shift,
            window.y_min,
            window.y_max,
        )
    }
}
