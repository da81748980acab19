//! Dual strip weaving part 1 (Campen & Kobbelt 2014 §5, §6.2): the elastica
//! loop engine on analytic surfaces with known best loops.

use std::f64::consts::{PI, TAU};

use glam::DVec3;
use quadrille::layout::{Anchor, DualLoop, ElasticaParams, LoopEngine};
use quadrille::mesh::TriMesh;
use quadrille::mesh::generate::{cylinder, flat_grid, icosphere, torus};

/// Closed capsule around the z axis: a cylinder of `radius` and `height`
/// with hemispherical caps; `segments` around, `rings` per cap quadrant.
fn capsule(radius: f64, height: f64, segments: u32, stacks: u32, rings: u32) -> TriMesh {
    let mut positions = Vec::new();
    let mut rows: Vec<(f64, f64)> = Vec::new(); // (z, ring radius)
    for i in 1..=rings {
        let a = -PI / 2.0 + PI / 2.0 * i as f64 / rings as f64;
        rows.push((-height / 2.0 + radius * a.sin(), radius * a.cos()));
    }
    for j in 1..stacks {
        rows.push((-height / 2.0 + height * j as f64 / stacks as f64, radius));
    }
    for i in 0..rings {
        let a = PI / 2.0 * i as f64 / rings as f64;
        rows.push((height / 2.0 + radius * a.sin(), radius * a.cos()));
    }
    positions.push(DVec3::new(0.0, 0.0, -height / 2.0 - radius));
    for &(z, r) in &rows {
        for k in 0..segments {
            let t = TAU * k as f64 / segments as f64;
            positions.push(DVec3::new(r * t.cos(), r * t.sin(), z));
        }
    }
    positions.push(DVec3::new(0.0, 0.0, height / 2.0 + radius));
    let top = positions.len() as u32 - 1;
    let s = segments;
    let idx = |row: u32, k: u32| 1 + row * s + k % s;
    let mut triangles = Vec::new();
    for k in 0..s {
        triangles.push([0, idx(0, k + 1), idx(0, k)]);
    }
    for row in 0..rows.len() as u32 - 1 {
        for k in 0..s {
            let (a, b, c, d) = (
                idx(row, k),
                idx(row, k + 1),
                idx(row + 1, k + 1),
                idx(row + 1, k),
            );
            triangles.push([a, b, c]);
            triangles.push([a, c, d]);
        }
    }
    let last = rows.len() as u32 - 1;
    for k in 0..s {
        triangles.push([idx(last, k), idx(last, k + 1), top]);
    }
    TriMesh::new(positions, triangles).unwrap()
}

fn engine(mesh: &TriMesh) -> LoopEngine {
    LoopEngine::new(mesh, &ElasticaParams::default())
}

/// Unit tangent of the loop's polyline nearest to `p`.
/// Central difference at the polyline point nearest `p`.
fn tangent_near(l: &DualLoop, p: DVec3) -> DVec3 {
    let n = l.points.len();
    let i = (0..n)
        .min_by(|&a, &b| l.points[a].distance(p).total_cmp(&l.points[b].distance(p)))
        .unwrap();
    let (a, b) = if l.closed && (i == 0 || i == n - 1) {
        (l.points[n - 2], l.points[1])
    } else {
        (l.points[i.saturating_sub(1)], l.points[(i + 1).min(n - 1)])
    };
    (b - a).normalize_or_zero()
}

fn distance_to(l: &DualLoop, p: DVec3) -> f64 {
    l.points
        .iter()
        .map(|q| q.distance(p))
        .fold(f64::INFINITY, f64::min)
}

fn angle_deg(a: DVec3, b: DVec3) -> f64 {
    a.normalize()
        .dot(b.normalize())
        .abs()
        .min(1.0)
        .acos()
        .to_degrees()
}

#[test]
fn cylinder_best_loop_is_the_circumference() {
    let (r, h) = (1.0, 8.0);
    let mesh = cylinder(r, h, 48, 96);
    let mut e = engine(&mesh);
    let anchor = DVec3::new(r, 0.0, 0.3);
    let l = e.best_loop(anchor).expect("a loop");
    assert!(l.closed, "expected a closed loop, got a dual curve");
    let len = l.length();
    assert!(
        (len - TAU * r).abs() < 0.03 * TAU * r,
        "length {len}, circumference {}",
        TAU * r
    );
    let z0 = l.points[0].z;
    let dz = l
        .points
        .iter()
        .map(|p| (p.z - z0).abs())
        .fold(0.0, f64::max);
    assert!(dz < 0.1, "not planar: z spread {dz}");
}

