//! The view of a picture: where the camera is ([`CameraSpec`]: the flags, a Radiance view
//! file, or fitted to the scene where left out) and the image's size, supersampling and
//! exposure ([`RenderOptions`]), checked once for every command that draws (`solve`, `render`,
//! `relight`).

use super::default_view::{self, DefaultView, ModelView};
use super::view_file::RadianceView;
use super::{Camera, Projection, RenderOptions};
use crate::intersect::Intersector;
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
#[serde(default)]
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
            if let Some(v) = &self.camera.view {
                return Invalid::err(format!(
                    "the picture would be {}x{} (--width/--height at the view's aspect {:.4}, from -vh and -vv): each side must be between 1 and {MAX_SIDE}",
                    r.width,
                    r.height,
                    v.aspect()
                ));
            }
            return Invalid::err(format!(
                "--width and --height must be between 1 and {MAX_SIDE}, got {}x{}",
                r.width, r.height
            ));
        }
        check_exposure(r.exposure)
    }

    /// The camera for a scene with bounds (lo, hi), at this picture's aspect (y up).
    pub fn camera_for(&self, lo: Vec3, hi: Vec3) -> Camera {
        self.camera.resolve(lo, hi, self.aspect())
    }

    /// The camera for a model, at this picture's aspect: with no camera flag at all, the
    /// default view ([`default_view::default_camera`]: fitted with the zenith up, or the plan
    /// of a building seen from outside), and which it took; else the flags' camera, what they
    /// leave out fitted with the zenith up ([`CameraSpec::resolve_up`]), and `None`.
    pub fn camera_of<I: Intersector>(
        &self,
        model: &ModelView<'_, I>,
    ) -> (Camera, Option<DefaultView>) {
        if self.camera.is_default() {
            let (cam, view) = default_view::default_camera(model, self.aspect());
            return (cam, Some(view));
        }
        let cam = self
            .camera
            .resolve_up(model.lo, model.hi, self.aspect(), model.zenith);
        (cam, None)
    }

    /// Width / height of the picture.
    fn aspect(&self) -> f32 {
        self.image.width as f32 / self.image.height as f32
    }
}

/// A camera from the command line; what is left out is fitted to the scene.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct CameraSpec {
    pub eye: Option<Vec3>,
    pub target: Option<Vec3>,
    pub up: Option<Vec3>,
    pub fov_y_deg: Option<f32>,
    /// `--near`: nothing nearer the eye than this (along the view direction) is drawn, so a
    /// camera inside a wall's thickness, or behind a wall, sees past it. Overrides a view
    /// file's `-vo`.
    pub near: Option<f32>,
    /// `--view FILE`: the whole camera from a Radiance view ([`RadianceView::read`]); the
    /// picture is exactly its field of view.
    pub view: Option<RadianceView>,
}

