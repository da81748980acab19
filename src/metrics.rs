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
//! - What of the input the output kept ([`PreservationMetrics`], the
//!   quality issue's "input boundary loops kept", DESIGN's "input
//!   boundaries are data"), measured in the output's mean edge length s so
//!   that any remesher's output is judged alike: an input boundary loop
//!   at least 2 s long is *kept* when every one of its vertices lies within
//!   s of an output boundary edge, *partly kept* when only some do (a hole
//!   kept coarser than its rim, two holes merged), and *closed over* when
//!   none does; shorter loops are *too small* (a hole needs three edges
//!   around). A loop none of whose vertices is near the output's boundary,
//!   at least half of whose vertices lie within s of another input loop
//!   (or of their own loop more than 3 s away along it), borders a *gap*
//!   narrower than an edge — a seam the input did not weld, a lid on its
//!   pot, an eyeball in its socket, a slot — and is counted apart: the
//!   output may close it. An input component is *lost* when none of its
//!   vertices lies within s of the output.

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

/// What of the input's boundaries and parts the output kept (module doc).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct PreservationMetrics {
    /// The input's boundary loops.
    pub input_loops: usize,
    /// Loops shorter than two output edges.
    pub loops_too_small: usize,
    /// Loops along a gap narrower than an edge (module doc).
    pub loops_at_gaps: usize,
    pub loops_kept: usize,
    /// Loops some of whose vertices lie within s of the output's boundary
    /// and some not (a hole kept, coarser than the rim).
    pub loops_partly_kept: usize,
    /// Perimeters, in output edge lengths, of the loops closed over.
    pub loops_closed: Vec<f64>,
    /// The input's connected components (through shared vertices).
    pub input_components: usize,
    /// Triangle counts of the input components the output lost.
    pub components_lost: Vec<usize>,
}

impl PreservationMetrics {
    /// One sentence on what was lost, or `None` when nothing was.
    pub fn warning(&self) -> Option<String> {
        let list = |values: Vec<String>| values.join(", ");
        let mut parts = Vec::new();
        let n = self.loops_closed.len();
        if n > 0 {
            parts.push(format!(
                "{n} of the input's {} boundary loops {} closed over (perimeter {} output edges)",
                self.input_loops,
                if n == 1 { "was" } else { "were" },
                list(
                    self.loops_closed
                        .iter()
                        .map(|e| format!("{e:.1}"))
                        .collect()
                )
            ));
        }
        let m = self.components_lost.len();
        if m > 0 {
            let total: usize = self.components_lost.iter().sum();
            parts.push(format!(
                "{m} of the input's {} parts {} lost ({} {}; more vertices keep small parts)",
                self.input_components,
                if m == 1 { "was" } else { "were" },
                list(self.components_lost.iter().map(|t| t.to_string()).collect()),
                if total == 1 { "triangle" } else { "triangles" }
            ));
        }
        (!parts.is_empty()).then(|| parts.join("; "))
    }
}

/// The thesis' chapter-4 metrics of one output mesh.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Metrics {
    pub topology: TopologyMetrics,
    pub quads: QuadMetrics,
    pub distance: DistanceMetrics,
    pub edges: EdgeMetrics,
    pub preservation: PreservationMetrics,
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