#[test]
fn capsule_axial_anchor_gives_the_long_loop() {
    let (r, h) = (1.0, 4.0);
    let mesh = capsule(r, h, 40, 40, 10);
    let mut e = engine(&mesh);
    let l = e
        .constrained_loop(&[Anchor::directional(DVec3::new(r, 0.0, 0.0), DVec3::Z)])
        .expect("a loop");
    assert!(l.closed);
    let zmax = l.points.iter().map(|p| p.z).fold(f64::MIN, f64::max);
    let zmin = l.points.iter().map(|p| p.z).fold(f64::MAX, f64::min);
    assert!(
        zmax > h / 2.0 + 0.8 * r && zmin < -h / 2.0 - 0.8 * r,
        "z range {zmin}..{zmax}"
    );
    let expected = 2.0 * h + TAU * r;
    assert!(
        (l.length() - expected).abs() < 0.05 * expected,
        "length {}",
        l.length()
    );
}

/// Windings (around the z axis, around the tube) of a closed polyline on a
/// torus of major radius `major`.
fn windings(l: &DualLoop, major: f64) -> (i32, i32) {
    let (mut u, mut v) = (0.0, 0.0);
    let angles = |p: DVec3| (p.y.atan2(p.x), p.z.atan2(p.truncate().length() - major));
    for w in l.points.windows(2) {
        let (a, b) = (angles(w[0]), angles(w[1]));
        let wrap = |d: f64| (d + PI).rem_euclid(TAU) - PI;
        u += wrap(b.0 - a.0);
        v += wrap(b.1 - a.1);
    }
    ((u / TAU).round() as i32, (v / TAU).round() as i32)
}

#[test]
fn torus_principal_directions_give_both_homotopy_classes() {
    let (big, small) = (2.0, 0.7);
    let mesh = torus(big, small, 72, 28);
    let mut e = engine(&mesh);
    let p = DVec3::new(big + small, 0.0, 0.0);
    let around_tube = e
        .constrained_loop(&[Anchor::directional(p, DVec3::Z)])
        .expect("loop around the tube");
    let around_hole = e
        .constrained_loop(&[Anchor::directional(p, DVec3::Y)])
        .expect("loop around the hole");
    let (u1, v1) = windings(&around_tube, big);
    let (u2, v2) = windings(&around_hole, big);
    assert_eq!((u1, v1.abs()), (0, 1), "tube loop windings");
    assert_eq!((u2.abs(), v2), (1, 0), "hole loop windings");
    // The unconstrained alternatives contain both classes too.
    let alts = e.loops_through(p, 4);
    let classes: Vec<(i32, i32)> = alts
        .iter()
        .map(|l| {
            let (a, b) = windings(l, big);
            (a.abs(), b.abs())
        })
        .collect();
    assert!(
        classes.contains(&(0, 1)) && classes.contains(&(1, 0)),
        "{classes:?}"
    );
}

#[test]
fn anchors_are_interpolated() {
    let mesh = capsule(1.0, 3.0, 32, 24, 8);
    let mut e = engine(&mesh);
    let anchors = [
        Anchor::positional(DVec3::new(1.0, 0.0, 0.5)),
        Anchor::directional(DVec3::new(0.0, 1.0, 0.0), DVec3::new(-1.0, 0.0, 1.0)),
        Anchor::positional(DVec3::new(-1.0, 0.0, -0.5)),
    ];
    let l = e.constrained_loop(&anchors).expect("a loop");
    // One ring: the longest mesh edge is below 0.3 here.
    for a in &anchors {
        let d = distance_to(&l, a.position);
        assert!(d < 0.3, "anchor {:?} missed by {d}", a.position);
        if a.direction != DVec3::ZERO {
            let t = tangent_near(&l, a.position);
            let ang = angle_deg(t, a.direction);
            assert!(ang < 15.0, "direction off by {ang}°");
        }
    }
}

#[test]
fn committed_loop_is_crossed_transversally() {
    let mesh = icosphere(1.0, 4);
    let mut e = engine(&mesh);
    let p = DVec3::new(1.0, 0.2, 0.1).normalize();
    let first = e.best_loop(p).expect("a first loop");
    e.cover_loop(&first, 0.25);
    assert!(e.disabled_count() > 0);
    // A point on the committed loop.
    let on = first.points[first.points.len() / 3];
    let second = e.best_loop(on).expect("a second loop");
    let t1 = tangent_near(&first, on);
    let t2 = tangent_near(&second, on);
    let ang = angle_deg(t1, t2);
    assert!(ang > 45.0, "crossing angle {ang}°");
}