impl CameraSpec {
    /// Refuses a camera that cannot look anywhere: `--fov` outside (0, 180) degrees, `--eye`
    /// on `--target`, a zero `--up` or one along the line of sight, a negative `--near`, a
    /// view that cannot be drawn or one given together with the flags it replaces.
    pub fn check(&self) -> Result<(), Invalid> {
        if let Some(n) = self.near {
            if !(n >= 0.0 && n.is_finite()) {
                return Invalid::err(format!(
                    "--near must be a distance ≥ 0 in scene units, got {n}"
                ));
            }
        }
        if let Some(v) = &self.view {
            if self.eye.is_some()
                || self.target.is_some()
                || self.up.is_some()
                || self.fov_y_deg.is_some()
            {
                return Invalid::err(
                    "--view sets the whole camera: leave out --eye, --target, --up and --fov (--near may still override the view's -vo)",
                );
            }
            v.check().map_err(|e| Invalid(format!("--view: {e}")))?;
            let near = self.near.unwrap_or(v.vo);
            if v.va > 0.0 && near >= v.va {
                return Invalid::err(format!(
                    "--near {near} is not in front of the view's aft clipping distance -va {}",
                    v.va
                ));
            }
            return Ok(());
        }
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

    /// No camera flag given: the picture takes the default view.
    pub fn is_default(&self) -> bool {
        *self == CameraSpec::default()
    }

    /// The camera for a scene with bounds (lo, hi) and a picture of `aspect` (width / height):
    /// the view's if there is one, else fitted (y up) unless an eye is given. `--near` applies
    /// to either.
    pub fn resolve(&self, lo: Vec3, hi: Vec3, aspect: f32) -> Camera {
        self.resolve_up(lo, hi, aspect, Vec3::Y)
    }

    /// [`CameraSpec::resolve`] for a model whose up is `zenith`: what the flags leave out is
    /// fitted with the zenith up, looking horizontally ([`default_view::fitted`]).
    pub fn resolve_up(&self, lo: Vec3, hi: Vec3, aspect: f32, zenith: Vec3) -> Camera {
        if let Some(v) = &self.view {
            let mut cam = v.camera();
            if let Some(n) = self.near {
                cam.near = n;
            }
            return cam;
        }
        let mut cam = default_view::fitted(lo, hi, aspect, zenith);
        if let Some(n) = self.near {
            cam.near = n;
        }
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
            // The fitted camera's aspect, sanitised.
            cam.projection = Projection::perspective_for_aspect(f, cam.projection.aspect());
        }
        cam
    }
}

