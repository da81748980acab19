use serde::{Deserialize, Serialize};

use super::FaceList;

/// Combinatorial statistics of a polygon soup: what the import report and the
/// output metrics count. Works on non-manifold input (it never builds
/// half-edges).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct Topology {
    /// Vertices referenced by at least one face.
    pub vertices: usize,
    pub faces: usize,
    /// Undirected edges.
    pub edges: usize,
    /// Edges with exactly one incident face.
    pub boundary_edges: usize,
    /// Edges with more than two incident faces.
    pub nonmanifold_edges: usize,
    /// Vertices whose incident faces, linked through shared edges at the
    /// vertex, form more than one fan (bow-ties and the like).
    pub nonmanifold_vertices: usize,
    /// Two-face edges used twice in the same direction.
    pub inconsistent_edges: usize,
    /// Connected components through shared vertices (pieces as a user sees
    /// them; parts touching at one vertex are one piece with a non-manifold
    /// vertex).
    pub components: usize,
    /// V − E + F over referenced vertices.
    pub euler_characteristic: i64,
}

impl Topology {
    pub fn of(vertex_count: usize, faces: &FaceList) -> Topology {
        // Directed edges as (min, max, forward?, face) so that equal undirected
        // edges sort together.
        let mut directed: Vec<(u32, u32, bool, u32)> = Vec::with_capacity(faces.indices.len());
        for (f, face) in faces.iter().enumerate() {
            for (i, &a) in face.iter().enumerate() {
                let b = face[(i + 1) % face.len()];
                directed.push((a.min(b), a.max(b), a < b, f as u32));
            }
        }
        let mut components = UnionFind::new(vertex_count);
        for face in faces.iter() {
            for w in face.windows(2) {
                components.union(w[0], w[1]);
            }
        }
        directed.sort_unstable();

        let mut t = Topology {
            faces: faces.len(),
            ..Topology::default()
        };
        let mut i = 0;
        while i < directed.len() {
            let (a, b, _, _) = directed[i];
            let mut j = i;
            let mut forward = 0;
            while j < directed.len() && directed[j].0 == a && directed[j].1 == b {
                forward += directed[j].2 as usize;
                j += 1;
            }
            let count = j - i;
            t.edges += 1;
            match count {
                1 => t.boundary_edges += 1,
                2 if forward != 1 => t.inconsistent_edges += 1,
                2 => {}
                _ => t.nonmanifold_edges += 1,
            }
            i = j;
        }

        // Vertex → incident faces (CSR).
        let mut start = vec![0u32; vertex_count + 1];
        for &v in &faces.indices {
            start[v as usize + 1] += 1;
        }
        for v in 0..vertex_count {
            start[v + 1] += start[v];
        }
        let mut fill = start.clone();
        let mut incident = vec![0u32; faces.indices.len()];
        for (f, face) in faces.iter().enumerate() {
            for &v in face {
                incident[fill[v as usize] as usize] = f as u32;
                fill[v as usize] += 1;
            }
        }

        let mut fan = UnionFind::new(0);
        let mut spokes: Vec<(u32, u32)> = Vec::new();
        for v in 0..vertex_count {
            let around = &incident[start[v] as usize..start[v + 1] as usize];
            if around.is_empty() {
                continue;
            }
            t.vertices += 1;
            if components.find(v as u32) == v as u32 {
                t.components += 1;
            }
            fan.reset(around.len());
            spokes.clear();
            for (k, &f) in around.iter().enumerate() {
                let face = faces.face(f as usize);
                let n = face.len();
                for (i, &x) in face.iter().enumerate() {
                    if x as usize == v {
                        spokes.push((face[(i + 1) % n], k as u32));
                        spokes.push((face[(i + n - 1) % n], k as u32));
                    }
                }
            }
            spokes.sort_unstable();
            for w in spokes.windows(2) {
                if w[0].0 == w[1].0 {
                    fan.union(w[0].1, w[1].1);
                }
            }
            let fans = (0..around.len() as u32)
                .filter(|&k| fan.find(k) == k)
                .count();
            if fans > 1 {
                t.nonmanifold_vertices += 1;
            }
        }
        t.euler_characteristic = t.vertices as i64 - t.edges as i64 + t.faces as i64;
        t
    }

    /// Closed, manifold and consistently oriented.
    pub fn is_closed_manifold(&self) -> bool {
        self.boundary_edges == 0
            && self.nonmanifold_edges == 0
            && self.nonmanifold_vertices == 0
            && self.inconsistent_edges == 0
    }

    /// Total genus Σ g_i = (2C − χ) / 2, defined for closed orientable manifolds.
    pub fn genus(&self) -> Option<i64> {
        let twice = 2 * self.components as i64 - self.euler_characteristic;
        (self.is_closed_manifold() && twice % 2 == 0).then_some(twice / 2)
    }
}

/// Disjoint sets with path halving; `union` keeps the smaller root.
pub(crate) struct UnionFind {
    parent: Vec<u32>,
}

impl UnionFind {
    pub(crate) fn new(n: usize) -> Self {
        UnionFind {
            parent: (0..n as u32).collect(),
        }
    }

    pub(crate) fn reset(&mut self, n: usize) {
        self.parent.clear();
        self.parent.extend(0..n as u32);
    }

    pub(crate) fn find(&mut self, mut x: u32) -> u32 {
        while self.parent[x as usize] != x {
            let grand = self.parent[self.parent[x as usize] as usize];
            self.parent[x as usize] = grand;
            x = grand;
        }
        x
    }

    /// Hangs root `child` under root `root`: for callers that pick the
    /// representative themselves (union by size in the extraction's
    /// clusters). Both must be roots.
    pub(crate) fn link(&mut self, child: u32, root: u32) {
        debug_assert!(self.parent[child as usize] == child && self.parent[root as usize] == root);
        self.parent[child as usize] = root;
    }

    pub(crate) fn union(&mut self, a: u32, b: u32) {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra != rb {
            let (lo, hi) = if ra < rb { (ra, rb) } else { (rb, ra) };
            self.parent[hi as usize] = lo;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tetrahedron_is_closed_genus_zero() {
        let faces = FaceList::from_triangles(&[[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]]);
        let t = Topology::of(4, &faces);
        assert_eq!(t.edges, 6);
        assert!(t.is_closed_manifold());
        assert_eq!(t.euler_characteristic, 2);
        assert_eq!(t.genus(), Some(0));
        assert_eq!(t.components, 1);
    }

    #[test]
    fn bowtie_vertex_and_fin_edge_are_counted() {
        // Two triangles touching at vertex 0 only.
        let bowtie = FaceList::from_triangles(&[[0, 1, 2], [0, 3, 4]]);
        let t = Topology::of(5, &bowtie);
        assert_eq!(t.nonmanifold_vertices, 1);
        assert_eq!(t.boundary_edges, 6);
        assert_eq!(t.components, 1);
        // Three triangles on edge 0-1.
        let fin = FaceList::from_triangles(&[[0, 1, 2], [1, 0, 3], [0, 1, 4]]);
        let t = Topology::of(5, &fin);
        assert_eq!(t.nonmanifold_edges, 1);
    }

    #[test]
    fn flipped_face_is_inconsistent() {
        let faces = FaceList::from_triangles(&[[0, 1, 2], [0, 1, 3]]);
        assert_eq!(Topology::of(4, &faces).inconsistent_edges, 1);
    }
}
