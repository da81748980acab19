//! Extraction of the quad-dominant mesh from the position field and its
//! post-processing: Instant Meshes' extraction (digest §5) with Kloiber
//! 2018 §3.5–3.7, into a closed, manifold half-edge [`PolyMesh`].
//!
//! - [`clusters`]: integer translations → vertex clusters (§5.1–5.5, thesis 3.5.1);
//! - [`snap`]: thin-triangle snapping, quad diagonals (§5.6, thesis 3.5.2);
//! - [`faces`]: rotation system, orbits, n-gon splitting, hole loops (§5.7–5.10, thesis 3.5.3);
//! - [`repair`]: non-manifold repair, orientation, hole filling (thesis 3.6);
//! - [`postprocess`]: T-vertices, feature-aligned quads, flat triangles, odd-face pairing, edge rotations, diagonal collapses, smoothing (thesis 3.7);
//! - [`pure_quad`]: one Catmull–Clark split (§5.11).
//!
//! [`extract`] runs clusters → snapping → faces → repair; [`post_process`]
//! runs the thesis' post-processing and the optional pure-quad split. Both
//! end in `PolyMesh::from_faces`, which refuses non-manifold input, so their
//! output is manifold and consistently oriented by construction.

pub mod clusters;
pub mod faces;
pub mod placement;
pub mod postprocess;
pub mod pure_quad;
pub mod qex;
pub mod reopen;
pub mod repair;
pub mod snap;

use glam::DVec3;
use serde::{Deserialize, Serialize};

pub use clusters::{ClusterReport, ExtractInput, Graph};
pub use postprocess::{PostProcessParams, PostProcessReport};
pub use repair::RepairReport;
pub use snap::SnapReport;

use crate::mesh::PolyMesh;
use crate::progress::{Cancelled, Progress};
use crate::spatial::SurfaceIndex;

/// Parameters of extraction and post-processing. Every field has a default.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct ExtractionParams {
    /// Clusters smaller than this fraction of the average cluster are
    /// dropped (thesis 3.5.1: 1/10 … 1/20). Default 1/20.
    pub min_cluster_fraction: f64,
    /// Snap thin triangles (thesis 3.5.2). Default on.
    pub snap: bool,
    /// Split long faces by the thesis' quad score (§3.5.3: the candidate
    /// quad's own four corners) instead of Instant Meshes' (two of its
    /// corners and two beyond). Default on.
    pub thesis_quad_score: bool,
    /// The non-manifold repair also treats a face's diagonal that another
    /// face uses as non-manifold (thesis §3.6: "manifoldness is ensured for
    /// arbitrary triangulations"), not only non-manifold edges. Default on:
    /// without it the repair keeps the flaps it would remove, and the
    /// valences and corners suffer (`scripts/quality.py --orders 3`,
    /// medians, on → off; EV %, corner °): cow 29.0 → 40.7, 14.98 → 20.19
    /// (Hausdorff 0.113 → 0.086), suzanne 50.0 → 65.6, 21.0 → 23.9, spot
    /// corner 12.27 → 13.59; bunny, fandisk, rocker-arm within 0.6 of EV.
    pub triangulation_pairs: bool,
    /// The pair repair keeps a vertex on only the two faces of the pair
    /// (the tip of a horn or hoof the two faces cap) by splitting one of
    /// them, where that leaves no more odd faces than removing it (see
    /// `repair::cap_split`; a deviation from the thesis, which removes it).
    /// Default on: spot's horn tips are no longer cut off. `make quality`,
    /// medians over 5 vertex orders, off → on (Instant Meshes in
    /// brackets): spot Hausdorff 0.095 → 0.063 [0.110], limit after fit
    /// 8.55e-4 → 7.77e-4 [8.18e-4], two-sided limit 1.94e-3 → 1.52e-3,
    /// EV 27.9 → 25.8 %; suzanne EV 50.0 → 42.4 %, corner 23.3 → 22.8°;
    /// cow odd faces 7.8 → 6.8 % but EV 28.7 → 29.5 %, two-sided limit
    /// 6.39e-3 → 6.65e-3; fandisk, rocker-arm, bunny, beetle, teapot within
    /// noise. Also splitting where it adds two triangles (two quads around
    /// the tip) when the tip stands out by a quarter of the pair's
    /// distance cut the teapot's Hausdorff distance (0.185 → 0.102) but
    /// left 6–7 % odd faces there and on the cow: not taken.
    pub keep_cap_vertices: bool,
    /// Closed fragments of the face tracing (fewer than 12 faces) are
    /// joined to the nearest facing face of the rest by a tube instead of
    /// being dropped (see `repair::bridge_fragments`). Default on: the
    /// cow's hooves are no longer cut off (`make quality`, medians over 5
    /// vertex orders, off → on: Hausdorff 0.166 → 0.113, Instant Meshes
    /// 0.115; two-sided limit distance after the fit 7.86e-3 → 6.39e-3), at
    /// a cost in regularity there (EV 24.3 → 28.7 %, corner 13.07 →
    /// 14.98°, odd faces 5.6 → 7.8 %: the fragments' triangles and
    /// pentagons stay; the one-sided limit → input mean 1.06e-3 → 1.20e-3,
    /// it did not see the missing hooves); beetle odd faces 4.5 → 2.1 %,
    /// teapot EV 36.8 → 37.8 %, corner 9.37 → 8.78°; fandisk, rocker-arm,
    /// spot, bunny, suzanne unchanged (nothing to join).
    pub bridge_fragments: bool,
    /// Holes up to this many corners are filled (thesis: 30).
    pub max_hole: usize,
    /// Close larger holes that are not the input's with a centroid fan.
    /// Default on (closed output is the goal).
    pub fan_large_holes: bool,
    /// Re-run the position field and extraction once, with the edge lengths
    /// scaled by √(achieved / target), when the vertex count misses the
    /// target by more than `count_tolerance`. Default on.
    pub vertex_count_correction: bool,
    /// Default 0.05 (5 %).
    pub count_tolerance: f64,
    /// Extra attempts (position field from the next seeds) when the result
    /// misses the quality gate: vertex count within 10 % of the target and
    /// at most 10 % non-quad faces; the best attempt is kept. Default 3.
    pub restarts: usize,
    pub post: PostProcessParams,
    /// One Catmull–Clark split at the end (all quads). Default off.
    pub pure_quad: bool,
}

