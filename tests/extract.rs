//! Extraction over the shared meshes at the default target (issue 5's
//! acceptance: non-quads ≤ 10 % on the closed and scanned inputs, closed
//! inputs give closed outputs of the same genus, the bunny keeps its five
//! holes) and on analytic surfaces.

mod common;

use quadrille::io::Imported;
use quadrille::mesh::{FaceList, PolyMesh, TriMesh, generate};
use quadrille::pipeline::{Params, Pipeline};

fn from_mesh(mesh: TriMesh) -> Imported {
    let bytes =
        quadrille::io::write_obj(&mesh.positions, &FaceList::from_triangles(&mesh.triangles));
    quadrille::io::import(bytes.as_bytes(), "generated.obj").unwrap()
}

fn remesh(input: Imported, params: Params) -> (Pipeline, PolyMesh) {
    let mut p = Pipeline::new(input, params);
    p.run(&mut |_, _, _| true, &mut |_, _| {}, &|| 0.0).unwrap();
    let mesh = p.postprocess.as_ref().unwrap().mesh().clone();
    mesh.validate().unwrap();
    (p, mesh)
}

struct Outcome {
    target: usize,
    vertices: usize,
    non_quad: f64,
    boundary_loops: usize,
    genus: Option<i64>,
    max_degree: usize,
}

fn check(name: &str) -> Outcome {
    check_with(name, Params::default())
}

fn check_with(name: &str, params: Params) -> Outcome {
    let input = common::import(name);
    let (p, mesh) = remesh(input, params);
    let t = mesh.topology();
    assert_eq!(t.nonmanifold_edges, 0, "{name}");
    assert_eq!(t.nonmanifold_vertices, 0, "{name}");
    assert_eq!(t.inconsistent_edges, 0, "{name}");
    let target = p.extraction.as_ref().unwrap().target_vertices.unwrap();
    let hist = mesh.to_face_list().degree_histogram();
    let quads = hist.get(4).copied().unwrap_or(0);
    let o = Outcome {
        target,
        vertices: mesh.vertex_count(),
        non_quad: 100.0 * (mesh.face_count() - quads) as f64 / mesh.face_count() as f64,
        boundary_loops: mesh.boundary_loops().len(),
        genus: t.genus(),
        max_degree: hist.len() - 1,
    };
    println!(
        "{name}: target {} achieved {} ({:+.1} %), non-quads {:.1} %, boundary loops {}, genus {:?}, max degree {}",
        o.target,
        o.vertices,
        100.0 * (o.vertices as f64 - o.target as f64) / o.target as f64,
        o.non_quad,
        o.boundary_loops,
        o.genus,
        o.max_degree
    );
    // Vertex count within 10 % of the target.
    let miss = (o.vertices as f64 - o.target as f64).abs() / o.target as f64;
    assert!(
        miss <= 0.10,
        "{name}: {} vs target {}",
        o.vertices,
        o.target
    );
    assert!(o.max_degree <= 8, "{name}: face of degree {}", o.max_degree);
    o
}

#[test]
fn closed_cad_and_organic_inputs_give_closed_outputs_of_the_same_genus() {
    for (name, genus) in [("fandisk.obj", 0), ("rocker-arm.obj", 1), ("spot.obj", 0)] {
        let o = check(name);
        assert_eq!(o.boundary_loops, 0, "{name}");
        assert_eq!(o.genus, Some(genus), "{name}");
        assert!(o.non_quad <= 10.0, "{name}: {:.1} % non-quads", o.non_quad);
    }
}

#[test]
fn bunny_keeps_its_holes_and_gains_none() {
    // With the thesis' curvature-adaptive sizing the edges on the bunny's
    // base are shorter than the gaps between its five holes, and all five
    // stay separate loops. With the default uniform sizing two of them lie
    // closer than one edge length and join (tests/boundaries.rs checks that
    // no hole is closed over there).
    let mut params = Params::default();
    params.sizing.method = quadrille::sizing::EdgeLengthMethod::OsculatingError;
    let o = check_with("stanford-bunny.obj", params);
    assert_eq!(o.boundary_loops, 5, "{} loops", o.boundary_loops);
    assert!(o.non_quad <= 10.0, "{:.1} % non-quads", o.non_quad);
    let o = check("stanford-bunny.obj");
    assert!(o.boundary_loops >= 4, "{} loops", o.boundary_loops);
    assert!(o.non_quad <= 10.0, "{:.1} % non-quads", o.non_quad);
}

