//! Non-manifold vertices split, one copy per fan, before the map.
//!
//! The map (Bommes et al. 2009 §4's cut graph, `cut`) and the extraction
//! (QEx, Ebke et al. 2013, as Ebke et al. 2014 §6 uses it: the star of
//! every vertex is one fan of triangles) read the surface as a 2-manifold;
//! `topology` already treats a non-manifold edge as boundary, but a vertex
//! where two sheets touch (two fans of triangles, or more) has no star,
//! and every isoline that reaches it ends there. An old hand-made model
//! is made of panels that touch at such vertices (the beetle: 27 of the 77
//! isolines its extraction lost at its default target ended at one).
//! Here each such vertex where an open fan (a sheet's boundary) meets
//! another fan becomes one vertex per fan, at the same position: the
//! sheets meet along their boundaries as they do in the input, and each
//! is a manifold surface with boundary. The first vertices are the
//! input's; a vertex's first fan keeps its index. The beetle at the
//! table's target, medians over 15 vertex orders: Hausdorff distance
//! 0.342 without the split, 0.165 with it (`docs/RESULTS.md`, "The
//! beetle's global Hausdorff distance over 15 vertex orders").
//!
//! A pinch of closed fans stays as it is: that is a closed part touching
//! another at one point, and split off it is a part of its own, mapped on
//! its own. The cow's tail hangs from its back by one such vertex; split,
//! the thin tail (about one target edge round) came out as a second
//! component of distorted quads: over 5 vertex orders at the default
//! target the cow's mean corner deviation went 7.52° → 16.12° (Instant
//! Meshes 11.55°) and its Hausdorff distance 0.195 → 0.187 (its legs
//! stay the farthest part).

use super::topology::{EdgeTopology, ccw_next, cw_next};
use crate::mesh::{TriMesh, UnionFind};

/// The mesh with its non-manifold vertices that have an open fan split
/// into one vertex per fan; `None` when there is none.
pub fn split_nonmanifold_vertices(mesh: &TriMesh) -> Option<TriMesh> {
    let topology = EdgeTopology::new(mesh);
    let nf = mesh.triangles.len();
    // Union-find over corners (3 f + i): corners of one vertex joined
    // across the manifold edges between their faces.
    let mut sets = UnionFind::new(3 * nf);
    for f in 0..nf {
        for i in 0..3 {
            if let Some((g, gi)) = ccw_next(&topology, f, i) {
                sets.union((3 * f + i) as u32, 3 * g + gi as u32);
            }
        }
    }
    // Open fans (a corner without a neighbour on either side), by root.
    let mut open = vec![false; 3 * nf];
    for f in 0..nf {
        for i in 0..3 {
            if ccw_next(&topology, f, i).is_none() || cw_next(&topology, f, i).is_none() {
                let r = sets.find((3 * f + i) as u32) as usize;
                open[r] = true;
            }
        }
    }
    // Vertices with more than one fan, one of them open.
    let mut roots: Vec<Vec<usize>> = vec![Vec::new(); mesh.positions.len()];
    for f in 0..nf {
        for i in 0..3 {
            let r = sets.find((3 * f + i) as u32) as usize;
            let v = mesh.triangles[f][i] as usize;
            if !roots[v].contains(&r) {
                roots[v].push(r);
            }
        }
    }
    let split: Vec<bool> = roots
        .iter()
        .map(|rs| rs.len() > 1 && rs.iter().any(|&r| open[r]))
        .collect();
    // Per vertex, the index of each fan (by its root corner).
    let mut index_of_root: std::collections::HashMap<usize, u32> = Default::default();
    let mut first_root: Vec<Option<usize>> = vec![None; mesh.positions.len()];
    let mut positions = mesh.positions.clone();
    let mut triangles = mesh.triangles.clone();
    for f in 0..nf {
        for i in 0..3 {
            let v = mesh.triangles[f][i] as usize;
            let root = sets.find((3 * f + i) as u32) as usize;
            let id = match index_of_root.get(&root) {
                Some(&id) => id,
                None => {
                    let id = if first_root[v].is_none() || !split[v] {
                        first_root[v] = Some(root);
                        v as u32
                    } else {
                        positions.push(mesh.positions[v]);
                        (positions.len() - 1) as u32
                    };
                    index_of_root.insert(root, id);
                    id
                }
            };
            triangles[f][i] = id;
        }
    }
    (positions.len() > mesh.positions.len()).then_some(TriMesh {
        positions,
        triangles,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::param::vertex_fans;
    use glam::DVec3;

    #[test]
    fn two_triangles_touching_at_a_vertex_get_one_vertex_each() {
        // A bow tie: two triangles sharing only vertex 0.
        let mesh = TriMesh::new(
            vec![
                DVec3::ZERO,
                DVec3::new(1.0, 0.0, 0.0),
                DVec3::new(1.0, 1.0, 0.0),
                DVec3::new(-1.0, 0.0, 0.0),
                DVec3::new(-1.0, -1.0, 0.0),
            ],
            vec![[0, 1, 2], [0, 3, 4]],
        )
        .unwrap();
        assert!(vertex_fans(&mesh, &EdgeTopology::new(&mesh))[0].is_none());
        let split = split_nonmanifold_vertices(&mesh).expect("split");
        assert_eq!(split.positions.len(), 6);
        assert_eq!(split.triangles[0], [0, 1, 2]);
        assert_eq!(split.triangles[1], [5, 3, 4]);
        assert_eq!(split.positions[5], DVec3::ZERO);
        let fans = vertex_fans(&split, &EdgeTopology::new(&split));
        assert!(fans.iter().all(Option::is_some), "every vertex has one fan");
    }

    #[test]
    fn two_closed_surfaces_touching_at_a_vertex_stay_as_they_are() {
        // Two tetrahedra sharing one vertex: two closed fans round it.
        let a = crate::mesh::generate::tetrahedron();
        let n = a.positions.len() as u32;
        let mut positions = a.positions.clone();
        positions.extend(
            a.positions
                .iter()
                .skip(1)
                .map(|p| -*p + 2.0 * a.positions[0]),
        );
        let mut triangles = a.triangles.clone();
        let map = |v: u32| if v == 0 { 0 } else { v + n - 1 };
        triangles.extend(
            a.triangles
                .iter()
                .map(|t| [map(t[0]), map(t[2]), map(t[1])]),
        );
        let mesh = TriMesh::new(positions, triangles).unwrap();
        assert!(vertex_fans(&mesh, &EdgeTopology::new(&mesh))[0].is_none());
        assert!(split_nonmanifold_vertices(&mesh).is_none());
    }

    #[test]
    fn a_manifold_mesh_is_left_alone() {
        let mesh = crate::mesh::generate::icosphere(1.0, 2);
        assert!(split_nonmanifold_vertices(&mesh).is_none());
    }
}
