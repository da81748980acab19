//! Catmull–Clark subdivision, limit stencils and control-mesh fitting
//! (Kloiber 2018 §3.8), checked against independent references: repeated
//! subdivision for limit positions, the uniform bicubic B-spline on a
//! regular grid, a sphere, and real meshes from ../shared/meshes with
//! both Instant Meshes quad-dominant meshes (tests/fixtures/subdivision,
//! made by make_im_quads.py: the same fitting applied to another
//! remesher's output) and our own pipeline's extraction.

mod common;

use std::path::Path;
use std::time::Instant;

use glam::DVec3;
use quadrille::mesh::{FaceList, PolyMesh, generate};
use quadrille::pipeline::{Params, Pipeline};
use quadrille::progress::{Cancelled, Progress, silently};
use quadrille::subdivision::{
    BoundaryRule, FitParams, FitResult, FitSplit, fit_control_mesh, limit_mesh, limit_mesh_creased,
    limit_normals, limit_positions, poly_mesh_in_frame, subdivide,
};

fn unit_cube() -> PolyMesh {
    let (p, faces) = quadrille::mesh::generate::unit_cube_quads();
    PolyMesh::from_faces(p, &faces).unwrap()
}

/// The surface of the cube [-1, 1]³ with an `n × n` grid of quads on each
/// side, outward oriented; with `sphere`, every vertex projected onto the
/// unit sphere.
fn cube_grid(n: i32, sphere: bool) -> PolyMesh {
    let mut index = std::collections::HashMap::new();
    let mut positions = Vec::new();
    let mut id = |c: [i32; 3], positions: &mut Vec<DVec3>| -> u32 {
        *index.entry(c).or_insert_with(|| {
            let p = DVec3::new(c[0] as f64, c[1] as f64, c[2] as f64) * (2.0 / n as f64) - 1.0;
            positions.push(if sphere { p.normalize() } else { p });
            (positions.len() - 1) as u32
        })
    };
    let mut faces = FaceList::new();
    // (axis, side, u axis, v axis) with u × v pointing out.
    for (a, side, u, v) in [
        (0, n, 1, 2),
        (0, 0, 2, 1),
        (1, n, 2, 0),
        (1, 0, 0, 2),
        (2, n, 0, 1),
        (2, 0, 1, 0),
    ] {
        for j in 0..n {
            for i in 0..n {
                let corner = |di: i32, dj: i32| {
                    let mut c = [0; 3];
                    c[a] = side;
                    c[u] = i + di;
                    c[v] = j + dj;
                    c
                };
                let q = [
                    id(corner(0, 0), &mut positions),
                    id(corner(1, 0), &mut positions),
                    id(corner(1, 1), &mut positions),
                    id(corner(0, 1), &mut positions),
                ];
                faces.push(&q);
            }
        }
    }
    PolyMesh::from_faces(positions, &faces).unwrap()
}

