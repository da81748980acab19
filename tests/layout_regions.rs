//! Dual strip weaving part 2 (Campen & Kobbelt 2014 §4.2, §7, §5.8):
//! regions between loops, the primal layout and its export, reflectional
//! symmetry — on exact plane sections of generated meshes.

mod common;

use std::f64::consts::{FRAC_PI_2, PI};

use glam::{DQuat, DVec3};
use quadrille::layout::grid::{grid_layout, patch_polygons};
use quadrille::layout::primal::{LayoutExport, QuadLayout};
use quadrille::layout::regions::{Guidance, Regions};
use quadrille::layout::symmetry::{self, MirrorPlane};
use quadrille::layout::{EdgeCrossing, EmbeddedLoop, Singularity};
use quadrille::mesh::generate::{flat_grid, icosphere, torus};
use quadrille::mesh::{PolyMesh, TriMesh};
use quadrille::spatial::SurfaceIndex;

/// The curves where the plane `n·p = d` cuts the mesh, as exact embedded
/// loops (closed) or dual curves (open, boundary to boundary). The plane
/// must miss every vertex.
fn plane_sections(mesh: &TriMesh, n: DVec3, d: f64) -> Vec<EmbeddedLoop> {
    let s: Vec<f64> = mesh.positions.iter().map(|p| n.dot(*p) - d).collect();
    assert!(s.iter().all(|x| x.abs() > 1e-9), "plane hits a vertex");
    // Crossed edges and their faces.
    let mut edge_faces: std::collections::HashMap<(u32, u32), Vec<u32>> = Default::default();
    for (f, t) in mesh.triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            if (s[a as usize] > 0.0) != (s[b as usize] > 0.0) {
                edge_faces
                    .entry((a.min(b), a.max(b)))
                    .or_default()
                    .push(f as u32);
            }
        }
    }
    let crossing = |(a, b): (u32, u32)| {
        let (sa, sb) = (s[a as usize], s[b as usize]);
        EdgeCrossing {
            a,
            b,
            t: (sa / (sa - sb)).clamp(1e-6, 1.0 - 1e-6),
        }
    };
    let other_edge = |f: u32, e: (u32, u32)| {
        let t = mesh.triangles[f as usize];
        (0..3)
            .map(|k| (t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3])))
            .find(|x| *x != e && edge_faces.contains_key(x))
            .unwrap()
    };
    let mut used = std::collections::HashSet::new();
    let mut keys: Vec<(u32, u32)> = edge_faces.keys().copied().collect();
    keys.sort();
    // Open curves first (start on boundary edges), then closed loops.
    keys.sort_by_key(|e| edge_faces[e].len());
    let mut out = Vec::new();
    for start in keys {
        if used.contains(&start) {
            continue;
        }
        let open = edge_faces[&start].len() == 1;
        let mut l = EmbeddedLoop {
            closed: !open,
            ..Default::default()
        };
        let (mut e, mut f) = (start, edge_faces[&start][0]);
        loop {
            used.insert(e);
            l.crossings.push(crossing(e));
            let next = other_edge(f, e);
            l.faces.push(f);
            if next == start {
                break;
            }
            e = next;
            let fs = &edge_faces[&e];
            if fs.len() == 1 {
                used.insert(e);
                l.crossings.push(crossing(e));
                break;
            }
            f = if fs[0] == f { fs[1] } else { fs[0] };
        }
        out.push(l);
    }
    out
}

/// Torus R = 2, r = 0.7 with 48 × 24 segments.
fn test_torus() -> TriMesh {
    torus(2.0, 0.7, 48, 24)
}

/// The two meridians in the plane through the z axis at angle `a`; `a`
/// must avoid the vertex columns.
fn meridians(mesh: &TriMesh, a: f64) -> Vec<EmbeddedLoop> {
    let l = plane_sections(mesh, DVec3::new(-a.sin(), a.cos(), 0.0), 0.0);
    assert_eq!(l.len(), 2);
    l
}

/// The outer longitude at height z (two circles; the larger).
fn outer_longitude(mesh: &TriMesh, z: f64) -> EmbeddedLoop {
    let mut l = plane_sections(mesh, DVec3::Z, z);
    assert_eq!(l.len(), 2);
    l.sort_by_key(|x| x.crossings.len());
    l.pop().unwrap()
}

const MERIDIAN_ANGLE: f64 = PI / 48.0 + 0.01;

#[test]
fn torus_one_meridian_is_one_red_cylinder() {
    let mesh = test_torus();
    let m = meridians(&mesh, MERIDIAN_ANGLE);
    let r = Regions::compute(&mesh, &m[..1], &[]).unwrap();
    println!("torus, 1 meridian: {:?}", summary(&r));
    assert_eq!(r.regions.len(), 1);
    assert_eq!(r.regions[0].euler, 0);
    assert_eq!(r.regions[0].boundary_cycles, 2);
    assert_eq!(r.regions[0].guidance, Guidance::NonDisc);
    assert!(!r.sufficient);
    assert!(QuadLayout::build(&mesh, &m[..1], &r, &[]).is_err());
}

#[test]
fn torus_meridian_and_longitude_is_one_quad() {
    let mesh = test_torus();
    let m = meridians(&mesh, MERIDIAN_ANGLE);
    let loops = vec![m[0].clone(), outer_longitude(&mesh, 0.1)];
    let r = Regions::compute(&mesh, &loops, &[]).unwrap();
    println!("torus, meridian + longitude: {:?}", summary(&r));
    assert_eq!(r.regions.len(), 1);
    assert_eq!(r.crossings.len(), 1);
    let reg = &r.regions[0];
    assert_eq!((reg.euler, reg.boundary_cycles, reg.valence), (1, 1, 4));
    // Total curvature of a torus: 0 (Gauss–Bonnet), so v = 4 expected.
    assert!(reg.total_curvature.abs() < 1e-9);
    assert_eq!(reg.guidance, Guidance::Ok);
    assert!(r.sufficient);
    let layout = QuadLayout::build(&mesh, &loops, &r, &[]).unwrap();
    assert_eq!(layout.vertices.len(), 1);
    assert_eq!(layout.edges.len(), 2);
    assert_eq!(layout.patches.len(), 1);
}

#[test]
fn torus_two_meridians_and_longitude_are_two_quads() {
    let mesh = test_torus();
    let mut loops = meridians(&mesh, MERIDIAN_ANGLE);
    loops.push(outer_longitude(&mesh, 0.1));
    let r = Regions::compute(&mesh, &loops, &[]).unwrap();
    println!("torus, 2 meridians + longitude: {:?}", summary(&r));
    assert_eq!(r.regions.len(), 2);
    for reg in &r.regions {
        assert_eq!((reg.euler, reg.valence), (1, 4));
    }
    assert!(r.sufficient);
    let layout = QuadLayout::build(&mesh, &loops, &r, &[]).unwrap();
    assert_eq!(layout.patches.len(), 2);
    assert_eq!(layout.vertices.len(), 2);
    assert_eq!(layout.edges.len(), 4);
    check_layout(&layout);
    // Each half torus is symmetric about the plane through the z axis at
    // a ± π/2: its corridor-crossing vertex lies there (within two columns).
    for v in &layout.vertices {
        let angle = v.position.y.atan2(v.position.x);
        let off = (angle - MERIDIAN_ANGLE).rem_euclid(PI) - FRAC_PI_2;
        assert!(off.abs() < 2.0 * 2.0 * PI / 48.0, "{angle}");
    }
}

/// A generic rotation, so the coordinate planes miss the icosphere's
/// vertices.
fn tilt() -> DQuat {
    DQuat::from_euler(glam::EulerRot::XYZ, 0.31, 0.17, 0.23)
}

fn sphere() -> TriMesh {
    icosphere(1.0, 4)
}

fn great_circle(mesh: &TriMesh, axis: DVec3) -> EmbeddedLoop {
    let mut l = plane_sections(mesh, tilt() * axis, 0.0);
    assert_eq!(l.len(), 1);
    l.pop().unwrap()
}

