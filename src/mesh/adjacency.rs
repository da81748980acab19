//! Adjacency in compressed-row (CSR) form: vertex → neighbouring vertices,
//! vertex → incident faces, face → edge-adjacent faces, and n-ring
//! neighbourhoods.
//!
//! Every list is sorted by index, so everything built on it is deterministic.
//! Non-manifold input is fine: a vertex's neighbours are simply all vertices
//! it shares an edge with, and faces around a non-manifold edge are all
//! adjacent to each other.

use std::collections::HashMap;

use super::TriMesh;

/// Compressed rows: row `i` is `items[offsets[i]..offsets[i + 1]]`.
///
/// Invariants: `offsets.len() == rows + 1`, `offsets[0] == 0`, `offsets` is
/// non-decreasing and ends at `items.len()`.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Csr {
    pub offsets: Vec<u32>,
    pub items: Vec<u32>,
}

impl Csr {
    /// Builds rows from `(row, item)` pairs; each row sorted, duplicates removed.
    pub fn from_pairs(rows: usize, mut pairs: Vec<(u32, u32)>) -> Csr {
        pairs.sort_unstable();
        pairs.dedup();
        let mut offsets = vec![0u32; rows + 1];
        for &(r, _) in &pairs {
            offsets[r as usize + 1] += 1;
        }
        for r in 0..rows {
            offsets[r + 1] += offsets[r];
        }
        Csr {
            offsets,
            items: pairs.into_iter().map(|(_, i)| i).collect(),
        }
    }

    pub fn rows(&self) -> usize {
        self.offsets.len().saturating_sub(1)
    }

    pub fn row(&self, r: usize) -> &[u32] {
        &self.items[self.offsets[r] as usize..self.offsets[r + 1] as usize]
    }
}

/// Vertex → neighbouring vertices (one entry per undirected edge end).
///
/// Built from a triangle mesh, or from any edge list — coarser levels of the
/// multiresolution hierarchy are vertex graphs without triangles, and the
/// analysis runs on them too.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct VertexAdjacency {
    csr: Csr,
}

impl VertexAdjacency {
    /// The edges of `mesh`'s triangles. Unreferenced vertices get no neighbours.
    pub fn new(mesh: &TriMesh) -> VertexAdjacency {
        let mut pairs = Vec::with_capacity(mesh.triangles.len() * 6);
        for t in &mesh.triangles {
            for i in 0..3 {
                let (a, b) = (t[i], t[(i + 1) % 3]);
                pairs.push((a, b));
                pairs.push((b, a));
            }
        }
        VertexAdjacency {
            csr: Csr::from_pairs(mesh.positions.len(), pairs),
        }
    }

    /// From undirected edges over `vertex_count` vertices. Edges with an end
    /// out of range and self-loops are ignored.
    pub fn from_edges(vertex_count: usize, edges: &[[u32; 2]]) -> VertexAdjacency {
        let mut pairs = Vec::with_capacity(edges.len() * 2);
        for &[a, b] in edges {
            if a != b && (a as usize) < vertex_count && (b as usize) < vertex_count {
                pairs.push((a, b));
                pairs.push((b, a));
            }
        }
        VertexAdjacency {
            csr: Csr::from_pairs(vertex_count, pairs),
        }
    }

    pub fn vertex_count(&self) -> usize {
        self.csr.rows()
    }

    pub fn neighbors(&self, v: usize) -> &[u32] {
        self.csr.row(v)
    }

    pub fn degree(&self, v: usize) -> usize {
        self.neighbors(v).len()
    }

    /// The underlying rows (offsets and neighbour indices).
    pub fn csr(&self) -> &Csr {
        &self.csr
    }
}

/// Vertex → incident triangles.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct VertexFaces {
    csr: Csr,
}

impl VertexFaces {
    pub fn new(mesh: &TriMesh) -> VertexFaces {
        let mut pairs = Vec::with_capacity(mesh.triangles.len() * 3);
        for (f, t) in mesh.triangles.iter().enumerate() {
            for &v in t {
                pairs.push((v, f as u32));
            }
        }
        VertexFaces {
            csr: Csr::from_pairs(mesh.positions.len(), pairs),
        }
    }

