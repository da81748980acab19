//! Catmull–Clark subdivision (Catmull and Clark 1978) of polygon meshes of
//! any face degree, as used by Kloiber 2018 §3.8 to turn the quad-dominant
//! mesh into a pure quad mesh and to display the limit surface.
//!
//! Rules, for a manifold mesh:
//! - face point: the centroid of the face's corners;
//! - interior edge point: `(a + b + F₁ + F₂) / 4`;
//! - interior vertex point of valence `n`: `((n − 2) v + (Σ eⱼ + Σ Fⱼ) / n) / n`
//!   (`eⱼ` the edge neighbours, `Fⱼ` the new face points), which is
//!   Catmull–Clark's `(Q + 2R + (n − 3) S) / n`;
//! - boundary: see [`BoundaryRule`] (Kloiber's fixed boundary, or the cubic
//!   B-spline crease).
//!
//! Numbering: the new mesh keeps the old vertices first (same indices), then
//! one vertex per old edge (edge `e` → `V + e`), then one per old face
//! (`V + E + f`). So a control vertex keeps its index through every level,
//! which is what the convergence tests use.

use glam::DVec3;

use super::{BoundaryRule, face_point};
use crate::mesh::{FaceList, PolyMesh};

/// One Catmull–Clark step: every face of degree `d` becomes `d` quads.
pub fn subdivide(mesh: &PolyMesh, rule: BoundaryRule) -> PolyMesh {
    let nv = mesh.vertex_count();
    let ne = mesh.edge_count();
    let nf = mesh.face_count();
    let p = &mesh.positions;

    let face_points: Vec<DVec3> = (0..nf as u32).map(|f| face_point(mesh, f)).collect();
    let mut positions = Vec::with_capacity(nv + ne + nf);
    for v in 0..nv as u32 {
        positions.push(vertex_point(mesh, v, &face_points, rule));
    }
    for e in 0..ne as u32 {
        let h = 2 * e;
        let (a, b) = (p[mesh.origin(h) as usize], p[mesh.tip(h) as usize]);
        let (f1, f2) = (mesh.face(h), mesh.face(h ^ 1));
        positions.push(
            if mesh.is_boundary_halfedge(h) || mesh.is_boundary_halfedge(h ^ 1) {
                0.5 * (a + b)
            } else {
                0.25 * (a + b + face_points[f1 as usize] + face_points[f2 as usize])
            },
        );
    }
    positions.extend_from_slice(&face_points);

    let mut faces = FaceList::new();
    let mut hs: Vec<u32> = Vec::new();
    for f in 0..nf as u32 {
        hs.clear();
        hs.extend(mesh.face_halfedges(f));
        let d = hs.len();
        let centre = (nv + ne) as u32 + f;
        for i in 0..d {
            let h = hs[i];
            let before = hs[(i + d - 1) % d];
            faces.push(&[
                mesh.origin(h),
                nv as u32 + h / 2,
                centre,
                nv as u32 + before / 2,
            ]);
        }
    }
    // A valid half-edge mesh subdivides into a valid one (each new quad is
    // a corner of an old face; edges are split consistently), so failure
    // here is a bug in this function, never a property of user data.
    PolyMesh::from_faces(positions, &faces).expect("Catmull–Clark step of a valid mesh")
}

/// `levels` Catmull–Clark steps (`levels == 0` returns a copy).
pub fn subdivide_levels(mesh: &PolyMesh, levels: u32, rule: BoundaryRule) -> PolyMesh {
    let mut m = mesh.clone();
    for _ in 0..levels {
        m = subdivide(&m, rule);
    }
    m
}

fn vertex_point(mesh: &PolyMesh, v: u32, face_points: &[DVec3], rule: BoundaryRule) -> DVec3 {
    let p = mesh.positions[v as usize];
    if mesh.is_boundary_vertex(v) {
        return match rule {
            BoundaryRule::Fixed => p,
            BoundaryRule::Crease => {
                let (prev, next) = boundary_neighbours(mesh, v);
                (prev + 6.0 * p + next) / 8.0
            }
        };
    }
    let (mut sum_e, mut sum_f, mut n) = (DVec3::ZERO, DVec3::ZERO, 0usize);
    for h in mesh.outgoing(v) {
        sum_e += mesh.positions[mesh.tip(h) as usize];
        sum_f += face_points[mesh.face(h) as usize];
        n += 1;
    }
    let n = n as f64;
    ((n - 2.0) * p + (sum_e + sum_f) / n) / n
}

/// The two boundary neighbours of boundary vertex `v`: (the one before it on
/// the boundary loop, the one after it).
pub(crate) fn boundary_neighbours(mesh: &PolyMesh, v: u32) -> (DVec3, DVec3) {
    // `outgoing` starts with v's boundary half-edge; its tip follows v on the
    // loop. The last outgoing half-edge's twin is the boundary half-edge
    // entering v.
    let first = mesh.vertex_halfedge(v);
    let last = mesh.outgoing(v).last().unwrap_or(first);
    (
        mesh.positions[mesh.tip(last) as usize],
        mesh.positions[mesh.tip(first) as usize],
    )
}
