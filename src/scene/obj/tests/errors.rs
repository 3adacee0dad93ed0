//! Errors in the OBJ and the MTL (each one line naming the file), and the OBJ spellings tobj
//! does not read (comments after the data, continued lines).

use super::*;

// ---- errors in the OBJ ----

#[test]
fn unparsable_obj_is_an_error_with_its_line() {
    let obj = "v 0 0 0\nv 1 zero 0\nv 0 1 0\nf 1 2 3\n";
    assert_error(
        load_strs(obj, ""),
        "test.obj",
        &["vertex", "line 2", "v 1 zero 0"],
    );
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n";
    assert_error(load_strs(obj, ""), "test.obj", &["face", "line 4"]);
    let obj = "v 0 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    assert_error(load_strs(obj, ""), "test.obj", &["vertex", "line 1"]);
}

#[test]
fn non_finite_vertex_is_an_error_naming_it() {
    for (bad, needle) in [("nan 0 0", "NaN"), ("0 inf 0", "inf"), ("0 0 1e39", "1e39")] {
        let obj = format!("v 0 0 0\nv 1 0 0\nv {bad}\nf 1 2 3\n");
        let message = assert_error(
            load_strs(&obj, ""),
            "test.obj",
            &["vertex 3 (line 3)", "not finite"],
        );
        assert!(message.to_lowercase().contains(&needle.to_lowercase()));
    }
    // An unused bad vertex is harmless.
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv nan 0 0\nf 1 2 3\n";
    assert_eq!(load_strs(obj, "").unwrap().polygons.len(), 1);
}

#[test]
fn faces_of_fewer_than_three_vertices_are_errors() {
    for (face, n) in [
        ("f 1 2", "2 vertices"),
        ("f 1", "1 vertex"),
        ("f", "0 vertices"),
    ] {
        let obj = format!("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n{face}\n");
        assert_error(
            load_strs(&obj, ""),
            "test.obj",
            &["line 5", &format!("a face with {n} ")],
        );
    }
    // Lines and points are not faces and are skipped.
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2\np 3\nf 1 2 3\n";
    assert_eq!(load_strs(obj, "").unwrap().polygons.len(), 1);
}

#[test]
fn index_out_of_range_is_an_error() {
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n";
    assert_error(
        load_strs(obj, ""),
        "test.obj",
        &["line 4", "vertex 9, but the file has 3 vertices"],
    );
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n";
    assert_error(load_strs(obj, ""), "test.obj", &["line 4", "index 0"]);
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n";
    assert_error(load_strs(obj, ""), "test.obj", &["line 4", "vertex -4"]);
}

#[test]
fn polylines_of_three_or_more_vertices_are_not_polygons() {
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2 3\nl 1 2 3 1\n";
    assert_error(load_strs(obj, ""), "test.obj", &["no polygons"]);
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2 3\nf 1 2 3\n";
    assert_eq!(load_strs(obj, "").unwrap().polygons.len(), 1);
}

#[test]
fn no_polygons_is_an_error() {
    assert_error(load_strs("", ""), "test.obj", &["no polygons"]);
    let obj = "v 0 0 0\nv 1 0 0\nl 1 2\n";
    assert_error(load_strs(obj, ""), "test.obj", &["no polygons"]);
}

// ---- errors in the MTL ----

const TRIANGLE_USING_M: &str = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl m\nf 1 2 3\n";

#[test]
fn negative_or_non_finite_reflectance_is_an_error() {
    for kd in ["0.5 -0.1 0.5", "0.5 0.5 nan", "inf 0.5 0.5"] {
        let mtl = format!("newmtl m\nKd {kd}\n");
        assert_error(
            load_strs(TRIANGLE_USING_M, &mtl),
            "test.obj",
            &["'m'", "Kd", "not a reflectance", "at least 0"],
        );
    }
    // Just below 1 is kept as it is, without a warning.
    let scene = load_strs(TRIANGLE_USING_M, "newmtl m\nKd 0.999 0 0\n").unwrap();
    assert_eq!(scene.materials[0].rho, [0.999, 0.0, 0.0]);
    assert_eq!(scene.materials[0].rho_source, RhoSource::Kd);
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
}

