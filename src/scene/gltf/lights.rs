//! `KHR_lights_punctual` lights as the tool's light sources (docs/design.md §13):
//!
//! - a **point** light (intensity in candela) is a luminaire with an isotropic web;
//! - a **spot** light is a luminaire aimed down its node's −Z, its web I(γ) = I₀·s(γ)², s the
//!   cone's ramp clamp((cos γ − cos outer) / (cos inner − cos outer), 0, 1): the falloff the
//!   extension's specification gives, tabulated at 24 angles between the inner and the outer
//!   cone (linear between them, as a photometric web is read);
//! - a **directional** light (illuminance in lux, normal to its direction) is the sun.
//!
//! The web of each is written as an LM-63-2002 text and read by the IES reader, so a glTF
//! light is exactly the luminaire an IES file of that text would place ([`web_text`]). The
//! light's colour is its tint (normalised to luminance 1, [`crate::luminaire`]) and its
//! luminance multiplies the candela. `range` is not used: light falls off as 1/d² everywhere,
//! as it does in the world (and in Radiance).

use crate::luminaire::{normalise_colour, Frame, Luminaire, LUMINANCE_WEIGHTS};
use crate::photometry::parse_ies;
use crate::scene::obj::to_f64;
use crate::scene::ModelSun;
use glam::{DMat4, DVec3};
use gltf::khr_lights_punctual::Kind;
use std::path::Path;
use std::sync::Arc;

/// The cone's ramp is tabulated at this many steps between the inner and outer angles.
const SPOT_STEPS: usize = 24;

/// A light's shape of web: isotropic, or a spot's cone (radians).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Web {
    Point,
    Spot { inner: f64, outer: f64 },
}

/// The LM-63-2002 text of a web of peak intensity `candela` (absolute photometry, Type C,
/// rotationally symmetric).
pub fn web_text(web: Web, candela: f64, label: &str) -> String {
    let (angles, values): (Vec<f64>, Vec<f64>) = match web {
        Web::Point => (vec![0.0, 180.0], vec![candela, candela]),
        Web::Spot { inner, outer } => {
            let outer = outer.clamp(1e-4, std::f64::consts::PI);
            let inner = inner.clamp(0.0, outer);
            let (ci, co) = (inner.cos(), outer.cos());
            let mut a = vec![0.0];
            if inner > 0.0 {
                a.push(inner);
            }
            for k in 1..=SPOT_STEPS {
                a.push(inner + (outer - inner) * k as f64 / SPOT_STEPS as f64);
            }
            let mut deg: Vec<f64> = a.iter().map(|x| x.to_degrees()).collect();
            deg.dedup_by(|b, a| *b <= *a);
            let ramp = |g: f64| {
                if ci - co <= 0.0 {
                    return if g <= outer { 1.0 } else { 0.0 };
                }
                ((g.cos() - co) / (ci - co)).clamp(0.0, 1.0).powi(2)
            };
            let mut v: Vec<f64> = deg.iter().map(|d| candela * ramp(d.to_radians())).collect();
            if *deg.last().unwrap_or(&0.0) < 180.0 {
                deg.push(180.0);
                v.push(0.0);
            }
            (deg, v)
        }
    };
    let join = |v: &[f64]| {
        v.iter()
            .map(|x| format!("{x}"))
            .collect::<Vec<_>>()
            .join(" ")
    };
    format!(
        "IESNA:LM-63-2002\n[TEST] {label}\n[MANUFAC] glTF KHR_lights_punctual\nTILT=NONE\n\
         1 -1 1 {} 1 1 2 0 0 0\n1 1 0\n{}\n0\n{}\n",
        angles.len(),
        join(&angles),
        join(&values)
    )
}

/// A placed light: a luminaire, or the sun.
pub enum Placed {
    Luminaire(Luminaire),
    Sun(ModelSun),
    /// A light that gives none (black, or intensity 0): left out, with this reason.
    Dark(String),
}

