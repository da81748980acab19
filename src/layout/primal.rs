//! Primalization (Campen & Kobbelt 2014, *Dual Strip Weaving*, §7): the
//! quad layout dual to the loop arrangement of [`super::regions`].
//!
//! A region is a layout vertex, a loop arc (a loop's stretch between two
//! consecutive loop crossings) is a layout edge joining the regions on its
//! two sides (a closed loop crossed by no other gives no edge), and a
//! crossing of two loops is a quad patch whose corners are the four
//! regions around it. A vertex sits on the region's cross-field
//! singularity if it holds exactly one, otherwise at its geodesic centre:
//! the mesh vertex farthest from the region's boundary (multi-source
//! Dijkstra over the region's uncrossed mesh edges, seeded with the
//! distances to the loop crossings on its crossed edges and 0 on the mesh
//! boundary) — except in valence-4 and boundary regions, see below.
//!
//! Deviations from the paper:
//! - Edge routes are not elastica in the corridor: each is the shortest
//!   path over the region's mesh edges from the vertex to the mesh vertex
//!   next to the arc's middle loop crossing, through that crossing, and on
//!   to the other vertex; then a few Laplacian smoothing steps, each point
//!   projected back onto the surface (the crossing point stays fixed).
//! - In closed valence-4 regions without singularity the paper puts the
//!   vertex where the two corridor curves cross; we take the mesh vertex
//!   with the least summed geodesic distance to the four arc middles (on
//!   both shortest curves joining opposite middles where they cross).
//! - Open surfaces (boundary-aligned layouts, dual curves ending on the
//!   boundary): a region touching the mesh boundary gets its vertex on the
//!   boundary — at its sharpest boundary corner (turning ≥ π/4), else at
//!   the boundary vertex farthest from the loops — and the layout edge of
//!   an arc ending on the boundary is routed through that end, along the
//!   boundary. A region touching the boundary along several stretches has
//!   no vertex (it would need one per stretch and an edge between them
//!   that is dual to no loop): [`super::regions`] colours it red and names
//!   it. Trimmed (non-aligned) layouts, where the boundary cuts patches,
//!   are not built.
//! - Holes no dual curve ends on (mesh-boundary loops inside a region; not
//!   in the paper): the layout is built as if they were capped — a region's
//!   vertex goes on the boundary only along a stretch between curve ends,
//!   else to its geodesic centre, away from the holes (distance 0 on their
//!   rims) — and [`QuadLayout::holes`] keeps their rims, along which
//!   [`super::grid::grid_layout`] cuts them out of the grid.
//! - [`QuadLayout::move_vertex`] snaps the new point to the surface and
//!   re-routes from the region's mesh vertex nearest to it; a point outside
//!   the vertex's region is rejected.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use glam::DVec3;
use serde::{Deserialize, Serialize};

use super::OrdF64;
use super::embed::{EmbeddedLoop, Singularity};
use super::regions::{Edges, RegionError, Regions};
use crate::mesh::TriMesh;
use crate::spatial::SurfaceIndex;

/// Least turning of the mesh boundary (π − Σ angles) at a vertex for it to
/// be taken as a boundary region's layout corner.
const BOUNDARY_CORNER: f64 = std::f64::consts::FRAC_PI_4;

