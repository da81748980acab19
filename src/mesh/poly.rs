use std::collections::HashMap;

use glam::DVec3;

use super::{FaceList, MeshError, Topology};

/// "No element": a boundary half-edge's face.
pub const NONE: u32 = u32::MAX;

/// A manifold, consistently oriented polygon mesh with a half-edge structure
/// in flat index arrays (after geometry-central). Holds the quad-dominant
/// output, the control cage and its subdivisions.
///
/// Half-edges come in pairs: the twin of `h` is `h ^ 1`, so edge `e` is the
/// pair `(2e, 2e + 1)`. Every edge has both half-edges; a half-edge with no
/// face (`face == NONE`) lies on a boundary loop.
///
/// Invariants (checked by [`PolyMesh::validate`]):
/// 1. array lengths agree; the number of half-edges is even;
/// 2. `next` is a permutation; following `next` from `face_halfedge[f]`
///    visits ≥ 3 half-edges, all with face `f`, and returns; boundary
///    half-edges form closed loops too;
/// 3. `origin(next(h)) == origin(twin(h))` (a half-edge ends where its twin
///    starts), and `origin(h) != origin(twin(h))`;
/// 4. `vertex_halfedge[v]` starts at `v`; if `v` is on a boundary it is
///    `v`'s outgoing boundary half-edge;
/// 5. the one-ring walk `h → next(twin(h))` from `vertex_halfedge[v]`
///    visits every half-edge leaving `v` (each vertex is a single fan);
/// 6. no two edges join the same pair of vertices; positions are finite;
///    there are no isolated vertices.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PolyMesh {
    pub positions: Vec<DVec3>,
    next: Vec<u32>,
    origin: Vec<u32>,
    face: Vec<u32>,
    vertex_halfedge: Vec<u32>,
    face_halfedge: Vec<u32>,
}

impl PolyMesh {
    /// Builds the half-edge structure for `faces` over `positions`. Refuses
    /// what a half-edge mesh cannot hold: non-manifold edges and vertices,
    /// inconsistent orientation, degenerate faces, isolated vertices.
    pub fn from_faces(positions: Vec<DVec3>, faces: &FaceList) -> Result<PolyMesh, MeshError> {
        let n = positions.len();
        faces.validate(n)?;
        if let Some(v) = positions.iter().position(|p| !p.is_finite()) {
            return Err(MeshError::NonFinite { vertex: v });
        }
        let mut edge_of: HashMap<(u32, u32), u32> = HashMap::with_capacity(faces.indices.len());
        let mut origin: Vec<u32> = Vec::with_capacity(2 * faces.indices.len());
        let mut face: Vec<u32> = Vec::with_capacity(2 * faces.indices.len());
        let mut face_halfedge = Vec::with_capacity(faces.len());
        let mut next: Vec<u32> = Vec::with_capacity(2 * faces.indices.len());
        let mut face_hes: Vec<u32> = Vec::new();
        for (f, poly) in faces.iter().enumerate() {
            face_hes.clear();
            for (i, &a) in poly.iter().enumerate() {
                let b = poly[(i + 1) % poly.len()];
                if a == b || poly[..i].contains(&a) {
                    return Err(MeshError::DegenerateFace { face: f });
                }
                let key = (a.min(b), a.max(b));
                let h = match edge_of.get(&key) {
                    None => {
                        let e = (origin.len() / 2) as u32;
                        edge_of.insert(key, e);
                        origin.extend([a, b]);
                        face.extend([NONE, NONE]);
                        next.extend([NONE, NONE]);
                        2 * e
                    }
                    Some(&e) => {
                        let h = if origin[2 * e as usize] == a {
                            2 * e
                        } else {
                            2 * e + 1
                        };
                        if face[h as usize] != NONE {
                            let other = face[(h ^ 1) as usize];
                            return Err(if other == NONE {
                                MeshError::InconsistentOrientation { a, b }
                            } else {
                                MeshError::NonManifoldEdge { a, b }
                            });
                        }
                        h
                    }
                };
                face[h as usize] = f as u32;
                face_hes.push(h);
            }
            for (i, &h) in face_hes.iter().enumerate() {
                next[h as usize] = face_hes[(i + 1) % face_hes.len()];
            }
            face_halfedge.push(face_hes[0]);
        }

        // Boundary loops: the boundary half-edge ending at v continues with the
        // unique boundary half-edge leaving v.
        let mut boundary_out: Vec<u32> = vec![NONE; n];
        for h in 0..origin.len() {
            if face[h] == NONE {
                let v = origin[h] as usize;
                if boundary_out[v] != NONE {
                    return Err(MeshError::NonManifoldVertex { vertex: v as u32 });
                }
                boundary_out[v] = h as u32;
            }
        }
        for h in 0..origin.len() {
            if face[h] == NONE {
                let tip = origin[h ^ 1] as usize;
                next[h] = boundary_out[tip];
            }
        }
        let mut vertex_halfedge = boundary_out;
        for (h, &v) in origin.iter().enumerate() {
            if vertex_halfedge[v as usize] == NONE {
                vertex_halfedge[v as usize] = h as u32;
            }
        }
        if let Some(v) = vertex_halfedge.iter().position(|&h| h == NONE) {
            return Err(MeshError::IsolatedVertex { vertex: v as u32 });
        }
        let mesh = PolyMesh {
            positions,
            next,
            origin,
            face,
            vertex_halfedge,
            face_halfedge,
        };
        // A vertex with two fans that are both closed or that the boundary rule
        // above did not catch shows up as an incomplete one-ring walk.
        let mut degree = vec![0u32; n];
        for &v in &mesh.origin {
            degree[v as usize] += 1;
        }
        for v in 0..n as u32 {
            if mesh.outgoing(v).count() != degree[v as usize] as usize {
                return Err(MeshError::NonManifoldVertex { vertex: v });
            }
        }
        Ok(mesh)
    }