fn octant_loops(mesh: &TriMesh) -> Vec<EmbeddedLoop> {
    [DVec3::X, DVec3::Y, DVec3::Z]
        .iter()
        .map(|&a| great_circle(mesh, a))
        .collect()
}

/// The vertex nearest to the centre of each octant.
fn octant_centres(mesh: &TriMesh) -> Vec<Singularity> {
    let mut out = Vec::new();
    for sx in [-1.0, 1.0] {
        for sy in [-1.0, 1.0] {
            for sz in [-1.0, 1.0] {
                let c = tilt() * DVec3::new(sx, sy, sz).normalize();
                let v = (0..mesh.positions.len())
                    .max_by(|&a, &b| {
                        mesh.positions[a]
                            .dot(c)
                            .total_cmp(&mesh.positions[b].dot(c))
                    })
                    .unwrap();
                out.push(Singularity {
                    vertex: v as u32,
                    index: 1,
                });
            }
        }
    }
    out
}

#[test]
fn sphere_octants() {
    let mesh = sphere();
    let loops = octant_loops(&mesh);
    let r = Regions::compute(&mesh, &loops, &[]).unwrap();
    println!("sphere, 3 great circles: {:?}", summary(&r));
    assert_eq!(r.regions.len(), 8);
    assert_eq!(r.crossings.len(), 6);
    assert_eq!(r.arcs.len(), 12);
    let total: f64 = r.regions.iter().map(|g| g.total_curvature).sum();
    assert!((total - 4.0 * PI).abs() < 1e-9, "Gauss–Bonnet: {total}");
    for reg in &r.regions {
        assert_eq!((reg.euler, reg.boundary_cycles, reg.valence), (1, 1, 3));
        assert!(
            (reg.total_curvature - FRAC_PI_2).abs() < 0.05,
            "{}",
            reg.total_curvature
        );
        assert_eq!(reg.guidance, Guidance::Ok);
    }
    let layout = QuadLayout::build(&mesh, &loops, &r, &[]).unwrap();
    assert_eq!(
        (
            layout.vertices.len(),
            layout.edges.len(),
            layout.patches.len()
        ),
        (8, 12, 6)
    );
    check_layout(&layout);
}

#[test]
fn sphere_octants_with_singularities() {
    let mesh = sphere();
    let loops = octant_loops(&mesh);
    let sing = octant_centres(&mesh);
    let r = Regions::compute(&mesh, &loops, &sing).unwrap();
    for reg in &r.regions {
        assert_eq!(reg.singularities.len(), 1);
        assert_eq!(reg.guidance, Guidance::Ok);
    }
    let layout = QuadLayout::build(&mesh, &loops, &r, &sing).unwrap();
    for v in &layout.vertices {
        let s = sing[r.regions[v.region as usize].singularities[0] as usize];
        assert!(v.singular);
        assert!(v.position.distance(mesh.positions[s.vertex as usize]) < 1e-12);
    }
    // Two singularities in one region: orange.
    let mut two = sing.clone();
    two.push(Singularity {
        vertex: two[0].vertex,
        index: 1,
    });
    let r2 = Regions::compute(&mesh, &loops, &two).unwrap();
    assert_eq!(
        r2.regions
            .iter()
            .filter(|g| g.guidance == Guidance::CurvatureExtrema)
            .count(),
        1
    );
    // A +1/−1 pair (a wiggle of the field) next to the corner is no second
    // extremum: still fine.
    let mut pair = sing.clone();
    pair.push(Singularity {
        vertex: pair[0].vertex,
        index: 1,
    });
    pair.push(Singularity {
        vertex: pair[0].vertex,
        index: -1,
    });
    let r3 = Regions::compute(&mesh, &loops, &pair).unwrap();
    assert!(r3.regions.iter().all(|g| g.guidance == Guidance::Ok));
}

#[test]
fn sphere_one_great_circle_hemispheres() {
    let mesh = sphere();
    let r = Regions::compute(&mesh, &[great_circle(&mesh, DVec3::Z)], &[]).unwrap();
    println!("sphere, 1 great circle: {:?}", summary(&r));
    assert_eq!(r.regions.len(), 2);
    for reg in &r.regions {
        // K ≈ 2π ⇒ (4 − v)π/2 = 2π ⇒ v = 0: a hemisphere bounded by a loop
        // without corners matches its curvature.
        assert_eq!((reg.euler, reg.boundary_cycles, reg.valence), (1, 1, 0));
        assert!((reg.total_curvature - 2.0 * PI).abs() < 0.05);
        assert!(reg.expected_valence.abs() < 0.1);
        assert_eq!(reg.guidance, Guidance::Ok);
    }
    assert!(r.sufficient);
    // The layout: two vertices, no edge or patch (V − E + F = 2).
    let loops = [great_circle(&mesh, DVec3::Z)];
    let l = QuadLayout::build(&mesh, &loops, &r, &[]).unwrap();
    assert_eq!(
        (l.vertices.len(), l.edges.len(), l.patches.len()),
        (2, 0, 0)
    );
}

#[test]
fn sphere_two_great_circles_lunes() {
    let mesh = sphere();
    let loops = vec![great_circle(&mesh, DVec3::Z), great_circle(&mesh, DVec3::X)];
    let r = Regions::compute(&mesh, &loops, &[]).unwrap();
    println!("sphere, 2 great circles: {:?}", summary(&r));
    assert_eq!(r.regions.len(), 4);
    for reg in &r.regions {
        // A lune of opening π/2 has K = π ⇒ expected v = 2.
        assert_eq!((reg.euler, reg.valence), (1, 2));
        assert!((reg.total_curvature - PI).abs() < 0.05);
        assert_eq!(reg.guidance, Guidance::Ok);
    }
    // One great circle plus a yellow case: a region of valence 3 would
    // need K = π/2; the lune pair union is checked by the octants test.
    let layout = QuadLayout::build(&mesh, &loops, &r, &[]).unwrap();
    assert_eq!(
        (
            layout.vertices.len(),
            layout.edges.len(),
            layout.patches.len()
        ),
        (4, 4, 2)
    );
}

#[test]
fn flat_grid_with_one_dual_curve() {
    let mesh = flat_grid(1.0, 10);
    let mut loops = plane_sections(&mesh, DVec3::X, 0.05);
    assert_eq!(loops.len(), 1);
    assert!(!loops[0].closed);
    let r = Regions::compute(&mesh, &loops, &[]).unwrap();
    println!("flat grid, 1 dual curve: {:?}", summary(&r));
    assert_eq!(r.regions.len(), 2);
    for reg in &r.regions {
        assert_eq!((reg.euler, reg.boundary_cycles), (1, 1));
        // One side along the curve, one along the mesh boundary.
        assert_eq!(reg.valence, 2);
        assert!(reg.touches_mesh_boundary);
    }
    // Two crossing dual curves: four quarter squares, one crossing.
    loops.extend(plane_sections(&mesh, DVec3::Y, -0.05));
    let r = Regions::compute(&mesh, &loops, &[]).unwrap();
    println!("flat grid, 2 dual curves: {:?}", summary(&r));
    assert_eq!(r.regions.len(), 4);
    assert_eq!(r.crossings.len(), 1);
    for reg in &r.regions {
        assert_eq!((reg.euler, reg.valence), (1, 3));
    }
    // Flat, no loops: the plain square is one disc with one boundary cycle.
    let r = Regions::compute(&mesh, &[], &[]).unwrap();
    assert_eq!(r.regions.len(), 1);
    assert_eq!((r.regions[0].euler, r.regions[0].boundary_cycles), (1, 1));
}

#[test]
fn malformed_loops_are_errors() {
    let mesh = test_torus();
    let mut l = meridians(&mesh, MERIDIAN_ANGLE).remove(0);
    let mut bad = l.clone();
    bad.faces.pop();
    assert!(Regions::compute(&mesh, &[bad], &[]).is_err());
    let mut bad = l.clone();
    bad.crossings[3].t = f64::NAN;
    assert!(Regions::compute(&mesh, &[bad], &[]).is_err());
    l.faces[2] = l.faces[5];
    assert!(Regions::compute(&mesh, &[l], &[]).is_err());
    assert!(
        Regions::compute(
            &mesh,
            &[],
            &[Singularity {
                vertex: 1 << 30,
                index: 1
            }]
        )
        .is_err()
    );
}

