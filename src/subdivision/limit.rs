//! Limit positions and limit normals of Catmull–Clark control vertices
//! (Kloiber 2018 §3.8; stencils of Halstead, Kass and DeRose 1993).
//!
//! Limit position of an interior vertex `v` of valence `n` whose faces are
//! all quads, with edge neighbours `eⱼ` and diagonal ("opposite") vertices
//! `gⱼ` (Kloiber's equation in §3.8):
//!
//! ```text
//! v∞ = (n² v + 4 Σ eⱼ + Σ gⱼ) / (n (n + 5))
//! ```
//!
//! Limit tangents (Halstead et al. 1993, §A; the same masks appear in Loop
//! and Schaefer 2008), with `gⱼ` the diagonal vertex between `eⱼ` and
//! `eⱼ₊₁`, `θⱼ = 2πj/n` and `Aₙ = 1 + cos(2π/n) + cos(π/n) √(2 (9 + cos(2π/n)))`:
//!
//! ```text
//! t₁ = Σ Aₙ cos θⱼ eⱼ + (cos θⱼ + cos θⱼ₊₁) gⱼ
//! t₂ = Σ Aₙ sin θⱼ eⱼ + (sin θⱼ + sin θⱼ₊₁) gⱼ
//! ```
//!
//! and the limit normal is their cross product (for n = 4 these are the
//! uniform bicubic B-spline's derivatives, up to scale).
//!
//! Deviations and extensions:
//! - a vertex with a non-quad face in its one-ring is handled exactly by
//!   one *local* Catmull–Clark step (vertex point, edge points, face points
//!   of its ring): the limit of a vertex equals the limit of its vertex
//!   point, whose ring is all quads;
//! - boundary vertices: with [`BoundaryRule::Fixed`] the limit is the vertex
//!   itself, with [`BoundaryRule::Crease`] the cubic B-spline limit
//!   `(p₋ + 4p + p₊)/6`; their normal is the area-weighted mean of the
//!   adjacent face normals (an approximation; the fitting never moves them);
//! - sharp edges (see [`super::catmull_clark`]): a crease vertex's limit is
//!   the cubic B-spline limit `(a + 4v + b)/6` of its crease curve, a
//!   corner's is the vertex itself; a smooth vertex has no sharp edge in
//!   its ring's rules, so its stencil is exact; a dart (one sharp edge)
//!   uses the smooth stencil, an approximation.

use std::f64::consts::{PI, TAU};

use glam::DVec3;

use super::catmull_clark::{Vertex, boundary_neighbours, subdivide_creased};
use super::{BoundaryRule, face_normal, face_point};
use crate::mesh::PolyMesh;
use crate::progress::Cancelled;

/// The one-ring of an interior vertex in a quad neighbourhood: the centre,
/// its edge neighbours `e[j]` (in the order of [`PolyMesh::outgoing`]) and
/// `g[j]`, the diagonal vertex of the quad between `e[j-1]` and `e[j]`.
struct QuadRing {
    v: DVec3,
    e: Vec<DVec3>,
    g: Vec<DVec3>,
}

impl QuadRing {
    /// The ring of `v`, or `None` on a boundary.
    fn of(mesh: &PolyMesh, v: u32) -> Option<QuadRing> {
        if mesh.is_boundary_vertex(v) {
            return None;
        }
        let p = &mesh.positions;
        let all_quads = mesh.outgoing(v).all(|h| mesh.degree(mesh.face(h)) == 4);
        if all_quads {
            let mut ring = QuadRing {
                v: p[v as usize],
                e: Vec::new(),
                g: Vec::new(),
            };
            for h in mesh.outgoing(v) {
                ring.e.push(p[mesh.tip(h) as usize]);
                // Quad (v, eⱼ, g, eⱼ₋₁): g is two steps along the face.
                ring.g.push(p[mesh.tip(mesh.next(h)) as usize]);
            }
            return Some(ring);
        }
        // One local Catmull–Clark step: face points Fⱼ of face(hⱼ), edge
        // points Eⱼ of the edge hⱼ (between faces hⱼ and hⱼ₊₁), and the
        // vertex point; in the subdivided mesh the quad between Eⱼ₋₁ and
        // Eⱼ has diagonal Fⱼ.
        let hs: Vec<u32> = mesh.outgoing(v).collect();
        let n = hs.len();
        let f: Vec<DVec3> = hs.iter().map(|&h| face_point(mesh, mesh.face(h))).collect();
        let pv = p[v as usize];
        let mut e = Vec::with_capacity(n);
        let mut sum = DVec3::ZERO;
        for j in 0..n {
            let tip = p[mesh.tip(hs[j]) as usize];
            sum += tip + f[j];
            e.push(0.25 * (pv + tip + f[j] + f[(j + 1) % n]));
        }
        let nf = n as f64;
        Some(QuadRing {
            v: ((nf - 2.0) * pv + sum / nf) / nf,
            e,
            g: f,
        })
    }

