//! Radiance views: reading a view file (`--view FILE`) and writing the `VIEW=` options of the
//! camera a picture was drawn with.
//!
//! A view file is what `rvu` saves and `rpict -vf` reads: lines such as
//!
//! ```text
//! rview -vtv -vp 2 1.5 3 -vd 0 0 -1 -vu 0 1 0 -vh 45 -vv 45 -vo 0 -va 0 -vs 0 -vl 0
//! ```
//!
//! The first word may be a Radiance program's name (`rvu`, `rview`, `rpict`, `rpiece`,
//! `pinterp`, with or without a folder), `VIEW=` (the line a Radiance picture's header
//! carries), or absent. As in Radiance's `viewfile()`, the options of every line apply in turn
//! over Radiance's defaults (`-vtv -vp 0 0 0 -vd 0 1 0 -vu 0 0 1 -vh 45 -vv 45`), so a later
//! option overrides an earlier one. Blank lines and `#` comments are skipped; after a program's
//! name, words that are not view options (`rpict -x 512 -ab 2 …`) are skipped, as Radiance
//! does. A Radiance picture (a file starting `#?RADIANCE`) gives the view of its header's
//! `VIEW=` lines, so `--view picture.hdr` draws what `rpict` drew.
//!
//! Options (Radiance's `getviewopt()`, src/common/image.c): `-vtv` perspective, `-vtl`
//! parallel; `-vp X Y Z` the eye, `-vd X Y Z` the view direction, `-vu X Y Z` up; `-vh`,
//! `-vv` the horizontal and vertical angles of view in degrees (perspective) or the view's
//! width and height in scene units (parallel); `-vo`, `-va` the fore and aft clipping
//! distances (0: none); `-vs`, `-vl` the shift and lift of the picture, in fractions of its
//! width and height. The fisheye and panorama types (`-vth`, `-vta`, `-vts`, `-vtc`) and
//! `-vf` (a view file named inside a view file) are refused, each with one line naming it.

use super::camera::{Camera, Projection};
use crate::settings::Invalid;
use glam::{Vec2, Vec3};
use serde::{Deserialize, Serialize};
use std::io::Read;
use std::path::Path;

/// Largest view file read (a picture's header must end within it too).
const MAX_FILE: u64 = 1 << 20;

/// The view types this tool draws.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ViewType {
    /// `-vtv`.
    #[default]
    Perspective,
    /// `-vtl`.
    Parallel,
}

/// A Radiance view: the values of its options, Radiance's defaults where a file leaves one out.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct RadianceView {
    /// `-vt`.
    pub view_type: ViewType,
    /// `-vp`: the eye.
    pub vp: Vec3,
    /// `-vd`: the view direction (any length but 0).
    pub vd: Vec3,
    /// `-vu`: up.
    pub vu: Vec3,
    /// `-vh`, `-vv`: angles in degrees (perspective), or width and height (parallel).
    pub vh: f32,
    pub vv: f32,
    /// `-vo`, `-va`: fore and aft clipping distances along the view direction; 0 for none.
    pub vo: f32,
    pub va: f32,
    /// `-vs`, `-vl`: the picture's shift right and lift up, in its width and height.
    pub vs: f32,
    pub vl: f32,
}

impl Default for RadianceView {
    /// Radiance's defaults (src/common/image.c, `stdview`).
    fn default() -> Self {
        RadianceView {
            view_type: ViewType::Perspective,
            vp: Vec3::ZERO,
            vd: Vec3::Y,
            vu: Vec3::Z,
            vh: 45.0,
            vv: 45.0,
            vo: 0.0,
            va: 0.0,
            vs: 0.0,
            vl: 0.0,
        }
    }
}

