//! Longest-edge-first bisection of an input that is too coarse for the
//! target scale (Instant Meshes' preprocessing, ../shared/reference/
//! instant-meshes-digest.md §1.3; the thesis' pipeline, ../shared/seeds/004…
//! §3.1, runs on Instant Meshes' level 0).
//!
//! The fields live on the input's vertices and links. A link longer than
//! half a target edge spans two lattice cells, so its integer translation
//! is guessed from far-apart tangent planes, and a long, thin triangle
//! holds lattice points no vertex sees. Instant Meshes therefore splits
//! every edge longer than `min(s/2, 2·mean edge)` at its midpoint, longest
//! first, before it builds the hierarchy. Midpoint splits keep the surface
//! exactly (every new vertex lies on an old edge), its boundary loops and
//! its sharp edges.

use std::cmp::Ordering;
use std::collections::{BinaryHeap, HashMap};

use glam::DVec3;

use super::{TriMesh, edge_key};

/// An edge in the queue, ordered by squared length (longest first), then by
/// its vertices so that the order does not depend on hashing.
#[derive(PartialEq)]
struct Candidate {
    length2: f64,
    edge: (u32, u32),
}

impl Eq for Candidate {}

impl Ord for Candidate {
    fn cmp(&self, other: &Self) -> Ordering {
        self.length2
            .total_cmp(&other.length2)
            .then_with(|| other.edge.cmp(&self.edge))
    }
}

impl PartialOrd for Candidate {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

/// Instant Meshes' threshold: `min(s/2, 2·mean edge)` for the target edge
/// length `s`; `None` when no edge is longer (the input is used as it is).
pub fn split_threshold(mesh: &TriMesh, target_edge: f64) -> Option<f64> {
    let (mut sum, mut count, mut longest) = (0.0, 0usize, 0.0f64);
    for t in &mesh.triangles {
        for k in 0..3 {
            let l =
                (mesh.positions[t[k] as usize] - mesh.positions[t[(k + 1) % 3] as usize]).length();
            sum += l;
            count += 1;
            longest = longest.max(l);
        }
    }
    if count == 0 || target_edge.is_nan() || target_edge <= 0.0 {
        return None;
    }
    let threshold = (target_edge / 2.0).min(2.0 * sum / count as f64);
    (longest > threshold).then_some(threshold)
}

/// At most this many times the input's vertices: a safety bound. The
/// longest-edge bisection of the faces that are not frozen ends by itself.
const MAX_GROWTH: usize = 64;

/// Faces that must not be split: those with a long edge that cannot be
/// split (more than two faces; Instant Meshes skips non-manifold edges),
/// and, since that edge then stays long, every face reached from them
/// across long edges. Splitting next to an edge that stays long would never
/// end: each split makes another edge almost as long as it.
fn frozen_faces(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    faces_of: &HashMap<(u32, u32), Vec<u32>>,
    max2: f64,
) -> Vec<bool> {
    let long = |(a, b): (u32, u32)| {
        (positions[a as usize] - positions[b as usize]).length_squared() > max2
    };
    let mut frozen = vec![false; triangles.len()];
    let mut stack: Vec<u32> = Vec::new();
    for (&edge, faces) in faces_of {
        if faces.len() > 2 && long(edge) {
            stack.extend(faces);
        }
    }
    while let Some(f) = stack.pop() {
        if std::mem::replace(&mut frozen[f as usize], true) {
            continue;
        }
        let t = triangles[f as usize];
        for k in 0..3 {
            let edge = edge_key(t[k], t[(k + 1) % 3]);
            if long(edge) {
                stack.extend(faces_of[&edge].iter().filter(|&&g| !frozen[g as usize]));
            }
        }
    }
    frozen
}

/// Splits every edge longer than `max_length` at its midpoint, longest
/// first, until none is (digest §1.3), except in [`frozen_faces`]. Orientation is kept:
/// a triangle (a, b, c) split on ab becomes (a, m, c) and (m, b, c).
/// Returns `None` when nothing was split.
pub fn split_long_edges(mesh: &TriMesh, max_length: f64) -> Option<TriMesh> {
    if !max_length.is_finite() || max_length <= 0.0 {
        return None;
    }
    let mut positions: Vec<DVec3> = mesh.positions.clone();
    let mut triangles: Vec<[u32; 3]> = mesh.triangles.clone();
    let mut faces_of: HashMap<(u32, u32), Vec<u32>> = HashMap::new();
    for (f, t) in triangles.iter().enumerate() {
        for k in 0..3 {
            faces_of
                .entry(edge_key(t[k], t[(k + 1) % 3]))
                .or_default()
                .push(f as u32);
        }
    }
    let max2 = max_length * max_length;
    let length2 =
        |p: &[DVec3], (a, b): (u32, u32)| (p[a as usize] - p[b as usize]).length_squared();
    let frozen = frozen_faces(&positions, &triangles, &faces_of, max2);
    let mut queue: BinaryHeap<Candidate> = faces_of
        .keys()
        .map(|&edge| Candidate {
            length2: length2(&positions, edge),
            edge,
        })
        .filter(|c| c.length2 > max2)
        .collect();
    let mut split_any = false;
    while let Some(Candidate { edge, .. }) = queue.pop() {
        let Some(faces) = faces_of.get(&edge) else {
            continue; // split already
        };
        if faces.len() > 2 || faces.iter().any(|&f| frozen.get(f as usize) == Some(&true)) {
            continue;
        }
        if positions.len() >= MAX_GROWTH * mesh.positions.len().max(1) {
            break;
        }
        let faces = faces_of.remove(&edge).unwrap_or_default();
        let (a, b) = edge;
        let m = positions.len() as u32;
        positions.push(0.5 * (positions[a as usize] + positions[b as usize]));
        split_any = true;
        let mut touched = vec![edge_key(a, m), edge_key(m, b)];
        for f in faces {
            let t = triangles[f as usize];
            // Rotate so that the split edge is t[0] → t[1].
            let k = (0..3)
                .find(|&k| edge_key(t[k], t[(k + 1) % 3]) == edge)
                .expect("the face holds its edge");
            let (p, q, c) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
            let g = triangles.len() as u32;
            triangles[f as usize] = [p, m, c];
            triangles.push([m, q, c]);
            faces_of.entry(edge_key(p, m)).or_default().push(f);
            faces_of.entry(edge_key(m, q)).or_default().push(g);
            let mc = edge_key(m, c);
            faces_of.entry(mc).or_default().extend([f, g]);
            if let Some(qc) = faces_of.get_mut(&edge_key(q, c)) {
                for x in qc.iter_mut().filter(|x| **x == f) {
                    *x = g;
                }
            }
            touched.push(mc);
        }
        for e in touched {
            let l2 = length2(&positions, e);
            if l2 > max2 {
                queue.push(Candidate {
                    length2: l2,
                    edge: e,
                });
            }
        }
    }
    split_any.then_some(TriMesh {
        positions,
        triangles,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn longest_edge(m: &TriMesh) -> f64 {
        m.triangles
            .iter()
            .flat_map(|t| (0..3).map(move |k| (t[k] as usize, t[(k + 1) % 3] as usize)))
            .map(|(a, b)| (m.positions[a] - m.positions[b]).length())
            .fold(0.0, f64::max)
    }

    fn area(m: &TriMesh) -> f64 {
        m.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| m.positions[i as usize]);
                0.5 * (b - a).cross(c - a).length()
            })
            .sum()
    }

