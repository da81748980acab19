//! Holes below the target scale, closed before the map (Ebke et al. 2014,
//! `../shared/seeds/000_…`, §6: the quad mesh keeps the input's features
//! at the target scale, and what is smaller — a handle, a fold — leaves no
//! trace in it).
//!
//! The map puts every boundary loop on integer isolines (`seamless`'s
//! boundary constraints), so a loop much shorter than a quad's perimeter
//! must shrink to a point or to a zero-width slit, and the triangles
//! round it fold. Closed here: the loops shorter than the ones the output
//! is to keep ([`KEPT_LOOP_EDGES`] target edges, the metrics' "too small";
//! closing up to a quad's perimeter, 4, closed the teapot's spout, which
//! the post-processing's reopening then opened again with corners of
//! 334°). An old hand-made
//! model's cracks and pinholes (the beetle: 24 of its 33 loops shorter
//! than two target edges at its default target) fold the map over most
//! of the surface, and the extraction finds no quads there. Here each such
//! loop is closed with a fan round its centroid (one triangle for three
//! vertices); the map and the extraction run on the closed mesh, whose
//! first vertices are the input's, and the quads pass over the hole as the
//! quad mesh of a surface without it would. Longer loops stay open and
//! stay boundaries.

use glam::DVec3;

use crate::mesh::TriMesh;
use crate::metrics::KEPT_LOOP_EDGES;

/// The input with its boundary loops shorter than `min_edges` times the
/// mean of `edge_length` (per vertex) on them closed; `None` when none is.
/// Only simple loops are closed (every vertex once, as their triangles
/// run them): at a non-manifold vertex the loop is ambiguous and stays.
pub fn close_small_holes(mesh: &TriMesh, edge_length: &[f64], min_edges: f64) -> Option<TriMesh> {
    if !(min_edges.is_finite() && min_edges > 0.0) {
        return None;
    }
    // Boundary half-edges a → b as their triangle runs them, by start.
    let mut next: std::collections::HashMap<u32, Vec<u32>> = Default::default();
    for (a, b) in crate::mesh::boundary_half_edges(mesh) {
        next.entry(a).or_default().push(b);
    }
    let mut starts: Vec<u32> = next.keys().copied().collect();
    starts.sort_unstable();
    let mut positions = mesh.positions.clone();
    let mut triangles = mesh.triangles.clone();
    let mut used: std::collections::HashSet<(u32, u32)> = Default::default();
    let mut closed = 0usize;
    for start in starts {
        if next[&start].len() != 1 || used.contains(&(start, next[&start][0])) {
            continue;
        }
        // Walk the loop while every vertex has one way on.
        let mut ring = vec![start];
        let mut simple = true;
        loop {
            let at = *ring.last().unwrap();
            let Some(outs) = next.get(&at).filter(|o| o.len() == 1) else {
                simple = false;
                break;
            };
            let b = outs[0];
            used.insert((at, b));
            if b == start {
                break;
            }
            if ring.len() > mesh.positions.len() || ring.contains(&b) {
                simple = false;
                break;
            }
            ring.push(b);
        }
        if !simple || ring.len() < 3 {
            continue;
        }
        let n = ring.len();
        let p = |k: usize| mesh.positions[ring[k % n] as usize];
        let perimeter: f64 = (0..n).map(|k| (p(k + 1) - p(k)).length()).sum();
        let mean_edge = ring
            .iter()
            .map(|&v| edge_length.get(v as usize).copied().unwrap_or(f64::NAN))
            .sum::<f64>()
            / n as f64;
        if !(mean_edge.is_finite() && perimeter < min_edges * mean_edge) {
            continue;
        }
        closed += 1;
        // The hole's triangles run its edges backwards.
        if n == 3 {
            triangles.push([ring[2], ring[1], ring[0]]);
            continue;
        }
        let centre = ring
            .iter()
            .map(|&v| mesh.positions[v as usize])
            .sum::<DVec3>()
            / n as f64;
        let c = positions.len() as u32;
        positions.push(centre);
        for k in 0..n {
            triangles.push([ring[(k + 1) % n], ring[k], c]);
        }
    }
    (closed > 0).then_some(TriMesh {
        positions,
        triangles,
    })
}