/// Laplacian smoothing steps on an edge route.
const SMOOTHING_STEPS: usize = 10;

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LayoutVertex {
    pub position: DVec3,
    /// A triangle the position lies on.
    pub face: u32,
    pub region: u32,
    /// Placed on a cross-field singularity.
    pub singular: bool,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LayoutEdge {
    /// Layout vertices: the regions left and right of the arc.
    pub ends: [u32; 2],
    /// The loop arc it crosses (index into `Regions::arcs`) and its loop.
    pub arc: u32,
    pub loop_index: u32,
    /// Route on the surface from `ends[0]` to `ends[1]`.
    pub polyline: Vec<DVec3>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LayoutPatch {
    /// Counter-clockwise; `edges[i]` joins `corners[i]` and `corners[i+1]`.
    pub corners: [u32; 4],
    pub edges: [u32; 4],
    /// The loop crossing it is dual to (index into `Regions::crossings`).
    pub crossing: u32,
    /// Whether `edges[i]`'s polyline runs from `corners[i + 1]` to
    /// `corners[i]` (against the patch's counter-clockwise order); needed
    /// where both corners are one layout vertex.
    #[serde(default)]
    pub reversed: [bool; 4],
}

/// The exported layout: what `to_json` writes and `from_json` reads.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LayoutExport {
    pub vertices: Vec<LayoutVertex>,
    pub edges: Vec<LayoutEdge>,
    pub patches: Vec<LayoutPatch>,
    /// See [`QuadLayout::holes`].
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub holes: Vec<Vec<DVec3>>,
}

impl LayoutExport {
    pub fn from_json(text: &str) -> Result<LayoutExport, serde_json::Error> {
        serde_json::from_str(text)
    }

    /// Maps the layout onto another surface of the same shape (a proxy's
    /// layout onto the original, §8.1): every vertex and route point to its
    /// closest point there.
    pub fn project_onto(&mut self, index: &SurfaceIndex) {
        for v in &mut self.vertices {
            let c = index.closest(v.position);
            v.position = c.point;
            v.face = c.face;
        }
        for p in self
            .edges
            .iter_mut()
            .flat_map(|e| &mut e.polyline)
            .chain(self.holes.iter_mut().flatten())
        {
            *p = index.closest(*p).point;
        }
    }
}

/// A quad layout on the surface; vertex i is region i.
pub struct QuadLayout {
    pub vertices: Vec<LayoutVertex>,
    pub edges: Vec<LayoutEdge>,
    pub patches: Vec<LayoutPatch>,
    /// The rims of the holes no dual curve ends on (closed, the surface on
    /// their left): the layout covers them as if capped; the grid cuts
    /// them out.
    pub holes: Vec<Vec<DVec3>>,
    router: Router,
}

/// What re-routing needs: the region graph of mesh vertices and, per
/// layout edge, the fixed point where it crosses its arc.
struct Router {
    positions: Vec<DVec3>,
    triangles: Vec<[u32; 3]>,
    vertex_region: Vec<u32>,
    /// Uncrossed mesh edges per vertex (CSR).
    offsets: Vec<u32>,
    neighbours: Vec<u32>,
    /// Shortest-path tree towards each layout vertex's source.
    parent: Vec<u32>,
    /// Dijkstra scratch, all infinite between runs.
    dist: Vec<f64>,
    /// Mesh vertex each layout vertex's routes start from (`u32::MAX` for
    /// a region too thin to hold a mesh vertex).
    source: Vec<u32>,
    /// Per layout edge: the crossing point and the mesh vertices beside it
    /// in the left and right region (`None`: a region without vertices).
    middles: Vec<(DVec3, [Option<u32>; 2])>,
    index: Option<SurfaceIndex>,
}

impl Router {
    /// Dijkstra inside one region from the given (vertex, distance) seeds;
    /// fills `parent` for the vertices reached if `record_parent`, and
    /// returns the vertices reached with their distances.
    fn dijkstra(&mut self, seeds: &[(u32, f64)], record_parent: bool) -> Vec<(u32, f64)> {
        let mut heap = BinaryHeap::new();
        let mut touched = Vec::new();
        for &(v, d) in seeds {
            if d < self.dist[v as usize] {
                if self.dist[v as usize] == f64::INFINITY {
                    touched.push(v);
                }
                self.dist[v as usize] = d;
                heap.push((Reverse(OrdF64(d)), v));
                if record_parent {
                    self.parent[v as usize] = v;
                }
            }
        }
        let mut done = Vec::new();
        while let Some((Reverse(OrdF64(d)), v)) = heap.pop() {
            if d > self.dist[v as usize] {
                continue;
            }
            done.push((v, d));
            for i in self.offsets[v as usize]..self.offsets[v as usize + 1] {
                let w = self.neighbours[i as usize];
                let nd = d + self.positions[v as usize].distance(self.positions[w as usize]);
                if nd < self.dist[w as usize] {
                    if self.dist[w as usize] == f64::INFINITY {
                        touched.push(w);
                    }
                    self.dist[w as usize] = nd;
                    heap.push((Reverse(OrdF64(nd)), w));
                    if record_parent {
                        self.parent[w as usize] = v;
                    }
                }
            }
        }
        for v in touched {
            self.dist[v as usize] = f64::INFINITY;
        }
        done
    }

    /// Mesh vertices from `v` back to its tree's source.
    fn path_to_source(&self, mut v: u32) -> Vec<u32> {
        if self.parent[v as usize] == u32::MAX {
            return Vec::new();
        }
        let mut out = vec![v];
        for _ in 0..self.positions.len() {
            let p = self.parent[v as usize];
            if p == v || p == u32::MAX {
                break;
            }
            out.push(p);
            v = p;
        }
        out
    }

    fn nearest_in_region(&self, region: u32, p: DVec3) -> Option<u32> {
        (0..self.positions.len() as u32)
            .filter(|&v| self.vertex_region[v as usize] == region)
            .min_by(|&a, &b| {
                self.positions[a as usize]
                    .distance_squared(p)
                    .total_cmp(&self.positions[b as usize].distance_squared(p))
            })
    }

    /// Route of an edge from `from` (layout vertex position) to `to`.
    fn route(&self, from: DVec3, to: DVec3, edge: usize) -> Vec<DVec3> {
        let (mid, beside) = self.middles[edge];
        let mut pts = vec![from];
        let path = |b: Option<u32>| b.map(|v| self.path_to_source(v)).unwrap_or_default();
        pts.extend(
            path(beside[0])
                .iter()
                .rev()
                .map(|&v| self.positions[v as usize]),
        );
        pts.push(mid);
        pts.extend(path(beside[1]).iter().map(|&v| self.positions[v as usize]));
        pts.push(to);
        pts.dedup_by(|a, b| a.distance(*b) < 1e-12);
        // The arc crossing stays where it is.
        let fixed = pts.iter().position(|p| *p == mid);
        if let Some(index) = &self.index {
            for _ in 0..SMOOTHING_STEPS {
                let prev = pts.clone();
                for i in 1..pts.len().saturating_sub(1) {
                    if Some(i) != fixed {
                        let q = 0.5 * prev[i] + 0.25 * (prev[i - 1] + prev[i + 1]);
                        pts[i] = index.closest(q).point;
                    }
                }
            }
        }
        pts
    }
}

impl QuadLayout {
    /// The layout dual to `loops`; `regions` must come from
    /// [`Regions::compute`] on the same mesh and loops and be sufficient.
    pub fn build(
        mesh: &TriMesh,
        loops: &[EmbeddedLoop],
        regions: &Regions,
        singularities: &[Singularity],
    ) -> Result<QuadLayout, RegionError> {
        check_inputs(mesh, loops, regions)?;
        let nv = mesh.positions.len();
        let mut router = Router::uncrossed(mesh, loops, regions);

        // Distances from region boundaries: loop crossings and mesh boundary.
        let on_boundary = crate::mesh::boundary_vertices(mesh);
        let (seeds, loop_seeds) = region_seeds(mesh, loops, regions, &on_boundary);
        // Turning of the mesh boundary at each boundary vertex: π − Σ angles.
        let turning: Vec<f64> = mesh
            .angle_defects()
            .iter()
            .map(|d| d - std::f64::consts::PI)
            .collect();

        let arc_middles = arc_middles(mesh, loops, regions, &mut router);
        let holes: Vec<&Vec<u32>> = regions.regions.iter().flat_map(|g| &g.holes).collect();
        let mut on_hole = vec![false; nv];
        for &v in holes.iter().copied().flatten() {
            on_hole[v as usize] = true;
        }
        let mut vertices = Vec::with_capacity(regions.regions.len());
        for (r, region) in regions.regions.iter().enumerate() {
            let single = match region.singularities[..] {
                [s] => singularities.get(s as usize).map(|s| s.vertex),
                _ => None,
            };
            let vertex = if let Some(v) = single {
                Some(v)
            } else if region.boundary_stretches() > 0 {
                // Boundary-aligned layout: on the mesh boundary, at its
                // sharpest corner in the region, else farthest from loops.
                let on_region_boundary = |v: u32| {
                    on_boundary[v as usize]
                        && !on_hole[v as usize]
                        && regions.vertex_region[v as usize] == r as u32
                };
                let corner = (0..nv as u32)
                    .filter(|&v| on_region_boundary(v))
                    .max_by(|&a, &b| {
                        turning[a as usize]
                            .total_cmp(&turning[b as usize])
                            .then(b.cmp(&a))
                    })
                    .filter(|&v| turning[v as usize] >= BOUNDARY_CORNER);
                corner.or_else(|| {
                    router
                        .dijkstra(&loop_seeds[r], false)
                        .iter()
                        .filter(|&&(v, _)| on_region_boundary(v))
                        .max_by(|a, b| a.1.total_cmp(&b.1).then(b.0.cmp(&a.0)))
                        .map(|&(v, _)| v)
                })
            } else if let Some(v) = corridor_crossing(&mut router, region, &arc_middles) {
                Some(v)
            } else if seeds[r].is_empty() {
                // No boundary at all (no loops): any vertex of the region.
                (0..nv as u32).find(|&v| regions.vertex_region[v as usize] == r as u32)
            } else {
                let reached = router.dijkstra(&seeds[r], false);
                reached
                    .iter()
                    .max_by(|a, b| a.1.total_cmp(&b.1).then(b.0.cmp(&a.0)))
                    .map(|&(v, _)| v)
            };
            let (position, face) = match vertex {
                Some(v) => (mesh.positions[v as usize], first_face(mesh, v)),
                None => thin_region_point(regions, r as u32, router.index.as_ref())
                    .ok_or_else(|| RegionError::Degenerate(format!("region {r} is empty")))?,
            };
            vertices.push(LayoutVertex {
                position,
                face,
                region: r as u32,
                singular: single.is_some(),
            });
            router.source.push(vertex.unwrap_or(u32::MAX));
        }
        for r in 0..vertices.len() {
            let s = router.source[r];
            if s != u32::MAX {
                router.dijkstra(&[(s, 0.0)], true);
            }
        }
        let (layout_edges, edge_of_arc) =
            route_edges(loops, regions, &vertices, &arc_middles, &mut router);
        let patches = regions
            .crossings
            .iter()
            .enumerate()
            .map(|(c, x)| LayoutPatch {
                corners: x.corners,
                edges: x.arcs.map(|a| edge_of_arc[a as usize]),
                crossing: c as u32,
                // Polylines run from the arc's left to its right region; an
                // arc leaving the crossing has corners[i] on its right.
                reversed: x.outgoing,
            })
            .collect();
        Ok(QuadLayout {
            vertices,
            edges: layout_edges,
            patches,
            holes: holes
                .iter()
                .map(|rim| rim.iter().map(|&v| mesh.positions[v as usize]).collect())
                .collect(),
            router,
        })
    }

    /// Moves layout vertex `i` to the surface point nearest `point` and
    /// re-routes its edges. The point must lie in the vertex's region.
    pub fn move_vertex(&mut self, i: usize, point: DVec3) -> Result<(), RegionError> {
        if i >= self.vertices.len() || !point.is_finite() {
            return Err(RegionError::Invalid(format!(
                "cannot move layout vertex {i} to {point}"
            )));
        }
        let region = self.vertices[i].region;
        let (snapped, face) = match &self.router.index {
            Some(index) => {
                let c = index.closest(point);
                (c.point, c.face)
            }
            None => (point, self.vertices[i].face),
        };
        let tri = self.router.triangles[face as usize];
        let nearest = *tri
            .iter()
            .min_by(|&&a, &&b| {
                let pa = self.router.positions[a as usize];
                let pb = self.router.positions[b as usize];
                pa.distance_squared(snapped)
                    .total_cmp(&pb.distance_squared(snapped))
            })
            .unwrap_or(&tri[0]);
        if self.router.vertex_region[nearest as usize] != region {
            return Err(RegionError::Invalid(format!(
                "the point lies outside region {region} of layout vertex {i}"
            )));
        }
        self.vertices[i].position = snapped;
        self.vertices[i].face = face;
        self.vertices[i].singular = false;
        self.router.source[i] = nearest;
        self.router.dijkstra(&[(nearest, 0.0)], true);
        for (k, e) in self.edges.iter_mut().enumerate() {
            if e.ends.contains(&(i as u32)) {
                e.polyline = self.router.route(
                    self.vertices[e.ends[0] as usize].position,
                    self.vertices[e.ends[1] as usize].position,
                    k,
                );
            }
        }
        Ok(())
    }

    pub fn export(&self) -> LayoutExport {
        LayoutExport {
            vertices: self.vertices.clone(),
            edges: self.edges.clone(),
            patches: self.patches.clone(),
            holes: self.holes.clone(),
        }
    }

    /// JSON: `{ vertices: [{position, face, region, singular}], edges:
    /// [{ends, arc, loop_index, polyline}], patches: [{corners, edges,
    /// crossing, reversed}], holes: [[point]] }` (holes only when there
    /// are some), positions as `[x, y, z]`.
    pub fn to_json(&self) -> Result<String, serde_json::Error> {
        serde_json::to_string(&self.export())
    }

    /// OBJ lines: `v` per polyline point, one `l` per layout edge, comments
    /// naming the vertices and patches.
    pub fn to_obj(&self) -> String {
        use std::fmt::Write;
        let mut s = String::new();
        let _ = writeln!(
            s,
            "# quad layout (dual strip weaving): {} vertices, {} edges, {} patches",
            self.vertices.len(),
            self.edges.len(),
            self.patches.len()
        );
        for (i, v) in self.vertices.iter().enumerate() {
            let p = v.position;
            let _ = writeln!(
                s,
                "# vertex {i} {} {} {} region {}",
                p.x, p.y, p.z, v.region
            );
        }
        let mut next = 1usize;
        for (i, e) in self.edges.iter().enumerate() {
            let _ = writeln!(s, "# edge {i} joins vertices {} {}", e.ends[0], e.ends[1]);
            for p in &e.polyline {
                let _ = writeln!(s, "v {} {} {}", p.x, p.y, p.z);
            }
            let ids: Vec<String> = (next..next + e.polyline.len())
                .map(|k| k.to_string())
                .collect();
            let _ = writeln!(s, "l {}", ids.join(" "));
            next += e.polyline.len();
        }
        for (i, p) in self.patches.iter().enumerate() {
            let _ = writeln!(
                s,
                "# patch {i} corners {} {} {} {} edges {} {} {} {}",
                p.corners[0],
                p.corners[1],
                p.corners[2],
                p.corners[3],
                p.edges[0],
                p.edges[1],
                p.edges[2],
                p.edges[3]
            );
        }
        s
    }
}

/// The regular vertex of a closed valence-4 region (§7: "in regions of
/// valence 4 two curves cross"): the mesh vertex minimizing the summed
/// geodesic distances to the four arc middles, which is where the two
/// shortest curves joining opposite middles cross.
fn corridor_crossing(
    router: &mut Router,
    region: &super::regions::Region,
    arc_middles: &[(DVec3, [Option<u32>; 2])],
) -> Option<u32> {
    use super::regions::BoundarySide;
    if region.valence != 4 || region.touches_mesh_boundary || region.boundary.len() != 1 {
        return None;
    }
    let mut sums: std::collections::HashMap<u32, (f64, u32)> = Default::default();
    for side in &region.boundary[0] {
        let BoundarySide::Arc { arc, left } = *side else {
            return None;
        };
        let (mid, beside) = arc_middles[arc as usize];
        let v = beside[if left { 0 } else { 1 }]?;
        let d0 = router.positions[v as usize].distance(mid);
        for (w, d) in router.dijkstra(&[(v, d0)], false) {
            let e = sums.entry(w).or_insert((0.0, 0));
            e.0 += d;
            e.1 += 1;
        }
    }
    sums.into_iter()
        .filter(|&(_, (_, n))| n == 4)
        .min_by(|a, b| a.1.0.total_cmp(&b.1.0).then(a.0.cmp(&b.0)))
        .map(|(v, _)| v)
}

/// A point for a region that holds no mesh vertex (thinner than a
/// triangle): the mean of the loop crossings at its corners, on the surface.
fn thin_region_point(
    regions: &Regions,
    r: u32,
    index: Option<&SurfaceIndex>,
) -> Option<(DVec3, u32)> {
    let corners: Vec<&super::regions::LoopCrossing> = regions
        .crossings
        .iter()
        .filter(|c| c.corners.contains(&r))
        .collect();
    let first = corners.first()?;
    let mean = corners.iter().map(|c| c.point).sum::<DVec3>() / corners.len() as f64;
    Some(match index {
        Some(index) => {
            let c = index.closest(mean);
            (c.point, c.face)
        }
        None => (first.point, first.face),
    })
}

fn first_face(mesh: &TriMesh, v: u32) -> u32 {
    mesh.triangles
        .iter()
        .position(|t| t.contains(&v))
        .unwrap_or(0) as u32
}

/// The layout needs sufficient regions computed on this mesh and these
/// loops.
fn check_inputs(
    mesh: &TriMesh,
    loops: &[EmbeddedLoop],
    regions: &Regions,
) -> Result<(), RegionError> {
    if !regions.sufficient {
        return Err(RegionError::Insufficient(regions.red_count()));
    }
    if regions.vertex_region.len() != mesh.positions.len()
        || regions.face_region.len() != mesh.triangles.len()
    {
        return Err(RegionError::Invalid(
            "regions were computed on another mesh".into(),
        ));
    }
    let from_these_loops = regions.arcs.iter().all(|a| {
        loops.get(a.loop_index as usize).is_some_and(|l| {
            a.edge_crossings
                .iter()
                .all(|&c| (c as usize) < l.crossings.len())
        })
    });
    if !from_these_loops {
        return Err(RegionError::Invalid(
            "regions were computed for other loops".into(),
        ));
    }
    Ok(())
}

impl Router {
    /// A router over the mesh edges no loop crosses (their ends lie in one
    /// region).
    fn uncrossed(mesh: &TriMesh, loops: &[EmbeddedLoop], regions: &Regions) -> Router {
        let nv = mesh.positions.len();
        let edges = Edges::new(mesh);
        // Uncrossed edges (their ends lie in one region).
        let mut crossed = vec![false; edges.verts.len()];
        for l in loops {
            for c in &l.crossings {
                if let Some(e) = edges.find(c.a, c.b) {
                    crossed[e as usize] = true;
                }
            }
        }
        let mut pairs: Vec<(u32, u32)> = Vec::new();
        for (e, &[a, b]) in edges.verts.iter().enumerate() {
            if !crossed[e] {
                pairs.push((a, b));
                pairs.push((b, a));
            }
        }
        pairs.sort_unstable();
        let mut offsets = vec![0u32; nv + 1];
        for &(a, _) in &pairs {
            offsets[a as usize + 1] += 1;
        }
        for i in 0..nv {
            offsets[i + 1] += offsets[i];
        }
        Router {
            positions: mesh.positions.clone(),
            triangles: mesh.triangles.clone(),
            vertex_region: regions.vertex_region.clone(),
            offsets,
            neighbours: pairs.iter().map(|p| p.1).collect(),
            parent: vec![u32::MAX; nv],
            dist: vec![f64::INFINITY; nv],
            source: Vec::new(),
            middles: Vec::new(),
            index: SurfaceIndex::new(mesh),
        }
    }
}

/// Per region, Dijkstra sources with their start distances.
type Seeds = Vec<Vec<(u32, f64)>>;

/// Dijkstra seeds per region: the mesh vertices beside every loop crossing
/// (at their distance to it), and, in the first list only, also the mesh
/// boundary vertices (at zero). Returns (all seeds, loop seeds).
fn region_seeds(
    mesh: &TriMesh,
    loops: &[EmbeddedLoop],
    regions: &Regions,
    on_boundary: &[bool],
) -> (Seeds, Seeds) {
    let mut seeds: Seeds = vec![Vec::new(); regions.regions.len()];
    for l in loops {
        for c in &l.crossings {
            let p = mesh.positions[c.a as usize].lerp(mesh.positions[c.b as usize], c.t);
            for v in [c.a, c.b] {
                let r = regions.vertex_region[v as usize];
                seeds[r as usize].push((v, mesh.positions[v as usize].distance(p)));
            }
        }
    }
    let loop_seeds = seeds.clone();
    for (v, &b) in on_boundary.iter().enumerate() {
        let r = regions.vertex_region[v];
        if b && r != u32::MAX {
            seeds[r as usize].push((v as u32, 0.0));
        }
    }
    (seeds, loop_seeds)
}

/// Where each arc's layout edge crosses it, and the mesh vertices beside
/// that point in the regions left and right.
fn arc_middles(
    mesh: &TriMesh,
    loops: &[EmbeddedLoop],
    regions: &Regions,
    router: &mut Router,
) -> Vec<(DVec3, [Option<u32>; 2])> {
    let mut arc_middles: Vec<(DVec3, [Option<u32>; 2])> = Vec::with_capacity(regions.arcs.len());
    for arc in &regions.arcs {
        let l = &loops[arc.loop_index as usize];
        let (mid, near) = if arc.edge_crossings.is_empty() {
            let a = arc.start.map(|c| regions.crossings[c as usize].point);
            let b = arc.end.map(|c| regions.crossings[c as usize].point);
            let m = match (a, b) {
                (Some(a), Some(b)) => 0.5 * (a + b),
                (Some(a), None) | (None, Some(a)) => a,
                (None, None) => DVec3::ZERO,
            };
            (m, [None, None])
        } else {
            // Arcs ending on the mesh boundary: through their end there,
            // so the layout edge runs along the boundary.
            let ec = &arc.edge_crossings;
            let at = if l.closed {
                ec[ec.len() / 2]
            } else if arc.end.is_none() {
                ec[ec.len() - 1]
            } else if arc.start.is_none() {
                ec[0]
            } else {
                ec[ec.len() / 2]
            };
            let c = l.crossings[at as usize];
            let p = mesh.positions[c.a as usize].lerp(mesh.positions[c.b as usize], c.t);
            let pick = |r: u32| {
                [c.a, c.b]
                    .into_iter()
                    .find(|&v| regions.vertex_region[v as usize] == r)
            };
            if arc.left == arc.right {
                // One region on both sides (a loop that does not separate
                // it, as on a torus): the crossed edge's end on each side,
                // so the edge's route leaves the region on one side of the
                // loop and comes back on the other.
                (p, sides_of_crossing(mesh, l, at as usize))
            } else {
                (p, [pick(arc.left), pick(arc.right)])
            }
        };
        let mut beside = [None; 2];
        for (k, r) in [arc.left, arc.right].into_iter().enumerate() {
            beside[k] = near[k].or_else(|| router.nearest_in_region(r, mid));
        }
        arc_middles.push((mid, beside));
    }
    arc_middles
}

/// The ends of the mesh edge loop `l` crosses at its crossing `at` that lie
/// on the loop's left and on its right (seen along the loop, normal up).
fn sides_of_crossing(mesh: &TriMesh, l: &EmbeddedLoop, at: usize) -> [Option<u32>; 2] {
    let n = l.crossings.len();
    let point = |i: usize| {
        let c = l.crossings[i];
        mesh.positions[c.a as usize].lerp(mesh.positions[c.b as usize], c.t)
    };
    let (prev, next) = if l.closed {
        ((at + n - 1) % n, (at + 1) % n)
    } else {
        (at.saturating_sub(1), (at + 1).min(n - 1))
    };
    let direction = point(next) - point(prev);
    let face = l.faces.get(at.min(l.faces.len().saturating_sub(1)));
    let normal = face.map_or(DVec3::ZERO, |&f| mesh.face_normal_unnormalized(f as usize));
    let left = normal.cross(direction);
    let c = l.crossings[at];
    let p = point(at);
    let a_left = (mesh.positions[c.a as usize] - p).dot(left) > 0.0;
    if a_left {
        [Some(c.a), Some(c.b)]
    } else {
        [Some(c.b), Some(c.a)]
    }
}

/// One edge per arc, routed through the arc's middle crossing. A closed
/// loop crossed by no loop bounds no patch: no edge. Returns the edges and
/// each arc's edge (`u32::MAX` for none).
fn route_edges(
    loops: &[EmbeddedLoop],
    regions: &Regions,
    vertices: &[LayoutVertex],
    arc_middles: &[(DVec3, [Option<u32>; 2])],
    router: &mut Router,
) -> (Vec<LayoutEdge>, Vec<u32>) {
    let mut layout_edges = Vec::with_capacity(regions.arcs.len());
    let mut edge_of_arc = vec![u32::MAX; regions.arcs.len()];
    for (i, arc) in regions.arcs.iter().enumerate() {
        let l = &loops[arc.loop_index as usize];
        if l.closed && arc.start.is_none() {
            continue;
        }
        edge_of_arc[i] = layout_edges.len() as u32;
        let (mid, beside) = arc_middles[i];
        router.middles.push((mid, beside));
        let ends = [arc.left, arc.right];
        let polyline = router.route(
            vertices[ends[0] as usize].position,
            vertices[ends[1] as usize].position,
            layout_edges.len(),
        );
        layout_edges.push(LayoutEdge {
            ends,
            arc: i as u32,
            loop_index: arc.loop_index,
            polyline,
        });
    }
    (layout_edges, edge_of_arc)
}