fn summary(r: &Regions) -> Vec<(i64, u32, u32, f64, Guidance)> {
    r.regions
        .iter()
        .map(|g| {
            (
                g.euler,
                g.boundary_cycles,
                g.valence,
                (g.total_curvature * 1000.0).round() / 1000.0,
                g.guidance,
            )
        })
        .collect()
}

/// Every patch has 4 distinct corners on a closed genus-0 layout, every
/// edge joins the corners its patches say, polylines start and end at
/// their vertices.
fn check_layout(layout: &QuadLayout) {
    for e in &layout.edges {
        let p = &e.polyline;
        assert!(p.len() >= 2);
        let a = layout.vertices[e.ends[0] as usize].position;
        let b = layout.vertices[e.ends[1] as usize].position;
        assert!(p[0].distance(a) < 1e-9 && p[p.len() - 1].distance(b) < 1e-9);
    }
    for patch in &layout.patches {
        for i in 0..4 {
            let e = &layout.edges[patch.edges[i] as usize];
            let (c0, c1) = (patch.corners[i], patch.corners[(i + 1) % 4]);
            assert!(
                (e.ends == [c0, c1]) || (e.ends == [c1, c0]),
                "patch edge {i} joins {:?}, corners {c0} {c1}",
                e.ends
            );
        }
    }
}

#[test]
fn octant_layout_is_a_cube() {
    let mesh = sphere();
    let loops = octant_loops(&mesh);
    let r = Regions::compute(&mesh, &loops, &[]).unwrap();
    let layout = QuadLayout::build(&mesh, &loops, &r, &[]).unwrap();
    let (v, e, f) = (
        layout.vertices.len() as i64,
        layout.edges.len() as i64,
        layout.patches.len() as i64,
    );
    assert_eq!(v - e + f, 2);
    for patch in &layout.patches {
        let mut c = patch.corners.to_vec();
        c.sort();
        c.dedup();
        assert_eq!(c.len(), 4);
    }
    for e in &layout.edges {
        assert_ne!(e.ends[0], e.ends[1]);
    }
    // Vertices sit near the octant centres (geodesic centre of a spherical
    // right triangle = its centroid direction).
    for vtx in &layout.vertices {
        let d = tilt().inverse() * vtx.position.normalize();
        let c = DVec3::new(d.x.signum(), d.y.signum(), d.z.signum()).normalize();
        assert!(d.angle_between(c) < 0.15, "{}", d.angle_between(c));
    }
}

#[test]
fn export_round_trips() {
    let mesh = sphere();
    let loops = octant_loops(&mesh);
    let r = Regions::compute(&mesh, &loops, &[]).unwrap();
    let layout = QuadLayout::build(&mesh, &loops, &r, &[]).unwrap();
    let json = layout.to_json().unwrap();
    let back: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert_eq!(back["vertices"].as_array().unwrap().len(), 8);
    assert_eq!(back["edges"].as_array().unwrap().len(), 12);
    assert_eq!(back["patches"].as_array().unwrap().len(), 6);
    let parsed = quadrille::layout::primal::LayoutExport::from_json(&json).unwrap();
    assert_eq!(parsed.patches.len(), 6);
    assert_eq!(
        parsed.edges[3].polyline.len(),
        layout.edges[3].polyline.len()
    );

    let obj = layout.to_obj();
    let v_lines = obj.lines().filter(|l| l.starts_with("v ")).count();
    let l_lines: Vec<&str> = obj.lines().filter(|l| l.starts_with("l ")).collect();
    assert_eq!(l_lines.len(), 12);
    let points: usize = layout.edges.iter().map(|e| e.polyline.len()).sum();
    assert_eq!(v_lines, points);
    for l in l_lines {
        for idx in l.split_whitespace().skip(1) {
            let i: usize = idx.parse().unwrap();
            assert!(i >= 1 && i <= v_lines);
        }
    }
    assert_eq!(obj.lines().filter(|l| l.starts_with("# patch")).count(), 6);
}

#[test]
fn moving_a_vertex_reroutes_its_edges() {
    let mesh = sphere();
    let loops = octant_loops(&mesh);
    let r = Regions::compute(&mesh, &loops, &[]).unwrap();
    let mut layout = QuadLayout::build(&mesh, &loops, &r, &[]).unwrap();
    let old = layout.vertices[0].position;
    // A point of the same region: a vertex of it next to the centre.
    let region = layout.vertices[0].region;
    let target = (0..mesh.positions.len())
        .filter(|&v| r.vertex_region[v] == region)
        .map(|v| mesh.positions[v])
        .find(|p| p.distance(old) > 0.1)
        .unwrap();
    layout.move_vertex(0, target).unwrap();
    assert!(layout.vertices[0].position.distance(target) < 1e-6);
    check_layout(&layout);
    assert!(layout.move_vertex(99, target).is_err());
}

#[test]
fn mirror_plane_of_a_torus() {
    let mut mesh = test_torus();
    // Move it so the symmetry planes are not through the origin.
    mesh.map_positions(|p| p + DVec3::new(0.3, -0.2, 0.5));
    let (plane, score) = symmetry::detect(&mesh).unwrap();
    println!("torus mirror plane {plane:?} score {score}");
    assert!(score < 1e-3);
    assert!(
        (plane.point - DVec3::new(0.3, -0.2, 0.5))
            .dot(plane.normal)
            .abs()
            < 1e-9
    );
    // The meridian at angle a mirrors (plane through the axis) onto a
    // curve on the surface; a longitude mirrored in z = 0.5 + 0 ... its
    // own mirror image when the plane is x or y.
    let lon = outer_longitude(&test_torus(), 0.1);
    let pts: Vec<DVec3> = lon
        .crossings
        .iter()
        .map(|c| {
            let m = test_torus();
            m.positions[c.a as usize].lerp(m.positions[c.b as usize], c.t)
        })
        .collect();
    let base = test_torus();
    let index = quadrille::spatial::SurfaceIndex::new(&base).unwrap();
    for normal in [DVec3::X, DVec3::Y] {
        let p = MirrorPlane {
            point: DVec3::ZERO,
            normal,
        };
        let m = symmetry::mirror_polyline(&index, &p, &pts);
        assert!(symmetry::is_self_symmetric(&pts, &m, 1e-3));
    }
    let z = MirrorPlane {
        point: DVec3::ZERO,
        normal: DVec3::Z,
    };
    let m = symmetry::mirror_polyline(&index, &z, &pts);
    assert!(!symmetry::is_self_symmetric(&pts, &m, 1e-3));
    // A lumpy shape has no mirror plane.
    let mut lumpy = icosphere(1.0, 3);
    lumpy.map_positions(|p| {
        p * (1.0
            + 0.3 * (3.0 * p.x + 1.0).sin() * (2.0 * p.y + 0.5).cos()
            + 0.2 * (4.0 * p.z).sin())
    });
    println!("lumpy sphere: {:?}", symmetry::best_axis_plane(&lumpy));
    assert!(symmetry::detect(&lumpy).is_none());
}

#[test]
fn sphere_two_great_circles_at_a_small_angle_are_yellow() {
    let mesh = sphere();
    let theta: f64 = 0.3;
    let loops = vec![
        great_circle(&mesh, DVec3::Z),
        great_circle(&mesh, DVec3::new(0.0, theta.sin(), theta.cos())),
    ];
    let r = Regions::compute(&mesh, &loops, &[]).unwrap();
    println!("sphere, 2 great circles at 0.3 rad: {:?}", summary(&r));
    assert_eq!(r.regions.len(), 4);
    let mut k: Vec<f64> = r.regions.iter().map(|g| g.total_curvature).collect();
    k.sort_by(f64::total_cmp);
    // Lunes of opening θ and π − θ: K = 2θ and 2π − 2θ; valence 2 while
    // K asks for 4 − 4θ/π ≈ 3.6 and 4θ/π ≈ 0.4: off by more than 1.
    assert!((k[0] - 2.0 * theta).abs() < 0.05 && (k[3] - (2.0 * PI - 2.0 * theta)).abs() < 0.05);
    for reg in &r.regions {
        assert_eq!((reg.euler, reg.valence), (1, 2));
        assert_eq!(reg.guidance, Guidance::ValenceMismatch);
    }
    assert!(r.sufficient);
}