/// The picture's size in pixels from `--width` and `--height` as given (`None`: left out).
///
/// Without a view: each side as given, else 640×480. With a view (`--view`), the picture is
/// exactly the view's field, so its aspect is the view's ([`RadianceView::aspect`]) and the
/// pixels square: `--width` alone sets the width and the height follows (`--height` alone the
/// other way round); both given, the picture is fitted inside that box, the side too long for
/// the view's aspect shrinking, as `rpict -x W -y H` does at its default `-pa 1`; neither, the
/// width is 640. A derived side is rounded to the nearest pixel and at least 1.
pub fn image_size(camera: &CameraSpec, width: Option<u32>, height: Option<u32>) -> (u32, u32) {
    let Some(view) = &camera.view else {
        return (
            width.unwrap_or(DEFAULT_WIDTH),
            height.unwrap_or(DEFAULT_HEIGHT),
        );
    };
    let a = f64::from(view.aspect());
    let a = if a.is_finite() && a > 0.0 { a } else { 1.0 };
    let side = |x: f64| x.round().clamp(1.0, f64::from(u32::MAX)) as u32;
    match (width, height) {
        (None, None) => (DEFAULT_WIDTH, side(f64::from(DEFAULT_WIDTH) / a)),
        (Some(w), None) => (w, side(f64::from(w) / a)),
        (None, Some(h)) => (side(f64::from(h) * a), h),
        (Some(w), Some(h)) => {
            if f64::from(w) > f64::from(h) * a {
                (side(f64::from(h) * a).min(w), h)
            } else {
                (w, side(f64::from(w) / a).min(h))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn with_view(text: &str) -> CameraSpec {
        CameraSpec {
            view: Some(RadianceView::parse(text, false).unwrap()),
            ..CameraSpec::default()
        }
    }

    #[test]
    fn image_size_follows_the_views_aspect() {
        let none = CameraSpec::default();
        assert_eq!(image_size(&none, None, None), (640, 480));
        assert_eq!(image_size(&none, Some(100), None), (100, 480));
        // -vh 90 -vv 53.13: 2:1.
        let wide = with_view("-vh 90 -vv 53.130102");
        assert_eq!(image_size(&wide, None, None), (640, 320));
        assert_eq!(image_size(&wide, Some(150), None), (150, 75));
        assert_eq!(image_size(&wide, None, Some(100)), (200, 100));
        // Both: fitted inside the box, as rpict -x -y.
        assert_eq!(image_size(&wide, Some(400), Some(400)), (400, 200));
        assert_eq!(image_size(&wide, Some(400), Some(100)), (200, 100));
        // A parallel view 3 wide, 6 high.
        let tall = with_view("-vtl -vh 3 -vv 6");
        assert_eq!(image_size(&tall, Some(300), None), (300, 600));
        assert_eq!(image_size(&tall, Some(1), None), (1, 2));
    }

    #[test]
    fn view_camera_takes_near_and_refuses_the_flags_it_replaces() {
        let mut spec = with_view("rvu -vtv -vp 1 2 3 -vd 0 0 -1 -vu 0 1 0 -vh 60 -vv 40 -vo 0.5");
        let cam = spec.resolve(Vec3::ZERO, Vec3::ONE, 7.0);
        assert_eq!((cam.eye, cam.near), (Vec3::new(1.0, 2.0, 3.0), 0.5));
        // The view's own angles, whatever the picture's aspect.
        assert_eq!(
            cam.projection,
            Projection::Perspective {
                fov_x_deg: 60.0,
                fov_y_deg: 40.0
            }
        );
        spec.near = Some(2.0);
        assert_eq!(spec.resolve(Vec3::ZERO, Vec3::ONE, 1.0).near, 2.0);
        assert!(spec.check().is_ok());
        for bad in [
            CameraSpec {
                eye: Some(Vec3::ONE),
                ..spec.clone()
            },
            CameraSpec {
                fov_y_deg: Some(30.0),
                ..spec.clone()
            },
        ] {
            assert!(bad
                .check()
                .unwrap_err()
                .0
                .contains("--view sets the whole camera"));
        }
        let e = CameraSpec {
            near: Some(-1.0),
            ..CameraSpec::default()
        };
        assert!(e
            .check()
            .unwrap_err()
            .0
            .contains("--near must be a distance ≥ 0"));
        let mut clipped = with_view("-vo 1 -va 3");
        clipped.near = Some(4.0);
        assert!(clipped.check().unwrap_err().0.contains("-va 3"));
        let mut tall = ViewSettings {
            camera: with_view("-vtl -vh 1 -vv 100"),
            ..ViewSettings::default()
        };
        (tall.image.width, tall.image.height) = image_size(&tall.camera, None, None);
        assert!(tall.check().unwrap_err().0.contains("640x64000"));
    }

    #[test]
    fn near_applies_to_the_flag_camera_too() {
        let spec = CameraSpec {
            eye: Some(Vec3::new(0.0, 0.0, 5.0)),
            fov_y_deg: Some(30.0),
            near: Some(1.5),
            ..CameraSpec::default()
        };
        let cam = spec.resolve(Vec3::ZERO, Vec3::ONE, 2.0);
        assert_eq!(cam.near, 1.5);
        // --fov stays vertical; the horizontal angle follows the picture's aspect.
        assert!((cam.projection.aspect() - 2.0).abs() < 1e-5);
    }

    #[test]
    fn older_serialised_views_still_read() {
        // ViewSettings as serialised before --near and --view existed.
        let old = r#"{"camera":{"eye":[1.0,2.0,3.0],"target":null,"up":null,"fov_y_deg":50.0},"image":{"width":64,"height":48,"supersample":3,"exposure":null}}"#;
        let v: ViewSettings = serde_json::from_str(old).unwrap();
        assert_eq!(v.camera.eye, Some(Vec3::new(1.0, 2.0, 3.0)));
        assert_eq!((v.camera.near, v.camera.view), (None, None));
        let new = ViewSettings {
            camera: with_view("-vtl -vh 2 -vv 1 -vs 0.25"),
            ..ViewSettings::default()
        };
        let json = serde_json::to_string(&new).unwrap();
        assert_eq!(serde_json::from_str::<ViewSettings>(&json).unwrap(), new);
        assert_eq!(
            serde_json::from_str::<ViewSettings>("{}").unwrap(),
            ViewSettings::default()
        );
    }
}
