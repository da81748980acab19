//! Quality metrics of an output mesh against the input: Kloiber 2018
//! chapter 4's list, used by `quadrille remesh --stats` and the browser.
//!
//! [`Metrics`] is a struct of sections so later stages can add theirs
//! (e.g. the limit surface's error) without touching these.
//!
//! Definitions and decisions:
//! - EVs (extraordinary vertices): interior vertices of valence ≠ 4 and
//!   boundary vertices of valence ≠ 3, as a percentage of vertices.
//! - Planarity: per quad, the distance between the midpoints of its two
//!   diagonals (thesis: "distance between diagonal centre points").
//! - Corner angles: mean |α − 90°| over quad corners, and the mean angle.
//! - Opposite-edge ratio: per quad, the mean of min/max over both pairs of
//!   opposite edges (1 = parallelogram-like).
//! - Quad quality after Marinov & Kobbelt 2006 as adapted by the thesis,
//!   `E = (1 + O)(1 + P) R − 1` with O = Σ|α_i − π/2|, P = Σ|α_i + α_{i+1} − π|,
//!   R = (2 − min/max(l0,l2))(2 − min/max(l1,l3)). The thesis prints
//!   `(1 − O)(1 − P)`, which is not minimal at E = 0 as the text says; we use
//!   the signs that make 0 the optimum.
//! - Hausdorff distance, two-sided: the output's vertices, edge midpoints
//!   and face centroids against the input, and the input's vertices against
//!   the output (triangulated). Face centroids: mean and max distance to the
//!   input.
//! - Lengths are in the mesh's coordinates (the pipeline's local frame:
//!   largest bounding-box axis 1, so distances read as fractions of it).

use glam::DVec3;
use serde::{Deserialize, Serialize};

use crate::mesh::{FaceList, PolyMesh, TriMesh};
use crate::spatial::SurfaceIndex;

/// Topology and face statistics.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct TopologyMetrics {
    pub vertices: usize,
    pub faces: usize,
    pub edges: usize,
    pub input_vertices: usize,
    /// 100 · (1 − V_out / V_in).
    pub vertex_reduction_percent: f64,
    pub extraordinary_vertex_percent: f64,
    pub non_quad_percent: f64,
    /// `[degree, count]` pairs.
    pub face_degrees: Vec<[usize; 2]>,
    pub max_face_degree: usize,
    pub boundary_edges: usize,
    pub boundary_vertices: usize,
    pub boundary_loops: usize,
    pub nonmanifold_edges: usize,
    pub nonmanifold_vertices: usize,
    pub inconsistent_edges: usize,
    pub components: usize,
    pub euler_characteristic: i64,
    pub genus: Option<i64>,
}

/// Shape of the quads.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct QuadMetrics {
    pub quads: usize,
    /// Mean distance between a quad's diagonal midpoints.
    pub planarity: f64,
    /// Mean |corner angle − 90°|, degrees.
    pub corner_angle_deviation_degrees: f64,
    /// Mean corner angle, degrees.
    pub mean_corner_angle_degrees: f64,
    pub opposite_edge_ratio: f64,
    /// Mean adapted Marinov–Kobbelt quad quality (0 is best).
    pub quad_quality: f64,
    /// Share of quads with a corner below 45° or above 135°, percent.
    pub distorted_quad_percent: f64,
    /// The largest quad corner angle, degrees (above 180°: a non-convex quad).
    pub max_corner_angle_degrees: f64,
}

/// Distances to the input.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct DistanceMetrics {
    pub hausdorff: f64,
    /// Output samples → input.
    pub output_to_input_max: f64,
    pub output_to_input_mean: f64,
    /// Input vertices → output.
    pub input_to_output_max: f64,
    pub input_to_output_mean: f64,
    pub face_centroid_mean: f64,
    pub face_centroid_max: f64,
}

/// Edge lengths.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct EdgeMetrics {
    pub mean: f64,
    pub std_dev: f64,
    pub min: f64,
    pub max: f64,
}

/// The thesis' chapter-4 metrics of one output mesh.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Metrics {
    pub topology: TopologyMetrics,
    pub quads: QuadMetrics,
    pub distance: DistanceMetrics,
    pub edges: EdgeMetrics,
}

fn angle(a: DVec3, b: DVec3, c: DVec3) -> f64 {
    let (u, v) = (a - b, c - b);
    if u.length_squared() == 0.0 || v.length_squared() == 0.0 {
        return 0.0;
    }
    u.angle_between(v)
}