    pub fn faces(&self, v: usize) -> &[u32] {
        self.csr.row(v)
    }
}

/// Triangle → triangles sharing an edge with it (the dual graph).
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct FaceAdjacency {
    csr: Csr,
}

impl FaceAdjacency {
    pub fn new(mesh: &TriMesh) -> FaceAdjacency {
        let sides = sorted_sides(mesh);
        let mut pairs = Vec::with_capacity(sides.len() * 2);
        for run in edge_runs(&sides) {
            for (x, sx) in run.iter().enumerate() {
                for (y, sy) in run.iter().enumerate() {
                    if x != y {
                        pairs.push((sx.2, sy.2));
                    }
                }
            }
        }
        FaceAdjacency {
            csr: Csr::from_pairs(mesh.triangles.len(), pairs),
        }
    }

    pub fn neighbors(&self, f: usize) -> &[u32] {
        self.csr.row(f)
    }

    /// The underlying rows (offsets and neighbouring face indices).
    pub fn csr(&self) -> &Csr {
        &self.csr
    }
}

/// A triangle side: (min vertex, max vertex, face, local edge `i` from
/// corner `i` to corner `i + 1`).
type Side = (u32, u32, u32, u8);

/// Every triangle side, sorted: the sides of one undirected edge stand
/// together, in face order.
fn sorted_sides(mesh: &TriMesh) -> Vec<Side> {
    let mut sides: Vec<Side> = Vec::with_capacity(mesh.triangles.len() * 3);
    for (f, t) in mesh.triangles.iter().enumerate() {
        for i in 0..3 {
            let (a, b) = super::edge_key(t[i], t[(i + 1) % 3]);
            sides.push((a, b, f as u32, i as u8));
        }
    }
    sides.sort_unstable();
    sides
}

/// The runs of [`sorted_sides`] that share one undirected edge.
fn edge_runs(sides: &[Side]) -> impl Iterator<Item = &[Side]> {
    sides.chunk_by(|a, b| (a.0, a.1) == (b.0, b.1))
}

/// Per face and local edge i (from corner i to corner i + 1): the face on
/// the other side, or `u32::MAX` on the boundary, at non-manifold edges and
/// where the two faces are oppositely oriented (a twisted pair would make
/// charts built across it disagree).
#[derive(Debug, Clone, PartialEq)]
pub struct EdgeTopology {
    pub opposite: Vec<[u32; 3]>,
    /// The local edge index of the same edge in the opposite face.
    pub opposite_edge: Vec<[u8; 3]>,
}

impl EdgeTopology {
    pub fn new(mesh: &TriMesh) -> EdgeTopology {
        let mut opposite = vec![[u32::MAX; 3]; mesh.triangles.len()];
        let mut opposite_edge = vec![[0u8; 3]; mesh.triangles.len()];
        for run in edge_runs(&sorted_sides(mesh)) {
            if let &[x, y] = run {
                let tx = mesh.triangles[x.2 as usize];
                let ty = mesh.triangles[y.2 as usize];
                if tx[x.3 as usize] != ty[(y.3 as usize + 1) % 3] {
                    continue;
                }
                opposite[x.2 as usize][x.3 as usize] = y.2;
                opposite_edge[x.2 as usize][x.3 as usize] = y.3;
                opposite[y.2 as usize][y.3 as usize] = x.2;
                opposite_edge[y.2 as usize][y.3 as usize] = x.3;
            }
        }
        EdgeTopology {
            opposite,
            opposite_edge,
        }
    }

    /// The local edge of `f` shared with `g`.
    pub fn shared_edge(&self, f: u32, g: u32) -> Option<usize> {
        self.opposite[f as usize].iter().position(|&h| h == g)
    }

    pub fn face_count(&self) -> usize {
        self.opposite.len()
    }

    /// The face across local edge `e` of `f` and that edge's index there.
    pub fn across(&self, f: usize, e: usize) -> Option<(usize, usize)> {
        let g = self.opposite[f][e];
        (g != u32::MAX).then(|| (g as usize, self.opposite_edge[f][e] as usize))
    }