impl ExtractionParams {
    /// The repair's rules these parameters set, checking holes against
    /// `surface`.
    pub fn repair_rules<'a>(&self, surface: Option<&'a SurfaceIndex>) -> repair::RepairRules<'a> {
        repair::RepairRules {
            triangulation_pairs: self.triangulation_pairs,
            keep_cap_vertices: self.keep_cap_vertices,
            bridge_fragments: self.bridge_fragments,
            max_hole: self.max_hole,
            fan_large_holes: self.fan_large_holes,
            thesis_quad_score: self.thesis_quad_score,
            surface,
        }
    }
}

impl Default for ExtractionParams {
    fn default() -> Self {
        ExtractionParams {
            min_cluster_fraction: 0.05,
            snap: true,
            thesis_quad_score: true,
            triangulation_pairs: true,
            keep_cap_vertices: true,
            bridge_fragments: true,
            max_hole: 30,
            fan_large_holes: true,
            vertex_count_correction: true,
            count_tolerance: 0.05,
            restarts: 3,
            post: PostProcessParams::default(),
            pure_quad: false,
        }
    }
}

/// What extraction found and did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct ExtractionReport {
    pub clusters: ClusterReport,
    pub snap: SnapReport,
    /// Loops traced from the rotation system.
    pub loops: usize,
    pub faces_traced: usize,
    /// Loops longer than 8 corners treated as holes.
    pub long_loops: usize,
    /// Loops of at most 8 corners around an input hole (not faces).
    pub input_hole_loops: usize,
    /// The input's boundary loops, and how many of them are shorter than
    /// two lattice spacings (those may close: too small to keep).
    pub input_boundary_loops: usize,
    pub input_loops_too_small: usize,
    pub repair: RepairReport,
    /// Scale factor of the vertex-count correction (1 when not applied).
    pub scale_correction: f64,
    /// Extraction attempts made (see [`ExtractionParams::restarts`]).
    pub attempts: usize,
    /// Seed of the position field the kept attempt was extracted from.
    pub position_seed: u64,
}

