//! Strips of dual strip weaving (Campen & Kobbelt 2014, §6): loops on the
//! triangulation, the strip cross field, the global parametrization and
//! the strips grown from the loops.

use std::f64::consts::TAU;

use glam::DVec3;
use quadrille::layout::parametrization::{Parametrization, parametrize};
use quadrille::layout::strip_field::strip_field;
use quadrille::layout::{
    ElasticaParams, EmbeddedLoop, LoopEngine, StripParams, embed_loop, strip_analysis,
};
use quadrille::mesh::TriMesh;
use quadrille::mesh::generate::{cylinder, flat_grid, icosphere, torus};

fn engine(mesh: &TriMesh) -> LoopEngine {
    LoopEngine::new(mesh, &ElasticaParams::default())
}

/// Largest distance of a crossing from the polyline.
fn max_distance_to_polyline(mesh: &TriMesh, l: &EmbeddedLoop, points: &[DVec3]) -> f64 {
    l.crossings
        .iter()
        .map(|c| {
            let p = c.point(mesh);
            points
                .windows(2)
                .map(|w| {
                    let d = w[1] - w[0];
                    let s = ((p - w[0]).dot(d) / d.length_squared().max(1e-300)).clamp(0.0, 1.0);
                    p.distance(w[0] + s * d)
                })
                .fold(f64::INFINITY, f64::min)
        })
        .fold(0.0, f64::max)
}

fn mean_edge(mesh: &TriMesh) -> f64 {
    let mut s = 0.0;
    for t in &mesh.triangles {
        for i in 0..3 {
            s += mesh.positions[t[i] as usize].distance(mesh.positions[t[(i + 1) % 3] as usize]);
        }
    }
    s / (3 * mesh.triangles.len()) as f64
}

#[test]
fn engine_loops_embed_as_valid_walks_near_the_polyline() {
    let meshes = [
        (
            "cylinder",
            cylinder(1.0, 6.0, 48, 64),
            DVec3::new(1.0, 0.0, 0.3),
        ),
        ("torus", torus(2.0, 0.7, 64, 24), DVec3::new(2.7, 0.0, 0.0)),
        (
            "sphere",
            icosphere(1.0, 4),
            DVec3::new(0.3, 0.5, 0.81).normalize(),
        ),
    ];
    for (name, mesh, p) in meshes {
        let mut e = engine(&mesh);
        let l = e.best_loop(p).expect("a loop");
        let emb = embed_loop(&mesh, &l.points, l.closed).expect("embedded");
        emb.check(&mesh).unwrap_or_else(|m| panic!("{name}: {m}"));
        assert_eq!(emb.closed, l.closed);
        let d = max_distance_to_polyline(&mesh, &emb, &l.points);
        let h = mean_edge(&mesh);
        println!(
            "{name}: {} crossings, max distance {d:.4} (mean edge {h:.4})",
            emb.crossings.len()
        );
        assert!(
            d < 1.0 * h,
            "{name}: crossing {d} from the polyline (mean edge {h})"
        );
    }
}

#[test]
fn polyline_through_vertices_embeds_validly() {
    // The cylinder's ring of vertices at one height: every point is a vertex.
    let (segments, stacks) = (32u32, 16u32);
    let mesh = cylinder(1.0, 4.0, segments, stacks);
    let z = mesh.positions[(5 * segments) as usize].z;
    let mut ring: Vec<DVec3> = mesh
        .positions
        .iter()
        .copied()
        .filter(|p| (p.z - z).abs() < 1e-9)
        .collect();
    assert_eq!(ring.len(), segments as usize);
    ring.sort_by(|a, b| a.y.atan2(a.x).total_cmp(&b.y.atan2(b.x)));
    ring.push(ring[0]);
    let emb = embed_loop(&mesh, &ring, true).expect("embedded");
    emb.check(&mesh).unwrap();
    // Perturbed off the vertices, it stays within one ring of the circle and
    // goes round once: every crossing near height z.
    let h = 4.0 / stacks as f64;
    for c in &emb.crossings {
        assert!((c.point(&mesh).z - z).abs() <= h, "{c:?}");
    }
    let mut turn = 0.0;
    let pts: Vec<DVec3> = emb.crossings.iter().map(|c| c.point(&mesh)).collect();
    for i in 0..pts.len() {
        let (a, b) = (pts[i], pts[(i + 1) % pts.len()]);
        let mut d = b.y.atan2(b.x) - a.y.atan2(a.x);
        if d > TAU / 2.0 {
            d -= TAU;
        } else if d < -TAU / 2.0 {
            d += TAU;
        }
        turn += d;
    }
    assert!((turn.abs() - TAU).abs() < 1e-6, "winds {turn}");

    // An open polyline along a grid line of a flat grid, vertex to vertex,
    // from boundary to boundary.
    let grid = flat_grid(1.0, 10);
    let mut line: Vec<DVec3> = grid
        .positions
        .iter()
        .copied()
        .filter(|p| p.y.abs() < 1e-9)
        .collect();
    line.sort_by(|a, b| a.x.total_cmp(&b.x));
    let emb = embed_loop(&grid, &line, false).expect("embedded");
    emb.check(&grid).unwrap();
    assert!(
        emb.crossings
            .iter()
            .all(|c| c.point(&grid).y.abs() <= 0.2 + 1e-9)
    );
}