/// A regular `n × n` quad grid in the plane with heights `z(i, j)`, faces
/// counter-clockwise seen from +z.
fn height_grid(n: usize, z: impl Fn(usize, usize) -> f64) -> PolyMesh {
    let mut p = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            p.push(DVec3::new(i as f64, j as f64, z(i, j)));
        }
    }
    let id = |i: usize, j: usize| (j * (n + 1) + i) as u32;
    let mut faces = FaceList::new();
    for j in 0..n {
        for i in 0..n {
            faces.push(&[id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    PolyMesh::from_faces(p, &faces).unwrap()
}

/// A deterministic pseudo-random value in [-0.5, 0.5).
fn noise(i: usize, j: usize) -> f64 {
    let mut x = (i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)
        ^ (j as u64).wrapping_mul(0xC2B2_AE3D_27D4_EB4F);
    x ^= x >> 31;
    x = x.wrapping_mul(0xBF58_476D_1CE4_E5B9);
    x ^= x >> 29;
    (x >> 11) as f64 / (1u64 << 53) as f64 - 0.5
}

#[test]
fn subdivision_keeps_topology_and_makes_quads() {
    let cube = unit_cube();
    let mut m = cube.clone();
    for level in 1..=3 {
        m = subdivide(&m, BoundaryRule::Fixed);
        m.validate().unwrap();
        assert_eq!(m.face_count(), 6 * 4usize.pow(level));
        assert_eq!(m.euler_characteristic(), 2);
        assert!((0..m.face_count() as u32).all(|f| m.degree(f) == 4));
    }
    // A mesh with a triangle and a pentagon: one step gives d quads per face.
    let p = vec![
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(1.0, 0.0, 0.0),
        DVec3::new(2.0, 0.0, 0.0),
        DVec3::new(2.0, 1.0, 0.0),
        DVec3::new(1.0, 1.0, 0.0),
        DVec3::new(0.0, 1.0, 0.0),
        DVec3::new(1.0, 2.0, 0.0),
    ];
    let mut faces = FaceList::new();
    faces.push(&[0, 1, 4, 5]);
    faces.push(&[1, 2, 3, 4]);
    faces.push(&[5, 4, 6]);
    let mixed = PolyMesh::from_faces(p, &faces).unwrap();
    for rule in [BoundaryRule::Fixed, BoundaryRule::Crease] {
        let s = subdivide(&mixed, rule);
        s.validate().unwrap();
        assert_eq!(s.face_count(), 4 + 4 + 3);
        assert_eq!(s.euler_characteristic(), mixed.euler_characteristic());
        assert_eq!(s.boundary_loops().len(), 1);
    }
    // Fixed boundary: boundary vertices do not move; crease: a straight
    // boundary stays straight and the corner-free boundary is a B-spline.
    let grid = height_grid(4, noise);
    let fixed = subdivide(&grid, BoundaryRule::Fixed);
    let crease = subdivide(&grid, BoundaryRule::Crease);
    for v in 0..grid.vertex_count() as u32 {
        if grid.is_boundary_vertex(v) {
            assert_eq!(fixed.positions[v as usize], grid.positions[v as usize]);
        }
    }
    // Vertex (2, 0) on the bottom edge: crease point (p₋ + 6p + p₊)/8.
    let g = &grid.positions;
    let expected = (g[1] + 6.0 * g[2] + g[3]) / 8.0;
    assert!((crease.positions[2] - expected).length() < 1e-12);
}

#[test]
fn cube_limit_positions_match_six_levels_of_subdivision() {
    let cube = unit_cube();
    let limit = limit_positions(&cube, BoundaryRule::Fixed);
    let mut m = cube.clone();
    for _ in 0..6 {
        m = subdivide(&m, BoundaryRule::Fixed);
        m.validate().unwrap();
    }
    // Control vertices keep their indices through subdivision.
    let fine_limit = limit_positions(&m, BoundaryRule::Fixed);
    for v in 0..8 {
        let d = (m.positions[v] - limit[v]).length();
        assert!(
            d < 1e-3,
            "vertex {v}: level 6 is {d} from the stencil's limit"
        );
        // The limit is invariant under subdivision.
        assert!((fine_limit[v] - limit[v]).length() < 1e-12);
    }
    // Valence 3 corner of the unit cube: by symmetry on the diagonal; the
    // stencil (9v + 4Σe + Σg)/24 gives (4·(1,1,1) + (2,2,2))/24 = 1/4.
    let expected = DVec3::splat(0.25);
    assert!((limit[0] - expected).length() < 1e-12, "{}", limit[0]);
    // Limit normals at the corners point along the diagonals, outwards.
    let normals = limit_normals(&cube);
    for v in 0..8 {
        let out = (cube.positions[v] - DVec3::splat(0.5)).normalize();
        assert!(normals[v].dot(out) > 1.0 - 1e-12, "{v}: {}", normals[v]);
    }
    // And at level 6 the normals at the control vertices agree with the
    // normals of the fine limit mesh's faces around them.
    let fine_normals = limit_normals(&m);
    for v in 0..8 {
        assert!(fine_normals[v].dot(normals[v]) > 1.0 - 1e-9);
    }
}

#[test]
fn limit_of_a_vertex_next_to_non_quads_equals_its_limit_after_one_step() {
    // A closed mesh with triangles and pentagons: a pentagonal prism with a
    // cone on top (triangles) and a flat pentagon at the bottom.
    let mut p = Vec::new();
    for k in 0..5 {
        let a = std::f64::consts::TAU * k as f64 / 5.0;
        p.push(DVec3::new(a.cos(), a.sin(), 0.0));
    }
    for k in 0..5 {
        let a = std::f64::consts::TAU * k as f64 / 5.0;
        p.push(DVec3::new(a.cos(), a.sin(), 1.0));
    }
    p.push(DVec3::new(0.0, 0.0, 1.7));
    let mut faces = FaceList::new();
    faces.push(&[4, 3, 2, 1, 0]);
    for k in 0..5u32 {
        let k1 = (k + 1) % 5;
        faces.push(&[k, k1, 5 + k1, 5 + k]);
        faces.push(&[5 + k, 5 + k1, 10]);
    }
    let mesh = PolyMesh::from_faces(p, &faces).unwrap();
    mesh.validate().unwrap();
    let direct = limit_positions(&mesh, BoundaryRule::Fixed);
    let once = subdivide(&mesh, BoundaryRule::Fixed);
    let after_one = limit_positions(&once, BoundaryRule::Fixed);
    let mut twice = once.clone();
    for _ in 0..6 {
        twice = subdivide(&twice, BoundaryRule::Fixed);
    }
    for v in 0..mesh.vertex_count() {
        assert!((direct[v] - after_one[v]).length() < 1e-12);
        assert!((direct[v] - twice.positions[v]).length() < 2e-3);
    }
    let normals = limit_normals(&mesh);
    let centre = DVec3::new(0.0, 0.0, 0.8);
    for v in 0..mesh.vertex_count() {
        assert!(
            normals[v].dot(direct[v] - centre) > 0.0,
            "normal {v} points in"
        );
    }
}

#[test]
fn regular_grid_limit_is_the_uniform_bicubic_b_spline() {
    let n = 6;
    let z = |i: usize, j: usize| noise(i, j) + 0.1 * (i * j) as f64;
    let grid = height_grid(n, z);
    let limit = limit_positions(&grid, BoundaryRule::Fixed);
    let normals = limit_normals(&grid);
    let w = [1.0 / 6.0, 4.0 / 6.0, 1.0 / 6.0];
    let dw = [-0.5, 0.0, 0.5];
    for j in 1..n {
        for i in 1..n {
            let (mut s, mut du, mut dv) = (DVec3::ZERO, DVec3::ZERO, DVec3::ZERO);
            for b in 0..3 {
                for a in 0..3 {
                    let q = grid.positions[(j + b - 1) * (n + 1) + i + a - 1];
                    s += w[a] * w[b] * q;
                    du += dw[a] * w[b] * q;
                    dv += w[a] * dw[b] * q;
                }
            }
            let v = j * (n + 1) + i;
            assert!((limit[v] - s).length() < 1e-12, "({i}, {j})");
            let bspline_normal = du.cross(dv).normalize();
            assert!(
                normals[v].dot(bspline_normal) > 1.0 - 1e-12,
                "({i}, {j}): {} vs {}",
                normals[v],
                bspline_normal
            );
        }
    }
}

fn fit(quads: &PolyMesh, reference: &quadrille::mesh::TriMesh) -> (FitResult, f64) {
    let t = Instant::now();
    let r = silently("fit", |p| {
        fit_control_mesh(quads, reference, &FitParams::default(), p)
    })
    .unwrap();
    r.control.validate().unwrap();
    (r, t.elapsed().as_secs_f64())
}

#[test]
fn fitting_to_a_sphere_brings_the_limit_surface_onto_it() {
    let sphere = generate::icosphere(1.0, 5);
    let quads = cube_grid(4, true);
    let (r, secs) = fit(&quads, &sphere);
    let s = &r.summary;
    eprintln!(
        "sphere: before mean {:.2e} max {:.2e}, after mean {:.2e} max {:.2e}, {} iterations, moves {:?}, {}/{} rays missed, {secs:.2}s",
        s.before.stats.mean,
        s.before.hausdorff,
        s.after.stats.mean,
        s.after.hausdorff,
        s.iterations,
        s.max_move,
        s.rays_missed,
        s.rays_cast
    );
    assert!(s.after.stats.mean < 1e-3, "{}", s.after.stats.mean);
    assert!(s.before.stats.mean > 5.0 * s.after.stats.mean);
    assert!(s.converged && s.iterations <= 20);
    assert_eq!(s.rays_missed, 0);
    // The limit mesh's per-vertex errors belong to its vertices and agree
    // with the radius (the icosphere's chords are within ~2e-4 of it).
    assert_eq!(r.after.per_vertex_signed.len(), r.limit.vertex_count());
    for (p, d) in r.limit.positions.iter().zip(&r.after.per_vertex_signed) {
        assert!((p.length() - 1.0 - d).abs() < 5e-4);
    }
}

/// `fit.split`: a pure-quad mesh is fitted as it is with `non-quads` (its
/// vertices are the control vertices, a quarter of the split's), split
/// with `always` and `auto` (the default of a mesh fitted on its own); a
/// mesh with a triangle is split with `non-quads` too.
#[test]
fn a_pure_quad_mesh_is_fitted_without_the_split_when_asked() {
    let sphere = generate::icosphere(1.0, 4);
    let quads = cube_grid(6, true);
    let with = |mesh: &PolyMesh, split: FitSplit| {
        let params = FitParams {
            split,
            measure_before: false,
            ..FitParams::default()
        };
        silently("fit", |p| fit_control_mesh(mesh, &sphere, &params, p)).unwrap()
    };
    let (v, e, f) = (quads.vertex_count(), quads.edge_count(), quads.face_count());
    let direct = with(&quads, FitSplit::NonQuads);
    eprintln!(
        "cube grid on the sphere, fitted as it is: {} control vertices, limit mean {:.2e}",
        direct.summary.control_vertices, direct.summary.after.stats.mean
    );
    assert!(!direct.summary.split);
    assert_eq!(direct.summary.control_vertices, v);
    assert_eq!(direct.control.face_count(), f);
    direct.control.validate().unwrap();
    // Fitted as it is, the 218-vertex cage still brings its limit onto the
    // sphere (measured: mean 1.9e-4).
    assert!(
        direct.summary.after.stats.mean < 2e-3,
        "{}",
        direct.summary.after.stats.mean
    );
    for split in [FitSplit::Always, FitSplit::Auto] {
        let r = with(&quads, split);
        assert!(r.summary.split, "{split:?}");
        assert_eq!(r.summary.control_vertices, v + e + f, "{split:?}");
    }
    // One quad cut into two triangles: not pure quads, so split anyway.
    let mut faces: Vec<Vec<u32>> = quads.to_face_list().iter().map(|f| f.to_vec()).collect();
    let q = faces.pop().unwrap();
    faces.push(vec![q[0], q[1], q[2]]);
    faces.push(vec![q[0], q[2], q[3]]);
    let mut list = FaceList::new();
    for f in &faces {
        list.push(f);
    }
    let mixed = PolyMesh::from_faces(quads.positions.clone(), &list).unwrap();
    let r = with(&mixed, FitSplit::NonQuads);
    assert!(r.summary.split);
    assert_eq!(
        r.summary.control_vertices,
        mixed.vertex_count() + mixed.edge_count() + mixed.face_count()
    );
}

/// Distance of `p` from the surface of the cube [0, 1]³ (for points inside
/// or on it).
fn off_unit_cube(p: DVec3) -> f64 {
    let inside = p.min(DVec3::ONE - p).min_element();
    inside.abs()
}

#[test]
fn an_all_sharp_cube_is_its_own_limit_surface() {
    // Every edge an infinitely sharp crease, every vertex a corner (three
    // creases): faces stay planar, creases straight, corners fixed (Hoppe
    // et al. 1994), so the limit surface is the cube itself.
    let cube = unit_cube();
    let sharp = vec![true; cube.edge_count()];
    let limit = limit_mesh_creased(&cube, &sharp, 3, BoundaryRule::Fixed);
    let worst = limit
        .positions
        .iter()
        .map(|&p| off_unit_cube(p))
        .fold(0.0, f64::max);
    assert!(worst < 1e-12, "{worst}");
    for v in 0..8 {
        assert!(limit.positions[v].distance(cube.positions[v]) < 1e-12);
    }
    // An edge's points lie on the edge, and they cover it (B-spline of a
    // straight control polygon: uniform spacing).
    let on_edge = limit
        .positions
        .iter()
        .filter(|p| {
            let c = [p.x, p.y, p.z];
            c.iter()
                .filter(|&&x| x.abs() < 1e-12 || (x - 1.0).abs() < 1e-12)
                .count()
                >= 2
        })
        .count();
    assert_eq!(on_edge, 8 + 12 * 7);
    // Without creases the corners are rounded off.
    let smooth = limit_mesh(&cube, 3, BoundaryRule::Fixed);
    assert!(smooth.positions[0].distance(DVec3::ZERO) > 0.2);
    // Only the four edges of one face sharp: each of its corners is on two
    // creases, and the crease loop is the closed cubic B-spline of the
    // square, whose limit at a control point is (a + 4v + b) / 6.
    let mut one_face = vec![false; cube.edge_count()];
    for h in cube.face_halfedges(0) {
        one_face[h as usize / 2] = true;
    }
    let limit = limit_mesh_creased(&cube, &one_face, 3, BoundaryRule::Fixed);
    let square: Vec<u32> = cube.face_vertices(0).collect();
    for (i, &v) in square.iter().enumerate() {
        let p = |k: usize| cube.positions[square[k % 4] as usize];
        let expected = (p(i + 3) + 4.0 * p(i) + p(i + 1)) / 6.0;
        assert!(limit.positions[v as usize].distance(expected) < 1e-12);
    }
}

#[test]
fn fitting_makes_creases_along_fandisks_sharp_edges_and_none_on_a_sphere() {
    // fandisk: 97 % of the smooth fit's limit error lies within an edge of
    // its sharp edges; with creases along them the error falls well below
    // half (measured: 7.2e-4 -> 2.0e-4 at the default target).
    let (reference, quads) = reference_and_extracted("fandisk");
    let with = |crease_degrees: f64| {
        let params = FitParams {
            crease_degrees,
            measure_before: false,
            ..FitParams::default()
        };
        silently("fit", |p| {
            fit_control_mesh(&quads, &reference.mesh, &params, p)
        })
        .unwrap()
    };
    let (creased, smooth) = (with(40.0), with(0.0));
    let (c, s) = (&creased.summary, &smooth.summary);
    eprintln!(
        "fandisk: {} crease edges; limit mean {:.3e} -> {:.3e}, Hausdorff {:.3e} -> {:.3e}",
        c.crease_edges,
        s.after.stats.mean,
        c.after.stats.mean,
        s.after.hausdorff,
        c.after.hausdorff
    );
    assert_eq!(s.crease_edges, 0);
    assert!(c.crease_edges >= 50, "{}", c.crease_edges);
    assert!(c.after.stats.mean < 0.5 * s.after.stats.mean);
    assert!(c.after.reference_to_limit.mean < 0.5 * s.after.reference_to_limit.mean);
    assert_eq!(creased.sharp.len(), creased.control.edge_count());
    // The written control mesh carries its creases (OBJ `t crease` tags):
    // read back, the tagged edges' limit surface is the fit's, and
    // without the tags it is not.
    let text = quadrille::io::write_obj_with_creases(
        &creased.control.positions,
        &creased.control.to_face_list(),
        &creased.crease_vertex_pairs(),
    );
    let (_, raw) = quadrille::io::read_raw(text.as_bytes(), "control.obj").unwrap();
    // Each crease edge of the quads is two edges of the control mesh.
    assert_eq!(raw.creases.len(), 2 * c.crease_edges);
    let back = PolyMesh::from_faces(raw.positions, &raw.faces).unwrap();
    let tagged: std::collections::HashSet<[u32; 2]> = raw
        .creases
        .iter()
        .flat_map(|&([a, b], s)| {
            assert_eq!(s, 10.0);
            [[a, b], [b, a]]
        })
        .collect();
    let sharp: Vec<bool> = (0..back.edge_count() as u32)
        .map(|e| tagged.contains(&[back.origin(2 * e), back.tip(2 * e)]))
        .collect();
    let (levels, rule) = (
        FitParams::default().error_levels,
        FitParams::default().boundary,
    );
    let gap = |sharp: &[bool]| {
        let limit = limit_mesh_creased(&back, sharp, levels, rule);
        assert_eq!(limit.positions.len(), creased.limit.positions.len());
        limit
            .positions
            .iter()
            .zip(&creased.limit.positions)
            .map(|(a, b)| a.distance(*b))
            .fold(0.0, f64::max)
    };
    let (kept, lost) = (gap(&sharp), gap(&vec![false; back.edge_count()]));
    eprintln!("read-back limit: {kept:.1e} from the fit's with the tags, {lost:.1e} without");
    assert!(kept < 1e-12, "{kept}");
    assert!(lost > 1e-3, "{lost}");
    // A smooth reference has no feature curves, whatever the quads.
    let sphere = generate::icosphere(1.0, 5);
    let r = silently("fit", |p| {
        fit_control_mesh(&cube_grid(4, true), &sphere, &FitParams::default(), p)
    })
    .unwrap();
    assert_eq!(r.summary.crease_edges, 0);
    // Without creases the control mesh is written without tags (its
    // `sharp` may be empty).
    assert!(r.crease_vertex_pairs().is_empty());
    assert!(smooth.crease_vertex_pairs().is_empty());
}

#[test]
fn fitting_is_cancellable() {
    let sphere = generate::icosphere(1.0, 3);
    let quads = cube_grid(2, true);
    let mut calls = 0;
    let mut sink = |_: &str, _: f32, _: &str| {
        calls += 1;
        calls < 3
    };
    let mut progress = Progress::new(&mut sink, "fit");
    let r = fit_control_mesh(&quads, &sphere, &FitParams::default(), &mut progress);
    assert!(matches!(r, Err(Cancelled)));
}

#[test]
fn limit_mesh_lies_on_the_limit_surface() {
    // The limit mesh at level k has the same limit as the control mesh: its
    // vertices are limit points, so a further level's limit points of the
    // old vertices coincide.
    let cube = cube_grid(2, false);
    let l1 = limit_mesh(&cube, 1, BoundaryRule::Fixed);
    let s2 = subdivide(&subdivide(&cube, BoundaryRule::Fixed), BoundaryRule::Fixed);
    let l2 = limit_positions(&s2, BoundaryRule::Fixed);
    for v in 0..l1.vertex_count() {
        assert!((l1.positions[v] - l2[v]).length() < 1e-12);
    }
}

/// The reference mesh and its Instant Meshes stand-in quad-dominant mesh,
/// in the reference's import frame.
fn reference_and_quads(name: &str) -> (quadrille::io::Imported, PolyMesh) {
    let bytes = common::bytes(&format!("{name}.obj"));
    let reference = quadrille::io::import(&bytes, name).unwrap();
    let fixture = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join(format!("tests/fixtures/subdivision/{name}-im-quads.obj"));
    let bytes = std::fs::read(&fixture).unwrap();
    let (_, raw) = quadrille::io::read_raw(&bytes, "quads.obj").unwrap();
    let (quads, split) = poly_mesh_in_frame(&raw, &reference.frame).unwrap();
    eprintln!("{name}: {split} non-manifold vertices split");
    quads.validate().unwrap();
    (reference, quads)
}

/// Our own quad-dominant mesh: the pipeline up to post-processing at the
/// default parameters (default target: input vertices / 16).
fn reference_and_extracted(name: &str) -> (quadrille::io::Imported, PolyMesh) {
    let bytes = common::bytes(&format!("{name}.obj"));
    let reference = quadrille::io::import(&bytes, name).unwrap();
    let mut p = Pipeline::new(reference.clone(), Params::default());
    p.run(&mut |_, _, _| true, &mut |_, _| {}, &|| 0.0).unwrap();
    let mesh = p.postprocess.as_ref().unwrap().mesh().clone();
    mesh.validate().unwrap();
    (reference, mesh)
}

fn check_shared(name: &str, source: &str, reference: &quadrille::io::Imported, quads: &PolyMesh) {
    let name = format!("{name} ({source})");
    let (r, secs) = fit(quads, &reference.mesh);
    let s = &r.summary;
    eprintln!(
        "{name}: {} quad-dominant faces -> {} control faces; limit Hausdorff {:.2e} -> {:.2e}, mean {:.2e} -> {:.2e}, RMS {:.2e} -> {:.2e}; {} iterations (converged {}), max moves {:?}; {}/{} rays missed; max displacement {:.2e} ({:.2} local edges); {secs:.2}s",
        quads.face_count(),
        s.control_faces,
        s.before.hausdorff,
        s.after.hausdorff,
        s.before.stats.mean,
        s.after.stats.mean,
        s.before.stats.rms,
        s.after.stats.rms,
        s.iterations,
        s.converged,
        s.max_move,
        s.rays_missed,
        s.rays_cast,
        s.max_displacement,
        s.max_displacement_edges,
    );
    assert!(
        s.after.stats.mean <= 0.5 * s.before.stats.mean,
        "{name}: mean {} -> {}",
        s.before.stats.mean,
        s.after.stats.mean
    );
    // Thesis semantics: converged (largest move below 1e-4 of the largest
    // axis) within 20 iterations. The moves shrink geometrically (about
    // ×0.85 per iteration; the slowest mode of the limit stencil is the
    // checkerboard one); measured: fandisk 17 (ours) and 20 (Instant
    // Meshes' quads), bunny 18 and 14.
    assert!(
        s.converged && s.iterations <= 20,
        "{name}: {:?}",
        s.max_move
    );
    // No vertex travels far relative to its edges: each move is bounded by
    // the search length (2 local edges), and in total vertices move a few
    // edges at most (the most at sharp creases, which a smooth limit
    // surface approaches by pulling its control polygon outwards); a jump
    // across a thin part would show as a large total.
    assert!(
        s.max_displacement_edges < 6.0,
        "{name}: {}",
        s.max_displacement_edges
    );
}

#[test]
fn fitting_halves_the_limit_error_on_fandisk() {
    let (reference, quads) = reference_and_quads("fandisk");
    check_shared("fandisk", "Instant Meshes", &reference, &quads);
    let (reference, quads) = reference_and_extracted("fandisk");
    check_shared("fandisk", "extracted", &reference, &quads);
}

#[test]
fn fitting_halves_the_limit_error_on_the_bunny() {
    let (reference, quads) = reference_and_quads("stanford-bunny");
    check_shared("stanford-bunny", "Instant Meshes", &reference, &quads);
    let (reference, quads) = reference_and_extracted("stanford-bunny");
    check_shared("stanford-bunny", "extracted", &reference, &quads);
}

/// The least-squares finish (`fit.lspia_iterations`, LSPIA with hat
/// weights and momentum) after the thesis' normal offsets: on fandisk and the bunny,
/// with Instant Meshes' quads and with ours, the limit surface's mean
/// distance to the input falls by a tenth or more, the input's mean
/// distance to the limit surface falls too, and no sample strays further
/// (Hausdorff within 5 %). Measured: fandisk (Instant Meshes' quads)
/// 8.8e-4 → 5.2e-4, the bunny (ours) 2.0e-4 → 1.6e-4.
#[test]
fn the_least_squares_finish_brings_the_limit_surface_closer() {
    for name in ["fandisk", "stanford-bunny"] {
        let (reference, im) = reference_and_quads(name);
        let (_, ours) = reference_and_extracted(name);
        for (source, quads) in [("Instant Meshes", &im), ("extracted", &ours)] {
            let run = |lspia_iterations| {
                let params = FitParams {
                    lspia_iterations,
                    ..FitParams::default()
                };
                silently("fit", |p| {
                    fit_control_mesh(quads, &reference.mesh, &params, p)
                })
                .unwrap()
            };
            let (thesis, finished) = (run(0), run(10));
            finished.control.validate().unwrap();
            let (a, b) = (&thesis.summary, &finished.summary);
            eprintln!(
                "{name} ({source}): mean {:.3e} -> {:.3e}, input to limit {:.3e} -> {:.3e}, Hausdorff {:.3e} -> {:.3e}, {} steps, moves {:?}",
                a.after.stats.mean,
                b.after.stats.mean,
                a.after.reference_to_limit.mean,
                b.after.reference_to_limit.mean,
                a.after.hausdorff,
                b.after.hausdorff,
                b.lspia_iterations,
                b.lspia_max_move
            );
            assert_eq!(a.lspia_iterations, 0);
            assert!(b.lspia_iterations > 0);
            assert!(
                b.after.stats.mean < 0.9 * a.after.stats.mean,
                "{name} ({source})"
            );
            assert!(
                b.after.reference_to_limit.mean < a.after.reference_to_limit.mean,
                "{name} ({source})"
            );
            assert!(
                b.after.hausdorff < 1.05 * a.after.hausdorff,
                "{name} ({source})"
            );
        }
    }
}
