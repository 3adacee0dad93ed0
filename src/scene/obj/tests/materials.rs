//! Materials beyond the colours: textures (`map_Kd`) and glazing, grey and tinted
//! (docs/design.md §9).

use super::*;

// ---- textures ----

/// A folder with `model.obj` (a lit triangle of material `m`), `mat/m.mtl` holding `mtl` and
/// the files `files` (paths relative to the folder).
fn textured(mtl: &str, files: &[(&str, Vec<u8>)]) -> (tempfile::TempDir, std::path::PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("model.obj");
    std::fs::write(
        &path,
        "mtllib mat/m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl m\nf 1 2 3\n",
    )
    .unwrap();
    std::fs::create_dir_all(dir.path().join("mat")).unwrap();
    std::fs::write(dir.path().join("mat/m.mtl"), mtl).unwrap();
    for (name, bytes) in files {
        let file = dir.path().join(name);
        std::fs::create_dir_all(file.parent().unwrap()).unwrap();
        std::fs::write(file, bytes).unwrap();
    }
    (dir, path)
}

/// An image of `texels` (RGB, 8-bit) in one row, encoded as `format`.
fn encode(texels: &[[u8; 3]], format: image::ImageFormat) -> Vec<u8> {
    let image = image::RgbImage::from_fn(texels.len() as u32, 1, |x, _| {
        image::Rgb(texels[x as usize])
    });
    let mut bytes = std::io::Cursor::new(Vec::new());
    image.write_to(&mut bytes, format).unwrap();
    bytes.into_inner()
}

fn close(a: [f64; 3], b: [f64; 3], tol: f64) -> bool {
    (0..3).all(|c| (a[c] - b[c]).abs() <= tol)
}

#[test]
fn reflectance_is_kd_times_the_mean_texture_colour_in_linear_light() {
    // Half black, half white: 0.5 in linear light (an sRGB mean would say so too, but see
    // the grey below).
    let half = encode(
        &[[0; 3], [255; 3], [0; 3], [255; 3]],
        image::ImageFormat::Png,
    );
    // sRGB 188 is 0.5 in linear light (not 0.737).
    let grey = encode(&[[188, 188, 188]], image::ImageFormat::Png);
    let mtl = "newmtl m\nKd 0.8 0.6 0.4\nmap_Kd -s 1 1 1 -bm 1 -clamp on textures/half.png\n\
               newmtl g\nKd 1 1 1\nmap_Kd textures/grey.png # grey\n";
    let (_dir, path) = textured(
        mtl,
        &[
            ("mat/textures/half.png", half),
            ("mat/textures/grey.png", grey),
        ],
    );
    let scene = load_obj(&path, &LoadOptions::default()).unwrap();
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    let m = material(&scene, "m");
    assert!(close(m.rho, [0.4, 0.3, 0.2], 1e-12), "{:?}", m.rho);
    assert_eq!(
        m.rho_source,
        RhoSource::KdTimesTexture {
            file: "textures/half.png".into(),
            kd: [0.8, 0.6, 0.4],
            mean: [0.5; 3]
        }
    );
    // Kd 1 1 1 with a texture, as exporters write it: ρ is the texture's mean, no clamp.
    let g = material(&scene, "g");
    assert!(close(g.rho, [0.5; 3], 0.005), "{:?}", g.rho);
    assert!(matches!(g.rho_source, RhoSource::KdTimesTexture { .. }));
}

#[test]
fn jpeg_tga_and_bmp_textures_decode() {
    let colour = [[200, 100, 50]; 16];
    let expected = [200.0, 100.0, 50.0].map(|v: f64| super::texture::srgb_to_linear(v / 255.0));
    for (ext, format) in [
        ("jpg", image::ImageFormat::Jpeg),
        ("tga", image::ImageFormat::Tga),
        ("bmp", image::ImageFormat::Bmp),
    ] {
        let file = format!("t.{ext}");
        let mtl = format!("newmtl m\nKd 0.9 0.9 0.9\nmap_Kd ../{file}\n");
        let (_dir, path) = textured(&mtl, &[(&file, encode(&colour, format))]);
        let scene = load_obj(&path, &LoadOptions::default()).unwrap();
        assert!(scene.warnings.is_empty(), "{ext}: {:?}", scene.warnings);
        let rho = scene.materials[0].rho;
        // JPEG is lossy: a few levels of 255.
        assert!(
            close(rho, expected.map(|e| 0.9 * e), 0.02),
            "{ext}: {rho:?}"
        );
    }
}