/// Deviation (degrees) of a cross arm from a direction, modulo π/2.
fn cross_deviation_deg(arm: DVec3, dir: DVec3) -> f64 {
    let a = arm
        .normalize()
        .dot(dir.normalize())
        .abs()
        .min(1.0)
        .acos()
        .to_degrees();
    a.min(90.0 - a)
}

fn great_circle(normal: DVec3, samples: usize) -> Vec<DVec3> {
    let u = normal.any_orthonormal_vector();
    let v = normal.cross(u);
    (0..=samples)
        .map(|k| {
            let a = TAU * k as f64 / samples as f64;
            u * a.cos() + v * a.sin()
        })
        .collect()
}

fn three_great_circles(mesh: &TriMesh) -> Vec<EmbeddedLoop> {
    [DVec3::X, DVec3::Y, DVec3::Z]
        .into_iter()
        .map(|n| embed_loop(mesh, &great_circle(n, 400), true).expect("embedded"))
        .collect()
}

#[test]
fn cylinder_loop_field_follows_the_circumference() {
    let mesh = cylinder(1.0, 8.0, 48, 64);
    let mut e = engine(&mesh);
    let l = e.best_loop(DVec3::new(1.0, 0.0, 0.3)).expect("a loop");
    assert!(l.closed, "the circumference is shorter than the height");
    let emb = embed_loop(&mesh, &l.points, true).unwrap();
    let field = strip_field(&mesh, &[emb]).expect("a field");
    let mut worst: f64 = 0.0;
    for (f, arm) in field.cross.iter().enumerate() {
        let c = mesh.corners(f);
        let m = (c[0] + c[1] + c[2]) / 3.0;
        worst = worst.max(cross_deviation_deg(*arm, DVec3::new(-m.y, m.x, 0.0)));
    }
    println!("cylinder: max deviation from the circumference {worst:.3}°");
    assert!(worst < 5.0, "max deviation {worst}°");
    assert!(field.singularities.is_empty(), "{:?}", field.singularities);
}

#[test]
fn field_singularities_obey_poincare_hopf() {
    let sphere = icosphere(1.0, 4);
    let mut e = engine(&sphere);
    let l = e
        .best_loop(DVec3::new(0.3, 0.5, 0.81).normalize())
        .expect("a loop");
    let emb = embed_loop(&sphere, &l.points, true).unwrap();
    let field = strip_field(&sphere, &[emb]).expect("a field");
    let sum: i32 = field.singularities.iter().map(|s| s.index).sum();
    println!(
        "sphere, one loop: {} singularities, Σ index {sum}",
        field.singularities.len()
    );
    assert_eq!(sum, 8, "{:?}", field.singularities);

    let tor = torus(2.0, 0.7, 64, 24);
    let mut e = engine(&tor);
    let loops: Vec<EmbeddedLoop> = [DVec3::new(2.7, 0.0, 0.0), DVec3::new(0.0, 1.3, 0.0)]
        .into_iter()
        .map(|p| {
            let l = e.best_loop(p).expect("a loop");
            embed_loop(&tor, &l.points, true).unwrap()
        })
        .collect();
    let field = strip_field(&tor, &loops).expect("a field");
    let sum: i32 = field.singularities.iter().map(|s| s.index).sum();
    println!(
        "torus: {} singularities, Σ index {sum}",
        field.singularities.len()
    );
    assert_eq!(sum, 0, "{:?}", field.singularities);
}