/// The extracted mesh with per-vertex attributes (`graph` vertex `k` is
/// mesh vertex `k`).
#[derive(Debug, Clone)]
pub struct Extracted {
    pub mesh: PolyMesh,
    pub graph: Graph,
    pub report: ExtractionReport,
}

/// Clusters → snapping → faces → repair.
pub fn extract(
    input: &ExtractInput<'_>,
    surface: Option<&SurfaceIndex>,
    params: &ExtractionParams,
    progress: &mut Progress<'_>,
) -> Result<Extracted, Cancelled> {
    let mut report = ExtractionReport {
        scale_correction: 1.0,
        ..Default::default()
    };
    let arcs = input.boundary_arcs;
    report.input_boundary_loops = arcs.length.len();
    let mut loop_scale = vec![(0.0f64, 0usize); arcs.length.len()];
    for (v, &l) in arcs.loop_of.iter().enumerate() {
        if let (Some(e), Some(&s)) = (loop_scale.get_mut(l as usize), input.scale.get(v)) {
            e.0 += s as f64;
            e.1 += 1;
        }
    }
    report.input_loops_too_small = arcs
        .length
        .iter()
        .zip(&loop_scale)
        .filter(|&(&len, &(sum, count))| len < 2.0 * sum / count.max(1) as f64)
        .count();
    let mut loop_centroid = vec![(DVec3::ZERO, 0usize); arcs.length.len()];
    for (v, &l) in arcs.loop_of.iter().enumerate() {
        if let (Some(e), Some(q)) = (
            loop_centroid.get_mut(l as usize),
            input.level.positions.get(v),
        ) {
            e.0 += q.as_dvec3();
            e.1 += 1;
        }
    }
    let loop_centroid: Vec<DVec3> = loop_centroid
        .into_iter()
        .map(|(sum, count)| sum / count.max(1) as f64)
        .collect();
    let (mut g, cr) = clusters::build_clusters(input, params.min_cluster_fraction, progress)?;
    report.clusters = cr;
    if params.snap {
        report.snap = snap::snap(&mut g, progress)?;
    }
    // Dangling vertices (degree ≤ 1) cannot bound a face.
    loop {
        let mut changed = false;
        for v in 0..g.len() {
            if g.adj[v].len() == 1 {
                let x = g.adj[v][0];
                g.remove_edge(v as u32, x);
                changed = true;
            }
        }
        if !changed {
            break;
        }
    }
    progress.report(0.7, "tracing faces")?;
    let loops = faces::trace_loops(&g);
    report.loops = loops.len();
    let mut face_list: Vec<Vec<u32>> = Vec::with_capacity(loops.len());
    let mut edges = std::collections::HashSet::new();
    for l in &loops {
        if l.len() <= 8 {
            for k in 0..l.len() {
                let (a, b) = (l[k], l[(k + 1) % l.len()]);
                edges.insert((a.min(b), a.max(b)));
            }
        }
    }
    for l in loops {
        if l.len() <= 8 && around_input_hole(&l, &g, surface, &loop_centroid, &arcs.length) {
            report.input_hole_loops += 1;
        } else if l.len() <= 8 {
            faces::fill_polygon(
                &g.pos,
                &l,
                &|a, b| edges.contains(&(a.min(b), a.max(b))),
                params.thesis_quad_score,
                &mut face_list,
            );
        } else {
            // Longer orbits are holes; the repair's hole filling decides.
            report.long_loops += 1;
        }
    }
    report.faces_traced = face_list.len();
    progress.report(0.8, "repairing")?;
    let rules = params.repair_rules(surface);
    let (mesh, map) = repair::repair(face_list, &mut g, &rules, &mut report.repair);
    let graph = g.select(&map);
    progress.report(1.0, "extracted")?;
    Ok(Extracted {
        mesh,
        graph,
        report,
    })
}