    /// The sharp edges, the one dihedral-angle test of the crate (the
    /// param's feature curves, the layout's feature tangents): edges of
    /// exactly two triangles whose unit normals (from `face_normals`, any
    /// length; a zero one never counts) differ by more than `degrees`,
    /// and, with `boundary`, the edges of one triangle (both sides the
    /// same). In (a, b) order; non-manifold edges are never sharp.
    pub fn sharp_edges(
        mesh: &TriMesh,
        face_normals: &[glam::DVec3],
        degrees: f64,
        boundary: bool,
    ) -> Vec<SharpEdge> {
        let cos_limit = degrees.to_radians().cos();
        let normal = |f: u32| {
            face_normals
                .get(f as usize)
                .map_or(glam::DVec3::ZERO, |n| n.normalize_or_zero())
        };
        let mut out = Vec::new();
        for run in edge_runs(&sorted_sides(mesh)) {
            let sides = match run {
                [x] if boundary => [(x.2, x.3); 2],
                [x, y] => {
                    let (n0, n1) = (normal(x.2), normal(y.2));
                    if n0 == glam::DVec3::ZERO || n1 == glam::DVec3::ZERO || n0.dot(n1) >= cos_limit
                    {
                        continue;
                    }
                    [(x.2, x.3), (y.2, y.3)]
                }
                _ => continue,
            };
            out.push(SharpEdge {
                a: run[0].0,
                b: run[0].1,
                sides,
                boundary: run.len() == 1,
            });
        }
        out
    }
}

/// An edge found by [`EdgeTopology::sharp_edges`]: its end points (a < b)
/// and its two triangle sides (face, local edge from corner i to i + 1).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SharpEdge {
    pub a: u32,
    pub b: u32,
    pub sides: [(u32, u8); 2],
    /// A boundary edge (one triangle; both sides are the same).
    pub boundary: bool,
}

/// The boundary half-edges (a, b) — the sides of the edges of exactly one
/// triangle, as their triangle runs them — in face order, then corner
/// order. The one place that finds a triangle mesh's boundary.
pub fn boundary_half_edges(mesh: &TriMesh) -> Vec<(u32, u32)> {
    boundary_sides(mesh)
        .into_iter()
        .map(|(f, i)| {
            let t = mesh.triangles[f as usize];
            (t[i as usize], t[(i as usize + 1) % 3])
        })
        .collect()
}

/// [`boundary_half_edges`] as triangle sides (face, local edge from
/// corner i to corner i + 1), in the same order.
fn boundary_sides(mesh: &TriMesh) -> Vec<(u32, u8)> {
    let mut sides: Vec<(u32, u8)> = edge_runs(&sorted_sides(mesh))
        .filter_map(|run| match run {
            [x] => Some((x.2, x.3)),
            _ => None,
        })
        .collect();
    sides.sort_unstable();
    sides
}

/// Vertices on an edge that belongs to exactly one triangle.
pub fn boundary_vertices(mesh: &TriMesh) -> Vec<bool> {
    let mut boundary = vec![false; mesh.positions.len()];
    for (a, b) in boundary_half_edges(mesh) {
        boundary[a as usize] = true;
        boundary[b as usize] = true;
    }
    boundary
}

/// The input's boundary loops, parametrised by arc length: for each vertex
/// on a boundary, which loop it lies on and how far along it (from the
/// loop's first vertex, in mesh units), and each loop's length. A vertex
/// where several loops touch (non-manifold) keeps the first loop it was
/// reached on.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct BoundaryArcs {
    /// Loop index per vertex, `u32::MAX` off the boundary.
    pub loop_of: Vec<u32>,
    /// Arc length from the loop's start per vertex (0 off the boundary).
    pub arc: Vec<f64>,
    /// Length of each loop.
    pub length: Vec<f64>,
}