#[test]
fn two_curves_crossing_at_one_edge_point() {
    // Both dual curves cross the grid edge y = 0, x ∈ [0, 0.2] at x = 0.05,
    // with the same t: the crossing is seen in exactly one triangle.
    let mesh = flat_grid(1.0, 10);
    let a = plane_sections(&mesh, DVec3::X, 0.05).remove(0);
    let n = DVec3::new(-0.37, 1.0, 0.0);
    let mut b = plane_sections(&mesh, n, n.dot(DVec3::new(0.05, 0.0, 0.0))).remove(0);
    let shared: Vec<_> = a
        .crossings
        .iter()
        .filter_map(|ca| {
            b.crossings
                .iter()
                .position(|cb| (cb.a, cb.b) == (ca.a, ca.b))
                .map(|i| (i, ca.t))
        })
        .collect();
    assert_eq!(shared.len(), 1);
    b.crossings[shared[0].0].t = shared[0].1;
    let r = Regions::compute(&mesh, &[a.clone(), b.clone()], &[]).unwrap();
    println!(
        "flat grid, 2 curves through one edge point: {:?}",
        summary(&r)
    );
    assert_eq!(r.crossings.len(), 1);
    assert_eq!(r.regions.len(), 4);
    for reg in &r.regions {
        assert_eq!((reg.euler, reg.valence), (1, 3));
    }
    // Same with the loop order swapped (the tie is broken by loop index).
    let r = Regions::compute(&mesh, &[b, a], &[]).unwrap();
    assert_eq!((r.crossings.len(), r.regions.len()), (1, 4));
}

/// Timings on a ~30k-face torus and the rocker arm (run with --nocapture).
#[test]
fn timings_at_30k_faces() {
    use std::time::Instant;
    let mesh = torus(2.0, 0.7, 150, 100);
    let mut loops = meridians(&mesh, PI / 150.0 + 0.003);
    loops.push(outer_longitude(&mesh, 0.1));
    let t = Instant::now();
    let r = Regions::compute(&mesh, &loops, &[]).unwrap();
    let t_regions = t.elapsed();
    let t = Instant::now();
    let layout = QuadLayout::build(&mesh, &loops, &r, &[]).unwrap();
    let t_primal = t.elapsed();
    println!(
        "torus {} faces, {} loops: regions {:.1} ms, primal {:.1} ms ({} patches)",
        mesh.triangles.len(),
        loops.len(),
        t_regions.as_secs_f64() * 1e3,
        t_primal.as_secs_f64() * 1e3,
        layout.patches.len()
    );
    assert_eq!(layout.patches.len(), 2);

    let mesh = common::mesh("rocker-arm.obj");
    let bbox = mesh.bbox().unwrap();
    let c = bbox.center();
    let mut loops = Vec::new();
    for (n, off) in [
        (DVec3::X, 0.013),
        (DVec3::Y, 0.011),
        (DVec3::Z, 0.007),
        (DVec3::new(1.0, 1.0, 0.0).normalize(), 0.017),
    ] {
        let d = n.dot(c) + off * bbox.diagonal();
        if mesh.positions.iter().any(|p| (n.dot(*p) - d).abs() < 1e-9) {
            continue;
        }
        loops.extend(plane_sections(&mesh, n, d));
    }
    let t = Instant::now();
    let r = Regions::compute(&mesh, &loops, &[]).unwrap();
    let t_regions = t.elapsed();
    let t = Instant::now();
    let layout = QuadLayout::build(&mesh, &loops, &r, &[]);
    let t_primal = t.elapsed();
    println!(
        "rocker arm {} faces, {} loops, {} crossings: {} regions ({} red), regions {:.1} ms, primal {:.1} ms ({})",
        mesh.triangles.len(),
        loops.len(),
        r.crossings.len(),
        r.regions.len(),
        r.red_count(),
        t_regions.as_secs_f64() * 1e3,
        t_primal.as_secs_f64() * 1e3,
        match &layout {
            Ok(l) => format!(
                "{} vertices, {} edges, {} patches",
                l.vertices.len(),
                l.edges.len(),
                l.patches.len()
            ),
            Err(e) => e.to_string(),
        }
    );
    println!("rocker arm regions: {:?}", summary(&r));
    // Invariants: Gauss–Bonnet over the regions, and the layout has the
    // surface's Euler characteristic.
    let chi = {
        let t = mesh.topology();
        t.euler_characteristic
    };
    let total: f64 = r.regions.iter().map(|g| g.total_curvature).sum();
    assert!(
        (total - 2.0 * PI * chi as f64).abs() < 1e-6,
        "{total} vs χ = {chi}"
    );
    if let Ok(l) = layout {
        let (v, e, f) = (
            l.vertices.len() as i64,
            l.edges.len() as i64,
            l.patches.len() as i64,
        );
        assert_eq!(v - e + f, chi);
        check_layout(&l);
    }
}

/// A closed polyline in the plane z = 0 traced through a flat mesh: its
/// crossings with the mesh edges in order along the curve, and the face
/// between consecutive crossings (brute force; small meshes only).
fn trace_planar_loop(mesh: &TriMesh, curve: &[DVec3]) -> EmbeddedLoop {
    let mut edges: Vec<(u32, u32)> = mesh
        .triangles
        .iter()
        .flat_map(|t| (0..3).map(move |k| (t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3]))))
        .collect();
    edges.sort();
    edges.dedup();
    let cross = |a: DVec3, b: DVec3| a.x * b.y - a.y * b.x;
    let mut l = EmbeddedLoop {
        closed: true,
        ..Default::default()
    };
    let mut points = Vec::new();
    for i in 0..curve.len() {
        let (p, q) = (curve[i], curve[(i + 1) % curve.len()]);
        let mut hits = Vec::new();
        for &(a, b) in &edges {
            let (pa, pb) = (mesh.positions[a as usize], mesh.positions[b as usize]);
            let (r, s) = (q - p, pb - pa);
            let d = cross(r, s);
            if d.abs() < 1e-15 {
                continue;
            }
            let u = cross(pa - p, s) / d;
            let t = cross(pa - p, r) / d;
            if (0.0..1.0).contains(&u) && t > 0.0 && t < 1.0 {
                assert!(t > 1e-6 && t < 1.0 - 1e-6, "curve passes a vertex");
                hits.push((u, EdgeCrossing { a, b, t }));
            }
        }
        hits.sort_by(|x, y| x.0.total_cmp(&y.0));
        for (_, c) in hits {
            points.push(mesh.positions[c.a as usize].lerp(mesh.positions[c.b as usize], c.t));
            l.crossings.push(c);
        }
    }
    let n = l.crossings.len();
    for i in 0..n {
        let (c0, c1) = (l.crossings[i], l.crossings[(i + 1) % n]);
        let f = mesh
            .triangles
            .iter()
            .position(|t| {
                let has = |c: EdgeCrossing| t.contains(&c.a) && t.contains(&c.b);
                let m = 0.5 * (points[i] + points[(i + 1) % n]);
                let [x, y, z] = t.map(|v| mesh.positions[v as usize]);
                let inside = cross(y - x, m - x) >= -1e-12
                    && cross(z - y, m - y) >= -1e-12
                    && cross(x - z, m - z) >= -1e-12;
                has(c0) && has(c1) && inside
            })
            .expect("consecutive crossings share a face");
        l.faces.push(f as u32);
    }
    l
}