/// Whether a short orbit (at most 8 corners) runs around a small input
/// hole and is therefore no face: every corner on the input's boundary
/// and [`repair::is_input_hole`] (half of them were not enough for that
/// test: the teapot's faces along its rims became holes, Hausdorff 0.19 →
/// 0.28); or at least half of its corners on the boundary and the centroid
/// of one of their input loops, no longer than twice the orbit, inside the
/// orbit (in its plane, within half an edge length of it) and off the input
/// (more than a quarter edge length: a lid's rim has its centroid on the
/// lid, and the faces over it are the surface). A corner
/// cluster next to a hole may hold no boundary vertex (the lattice point
/// fell just inside the rim): with the input's long edges split, that
/// closed one of the bunny's five holes in 3 of 6 seeds.
fn around_input_hole(
    l: &[u32],
    g: &Graph,
    surface: Option<&SurfaceIndex>,
    loop_centroid: &[DVec3],
    loop_length: &[f64],
) -> bool {
    let m = l.len();
    let on_boundary = l.iter().filter(|&&v| g.boundary[v as usize]).count();
    if on_boundary == m {
        return repair::is_input_hole(l, g, surface);
    }
    if 2 * on_boundary < m {
        return false;
    }
    let p: Vec<DVec3> = l.iter().map(|&v| g.pos[v as usize]).collect();
    let centre = p.iter().sum::<DVec3>() / m as f64;
    let s = l.iter().map(|&v| g.scale[v as usize]).sum::<f64>() / m as f64;
    let perimeter: f64 = (0..m).map(|k| p[k].distance(p[(k + 1) % m])).sum();
    let Some(n) = crate::mesh::face_newell_normal(&g.pos, l).try_normalize() else {
        return false;
    };
    let (u, w) = n.any_orthonormal_pair();
    let flat: Vec<(f64, f64)> = p
        .iter()
        .map(|&q| ((q - centre).dot(u), (q - centre).dot(w)))
        .collect();
    let inside = |c: DVec3| {
        let (x, y) = ((c - centre).dot(u), (c - centre).dot(w));
        let mut odd = false;
        for k in 0..m {
            let (a, b) = (flat[k], flat[(k + 1) % m]);
            if (a.1 > y) != (b.1 > y) && x < a.0 + (y - a.1) * (b.0 - a.0) / (b.1 - a.1) {
                odd = !odd;
            }
        }
        odd
    };
    l.iter()
        .map(|&v| g.boundary_loop[v as usize])
        .filter(|&k| k != u32::MAX)
        .filter_map(|k| {
            Some((
                *loop_centroid.get(k as usize)?,
                *loop_length.get(k as usize)?,
            ))
        })
        .any(|(c, len)| {
            len <= 2.0 * perimeter
                && (c - centre).dot(n).abs() <= 0.5 * s
                && inside(c)
                && surface.is_none_or(|sf| sf.distance(c) > 0.25 * s)
        })
}

/// The post-processed mesh.
#[derive(Debug, Clone)]
pub struct PostProcessed {
    pub mesh: PolyMesh,
    pub report: PostProcessReport,
    /// Repairs the rebuild needed (normally none).
    pub repair: RepairReport,
    /// The extraction graph's attributes per vertex of `mesh`; `None` in
    /// the global mode.
    pub graph: Option<Graph>,
}