#[test]
fn three_great_circles_give_one_singularity_per_octant() {
    let sphere = icosphere(1.0, 4);
    let loops = three_great_circles(&sphere);
    let field = strip_field(&sphere, &loops).expect("a field");
    println!("{:?}", field.singularities);
    assert_eq!(field.singularities.len(), 8, "{:?}", field.singularities);
    let mut octants: Vec<u8> = field
        .singularities
        .iter()
        .map(|s| {
            assert_eq!(s.index, 1);
            let p = sphere.positions[s.vertex as usize];
            (p.x > 0.0) as u8 | ((p.y > 0.0) as u8) << 1 | ((p.z > 0.0) as u8) << 2
        })
        .collect();
    octants.sort_unstable();
    octants.dedup();
    assert_eq!(octants.len(), 8);
}

#[test]
fn no_loops_no_field() {
    assert!(strip_field(&icosphere(1.0, 2), &[]).is_none());
}

fn torus_meridian(u0: f64, big: f64, small: f64) -> Vec<DVec3> {
    (0..=300)
        .map(|k| {
            let v = TAU * k as f64 / 300.0;
            let ring = big + small * v.cos();
            DVec3::new(ring * u0.cos(), ring * u0.sin(), small * v.sin())
        })
        .collect()
}

fn torus_longitude(v0: f64, big: f64, small: f64) -> Vec<DVec3> {
    (0..=600)
        .map(|k| {
            let u = TAU * k as f64 / 600.0;
            let ring = big + small * v0.cos();
            DVec3::new(ring * u.cos(), ring * u.sin(), small * v0.sin())
        })
        .collect()
}

fn spacing(mesh: &TriMesh) -> f64 {
    0.02 * mesh.bbox().unwrap().diagonal()
}

/// Spread of the transversal coordinate over the loop's crossings.
fn isoline_spread(mesh: &TriMesh, p: &Parametrization, l: &EmbeddedLoop) -> f64 {
    let chart = p.loop_chart(mesh, l).expect("a chart");
    let t: Vec<f64> = chart.values.iter().map(|x| x[chart.comp]).collect();
    t.iter().copied().fold(f64::MIN, f64::max) - t.iter().copied().fold(f64::MAX, f64::min)
}

#[test]
fn torus_loops_are_isolines_and_the_map_is_fold_free() {
    let (big, small) = (2.0, 0.7);
    let mesh = torus(big, small, 64, 24);
    let loops = vec![
        embed_loop(&mesh, &torus_meridian(0.05, big, small), true).unwrap(),
        embed_loop(&mesh, &torus_longitude(1.3, big, small), true).unwrap(),
    ];
    let field = strip_field(&mesh, &loops).unwrap();
    let p = parametrize(&mesh, &field, &loops).expect("a parametrization");
    let h = spacing(&mesh);
    for l in &loops {
        let spread = isoline_spread(&mesh, &p, l);
        println!(
            "torus: isoline spread {spread:.2e} ({:.3} % of the spacing {h:.3})",
            100.0 * spread / h
        );
        assert!(spread < 0.01 * h);
    }
    // Fold-free away from singularities (two rings).
    let vf = quadrille::mesh::VertexFaces::new(&mesh);
    let mut near = vec![false; mesh.positions.len()];
    for s in &field.singularities {
        for &f in vf.faces(s.vertex as usize) {
            for &v in &mesh.triangles[f as usize] {
                near[v as usize] = true;
            }
        }
    }
    let folded: Vec<usize> = (0..mesh.triangles.len())
        .filter(|&f| p.folded[f] && !mesh.triangles[f].iter().any(|&v| near[v as usize]))
        .collect();
    println!(
        "torus: {} singularities, {} folded faces away from them",
        field.singularities.len(),
        folded.len()
    );
    assert!(folded.is_empty(), "{folded:?}");
}