#[test]
fn messy_inputs_finish_manifold() {
    for name in ["beetle.obj", "teapot.obj", "suzanne.obj"] {
        let o = check(name);
        // Suzanne's default target is 31 vertices for a head with ears:
        // the first seed leaves 12.9 % odd faces, a restart meets the gate.
        assert!(o.non_quad <= 10.0, "{name}: {:.1} % non-quads", o.non_quad);
    }
}

#[test]
fn cow_with_thin_legs_and_a_pinched_vertex_stays_one_closed_surface() {
    let o = check("cow.obj");
    assert_eq!((o.boundary_loops, o.genus), (0, Some(0)));
    assert!(o.non_quad <= 10.0, "{:.1} % non-quads", o.non_quad);
}

/// The quality issue's bar that no quad has a corner above 170°, at the
/// default target of the small shared meshes, where thin tips, folds and
/// rim notches leave them (before the untangling tried rings of positions
/// and took splits back only beyond the budget: cow 205°, teapot 203°,
/// spot 190°, beetle 174°).
#[test]
fn small_meshes_keep_no_quad_corner_above_170_degrees() {
    for name in [
        "cow.obj",
        "teapot.obj",
        "spot.obj",
        "beetle.obj",
        "suzanne.obj",
    ] {
        let (_, mesh) = remesh(common::import(name), Params::default());
        let mut widest = 0.0f64;
        for f in 0..mesh.face_count() as u32 {
            let corners: Vec<u32> = mesh.face_vertices(f).collect();
            if let &[a, b, c, d] = corners.as_slice() {
                let p = [a, b, c, d].map(|v| mesh.positions[v as usize]);
                for angle in quadrille::metrics::quad_corner_angles(&p) {
                    widest = widest.max(angle.to_degrees());
                }
            }
        }
        println!("{name}: widest quad corner {widest:.1}°");
        assert!(
            widest <= 170.0 + 1e-9,
            "{name}: a quad corner of {widest:.1}°"
        );
    }
}

/// A shared mesh remeshed with the defaults: the input, the mean target
/// edge length and the output's surface (for distances to it).
fn remeshed_with_surface(name: &str) -> (TriMesh, f64, quadrille::spatial::SurfaceIndex) {
    let input = common::import(name);
    let mesh = input.mesh.clone();
    let (p, out) = remesh(input, Params::default());
    let sizing = &p.analysis.as_ref().unwrap().surface.sizing.edge_length;
    let s = sizing.iter().sum::<f64>() / sizing.len() as f64;
    let tris = TriMesh {
        positions: out.positions.clone(),
        triangles: out.to_face_list().triangulate(&out.positions),
    };
    let surface = quadrille::spatial::SurfaceIndex::new(&tris).unwrap();
    (mesh, s, surface)
}

/// The cow's legs are tubes three or four target edges around. The face
/// tracing leaves each hoof as a small closed fragment, apart from a leg
/// closed off above it; dropping those fragments cut the hooves off (with
/// `extraction.bridge_fragments` off the first is 1.92 target edges from
/// the output). Joined by a tube, every hoof (the input's lowest vertex
/// under each quarter of the ground plan) lies within 1.25 target edges of
/// the output (0.27, 0.22, 0.99, 0.34).
#[test]
fn the_cows_hooves_are_kept() {
    let (mesh, s, surface) = remeshed_with_surface("cow.obj");
    let bbox = mesh.bbox().unwrap();
    let centre = 0.5 * (bbox.min + bbox.max);
    // The ground plan: x and z; y is up.
    let mut hooves = [None::<glam::DVec3>; 4];
    for &q in &mesh.positions {
        let k = (q.x > centre.x) as usize * 2 + (q.z > centre.z) as usize;
        if hooves[k].is_none_or(|h| q.y < h.y) {
            hooves[k] = Some(q);
        }
    }
    for h in hooves {
        let h = h.unwrap();
        let d = surface.distance(h) / s;
        println!("hoof at {h:.3}: {d:.2} target edges from the output");
        assert!(
            d <= 1.25,
            "hoof at {h:.3} is {d:.2} target edges from the output"
        );
    }
}