#[test]
fn a_texture_that_does_not_load_is_one_warning_and_kd_alone() {
    let mtl = "newmtl m\nKd 0.25 0.5 0.75\nmap_Kd missing.png\n\
               newmtl broken\nKd 0.5 0.5 0.5\nmap_Kd broken.png\n\
               newmtl bare\nmap_Kd -bm 1\n";
    let (_dir, path) = textured(mtl, &[("mat/broken.png", b"not a png".to_vec())]);
    let scene = load_obj(&path, &LoadOptions::default()).unwrap();
    assert_eq!(scene.warnings.len(), 1, "{:?}", scene.warnings);
    let w = &scene.warnings[0];
    for needle in [
        "3 texture(s) not loaded",
        "Kd alone",
        "'m'",
        "missing.png: no such file",
        "'broken'",
        "broken.png: cannot decode",
        "'bare'",
        "no file name",
    ] {
        assert!(w.contains(needle), "{w:?} lacks {needle:?}");
    }
    let m = material(&scene, "m");
    assert_eq!(m.rho, [0.25, 0.5, 0.75]);
    assert_eq!(
        m.rho_source,
        RhoSource::TextureNotLoaded {
            file: "missing.png".into(),
            fallback: Box::new(RhoSource::Kd)
        }
    );
    assert_eq!(material(&scene, "bare").rho, [0.5; 3]);
}

#[test]
fn texture_paths_as_windows_exporters_write_them() {
    let white = encode(&[[255; 3]], image::ImageFormat::Png);
    let mtl = "newmtl m\nKd 0.5 0.5 0.5\nmap_Kd Textures\\WALL.PNG\n";
    let (_dir, path) = textured(mtl, &[("mat/Textures/wall.png", white)]);
    let scene = load_obj(&path, &LoadOptions::default()).unwrap();
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    assert!(close(scene.materials[0].rho, [0.5; 3], 1e-12));
}

#[test]
fn a_texture_that_makes_one_or_more_is_clamped() {
    let white = encode(&[[255; 3]], image::ImageFormat::Png);
    let mtl = "newmtl m\nKd 1 1 1\nmap_Kd white.png\n";
    let (_dir, path) = textured(mtl, &[("mat/white.png", white)]);
    let scene = load_obj(&path, &LoadOptions::default()).unwrap();
    assert_eq!(scene.warnings.len(), 1, "{:?}", scene.warnings);
    assert!(scene.warnings[0].contains("'m'"), "{:?}", scene.warnings);
    assert_eq!(scene.materials[0].rho, [MAX_REFLECTANCE; 3]);
    let RhoSource::Clamped { from, .. } = &scene.materials[0].rho_source else {
        panic!("{:?}", scene.materials[0].rho_source);
    };
    assert!(matches!(**from, RhoSource::KdTimesTexture { .. }));
}

#[test]
fn map_file_skips_the_options() {
    use super::texture::map_file;
    for (value, file) in [
        ("wall.png", "wall.png"),
        ("-s 1 1 1 wall.png", "wall.png"),
        ("-s 2 wall.png", "wall.png"),
        (
            "-bm 1 -o 0 0 0 -t 0.1 0.1 textures/wall.png",
            "textures/wall.png",
        ),
        (
            "-clamp on -blendu off -imfchan r -mm 0 1 a b.png",
            "a b.png",
        ),
        ("-type sphere -texres 512 -boost 2 w.jpg", "w.jpg"),
        ("my wall.png", "my wall.png"),
        ("-bm", "-bm"),
        ("-bm 1", ""),
        ("", ""),
        ("-s 1 1 1 -tex.png", "-tex.png"),
    ] {
        assert_eq!(map_file(value), file, "{value}");
    }
}

// ---- glazing: grey and tinted (docs/design.md §9) ----

