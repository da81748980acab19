//! The flat arrays the page needs to draw an imported mesh: f32 positions in
//! local coordinates, u32 triangles, area-weighted vertex normals, and the
//! edges of the file's polygons (so quads are drawn as quads, not as two
//! triangles with a diagonal) with the boundary edges among them.

use glam::DVec3;

use crate::mesh::{FaceList, TriMesh};

#[derive(Debug, Clone, Default, PartialEq)]
pub struct MeshArrays {
    /// xyz per vertex, local coordinates.
    pub positions: Vec<f32>,
    /// Vertex triples.
    pub triangles: Vec<u32>,
    /// xyz unit normal per vertex (zero where every adjacent face is degenerate).
    pub normals: Vec<f32>,
    /// Vertex pairs, one per undirected polygon edge.
    pub polygon_edges: Vec<u32>,
    /// Vertex pairs of the polygon edges used by exactly one polygon.
    pub boundary_edges: Vec<u32>,
}

impl MeshArrays {
    /// `polygons` index `mesh.positions`, as [`crate::io::Imported`] guarantees.
    pub fn new(mesh: &TriMesh, polygons: &FaceList) -> MeshArrays {
        let positions = mesh
            .positions
            .iter()
            .flat_map(|p| [p.x as f32, p.y as f32, p.z as f32])
            .collect();
        let triangles = mesh.triangles.iter().flatten().copied().collect();
        let (polygon_edges, boundary_edges) = polygon_edges(polygons);
        MeshArrays {
            positions,
            triangles,
            normals: vertex_normals(mesh),
            polygon_edges,
            boundary_edges,
        }
    }
}

/// Area-weighted vertex normals (the sum of unnormalised face normals).
pub fn vertex_normals(mesh: &TriMesh) -> Vec<f32> {
    let mut sums = vec![DVec3::ZERO; mesh.positions.len()];
    for (f, t) in mesh.triangles.iter().enumerate() {
        let n = mesh.face_normal_unnormalized(f);
        for &v in t {
            sums[v as usize] += n;
        }
    }
    sums.iter()
        .flat_map(|n| {
            let n = n.normalize_or_zero();
            [n.x as f32, n.y as f32, n.z as f32]
        })
        .collect()
}

/// All undirected edges of the polygons, and those used by exactly one polygon.
pub fn polygon_edges(polygons: &FaceList) -> (Vec<u32>, Vec<u32>) {
    let mut edges: Vec<(u32, u32)> = Vec::with_capacity(polygons.indices.len());
    for face in polygons.iter() {
        for (i, &a) in face.iter().enumerate() {
            let b = face[(i + 1) % face.len()];
            edges.push((a.min(b), a.max(b)));
        }
    }
    edges.sort_unstable();
    let (mut all, mut boundary) = (Vec::new(), Vec::new());
    let mut i = 0;
    while i < edges.len() {
        let mut j = i + 1;
        while j < edges.len() && edges[j] == edges[i] {
            j += 1;
        }
        let (a, b) = edges[i];
        all.extend([a, b]);
        if j - i == 1 {
            boundary.extend([a, b]);
        }
        i = j;
    }
    (all, boundary)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quad_pair_has_seven_edges_and_six_on_the_boundary() {
        // Two quads sharing the edge 1–4.
        let mut polygons = FaceList::new();
        polygons.push(&[0, 1, 4, 3]);
        polygons.push(&[1, 2, 5, 4]);
        let (all, boundary) = polygon_edges(&polygons);
        assert_eq!(all.len(), 2 * 7);
        assert_eq!(boundary.len(), 2 * 6);
        assert!(!boundary.chunks(2).any(|e| e == [1, 4]));
        assert!(
            !all.chunks(2).any(|e| e == [0, 4] || e == [1, 3]),
            "no diagonals"
        );
    }

    #[test]
    fn normals_of_a_flat_square_point_up() {
        let mesh = TriMesh::new(
            vec![
                DVec3::new(0., 0., 0.),
                DVec3::new(1., 0., 0.),
                DVec3::new(1., 1., 0.),
                DVec3::new(0., 1., 0.),
            ],
            vec![[0, 1, 2], [0, 2, 3]],
        )
        .unwrap();
        let arrays = MeshArrays::new(&mesh, &FaceList::from_triangles(&mesh.triangles));
        assert_eq!(arrays.normals, [0., 0., 1.].repeat(4));
        assert_eq!(arrays.positions.len(), 12);
        assert_eq!(arrays.triangles, vec![0, 1, 2, 0, 2, 3]);
        assert_eq!(arrays.boundary_edges.len(), 8);
    }
}
