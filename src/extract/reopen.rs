//! Input holes the extraction closed over, opened again (not in the thesis;
//! DESIGN's "input boundaries are data" and the quality issue's "every
//! input boundary loop whose length exceeds about two target edges is a
//! boundary loop of the output").
//!
//! The extraction decides from the traced orbits alone whether a short
//! orbit runs around an input hole (`around_input_hole`); a hole a few
//! edges around can end up under a face (the bunny's smallest hole, 3.1
//! edges around, under a triangle at 600 vertices). After post-processing,
//! [`crate::metrics::loop_audit`] finds such loops; a face whose centroid's
//! closest point on the input lies on the rim of one of them lies over the
//! hole and is removed. A removal that would leave the mesh non-manifold is
//! not made.

use crate::mesh::{FaceList, PolyMesh, TriMesh};
use crate::metrics::{LoopFate, loop_audit};
use crate::spatial::{SegmentGrid, SurfaceIndex};

/// The mesh without the faces over input holes it closed over, and how
/// many loops that opened; `None` when no face lies over such a hole (or
/// removing them would break the mesh).
pub fn reopen_closed_loops(
    mesh: &PolyMesh,
    input: &TriMesh,
    surface: &SurfaceIndex,
) -> Option<(PolyMesh, usize)> {
    let audit = loop_audit(mesh, input);
    if !audit.fates.contains(&LoopFate::ClosedOver) {
        return None;
    }
    // The rims of the loops closed over, each edge tagged with its loop.
    let rims: Vec<_> = audit
        .boundary_edges
        .iter()
        .filter_map(|&[a, b]| {
            let l = audit.arcs.loop_of[a as usize];
            (audit.fates[l as usize] == LoopFate::ClosedOver).then_some((
                [input.positions[a as usize], input.positions[b as usize]],
                l,
            ))
        })
        .collect();
    let rims = SegmentGrid::new(rims, audit.s);
    let tolerance = 1e-9 * audit.s.max(f64::MIN_POSITIVE);
    let mut opened = std::collections::BTreeSet::new();
    let mut faces = FaceList::new();
    for f in 0..mesh.face_count() as u32 {
        let corners: Vec<u32> = mesh.face_vertices(f).collect();
        let centroid = corners
            .iter()
            .map(|&v| mesh.positions[v as usize])
            .sum::<glam::DVec3>()
            / corners.len() as f64;
        let q = surface.closest(centroid).point;
        match rims.first_within(q, tolerance, |_| true) {
            Some(l) => {
                opened.insert(l);
            }
            None => faces.push(&corners),
        }
    }
    if opened.is_empty() {
        return None;
    }
    // Only the vertices the remaining faces use, renumbered.
    let mut index = vec![u32::MAX; mesh.vertex_count()];
    let mut positions = Vec::new();
    let mut kept = FaceList::new();
    for face in faces.iter() {
        let renumbered: Vec<u32> = face
            .iter()
            .map(|&v| {
                if index[v as usize] == u32::MAX {
                    index[v as usize] = positions.len() as u32;
                    positions.push(mesh.positions[v as usize]);
                }
                index[v as usize]
            })
            .collect();
        kept.push(&renumbered);
    }
    let topology = crate::mesh::Topology::of(positions.len(), &kept);
    if topology.nonmanifold_vertices > 0 || topology.nonmanifold_edges > 0 {
        return None;
    }
    let reopened = PolyMesh::from_faces(positions, &kept).ok()?;
    Some((reopened, opened.len()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::metrics::preservation_metrics;
    use crate::metrics::tests::{quad_grid, tri_grid};

    #[test]
    fn the_faces_over_a_closed_hole_go_and_nothing_else_does() {
        // Output edges 0.2; the input's hole 0.4 across (8 edges around),
        // covered in the output by its 2 × 2 middle quads.
        let hole = |x: f64, y: f64| x.abs().max(y.abs()) > 0.2;
        let input = tri_grid(hole);
        let surface = SurfaceIndex::new(&input).unwrap();
        let covered = quad_grid(10, |_, _| true);
        assert_eq!(preservation_metrics(&covered, &input).loops_closed.len(), 1);
        let (opened, n) = reopen_closed_loops(&covered, &input, &surface).unwrap();
        assert_eq!(n, 1);
        assert_eq!(opened.face_count(), 96);
        assert_eq!(opened.boundary_loops().len(), 2);
        let after = preservation_metrics(&opened, &input);
        assert!(
            after.loops_closed.is_empty() && after.loops_kept == 2,
            "{after:?}"
        );
        // A mesh that kept the hole, and a hole too small to keep: nothing to do.
        assert!(reopen_closed_loops(&quad_grid(10, hole), &input, &surface).is_none());
        let tiny = tri_grid(|x, y| x.abs().max(y.abs()) > 0.04);
        let tiny_surface = SurfaceIndex::new(&tiny).unwrap();
        assert!(reopen_closed_loops(&covered, &tiny, &tiny_surface).is_none());
    }
}