#[test]
fn figure_eight_crosses_itself() {
    let mesh = flat_grid(1.0, 20);
    let centre = DVec3::new(0.013, 0.027, 0.0);
    let curve: Vec<DVec3> = (0..400)
        .map(|i| {
            let s = 2.0 * PI * i as f64 / 400.0;
            centre + DVec3::new(0.8 * s.sin(), 0.5 * s.sin() * s.cos(), 0.0)
        })
        .collect();
    let l = trace_planar_loop(&mesh, &curve);
    let r = Regions::compute(&mesh, &[l], &[]).unwrap();
    println!("flat grid, figure eight: {:?}", summary(&r));
    assert_eq!(r.crossings.len(), 1);
    assert_eq!(r.arcs.len(), 2);
    assert_eq!(r.regions.len(), 3);
    let mut got: Vec<(i64, u32, u32)> = r
        .regions
        .iter()
        .map(|g| (g.euler, g.boundary_cycles, g.valence))
        .collect();
    got.sort();
    // Outside: the square minus the figure eight, an annulus whose inner
    // boundary passes the crossing twice; two lobes with one corner each.
    assert_eq!(got, vec![(0, 2, 2), (1, 1, 1), (1, 1, 1)]);
    assert!(!r.sufficient);
}

#[test]
fn open_surface_layout_with_two_crossing_curves() {
    let mesh = flat_grid(1.0, 10);
    let mut loops = plane_sections(&mesh, DVec3::X, 0.05);
    loops.extend(plane_sections(
        &mesh,
        DVec3::new(0.3, 1.0, 0.0).normalize(),
        -0.05,
    ));
    let r = Regions::compute(&mesh, &loops, &[]).unwrap();
    let layout = QuadLayout::build(&mesh, &loops, &r, &[]).unwrap();
    assert_eq!(
        (
            layout.vertices.len(),
            layout.edges.len(),
            layout.patches.len()
        ),
        (4, 4, 1)
    );
    check_layout(&layout);
    // Boundary-aligned: the quarters' vertices are the square's corners and
    // the four edges run along its sides.
    for v in &layout.vertices {
        assert!(
            (v.position.x.abs() - 1.0).abs() < 1e-12 && (v.position.y.abs() - 1.0).abs() < 1e-12
        );
    }
    for e in &layout.edges {
        let (a, b) = (e.polyline[0], e.polyline[e.polyline.len() - 1]);
        let side = if (a.x - b.x).abs() < 1e-12 {
            DVec3::X
        } else {
            DVec3::Y
        };
        for p in &e.polyline {
            assert!((p.dot(side).abs() - 1.0).abs() < 1e-9, "{p} off the side");
        }
    }
    // Moving a vertex into another region is refused.
    let other = layout.vertices[1].position;
    let mut layout = layout;
    assert!(layout.move_vertex(0, other).is_err());
}

#[test]
fn layout_refuses_regions_of_other_loops() {
    let mesh = sphere();
    let loops = octant_loops(&mesh);
    let r = Regions::compute(&mesh, &loops, &[]).unwrap();
    assert!(QuadLayout::build(&mesh, &loops[..1], &r, &[]).is_err());
    assert!(QuadLayout::build(&test_torus(), &loops, &r, &[]).is_err());
}

#[test]
fn mirror_planes_of_the_shared_meshes() {
    for name in ["suzanne.obj", "fandisk.obj", "spot.obj", "rocker-arm.obj"] {
        let mesh = common::mesh(name);
        println!(
            "{name}: best axis plane {:?}, detected: {}",
            symmetry::best_axis_plane(&mesh),
            symmetry::detect(&mesh).is_some()
        );
    }
}

/// Random plane sections on closed meshes: every loop graph satisfies
/// χ(M) = Σ χ(regions) − #crossings (the loop graph has one 4-valent vertex
/// per crossing and two arcs per crossing), Gauss–Bonnet over the regions,
/// Σ valence = 2 · #arcs (each arc side is one corner), and a sufficient
/// arrangement gives a layout with V − E + F = χ(M).
#[test]
fn random_plane_sections_keep_the_invariants() {
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut rand = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut meshes = vec![
        ("sphere", icosphere(1.0, 3)),
        ("torus", torus(2.0, 0.7, 40, 20)),
    ];
    meshes.push(("rocker arm", common::mesh("rocker-arm.obj")));
    let mut sufficient = 0;
    for (name, mesh) in &meshes {
        let chi = mesh.topology().euler_characteristic;
        let scale = mesh.bbox().unwrap().diagonal();
        for trial in 0..25 {
            let mut loops = Vec::new();
            for _ in 0..1 + trial % 5 {
                let n = DVec3::new(rand() - 0.5, rand() - 0.5, rand() - 0.5).normalize();
                let d = (rand() - 0.5) * 0.4 * scale;
                if mesh.positions.iter().any(|p| (n.dot(*p) - d).abs() < 1e-9) {
                    continue;
                }
                loops.extend(plane_sections(mesh, n, d));
            }
            let r = Regions::compute(mesh, &loops, &[]).unwrap();
            let euler: i64 = r.regions.iter().map(|g| g.euler).sum();
            assert_eq!(
                euler - r.crossings.len() as i64,
                chi,
                "{name} trial {trial}"
            );
            let k: f64 = r.regions.iter().map(|g| g.total_curvature).sum();
            assert!((k - 2.0 * PI * chi as f64).abs() < 1e-6);
            let ended = r.arcs.iter().filter(|a| a.start.is_some()).count() as u32;
            assert_eq!(r.regions.iter().map(|g| g.valence).sum::<u32>(), 2 * ended);
            assert_eq!(ended as usize, 2 * r.crossings.len());
            if r.sufficient {
                sufficient += 1;
                let l = QuadLayout::build(mesh, &loops, &r, &[]).unwrap();
                let (v, e, f) = (
                    l.vertices.len() as i64,
                    l.edges.len() as i64,
                    l.patches.len() as i64,
                );
                assert_eq!(v - e + f, chi, "{name} trial {trial}");
                check_layout(&l);
            }
        }
    }
    println!("{sufficient} sufficient random arrangements laid out");
    assert!(sufficient > 5);
}

/// Garbage loops never panic: they are errors or (when they happen to be
/// valid) regions.
#[test]
fn garbage_loops_do_not_panic() {
    let mesh = torus(2.0, 0.7, 12, 8);
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = move |m: u64| {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state % m
    };
    let nv = mesh.positions.len() as u64;
    let nf = mesh.triangles.len() as u64;
    for _ in 0..2000 {
        let n = next(6) as usize;
        let closed = next(2) == 0;
        let crossings = (0..n)
            .map(|_| {
                let (a, b) = (next(nv + 2) as u32, next(nv + 2) as u32);
                EdgeCrossing {
                    a: a.min(b),
                    b: a.max(b),
                    t: next(5) as f64 / 4.0,
                }
            })
            .collect();
        let faces = (0..n.saturating_sub(!closed as usize))
            .map(|_| next(nf + 2) as u32)
            .collect();
        let l = EmbeddedLoop {
            crossings,
            faces,
            closed,
        };
        let _ = Regions::compute(&mesh, &[l], &[]);
    }
}

#[test]
fn rounded_box_corners_are_curvature_extrema() {
    let mesh = quadrille::mesh::generate::rounded_box(1.0, 0.1, 12, 4);
    let planes = [
        plane_sections(&mesh, DVec3::X, 0.013),
        plane_sections(&mesh, DVec3::Y, 0.011),
        plane_sections(&mesh, DVec3::Z, 0.007),
    ];
    // Two planes: four quarters, each holding two box corners → orange.
    let loops: Vec<EmbeddedLoop> = planes[..2].concat();
    let r = Regions::compute(&mesh, &loops, &[]).unwrap();
    println!("rounded box, 2 planes: {:?}", summary(&r));
    assert_eq!(r.regions.len(), 4);
    for reg in &r.regions {
        assert_eq!(reg.curvature_extrema.len(), 2);
        assert_eq!(reg.guidance, Guidance::CurvatureExtrema);
    }
    // Three planes: eight octants with one corner each, valence 3 and
    // K = π/2: all fine.
    let loops: Vec<EmbeddedLoop> = planes.concat();
    let r = Regions::compute(&mesh, &loops, &[]).unwrap();
    println!("rounded box, 3 planes: {:?}", summary(&r));
    assert_eq!(r.regions.len(), 8);
    for reg in &r.regions {
        assert_eq!(reg.curvature_extrema.len(), 1);
        assert_eq!(reg.valence, 3);
        assert!((reg.total_curvature - FRAC_PI_2).abs() < 1e-6);
        assert_eq!(reg.guidance, Guidance::Ok);
    }
    // A sphere has no pronounced extremum anywhere.
    let r = Regions::compute(&sphere(), &[], &[]).unwrap();
    assert!(r.regions[0].curvature_extrema.is_empty());
}