    fn limit(&self) -> DVec3 {
        let n = self.e.len() as f64;
        let se: DVec3 = self.e.iter().sum();
        let sg: DVec3 = self.g.iter().sum();
        (n * n * self.v + 4.0 * se + sg) / (n * (n + 5.0))
    }

    /// Unnormalised limit normal, pointing to the side faces are
    /// counter-clockwise from.
    fn normal(&self) -> DVec3 {
        let n = self.e.len();
        let nf = n as f64;
        let c = (TAU / nf).cos();
        let a = 1.0 + c + (PI / nf).cos() * (2.0 * (9.0 + c)).sqrt();
        let (mut t1, mut t2) = (DVec3::ZERO, DVec3::ZERO);
        for j in 0..n {
            let (s0, c0) = (TAU * j as f64 / nf).sin_cos();
            let (s1, c1) = (TAU * (j + 1) as f64 / nf).sin_cos();
            // The diagonal between eⱼ and eⱼ₊₁ is g[j + 1].
            let g = self.g[(j + 1) % n];
            t1 += a * c0 * self.e[j] + (c0 + c1) * g;
            t2 += a * s0 * self.e[j] + (s0 + s1) * g;
        }
        // `outgoing` turns clockwise seen from the side the faces are
        // counter-clockwise from, so t₂ × t₁ points out.
        t2.cross(t1)
    }
}

/// Limit position of every vertex of `mesh` (see the module docs).
pub fn limit_positions(mesh: &PolyMesh, rule: BoundaryRule) -> Vec<DVec3> {
    limit_positions_creased(mesh, rule, &[])
}

/// [`limit_positions`] with sharp edges (`sharp[e]` for edge `e`).
pub fn limit_positions_creased(mesh: &PolyMesh, rule: BoundaryRule, sharp: &[bool]) -> Vec<DVec3> {
    (0..mesh.vertex_count() as u32)
        .map(|v| match Vertex::of(mesh, v, sharp) {
            Vertex::Corner => mesh.positions[v as usize],
            Vertex::Crease(a, b) => (a + 4.0 * mesh.positions[v as usize] + b) / 6.0,
            Vertex::Boundary | Vertex::Smooth => limit_position(mesh, v, rule),
        })
        .collect()
}

fn limit_position(mesh: &PolyMesh, v: u32, rule: BoundaryRule) -> DVec3 {
    if let Some(ring) = QuadRing::of(mesh, v) {
        return ring.limit();
    }
    let p = mesh.positions[v as usize];
    match rule {
        BoundaryRule::Fixed => p,
        BoundaryRule::Crease => {
            let (prev, next) = boundary_neighbours(mesh, v);
            (prev + 4.0 * p + next) / 6.0
        }
    }
}

/// Unit limit normal of every vertex of `mesh`, on the side its faces are
/// counter-clockwise from (outwards for a closed, outward-oriented mesh).
/// Zero where the tangents are degenerate.
pub fn limit_normals(mesh: &PolyMesh) -> Vec<DVec3> {
    (0..mesh.vertex_count() as u32)
        .map(|v| match QuadRing::of(mesh, v) {
            Some(ring) => ring.normal().normalize_or_zero(),
            None => mesh
                .outgoing(v)
                .filter(|&h| !mesh.is_boundary_halfedge(h))
                .map(|h| face_normal(mesh, mesh.face(h)))
                .sum::<DVec3>()
                .normalize_or_zero(),
        })
        .collect()
}

/// The limit surface sampled: `levels` Catmull–Clark steps of `control`,
/// then every vertex moved to its limit position. `levels = 0` puts the
/// control mesh's own vertices on the limit surface.
pub fn limit_mesh(control: &PolyMesh, levels: u32, rule: BoundaryRule) -> PolyMesh {
    limit_mesh_with_progress(control, &[], levels, rule, &mut |_| Ok(()))
        .expect("a sink that never cancels")
}

/// [`limit_mesh`] of a control mesh with sharp edges (`sharp[e]` for edge `e`).
pub fn limit_mesh_creased(
    control: &PolyMesh,
    sharp: &[bool],
    levels: u32,
    rule: BoundaryRule,
) -> PolyMesh {
    limit_mesh_with_progress(control, sharp, levels, rule, &mut |_| Ok(()))
        .expect("a sink that never cancels")
}

/// [`limit_mesh`], calling `between(done)` before each subdivision step and
/// before the limit positions (`done` = steps finished / (levels + 1)).
pub fn limit_mesh_with_progress(
    control: &PolyMesh,
    sharp: &[bool],
    levels: u32,
    rule: BoundaryRule,
    between: &mut dyn FnMut(f32) -> Result<(), Cancelled>,
) -> Result<PolyMesh, Cancelled> {
    let mut m = control.clone();
    let mut sharp = sharp.to_vec();
    for l in 0..levels {
        between(l as f32 / (levels + 1) as f32)?;
        (m, sharp) = subdivide_creased(&m, rule, &sharp);
    }
    between(levels as f32 / (levels + 1) as f32)?;
    m.positions = limit_positions_creased(&m, rule, &sharp);
    Ok(m)
}