/// The interior angle at `b` of a polygon with normal `normal` whose
/// corners run counter-clockwise about it (`a` before `b`, `c` after): a
/// reflex corner (a non-convex quad) reads above π.
fn interior_angle(a: DVec3, b: DVec3, c: DVec3, normal: DVec3) -> f64 {
    let alpha = angle(a, b, c);
    if (c - b).cross(a - b).dot(normal) < 0.0 {
        std::f64::consts::TAU - alpha
    } else {
        alpha
    }
}

/// The interior corner angles (radians) of quad `p`, its normal the cross
/// product of its diagonals; a reflex corner reads above π.
pub fn quad_corner_angles(p: &[DVec3; 4]) -> [f64; 4] {
    let normal = (p[2] - p[0]).cross(p[3] - p[1]);
    std::array::from_fn(|i| interior_angle(p[(i + 3) % 4], p[i], p[(i + 1) % 4], normal))
}

/// The shape of the quads of any polygon soup (manifold or not): corner
/// angles, planarity, edge ratios, quad quality.
pub fn quad_metrics(positions: &[DVec3], faces: &FaceList) -> QuadMetrics {
    let mut quad = QuadMetrics::default();
    let (mut planarity, mut dev, mut mean_angle, mut ratio, mut quality) =
        (0.0, 0.0, 0.0, 0.0, 0.0);
    let mut distorted = 0usize;
    for vs in faces.iter().filter(|f| f.len() == 4) {
        quad.quads += 1;
        let p: [DVec3; 4] = std::array::from_fn(|i| positions[vs[i] as usize]);
        planarity += (0.5 * (p[0] + p[2])).distance(0.5 * (p[1] + p[3]));
        let a = quad_corner_angles(&p);
        let l: Vec<f64> = (0..4).map(|i| p[i].distance(p[(i + 1) % 4])).collect();
        let half_pi = std::f64::consts::FRAC_PI_2;
        let o: f64 = a.iter().map(|x| (x - half_pi).abs()).sum();
        let par: f64 = (0..4)
            .map(|i| (a[i] + a[(i + 1) % 4] - std::f64::consts::PI).abs())
            .sum();
        let mm = |x: f64, y: f64| {
            if x.max(y) > 0.0 {
                x.min(y) / x.max(y)
            } else {
                1.0
            }
        };
        let r = (2.0 - mm(l[0], l[2])) * (2.0 - mm(l[1], l[3]));
        quality += (1.0 + o) * (1.0 + par) * r - 1.0;
        ratio += 0.5 * (mm(l[0], l[2]) + mm(l[1], l[3]));
        dev += a.iter().map(|x| (x.to_degrees() - 90.0).abs()).sum::<f64>() / 4.0;
        mean_angle += a.iter().map(|x| x.to_degrees()).sum::<f64>() / 4.0;
        let degrees = a.iter().map(|x| x.to_degrees());
        if degrees.clone().any(|x| !(45.0..=135.0).contains(&x)) {
            distorted += 1;
        }
        quad.max_corner_angle_degrees = degrees.fold(quad.max_corner_angle_degrees, f64::max);
    }
    if quad.quads > 0 {
        let q = quad.quads as f64;
        quad.planarity = planarity / q;
        quad.corner_angle_deviation_degrees = dev / q;
        quad.mean_corner_angle_degrees = mean_angle / q;
        quad.opposite_edge_ratio = ratio / q;
        quad.quad_quality = quality / q;
        quad.distorted_quad_percent = 100.0 * distorted as f64 / q;
    }
    quad
}

/// Extraordinary vertices of any polygon soup, as a percentage of the
/// vertices faces use: valence = distinct edge neighbours; a vertex on an
/// edge of exactly one face is a boundary vertex (regular at 3), else
/// regular at 4. For a manifold mesh this is the EV of [`shape_metrics`].
pub fn extraordinary_vertex_percent(vertex_count: usize, faces: &FaceList) -> f64 {
    let mut edges: std::collections::HashMap<(u32, u32), u32> = Default::default();
    for f in faces.iter() {
        for k in 0..f.len() {
            let (a, b) = (f[k], f[(k + 1) % f.len()]);
            *edges.entry((a.min(b), a.max(b))).or_insert(0) += 1;
        }
    }
    let mut valence = vec![0usize; vertex_count];
    let mut boundary = vec![false; vertex_count];
    for (&(a, b), &count) in &edges {
        for v in [a, b] {
            valence[v as usize] += 1;
            boundary[v as usize] |= count == 1;
        }
    }
    let used: Vec<usize> = (0..vertex_count).filter(|&v| valence[v] > 0).collect();
    let ev = used
        .iter()
        .filter(|&&v| valence[v] != if boundary[v] { 3 } else { 4 })
        .count();
    100.0 * ev as f64 / used.len().max(1) as f64
}