/// The interior corner angles (radians) of any polygon: a quad's as
/// [`quad_corner_angles`], another polygon's about its Newell normal.
pub(crate) fn polygon_corner_angles(p: &[DVec3]) -> Vec<f64> {
    if let Ok(q) = <&[DVec3; 4]>::try_from(p) {
        return quad_corner_angles(q).to_vec();
    }
    let n = p.len();
    let normal = crate::mesh::newell_normal(p.iter().copied());
    (0..n)
        .map(|i| interior_angle(p[(i + n - 1) % n], p[i], p[(i + 1) % n], normal))
        .collect()
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

/// Distances between the output and the input surface, with the input's
/// vertices' distances to the output given (`None`: the output has no
/// faces to measure against).
fn distances(mesh: &PolyMesh, input_index: &SurfaceIndex, back: Option<&[f64]>) -> DistanceMetrics {
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
    if let Some(back) = back {
        d.input_to_output_max = back.iter().copied().fold(0.0, f64::max);
        d.input_to_output_mean = back.iter().sum::<f64>() / back.len().max(1) as f64;
    }
    d.hausdorff = d.output_to_input_max.max(d.input_to_output_max);
    d
}

/// Each input vertex's distance to the output's faces (triangulated);
/// `None` when the output has none.
fn input_to_output(mesh: &PolyMesh, input: &TriMesh) -> Option<Vec<f64>> {
    let tris = mesh.to_face_list().triangulate(&mesh.positions);
    let index = TriMesh::new(mesh.positions.clone(), tris)
        .ok()
        .and_then(|t| SurfaceIndex::new(&t))?;
    let mut d = Vec::new();
    crate::parallel::map_into(&input.positions, &mut d, |&q| index.distance(q));
    Some(d)
}

/// [`PreservationMetrics`] of `mesh` against `input` (module doc), with s
/// the output's mean edge length.
pub fn preservation_metrics(mesh: &PolyMesh, input: &TriMesh) -> PreservationMetrics {
    preservation(mesh, input, input_to_output(mesh, input).as_deref())
}

/// Input boundary loops at least this many target edges (the output's
/// mean edge) long are to be boundary loops of the output (issue 19's
/// "every input boundary loop whose length exceeds about two target
/// edges"); shorter ones are too small to keep.
pub const KEPT_LOOP_EDGES: f64 = 2.0;

/// What the output does with one input boundary loop (module doc).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LoopFate {
    TooSmall,
    Kept,
    /// Some of its vertices lie within s of the output's boundary, some
    /// not: a hole kept coarser than the input's rim, or two holes merged.
    PartlyKept,
    AtGap,
    ClosedOver,
}

/// Every input boundary loop's [`LoopFate`], with the loops and the
/// output's mean edge length s they were judged by.
pub struct LoopAudit {
    pub s: f64,
    pub arcs: crate::mesh::BoundaryArcs,
    /// The input's boundary edges (edges of one triangle), as vertex pairs.
    pub boundary_edges: Vec<[u32; 2]>,
    pub fates: Vec<LoopFate>,
}

/// The output's mean edge length.
fn mean_edge_length(mesh: &PolyMesh) -> f64 {
    let (sum, n) = (0..mesh.edge_count() as u32).fold((0.0, 0usize), |(sum, n), e| {
        let (a, b) = (mesh.origin(2 * e), mesh.tip(2 * e));
        (
            sum + mesh.positions[a as usize].distance(mesh.positions[b as usize]),
            n + 1,
        )
    });
    sum / n.max(1) as f64
}

/// [`LoopAudit`] of `mesh` against `input`.
pub fn loop_audit(mesh: &PolyMesh, input: &TriMesh) -> LoopAudit {
    let s = mean_edge_length(mesh);
    let arcs = crate::mesh::BoundaryArcs::new(input);
    let output_boundary = crate::spatial::SegmentGrid::new(
        (0..mesh.halfedge_count() as u32)
            .filter(|&h| mesh.is_boundary_halfedge(h))
            .map(|h| {
                let (a, b) = (mesh.origin(h), mesh.tip(h));
                ([mesh.positions[a as usize], mesh.positions[b as usize]], ())
            })
            .collect(),
        s,
    );
    // The input's boundary edges (on one triangle), each tagged with its
    // loop and its start's arc length.
    let on_loop = |v: u32| arcs.loop_of[v as usize] != u32::MAX;
    let boundary_edges: Vec<[u32; 2]> = crate::mesh::boundary_half_edges(input)
        .into_iter()
        .filter(|&(a, b)| on_loop(a) && on_loop(b))
        .map(|(a, b)| [a.min(b), a.max(b)])
        .collect();
    let input_boundary: Vec<([DVec3; 2], (u32, f64))> = boundary_edges
        .iter()
        .map(|&[a, b]| {
            let tag = (arcs.loop_of[a as usize], arcs.arc[a as usize]);
            (
                [input.positions[a as usize], input.positions[b as usize]],
                tag,
            )
        })
        .collect();
    let input_boundary = crate::spatial::SegmentGrid::new(input_boundary, s);
    // Per loop: whether a vertex lies far from the output's boundary; how
    // many of its vertices have no other part of the input's boundary
    // within s (another loop, or its own loop more than 3 s away along it).
    let mut far = vec![false; arcs.length.len()];
    let mut near = vec![false; arcs.length.len()];
    let mut open = vec![(0usize, 0usize); arcs.length.len()];
    for (v, &l) in arcs.loop_of.iter().enumerate() {
        if l == u32::MAX || arcs.length[l as usize] < KEPT_LOOP_EDGES * s {
            continue;
        }
        let q = input.positions[v];
        let l = l as usize;
        if output_boundary.any_within(q, s, |_| true) {
            near[l] = true;
        } else {
            far[l] = true;
        }
        let (arc, length) = (arcs.arc[v], arcs.length[l]);
        let across = input_boundary.any_within(q, s, |(other, at)| {
            let along = (at - arc).abs();
            other as usize != l || along.min(length - along) > 3.0 * s
        });
        open[l].0 += usize::from(!across);
        open[l].1 += 1;
    }
    let fates = arcs
        .length
        .iter()
        .enumerate()
        .map(|(l, &length)| {
            if length < KEPT_LOOP_EDGES * s {
                LoopFate::TooSmall
            } else if !far[l] {
                LoopFate::Kept
            } else if near[l] {
                LoopFate::PartlyKept
            } else if 2 * open[l].0 <= open[l].1 {
                LoopFate::AtGap
            } else {
                LoopFate::ClosedOver
            }
        })
        .collect();
    LoopAudit {
        s,
        arcs,
        boundary_edges,
        fates,
    }
}