#[test]
fn reflectance_of_one_or_more_is_clamped_with_one_warning() {
    let obj = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 0 0 1\n\
               usemtl white\nf 1 2 3\nusemtl hot\nf 2 4 3\nusemtl fine\nf 1 2 5\n";
    let mtl = "newmtl white\nKd 1 1 1\nnewmtl hot\nKd 1.5 0.5 0.25\nnewmtl fine\nKd 0.5 0.5 0.5\n";
    let scene = load_strs(obj, mtl).unwrap();
    assert_eq!(material(&scene, "white").rho, [MAX_REFLECTANCE; 3]);
    assert_eq!(material(&scene, "hot").rho, [MAX_REFLECTANCE, 0.5, 0.25]);
    assert_eq!(material(&scene, "fine").rho, [0.5; 3]);
    assert_eq!(
        material(&scene, "hot").rho_source,
        RhoSource::Clamped {
            unclamped: [1.5, 0.5, 0.25],
            from: Box::new(RhoSource::Kd)
        }
    );
    assert_eq!(scene.warnings.len(), 1, "{:?}", scene.warnings);
    let w = &scene.warnings[0];
    for needle in ["test.obj", "clamped to 0.98", "'white'", "'hot'"] {
        assert!(w.contains(needle), "{w:?} lacks {needle:?}");
    }
    assert!(!w.contains("'fine'"), "{w}");
    const { assert!(MAX_REFLECTANCE < 1.0) };
}

#[test]
fn negative_or_non_finite_ke_is_an_error() {
    for ke in ["-1 0 0", "0 inf 0", "nan 1 1"] {
        let mtl = format!("newmtl m\nKd 0.5 0.5 0.5\nKe {ke}\n");
        assert_error(
            load_strs(TRIANGLE_USING_M, &mtl),
            "test.obj",
            &["'m'", "Ke", "finite and not negative"],
        );
    }
}

#[test]
fn short_or_bad_colour_lines_are_errors_not_panics() {
    for (line, needle) in [
        ("Kd 0.5 0.5", "needs 3 numbers"),
        ("Kd", "needs 3 numbers"),
        ("Ke one two three", "'one' is not a number"),
        ("Kd spectral file.rfl", "not supported"),
    ] {
        let mtl = format!("newmtl m\n{line}\n");
        assert_error(
            load_strs(TRIANGLE_USING_M, &mtl),
            "test.obj",
            &["line 2", needle],
        );
    }
}

#[test]
fn patch_size_hint_is_read_from_its_comment() {
    let obj = "# radiosity: patch-size 0.6\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    let s = load_obj_from_strs("hint.obj", obj, "", &LoadOptions::default()).unwrap();
    assert_eq!(s.patch_size_hint, Some(0.6));
    let none = load_obj_from_strs("none.obj", &obj[28..], "", &LoadOptions::default()).unwrap();
    assert_eq!(none.patch_size_hint, None);
    let bad = obj.replace("0.6", "-1");
    let e = load_obj_from_strs("bad.obj", &bad, "", &LoadOptions::default()).unwrap_err();
    assert!(e.to_string().contains("patch-size"), "{e}");
}

#[test]
fn helpers_behave() {
    assert_eq!(one_line("a\nb\r\nc"), "a b c");
    assert_eq!(to_f64(0.725f32), 0.725);
    assert_eq!(parse_colour("2"), Some([2.0; 3]));
    assert_eq!(parse_colour("1 2"), None);
    assert_eq!(name_list(&[]), "none");
    assert_eq!(snippet(&"x".repeat(100)).len(), 60);
}

// ---- OBJ spellings: comments after the data, continued lines ----

