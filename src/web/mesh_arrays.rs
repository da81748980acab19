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

/// The viewer's parametrization layer: every input triangle gets its own
/// three corners (so triangle `t` is input face `t` and the (u, v) may
/// jump across the cut graph's seams), with the input's smooth vertex
/// normals, the integer-grid map's per-corner (u, v) (one unit = one
/// target edge) and, per corner, an RGBA colour: plain, or
/// [`FLIPPED_COLOR`] on triangles whose parametric area is not positive.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct GridMapArrays {
    pub positions: Vec<f32>,
    pub normals: Vec<f32>,
    pub triangles: Vec<u32>,
    /// Two floats per corner.
    pub uv: Vec<f32>,
    /// Four bytes per corner.
    pub colors: Vec<u8>,
    pub flipped: usize,
}

/// The surface colour of the parametrization layer (the viewer's plain grey).
pub const GRID_COLOR: [u8; 4] = [0xc8, 0xcd, 0xd8, 0xff];
/// Tint of flipped triangles (magenta: neither cone colour).
pub const FLIPPED_COLOR: [u8; 4] = [0xe0, 0x2d, 0xc8, 0xff];

impl GridMapArrays {
    pub fn new(mesh: &TriMesh, map: &crate::param::GridMap) -> GridMapArrays {
        let normals = vertex_normals(mesh);
        let flipped = map.flipped();
        let n = mesh.face_count();
        let mut out = GridMapArrays {
            positions: Vec::with_capacity(9 * n),
            normals: Vec::with_capacity(9 * n),
            triangles: (0..(3 * n) as u32).collect(),
            uv: Vec::with_capacity(6 * n),
            colors: Vec::with_capacity(12 * n),
            flipped: flipped.iter().filter(|&&f| f).count(),
        };
        for (f, t) in mesh.triangles.iter().enumerate() {
            let color = if flipped.get(f).copied().unwrap_or(false) {
                FLIPPED_COLOR
            } else {
                GRID_COLOR
            };
            for (i, &v) in t.iter().enumerate() {
                let p = mesh.positions[v as usize];
                out.positions
                    .extend_from_slice(&[p.x as f32, p.y as f32, p.z as f32]);
                out.normals
                    .extend_from_slice(&normals[3 * v as usize..3 * v as usize + 3]);
                let q = map.uv.get(f).map_or(glam::DVec2::ZERO, |q| q[i]);
                out.uv.extend_from_slice(&[q.x as f32, q.y as f32]);
                out.colors.extend_from_slice(&color);
            }
        }
        out
    }
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
    fn grid_map_arrays_carry_the_maps_corners_and_flips() {
        // A 4×4 grid of unit squares, its map (u, v) = (x, y) with one
        // triangle's corners swapped so its parametric area is negative.
        let mesh = crate::mesh::generate::flat_grid(2.0, 4);
        let nf = mesh.face_count();
        let mut uv: Vec<[glam::DVec2; 3]> = mesh
            .triangles
            .iter()
            .map(|t| t.map(|v| mesh.positions[v as usize].truncate()))
            .collect();
        uv[5].swap(0, 1);
        let topology = crate::param::EdgeTopology::new(&mesh);
        let map = crate::param::GridMap {
            uv: uv.clone(),
            cut: crate::param::Cut {
                comb: vec![0; nf],
                matching: vec![[0; 3]; nf],
                tree: vec![[false; 3]; nf],
                seam: vec![[false; 3]; nf],
                wedge: (0..nf as u32)
                    .map(|f| [3 * f, 3 * f + 1, 3 * f + 2])
                    .collect(),
                wedge_count: 3 * nf,
            },
            frames: Vec::new(),
            cones: Vec::new(),
            topology,
            energy: 0.0,
            rounding_steps: 0,
            symbolic_analyses: 0,
            conflicts: 0,
            closed_loops: 0,
            widened_loops: 0,
        };
        let a = GridMapArrays::new(&mesh, &map);
        assert_eq!(a.positions.len(), 9 * mesh.face_count());
        assert_eq!(a.uv.len(), 6 * mesh.face_count());
        assert_eq!(a.flipped, 1);
        for (f, t) in mesh.triangles.iter().enumerate() {
            for i in 0..3 {
                let c = 3 * f + i;
                let p = mesh.positions[t[i] as usize];
                assert_eq!(
                    a.positions[3 * c..3 * c + 3],
                    [p.x as f32, p.y as f32, p.z as f32]
                );
                assert_eq!(
                    a.uv[2 * c..2 * c + 2],
                    [uv[f][i].x as f32, uv[f][i].y as f32]
                );
                let expected = if f == 5 { FLIPPED_COLOR } else { GRID_COLOR };
                assert_eq!(a.colors[4 * c..4 * c + 4], expected);
            }
        }
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
