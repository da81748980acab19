//! The malformed-file corpus: every file in tests/fixtures/malformed/ must be
//! refused with an error that names the file, without panicking; errors in
//! text formats name the line. Files in tests/fixtures/valid/ are awkward but
//! legal and must load with the counts computed by hand below.
//!
//! The corpus is written by tests/fixtures/make_malformed.py; each file is
//! named after the one thing wrong with it.

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};

use quadrille::io::{IoError, Location, import, read_raw};

fn fixtures(folder: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures")
        .join(folder)
}

/// Imports `bytes` under `name`, turning a panic into a test failure that
/// names the file.
fn import_err(bytes: &[u8], name: &str) -> IoError {
    match catch_unwind(AssertUnwindSafe(|| import(bytes, name))) {
        Err(_) => panic!("{name}: import panicked"),
        Ok(Ok(imported)) => panic!(
            "{name}: import succeeded with {} vertices and {} faces, expected an error",
            imported.report.vertices, imported.report.faces
        ),
        Ok(Err(e)) => e,
    }
}

fn corpus() -> Vec<(String, Vec<u8>)> {
    let mut files: Vec<(String, Vec<u8>)> = std::fs::read_dir(fixtures("malformed"))
        .expect("tests/fixtures/malformed exists")
        .map(|entry| {
            let path = entry.unwrap().path();
            let name = path.file_name().unwrap().to_string_lossy().into_owned();
            (name, std::fs::read(&path).unwrap())
        })
        .collect();
    files.sort();
    files
}

#[test]
fn every_malformed_file_is_refused_naming_the_file() {
    let files = corpus();
    assert!(
        files.len() >= 30,
        "the corpus has only {} files",
        files.len()
    );
    for format in ["obj", "off", "ply", "stl", "glb", "gltf"] {
        assert!(
            files.iter().filter(|(n, _)| n.ends_with(format)).count() >= 3,
            "fewer than 3 malformed .{format} files"
        );
    }
    for (name, bytes) in &files {
        let e = import_err(bytes, name);
        let text = e.to_string();
        assert!(
            text.contains(name.as_str()),
            "{name}: message does not name the file: {text}"
        );
        assert_eq!(&e.file, name);
        assert!(e.message.len() > 10, "{name}: message too terse: {text}");
        // The raw readers alone must not panic either (import calls them,
        // but this keeps the guarantee if import ever short-circuits).
        let raw = catch_unwind(AssertUnwindSafe(|| read_raw(bytes, name)));
        assert!(raw.is_ok(), "{name}: read_raw panicked");
    }
}