/// The same closed loop traversed the other way.
fn reversed(l: &EmbeddedLoop) -> EmbeddedLoop {
    let n = l.crossings.len();
    EmbeddedLoop {
        crossings: l.crossings.iter().rev().copied().collect(),
        faces: (0..n).map(|i| l.faces[(2 * n - 2 - i) % n]).collect(),
        closed: l.closed,
    }
}

#[test]
fn loop_direction_and_order_do_not_matter() {
    let mesh = sphere();
    let loops = octant_loops(&mesh);
    let base = Regions::compute(&mesh, &loops, &[]).unwrap();
    let sorted = |r: &Regions| {
        let mut s: Vec<(i64, u32, u32, i64)> = r
            .regions
            .iter()
            .map(|g| {
                (
                    g.euler,
                    g.boundary_cycles,
                    g.valence,
                    (g.total_curvature * 1e6).round() as i64,
                )
            })
            .collect();
        s.sort();
        s
    };
    let want = sorted(&base);
    let variants = [
        vec![reversed(&loops[0]), loops[1].clone(), loops[2].clone()],
        vec![loops[2].clone(), reversed(&loops[1]), loops[0].clone()],
        loops.iter().map(reversed).collect(),
    ];
    for v in variants {
        let r = Regions::compute(&mesh, &v, &[]).unwrap();
        assert_eq!(sorted(&r), want);
        let l = QuadLayout::build(&mesh, &v, &r, &[]).unwrap();
        assert_eq!(
            (l.vertices.len(), l.edges.len(), l.patches.len()),
            (8, 12, 6)
        );
        check_layout(&l);
    }
    // Mutations of valid loops are errors or valid arrangements, never
    // panics.
    for i in 0..loops[0].crossings.len() {
        let mut m = loops.clone();
        m[0].faces.swap(i, (i + 7) % loops[0].faces.len());
        let _ = Regions::compute(&mesh, &m, &[]);
        let mut m = loops.clone();
        let k = i % m[1].crossings.len();
        m[1].crossings.remove(k);
        let _ = Regions::compute(&mesh, &m, &[]);
    }
}

#[test]
fn octant_edge_routes_are_nearly_geodesic() {
    let mesh = sphere();
    let loops = octant_loops(&mesh);
    let r = Regions::compute(&mesh, &loops, &[]).unwrap();
    let layout = QuadLayout::build(&mesh, &loops, &r, &[]).unwrap();
    let mut worst: f64 = 0.0;
    for e in &layout.edges {
        let len: f64 = e.polyline.windows(2).map(|w| w[0].distance(w[1])).sum();
        // Neighbouring octant centres: the great circle between them
        // crosses the shared arc at its middle (by symmetry).
        let (a, b) = (e.polyline[0], e.polyline[e.polyline.len() - 1]);
        let geodesic = a.normalize().angle_between(b.normalize());
        worst = worst.max(len / geodesic);
        // Every route point lies on the unit sphere's polyhedron.
        assert!(e.polyline.iter().all(|p| (p.length() - 1.0).abs() < 0.01));
    }
    println!("octant routes: worst length / great-circle length {worst:.3}");
    assert!(worst < 1.15, "{worst}");
}

// ---------------------------------------------------------------- the layout as a mesh

/// Deepest point of a triangle mesh inscribed in the unit sphere: the
/// largest 1 − (distance of a face plane from the centre).
fn inscribed_sagitta(mesh: &TriMesh) -> f64 {
    mesh.triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|v| mesh.positions[v as usize]);
            let n = (b - a).cross(c - a).normalize();
            1.0 - n.dot(a).abs()
        })
        .fold(0.0, f64::max)
}

/// Checks a closed pure-quad mesh: valid, no boundary, every face a quad
/// facing away from `inside` (the outward direction at its centroid).
fn check_closed_quads(m: &PolyMesh, outward: impl Fn(DVec3) -> DVec3) {
    m.validate().expect("a valid half-edge mesh");
    assert!(m.boundary_loops().is_empty(), "closed");
    for f in 0..m.face_count() as u32 {
        assert_eq!(m.degree(f), 4, "face {f} is a quad");
        let vs: Vec<DVec3> = m
            .face_vertices(f)
            .map(|v| m.positions[v as usize])
            .collect();
        let centroid = vs.iter().sum::<DVec3>() / 4.0;
        let mut normal = DVec3::ZERO;
        for k in 0..4 {
            normal += vs[k].cross(vs[(k + 1) % 4]);
        }
        assert!(
            normal.dot(outward(centroid)) > 0.0,
            "face {f} faces inwards or is folded"
        );
    }
}

#[test]
fn sphere_octant_grid_is_a_closed_quad_mesh_on_the_sphere() {
    let mesh = sphere();
    let loops = octant_loops(&mesh);
    let r = Regions::compute(&mesh, &loops, &[]).unwrap();
    let layout = QuadLayout::build(&mesh, &loops, &r, &[]).unwrap();
    let index = SurfaceIndex::new(&mesh).unwrap();
    let sagitta = inscribed_sagitta(&mesh);
    // One count for all strips: the cube's regular refinement.
    let n = 8usize;
    let started = std::time::Instant::now();
    let g = grid_layout(&layout.export(), &[n as u32; 3], &mesh, &index).unwrap();
    println!(
        "sphere octants, grid {n}: {} vertices, {} quads in {:.2} ms",
        g.mesh.vertex_count(),
        g.mesh.face_count(),
        started.elapsed().as_secs_f64() * 1e3
    );
    let m = &g.mesh;
    check_closed_quads(m, |c| c);
    assert_eq!(m.face_count(), 6 * n * n);
    assert_eq!(m.vertex_count(), 6 * n * n + 2);
    assert_eq!(m.euler_characteristic(), 2);
    let valence3: Vec<u32> = (0..m.vertex_count() as u32)
        .filter(|&v| m.valence(v) == 3)
        .collect();
    assert_eq!(valence3.len(), 8, "the cube's corners");
    // They are the layout vertices (ids 0..8); every other vertex is regular.
    assert_eq!(valence3, (0..8).collect::<Vec<u32>>());
    assert!((0..m.vertex_count() as u32).all(|v| m.valence(v) == 3 || m.valence(v) == 4));
    // Every vertex on the surface: between the inscribed mesh's deepest
    // point and the analytic sphere.
    for (v, p) in m.positions.iter().enumerate() {
        let radius = p.length();
        assert!(
            radius <= 1.0 + 1e-9 && radius >= 1.0 - sagitta - 1e-9,
            "vertex {v} at radius {radius} (sagitta {sagitta})"
        );
    }
    // Even quads: in the cube's refinement the largest edge is at most
    // a few times the smallest.
    let lengths: Vec<f64> = (0..m.halfedge_count() as u32)
        .map(|h| m.positions[m.origin(h) as usize].distance(m.positions[m.tip(h) as usize]))
        .collect();
    let (lo, hi) = lengths
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(a, b), &l| (a.min(l), b.max(l)));
    println!("sphere octants, grid {n}: edge lengths {lo:.4} … {hi:.4}");
    assert!(hi < 4.0 * lo, "edge lengths {lo} … {hi}");
}

