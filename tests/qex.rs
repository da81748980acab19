//! Quad extraction from the integer-grid map (src/extract/qex.rs), checked
//! against what the map says independently: the integer points of an exact
//! grid, Euler characteristics, the valences the cones prescribe, points
//! on the analytic surface, and kept boundaries.

mod common;

use quadrille::extract::qex::{self, Quadrangulation};
use quadrille::mesh::generate::{cylinder, flat_grid, icosphere, torus};
use quadrille::mesh::{PolyMesh, TriMesh};
use quadrille::param::{self, Params};
use quadrille::sizing::EdgeLengthMethod;

fn uniform(vertices: usize) -> Params {
    let mut p = Params::default();
    p.sizing.method = EdgeLengthMethod::Uniform;
    p.sizing.target_vertex_count = Some(vertices);
    p
}

fn quads(mesh: &TriMesh, params: &Params) -> (param::GridMap, Quadrangulation) {
    let run = param::run(mesh, params, &|| 0.0).expect("a map");
    let q = quadrille::progress::silently("qex", |p| qex::extract(mesh, &run.map, p))
        .expect("a quad mesh");
    (run.map, q)
}

fn valences(m: &PolyMesh) -> Vec<(usize, bool)> {
    (0..m.vertex_count() as u32)
        .map(|v| (m.valence(v), m.is_boundary_vertex(v)))
        .collect()
}

fn assert_pure_quads(m: &PolyMesh) {
    m.validate().expect("a valid half-edge mesh");
    for f in 0..m.face_count() as u32 {
        assert_eq!(m.degree(f), 4, "face {f}");
    }
}

#[test]
fn flat_square_gives_one_vertex_per_integer_point() {
    let mesh = flat_grid(1.0, 12);
    let (map, q) = quads(&mesh, &uniform(50));
    let m = &q.mesh;
    assert_pure_quads(m);
    // The map's extent in integer steps.
    let (mut lo, mut hi) = ([f64::MAX; 2], [f64::MIN; 2]);
    for c in map.uv.iter().flatten() {
        for (i, x) in [c.x, c.y].into_iter().enumerate() {
            lo[i] = lo[i].min(x);
            hi[i] = hi[i].max(x);
        }
    }
    let n: Vec<i64> = (0..2)
        .map(|i| (hi[i].round() - lo[i].round()) as i64)
        .collect();
    println!("square: {n:?} cells, report {:?}", q.report);
    assert_eq!(m.vertex_count() as i64, (n[0] + 1) * (n[1] + 1));
    assert_eq!(m.face_count() as i64, n[0] * n[1]);
    assert_eq!(m.boundary_loops().len(), 1, "the square's boundary is kept");
    assert_eq!(q.report.holes_filled, 0);
    // Every vertex lies on the square, the corners have valence 2.
    for p in &m.positions {
        assert!(p.z.abs() < 1e-12 && p.x.abs() <= 1.0 + 1e-12 && p.y.abs() <= 1.0 + 1e-12);
    }
    let corners = valences(m).iter().filter(|&&(v, _)| v == 2).count();
    assert_eq!(corners, 4);
}

#[test]
fn torus_gives_a_closed_regular_grid() {
    let mesh = torus(2.0, 0.7, 60, 24);
    let (_, q) = quads(&mesh, &uniform(300));
    let m = &q.mesh;
    println!("torus: V {}, report {:?}", m.vertex_count(), q.report);
    assert_pure_quads(m);
    assert!(m.boundary_loops().is_empty());
    assert_eq!(m.euler_characteristic(), 0);
    assert!(
        valences(m).iter().all(|&(v, _)| v == 4),
        "no cones, no irregular vertex"
    );
    let v = m.vertex_count() as f64;
    assert!((v / 300.0 - 1.0).abs() <= 0.1, "{v} vertices for 300");
}

#[test]
fn sphere_gives_eight_valence_three_vertices_on_the_surface() {
    let mesh = icosphere(1.0, 4);
    let (map, q) = quads(&mesh, &uniform(200));
    let m = &q.mesh;
    println!("sphere: V {}, report {:?}", m.vertex_count(), q.report);
    assert_eq!(map.cones.len(), 8);
    assert_pure_quads(m);
    assert!(m.boundary_loops().is_empty());
    assert_eq!(m.euler_characteristic(), 2);
    let vals = valences(m);
    assert_eq!(vals.iter().filter(|&&(v, _)| v == 3).count(), 8);
    assert!(vals.iter().all(|&(v, _)| v == 3 || v == 4));
    // Vertices interpolate the icosphere's flat triangles: within its
    // chord error (edge ≈ 0.077: sagitta ≈ 7.5e-4) of the unit sphere.
    for p in &m.positions {
        assert!((p.length() - 1.0).abs() < 2e-3, "{p:?}");
    }
}