/// The light of a node: `light` at the node's world transform `world` (model units; `scale`
/// the load's `--scale`), aimed by the model's `zenith`. `file` is the model (where the
/// luminaire says it came from), `label` names the light in messages.
pub fn place(
    light: &gltf::khr_lights_punctual::Light,
    world: &DMat4,
    (file, label): (&Path, &str),
    zenith: DVec3,
) -> Result<Placed, String> {
    // Errors name the light as the document does, and by the name it is listed under.
    let what = format!("light {} '{label}'", light.index());
    let colour = light.color().map(to_f64);
    let intensity = to_f64(light.intensity());
    if !(intensity.is_finite() && intensity >= 0.0) {
        return Err(format!(
            "{what}: its intensity {intensity} is not a finite, non-negative number"
        ));
    }
    let Some(tint) = normalise_colour(colour) else {
        if colour.iter().all(|c| *c == 0.0) {
            return Ok(Placed::Dark(format!("{label} is black")));
        }
        return Err(format!(
            "{what}: its colour {} {} {} is not a colour (each channel finite, not negative)",
            colour[0], colour[1], colour[2]
        ));
    };
    if intensity == 0.0 {
        return Ok(Placed::Dark(format!("{label} has intensity 0")));
    }
    let luminance: f64 = colour
        .iter()
        .zip(LUMINANCE_WEIGHTS)
        .map(|(c, w)| c * w)
        .sum();
    let aim = world.transform_vector3(DVec3::NEG_Z);
    let web = match light.kind() {
        Kind::Directional => {
            let towards = -aim.normalize_or_zero();
            if towards == DVec3::ZERO || !towards.is_finite() {
                return Err(format!("{what}: its node's transform has no direction"));
            }
            return Ok(Placed::Sun(ModelSun {
                name: label.to_string(),
                towards,
                illuminance: intensity * luminance,
                white: tint == [1.0; 3],
            }));
        }
        Kind::Point => Web::Point,
        Kind::Spot {
            inner_cone_angle,
            outer_cone_angle,
        } => Web::Spot {
            inner: to_f64(inner_cone_angle),
            outer: to_f64(outer_cone_angle),
        },
    };
    let c0 = world.transform_vector3(DVec3::X);
    let frame = Frame::new(aim, 0.0, Some(c0), zenith)
        .or_else(|| Frame::new(aim, 0.0, None, zenith))
        .ok_or_else(|| format!("{what}: its node's transform has no direction"))?;
    let position = world.transform_point3(DVec3::ZERO);
    if !position.is_finite() {
        return Err(format!("{what}: its node's position is not finite"));
    }
    let text = web_text(web, intensity * luminance, label);
    let photometry = parse_ies(&text, label).map_err(|e| e.to_string())?;
    let web_lumens = photometry.total_lumens();
    Ok(Placed::Luminaire(Luminaire {
        name: label.to_string(),
        group: label.to_string(),
        file: file.to_path_buf(),
        photometry: Arc::new(photometry),
        web_lumens,
        position,
        frame,
        scale: 1.0,
        colour: tint,
        tilt_factor: 1.0,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_spot_web_follows_the_cone_ramp_at_its_nodes_and_is_dark_outside() {
        let (inner, outer) = (20f64.to_radians(), 35f64.to_radians());
        let text = web_text(Web::Spot { inner, outer }, 1000.0, "spot");
        let p = parse_ies(&text, "spot").unwrap();
        assert_eq!(p.intensity(0.0, 0.0), 1000.0);
        assert_eq!(p.intensity(90.0, 20.0), 1000.0);
        assert_eq!(p.intensity(45.0, 35.0), 0.0);
        assert_eq!(p.intensity(0.0, 90.0), 0.0);
        // Halfway down the ramp in cos: a quarter.
        let g = ((inner.cos() + outer.cos()) / 2.0).acos().to_degrees();
        let i = p.intensity(0.0, g);
        assert!((i - 250.0).abs() < 3.0, "{i}");
    }

    #[test]
    fn a_point_web_holds_four_pi_times_its_candela_in_lumens() {
        let p = parse_ies(&web_text(Web::Point, 100.0, "p"), "p").unwrap();
        let lm = p.total_lumens();
        assert!(
            (lm / (4.0 * std::f64::consts::PI * 100.0) - 1.0).abs() < 1e-4,
            "{lm}"
        );
    }
}