#[test]
fn sphere_octant_grid_takes_one_count_per_strip() {
    let mesh = sphere();
    let loops = octant_loops(&mesh);
    let r = Regions::compute(&mesh, &loops, &[]).unwrap();
    let layout = QuadLayout::build(&mesh, &loops, &r, &[]).unwrap();
    let index = SurfaceIndex::new(&mesh).unwrap();
    let counts = [2u32, 3, 5];
    let g = grid_layout(&layout.export(), &counts, &mesh, &index).unwrap();
    check_closed_quads(&g.mesh, |c| c);
    // Each patch is the crossing of two strips: counts a·b, two per pair.
    let [a, b, c] = counts.map(|x| x as usize);
    assert_eq!(g.mesh.face_count(), 2 * (a * b + b * c + c * a));
    assert_eq!(g.mesh.euler_characteristic(), 2);
    for (p, patch) in layout.patches.iter().enumerate() {
        let strips = [0, 1].map(|s| layout.edges[patch.edges[s] as usize].loop_index as usize);
        let faces = (g.patch_faces[p + 1] - g.patch_faces[p]) as usize;
        assert_eq!(
            faces,
            counts[strips[0]] as usize * counts[strips[1]] as usize
        );
    }
    // Bad counts are errors, not panics.
    assert!(grid_layout(&layout.export(), &[8, 8], &mesh, &index).is_err());
    assert!(grid_layout(&layout.export(), &[8, 0, 8], &mesh, &index).is_err());
}

#[test]
fn torus_grid_wraps_the_half_tubes() {
    let mesh = test_torus();
    let mut loops = meridians(&mesh, MERIDIAN_ANGLE);
    loops.push(outer_longitude(&mesh, 0.1));
    let r = Regions::compute(&mesh, &loops, &[]).unwrap();
    let layout = QuadLayout::build(&mesh, &loops, &r, &[]).unwrap();
    let index = SurfaceIndex::new(&mesh).unwrap();
    let started = std::time::Instant::now();
    let g = grid_layout(&layout.export(), &[8; 3], &mesh, &index).unwrap();
    println!(
        "torus, 3 strips, grid 8: {} vertices, {} quads in {:.2} ms",
        g.mesh.vertex_count(),
        g.mesh.face_count(),
        started.elapsed().as_secs_f64() * 1e3
    );
    // Outward: away from the tube's centre circle. (Not every quad: a side
    // winding around the tube can fold one or two; see grid.rs.)
    let tube_centre = |p: DVec3| 2.0 * DVec3::new(p.x, p.y, 0.0).normalize();
    println!("torus, grid 8: {} folded quads", g.folded);
    g.mesh.validate().expect("a valid half-edge mesh");
    assert!(g.mesh.boundary_loops().is_empty(), "closed");
    assert!((0..g.mesh.face_count() as u32).all(|f| g.mesh.degree(f) == 4));
    assert_eq!(g.mesh.euler_characteristic(), 0);
    assert_eq!(g.mesh.face_count(), 2 * 64);
    assert!((0..g.mesh.vertex_count() as u32).all(|v| g.mesh.valence(v) == 4));
    // On the surface: at the tube's radius, within the mesh's chord error
    // (48 × 24 segments: a chord of the tube circle sags r(1 − cos(π/24)),
    // a chord of the ring by up to (R + r)(1 − cos(π/48)) more on the
    // outside; on the inside, where the ring is concave, a ring chord lies
    // outside the tube by up to (R − r)(1 − cos(π/48))).
    let ring_sag = 1.0 - (PI / 48.0).cos();
    let sag = 0.7 * (1.0 - (PI / 24.0).cos()) + 2.7 * ring_sag;
    for p in &g.mesh.positions {
        let d = p.distance(tube_centre(*p));
        assert!(
            d <= 0.7 + 1.3 * ring_sag + 1e-9 && d >= 0.7 - sag - 1e-9,
            "{d}"
        );
    }
    // The tube is covered all the way round: every grid row around the
    // tube (a patch side crossing the longitude) spans the full circle,
    // so the vertices' tube angles fill it without a gap over 60°.
    let mut angles: Vec<f64> = g
        .mesh
        .positions
        .iter()
        .map(|p| {
            let radial = DVec3::new(p.x, p.y, 0.0).length() - 2.0;
            p.z.atan2(radial)
        })
        .collect();
    angles.sort_by(f64::total_cmp);
    let gap = angles
        .windows(2)
        .map(|w| w[1] - w[0])
        .fold(angles[0] + 2.0 * PI - angles[angles.len() - 1], f64::max);
    assert!(gap < PI / 3.0, "gap {gap}");
}

#[test]
fn patch_polygons_follow_the_routes() {
    let mesh = sphere();
    let loops = octant_loops(&mesh);
    let r = Regions::compute(&mesh, &loops, &[]).unwrap();
    let layout = QuadLayout::build(&mesh, &loops, &r, &[]).unwrap();
    let (positions, faces) = patch_polygons(&layout.export()).unwrap();
    assert_eq!(faces.len(), 6);
    let inner: usize = layout.edges.iter().map(|e| e.polyline.len() - 2).sum();
    assert_eq!(positions.len(), 8 + inner);
    // A closed polygon mesh: every route point is shared by two patches.
    let m = PolyMesh::from_faces(positions, &faces).unwrap();
    assert!(m.boundary_loops().is_empty());
    assert_eq!(m.euler_characteristic(), 2);
}

/// `mesh` without the triangles around `vertices` (each leaves a hole of
/// its one-ring), unreferenced vertices dropped.
fn with_holes(mesh: &TriMesh, vertices: &[usize]) -> TriMesh {
    common::kept_triangles(mesh, |t| {
        !t.iter().any(|&v| vertices.contains(&(v as usize)))
    })
}

/// The input's boundary edges as segments.
fn boundary_segments(mesh: &TriMesh) -> Vec<[DVec3; 2]> {
    let mut directed = std::collections::HashSet::new();
    for t in &mesh.triangles {
        for k in 0..3 {
            directed.insert((t[k], t[(k + 1) % 3]));
        }
    }
    directed
        .iter()
        .filter(|&&(a, b)| !directed.contains(&(b, a)))
        .map(|&(a, b)| [mesh.positions[a as usize], mesh.positions[b as usize]])
        .collect()
}

/// A gridded layout's invariants around holes: a valid manifold of quads
/// with Euler characteristic `chi`, one boundary loop per hole (`holes`),
/// every vertex within `tolerance` of the input and every boundary vertex
/// on a rim segment (`rims`).
fn assert_gridded_around_holes(
    m: &PolyMesh,
    chi: i64,
    holes: usize,
    rims: &[[DVec3; 2]],
    index: &SurfaceIndex,
    tolerance: f64,
) {
    m.validate().expect("a valid, manifold half-edge mesh");
    assert!((0..m.face_count() as u32).all(|f| m.degree(f) == 4));
    assert_eq!(m.euler_characteristic(), chi);
    assert_eq!(m.boundary_loops().len(), holes, "a loop per hole");
    for (v, p) in m.positions.iter().enumerate() {
        assert!(index.distance(*p) < tolerance, "vertex {v} off the input");
    }
    for h in 0..m.halfedge_count() as u32 {
        if m.is_boundary_halfedge(h) {
            let p = m.positions[m.origin(h) as usize];
            let d = rims
                .iter()
                .map(|&s| distance_to_segment(p, s))
                .fold(f64::INFINITY, f64::min);
            assert!(
                d < 1e-9,
                "boundary vertex {} off the rims: {d}",
                m.origin(h)
            );
        }
    }
}

fn distance_to_segment(p: DVec3, [a, b]: [DVec3; 2]) -> f64 {
    let ab = b - a;
    let t = ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0);
    p.distance(a + t * ab)
}