/// Thesis 3.7 on an extracted mesh, then the optional pure-quad split.
pub fn post_process(
    extracted: &Extracted,
    surface: Option<&SurfaceIndex>,
    params: &ExtractionParams,
    progress: &mut Progress<'_>,
) -> Result<PostProcessed, Cancelled> {
    let p = &params.post;
    let mut g = extracted.graph.clone();
    let list = extracted.mesh.to_face_list();
    let mut faces: Vec<Vec<u32>> = list.iter().map(|f| f.to_vec()).collect();
    let mut report = PostProcessReport::default();
    if p.t_vertices {
        progress.report(0.1, "flat T-vertices")?;
        for _ in 0..4 {
            let r = postprocess::remove_t_vertices(&mut faces, &g, p);
            report.t_vertices_removed += r;
            if r == 0 {
                break;
            }
        }
    }
    if p.feature_quads {
        progress.report(0.3, "feature-aligned quads")?;
        let (r, s) = postprocess::align_feature_quads(&mut faces, &mut g, surface);
        report.feature_quads_removed += r;
        report.feature_quads_split += s;
    }
    if p.flat_triangles {
        progress.report(0.5, "flat triangles")?;
        report.triangle_pairs_merged +=
            postprocess::merge_flat_triangles(&mut faces, &g, p.flat_triangle_degrees);
    }
    if p.pair_non_quads_degrees > 0.0 {
        report.non_quad_pairs_merged +=
            postprocess::pair_with_fallback(&mut faces, &mut g, p, surface, 4);
    }
    if p.rotate_edges_degrees > 0.0 {
        progress.report(0.55, "edge rotations")?;
        report.edges_rotated += postprocess::rotate_edges(
            &mut faces,
            &g,
            p.rotate_edges_degrees,
            p.wide_corner_degrees,
        );
        if p.collapse_diagonals {
            report.diagonals_collapsed +=
                postprocess::collapse_diagonals(&mut faces, &mut g, p.rotate_edges_degrees);
        }
    }
    progress.report(0.6, "smoothing")?;
    report.smoothed_vertices = postprocess::smooth(&faces, &mut g, p, surface);
    progress.report(0.8, "rebuilding")?;
    let rules = params.repair_rules(surface);
    let mut repair_report = RepairReport::default();
    let (mesh, map) = repair::repair(faces, &mut g, &rules, &mut repair_report);
    // The graph's attributes per vertex of `mesh`.
    let mesh_graph = g.select(&map);
    let (mut mesh, mesh_graph) = finish(
        mesh,
        mesh_graph,
        params,
        surface,
        &mut report,
        &mut repair_report,
    );
    let mut graph = Some(mesh_graph);
    if params.pure_quad {
        progress.report(0.9, "pure-quad split")?;
        if let Ok(split) = pure_quad::catmull_clark_split(&mesh, surface)
            && let Some(g) = graph.take()
        {
            (mesh, graph) = split_and_smooth(&mesh, split, g, p, surface);
        }
    }
    Ok(PostProcessed {
        mesh,
        report,
        repair: repair_report,
        graph,
    })
}

/// The post-processing's last steps on a rebuilt mesh and its graph: the
/// odd faces the rebuild left paired once more, then the wide-corner fix.
/// Run by [`post_process`], and again by [`finish_reopened`] on a mesh
/// whose input holes [`reopen`] opened.
fn finish(
    mut mesh: PolyMesh,
    mut mesh_graph: Graph,
    params: &ExtractionParams,
    surface: Option<&SurfaceIndex>,
    report: &mut PostProcessReport,
    repair_report: &mut RepairReport,
) -> (PolyMesh, Graph) {
    let p = &params.post;
    let rules = params.repair_rules(surface);
    // The rebuild's repair can leave odd faces of its own (a removed vertex
    // turns its quads into triangles): pair them once more.
    if p.pair_non_quads_degrees > 0.0 {
        let list = mesh.to_face_list();
        let mut faces: Vec<Vec<u32>> = list.iter().map(|f| f.to_vec()).collect();
        // Quads left folded (by the extraction, the smoothing or the
        // projection onto the input).
        let splits = if p.split_reflex_degrees > 0.0 {
            postprocess::split_reflex_quads(&mut faces, &mesh_graph, p.split_reflex_degrees)
        } else {
            0
        };
        report.reflex_quads_split += splits;
        if faces.iter().any(|f| f.len() != 4) {
            let m = postprocess::pair_with_fallback(&mut faces, &mut mesh_graph, p, surface, 1);
            let (rotated, collapsed) = if p.rotate_edges_degrees > 0.0 {
                let r = postprocess::rotate_edges(
                    &mut faces,
                    &mesh_graph,
                    p.rotate_edges_degrees,
                    p.wide_corner_degrees,
                );
                let c = if p.collapse_diagonals {
                    let d = p.rotate_edges_degrees;
                    postprocess::collapse_diagonals(&mut faces, &mut mesh_graph, d)
                } else {
                    0
                };
                (r, c)
            } else {
                (0, 0)
            };
            report.edges_rotated += rotated;
            report.diagonals_collapsed += collapsed;
            let valences_changed = rotated + collapsed > 0;
            if valences_changed {
                postprocess::smooth(&faces, &mut mesh_graph, p, surface);
            }
            if m > 0 || splits > 0 || valences_changed {
                report.non_quad_pairs_merged += m;
                let (again, map2) = repair::repair(faces, &mut mesh_graph, &rules, repair_report);
                mesh = again;
                mesh_graph = mesh_graph.select(&map2);
            }
        }
    }
    if p.fix_wide_corners && p.wide_corner_degrees > 0.0 {
        let list = mesh.to_face_list();
        let mut faces: Vec<Vec<u32>> = list.iter().map(|f| f.to_vec()).collect();
        let (moved, dissolved, splits) = postprocess::fix_wide_corners(
            &mut faces,
            &mut mesh_graph.pos,
            &mesh_graph.boundary,
            p.wide_corner_degrees,
            surface,
        );
        report.wide_corner_vertices_moved += moved;
        report.wide_corner_rim_vertices_dissolved += dissolved;
        // The triangles left may pair with other odd faces into quads whose
        // corners stay below the bar; the splits whose triangles did not
        // are taken back while the odd faces exceed the budget.
        if dissolved + splits.len() > 0 && p.pair_non_quads_degrees > 0.0 {
            let narrow = postprocess::PostProcessParams {
                pair_max_corner_deviation: p
                    .pair_max_corner_deviation
                    .min(p.wide_corner_degrees - 90.0),
                ..*p
            };
            report.non_quad_pairs_merged +=
                postprocess::pair_non_quads(&mut faces, &mesh_graph, &narrow, surface);
        }
        let undone =
            postprocess::undo_splits(&mut faces, &splits, p.wide_corner_split_budget_percent);
        report.wide_corner_quads_split += splits.len() - undone;
        if moved + dissolved + splits.len() > 0 {
            let (again, map2) = repair::repair(faces, &mut mesh_graph, &rules, repair_report);
            mesh = again;
            mesh_graph = mesh_graph.select(&map2);
        }
    }
    (mesh, mesh_graph)
}