impl RadianceView {
    /// Refuses a view that cannot be drawn, naming the option (as Radiance's `setview()` does):
    /// a zero `-vd`, a `-vu` that is zero or along `-vd`, angles outside (0, 180) degrees
    /// (perspective) or sizes not above 0 (parallel), negative `-vo`, `-va` not beyond `-vo`,
    /// anything not finite.
    pub fn check(&self) -> Result<(), String> {
        let vec = |v: Vec3| format!("{} {} {}", v.x, v.y, v.z);
        for (name, v) in [("-vp", self.vp), ("-vd", self.vd), ("-vu", self.vu)] {
            if !v.is_finite() {
                return Err(format!("{name} {} is not finite", vec(v)));
            }
        }
        if self.vd.length_squared() == 0.0 {
            return Err("-vd 0 0 0: the view direction must not be zero".into());
        }
        let (d, u) = (self.vd.normalize(), self.vu.normalize_or_zero());
        if u == Vec3::ZERO || d.cross(u).length_squared() < 1e-6 {
            return Err(format!(
                "-vu {} is zero or along -vd {}: up must point off the line of sight",
                vec(self.vu),
                vec(self.vd)
            ));
        }
        for (name, x, what) in [("-vh", self.vh, "horizontal"), ("-vv", self.vv, "vertical")] {
            match self.view_type {
                ViewType::Perspective if !(x > 0.0 && x < 180.0) => {
                    return Err(format!(
                        "{name} {x}: a perspective view's {what} angle must be between 0 and 180 degrees"
                    ))
                }
                ViewType::Parallel if !(x > 0.0 && x.is_finite()) => {
                    return Err(format!(
                        "{name} {x}: a parallel view's {what} size must be a positive distance in scene units"
                    ))
                }
                _ => {}
            }
        }
        if !(self.vo >= 0.0 && self.vo.is_finite()) {
            return Err(format!(
                "-vo {}: the fore clipping distance must be a distance ≥ 0",
                self.vo
            ));
        }
        if !(self.va == 0.0 || (self.va > self.vo && self.va.is_finite())) {
            return Err(format!(
                "-va {}: the aft clipping distance must be 0 (none) or beyond -vo {}",
                self.va, self.vo
            ));
        }
        for (name, x) in [("-vs", self.vs), ("-vl", self.vl)] {
            if !x.is_finite() {
                return Err(format!("{name} {x} is not finite"));
            }
        }
        Ok(())
    }

    /// Width / height of the picture this view shows with square pixels: for a perspective
    /// view tan(vh/2) / tan(vv/2), for a parallel one vh / vv (what `rpict` fits `-x`/`-y`
    /// to at `-pa 1`).
    pub fn aspect(&self) -> f32 {
        self.projection().aspect()
    }

    fn projection(&self) -> Projection {
        match self.view_type {
            ViewType::Perspective => Projection::Perspective {
                fov_x_deg: self.vh,
                fov_y_deg: self.vv,
            },
            ViewType::Parallel => Projection::Parallel {
                width: self.vh,
                height: self.vv,
            },
        }
    }

    /// The camera of this view (check it first: a bad view draws the fallbacks of
    /// [`Camera::frame`]).
    pub fn camera(&self) -> Camera {
        Camera {
            eye: self.vp,
            target: self.vp + self.vd.normalize_or_zero(),
            up: self.vu,
            projection: self.projection(),
            near: self.vo,
            far: (self.va > 0.0).then_some(self.va),
            shift: Vec2::new(self.vs, self.vl),
        }
    }

    /// Reads a view file (or a Radiance picture's header); every error is one line naming the
    /// file, the line and the option.
    pub fn read(path: &Path) -> Result<RadianceView, Invalid> {
        let at = |msg: String| Invalid(format!("--view {}: {msg}", path.display()));
        let file = std::fs::File::open(path).map_err(|e| at(format!("cannot open it: {e}")))?;
        let mut bytes = Vec::new();
        file.take(MAX_FILE + 1)
            .read_to_end(&mut bytes)
            .map_err(|e| at(format!("cannot read it: {e}")))?;
        let picture = bytes.starts_with(b"#?");
        if picture {
            // The header ends at the first empty line; the pixels follow.
            let end = bytes
                .windows(2)
                .position(|w| w == b"\n\n")
                .ok_or_else(|| at("a Radiance picture whose header does not end".into()))?;
            bytes.truncate(end + 1);
        } else if bytes.len() as u64 > MAX_FILE {
            return Err(at(format!("over {} KiB: not a view file", MAX_FILE / 1024)));
        }
        let text = String::from_utf8_lossy(&bytes);
        Self::parse(&text, picture).map_err(at)
    }