/// Topology and quad-shape metrics (no distances).
pub fn shape_metrics(
    mesh: &PolyMesh,
    input_vertices: usize,
) -> (TopologyMetrics, QuadMetrics, EdgeMetrics) {
    let topo = mesh.topology();
    let nv = mesh.vertex_count();
    let nf = mesh.face_count();
    let faces = mesh.to_face_list();
    let hist = faces.degree_histogram();
    let quad = quad_metrics(&mesh.positions, &faces);
    let mut ev = 0;
    let mut boundary_vertices = 0;
    for v in 0..nv as u32 {
        let b = mesh.is_boundary_vertex(v);
        boundary_vertices += b as usize;
        let regular = if b { 3 } else { 4 };
        if mesh.valence(v) != regular {
            ev += 1;
        }
    }
    let lengths: Vec<f64> = (0..mesh.edge_count() as u32)
        .map(|e| {
            mesh.positions[mesh.origin(2 * e) as usize]
                .distance(mesh.positions[mesh.tip(2 * e) as usize])
        })
        .collect();
    let mut edges = EdgeMetrics::default();
    if !lengths.is_empty() {
        let n = lengths.len() as f64;
        edges.mean = lengths.iter().sum::<f64>() / n;
        edges.std_dev = (lengths
            .iter()
            .map(|l| (l - edges.mean).powi(2))
            .sum::<f64>()
            / n)
            .sqrt();
        edges.min = lengths.iter().copied().fold(f64::INFINITY, f64::min);
        edges.max = lengths.iter().copied().fold(0.0, f64::max);
    }
    let pct = |x: usize, of: usize| {
        if of > 0 {
            100.0 * x as f64 / of as f64
        } else {
            0.0
        }
    };
    let topology = TopologyMetrics {
        vertices: nv,
        faces: nf,
        edges: mesh.edge_count(),
        input_vertices,
        vertex_reduction_percent: if input_vertices > 0 {
            100.0 * (1.0 - nv as f64 / input_vertices as f64)
        } else {
            0.0
        },
        extraordinary_vertex_percent: pct(ev, nv),
        non_quad_percent: pct(nf - quad.quads, nf),
        face_degrees: hist
            .iter()
            .enumerate()
            .filter(|&(_, &c)| c > 0)
            .map(|(d, &c)| [d, c])
            .collect(),
        max_face_degree: hist.len().saturating_sub(1),
        boundary_edges: topo.boundary_edges,
        boundary_vertices,
        boundary_loops: mesh.boundary_loops().len(),
        nonmanifold_edges: topo.nonmanifold_edges,
        nonmanifold_vertices: topo.nonmanifold_vertices,
        inconsistent_edges: topo.inconsistent_edges,
        components: topo.components,
        euler_characteristic: topo.euler_characteristic,
        genus: topo.genus(),
    };
    (topology, quad, edges)
}

/// Distances between the output and the input surface.
pub fn distance_metrics(
    mesh: &PolyMesh,
    input: &TriMesh,
    input_index: &SurfaceIndex,
) -> DistanceMetrics {
    let mut d = DistanceMetrics::default();
    let mut samples: Vec<DVec3> = mesh.positions.clone();
    for e in 0..mesh.edge_count() as u32 {
        samples.push(
            0.5 * (mesh.positions[mesh.origin(2 * e) as usize]
                + mesh.positions[mesh.tip(2 * e) as usize]),
        );
    }
    let centroids: Vec<DVec3> = (0..mesh.face_count() as u32)
        .map(|f| {
            let (s, k) = mesh.face_vertices(f).fold((DVec3::ZERO, 0.0), |(s, k), v| {
                (s + mesh.positions[v as usize], k + 1.0)
            });
            s / k
        })
        .collect();
    let dist = |pts: &[DVec3], idx: &SurfaceIndex| -> Vec<f64> {
        let mut out = Vec::new();
        crate::parallel::map_into(pts, &mut out, |&p| idx.distance(p));
        out
    };
    let c = dist(&centroids, input_index);
    let s = dist(&samples, input_index);
    let all_out = s.iter().chain(&c);
    let n_out = (s.len() + c.len()).max(1) as f64;
    d.output_to_input_max = all_out.clone().copied().fold(0.0, f64::max);
    d.output_to_input_mean = all_out.sum::<f64>() / n_out;
    if !c.is_empty() {
        d.face_centroid_mean = c.iter().sum::<f64>() / c.len() as f64;
        d.face_centroid_max = c.iter().copied().fold(0.0, f64::max);
    }
    let tris = mesh.to_face_list().triangulate(&mesh.positions);
    if let Some(out_index) = TriMesh::new(mesh.positions.clone(), tris)
        .ok()
        .and_then(|t| SurfaceIndex::new(&t))
    {
        let back = dist(&input.positions, &out_index);
        d.input_to_output_max = back.iter().copied().fold(0.0, f64::max);
        d.input_to_output_mean = back.iter().sum::<f64>() / back.len().max(1) as f64;
    }
    d.hausdorff = d.output_to_input_max.max(d.input_to_output_max);
    d
}

