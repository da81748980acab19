//! The real meshes in ../shared/meshes load with the counts their sources
//! document, every import validates, and the half-edge structure accepts
//! every closed manifold one.
//!
//! Expected values: vertex and face counts from ../shared/meshes/README.md
//! (the bunny's 34,834 vertices are its referenced vertices: the file stores
//! 1,113 more that no face uses); topology (genus, boundary edges,
//! non-manifold edges) from the same README and from the models' known shape.

mod common;

use quadrille::io::Imported;
use quadrille::mesh::PolyMesh;

fn load(name: &str) -> Imported {
    let imported = common::import(name);
    imported.mesh.validate().unwrap();
    imported
        .polygons
        .validate(imported.mesh.vertex_count())
        .unwrap();
    imported
}

#[test]
fn bunny_has_its_documented_counts_and_five_holes() {
    let m = load("stanford-bunny.obj");
    let r = &m.report;
    assert_eq!(r.vertices, 34_834);
    assert_eq!(r.faces, 69_451);
    assert_eq!(r.boundary_edges, 223);
    assert_eq!(r.repairs.unreferenced_vertices_removed, 1_113);
    assert_eq!(r.nonmanifold_edges, 0);
    assert_eq!(r.components, 1);
    let poly = PolyMesh::from_triangles(m.mesh.positions.clone(), &m.mesh.triangles).unwrap();
    poly.validate().unwrap();
    assert_eq!(
        poly.boundary_loops().len(),
        5,
        "the bunny has 5 holes at its base"
    );
}

#[test]
fn closed_meshes_are_closed_with_their_genus() {
    for (name, vertices, faces, genus) in [
        ("fandisk.obj", 6_475, 12_946, 0),
        ("rocker-arm.obj", 10_044, 20_088, 1),
        ("spot.obj", 2_930, 5_856, 0),
    ] {
        let m = load(name);
        let r = &m.report;
        assert_eq!((r.vertices, r.faces), (vertices, faces), "{name}");
        assert_eq!(r.boundary_edges, 0, "{name}");
        assert_eq!(r.genus, Some(genus), "{name}");
        assert_eq!(r.components, 1, "{name}");
        let poly = PolyMesh::from_triangles(m.mesh.positions.clone(), &m.mesh.triangles).unwrap();
        poly.validate().unwrap();
        assert_eq!(poly.euler_characteristic(), 2 - 2 * genus, "{name}");
    }
}

#[test]
fn cow_is_closed_but_pinched_at_one_vertex() {
    let m = load("cow.obj");
    let r = &m.report;
    assert_eq!((r.vertices, r.faces), (2_903, 5_804));
    assert_eq!(r.boundary_edges, 0);
    assert_eq!(r.nonmanifold_edges, 0);
    assert_eq!(r.nonmanifold_vertices, 1);
    assert_eq!(r.genus, None, "a pinched vertex is not a manifold");
    assert!(PolyMesh::from_triangles(m.mesh.positions.clone(), &m.mesh.triangles).is_err());
}

#[test]
fn messy_meshes_are_reported_not_rejected() {
    let beetle = load("beetle.obj");
    assert_eq!(beetle.report.faces, 2_053);
    assert_eq!(beetle.report.nonmanifold_edges, 47);
    assert!(beetle.report.boundary_edges > 0);

    // The teapot's patches repeat their seam vertices: 403 of its 3,644
    // are welded (its 4 parts become 3).
    let teapot = load("teapot.obj");
    assert_eq!(
        (teapot.report.vertices, teapot.report.faces),
        (3_644 - 403, 6_320)
    );
    assert_eq!(teapot.report.repairs.welded_vertices, 403);
    assert_eq!(teapot.report.components, 3);
    assert!(teapot.report.boundary_edges > 0);

    let suzanne = load("suzanne.obj");
    assert_eq!(suzanne.report.vertices, 507);
    assert_eq!(
        suzanne.report.faces, 500,
        "quads stay quads in the polygon list"
    );
    assert_eq!(
        suzanne.report.triangles, 968,
        "the README's face count is the triangulated one"
    );
    assert_eq!(suzanne.report.repairs.polygons_triangulated, 468);
    assert!(suzanne.report.components > 1);
    assert!(suzanne.report.boundary_edges > 0);
}

#[test]
fn import_normalises_and_frame_restores_file_coordinates() {
    for name in ["fandisk.obj", "teapot.obj"] {
        let m = load(name);
        let b = m.mesh.bbox().unwrap();
        assert!((b.largest_axis() - 1.0).abs() < 1e-12, "{name}");
        assert!(b.center().length() < 1e-12, "{name}");
        let world = m.report.bbox;
        let restored_min = m.frame.to_world(b.min);
        assert!(
            (restored_min - world.min).length() < 1e-12 * world.diagonal(),
            "{name}"
        );
    }
}

#[test]
fn cli_info_prints_the_report_as_json() {
    let path = common::path("fandisk.obj");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_quadrille"))
        .args(["info", "--compact"])
        .arg(&path)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    for key in [
        "vertices",
        "faces",
        "boundary_edges",
        "nonmanifold_edges",
        "nonmanifold_vertices",
        "components",
        "bbox",
        "repairs",
    ] {
        assert!(json.get(key).is_some(), "missing {key}");
    }
    assert_eq!(json["vertices"], 6_475);
    assert_eq!(json["bbox"]["max"][1], 17.85);

    let bad = std::process::Command::new(env!("CARGO_BIN_EXE_quadrille"))
        .args(["info", "/nonexistent/mesh.obj"])
        .output()
        .unwrap();
    assert!(!bad.status.success());
    assert!(String::from_utf8_lossy(&bad.stderr).contains("/nonexistent/mesh.obj"));
}