/// Spot's horn tips, capped by two faces around a valence-2 vertex in the
/// traced faces, are kept by the repair's face split
/// (`extraction.keep_cap_vertices`) instead of being cut off.
#[test]
fn spots_horn_tips_are_kept() {
    let (mesh, s, surface) = remeshed_with_surface("spot.obj");
    let bbox = mesh.bbox().unwrap();
    let centre = 0.5 * (bbox.min + bbox.max);
    // y is up; the horns are the highest points left and right of x's centre.
    let mut tips = [None::<glam::DVec3>; 2];
    for &q in &mesh.positions {
        let k = (q.x > centre.x) as usize;
        if tips[k].is_none_or(|h| q.y > h.y) {
            tips[k] = Some(q);
        }
    }
    for h in tips {
        let h = h.unwrap();
        let d = surface.distance(h) / s;
        println!("horn tip at {h:.3}: {d:.2} target edges from the output");
        assert!(
            d <= 0.5,
            "horn tip at {h:.3} is {d:.2} target edges from the output"
        );
    }
}

#[test]
fn sphere_and_torus_give_closed_manifold_quad_dominant_meshes() {
    for (mesh, genus) in [
        (generate::icosphere(1.0, 4), 0),
        (generate::torus(1.0, 0.4, 96, 48), 1),
    ] {
        let mut params = Params::default();
        params.sizing.target_vertex_count = Some(300);
        let (_, out) = remesh(from_mesh(mesh), params);
        let t = out.topology();
        assert!(t.is_closed_manifold(), "{t:?}");
        assert_eq!(t.genus(), Some(genus));
        let hist = out.to_face_list().degree_histogram();
        assert!(hist[4] * 2 > out.face_count(), "{hist:?}");
    }
}

#[test]
fn same_seed_same_mesh() {
    let run = || {
        let mut params = Params::default();
        params.sizing.target_vertex_count = Some(200);
        remesh(from_mesh(generate::icosphere(1.0, 3)), params).1
    };
    assert_eq!(run(), run());
}

/// The pure-quad route (Instant Meshes' step 9 and 10: one split, then the
/// smoothing): all quads, closed, the target honoured by the split mesh,
/// every vertex on the input, and the smoothing after the split evens out
/// the split triangles' and pentagons' quads (lower mean corner deviation
/// than the split alone).
#[test]
fn pure_quad_split_is_closed_on_the_surface_and_smoothed() {
    let mut deviation = Vec::new();
    for smoothing in [0, 3] {
        let mut params = Params::default();
        params.sizing.target_vertex_count = Some(600);
        params.extraction.pure_quad = true;
        params.extraction.post.smoothing_iterations = smoothing;
        // The split's smoothing and reprojection alone: the least-squares
        // placement (its own test below) moves the vertices off the input.
        params.extraction.post.least_squares_iterations = 0;
        let input = from_mesh(generate::icosphere(1.0, 4));
        // The import normalises (largest axis 1): the radius it gives.
        let radius = input.mesh.positions[0].length();
        let (_, out) = remesh(input, params);
        let t = out.topology();
        assert!(t.is_closed_manifold(), "{t:?}");
        assert_eq!(t.genus(), Some(0));
        let faces = out.to_face_list();
        assert!(faces.iter().all(|f| f.len() == 4));
        let miss = (out.vertex_count() as f64 - 600.0).abs() / 600.0;
        assert!(miss <= 0.10, "{} vertices for 600", out.vertex_count());
        // Within the chordal error of the level-4 icosphere (edge ≈ 0.08 r).
        for p in &out.positions {
            assert!((p.length() / radius - 1.0).abs() < 2e-3, "{p}");
        }
        let q = quadrille::metrics::quad_metrics(&out.positions, &faces);
        println!(
            "smoothing {smoothing}: {} vertices, corner deviation {:.2}°",
            out.vertex_count(),
            q.corner_angle_deviation_degrees
        );
        deviation.push(q.corner_angle_deviation_degrees);
    }
    assert!(deviation[1] < deviation[0], "{deviation:?}");
    // Measured: 8.0° unsmoothed, 5.4° with the smoothing before the split
    // only, 4.0° with the smoothing after it as well.
    assert!(deviation[1] < 5.0, "{deviation:?}");
}

