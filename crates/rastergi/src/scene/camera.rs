//! The pinhole camera.

use glam::Vec3;

use crate::error::{Error, Result};

/// A pinhole camera. `fov_y_deg` is the full vertical field of view.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    pub eye: Vec3,
    pub target: Vec3,
    pub up: Vec3,
    pub fov_y_deg: f32,
}

impl Camera {
    /// The camera's orthonormal frame: (right, up, forward), right-handed, looking along forward.
    pub fn frame(&self) -> (Vec3, Vec3, Vec3) {
        let forward = (self.target - self.eye).normalize();
        let right = forward.cross(self.up).normalize();
        let up = right.cross(forward);
        (right, up, forward)
    }

    /// Rejects cameras that define no view: coincident eye and target, an up vector along the
    /// view direction, non-finite values or a field of view outside (0, 180) degrees.
    pub fn validate(&self) -> Result<()> {
        let finite = self.eye.is_finite() && self.target.is_finite() && self.up.is_finite();
        let forward = self.target - self.eye;
        if !finite || forward.length_squared() <= 0.0 {
            return Err(Error::InvalidCamera("eye and target must be distinct finite points".into()));
        }
        if forward.normalize().cross(self.up).length_squared() < 1e-12 {
            return Err(Error::InvalidCamera("the up vector must not be parallel to the view direction".into()));
        }
        if !(self.fov_y_deg > 0.0 && self.fov_y_deg < 180.0) {
            return Err(Error::InvalidCamera(format!(
                "the field of view must lie strictly between 0 and 180 degrees, got {}",
                self.fov_y_deg
            )));
        }
        Ok(())
    }
}
