//! Catmull–Clark subdivision surfaces: the control mesh fitted to the input
//! and its limit surface (Kloiber 2018 §3.8, after Thaller, Augsdörfer and
//! Fellner 2016; limit stencils of Halstead, Kass and DeRose 1993).
//!
//! - [`catmull_clark`]: one or `k` steps of Catmull–Clark subdivision of a
//!   polygon mesh of any face degree, with a [`BoundaryRule`];
//! - [`limit`]: limit positions and limit normals of control vertices, and
//!   the limit mesh (`k` subdivision steps, every vertex pushed to its limit
//!   position) for display, export and error measurement;
//! - [`fit`]: the control-mesh fitting ([`fit_control_mesh`]);
//! - [`error`]: the limit surface's distance to the input ([`LimitError`]),
//!   per vertex (signed, for the violet/green colouring of §3.9) and summed
//!   up (Hausdorff, mean, RMS).
//!
//! Coordinates are the pipeline's normalised ones (largest bounding-box axis
//! 1); every tolerance is relative to the reference's largest axis.

pub mod catmull_clark;
pub mod error;
pub mod fit;
pub mod limit;

use glam::DVec3;
use serde::{Deserialize, Serialize};

use crate::io::RawMesh;
use crate::mesh::{FaceList, Frame, MeshError, PolyMesh, UnionFind, newell_normal};

pub use catmull_clark::{subdivide, subdivide_creased, subdivide_levels};
pub use error::LimitError;
pub use fit::{FitParams, FitResult, FitSplit, FitSummary, fit_control_mesh};
pub use limit::{
    limit_mesh, limit_mesh_creased, limit_mesh_with_progress, limit_normals, limit_positions,
    limit_positions_creased,
};

/// What happens on a boundary of the control mesh.
///
/// [`BoundaryRule::Fixed`] is Kloiber's choice (§3.8): boundary vertices stay
/// where they are during the fitting *and* during subdivision; boundary edge
/// points are edge midpoints. The limit boundary is then the control
/// polygon's boundary itself (a polyline, not a cubic B-spline), which keeps
/// a fitted boundary exactly on the input's border.
///
/// [`BoundaryRule::Crease`] is the usual crease rule (Hoppe et al. 1994,
/// DeRose et al. 1998): the boundary is subdivided as a uniform cubic
/// B-spline curve (vertex point `(p₋ + 6p + p₊)/8`, edge point the
/// midpoint), whose limit point is `(p₋ + 4p + p₊)/6`. Corners get no
/// special treatment.
///
/// Interior vertices use the interior rules in both cases: their limit
/// position depends only on their one-ring, which never contains a boundary
/// rule.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum BoundaryRule {
    #[default]
    Fixed,
    Crease,
}

/// A polygon mesh as a file stores it (e.g. a user's retopology read with
/// [`crate::io::read_raw`]) as a half-edge mesh in the local coordinates of
/// `frame` (the reference's import frame, so both meshes share coordinates).
/// Vertices no face uses are dropped; a vertex whose faces form several fans
/// (common in other remeshers' output) is split into one vertex per fan, and
/// the number of extra vertices made is returned. What a half-edge mesh still
/// cannot hold (non-manifold edges, inconsistent orientation, degenerate
/// faces) is refused with the reason.
pub fn poly_mesh_in_frame(raw: &RawMesh, frame: &Frame) -> Result<(PolyMesh, usize), MeshError> {
    raw.faces.validate(raw.positions.len())?;
    let mut remap = vec![u32::MAX; raw.positions.len()];
    let mut positions: Vec<DVec3> = Vec::new();
    let mut faces = FaceList::new();
    let mut buf = Vec::new();
    for face in raw.faces.iter() {
        buf.clear();
        for &i in face {
            let slot = &mut remap[i as usize];
            if *slot == u32::MAX {
                *slot = u32::try_from(positions.len()).map_err(|_| MeshError::TooLarge)?;
                positions.push(frame.to_local(raw.positions[i as usize]));
            }
            buf.push(*slot);
        }
        faces.push(&buf);
    }
    let split = split_fans(&mut positions, &mut faces)?;
    Ok((PolyMesh::from_faces(positions, &faces)?, split))
}

/// Gives every fan of faces around a vertex its own vertex. Corners (face
/// slots) at the same vertex are in one fan when a manifold, consistently
/// oriented edge joins their faces; other edges are left for
/// [`PolyMesh::from_faces`] to refuse. Returns the number of vertices added.
fn split_fans(positions: &mut Vec<DVec3>, faces: &mut FaceList) -> Result<usize, MeshError> {
    use std::collections::HashMap;
    let corners = faces.indices.len();
    // Corner c's face-successor (the corner at the tip of c's edge).
    let mut succ = vec![0u32; corners];
    for w in faces.offsets.windows(2) {
        let (a, b) = (w[0] as usize, w[1] as usize);
        for c in a..b {
            succ[c] = if c + 1 == b { a as u32 } else { c as u32 + 1 };
        }
    }
    let mut directed: HashMap<(u32, u32), (u32, u32)> = HashMap::with_capacity(corners);
    for c in 0..corners {
        let key = (faces.indices[c], faces.indices[succ[c] as usize]);
        directed.entry(key).or_insert((c as u32, 0)).1 += 1;
    }
    let mut fans = UnionFind::new(corners);
    for (&(a, b), &(c1, count)) in &directed {
        if count != 1 || a > b {
            continue;
        }
        let Some(&(c2, 1)) = directed.get(&(b, a)) else {
            continue;
        };
        // c1 runs a→b in one face, c2 runs b→a in the other: at a, c1 and
        // the corner after c2 share the edge; at b, c2 and the one after c1.
        for (x, y) in [(c1, succ[c2 as usize]), (c2, succ[c1 as usize])] {
            fans.union(x, y);
        }
    }
    let mut fan_vertex: HashMap<u32, u32> = HashMap::new();
    let mut claimed = vec![false; positions.len()];
    let mut added = 0;
    for c in 0..corners {
        let v = faces.indices[c];
        let root = fans.find(c as u32);
        let new = *fan_vertex.entry(root).or_insert_with(|| {
            if !claimed[v as usize] {
                claimed[v as usize] = true;
                v
            } else {
                positions.push(positions[v as usize]);
                added += 1;
                (positions.len() - 1) as u32
            }
        });
        faces.indices[c] = new;
    }
    if positions.len() > u32::MAX as usize {
        return Err(MeshError::TooLarge);
    }
    Ok(added)
}

/// Newell normal of face `f` (length = twice the area for a planar polygon).
pub(crate) fn face_normal(mesh: &PolyMesh, f: u32) -> DVec3 {
    newell_normal(mesh.face_vertices(f).map(|v| mesh.positions[v as usize]))
}

/// Centroid of face `f`'s corners (the Catmull–Clark face point).
pub(crate) fn face_point(mesh: &PolyMesh, f: u32) -> DVec3 {
    let (mut sum, mut n) = (DVec3::ZERO, 0usize);
    for v in mesh.face_vertices(f) {
        sum += mesh.positions[v as usize];
        n += 1;
    }
    sum / n as f64
}
