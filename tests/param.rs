//! The integer-grid map (src/param): checked against analytic surfaces and
//! invariants — Poincaré–Hopf (Σ cone index = χ), exact grids on developable
//! surfaces, integer seam transitions, and Ebke §3's claim that filtered
//! normals remove cones caused by detail below the target edge.

use quadrille::mesh::TriMesh;
use quadrille::mesh::generate::{cylinder, flat_grid, icosphere, torus};
use quadrille::param::{self, Params};
use quadrille::sizing::EdgeLengthMethod;

fn uniform(vertices: usize) -> Params {
    let mut p = Params::default();
    p.sizing.method = EdgeLengthMethod::Uniform;
    p.sizing.target_vertex_count = Some(vertices);
    p
}

fn field(mesh: &TriMesh, params: &Params) -> param::CrossField {
    let prepared = param::prepare(mesh, params);
    param::cross_field_of(mesh, &prepared, params).expect("a cross field")
}

/// A sphere with bumps far below the target edge: r = 1 + 0.1·sin(18x)sin(18y)sin(18z)
/// (wavelength 0.35 against a target edge of 0.46 at 60 vertices).
fn bumpy_sphere() -> TriMesh {
    let mut m = icosphere(1.0, 5);
    m.map_positions(|p| {
        let b = (18.0 * p.x).sin() * (18.0 * p.y).sin() * (18.0 * p.z).sin();
        p * (1.0 + 0.1 * b)
    });
    m
}

#[test]
fn sphere_cones_sum_to_two_and_are_eight_quarters() {
    let mesh = icosphere(1.0, 4);
    let f = field(&mesh, &uniform(200));
    let quarters: Vec<i32> = f.cones.iter().map(|c| c.quarters).collect();
    println!(
        "sphere: cones {quarters:?}, E_smooth {:.4}, index residual {:.2e}",
        f.energy, f.index_residual
    );
    assert!(f.index_residual < 1e-6);
    for c in &f.cones {
        println!(
            "  cone {} at {:?}",
            c.quarters, mesh.positions[c.vertex as usize]
        );
    }
    assert_eq!(quarters.iter().sum::<i32>(), 8, "Σ index = χ = 2");
    assert_eq!(quarters, vec![1; 8]);
}

#[test]
fn torus_flat_square_and_cylinder_have_no_cones() {
    for (name, mesh) in [
        ("torus", torus(2.0, 0.7, 60, 24)),
        ("square", flat_grid(1.0, 12)),
        ("cylinder", cylinder(1.0, 2.0, 32, 10)),
    ] {
        let f = field(&mesh, &uniform(100));
        println!(
            "{name}: {} cones, E_smooth {:.3e}, residual {:.2e}",
            f.cones.len(),
            f.energy,
            f.index_residual
        );
        assert!(f.index_residual < 1e-6);
        assert!(f.cones.is_empty(), "{name}: {:?}", f.cones);
    }
}

#[test]
fn bumpy_sphere_has_five_times_fewer_cones_with_filtered_normals() {
    let mesh = bumpy_sphere();
    let mut params = uniform(60);
    let filtered = field(&mesh, &params);
    params.filtered_normals = false;
    let raw = field(&mesh, &params);
    let sum = |f: &param::CrossField| f.cones.iter().map(|c| c.quarters).sum::<i32>();
    println!(
        "bumpy sphere: {} cones filtered (Σ {}), {} without (Σ {})",
        filtered.cones.len(),
        sum(&filtered),
        raw.cones.len(),
        sum(&raw)
    );
    assert_eq!(sum(&filtered), 8);
    assert_eq!(sum(&raw), 8);
    assert!(raw.cones.len() >= 5 * filtered.cones.len().max(1));
}