/// All metrics of `mesh` against `input`.
pub fn metrics(mesh: &PolyMesh, input: &TriMesh, input_index: &SurfaceIndex) -> Metrics {
    let (topology, quads, edges) = shape_metrics(mesh, input.vertex_count());
    Metrics {
        topology,
        quads,
        distance: distance_metrics(mesh, input, input_index),
        edges,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unit_square_grid_is_perfect() {
        let mut p = Vec::new();
        for j in 0..3 {
            for i in 0..3 {
                p.push(DVec3::new(i as f64, j as f64, 0.0));
            }
        }
        let mut f = FaceList::new();
        for j in 0..2u32 {
            for i in 0..2u32 {
                let id = |i: u32, j: u32| j * 3 + i;
                f.push(&[id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        let m = PolyMesh::from_faces(p, &f).unwrap();
        let (t, q, e) = shape_metrics(&m, 9);
        assert_eq!(q.quads, 4);
        assert!(q.quad_quality.abs() < 1e-12);
        assert!(q.planarity.abs() < 1e-12);
        assert!((q.opposite_edge_ratio - 1.0).abs() < 1e-12);
        assert!((e.mean - 1.0).abs() < 1e-12 && e.std_dev < 1e-12);
        assert_eq!(t.non_quad_percent, 0.0);
        assert_eq!(t.boundary_edges, 8);
        // Corners (valence 2) and the centre (interior valence 4): corner
        // valence 2 ≠ 3 → 4 EVs of 9.
        assert!((t.extraordinary_vertex_percent - 100.0 * 4.0 / 9.0).abs() < 1e-9);
        assert_eq!(q.distorted_quad_percent, 0.0);
        assert!((q.max_corner_angle_degrees - 90.0).abs() < 1e-9);
        // The face-list count (for non-manifold outputs) agrees.
        assert!(
            (extraordinary_vertex_percent(9, &f) - t.extraordinary_vertex_percent).abs() < 1e-12
        );
    }

    #[test]
    fn a_dart_reads_as_reflex_and_a_rhombus_as_distorted() {
        // Dart (arrowhead): the corner at (1, 0.5) is reflex, 360° − 2·atan2(…).
        let dart = vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(2.0, 1.0, 0.0),
            DVec3::new(0.0, 2.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
        ];
        let mut f = FaceList::new();
        f.push(&[0, 1, 2, 3]);
        let (_, q, _) = shape_metrics(&PolyMesh::from_faces(dart, &f).unwrap(), 4);
        let reflex = 360.0 - 2.0 * 45.0;
        assert!((q.max_corner_angle_degrees - reflex).abs() < 1e-9, "{q:?}");
        assert_eq!(q.distorted_quad_percent, 100.0);
        // Rhombus with 40° and 140° corners: convex, but distorted.
        let (c, s) = (40f64.to_radians().cos(), 40f64.to_radians().sin());
        let rhombus = vec![
            DVec3::ZERO,
            DVec3::X,
            DVec3::new(1.0 + c, s, 0.0),
            DVec3::new(c, s, 0.0),
        ];
        let (_, q, _) = shape_metrics(&PolyMesh::from_faces(rhombus, &f).unwrap(), 4);
        assert!((q.max_corner_angle_degrees - 140.0).abs() < 1e-9, "{q:?}");
        assert_eq!(q.distorted_quad_percent, 100.0);
        assert!((q.corner_angle_deviation_degrees - 50.0).abs() < 1e-9);
    }
}