/// [`finish`] once more, on a mesh whose input holes [`reopen`] opened
/// after the post-processing: the faces it removed leave odd faces on the
/// rims, with no pairing after them, and the corners it moved onto the
/// rims can leave quads with a corner above `wide_corner_degrees`.
/// `kept` gives the vertex of the post-processed mesh (whose graph is
/// `graph`) that each vertex of `opened` is; the vertices on `opened`'s
/// boundary, and only those, count as input-boundary vertices from here.
/// Its rebuilds fill no hole: these steps replace faces and remove none,
/// so every hole they meet is one of the input's, kept or opened again
/// (the repair's own test of that, by positions, closed the teapot's
/// spout again). Should the result have other boundary loops than
/// `opened`, or a loop of the input closed over again (the loop audit),
/// `None`: `opened` stays as it is. The counts go to `report` and
/// `repair_report`.
#[allow(clippy::too_many_arguments)]
pub fn finish_reopened(
    opened: &PolyMesh,
    kept: &[u32],
    graph: &Graph,
    input: &crate::mesh::TriMesh,
    surface: &SurfaceIndex,
    params: &ExtractionParams,
    report: &mut PostProcessReport,
    repair_report: &mut RepairReport,
) -> Option<(PolyMesh, Graph)> {
    if kept.len() != opened.vertex_count() || kept.iter().any(|&v| v as usize >= graph.len()) {
        return None;
    }
    let mut g = graph.select(kept);
    g.pos.clone_from(&opened.positions);
    for v in 0..opened.vertex_count() {
        g.boundary[v] = opened.is_boundary_vertex(v as u32);
    }
    let no_filling = ExtractionParams {
        max_hole: 0,
        fan_large_holes: false,
        ..*params
    };
    let (mut r, mut rr) = (*report, *repair_report);
    let (mesh, g) = finish(
        opened.clone(),
        g,
        &no_filling,
        Some(surface),
        &mut r,
        &mut rr,
    );
    let closed = |m: &PolyMesh| {
        crate::metrics::loop_audit(m, input)
            .fates
            .iter()
            .filter(|&&f| f == crate::metrics::LoopFate::ClosedOver)
            .count()
    };
    if mesh.boundary_loops().len() != opened.boundary_loops().len()
        || closed(&mesh) > closed(opened)
    {
        return None;
    }
    (*report, *repair_report) = (r, rr);
    Some((mesh, g))
}

