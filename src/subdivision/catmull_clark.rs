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
//!   B-spline crease);
//! - interior *sharp* edges (infinitely sharp creases, Hoppe et al. 1994,
//!   DeRose et al. 1998; see [`Vertex`]): the edge point is the midpoint; a vertex on
//!   exactly two sharp edges gets the crease rule `(a + 6v + b)/8` (`a`, `b`
//!   their other ends), one on three or more is a corner and stays, one on
//!   a single sharp edge (a dart) keeps the smooth rule. Both halves of a
//!   sharp edge are sharp.
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
    subdivide_creased(mesh, rule, &[]).0
}

/// How the rules see a vertex, given the sharp edges (`sharp[e]` for edge
/// `e`; missing entries are smooth).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Vertex {
    /// On the boundary (the [`BoundaryRule`] decides), with no interior
    /// sharp edge.
    Boundary,
    /// Interior, on fewer than two sharp edges: the smooth rules.
    Smooth,
    /// On exactly two sharp edges, whose other ends are given (a crease
    /// curve through the vertex).
    Crease(DVec3, DVec3),
    /// On three or more sharp edges, or on the boundary and a sharp edge:
    /// stays where it is.
    Corner,
}

impl Vertex {
    pub(crate) fn of(mesh: &PolyMesh, v: u32, sharp: &[bool]) -> Vertex {
        let boundary = mesh.is_boundary_vertex(v);
        let mut ends = [DVec3::ZERO; 2];
        let mut count = 0;
        for h in mesh.outgoing(v) {
            let interior = !mesh.is_boundary_halfedge(h) && !mesh.is_boundary_halfedge(h ^ 1);
            if interior && sharp.get(h as usize / 2).copied().unwrap_or(false) {
                if count < 2 {
                    ends[count] = mesh.positions[mesh.tip(h) as usize];
                }
                count += 1;
            }
        }
        match (boundary, count) {
            (true, 0) => Vertex::Boundary,
            (true, _) | (false, 3..) => Vertex::Corner,
            (false, 2) => Vertex::Crease(ends[0], ends[1]),
            (false, _) => Vertex::Smooth,
        }
    }
}

/// [`subdivide`] with infinitely sharp interior edges (`sharp[e]` for edge
/// `e`, see the module docs); returns the new mesh and its sharp edges.
pub fn subdivide_creased(
    mesh: &PolyMesh,
    rule: BoundaryRule,
    sharp: &[bool],
) -> (PolyMesh, Vec<bool>) {
    let nv = mesh.vertex_count();
    let ne = mesh.edge_count();
    let nf = mesh.face_count();
    let p = &mesh.positions;

    let face_points: Vec<DVec3> = (0..nf as u32).map(|f| face_point(mesh, f)).collect();
    let mut positions = Vec::with_capacity(nv + ne + nf);
    for v in 0..nv as u32 {
        positions.push(vertex_point(mesh, v, &face_points, rule, sharp));
    }
    for e in 0..ne as u32 {
        let h = 2 * e;
        let (a, b) = (p[mesh.origin(h) as usize], p[mesh.tip(h) as usize]);
        let (f1, f2) = (mesh.face(h), mesh.face(h ^ 1));
        positions.push(
            if mesh.is_boundary_halfedge(h)
                || mesh.is_boundary_halfedge(h ^ 1)
                || sharp.get(e as usize).copied().unwrap_or(false)
            {
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
    let new = PolyMesh::from_faces(positions, &faces).expect("Catmull–Clark step of a valid mesh");
    let mut new_sharp = Vec::new();
    if sharp.iter().any(|&s| s) {
        // A new edge is half of an old sharp edge when it joins an old
        // vertex (index < nv) to that edge's point (nv + e).
        new_sharp = (0..new.edge_count() as u32)
            .map(|e| {
                let (x, y) = (new.origin(2 * e) as usize, new.tip(2 * e) as usize);
                let (old, mid) = (x.min(y), x.max(y));
                old < nv && (nv..nv + ne).contains(&mid) && sharp.get(mid - nv) == Some(&true)
            })
            .collect();
    }
    (new, new_sharp)
}

/// `levels` Catmull–Clark steps (`levels == 0` returns a copy).
pub fn subdivide_levels(mesh: &PolyMesh, levels: u32, rule: BoundaryRule) -> PolyMesh {
    let mut m = mesh.clone();
    for _ in 0..levels {
        m = subdivide(&m, rule);
    }
    m
}

fn vertex_point(
    mesh: &PolyMesh,
    v: u32,
    face_points: &[DVec3],
    rule: BoundaryRule,
    sharp: &[bool],
) -> DVec3 {
    let p = mesh.positions[v as usize];
    match Vertex::of(mesh, v, sharp) {
        Vertex::Boundary => {
            return match rule {
                BoundaryRule::Fixed => p,
                BoundaryRule::Crease => {
                    let (prev, next) = boundary_neighbours(mesh, v);
                    (prev + 6.0 * p + next) / 8.0
                }
            };
        }
        Vertex::Corner => return p,
        Vertex::Crease(a, b) => return (a + 6.0 * p + b) / 8.0,
        Vertex::Smooth => {}
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