/// [`close_small_holes`] below the length of the loops the output is to
/// keep ([`KEPT_LOOP_EDGES`] target edges).
pub fn close_holes_too_small_to_keep(mesh: &TriMesh, edge_length: &[f64]) -> Option<TriMesh> {
    close_small_holes(mesh, edge_length, KEPT_LOOP_EDGES)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A flat n × n grid of unit squares (two triangles each) with the
    /// squares in `holes` left out.
    fn grid(n: u32, holes: &[(u32, u32)]) -> TriMesh {
        let mut positions = Vec::new();
        for j in 0..=n {
            for i in 0..=n {
                positions.push(DVec3::new(i as f64, j as f64, 0.0));
            }
        }
        let id = |i: u32, j: u32| j * (n + 1) + i;
        let mut triangles = Vec::new();
        for j in 0..n {
            for i in 0..n {
                if holes.contains(&(i, j)) {
                    continue;
                }
                triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        TriMesh::new(positions, triangles).unwrap()
    }

    /// The boundary edges of `m`, after checking that every other edge
    /// has two consistently oriented triangles.
    fn boundary_edges(m: &TriMesh) -> usize {
        let unmatched: usize = crate::mesh::EdgeTopology::new(m)
            .opposite
            .iter()
            .flatten()
            .filter(|&&g| g == u32::MAX)
            .count();
        let boundary = crate::mesh::boundary_half_edges(m).len();
        assert_eq!(unmatched, boundary, "manifold, oriented edges");
        boundary
    }

    #[test]
    fn a_hole_too_small_to_keep_closes_and_a_larger_one_and_the_rim_stay() {
        // A one-square hole (perimeter 4) and a 2 × 2 hole (perimeter 8)
        // in a 10 × 10 sheet (outer rim 40), at a target edge of 2.5: the
        // first is 1.6 target edges round, the second 3.2, the rim 16.
        let mesh = grid(10, &[(2, 2), (6, 6), (7, 6), (6, 7), (7, 7)]);
        assert_eq!(boundary_edges(&mesh), 40 + 4 + 8);
        let sizing = vec![2.5; mesh.positions.len()];
        let closed = close_holes_too_small_to_keep(&mesh, &sizing).expect("one hole closed");
        closed.validate().unwrap();
        assert_eq!(boundary_edges(&closed), 40 + 8);
        // One centre vertex, four fan triangles, at the hole's centre.
        assert_eq!(closed.positions.len(), mesh.positions.len() + 1);
        assert_eq!(closed.triangles.len(), mesh.triangles.len() + 4);
        assert!(
            (closed.positions[mesh.positions.len()] - DVec3::new(2.5, 2.5, 0.0)).length() < 1e-12
        );
        // Consistent orientation: the fan's normals agree with the sheet's.
        for t in &closed.triangles[mesh.triangles.len()..] {
            let [a, b, c] = t.map(|v| closed.positions[v as usize]);
            assert!((b - a).cross(c - a).z > 0.0);
        }
        // A finer target keeps both holes (the small one 2.1 edges round).
        assert!(close_holes_too_small_to_keep(&mesh, &vec![1.9; mesh.positions.len()]).is_none());
    }

    #[test]
    fn a_three_vertex_hole_gets_one_triangle() {
        // One triangle missing from a 4 × 4 sheet: a loop of three edges,
        // 3.41 long, 1.7 target edges of 2.
        let mut mesh = grid(4, &[]);
        let gone = mesh.triangles.remove(10);
        let closed =
            close_holes_too_small_to_keep(&mesh, &vec![2.0; mesh.positions.len()]).expect("closed");
        assert_eq!(closed.positions.len(), mesh.positions.len());
        let added = closed.triangles.last().unwrap();
        let mut a = *added;
        let mut g = gone;
        a.sort_unstable();
        g.sort_unstable();
        assert_eq!(a, g);
        assert_eq!(boundary_edges(&closed), 16);
    }
}
