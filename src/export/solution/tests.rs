//! The saved solution's tests: round trips, every damaged byte refused, old formats read, and
//! the bytes of fixed solutions the same as the files in `testdata/` (written before the
//! format moved into [`crate::container`]).

use super::write::section;
use super::*;
use crate::container::Cursor;
use crate::mesh::{Axis, Patch, PatchClass, Side};
use glam::Vec3;

fn sample() -> SavedSolution {
    let mut mesh = Mesh {
        vertices: vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y],
        patch_vertices: vec![0, 1, 2, 3],
        patches: Vec::new(),
        patch_size: 1.0,
        ..Mesh::default()
    };
    mesh.patches.push(Patch {
        first: 0,
        count: 4,
        material: 0,
        polygon: 0,
        area: 1.0,
        centre: Vec3::new(0.5, 0.5, 0.0),
        normal: Vec3::Z,
        class: PatchClass::Axial(Axis::Z),
        side: Side::One,
    });
    SavedSolution {
        meta: SolutionMeta {
            tool_version: "0.1.0".into(),
            scene: "unit".into(),
            scene_hash: 42,
            patch_size: 1.0,
            two_sided: false,
            method: "adaptive-rays".into(),
            seed: 1,
            tolerance: 0.05,
            energy_per_ray: 0.1,
            stop_fraction: 0.0006,
            stop_reason: Some("converged".into()),
            shots: 3,
            rays: 100,
            materials: vec![SavedMaterial {
                name: "m".into(),
                rho: [0.5; 3],
                ke: [1.0; 3],
                transmittance: 0.0,
                transmittance_rgb: None,
            }],
            settings: serde_json::Value::Null,
        },
        mesh,
        b: vec![[1.0, 2.0, 3.0]],
        unshot: vec![[0.0, 0.1, 0.2]],
        vertex_b: vec![[1.0, 2.0, 3.0]; 4],
        channels: vec![LightChannel {
            name: "m".into(),
            b: vec![[1.0, 2.0, 3.0]],
        }],
        elements: None,
    }
}

fn bytes(s: &SavedSolution) -> Vec<u8> {
    let mut v = Vec::new();
    s.write(&mut v).unwrap();
    v
}

#[test]
fn round_trip_is_identical() {
    let s = sample();
    let back = SavedSolution::from_bytes(Path::new("x.rad"), &bytes(&s)).unwrap();
    assert_eq!(back, s);
}

#[test]
fn every_truncation_is_refused_without_panic() {
    let b = bytes(&sample());
    for k in 0..b.len() {
        let e = SavedSolution::from_bytes(Path::new("x.rad"), &b[..k]).unwrap_err();
        assert!(
            matches!(
                e,
                SolutionError::Truncated { .. } | SolutionError::NotASolution { .. }
            ),
            "{k}: {e}"
        );
    }
}

#[test]
fn every_flipped_byte_is_refused_without_panic() {
    let b = bytes(&sample());
    for k in 0..b.len() {
        let mut c = b.clone();
        c[k] ^= 0x5a;
        // Flipping a reserved header byte is harmless; anything else must be caught.
        if let Ok(s) = SavedSolution::from_bytes(Path::new("x.rad"), &c) {
            assert!((12..16).contains(&k) || (28..32).contains(&k), "{k}");
            assert_eq!(s, sample());
        }
    }
}

/// The bytes of `sol` as format 1 wrote them: no `SIDE` and no element sections.
fn as_format_1(sol: &SavedSolution) -> Vec<u8> {
    let b = bytes(sol);
    let header_len = CONTAINER.header_len();
    let mut c = Cursor::new(&b[header_len..]);
    let mut payload = Vec::new();
    while !c.is_empty() {
        let tag = c.arr::<4>().unwrap();
        let len = c.u64().unwrap() as usize;
        let body = c.take(len).unwrap();
        if !matches!(
            &tag,
            b"SIDE" | b"EVRT" | b"EIDX" | b"ELEM" | b"EPAT" | b"EVRD"
        ) {
            section(&mut payload, &tag, |s| s.extend_from_slice(body));
        }
    }
    let mut out = b[..header_len].to_vec();
    out[8..12].copy_from_slice(&1u32.to_le_bytes());
    out[16..24].copy_from_slice(&(payload.len() as u64).to_le_bytes());
    out[24..28].copy_from_slice(&crc32fast::hash(&payload).to_le_bytes());
    out.extend_from_slice(&payload);
    out
}