/// (file, expected location, words the message must contain). Lines are
/// counted by hand in make_malformed.py's strings.
fn expected_places() -> Vec<(&'static str, Location, &'static [&'static str])> {
    use Location::*;
    let element = |kind, index| Element { kind, index };
    vec![
        ("obj_nan_coordinate.obj", Line(2), &["not finite"]),
        ("obj_inf_coordinate.obj", Line(3), &["not finite"]),
        (
            "obj_index_out_of_range.obj",
            Line(4),
            &["9", "out of range"],
        ),
        (
            "obj_negative_index_before_start.obj",
            Line(3),
            &["before the first vertex"],
        ),
        ("obj_zero_index.obj", Line(4), &["index 0"]),
        ("obj_face_two_corners.obj", Line(4), &["2 corners"]),
        // CRLF, lone CR and LF each end one line: the face is line 4.
        (
            "obj_mixed_line_endings_bad_index.obj",
            Line(4),
            &["out of range"],
        ),
        ("obj_not_a_number.obj", Line(2), &["'zero'"]),
        ("obj_unknown_statement.obj", Line(4), &["frobnicate"]),
        ("obj_invalid_utf8.obj", Line(3), &["UTF-8"]),
        ("obj_continuation_at_eof.obj", Line(4), &["continuation"]),
        ("obj_no_faces.obj", File, &["no faces"]),
        ("every-face-degenerate.obj", File, &["degenerate"]),
        ("empty.obj", File, &["empty"]),
        ("off_nan.off", Line(4), &["not finite"]),
        ("off_index_out_of_range.off", Line(6), &["out of range"]),
        ("off_face_too_small.off", Line(6), &["2 corners"]),
        ("off_truncated_faces.off", File, &["face 1"]),
        ("off_huge_counts.off", File, &["vertex 1"]),
        (
            "ply_index_out_of_range.ply",
            Line(13),
            &["face 0", "out of range"],
        ),
        ("ply_negative_index.ply", Line(13), &["negative"]),
        ("ply_ascii_inf.ply", Line(11), &["vertex 1", "not finite"]),
        ("ply_ascii_short_line.ply", Line(11), &["vertex 1", "'z'"]),
        ("ply_duplicate_element.ply", Line(7), &["declared twice"]),
        (
            "ply_tristrips_bad_index.ply",
            Line(14),
            &["tristrip 0", "-2"],
        ),
        ("ply_nan.ply", element("vertex", 1), &["not finite"]),
        ("ply_no_faces.ply", File, &["no 'face'"]),
        ("ply_no_vertex_element.ply", File, &["no 'vertex'"]),
        ("ply_bad_list_type.ply", File, &["integers"]),
        (
            "ply_huge_declared_count.ply",
            Byte(202),
            &["ends inside vertex 2"],
        ),
        (
            "ply_big_endian_huge_list.ply",
            Byte(201),
            &["ends inside face 0"],
        ),
        (
            "stl_truncated_binary.stl",
            Byte(154),
            &["truncated", "2 triangles"],
        ),
        (
            "stl_binary_solid_header_truncated.stl",
            Byte(174),
            &["truncated"],
        ),
        ("stl_nan.stl", element("triangle", 0), &["not finite"]),
        (
            "stl_ascii_missing_endloop.stl",
            element("facet", 1),
            &["endloop"],
        ),
        ("stl_ascii_inf.stl", element("facet", 0), &["finite"]),
        (
            "stl_ascii_no_endsolid.stl",
            element("facet", 1),
            &["endsolid"],
        ),
        ("glb_bad_magic.glb", File, &["glTF"]),
        (
            "gltf_external_buffer.gltf",
            element("mesh", 0),
            &["'triangle.bin'", "data URI"],
        ),
        (
            "gltf_accessor_out_of_range.gltf",
            element("mesh", 0),
            &["primitive 0", "POSITION"],
        ),
        ("gltf_missing_position.gltf", File, &["POSITION", "Missing"]),
        (
            "gltf_index_out_of_range.gltf",
            element("mesh", 0),
            &["vertex 7"],
        ),
        ("gltf_node_cycle.gltf", element("node", 0), &["twice"]),
        ("gltf_only_points.gltf", File, &["no faces"]),
        (
            "gltf_position_accessor_missing.gltf",
            element("mesh", 0),
            &["accessor 9"],
        ),
    ]
}

#[test]
fn errors_carry_the_expected_place() {
    let files = corpus();
    for (name, location, words) in expected_places() {
        let (_, bytes) = files
            .iter()
            .find(|(n, _)| n == name)
            .unwrap_or_else(|| panic!("{name} is missing from the corpus"));
        let e = import_err(bytes, name);
        assert_eq!(e.location, location, "{name}: {e}");
        for word in words {
            assert!(
                e.message.contains(word),
                "{name}: expected '{word}' in: {e}"
            );
        }
        if let Location::Line(n) = location {
            assert!(
                e.to_string().starts_with(&format!("{name}:{n}: ")),
                "{name}: {e}"
            );
        }
    }
}

#[test]
fn awkward_but_valid_files_load() {
    let load = |name: &str| {
        let bytes = std::fs::read(fixtures("valid").join(name)).unwrap();
        import(&bytes, name).unwrap_or_else(|e| panic!("{e}"))
    };
    let m = load("obj_mixed_line_endings.obj");
    assert_eq!((m.report.vertices, m.report.faces), (4, 1));
    assert_eq!(m.polygons.face(0), &[0, 1, 2, 3]);

    let m = load("obj_groups_texcoords_normals.obj");
    assert_eq!((m.report.vertices, m.report.faces), (4, 2));
    assert_eq!(m.polygons.face(0), &[0, 1, 2]);
    assert_eq!(m.polygons.face(1), &[0, 2, 3]);
    assert_eq!(m.report.warnings, vec!["skipped 1 line (l) elements"]);

    // f -3 -2 -1 after three vertices is 1 2 3; after the fourth vertex,
    // f -3 -1 -2 is 2 4 3.
    let m = load("obj_negative_indices.obj");
    assert_eq!(m.polygons.face(0), &[0, 1, 2]);
    assert_eq!(m.polygons.face(1), &[1, 3, 2]);
}