    /// A long, thin open strip: two triangles, one 10 units long.
    fn strip() -> TriMesh {
        TriMesh::new(
            vec![
                DVec3::ZERO,
                DVec3::new(10.0, 0.0, 0.0),
                DVec3::new(10.0, 1.0, 0.0),
                DVec3::new(0.0, 1.0, 0.0),
            ],
            vec![[0, 1, 2], [0, 2, 3]],
        )
        .unwrap()
    }

    #[test]
    fn splits_until_no_edge_is_longer_and_keeps_surface_and_topology() {
        let input = strip();
        let out = split_long_edges(&input, 0.75).expect("edges are long");
        out.validate().unwrap();
        assert!(longest_edge(&out) <= 0.75 + 1e-12, "{}", longest_edge(&out));
        assert!((area(&out) - area(&input)).abs() < 1e-9);
        let (ti, to) = (input.topology(), out.topology());
        assert_eq!(ti.euler_characteristic, to.euler_characteristic);
        assert_eq!((to.nonmanifold_edges, to.inconsistent_edges), (0, 0));
        // One boundary loop still: its vertices form a single cycle.
        let arcs = crate::mesh::BoundaryArcs::new(&out);
        assert_eq!(arcs.length.len(), 1);
        assert!((arcs.length[0] - 22.0).abs() < 1e-9, "{:?}", arcs.length);
        // Orientation kept: every face's normal still points up.
        for t in &out.triangles {
            let [a, b, c] = t.map(|i| out.positions[i as usize]);
            assert!((b - a).cross(c - a).z > 0.0);
        }
    }

    #[test]
    fn a_long_non_manifold_edge_and_its_long_neighbourhood_stay_as_they_are() {
        // Three pages sharing the spine 0–1 (length 10), each page 10 × 1,
        // next to a small square that is split as usual.
        let mut positions = vec![DVec3::ZERO, DVec3::new(10.0, 0.0, 0.0)];
        let mut triangles = Vec::new();
        for k in 0..3 {
            let a = k as f64 * std::f64::consts::TAU / 3.0;
            positions.push(DVec3::new(5.0, a.cos(), a.sin()));
            triangles.push([0, 1, 2 + k]);
        }
        let b = positions.len() as u32;
        positions.extend([
            DVec3::new(20.0, 0.0, 0.0),
            DVec3::new(22.0, 0.0, 0.0),
            DVec3::new(22.0, 2.0, 0.0),
        ]);
        triangles.push([b, b + 1, b + 2]);
        let input = TriMesh::new(positions, triangles).unwrap();
        let out = split_long_edges(&input, 0.5).expect("the small triangle splits");
        out.validate().unwrap();
        assert_eq!(&out.triangles[..3], &input.triangles[..3]);
        assert!((area(&out) - area(&input)).abs() < 1e-9);
        // Only the small triangle was refined: all new vertices are on it.
        assert!(
            out.positions[input.positions.len()..]
                .iter()
                .all(|p| p.x >= 20.0)
        );
        assert!(out.vertex_count() < 64);
    }

    #[test]
    fn a_closed_mesh_stays_closed_and_the_threshold_follows_instant_meshes() {
        let input = crate::mesh::generate::icosphere(1.0, 0);
        let t = split_threshold(&input, 0.8).expect("the sphere's edges exceed 0.4");
        assert!((t - 0.4).abs() < 1e-12);
        let out = split_long_edges(&input, t).unwrap();
        out.validate().unwrap();
        let topo = out.topology();
        assert_eq!(topo.boundary_edges, 0);
        assert_eq!(topo.euler_characteristic, 2);
        assert_eq!((topo.nonmanifold_edges, topo.inconsistent_edges), (0, 0));
        assert!(longest_edge(&out) <= t + 1e-12);
        // Every new vertex lies on the input surface (on an old edge, hence
        // inside the unit ball and no closer than the inscribed polyhedron).
        for p in &out.positions {
            assert!(p.length() <= 1.0 + 1e-12);
        }
        assert!(split_threshold(&out, 0.8).is_none());
    }
}