#[test]
fn dual_curves_end_orthogonally_on_the_boundary() {
    let mesh = flat_grid(1.0, 30);
    let mut e = engine(&mesh);
    for p in [
        DVec3::new(0.1, 0.2, 0.0),
        DVec3::new(-0.3, 0.4, 0.0),
        DVec3::new(0.5, -0.1, 0.0),
    ] {
        let alts = e.loops_through(p, 3);
        assert!(!alts.is_empty());
        for l in alts.iter().filter(|l| !l.closed) {
            let n = l.points.len();
            for (a, b) in [
                (l.points[1], l.points[0]),
                (l.points[n - 2], l.points[n - 1]),
            ] {
                let end = b;
                // The boundary of the square [-1, 1]²: its normal at `end`.
                let normal = if (end.x.abs() - 1.0).abs() < 1e-9 && (end.y.abs() - 1.0).abs() > 1e-9
                {
                    DVec3::X
                } else if (end.y.abs() - 1.0).abs() < 1e-9 && (end.x.abs() - 1.0).abs() > 1e-9 {
                    DVec3::Y
                } else {
                    continue; // a corner: no single normal
                };
                let ang = angle_deg(b - a, normal);
                assert!(
                    ang < 20.0,
                    "meets the boundary {ang}° off orthogonal at {end:?}"
                );
            }
        }
        assert!(
            alts.iter().any(|l| !l.closed),
            "no dual curve through {p:?}"
        );
    }
}

/// Issue 10: every g-edge within k = 4 rings of the boundary used to be at
/// distance 0 from ∂, so anchors near the boundary got one-node, zero-cost
/// "dual curves". On the flat square (30 × 30 grid, spacing h = 2/30), the
/// hover result through every vertex within 4 rings of the boundary must be
/// a real crossing: positive cost, polyline length at least 2h (a curve
/// leaves the boundary, takes at least one arc and arrives at it again),
/// both ends on the boundary and, away from corners, within 20° of
/// orthogonal to it, and passing through the anchor.
#[test]
fn dual_curves_near_the_boundary_cross_the_surface() {
    let n = 30;
    let h = 2.0 / n as f64;
    let mesh = flat_grid(1.0, n);
    let mut e = engine(&mesh);
    let on_boundary = |p: DVec3| (p.x.abs() - 1.0).abs() < 1e-9 || (p.y.abs() - 1.0).abs() < 1e-9;
    let mut checked = 0;
    for &p in &mesh.positions {
        let rings = ((1.0 - p.x.abs()).min(1.0 - p.y.abs()) / h).round();
        if rings > 4.0 {
            continue;
        }
        checked += 1;
        let l = e
            .best_loop(p)
            .unwrap_or_else(|| panic!("no curve through {p:?}"));
        assert!(l.cost > 0.0, "zero-cost curve through {p:?}: {l:?}");
        if l.closed {
            continue;
        }
        let length: f64 = l.points.windows(2).map(|w| w[0].distance(w[1])).sum();
        assert!(
            length >= 2.0 * h - 1e-9,
            "curve through {p:?} of length {length}"
        );
        assert!(l.nodes.len() >= 2, "one-node curve through {p:?}");
        assert!(
            distance_to(&l, p) < 1e-9,
            "curve misses its anchor {p:?} by {}",
            distance_to(&l, p)
        );
        let m = l.points.len();
        for (a, b) in [
            (l.points[1], l.points[0]),
            (l.points[m - 2], l.points[m - 1]),
        ] {
            assert!(on_boundary(b), "curve through {p:?} ends inside at {b:?}");
            let normal = if (b.x.abs() - 1.0).abs() < 1e-9 && (b.y.abs() - 1.0).abs() > 1e-9 {
                DVec3::X
            } else if (b.y.abs() - 1.0).abs() < 1e-9 && (b.x.abs() - 1.0).abs() > 1e-9 {
                DVec3::Y
            } else {
                continue; // a corner: no single normal
            };
            let ang = angle_deg(b - a, normal);
            assert!(
                ang < 20.0,
                "curve through {p:?} meets the boundary {ang}° off orthogonal at {b:?}"
            );
        }
    }
    assert_eq!(checked, 31 * 31 - 21 * 21);
}

#[test]
fn degenerate_meshes_do_not_panic() {
    let empty = TriMesh::default();
    let mut e = engine(&empty);
    assert!(e.best_loop(DVec3::ZERO).is_none());
    assert!(
        e.constrained_loop(&[Anchor::positional(DVec3::ZERO)])
            .is_none()
    );
    let one = TriMesh::new(vec![DVec3::ZERO, DVec3::X, DVec3::Y], vec![[0, 1, 2]]).unwrap();
    let mut e = engine(&one);
    let _ = e.best_loop(DVec3::ZERO);
    let _ = e.loops_through(DVec3::ZERO, 5);
    // Two disconnected spheres.
    let mut a = icosphere(1.0, 2);
    let b = icosphere(1.0, 2);
    let off = a.positions.len() as u32;
    a.positions
        .extend(b.positions.iter().map(|p| *p + DVec3::X * 5.0));
    a.triangles.extend(
        b.triangles
            .iter()
            .map(|t| [t[0] + off, t[1] + off, t[2] + off]),
    );
    let mut e = engine(&a);
    let l = e
        .best_loop(DVec3::new(6.0, 0.0, 0.0))
        .expect("loop on the second sphere");
    assert!(l.points.iter().all(|p| p.x > 3.0));
    // Deterministic.
    let l2 = e.best_loop(DVec3::new(6.0, 0.0, 0.0)).unwrap();
    assert_eq!(l, l2);
}