impl BoundaryArcs {
    /// Walks every boundary edge (an edge of exactly one triangle) once,
    /// loops in the order of their smallest start vertex, each from there
    /// in its triangles' direction. At a vertex where several loops touch
    /// (a non-manifold vertex: two fans of triangles meet there) a loop
    /// goes on along the boundary of the fan it arrived in, found by
    /// turning round the vertex through that fan's triangles; a loop that
    /// cannot be turned (a non-manifold edge in the fan) goes on along any
    /// boundary edge not yet walked from there.
    pub fn new(mesh: &TriMesh) -> BoundaryArcs {
        let sides = boundary_sides(mesh);
        let topology = EdgeTopology::new(mesh);
        let nf = mesh.triangles.len();
        // Index of each boundary side in `sides`, per face and local edge.
        let mut index = vec![[u32::MAX; 3]; nf];
        let mut from: HashMap<u32, Vec<u32>> = HashMap::new();
        for (k, &(f, i)) in sides.iter().enumerate() {
            index[f as usize][i as usize] = k as u32;
            from.entry(mesh.triangles[f as usize][i as usize])
                .or_default()
                .push(k as u32);
        }
        let start_of = |k: u32| {
            let (f, i) = sides[k as usize];
            mesh.triangles[f as usize][i as usize]
        };
        let mut walked = vec![false; sides.len()];
        // The boundary side after side k: turn round its end vertex
        // through its fan until a boundary side leaves it.
        let after = |k: u32, walked: &[bool]| -> Option<u32> {
            let (f, i) = sides[k as usize];
            let (mut g, mut e) = (f as usize, (i as usize + 1) % 3);
            for _ in 0..nf {
                let s = index[g][e];
                if s != u32::MAX {
                    return Some(s);
                }
                let Some((h, j)) = topology.across(g, e) else {
                    break;
                };
                (g, e) = (h, (j + 1) % 3);
            }
            let end = mesh.triangles[f as usize][(i as usize + 1) % 3];
            from.get(&end)?
                .iter()
                .copied()
                .find(|&s| !walked[s as usize])
        };
        let mut order: Vec<u32> = (0..sides.len() as u32).collect();
        order.sort_by_key(|&k| (start_of(k), k));
        let n = mesh.positions.len();
        let mut arcs = BoundaryArcs {
            loop_of: vec![u32::MAX; n],
            arc: vec![0.0; n],
            length: Vec::new(),
        };
        for first in order {
            if walked[first as usize] {
                continue;
            }
            let id = arcs.length.len() as u32;
            let (mut k, mut along) = (first, 0.0);
            loop {
                walked[k as usize] = true;
                let (f, i) = sides[k as usize];
                let t = mesh.triangles[f as usize];
                let (a, b) = (t[i as usize], t[(i as usize + 1) % 3]);
                if arcs.loop_of[a as usize] == u32::MAX {
                    arcs.loop_of[a as usize] = id;
                    arcs.arc[a as usize] = along;
                }
                along += mesh.positions[a as usize].distance(mesh.positions[b as usize]);
                match after(k, &walked) {
                    Some(s) if !walked[s as usize] => k = s,
                    _ => break,
                }
            }
            arcs.length.push(along);
        }
        arcs
    }

    pub fn is_boundary(&self, v: usize) -> bool {
        self.loop_of.get(v).is_some_and(|&l| l != u32::MAX)
    }
}

/// Collects n-ring neighbourhoods by breadth-first search, reusing its
/// buffers between calls (one per thread; O(ring size) per query).
#[derive(Debug, Clone, Default)]
pub struct RingCollector {
    stamp: Vec<u32>,
    generation: u32,
}

impl RingCollector {
    pub fn new(vertex_count: usize) -> RingCollector {
        RingCollector {
            stamp: vec![0; vertex_count],
            generation: 0,
        }
    }

