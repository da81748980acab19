//! The field stage against independent truth: Poincaré–Hopf on closed
//! surfaces, lattice spacing on a plane against the prescribed sizing,
//! determinism.

mod common;

use glam::Vec3;
use quadrille::analysis::areas::barycentric_cell_areas;
use quadrille::analysis::normals::{NormalWeighting, vertex_normals};
use quadrille::field::{
    FieldParams, Hierarchy, Level, OrientationConstraints, mesh_links, orientation_singularities,
    position_singularities, restrict_by_area, solve_orientation, solve_position,
};
use quadrille::mesh::{TriMesh, generate};
use quadrille::progress::silently;

struct Fields {
    hierarchy: Hierarchy,
    q: Vec<Vec3>,
    o: Vec<Vec3>,
    scale: Vec<f32>,
}

fn level0(mesh: &TriMesh) -> Hierarchy {
    let normals: Vec<Vec3> = vertex_normals(mesh, NormalWeighting::Angle)
        .iter()
        .map(|n| n.as_vec3())
        .collect();
    let areas: Vec<f32> = barycentric_cell_areas(mesh)
        .iter()
        .map(|&a| a as f32)
        .collect();
    let positions: Vec<Vec3> = mesh.positions.iter().map(|p| p.as_vec3()).collect();
    let links = mesh_links(mesh.vertex_count(), &mesh.triangles);
    silently("hierarchy", |p| {
        Hierarchy::build(positions, normals, areas, links, 0, p)
    })
    .unwrap()
}

fn solve(
    mesh: &TriMesh,
    scale: Vec<f32>,
    constraints: Option<OrientationConstraints>,
    params: &FieldParams,
) -> Fields {
    let hierarchy = level0(mesh);
    let cons = constraints.unwrap_or_else(|| OrientationConstraints::none(mesh.vertex_count()));
    let q = silently("orientation", |p| {
        solve_orientation(
            &hierarchy,
            &cons,
            params.orientation_iterations,
            params.seed,
            p,
        )
    })
    .unwrap();
    let scales = restrict_by_area(&hierarchy, &scale);
    let o = silently("position", |p| {
        solve_position(
            &hierarchy,
            &q,
            &scales,
            params.scale_mode,
            params.position_iterations,
            params.seed,
            None,
            p,
        )
    })
    .unwrap();
    Fields {
        q: q[0].clone(),
        o,
        scale,
        hierarchy,
    }
}

fn level(f: &Fields) -> &Level {
    &f.hierarchy.levels[0]
}

/// Σ index over singularities, in quarter turns: 4χ by Poincaré–Hopf.
fn index_sum(mesh: &TriMesh, f: &Fields) -> i32 {
    orientation_singularities(level(f), &f.q, &mesh.triangles)
        .iter()
        .map(|s| s.index)
        .sum()
}

#[test]
fn singularity_indices_sum_to_the_euler_characteristic() {
    let params = FieldParams::default();
    for (name, mesh, chi) in [
        ("sphere", generate::icosphere(1.0, 4), 2),
        ("torus", generate::torus(1.0, 0.35, 96, 36), 0),
        ("rocker-arm", common::mesh("rocker-arm.obj"), 0),
        ("fandisk", common::mesh("fandisk.obj"), 2),
    ] {
        let s = 0.08 * mesh.bbox().unwrap().largest_axis() as f32;
        let f = solve(&mesh, vec![s; mesh.vertex_count()], None, &params);
        let sum = index_sum(&mesh, &f);
        let count = orientation_singularities(level(&f), &f.q, &mesh.triangles).len();
        let position =
            position_singularities(level(&f), &f.q, &f.scale, &f.o, &mesh.triangles).len();
        println!(
            "{name}: {count} orientation singularities, index sum {sum}/4, {position} position singularities"
        );
        assert_eq!(sum, 4 * chi, "{name}");
        // The lattice closes up almost everywhere.
        assert!(
            position * 100 < 3 * mesh.face_count(),
            "{name}: {position} position singularities"
        );
    }
}

#[test]
fn a_plane_with_constant_sizing_gets_a_regular_lattice() {
    let mesh = generate::flat_grid(1.0, 60);
    let s = 0.1f32;
    let f = solve(
        &mesh,
        vec![s; mesh.vertex_count()],
        None,
        &FieldParams::default(),
    );
    assert!(orientation_singularities(level(&f), &f.q, &mesh.triangles).is_empty());
    // The orientation field is constant up to its symmetry (within what a
    // fixed number of Gauss–Seidel sweeps converges to).
    // Deviation from the field's 4-RoSy mean direction (mean of e^{4iθ}).
    let angle = |q: &Vec3| q.y.atan2(q.x);
    let (c, s4) = f.q.iter().fold((0.0f32, 0.0f32), |(c, s), q| {
        (c + (4.0 * angle(q)).cos(), s + (4.0 * angle(q)).sin())
    });
    let mean_angle = s4.atan2(c) / 4.0;
    let deviation: Vec<f32> =
        f.q.iter()
            .map(|q| {
                let d = (angle(q) - mean_angle).rem_euclid(std::f32::consts::FRAC_PI_2);
                d.min(std::f32::consts::FRAC_PI_2 - d).to_degrees()
            })
            .collect();
    let max = deviation.iter().cloned().fold(0.0, f32::max);
    let mean = deviation.iter().sum::<f32>() / deviation.len() as f32;
    println!("plane: cross deviation mean {mean:.3}°, max {max:.3}°");
    assert!(
        max < 5.0 && mean < 1.0,
        "cross deviation mean {mean}°, max {max}°"
    );
    // Neighbouring lattice points (integer offset of one step) are s apart.
    let spacing = unit_step_lengths(&f, |_| true);
    let mean = spacing.iter().sum::<f32>() / spacing.len() as f32;
    assert!(spacing.len() > 1000);
    assert!(
        (mean / s - 1.0).abs() < 0.05,
        "mean spacing {mean} for s = {s}"
    );
    assert!(
        position_singularities(level(&f), &f.q, &f.scale, &f.o, &mesh.triangles).len()
            < mesh.face_count() / 50
    );
}

