//! Edge and vertex-fan topology of a triangle mesh, per face and local
//! edge, as the cross field, the cut graph and the layout tool read it.
//!
//! Local edge `i` of a face runs from its corner `i` to corner `i + 1`.
//! Non-manifold edges (more than two faces) are treated as boundary.

use crate::mesh::TriMesh;

/// Marks a missing neighbour (boundary or non-manifold edge).
pub const NO_FACE: u32 = u32::MAX;

pub use crate::mesh::EdgeTopology;

/// The faces around one vertex in counter-clockwise order (seen from the
/// side the normals point to): `(face, local corner of the vertex)`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Fan {
    pub corners: Vec<(u32, u8)>,
    /// The fan closes around the vertex (an interior vertex).
    pub closed: bool,
}

/// The fan of every vertex that has a single one (manifold vertices);
/// `None` for unused and non-manifold vertices.
pub fn vertex_fans(mesh: &TriMesh, topology: &EdgeTopology) -> Vec<Option<Fan>> {
    let nv = mesh.positions.len();
    let mut first: Vec<Option<(u32, u8)>> = vec![None; nv];
    let mut uses = vec![0u32; nv];
    for (f, t) in mesh.triangles.iter().enumerate() {
        for (i, &v) in t.iter().enumerate() {
            uses[v as usize] += 1;
            first[v as usize].get_or_insert((f as u32, i as u8));
        }
    }
    (0..nv)
        .map(|v| {
            let start = first[v]?;
            let fan = walk_fan(mesh, topology, start)?;
            (fan.corners.len() == uses[v] as usize).then_some(fan)
        })
        .collect()
}

/// Walks from corner `start` clockwise to the fan's first face (or once
/// round), then counter-clockwise collecting the corners.
fn walk_fan(mesh: &TriMesh, topology: &EdgeTopology, start: (u32, u8)) -> Option<Fan> {
    let limit = mesh.triangles.len() + 1;
    let mut at = start;
    let mut closed = false;
    for _ in 0..limit {
        let Some(prev) = cw_next(topology, at.0 as usize, at.1 as usize) else {
            break;
        };
        at = prev;
        if at == start {
            closed = true;
            break;
        }
    }
    let first = at;
    let mut corners = vec![first];
    for _ in 0..limit {
        let Some(next) = ccw_next(topology, at.0 as usize, at.1 as usize) else {
            break;
        };
        at = next;
        if at == first {
            break;
        }
        corners.push(at);
    }
    Some(Fan { corners, closed })
}

/// The next corner of the same vertex counter-clockwise: across local
/// edge i + 2 (corner i + 2 → corner i); there the edge starts at the
/// vertex.
pub fn ccw_next(topology: &EdgeTopology, f: usize, i: usize) -> Option<(u32, u8)> {
    let (g, ge) = topology.across(f, (i + 2) % 3)?;
    Some((g as u32, ge as u8))
}

/// The next corner clockwise: across local edge i (corner i → i + 1);
/// there the edge ends at the vertex.
pub fn cw_next(topology: &EdgeTopology, f: usize, i: usize) -> Option<(u32, u8)> {
    let (g, ge) = topology.across(f, i)?;
    Some((g as u32, ((ge + 1) % 3) as u8))
}