#[test]
fn cylinder_keeps_both_boundary_loops() {
    let mesh = cylinder(1.0, 2.0, 32, 10);
    let (_, q) = quads(&mesh, &uniform(60));
    let m = &q.mesh;
    println!("cylinder: V {}, report {:?}", m.vertex_count(), q.report);
    assert_pure_quads(m);
    assert_eq!(m.boundary_loops().len(), 2);
    assert_eq!(m.euler_characteristic(), 0);
    // Boundary vertices lie on the rims (z = ±1).
    for v in 0..m.vertex_count() as u32 {
        if m.is_boundary_vertex(v) {
            assert!((m.positions[v as usize].z.abs() - 1.0).abs() < 1e-9);
        }
    }
}

#[test]
fn clean_shared_meshes_give_closed_pure_quads_of_their_genus() {
    for (name, chi) in [("fandisk", 2), ("rocker-arm", 0), ("spot", 2)] {
        let mesh = common::mesh(&format!("{name}.obj"));
        let target = mesh.positions.len() / 16;
        let mut params = Params::default();
        params.sizing.target_vertex_count = Some(target);
        let (_, q) = quads(&mesh, &params);
        let m = &q.mesh;
        println!(
            "{name}: V {} for {target}, report {:?}",
            m.vertex_count(),
            q.report
        );
        assert_pure_quads(m);
        assert!(m.boundary_loops().is_empty(), "{name}");
        assert_eq!(m.euler_characteristic(), chi, "{name}");
        assert_eq!(q.report.euler_characteristic, [chi, chi], "{name}");
        assert_eq!(q.report.holes_left_open, 0, "{name}");
        let v = m.vertex_count() as f64;
        assert!(
            (v / target as f64 - 1.0).abs() <= 0.1,
            "{name}: {v} for {target}"
        );
    }
}

#[test]
fn messy_shared_meshes_give_a_valid_mesh_or_a_clear_error() {
    for name in ["cow", "suzanne", "beetle", "teapot"] {
        let mesh = common::mesh(&format!("{name}.obj"));
        let mut params = Params::default();
        params.sizing.target_vertex_count = Some(mesh.positions.len() / 16);
        let run = param::run(&mesh, &params, &|| 0.0).expect("a map");
        match quadrille::progress::silently("qex", |p| qex::extract(&mesh, &run.map, p)) {
            Ok(q) => {
                q.mesh.validate().expect("valid");
                assert!((0..q.mesh.face_count() as u32).all(|f| q.mesh.degree(f) == 4));
                println!(
                    "{name}: V {} χ {} report {:?}",
                    q.mesh.vertex_count(),
                    q.mesh.euler_characteristic(),
                    q.report
                );
            }
            Err(e) => {
                let text = e.to_string();
                println!("{name}: {text}");
                assert!(!text.is_empty());
            }
        }
    }
}

/// Ebke Fig. 9: an accordion of pleats finer than the target edge adds no
/// quad loops with filtered normals — the crosses projected from the
/// filtered (flat) normal field measure the pleats by their flat width —
/// while without the filter every pleat's slope lengthens the grid.
#[test]
fn pleats_below_the_target_edge_add_no_quad_loops() {
    use quadrille::mesh::generate::height_field;
    // Zig-zag pleats of wavelength 0.1 and slope 3 across x (arc length
    // 3.2 times the width), target edge 0.4.
    let pleat = |x: f64, _y: f64| {
        let t = (x / 0.1).rem_euclid(1.0);
        0.15 * if t < 0.5 { t } else { 1.0 - t }
    };
    let flat = flat_grid(1.0, 120);
    let pleated = height_field(1.0, 120, pleat);
    let count = |mesh: &TriMesh, filtered: bool| {
        let mut p = Params::default();
        p.sizing.method = EdgeLengthMethod::Uniform;
        p.sizing.edge_length = Some(0.4);
        p.sizing.target_vertex_count = None;
        p.filtered_normals = filtered;
        quads(mesh, &p).1.mesh.vertex_count()
    };
    let (v_flat, v_filtered, v_unfiltered) = (
        count(&flat, true),
        count(&pleated, true),
        count(&pleated, false),
    );
    println!("pleats: flat {v_flat}, pleated {v_filtered} filtered, {v_unfiltered} unfiltered");
    assert!(
        (v_filtered as f64) <= 1.15 * v_flat as f64,
        "{v_filtered} vertices against {v_flat} on the flat square"
    );
    assert!(v_unfiltered as f64 > 1.5 * v_flat as f64, "{v_unfiltered}");
}

/// The bunny's holes: the map collapses the smaller ones (their rims lie
/// on isolines of both coordinates), and the holes extraction leaves
/// around them are the input's holes, not gaps to close with quads.
#[test]
fn the_bunny_keeps_its_holes_open() {
    let mesh = common::mesh("stanford-bunny.obj");
    let mut params = Params::default();
    params.sizing.target_vertex_count = Some(mesh.positions.len() / 16);
    let (_, q) = quads(&mesh, &params);
    let m = &q.mesh;
    println!(
        "bunny: V {}, loops {}, report {:?}",
        m.vertex_count(),
        m.boundary_loops().len(),
        q.report
    );
    assert_pure_quads(m);
    assert_eq!(q.report.holes_filled, 0, "no quads over the input's holes");
    assert!(
        m.boundary_loops().len() >= 3,
        "{} loops",
        m.boundary_loops().len()
    );
}