    /// Writes the vertices within `rings` edges of `v` (excluding `v`) into
    /// `out`, nearest rings first, each ring in discovery order.
    pub fn collect(
        &mut self,
        adjacency: &VertexAdjacency,
        v: usize,
        rings: u32,
        out: &mut Vec<u32>,
    ) {
        out.clear();
        if self.stamp.len() < adjacency.vertex_count() {
            self.stamp.resize(adjacency.vertex_count(), 0);
        }
        if v >= adjacency.vertex_count() {
            return;
        }
        self.generation = self.generation.wrapping_add(1);
        if self.generation == 0 {
            self.stamp.fill(0);
            self.generation = 1;
        }
        let g = self.generation;
        self.stamp[v] = g;
        let mut ring_start = 0;
        // Ring 1 grows from `v`, later rings from the previous ring.
        for &n in adjacency.neighbors(v) {
            if self.stamp[n as usize] != g {
                self.stamp[n as usize] = g;
                out.push(n);
            }
        }
        for _ in 1..rings {
            let ring_end = out.len();
            if ring_start == ring_end {
                break;
            }
            for i in ring_start..ring_end {
                let u = out[i] as usize;
                for &n in adjacency.neighbors(u) {
                    if self.stamp[n as usize] != g {
                        self.stamp[n as usize] = g;
                        out.push(n);
                    }
                }
            }
            ring_start = ring_end;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    fn strip() -> TriMesh {
        // 0-1-2-3 along the bottom, 4-5-6-7 along the top.
        let mut p = Vec::new();
        for y in 0..2 {
            for x in 0..4 {
                p.push(DVec3::new(x as f64, y as f64, 0.0));
            }
        }
        let mut t = Vec::new();
        for x in 0..3u32 {
            t.push([x, x + 1, x + 5]);
            t.push([x, x + 5, x + 4]);
        }
        TriMesh::new(p, t).unwrap()
    }

    #[test]
    fn rings_grow_by_edges() {
        let m = strip();
        let adj = VertexAdjacency::new(&m);
        assert_eq!(adj.neighbors(0), &[1, 4, 5]);
        let mut rc = RingCollector::new(m.vertex_count());
        let mut out = Vec::new();
        rc.collect(&adj, 0, 1, &mut out);
        assert_eq!(out, vec![1, 4, 5]);
        rc.collect(&adj, 0, 2, &mut out);
        out.sort();
        assert_eq!(out, vec![1, 2, 4, 5, 6]);
        rc.collect(&adj, 0, 10, &mut out);
        assert_eq!(out.len(), 7);
    }

    #[test]
    fn dual_graph_and_boundary() {
        let m = strip();
        let fa = FaceAdjacency::new(&m);
        assert_eq!(fa.neighbors(0), &[1, 3]);
        assert_eq!(fa.neighbors(5), &[2, 4]);
        assert!(boundary_vertices(&m).iter().all(|&b| b));
        let vf = VertexFaces::new(&m);
        assert_eq!(vf.faces(5), &[0, 1, 3]);
    }

    #[test]
    fn edge_list_ignores_bad_edges() {
        let adj = VertexAdjacency::from_edges(3, &[[0, 1], [1, 1], [2, 9], [1, 0]]);
        assert_eq!(adj.neighbors(0), &[1]);
        assert_eq!(adj.neighbors(1), &[0]);
        assert!(adj.neighbors(2).is_empty());
    }

    fn lengths(arcs: &BoundaryArcs) -> Vec<f64> {
        let mut l = arcs.length.clone();
        l.sort_by(f64::total_cmp);
        l
    }

    #[test]
    fn boundary_arcs_walk_each_loop_whole() {
        let arcs = BoundaryArcs::new(&strip());
        assert_eq!(arcs.length, vec![8.0]);
        assert_eq!(arcs.arc[0], 0.0);
        assert!(arcs.loop_of.iter().all(|&l| l == 0));
    }

    #[test]
    fn boundary_arcs_go_on_through_a_pinched_vertex_along_their_own_fan() {
        // Two triangles touching at vertex 0 (a bow tie): two loops, each
        // its triangle's whole perimeter.
        let bow_tie = TriMesh {
            positions: vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::NEG_X, DVec3::NEG_Y],
            triangles: vec![[0, 1, 2], [0, 3, 4]],
        };
        let perimeter = 2.0 + 2f64.sqrt();
        let l = lengths(&BoundaryArcs::new(&bow_tie));
        assert_eq!(l.len(), 2);
        assert!(l.iter().all(|x| (x - perimeter).abs() < 1e-12), "{l:?}");
        // A 4 × 4 sheet without squares (1, 1) and (2, 2), which touch at
        // vertex (2, 2): the rim (16) and one loop round both holes (8), as
        // on the surface with vertex (2, 2) split into one per fan.
        let arcs = BoundaryArcs::new(&crate::mesh::generate::grid_cells(4, |x, y| {
            (x, y) != (1, 1) && (x, y) != (2, 2)
        }));
        assert_eq!(lengths(&arcs), vec![8.0, 16.0]);
        assert!(arcs.is_boundary(12));
    }
}