    /// Parses the text of a view file (`picture`: the header of a Radiance picture, where only
    /// `VIEW=` lines count). The error names the line and the option, without the file.
    pub fn parse(text: &str, picture: bool) -> Result<RadianceView, String> {
        let mut view = RadianceView::default();
        let mut found = false;
        for (i, line) in text.lines().enumerate() {
            let line = line.trim();
            let at = |msg: String| format!("line {}: {msg}", i + 1);
            if line.is_empty() || line.starts_with('#') {
                continue;
            }
            let (words, strict) = if let Some(rest) = line.strip_prefix("VIEW=") {
                (rest, true)
            } else if picture {
                // Other header lines (FORMAT=, the commands that made the picture, …).
                continue;
            } else if line.starts_with('-') {
                (line, true)
            } else {
                let (first, rest) = line.split_once(char::is_whitespace).unwrap_or((line, ""));
                let name = first.rsplit(['/', '\\']).next().unwrap_or(first);
                if !PROGRAMS.iter().any(|p| name.starts_with(p)) {
                    return Err(at(format!(
                        "'{first}' is not a view: expected options such as -vtv -vp X Y Z -vd X Y Z, after rvu, rview, rpict or VIEW= or alone"
                    )));
                }
                (rest, false)
            };
            found |= apply_options(&mut view, words, strict).map_err(at)?;
        }
        if !found {
            return Err(if picture {
                "a Radiance picture without a VIEW= line in its header".into()
            } else {
                "no view options in it (such as -vtv -vp X Y Z -vd X Y Z)".into()
            });
        }
        view.check()?;
        Ok(view)
    }
}

/// The program names a view line may start with (Radiance's `isview()`).
const PROGRAMS: [&str; 5] = ["rpict", "rview", "rvu", "rpiece", "pinterp"];

/// Applies the view options among `words` to `view`; true if there was one. `strict`: every
/// word must be a view option or its value (a bare line, `VIEW=`); otherwise other words are
/// skipped (a program's command line).
fn apply_options(view: &mut RadianceView, words: &str, strict: bool) -> Result<bool, String> {
    let mut words = words.split_whitespace().peekable();
    let mut found = false;
    while let Some(w) = words.next() {
        let Some(opt) = w.strip_prefix("-v") else {
            if strict {
                return Err(format!(
                    "'{w}' is not a view option (expected -vt, -vp, -vd, -vu, -vh, -vv, -vo, -va, -vs or -vl)"
                ));
            }
            continue;
        };
        let mut numbers = |n: usize| -> Result<Vec<f32>, String> {
            (0..n)
                .map(|_| {
                    let got = words.next();
                    got.and_then(|s| s.parse::<f64>().ok())
                        .filter(|x| x.is_finite() && x.abs() <= f64::from(f32::MAX))
                        .map(|x| x as f32)
                        .ok_or_else(|| {
                            let what = if n == 1 {
                                "a number".to_string()
                            } else {
                                format!("{n} numbers")
                            };
                            match got {
                                Some(s) => format!("{w} needs {what}, got '{s}'"),
                                None => format!("{w} needs {what}, got the end of the line"),
                            }
                        })
                })
                .collect()
        };
        let v3 = |x: Vec<f32>| Vec3::new(x[0], x[1], x[2]);
        match opt {
            "tv" => view.view_type = ViewType::Perspective,
            "tl" => view.view_type = ViewType::Parallel,
            "th" | "ta" | "ts" | "tc" => {
                let name = match opt {
                    "th" => "hemispherical fisheye",
                    "ta" => "angular fisheye",
                    "ts" => "planisphere (stereographic) fisheye",
                    _ => "cylindrical panorama",
                };
                return Err(format!(
                    "{w} ({name}) is not supported: this tool draws perspective (-vtv) and parallel (-vtl) views"
                ));
            }
            "t" => return Err("-vt needs its type letter joined to it, as -vtv or -vtl".into()),
            "p" => view.vp = v3(numbers(3)?),
            "d" => view.vd = v3(numbers(3)?),
            "u" => view.vu = v3(numbers(3)?),
            "h" => view.vh = numbers(1)?[0],
            "v" => view.vv = numbers(1)?[0],
            "o" => view.vo = numbers(1)?[0],
            "a" => view.va = numbers(1)?[0],
            "s" => view.vs = numbers(1)?[0],
            "l" => view.vl = numbers(1)?[0],
            "f" => {
                return Err(
                    "-vf (a view file named inside a view file) is not supported: give the view's options themselves"
                        .into(),
                )
            }
            _ if opt.starts_with('t') => {
                return Err(format!(
                    "{w}: unknown view type (this tool draws -vtv and -vtl)"
                ))
            }
            _ => return Err(format!("unknown view option {w}")),
        }
        found = true;
    }
    Ok(found)
}