/// [`preservation_metrics`] with the input's vertices' distances to the
/// output given.
fn preservation(mesh: &PolyMesh, input: &TriMesh, back: Option<&[f64]>) -> PreservationMetrics {
    let LoopAudit { s, arcs, fates, .. } = loop_audit(mesh, input);
    let mut p = PreservationMetrics {
        input_loops: fates.len(),
        ..Default::default()
    };
    for (&fate, &length) in fates.iter().zip(&arcs.length) {
        match fate {
            LoopFate::TooSmall => p.loops_too_small += 1,
            LoopFate::Kept => p.loops_kept += 1,
            LoopFate::PartlyKept => p.loops_partly_kept += 1,
            LoopFate::AtGap => p.loops_at_gaps += 1,
            LoopFate::ClosedOver => p.loops_closed.push(length / s),
        }
    }
    let mut parts = crate::mesh::UnionFind::new(input.vertex_count());
    for t in &input.triangles {
        parts.union(t[0], t[1]);
        parts.union(t[1], t[2]);
    }
    let mut triangles = vec![0usize; input.vertex_count()];
    for t in &input.triangles {
        triangles[parts.find(t[0]) as usize] += 1;
    }
    let mut near = vec![false; input.vertex_count()];
    for (v, &d) in back.unwrap_or(&[]).iter().enumerate() {
        if d <= s {
            near[parts.find(v as u32) as usize] = true;
        }
    }
    for (root, &count) in triangles.iter().enumerate() {
        if count > 0 {
            p.input_components += 1;
            if !near[root] {
                p.components_lost.push(count);
            }
        }
    }
    p
}

/// All metrics of `mesh` against `input`.
pub fn metrics(mesh: &PolyMesh, input: &TriMesh, input_index: &SurfaceIndex) -> Metrics {
    let (topology, quads, edges) = shape_metrics(mesh, input.vertex_count());
    let back = input_to_output(mesh, input);
    Metrics {
        topology,
        quads,
        distance: distances(mesh, input_index, back.as_deref()),
        edges,
        preservation: preservation(mesh, input, back.as_deref()),
    }
}

#[cfg(test)]
pub(crate) mod tests {
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