#[test]
fn comments_after_the_data_are_ignored() {
    let obj = "mtllib m.mtl   # the library\n\
               v 0 0 0   # note\nv 1 0 0 #x\nv 0 1 0\t# tab\nv 1 1 0# no space\n\
               g room # group\nusemtl grey # x\nf 1 2 3 # door\nf 2 4 3#\n";
    let mtl = "newmtl grey # the walls\nKd 0.5 0.5 0.5 # grey\nKe 0.25 # dim\n";
    let scene = load_strs(obj, mtl).unwrap();
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    assert_eq!(scene.positions.len(), 4);
    assert_eq!(scene.polygons.len(), 2);
    let m = &scene.materials[scene.polygons[0].material as usize];
    assert_eq!(
        (m.name.as_str(), m.rho, m.ke),
        ("grey", [0.5; 3], [0.25; 3])
    );
}

#[test]
fn a_hash_inside_a_name_is_part_of_it() {
    let obj = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl wall#2 # comment\nf 1 2 3\n";
    let scene = load_strs(obj, "newmtl wall#2\nKd 0.25 0.25 0.25\n").unwrap();
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    assert_eq!(scene.materials[0].name, "wall#2");
    assert_eq!(scene.materials[0].rho, [0.25; 3]);
}

#[test]
fn backslash_continues_a_line() {
    let obj = "mtllib m.mtl\nv 0 0 0\nv 1 0 \\\n  0\nv 1 1 0\nv 0 1 0\nusemtl grey\n\
               f 1 \\\n2 \\\n  3 \\\r\n4   # a quad over four lines\nf 1 2 3\n";
    let scene = load_strs(obj, GREY_MTL).unwrap();
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    assert_eq!(scene.positions.len(), 4);
    let arities: Vec<u32> = scene.polygons.iter().map(|p| p.len).collect();
    assert_eq!(arities, [4, 3]);
    assert_eq!(scene.positions[1], Vec3::new(1.0, 0.0, 0.0));
}

#[test]
fn a_backslash_in_a_comment_continues_nothing() {
    let obj = "v 0 0 0 # ends in \\\nv 1 0 0\nv 0 1 0\n# a comment \\\nf 1 2 3\n";
    let scene = load_strs(obj, "").unwrap();
    assert_eq!(scene.positions.len(), 3);
    assert_eq!(scene.polygons.len(), 1);
}

#[test]
fn errors_name_the_original_line_after_continued_lines() {
    // Lines 2-4 are one vertex; line 7 is the bad face.
    let obj = "# model\nv 0 \\\n0 \\\n0\nv 1 0 0 # x\nv 0 1 0\nf 1 2 x\n";
    assert_error(
        load_strs(obj, ""),
        "test.obj",
        &["line 7", "cannot read a face", "f 1 2 x"],
    );
    let obj = "v 0 0 0\nf 1 \\\n 2 \\\n 3\nv 1 0 0\nf 1 \\\n 2\n";
    assert_error(
        load_strs(obj, ""),
        "test.obj",
        &["line 6", "a face with 2 vertices"],
    );
    let obj = "v 0 0 0\nv 1 0 0\\\n\nv 0 1 0\nf 1 2 9 # far\n";
    assert_error(
        load_strs(obj, ""),
        "test.obj",
        &["line 5", "vertex 9", "has 3 vertices"],
    );
    let mtl = "newmtl m\nKd 0.5 \\\n 0.5\nNs \\\n shiny\n";
    assert_error(
        load_strs(TRIANGLE_USING_M, mtl),
        "test.obj",
        &["line 2", "needs 3 numbers"],
    );
}

#[test]
fn the_patch_size_comment_still_reads() {
    let obj = "# radiosity: patch-size 0.5\nv 0 0 0 # a\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    let scene = load_strs(obj, "").unwrap();
    assert_eq!(scene.patch_size_hint, Some(0.5));
}

#[test]
fn normalize_keeps_every_line_at_its_number() {
    use super::text::normalize;
    assert!(matches!(
        normalize("v 0 0 0\n# c\n"),
        std::borrow::Cow::Borrowed(_)
    ));
    let text = "a \\\nb\nc # x\n# d \\\ne \\\n# f\ng\\";
    let out = normalize(text);
    assert_eq!(out.lines().count(), text.lines().count());
    assert_eq!(out, "a  b\n\nc\n# d \\\ne  \n\ng \n");
}