/// [`sample`] with a back twin for its patch, and elements: the patch cut in two triangles.
fn with_twin_and_elements() -> SavedSolution {
    let mut s = sample();
    let mut twin = s.mesh.patches[0];
    twin.normal = -twin.normal;
    twin.side = Side::Back { front: 0 };
    s.mesh.patches[0].side = Side::Front { back: 1 };
    s.mesh.patches.push(twin);
    s.b.push([0.5; 3]);
    s.unshot.push([0.0; 3]);
    s.channels[0].b.push([0.5; 3]);
    let mut em = s.mesh.clone();
    em.patches.truncate(1);
    em.patches[0].side = Side::One;
    em.patches[0].count = 3;
    em.patch_vertices = vec![0, 1, 2, 0, 2, 3];
    let mut second = em.patches[0];
    second.first = 3;
    em.patches.push(second);
    s.elements = Some(Elements::new(em, vec![0, 0], vec![[1.0, 2.0, 3.0]; 4]));
    s
}

/// Format 2 keeps the sides and the elements; format 1 files still read (elements none,
/// every patch one-sided until `Mesh::pair_twins`).
#[test]
fn format_2_keeps_sides_and_elements_and_format_1_still_reads() {
    let s = with_twin_and_elements();
    let back = SavedSolution::from_bytes(Path::new("x.rad"), &bytes(&s)).unwrap();
    assert_eq!(back, s);
    assert_eq!(back.display().0.patches.len(), 2);
    // As format 1: no sides, no elements, the rest the same.
    let old = SavedSolution::from_bytes(Path::new("x.rad"), &as_format_1(&s)).unwrap();
    assert!(old.elements.is_none());
    assert!(old.mesh.patches.iter().all(|p| p.side == Side::One));
    assert_eq!(old.b, s.b);
    let mut paired = old.mesh.clone();
    assert_eq!(paired.pair_twins(), 1);
    assert_eq!(paired.patches, s.mesh.patches);
    assert_eq!(old.display().0.patches.len(), 2);
}

#[test]
fn newer_version_and_foreign_scene() {
    let mut b = bytes(&sample());
    b[8..12].copy_from_slice(&(FORMAT_VERSION + 1).to_le_bytes());
    let e = SavedSolution::from_bytes(Path::new("x.rad"), &b).unwrap_err();
    assert!(e.to_string().contains("newer"), "{e}");
    let s = sample();
    assert!(s.check_scene(Path::new("x.rad"), "unit", 42).is_ok());
    let e = s.check_scene(Path::new("x.rad"), "other", 43).unwrap_err();
    assert!(e.to_string().contains("another scene"), "{e}");
}

/// A material saved before glazing kept its colour (no `transmittance_rgb` in the META
/// JSON) reads as grey glazing; tinted glazing's colour round-trips, and grey glazing
/// writes no colour (so its files are as before).
#[test]
fn glazing_colour_is_optional_and_old_files_read_as_grey() {
    let old = r#"{"name":"glass","rho":[0.1,0.1,0.1],"ke":[0,0,0],"transmittance":0.6}"#;
    let m: SavedMaterial = serde_json::from_str(old).unwrap();
    assert_eq!(m.transmittance_rgb, None);
    let mat = m.material();
    assert_eq!(mat.transmittance_rgb(), [0.6; 3]);
    assert_eq!(mat.tint(), [1.0; 3]);
    assert!(!serde_json::to_string(&m)
        .unwrap()
        .contains("transmittance_rgb"));

    let mut s = sample();
    s.meta.materials[0].transmittance = 0.4;
    s.meta.materials[0].transmittance_rgb = Some([0.2, 0.6, 0.4]);
    let back = SavedSolution::from_bytes(Path::new("x.rad"), &bytes(&s)).unwrap();
    assert_eq!(back, s);
    let mat = back.meta.materials[0].material();
    assert_eq!(mat.transmittance_rgb(), [0.2, 0.6, 0.4]);
    assert!(mat.is_tinted());

    // A damaged colour is refused, not drawn.
    s.meta.materials[0].transmittance_rgb = Some([0.2, 1.6, 0.4]);
    let e = SavedSolution::from_bytes(Path::new("x.rad"), &bytes(&s)).unwrap_err();
    assert!(e.to_string().contains("transmittance"), "{e}");
}

/// Files written before the format moved into [`crate::container`] (`testdata/`, by the same
/// [`sample`]s) read back as they were, and the same solutions write the same bytes.
#[test]
fn files_written_before_read_and_write_the_same() {
    let path = Path::new("x.rad");
    let v2: &[u8] = include_bytes!("testdata/sample-v2.rad");
    assert_eq!(bytes(&sample()), v2);
    assert_eq!(SavedSolution::from_bytes(path, v2).unwrap(), sample());
    let elements: &[u8] = include_bytes!("testdata/elements-v2.rad");
    assert_eq!(bytes(&with_twin_and_elements()), elements);
    assert_eq!(
        SavedSolution::from_bytes(path, elements).unwrap(),
        with_twin_and_elements()
    );
    let v1: &[u8] = include_bytes!("testdata/sample-v1.rad");
    assert_eq!(as_format_1(&sample()), v1);
    let old = SavedSolution::from_bytes(path, v1).unwrap();
    assert_eq!((old.b, old.elements), (sample().b, None));
}