/// The Radiance view options of the camera a picture was drawn with, as `rpict` writes them
/// after `VIEW=` in a picture's header (so `getinfo`, `rvu -vf`, `pinterp` and `findglare`
/// know the view): `-vtv`/`-vtl -vp … -vd … -vu … -vh … -vv … -vo … -va … -vs … -vl …`, with
/// the values as drawn (the frame's fallbacks, clamped angles).
pub fn view_options(cam: &Camera) -> String {
    let f = cam.frame();
    let v = |v: Vec3| format!("{} {} {}", v.x, v.y, v.z);
    let (t, h, w) = match cam.projection.as_drawn() {
        Projection::Perspective {
            fov_x_deg,
            fov_y_deg,
        } => ("v", fov_x_deg, fov_y_deg),
        Projection::Parallel { width, height } => ("l", width, height),
    };
    let s = cam.shift_or_zero();
    format!(
        "-vt{t} -vp {} -vd {} -vu {} -vh {h} -vv {w} -vo {} -va {} -vs {} -vl {}",
        v(cam.eye_or_origin()),
        v(f.fwd),
        v(f.given_up),
        cam.near_distance(),
        cam.far_distance().unwrap_or(0.0),
        s.x,
        s.y
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<RadianceView, String> {
        RadianceView::parse(text, false)
    }

    #[test]
    fn rvu_line_gives_every_option() {
        let v = parse("rview -vtv -vp 2 1.5 3 -vd 0 0 -1 -vu 0 1 0 -vh 60 -vv 45 -vo 0.5 -va 20 -vs 0.1 -vl -0.2\n")
            .unwrap();
        assert_eq!(
            v,
            RadianceView {
                view_type: ViewType::Perspective,
                vp: Vec3::new(2.0, 1.5, 3.0),
                vd: Vec3::NEG_Z,
                vu: Vec3::Y,
                vh: 60.0,
                vv: 45.0,
                vo: 0.5,
                va: 20.0,
                vs: 0.1,
                vl: -0.2,
            }
        );
        let cam = v.camera();
        assert_eq!(cam.near, 0.5);
        assert_eq!(cam.far, Some(20.0));
        assert_eq!(cam.target, Vec3::new(2.0, 1.5, 2.0));
    }

    #[test]
    fn first_word_is_optional_and_defaults_are_radiances() {
        for text in [
            "-vtl -vh 4 -vv 3",
            "rvu -vtl -vh 4 -vv 3",
            "/usr/local/bin/rpict -x 512 -vtl -ab 2 -vh 4 -vv 3 scene.oct",
            "VIEW= -vtl -vh 4 -vv 3",
            "# a comment\n\n  rpict -vtl\n-vh 4 -vv 3\r\n",
        ] {
            let v = parse(text).unwrap_or_else(|e| panic!("{text}: {e}"));
            assert_eq!(v.view_type, ViewType::Parallel, "{text}");
            assert_eq!((v.vh, v.vv), (4.0, 3.0));
            // Radiance's defaults for what is left out: z up, looking along +y.
            assert_eq!((v.vp, v.vd, v.vu), (Vec3::ZERO, Vec3::Y, Vec3::Z));
            assert_eq!(v.aspect(), 4.0 / 3.0);
        }
        let v = parse("-vp 1 2 3").unwrap();
        assert_eq!(
            (v.view_type, v.vh, v.vv),
            (ViewType::Perspective, 45.0, 45.0)
        );
    }

    #[test]
    fn later_options_override_earlier() {
        let v = parse("rvu -vp 1 1 1 -vh 30 -vv 20\nrvu -vp 5 6 7 -vh 50\n").unwrap();
        assert_eq!((v.vp, v.vh, v.vv), (Vec3::new(5.0, 6.0, 7.0), 50.0, 20.0));
    }

    #[test]
    fn picture_header_gives_its_view_lines_only() {
        let header = "#?RADIANCE\noconv scene.rad\nrpict -vf v.vf -x 512 -vp 9 9 9\nSOFTWARE= RADIANCE 5.4a\nVIEW= -vtv -vp 1 2 3 -vd 0 1 0 -vh 60 -vv 40\nFORMAT=32-bit_rle_rgbe\n";
        let v = RadianceView::parse(header, true).unwrap();
        assert_eq!((v.vp, v.vh, v.vv), (Vec3::new(1.0, 2.0, 3.0), 60.0, 40.0));
        assert!(
            RadianceView::parse("#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n", true)
                .unwrap_err()
                .contains("without a VIEW= line")
        );
    }

    #[test]
    fn perspective_aspect_is_the_ratio_of_tangents() {
        let v = parse("-vtv -vh 90 -vv 53.130102").unwrap();
        // tan 45° / tan 26.565051° = 1 / 0.5.
        assert!((v.aspect() - 2.0).abs() < 1e-5, "{}", v.aspect());
    }

    #[test]
    fn each_error_names_the_line_and_the_option() {
        for (text, want) in [
            (
                "-vtv -vp 1 2",
                "line 1: -vp needs 3 numbers, got the end of the line",
            ),
            (
                "-vp 1 2 -vd 0 1 0",
                "line 1: -vp needs 3 numbers, got '-vd'",
            ),
            ("\n-vh wide", "line 2: -vh needs a number, got 'wide'"),
            ("-vh nan", "-vh needs a number, got 'nan'"),
            ("-vz 3", "unknown view option -vz"),
            ("-vtq", "-vtq: unknown view type"),
            ("-vt v", "-vt needs its type letter joined"),
            (
                "-vth -vh 180",
                "-vth (hemispherical fisheye) is not supported",
            ),
            ("-vta", "-vta (angular fisheye)"),
            ("-vts", "-vts (planisphere"),
            ("-vtc", "-vtc (cylindrical panorama)"),
            ("-vf other.vf", "-vf (a view file named inside a view file)"),
            ("-vp 0 0 0 extra", "'extra' is not a view option"),
            ("VIEW= -vtv -x 3", "'-x' is not a view option"),
            ("v 1 2 3\nf 1 2 3", "line 1: 'v' is not a view"),
            ("# nothing\n", "no view options"),
            (
                "-vd 0 0 0",
                "-vd 0 0 0: the view direction must not be zero",
            ),
            ("-vd 0 0 1", "-vu 0 0 1 is zero or along -vd 0 0 1"),
            ("-vu 0 0 0", "-vu 0 0 0 is zero"),
            (
                "-vh 180",
                "-vh 180: a perspective view's horizontal angle must be between 0 and 180",
            ),
            ("-vv 0", "-vv 0: a perspective view's vertical angle"),
            ("-vh -10", "-vh -10: a perspective"),
            (
                "-vtl -vh 0",
                "-vh 0: a parallel view's horizontal size must be a positive",
            ),
            ("-vo -1", "-vo -1: the fore clipping distance"),
            (
                "-vo 2 -va 1",
                "-va 1: the aft clipping distance must be 0 (none) or beyond -vo 2",
            ),
            ("-vp 1e39 0 0", "-vp needs 3 numbers, got '1e39'"),
        ] {
            let err = parse(text).expect_err(text);
            assert!(err.contains(want), "{text:?}: {err}");
        }
    }

    #[test]
    fn reading_a_file_names_it() {
        let dir = tempfile::tempdir().unwrap();
        let missing = dir.path().join("missing.vf");
        let e = RadianceView::read(&missing).unwrap_err().0;
        assert!(
            e.starts_with(&format!("--view {}: cannot open it", missing.display())),
            "{e}"
        );
        let bad = dir.path().join("bad.vf");
        std::fs::write(&bad, "rvu -vp 1 2\n").unwrap();
        let e = RadianceView::read(&bad).unwrap_err().0;
        assert_eq!(
            e,
            format!(
                "--view {}: line 1: -vp needs 3 numbers, got the end of the line",
                bad.display()
            )
        );
        // A picture: the header ends at the empty line, binary pixels after it.
        let pic = dir.path().join("p.hdr");
        let mut bytes =
            b"#?RADIANCE\nVIEW= -vtv -vp 1 2 3\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 +X 1\n".to_vec();
        bytes.extend([0xff, 0x80, 0x00, 0x81]);
        std::fs::write(&pic, bytes).unwrap();
        assert_eq!(
            RadianceView::read(&pic).unwrap().vp,
            Vec3::new(1.0, 2.0, 3.0)
        );
    }

    #[test]
    fn rays_match_radiances_vwrays() {
        // `vwrays -vf v.hdr -x 64 -y 32 -pa 0 -fa` (Radiance 6.0a), first ray (top-left
        // pixel): origin 0.5 0.5 0.5, direction -0.663121 0.326298 -0.673647.
        let cam = parse("-vtv -vp 0.5 0.5 0.5 -vd 0 0 -1 -vu 0 1 0 -vh 90 -vv 53.130102")
            .unwrap()
            .camera();
        let (o, d) = cam.ray(0.5 / 64.0, 0.5 / 32.0);
        assert_eq!(o, Vec3::splat(0.5));
        assert!(
            (d - Vec3::new(-0.663121, 0.326298, -0.673647)).length() < 1e-5,
            "{d}"
        );
        // A shifted, lifted parallel view, 40 × 20: origin 0.31 0.65 0.5, direction 0 0 -1.
        let cam =
            parse("-vtl -vp 0.5 0.5 0.5 -vd 0 0 -1 -vu 0 1 0 -vh 0.8 -vv 0.4 -vs 0.25 -vl -0.1")
                .unwrap()
                .camera();
        let (o, d) = cam.ray(0.5 / 40.0, 0.5 / 20.0);
        assert!((o - Vec3::new(0.31, 0.65, 0.5)).length() < 1e-6, "{o}");
        assert_eq!(d, Vec3::NEG_Z);
    }

    #[test]
    fn view_options_read_back_to_the_same_camera() {
        let v = parse("rvu -vtv -vp 2 1.5 3 -vd 0 0 -2 -vu 0 1 0 -vh 60 -vv 45 -vo 0.25 -va 9 -vs 0.1 -vl -0.2").unwrap();
        let cam = v.camera();
        let line = view_options(&cam);
        assert_eq!(
            line,
            "-vtv -vp 2 1.5 3 -vd 0 0 -1 -vu 0 1 0 -vh 60 -vv 45 -vo 0.25 -va 9 -vs 0.1 -vl -0.2"
        );
        let back = parse(&format!("VIEW= {line}")).unwrap().camera();
        assert_eq!(back, cam);
        let par = parse("-vtl -vp 0 0 5 -vd 0 0 -1 -vu 0 1 0 -vh 4 -vv 3")
            .unwrap()
            .camera();
        assert!(view_options(&par)
            .starts_with("-vtl -vp 0 0 5 -vd 0 0 -1 -vu 0 1 0 -vh 4 -vv 3 -vo 0 -va 0"));
    }
}