/// Grids `mesh` (a sphere with holes the octant circles miss) and checks
/// the result: manifold pure quads on the surface, the input's Euler
/// characteristic and one boundary loop per hole, lying on the rims. The
/// `coarse` counts, too small to cut two holes apart, may fail instead,
/// naming the hole.
fn check_octant_grid_with_holes(mesh: &TriMesh, counts: &[u32], coarse: &[u32]) {
    let input = mesh.topology();
    let holes = boundary_segments(mesh);
    let loops = octant_loops(mesh);
    assert!(loops.iter().all(|l| l.closed), "the circles miss the holes");
    let r = Regions::compute(mesh, &loops, &[]).unwrap();
    assert!(r.sufficient, "{:?}", summary(&r));
    let hole_count = (2 - input.euler_characteristic) as usize;
    assert_eq!(
        r.regions.iter().map(|g| g.holes.len()).sum::<usize>(),
        hole_count
    );
    let layout = QuadLayout::build(mesh, &loops, &r, &[]).unwrap();
    assert_eq!(layout.holes.len(), hole_count);
    // The rims travel with the exported layout.
    let exported = LayoutExport::from_json(&layout.to_json().unwrap()).unwrap();
    assert_eq!(exported.holes.len(), hole_count);
    for (a, b) in exported.holes.iter().zip(&layout.holes) {
        assert_eq!(a.len(), b.len());
        assert!(a.iter().zip(b).all(|(p, q)| p.distance(*q) < 1e-12));
    }
    let index = SurfaceIndex::new(mesh).unwrap();
    for &n in coarse.iter().chain(counts) {
        let g = match grid_layout(&layout.export(), &[n; 3], mesh, &index) {
            Ok(g) => g,
            Err(e) if coarse.contains(&n) && e.to_string().contains("raise the grid counts") => {
                println!("grid {n}: {e}");
                continue;
            }
            Err(e) => panic!("grid {n}: {e}"),
        };
        let m = &g.mesh;
        assert_eq!(m.topology().components, 1);
        assert_gridded_around_holes(
            m,
            input.euler_characteristic,
            hole_count,
            &holes,
            &index,
            1e-9,
        );
        // No quad is folded, or pressed flat against a rim.
        let (corner, area) = worst_rim_quad(m);
        assert_eq!(g.folded, 0, "grid {n}: folded quads");
        assert!(corner < 170.0, "grid {n}: a corner of {corner:.1}°");
        assert!(area > 0.05, "grid {n}: a quad of {area:.3} the mean area");
        println!(
            "sphere with {hole_count} holes, grid {n}: {} vertices, {} quads, {} folded, \
             largest corner {corner:.1}°, smallest area {area:.3} × the mean",
            m.vertex_count(),
            m.face_count(),
            g.folded
        );
    }
}

/// Of the faces with a corner on the mesh boundary: the largest corner
/// angle (degrees) and the smallest area relative to the mean face area
/// (Newell areas).
fn worst_rim_quad(m: &PolyMesh) -> (f64, f64) {
    let mut on_boundary = vec![false; m.vertex_count()];
    for h in 0..m.halfedge_count() as u32 {
        if m.is_boundary_halfedge(h) {
            on_boundary[m.origin(h) as usize] = true;
        }
    }
    let faces = m.to_face_list();
    let mut corner: f64 = 0.0;
    let (mut areas, mut rim_areas) = (Vec::new(), Vec::new());
    for face in faces.iter() {
        let p: Vec<DVec3> = face.iter().map(|&v| m.positions[v as usize]).collect();
        let k = p.len();
        let rim = face.iter().any(|&v| on_boundary[v as usize]);
        let mut newell = DVec3::ZERO;
        for i in 0..k {
            let (prev, here, next) = (p[(i + k - 1) % k], p[i], p[(i + 1) % k]);
            if rim {
                corner = corner.max((prev - here).angle_between(next - here).to_degrees());
            }
            newell += here.cross(next);
        }
        areas.push(0.5 * newell.length());
        if rim {
            rim_areas.push(0.5 * newell.length());
        }
    }
    let mean = areas.iter().sum::<f64>() / areas.len() as f64;
    let least = rim_areas.iter().copied().fold(f64::INFINITY, f64::min);
    (corner, least / mean)
}

#[test]
fn sphere_with_holes_grids_around_them() {
    let sphere = sphere();
    let centres = octant_centres(&sphere);
    // Two small holes in two octants.
    let (a, b) = (centres[0].vertex as usize, centres[5].vertex as usize);
    check_octant_grid_with_holes(&with_holes(&sphere, &[a, b]), &[2, 3, 8], &[]);
    // Two in one octant (a count of 8 puts them in different quads), and
    // one more elsewhere.
    let near = (0..sphere.positions.len())
        .filter(|&v| {
            let d = sphere.positions[v].distance(sphere.positions[a]);
            d > 0.35 && d < 0.4
        })
        .min()
        .unwrap();
    let c = centres[7].vertex as usize;
    check_octant_grid_with_holes(&with_holes(&sphere, &[a, near, c]), &[8, 12], &[2, 4]);
}

#[test]
fn regions_touching_the_boundary_twice_are_red_and_say_why() {
    // Two parallel dual curves: the middle band touches the top and the
    // bottom of the square.
    let mesh = flat_grid(1.0, 10);
    let mut loops = plane_sections(&mesh, DVec3::X, 0.05);
    loops.extend(plane_sections(&mesh, DVec3::X, 0.45));
    let r = Regions::compute(&mesh, &loops, &[]).unwrap();
    assert_eq!(r.regions.len(), 3);
    assert!(!r.sufficient);
    let red: Vec<usize> = (0..3)
        .filter(|&g| r.regions[g].guidance == Guidance::NonDisc)
        .collect();
    assert_eq!(red.len(), 1);
    let band = &r.regions[red[0]];
    assert_eq!((band.euler, band.boundary_stretches()), (1, 2));
    let why = band.layout_blocker(red[0]).unwrap();
    assert!(why.contains(&format!("region {}", red[0])) && why.contains("2 stretches"));
    assert!(QuadLayout::build(&mesh, &loops, &r, &[]).is_err());
}

/// The Stanford bunny (a scan; 5 holes in its base, two of them 0.027
/// apart, the size being 1), designed on the page's ~30k-face proxy with
/// five plane sections that miss the holes — around the lower body, the
/// rump, the side, the neck and lengthwise over the head and one ear (the
/// small ring that plane cuts off the other ear is left out: crossed by no
/// other loop it would bound an annulus) — 14 patches, the holes inside
/// regions (capped, cut out of the grid), gridded on the input as the page
/// does. At 32 and 64 per strip: a manifold pure-quad mesh of the input's
/// Euler characteristic with one boundary loop per hole, on its rim, every
/// vertex on the input. Coarser counts name the hole whose cut touches
/// another's ("raise the grid counts"). Before the holes were cut from a
/// grid on the capped input (c56e7dc) this failed at 16: cut rings laid on
/// the chords of the proxy's rims, vertices off the input.
#[test]
fn bunny_layout_grids_around_its_holes() {
    let input = common::mesh("stanford-bunny.obj");
    let proxy = quadrille::layout::proxy::decimate(&input, quadrille::layout::proxy::PROXY_FACES);
    let planes = [
        (DVec3::Y, -0.25),
        (DVec3::X, 0.3),
        (DVec3::Z, 0.2),
        (DVec3::Y, 0.2),
        (DVec3::X, -0.34),
    ];
    let mut loops = Vec::new();
    for (n, d) in planes {
        let sections = plane_sections(&proxy, n, d);
        assert!(
            sections.iter().all(|l| l.closed),
            "the plane misses the holes"
        );
        loops.extend(sections.into_iter().filter(|l| l.crossings.len() >= 60));
    }
    assert_eq!(loops.len(), 5);
    let r = Regions::compute(&proxy, &loops, &[]).unwrap();
    assert!(r.sufficient, "{:?}", summary(&r));
    assert_eq!(r.regions.iter().map(|g| g.holes.len()).sum::<usize>(), 5);
    let layout = QuadLayout::build(&proxy, &loops, &r, &[]).unwrap();
    let mut exported = layout.export();
    let index = SurfaceIndex::new(&input).unwrap();
    exported.project_onto(&index);
    let chi = input.topology().euler_characteristic;
    let rims = boundary_segments(&input);
    for n in [8u32, 16, 32, 64] {
        let g = match grid_layout(&exported, &[n; 5], &input, &index) {
            Ok(g) => g,
            Err(e) if n < 32 && e.to_string().contains("raise the grid counts") => {
                println!("bunny, grid {n}: {e}");
                continue;
            }
            Err(e) => panic!("grid {n}: {e}"),
        };
        let m = &g.mesh;
        assert_gridded_around_holes(m, chi, 5, &rims, &index, 1e-6);
        let (corner, area) = worst_rim_quad(m);
        println!(
            "bunny, grid {n}: {} vertices, {} quads, {} folded; at the rims: largest corner \
             {corner:.1}°, smallest area {area:.3} × the mean",
            m.vertex_count(),
            m.face_count(),
            g.folded
        );
    }
}
