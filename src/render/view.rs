//! The view of a picture: where the camera is ([`CameraSpec`], fitted to the scene where left
//! out) and the image's size, supersampling and exposure ([`RenderOptions`]), checked once for
//! every command that draws (`solve`, `render`, `relight`).

use super::{Camera, RenderOptions};
use crate::settings::Invalid;
use glam::Vec3;
use serde::{Deserialize, Serialize};

/// Largest image side the commands accept.
pub const MAX_SIDE: u32 = 16384;
/// Default image size and supersampling.
pub const DEFAULT_WIDTH: u32 = 640;
pub const DEFAULT_HEIGHT: u32 = 480;
pub const DEFAULT_SUPERSAMPLE: u32 = 3;

/// Checks `--exposure` (images and exported meshes alike).
pub fn check_exposure(exposure: Option<f32>) -> Result<(), Invalid> {
    match exposure {
        Some(e) if !(e > 0.0 && e.is_finite()) => {
            Invalid::err(format!("--exposure must be a positive number, got {e}"))
        }
        _ => Ok(()),
    }
}

/// The camera and the picture.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ViewSettings {
    pub camera: CameraSpec,
    pub image: RenderOptions,
}

impl ViewSettings {
    /// Checks the camera and the picture (one line naming the flag).
    pub fn check(&self) -> Result<(), Invalid> {
        self.camera.check()?;
        let r = &self.image;
        if r.width == 0 || r.height == 0 || r.width > MAX_SIDE || r.height > MAX_SIDE {
            return Invalid::err(format!(
                "--width and --height must be between 1 and {MAX_SIDE}, got {}x{}",
                r.width, r.height
            ));
        }
        check_exposure(r.exposure)
    }

    /// The camera for a scene with bounds (lo, hi), at this picture's aspect.
    pub fn camera_for(&self, lo: Vec3, hi: Vec3) -> Camera {
        self.camera
            .resolve(lo, hi, self.image.width as f32 / self.image.height as f32)
    }
}

/// A camera from the command line; what is left out is fitted to the scene.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct CameraSpec {
    pub eye: Option<Vec3>,
    pub target: Option<Vec3>,
    pub up: Option<Vec3>,
    pub fov_y_deg: Option<f32>,
}

impl CameraSpec {
    /// Refuses a camera that cannot look anywhere: `--fov` outside (0, 180) degrees, `--eye`
    /// on `--target`, a zero `--up` or one along the line of sight.
    pub fn check(&self) -> Result<(), Invalid> {
        if let Some(f) = self.fov_y_deg {
            if !(f > 0.0 && f < 180.0) {
                return Invalid::err(format!("--fov must be in (0, 180) degrees, got {f}"));
            }
        }
        if let (Some(eye), Some(target)) = (self.eye, self.target) {
            if eye == target {
                return Invalid::err(format!(
                    "--eye and --target are the same point ({eye}): the camera looks nowhere"
                ));
            }
            if let Some(up) = self.up {
                if up.cross(target - eye).length_squared() == 0.0 && up != Vec3::ZERO {
                    return Invalid::err(format!(
                        "--up {up} is along the line of sight from --eye to --target"
                    ));
                }
            }
        }
        if self.up == Some(Vec3::ZERO) {
            return Invalid::err("--up must not be 0,0,0");
        }
        Ok(())
    }

    /// The camera for a scene with bounds (lo, hi): fitted unless an eye is given.
    pub fn resolve(&self, lo: Vec3, hi: Vec3, aspect: f32) -> Camera {
        let mut cam = Camera::fit(lo, hi, aspect);
        if let Some(eye) = self.eye {
            cam.eye = eye;
            cam.target = self.target.unwrap_or((lo + hi) * 0.5);
        } else if let Some(t) = self.target {
            cam.target = t;
        }
        if let Some(up) = self.up {
            cam.up = up;
        }
        if let Some(f) = self.fov_y_deg {
            cam.fov_y_deg = f;
        }
        cam
    }
}