#[test]
fn sphere_great_circles_are_isolines() {
    let sphere = icosphere(1.0, 4);
    let loops = three_great_circles(&sphere);
    let field = strip_field(&sphere, &loops).unwrap();
    let p = parametrize(&sphere, &field, &loops).expect("a parametrization");
    let h = spacing(&sphere);
    for l in &loops {
        let spread = isoline_spread(&sphere, &p, l);
        println!(
            "sphere: isoline spread {spread:.2e} ({:.3} % of the spacing {h:.3})",
            100.0 * spread / h
        );
        assert!(spread < 0.01 * h);
    }
    let folded = p.folded.iter().filter(|&&x| x).count();
    println!(
        "sphere: {folded} folded faces of {}",
        sphere.triangles.len()
    );
}

fn circle_at(z: f64, samples: usize) -> Vec<DVec3> {
    (0..=samples)
        .map(|k| {
            let a = TAU * k as f64 / samples as f64;
            DVec3::new(a.cos(), a.sin(), z)
        })
        .collect()
}

#[test]
fn cylinder_strip_covers_the_cylinder_with_circular_stripes() {
    let mesh = cylinder(1.0, 8.0, 48, 64);
    let mut e = engine(&mesh);
    let l = e.best_loop(DVec3::new(1.0, 0.0, 0.3)).expect("a loop");
    let engine_loop = embed_loop(&mesh, &l.points, l.closed).unwrap();
    let exact_circle = embed_loop(&mesh, &circle_at(0.3, 400), true).unwrap();
    for (name, emb) in [("engine loop", engine_loop), ("circle", exact_circle)] {
        let a = strip_analysis(&mesh, &[emb], &StripParams::default());
        assert!(a.singularities.is_empty(), "{name}: {:?}", a.singularities);
        assert_eq!(a.strips.len(), 1, "{name}: {:?}", a.notes);
        let s = &a.strips[0];
        println!(
            "cylinder ({name}): strip of {} / {} faces, extent {:.3} / {:.3}, field {:.1} ms, param {:.1} ms, strips {:.1} ms",
            s.faces.len(),
            mesh.triangles.len(),
            s.left,
            s.right,
            a.field_ms,
            a.parametrization_ms,
            a.strips_ms
        );
        assert_eq!(
            s.faces.len(),
            mesh.triangles.len(),
            "{name}: the strip covers everything"
        );
        assert!(
            a.covered.iter().all(|c| c.len() == 1),
            "one strip, one direction per vertex"
        );
        let worst_dir = a
            .covered
            .iter()
            .flatten()
            .map(|d| d.z.abs())
            .fold(0.0, f64::max);
        println!("cylinder ({name}): covered directions max |z| {worst_dir:.4}");
        assert!(
            worst_dir < 0.1,
            "{name}: covered direction not circumferential"
        );
        let segments = s.stripe_segments(&mesh, a.spacing);
        assert!(!segments.is_empty());
        let worst = segments
            .iter()
            .map(|[p, q]| (p.z - q.z).abs())
            .fold(0.0, f64::max);
        // Stripes are circles: on the exact circle's strip the two ends of
        // every segment lie at one height; their count per level is the
        // number of faces between two rings of the mesh.
        println!(
            "cylinder ({name}): {} stripe segments, max height change along one {worst:.2e} (spacing {:.3})",
            segments.len(),
            a.spacing
        );
        if name == "circle" {
            assert!(worst < 0.05 * a.spacing, "stripe not horizontal: {worst}");
        }
    }
}