/// A cube's faces cut into n × n quads, projected onto the unit sphere.
fn quad_sphere(n: usize) -> PolyMesh {
    use glam::DVec3;
    let mut positions: Vec<DVec3> = Vec::new();
    let mut index = std::collections::HashMap::new();
    let mut faces = FaceList::new();
    let mut vertex = |p: DVec3, positions: &mut Vec<DVec3>| -> u32 {
        // Grid points are exact multiples of 1/n: a key in integers.
        let k = (p * n as f64).round().as_ivec3();
        *index.entry((k.x, k.y, k.z)).or_insert_with(|| {
            positions.push(p.normalize());
            positions.len() as u32 - 1
        })
    };
    for axis in 0..3 {
        for sign in [-1.0, 1.0] {
            // u × v = normal: the quads turn counter-clockwise outside.
            let unit = |i: usize, x: f64| {
                let mut a = [0.0; 3];
                a[i % 3] = x;
                DVec3::from_array(a)
            };
            let (normal, u, v) = (unit(axis, sign), unit(axis + 1, 1.0), unit(axis + 2, sign));
            let at = |i: usize, j: usize| {
                normal
                    + u * (2.0 * i as f64 / n as f64 - 1.0)
                    + v * (2.0 * j as f64 / n as f64 - 1.0)
            };
            for i in 0..n {
                for j in 0..n {
                    let q = [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)]
                        .map(|p| vertex(p, &mut positions));
                    faces.push(&q);
                }
            }
        }
    }
    PolyMesh::from_faces(positions, &faces).expect("a closed quad sphere")
}

/// The least-squares placement's point: a mesh of chords of a sphere lies
/// inside it; placed, its faces straddle the sphere. Measured against the
/// exact sphere (the input is a fine icosphere): the mean distance of
/// points spread over the quads to the sphere at least halves, the
/// vertices move out, and the quads keep their shape.
#[test]
fn least_squares_placement_makes_the_faces_straddle_a_sphere() {
    use quadrille::extract::placement::least_squares_placement;
    let input = generate::icosphere(1.0, 6);
    let surface = quadrille::spatial::SurfaceIndex::new(&input).expect("a surface");
    let mut mesh = quad_sphere(4);
    assert!(mesh.topology().is_closed_manifold());
    // Mean |‖p‖ − 1| over a 4 × 4 grid of bilinear points in every quad.
    let error = |mesh: &PolyMesh| {
        let faces = mesh.to_face_list();
        let (mut sum, mut count) = (0.0, 0);
        for f in faces.iter() {
            let p: Vec<_> = f.iter().map(|&v| mesh.positions[v as usize]).collect();
            for a in 0..4 {
                for b in 0..4 {
                    let (s, t) = ((a as f64 + 0.5) / 4.0, (b as f64 + 0.5) / 4.0);
                    let x = p[0] * (1.0 - s) * (1.0 - t)
                        + p[1] * s * (1.0 - t)
                        + p[2] * s * t
                        + p[3] * (1.0 - s) * t;
                    sum += (x.length() - 1.0).abs();
                    count += 1;
                }
            }
        }
        sum / count as f64
    };
    let corners = |mesh: &PolyMesh| {
        quadrille::metrics::quad_metrics(&mesh.positions, &mesh.to_face_list())
            .corner_angle_deviation_degrees
    };
    let (before, corners_before) = (error(&mesh), corners(&mesh));
    let steps = least_squares_placement(&mut mesh, &surface, &input.positions, 10, None);
    let (after, corners_after) = (error(&mesh), corners(&mesh));
    println!(
        "{steps} steps: mean distance {before:.2e} → {after:.2e}, corner deviation {corners_before:.2}° → {corners_after:.2}°"
    );
    assert!(after < 0.5 * before, "{before:.2e} → {after:.2e}");
    assert!(
        mesh.positions.iter().all(|p| p.length() > 1.0),
        "every vertex moves out"
    );
    assert!(
        corners_after < corners_before + 0.5,
        "{corners_before} → {corners_after}"
    );
}