/// Distances between the origins of linked vertices whose lattices differ
/// by exactly one step along one axis.
fn unit_step_lengths(f: &Fields, keep: impl Fn(Vec3) -> bool) -> Vec<f32> {
    use quadrille::field::lattice::{
        Lattice, compat_orientation_extrinsic_4, compat_position_extrinsic_4,
    };
    let l = level(f);
    let mut out = Vec::new();
    for i in 0..l.len() {
        for (j, _) in l.links.of(i) {
            if j <= i || !keep(l.positions[i]) {
                continue;
            }
            let (qi, qj) =
                compat_orientation_extrinsic_4(f.q[i], l.normals[i], f.q[j], l.normals[j]);
            let li = Lattice {
                p: l.positions[i],
                n: l.normals[i],
                q: qi,
                o: f.o[i],
                s: f.scale[i],
            };
            let lj = Lattice {
                p: l.positions[j],
                n: l.normals[j],
                q: qj,
                o: f.o[j],
                s: f.scale[j],
            };
            let m = compat_position_extrinsic_4(&li, &lj);
            let d = (m.u0 - m.u1).abs();
            if d.x + d.y == 1 {
                // The two canonical origins are one lattice step apart.
                out.push(f.o[j].distance(f.o[i]));
            }
        }
    }
    out
}

#[test]
fn same_seed_gives_bit_identical_fields() {
    let mesh = generate::icosphere(1.0, 3);
    let scale = vec![0.15; mesh.vertex_count()];
    let a = solve(&mesh, scale.clone(), None, &FieldParams::default());
    let b = solve(&mesh, scale.clone(), None, &FieldParams::default());
    assert_eq!(a.q, b.q);
    assert_eq!(a.o, b.o);
    let c = solve(
        &mesh,
        scale,
        None,
        &FieldParams {
            seed: 1,
            ..FieldParams::default()
        },
    );
    assert_ne!(a.q, c.q, "the seed matters");
}

#[test]
fn sizing_that_halves_left_to_right_is_followed_by_the_lattice() {
    let mesh = generate::flat_grid(1.0, 100);
    let sizing = |x: f32| 0.12 * 0.5f32.powf((x + 1.0) / 2.0);
    let scale: Vec<f32> = mesh.positions.iter().map(|p| sizing(p.x as f32)).collect();
    let f = solve(&mesh, scale, None, &FieldParams::default());
    // Compare measured spacing with the sizing field in five vertical bands.
    for band in 0..5 {
        let (lo, hi) = (-1.0 + 0.4 * band as f32, -0.6 + 0.4 * band as f32);
        let inner = |p: Vec3| p.x >= lo && p.x < hi && p.y.abs() < 0.8 && p.x.abs() < 0.9;
        let spacing = unit_step_lengths(&f, inner);
        let mean = spacing.iter().sum::<f32>() / spacing.len() as f32;
        let expected = sizing(0.5 * (lo + hi));
        println!(
            "band {band}: spacing {mean:.4} expected {expected:.4} ({} steps)",
            spacing.len()
        );
        assert!(spacing.len() > 50, "band {band}");
        assert!(
            (mean / expected - 1.0).abs() < 0.15,
            "band {band}: spacing {mean} vs sizing {expected}"
        );
    }
}

#[test]
fn a_box_gets_its_eight_valence_three_singularities_at_the_corners() {
    // A sphere pushed onto the cube [-1, 1]³: sharp edges and corners.
    let mut mesh = generate::icosphere(1.0, 5);
    mesh.map_positions(|p| p / p.abs().max_element());
    let f = solve(
        &mesh,
        vec![0.15; mesh.vertex_count()],
        None,
        &FieldParams::default(),
    );
    let singular = orientation_singularities(level(&f), &f.q, &mesh.triangles);
    let valence3: Vec<_> = singular.iter().filter(|s| s.valence() == Some(3)).collect();
    println!(
        "box: {} singularities, {} of valence 3",
        singular.len(),
        valence3.len()
    );
    assert_eq!(singular.iter().map(|s| s.index).sum::<i32>(), 8);
    let mut corners_hit = [false; 8];
    for s in &valence3 {
        let p = s.position;
        let corner = Vec3::new(p.x.signum(), p.y.signum(), p.z.signum());
        let k = ((corner.x > 0.0) as usize)
            | (((corner.y > 0.0) as usize) << 1)
            | (((corner.z > 0.0) as usize) << 2);
        if p.distance(corner) < 0.2 {
            corners_hit[k] = true;
        }
    }
    assert!(
        corners_hit.iter().all(|&h| h),
        "valence-3 singularities at corners: {corners_hit:?}"
    );
}