#[test]
fn sphere_strip_stops_at_the_singularities() {
    // Equator only: the field follows the parallels; its 8 singularities
    // (index +1) cluster around the poles.
    let sphere = icosphere(1.0, 4);
    let equator = embed_loop(&sphere, &great_circle(DVec3::Z, 400), true).unwrap();
    let a = strip_analysis(&sphere, &[equator], &StripParams::default());
    assert_eq!(a.singularities.len(), 8, "{:?}", a.singularities);
    let s = &a.strips[0];
    let mut in_strip = vec![false; sphere.triangles.len()];
    for &f in &s.faces {
        in_strip[f as usize] = true;
    }
    let singular: Vec<u32> = a.singularities.iter().map(|x| x.vertex).collect();
    let sing_z = a
        .singularities
        .iter()
        .map(|x| sphere.positions[x.vertex as usize].z.abs());
    let lowest = sing_z.fold(f64::MAX, f64::min);
    let centre_z = |f: usize| sphere.corners(f).iter().map(|p| p.z).sum::<f64>() / 3.0;
    println!(
        "sphere, equator: strip of {} / {} faces, extent {:.3} / {:.3}, singularities at |z| ≥ {lowest:.3}",
        s.faces.len(),
        sphere.triangles.len(),
        s.left,
        s.right
    );
    for &f in &s.faces {
        assert!(
            !sphere.triangles[f as usize]
                .iter()
                .any(|v| singular.contains(v)),
            "strip face {f} touches a singularity"
        );
    }
    // Everything well below the singularities is covered, the caps are not.
    let band_z = lowest - 0.05;
    assert!(
        (0..sphere.triangles.len())
            .filter(|&f| centre_z(f).abs() < band_z)
            .all(|f| in_strip[f])
    );
    let north_out = (0..sphere.triangles.len())
        .filter(|&f| !in_strip[f] && centre_z(f) > 0.0)
        .count();
    let south_out = (0..sphere.triangles.len())
        .filter(|&f| !in_strip[f] && centre_z(f) < 0.0)
        .count();
    assert!(
        north_out > 0 && south_out > 0,
        "a pole is covered ({north_out}, {south_out} faces left out)"
    );

    // Three great circles: the layout is the cube's (singularities at the
    // octant centres = cube corners, at geodesic distance asin(1/√3) ≈ 0.615
    // from every circle). Each strip is a belt of four cube faces, bounded
    // by the cube edges through the corners: it reaches farthest from its
    // circle at the edge midpoints, where the other two circles cross, at
    // geodesic distance π/4 (to within an edge length ≈ 0.08: strip faces
    // straddle the bounding isoline). A strip leaking past the corners
    // would reach π/2.
    let loops = three_great_circles(&sphere);
    let a = strip_analysis(&sphere, &loops, &StripParams::default());
    assert_eq!(a.strips.len(), 3);
    let expected = (1.0 / 3f64.sqrt()).asin();
    for (s, n) in a.strips.iter().zip([DVec3::X, DVec3::Y, DVec3::Z]) {
        let reach = s
            .faces
            .iter()
            .flat_map(|&f| sphere.triangles[f as usize])
            .map(|v| sphere.positions[v as usize].dot(n).abs().min(1.0).asin())
            .fold(0.0, f64::max);
        println!(
            "sphere, 3 circles: strip of {} faces, extent {:.3} / {:.3} in S, reaches geodesic distance {reach:.3} (cube edge midpoints at π/4, corners at {expected:.3})",
            s.faces.len(),
            s.left,
            s.right
        );
        let pi4 = std::f64::consts::FRAC_PI_4;
        assert!((reach - pi4).abs() < 0.08, "reach {reach}");
    }
    // The three strips overlap and together cover the sphere except next to
    // the singularities (§6.2).
    let covered = a.covered.iter().filter(|c| !c.is_empty()).count();
    println!(
        "sphere, 3 circles: {covered} / {} vertices covered",
        sphere.positions.len()
    );
    assert!(covered as f64 > 0.99 * sphere.positions.len() as f64);
    // Where strips overlap, every strip keeps its own direction (§6.2): at a
    // vertex on the circle z = 0 (strip Z's spine, tangent ⟂ z) covered by
    // strip X or Y too, both directions are kept, and they are transversal.
    let mut doubly = 0;
    for (v, ds) in a.covered.iter().enumerate() {
        if ds.len() >= 2 {
            doubly += 1;
            let p = sphere.positions[v];
            if p.z.abs() < 0.02 {
                assert!(
                    ds.iter().any(|d| d.z.abs() < 0.5),
                    "vertex {v} on strip Z's spine lost its direction: {ds:?}"
                );
                assert!(
                    ds.iter().any(|d| d.z.abs() > 0.5),
                    "vertex {v}: the crossing strip's direction is lost: {ds:?}"
                );
            }
        }
        assert!(ds.len() <= 3, "at most one direction per strip");
    }
    println!("sphere, 3 circles: {doubly} vertices covered by two or three strips");
    assert!(
        doubly as f64 > 0.3 * sphere.positions.len() as f64,
        "strips overlap: {doubly}"
    );
}