/// The split mesh's new points (edge midpoints, face centroids) relaxed by
/// the post-processing's smoothing, as Instant Meshes smooths after its
/// split (digest §5.11–5.12): the centroid of a split triangle or pentagon
/// is a valence-3 or -5 vertex whose quads the smoothing evens out. The
/// old vertices get the attributes of `graph` (one entry per vertex of
/// `coarse`); an edge point is on the boundary when its edge is. Returns
/// the split mesh and its graph (`None` when `graph` does not fit
/// `coarse`; the split is then not smoothed).
fn split_and_smooth(
    coarse: &PolyMesh,
    mut split: PolyMesh,
    mut graph: Graph,
    p: &PostProcessParams,
    surface: Option<&SurfaceIndex>,
) -> (PolyMesh, Option<Graph>) {
    let nv = coarse.vertex_count();
    if graph.len() != nv || split.vertex_count() != nv + coarse.edge_count() + coarse.face_count() {
        return (split, None);
    }
    for e in 0..coarse.edge_count() as u32 {
        let h = 2 * e;
        let k = graph.push_copy(coarse.origin(h) as usize) as usize;
        graph.boundary[k] = coarse.is_boundary_halfedge(h) || coarse.is_boundary_halfedge(h ^ 1);
    }
    for f in 0..coarse.face_count() as u32 {
        let corner = coarse.origin(coarse.face_halfedge(f));
        let k = graph.push_copy(corner as usize) as usize;
        graph.boundary[k] = false;
    }
    graph.pos.clone_from(&split.positions);
    let faces: Vec<Vec<u32>> = split.to_face_list().iter().map(|f| f.to_vec()).collect();
    postprocess::smooth(&faces, &mut graph, p, surface);
    split.positions.clone_from(&graph.pos);
    (split, Some(graph))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::FaceList;

    /// [`postprocess::tests::plane_graph`] with `mesh`'s boundary.
    fn plane_graph(mesh: &PolyMesh) -> Graph {
        let mut g = postprocess::tests::plane_graph(mesh.positions.clone());
        g.boundary = (0..mesh.vertex_count() as u32)
            .map(|v| mesh.is_boundary_vertex(v))
            .collect();
        g
    }

    /// A quad on a rim with a vertex of that quad alone 8° off the chord
    /// of its neighbours (a 188° corner), as the reopening can leave one,
    /// next to a triangle: [`finish`] takes the vertex out (the quad
    /// becomes a triangle on the chord) and pairs the two triangles into a
    /// quad, leaving two quads with no corner above the bar. A mesh whose
    /// only wide corner is in a pentagon is left as it is.
    #[test]
    fn the_last_steps_fix_a_wide_corner_on_a_rim_and_pair_what_it_leaves() {
        let bend = 8f64.to_radians();
        let positions = vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(2.0, 0.0, 0.0),
            DVec3::new(2.0, 1.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(1.5, 0.5 * (0.5 * bend).tan(), 0.0),
        ];
        let params = ExtractionParams::default();
        let run = |mesh: &PolyMesh| {
            let (mut report, mut repair) = Default::default();
            let (out, graph) = finish(
                mesh.clone(),
                plane_graph(mesh),
                &params,
                None,
                &mut report,
                &mut repair,
            );
            assert_eq!(graph.len(), out.vertex_count());
            (out, report)
        };
        let mut faces = FaceList::new();
        faces.push(&[0, 1, 4, 5]);
        faces.push(&[1, 6, 2, 3, 4]);
        let pentagon = PolyMesh::from_faces(positions.clone(), &faces).unwrap();
        let (out, report) = run(&pentagon);
        assert_eq!(out.positions, pentagon.positions);
        assert_eq!(out.face_count(), 2);
        assert_eq!(report, PostProcessReport::default());

        let mut faces = FaceList::new();
        faces.push(&[0, 1, 4, 5]);
        faces.push(&[1, 6, 2, 3]);
        faces.push(&[1, 3, 4]);
        let mesh = PolyMesh::from_faces(positions, &faces).unwrap();
        let (fixed, report) = run(&mesh);
        assert_eq!(report.wide_corner_rim_vertices_dissolved, 1);
        assert_eq!(fixed.vertex_count(), 6);
        let degrees: Vec<usize> = (0..fixed.face_count() as u32)
            .map(|f| fixed.face_vertices(f).count())
            .collect();
        assert_eq!(degrees, vec![4, 4]);
        let widest = crate::metrics::quad_metrics(&fixed.positions, &fixed.to_face_list())
            .max_corner_angle_degrees;
        assert!(widest <= params.post.wide_corner_degrees, "{widest}");
    }
}