    pub fn from_triangles(
        positions: Vec<DVec3>,
        triangles: &[[u32; 3]],
    ) -> Result<PolyMesh, MeshError> {
        Self::from_faces(positions, &FaceList::from_triangles(triangles))
    }

    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }
    pub fn face_count(&self) -> usize {
        self.face_halfedge.len()
    }
    pub fn halfedge_count(&self) -> usize {
        self.origin.len()
    }
    pub fn edge_count(&self) -> usize {
        self.origin.len() / 2
    }

    pub fn twin(&self, h: u32) -> u32 {
        h ^ 1
    }
    pub fn next(&self, h: u32) -> u32 {
        self.next[h as usize]
    }
    /// The half-edge before `h` in its face or boundary loop (walks the loop).
    pub fn prev(&self, h: u32) -> u32 {
        let mut p = h;
        loop {
            let n = self.next(p);
            if n == h {
                return p;
            }
            p = n;
        }
    }
    pub fn origin(&self, h: u32) -> u32 {
        self.origin[h as usize]
    }
    pub fn tip(&self, h: u32) -> u32 {
        self.origin[(h ^ 1) as usize]
    }
    /// The face left of `h`, or [`NONE`] on a boundary.
    pub fn face(&self, h: u32) -> u32 {
        self.face[h as usize]
    }
    pub fn is_boundary_halfedge(&self, h: u32) -> bool {
        self.face[h as usize] == NONE
    }
    pub fn vertex_halfedge(&self, v: u32) -> u32 {
        self.vertex_halfedge[v as usize]
    }
    pub fn face_halfedge(&self, f: u32) -> u32 {
        self.face_halfedge[f as usize]
    }
    pub fn is_boundary_vertex(&self, v: u32) -> bool {
        self.is_boundary_halfedge(self.vertex_halfedge(v))
    }

    /// Half-edges of face (or boundary loop) starting at `h`, in order.
    pub fn loop_from(&self, h: u32) -> impl Iterator<Item = u32> + '_ {
        let mut cur = Some(h);
        std::iter::from_fn(move || {
            let c = cur?;
            let n = self.next(c);
            cur = (n != h).then_some(n);
            Some(c)
        })
    }

    pub fn face_halfedges(&self, f: u32) -> impl Iterator<Item = u32> + '_ {
        self.loop_from(self.face_halfedge(f))
    }

    pub fn face_vertices(&self, f: u32) -> impl Iterator<Item = u32> + '_ {
        self.face_halfedges(f).map(|h| self.origin(h))
    }

    pub fn degree(&self, f: u32) -> usize {
        self.face_halfedges(f).count()
    }

    /// Half-edges leaving `v`, rotating so that on a boundary vertex the
    /// outgoing boundary half-edge comes first.
    pub fn outgoing(&self, v: u32) -> impl Iterator<Item = u32> + '_ {
        let start = self.vertex_halfedge(v);
        let mut cur = Some(start);
        std::iter::from_fn(move || {
            let c = cur?;
            let n = self.next(self.twin(c));
            cur = (n != start).then_some(n);
            Some(c)
        })
    }

    pub fn valence(&self, v: u32) -> usize {
        self.outgoing(v).count()
    }

    /// One half-edge of each boundary loop.
    pub fn boundary_loops(&self) -> Vec<u32> {
        let mut seen = vec![false; self.halfedge_count()];
        let mut loops = Vec::new();
        for h in 0..self.halfedge_count() as u32 {
            if self.is_boundary_halfedge(h) && !seen[h as usize] {
                for g in self.loop_from(h) {
                    seen[g as usize] = true;
                }
                loops.push(h);
            }
        }
        loops
    }

    pub fn to_face_list(&self) -> FaceList {
        let mut list = FaceList::new();
        let mut buf = Vec::new();
        for f in 0..self.face_count() as u32 {
            buf.clear();
            buf.extend(self.face_vertices(f));
            list.push(&buf);
        }
        list
    }

    pub fn topology(&self) -> Topology {
        Topology::of(self.vertex_count(), &self.to_face_list())
    }

    pub fn euler_characteristic(&self) -> i64 {
        self.vertex_count() as i64 - self.edge_count() as i64 + self.face_count() as i64
    }

    /// Checks every invariant listed on the type.
    pub fn validate(&self) -> Result<(), MeshError> {
        let bad = |m: String| Err(MeshError::Connectivity(m));
        let nh = self.origin.len();
        if nh % 2 != 0 || self.next.len() != nh || self.face.len() != nh {
            return bad("half-edge arrays disagree in length".into());
        }
        if self.vertex_halfedge.len() != self.positions.len() {
            return bad("vertex arrays disagree in length".into());
        }
        if nh > u32::MAX as usize {
            return Err(MeshError::TooLarge);
        }
        if let Some(v) = self.positions.iter().position(|p| !p.is_finite()) {
            return Err(MeshError::NonFinite { vertex: v });
        }
        let nv = self.positions.len();
        let nf = self.face_halfedge.len();
        let mut incoming = vec![0u8; nh];
        for h in 0..nh {
            let n = self.next[h] as usize;
            if n >= nh {
                return bad(format!("next({h}) out of range"));
            }
            incoming[n] += 1;
            if self.origin[h] as usize >= nv {
                return bad(format!("origin({h}) out of range"));
            }
            let f = self.face[h];
            if f != NONE && f as usize >= nf {
                return bad(format!("face({h}) out of range"));
            }
            if self.face[n] != f {
                return bad(format!("next({h}) lies in another face"));
            }
            if self.origin[n] != self.origin[h ^ 1] {
                return bad(format!("half-edge {h} does not end where its twin starts"));
            }
            if self.origin[h] == self.origin[h ^ 1] {
                return bad(format!("half-edge {h} is a loop"));
            }
        }
        if incoming.iter().any(|&c| c != 1) {
            return bad("next is not a permutation".into());
        }
        let mut visited = vec![false; nh];
        for f in 0..nf as u32 {
            let h0 = self.face_halfedge[f as usize];
            if h0 as usize >= nh || self.face[h0 as usize] != f {
                return bad(format!("face {f}'s half-edge is not in it"));
            }
            let mut count = 0;
            for h in self.loop_from(h0) {
                visited[h as usize] = true;
                count += 1;
                if count > nh {
                    return bad(format!("face {f} does not close"));
                }
            }
            if count < 3 {
                return bad(format!("face {f} has degree {count}"));
            }
        }
        for h in 0..nh {
            if self.face[h] != NONE && !visited[h] {
                return bad(format!("half-edge {h} is not reachable from its face"));
            }
        }
        let mut degree = vec![0usize; nv];
        for &v in &self.origin {
            degree[v as usize] += 1;
        }
        for v in 0..nv as u32 {
            let h = self.vertex_halfedge[v as usize];
            if h == NONE {
                return Err(MeshError::IsolatedVertex { vertex: v });
            }
            if h as usize >= nh || self.origin[h as usize] != v {
                return bad(format!("vertex {v}'s half-edge does not start at it"));
            }
            let mut count = 0;
            let mut boundary = 0;
            for g in self.outgoing(v) {
                count += 1;
                boundary += self.is_boundary_halfedge(g) as usize;
                if count > degree[v as usize] {
                    break;
                }
            }
            if count != degree[v as usize] {
                return Err(MeshError::NonManifoldVertex { vertex: v });
            }
            if boundary > 1 || (boundary == 1 && !self.is_boundary_halfedge(h)) {
                return bad(format!("vertex {v}'s boundary half-edge is not its first"));
            }
        }
        let mut pairs: Vec<(u32, u32)> = (0..nh / 2)
            .map(|e| {
                let (a, b) = (self.origin[2 * e], self.origin[2 * e + 1]);
                (a.min(b), a.max(b))
            })
            .collect();
        pairs.sort_unstable();
        if let Some(w) = pairs.windows(2).find(|w| w[0] == w[1]) {
            return bad(format!("two edges join vertices {} and {}", w[0].0, w[0].1));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(n: usize) -> (Vec<DVec3>, FaceList) {
        let mut p = Vec::new();
        for j in 0..=n {
            for i in 0..=n {
                p.push(DVec3::new(i as f64, j as f64, 0.0));
            }
        }
        let mut faces = FaceList::new();
        let id = |i: usize, j: usize| (j * (n + 1) + i) as u32;
        for j in 0..n {
            for i in 0..n {
                faces.push(&[id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        (p, faces)
    }

    fn cube() -> (Vec<DVec3>, FaceList) {
        crate::mesh::generate::unit_cube_quads()
    }

    #[test]
    fn cube_is_closed_with_valence_three() {
        let (p, f) = cube();
        let m = PolyMesh::from_faces(p, &f).unwrap();
        m.validate().unwrap();
        assert_eq!(m.edge_count(), 12);
        assert_eq!(m.euler_characteristic(), 2);
        assert!(m.boundary_loops().is_empty());
        assert!((0..8).all(|v| m.valence(v) == 3));
        assert_eq!(m.to_face_list(), f);
    }

    #[test]
    fn grid_has_one_boundary_loop() {
        let (p, f) = grid(3);
        let m = PolyMesh::from_faces(p, &f).unwrap();
        m.validate().unwrap();
        let loops = m.boundary_loops();
        assert_eq!(loops.len(), 1);
        assert_eq!(m.loop_from(loops[0]).count(), 12);
        assert!(m.is_boundary_vertex(0));
        assert!(!m.is_boundary_vertex(5));
        assert_eq!(m.valence(5), 4);
        assert_eq!(m.valence(0), 2);
        assert_eq!(m.valence(1), 3);
        assert_eq!(m.topology().boundary_edges, 12);
    }

    #[test]
    fn refuses_what_half_edges_cannot_hold() {
        let p = vec![DVec3::ZERO; 6];
        let fin = FaceList::from_triangles(&[[0, 1, 2], [1, 0, 3], [0, 1, 4]]);
        assert!(matches!(
            PolyMesh::from_faces(p.clone(), &fin),
            Err(MeshError::NonManifoldEdge { .. }) | Err(MeshError::InconsistentOrientation { .. })
        ));
        let flipped = FaceList::from_triangles(&[[0, 1, 2], [0, 1, 3]]);
        assert!(matches!(
            PolyMesh::from_faces(p[..4].to_vec(), &flipped),
            Err(MeshError::InconsistentOrientation { .. })
        ));
        let bowtie = FaceList::from_triangles(&[[0, 1, 2], [0, 3, 4]]);
        assert!(matches!(
            PolyMesh::from_faces(p[..5].to_vec(), &bowtie),
            Err(MeshError::NonManifoldVertex { vertex: 0 })
        ));
        let isolated = FaceList::from_triangles(&[[0, 1, 2]]);
        assert!(matches!(
            PolyMesh::from_faces(p[..4].to_vec(), &isolated),
            Err(MeshError::IsolatedVertex { vertex: 3 })
        ));
    }

    #[test]
    fn closed_bowtie_of_two_tetrahedra_is_refused() {
        // Two closed tetrahedra sharing vertex 0: no boundary to catch it.
        let p = vec![DVec3::ZERO; 7];
        let faces = FaceList::from_triangles(&[
            [0, 2, 1],
            [0, 1, 3],
            [1, 2, 3],
            [2, 0, 3],
            [0, 5, 4],
            [0, 4, 6],
            [4, 5, 6],
            [5, 0, 6],
        ]);
        assert!(matches!(
            PolyMesh::from_faces(p, &faces),
            Err(MeshError::NonManifoldVertex { vertex: 0 })
        ));
    }

    #[test]
    fn validate_catches_corruption() {
        let (p, f) = cube();
        let mut m = PolyMesh::from_faces(p, &f).unwrap();
        m.next.swap(0, 2);
        assert!(m.validate().is_err());
    }
}