#[test]
fn malformed_loops_are_skipped_with_a_note() {
    let mesh = cylinder(1.0, 8.0, 24, 32);
    let good = embed_loop(&mesh, &circle_at(0.3, 200), true).unwrap();
    let bad = EmbeddedLoop {
        crossings: vec![quadrille::layout::EdgeCrossing {
            a: 0,
            b: 99_999,
            t: 0.5,
        }],
        faces: vec![7, 123_456],
        closed: true,
    };
    let empty = EmbeddedLoop::default();
    let a = strip_analysis(
        &mesh,
        &[bad.clone(), good, empty.clone()],
        &StripParams::default(),
    );
    assert_eq!(a.strips.len(), 1);
    assert_eq!(a.strips[0].loop_index, 1);
    assert_eq!(a.notes.len(), 2, "{:?}", a.notes);
    let none = strip_analysis(&mesh, &[bad, empty], &StripParams::default());
    assert!(none.strips.is_empty() && none.uv.is_empty());
    assert!(embed_loop(&mesh, &[DVec3::new(f64::NAN, 0.0, 0.0), DVec3::X], false).is_err());
    assert!(embed_loop(&mesh, &[DVec3::X], true).is_err());
}

#[test]
fn covered_directions_make_the_next_loop_transversal() {
    // §6.2: after committing the circumference of a cylinder, hovering
    // elsewhere must not propose a parallel loop again.
    let mesh = cylinder(1.0, 8.0, 48, 64);
    let mut e = engine(&mesh);
    let first = e.best_loop(DVec3::new(1.0, 0.0, 0.3)).expect("a loop");
    let emb = embed_loop(&mesh, &first.points, first.closed).unwrap();
    let a = strip_analysis(&mesh, &[emb], &StripParams::default());
    e.set_covered(&a.covered);
    let anchor = DVec3::new(0.0, 1.0, -2.0);
    match e.best_loop(anchor) {
        None => println!("no further loop"),
        Some(l) => {
            let i = (0..l.points.len())
                .min_by(|&x, &y| {
                    l.points[x]
                        .distance(anchor)
                        .total_cmp(&l.points[y].distance(anchor))
                })
                .unwrap();
            let (p, q) = (
                l.points[i.saturating_sub(1)],
                l.points[(i + 1).min(l.points.len() - 1)],
            );
            let d = (q - p).normalize();
            println!("next loop: closed {}, tangent {d:.3}", l.closed);
            assert!(
                d.z.abs() > std::f64::consts::FRAC_1_SQRT_2,
                "a loop parallel to the strip: {d}"
            );
        }
    }
}

/// Whether {a, b} is a boundary edge (held by one triangle).
fn is_boundary_edge(mesh: &TriMesh, a: u32, b: u32) -> bool {
    mesh.triangles
        .iter()
        .filter(|t| {
            (0..3).any(|i| (t[i], t[(i + 1) % 3]) == (a, b) || (t[i], t[(i + 1) % 3]) == (b, a))
        })
        .count()
        == 1
}

/// Dual curves (§5.7) start and end at boundary vertices; embedded, they
/// must start and end on boundary edges (the regions of §4.2 rely on it),
/// whichever face of the end vertex's fan the first samples fall in.
#[test]
fn engine_dual_curves_embed_from_boundary_edge_to_boundary_edge() {
    let mut curves = 0;
    for mesh in [flat_grid(1.0, 16), cylinder(1.0, 3.0, 24, 12)] {
        let mut e = engine(&mesh);
        let n = mesh.vertex_count();
        for v in (0..n).step_by(n / 40) {
            let Some(l) = e.best_loop(mesh.positions[v]) else {
                continue;
            };
            if l.closed {
                continue;
            }
            let emb = embed_loop(&mesh, &l.points, false).expect("embeds");
            emb.check(&mesh).expect("a valid walk");
            let (first, last) = (emb.crossings[0], emb.crossings[emb.crossings.len() - 1]);
            assert!(
                is_boundary_edge(&mesh, first.a, first.b),
                "vertex {v}: starts inside"
            );
            assert!(
                is_boundary_edge(&mesh, last.a, last.b),
                "vertex {v}: ends inside"
            );
            quadrille::layout::regions::Regions::compute(&mesh, &[emb], &[]).expect("regions");
            curves += 1;
        }
    }
    assert!(curves >= 20, "only {curves} dual curves");
}