const PANE_OBJ: &str = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nusemtl glass\nf 1 2 3\n";

#[test]
fn a_tinted_tf_keeps_its_colour_and_its_mean_is_the_transmittance() {
    let s = load_strs(
        PANE_OBJ,
        "newmtl glass\nKd 0.05 0.05 0.05\nTf 0.2 0.6 0.3\nillum 4\n",
    )
    .unwrap();
    let m = material(&s, "glass");
    assert_eq!(m.transmittance_rgb, Some([0.2, 0.6, 0.3]));
    assert_eq!(m.transmittance_rgb(), [0.2, 0.6, 0.3]);
    assert!((m.transmittance - (0.2 + 0.6 + 0.3) / 3.0).abs() < 1e-15);
    let tint = m.tint();
    assert!(
        (tint[0] + tint[1] + tint[2] - 3.0).abs() < 1e-12,
        "{tint:?}"
    );
    assert!((tint[1] / tint[0] - 3.0).abs() < 1e-12, "{tint:?}");
    assert!(m.is_tinted());
    // Dissolve scales the colour as it scales the mean.
    let s = load_strs(PANE_OBJ, "newmtl glass\nKd 0 0 0\nTf 0.2 0.6 0.4\nd 0.5\n").unwrap();
    let m = material(&s, "glass");
    assert_eq!(m.transmittance_rgb, Some([0.1, 0.3, 0.2]));
    assert!((m.transmittance - 0.2).abs() < 1e-15);
}

#[test]
fn a_grey_tf_stays_grey_exactly() {
    let s = load_strs(
        PANE_OBJ,
        "newmtl glass\nKd 0.1 0.1 0.1\nTf 0.5 0.5 0.5\nillum 4\n",
    )
    .unwrap();
    let m = material(&s, "glass");
    assert_eq!(m.transmittance, 0.5);
    assert_eq!(m.transmittance_rgb, None);
    assert_eq!(m.transmittance_rgb(), [0.5; 3]);
    assert_eq!(m.tint(), [1.0; 3]);
    assert!(!m.is_tinted());
    // Opaque materials have no colour either.
    let s = load_strs(PANE_OBJ, "newmtl glass\nKd 0.1 0.1 0.1\nTf 1 0.5 1\nd 1\n").unwrap();
    let m = material(&s, "glass");
    assert!(
        m.transmittance > 0.0,
        "Tf strictly between 0 and 1 in a channel transmits"
    );
    let s = load_strs(PANE_OBJ, "newmtl glass\nKd 0.1 0.1 0.1\nTf 0 0 0\n").unwrap();
    let m = material(&s, "glass");
    assert_eq!((m.transmittance, m.transmittance_rgb), (0.0, None));
}

#[test]
fn tinted_glazing_is_cut_per_channel_where_rho_plus_t_exceeds_one() {
    let s = load_strs(
        PANE_OBJ,
        "newmtl glass\nKd 0.5 0.1 0.1\nTf 0.9 0.6 0.3\nillum 4\n",
    )
    .unwrap();
    let m = material(&s, "glass");
    assert_eq!(m.transmittance_rgb, Some([0.5, 0.6, 0.3]));
    assert!((m.transmittance - 1.4 / 3.0).abs() < 1e-15);
    let w = s.warnings.join("\n");
    assert!(
        w.contains("'glass' (0.900 0.600 0.300 → 0.500 0.600 0.300)"),
        "{w}"
    );
    // Grey glazing keeps the rule T ≤ 1 − max ρ, and stays grey.
    let s = load_strs(
        PANE_OBJ,
        "newmtl glass\nKd 0.5 0.1 0.1\nTf 0.9 0.9 0.9\nillum 4\n",
    )
    .unwrap();
    let m = material(&s, "glass");
    assert_eq!((m.transmittance, m.transmittance_rgb), (0.5, None));
}

#[test]
fn a_negative_tf_channel_is_an_error() {
    let r = load_strs(
        PANE_OBJ,
        "newmtl glass\nKd 0 0 0\nTf -0.1 0.5 0.5\nillum 4\n",
    );
    assert_error(r, "test.obj", &["glass", "negative in a channel"]);
}