    /// A quad grid over [−1, 1]² with `n × n` cells, without the cells whose
    /// centre fails `keep`.
    pub(crate) fn quad_grid(n: u32, keep: impl Fn(f64, f64) -> bool) -> PolyMesh {
        let at = |i: u32| -1.0 + 2.0 * i as f64 / n as f64;
        let p: Vec<DVec3> = (0..=n)
            .flat_map(|j| (0..=n).map(move |i| DVec3::new(at(i), at(j), 0.0)))
            .collect();
        let id = |i: u32, j: u32| j * (n + 1) + i;
        // Only the vertices the kept cells use, renumbered.
        let mut index = vec![u32::MAX; p.len()];
        let mut used = Vec::new();
        let mut f = FaceList::new();
        for j in 0..n {
            for i in 0..n {
                let c = 1.0 / n as f64;
                if keep(at(i) + c, at(j) + c) {
                    let quad = [id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)].map(|v| {
                        if index[v as usize] == u32::MAX {
                            index[v as usize] = used.len() as u32;
                            used.push(p[v as usize]);
                        }
                        index[v as usize]
                    });
                    f.push(&quad);
                }
            }
        }
        PolyMesh::from_faces(used, &f).unwrap()
    }

    /// The input: a fine triangulated grid without the cells failing `keep`.
    pub(crate) fn tri_grid(keep: impl Fn(f64, f64) -> bool) -> TriMesh {
        let q = quad_grid(60, keep);
        let tris = q.to_face_list().triangulate(&q.positions);
        TriMesh::new(q.positions.clone(), tris).unwrap()
    }

    #[test]
    fn holes_kept_closed_too_small_and_at_gaps_and_lost_parts() {
        // Output edges 0.2 (10 × 10 over [−1, 1]²).
        let hole = |h: f64| move |x: f64, y: f64| x.abs().max(y.abs()) > h;
        // A 0.8 × 0.8 hole (perimeter 16 edges): kept when the output has
        // it, closed over (16 edges) when it does not.
        let input = tri_grid(hole(0.4));
        let kept = preservation_metrics(&quad_grid(10, hole(0.4)), &input);
        assert_eq!((kept.input_loops, kept.loops_kept), (2, 2), "{kept:?}");
        assert!(kept.loops_closed.is_empty() && kept.warning().is_none());
        let closed = preservation_metrics(&quad_grid(10, |_, _| true), &input);
        assert_eq!(closed.loops_kept, 1, "{closed:?}");
        assert_eq!(closed.loops_closed.len(), 1);
        assert!((closed.loops_closed[0] - 16.0).abs() < 1e-9, "{closed:?}");
        assert!(
            closed
                .warning()
                .unwrap()
                .contains("1 of the input's 2 boundary loops was closed over")
        );
        // A 1.2 × 0.4 slot-shaped hole of which the output keeps only the
        // middle 0.4 × 0.4: partly kept, not said to be closed over.
        let wide = tri_grid(|x, y| !(x.abs() < 0.6 && y.abs() < 0.2));
        let partly = preservation_metrics(&quad_grid(10, hole(0.2)), &wide);
        assert_eq!(
            (partly.loops_partly_kept, partly.loops_kept),
            (1, 1),
            "{partly:?}"
        );
        assert!(partly.warning().is_none());
        // A hole 0.067 across (perimeter 1.3 edges): too small.
        let small = preservation_metrics(&quad_grid(10, |_, _| true), &tri_grid(hole(0.04)));
        assert_eq!(
            (small.loops_too_small, small.loops_kept),
            (1, 1),
            "{small:?}"
        );
        assert!(small.warning().is_none());
        // A slot 0.067 wide and 1.2 long: a gap narrower than an edge.
        let slot = |x: f64, y: f64| !(x.abs() < 0.6 && y.abs() < 0.03);
        let gap = preservation_metrics(&quad_grid(10, |_, _| true), &tri_grid(slot));
        assert_eq!((gap.loops_at_gaps, gap.loops_kept), (1, 1), "{gap:?}");
        assert!(gap.warning().is_none());
        // A second input part, one small triangle above the plane: lost.
        let mut speck = tri_grid(|_, _| true);
        let base = speck.positions.len() as u32;
        let mut positions = speck.positions.clone();
        positions.extend([
            DVec3::new(0.0, 0.0, 1.0),
            DVec3::new(0.01, 0.0, 1.0),
            DVec3::new(0.0, 0.01, 1.0),
        ]);
        let mut triangles = speck.triangles.clone();
        triangles.push([base, base + 1, base + 2]);
        speck = TriMesh::new(positions, triangles).unwrap();
        let lost = preservation_metrics(&quad_grid(10, |_, _| true), &speck);
        assert_eq!(
            (lost.input_components, lost.components_lost.clone()),
            (2, vec![1]),
            "{lost:?}"
        );
        assert!(
            lost.warning()
                .unwrap()
                .contains("1 of the input's 2 parts was lost (1 triangle;")
        );
    }
}
