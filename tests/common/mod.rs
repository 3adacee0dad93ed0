//! Analytic scenes built in code, shared by the integration tests.
#![allow(dead_code)]

use glam::{vec3, Vec3};
use radiosity::scene::{Material, Polygon, Scene};

/// Adds a quad (counter-clockwise seen from its front).
pub fn quad(s: &mut Scene, pts: [Vec3; 4], material: u32) {
    let base = s.positions.len() as u32;
    s.positions.extend_from_slice(&pts);
    let first = s.indices.len() as u32;
    s.indices.extend(base..base + 4);
    s.polygons.push(Polygon {
        first,
        len: 4,
        material,
    });
}

pub fn material(name: &str, rho: f64, ke: f64) -> Material {
    Material {
        name: name.into(),
        rho: [rho; 3],
        ke: [ke; 3],
    }
}

/// A closed box [0, w]×[0, h]×[0, d] with every face pointing inwards, all of material 0.
pub fn closed_box(w: f32, h: f32, d: f32, mat: Material) -> Scene {
    let mut s = Scene {
        name: "closed-box".into(),
        materials: vec![mat],
        ..Scene::default()
    };
    let p = |x: f32, y: f32, z: f32| vec3(x * w, y * h, z * d);
    // floor (+y), ceiling (−y), walls facing in
    quad(
        &mut s,
        [p(0., 0., 0.), p(0., 0., 1.), p(1., 0., 1.), p(1., 0., 0.)],
        0,
    );
    quad(
        &mut s,
        [p(0., 1., 0.), p(1., 1., 0.), p(1., 1., 1.), p(0., 1., 1.)],
        0,
    );
    quad(
        &mut s,
        [p(0., 0., 0.), p(1., 0., 0.), p(1., 1., 0.), p(0., 1., 0.)],
        0,
    );
    quad(
        &mut s,
        [p(0., 0., 1.), p(0., 1., 1.), p(1., 1., 1.), p(1., 0., 1.)],
        0,
    );
    quad(
        &mut s,
        [p(0., 0., 0.), p(0., 1., 0.), p(0., 1., 1.), p(0., 0., 1.)],
        0,
    );
    quad(
        &mut s,
        [p(1., 0., 0.), p(1., 0., 1.), p(1., 1., 1.), p(1., 1., 0.)],
        0,
    );
    s
}
