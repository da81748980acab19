//! The surface graph g of Campen & Kobbelt 2014, *Dual Strip Weaving*,
//! §5.3: every vertex of the triangulation is joined to every vertex within
//! graph distance k (default 4) by two directed edges, each realised as an
//! approximate geodesic with a length and a tangent direction at both ends.
//!
//! Deviations (documented choices of this implementation):
//! - The geodesic of a g-edge `v → w` is approximated by the chord
//!   `p_w − p_v`: its tangent at `v` (at `w`) is the chord projected into the
//!   tangent plane of `v` (of `w`), and its length is the chord length
//!   corrected as if the chord subtended a circular arc whose end normals are
//!   the vertex normals (`|c| · (θ/2) / sin(θ/2)`, θ the angle between the
//!   normals; exact on spheres and cylinders). A Dijkstra path over mesh
//!   edges would quantise the directions to the 1-ring's, which defeats the
//!   purpose of k = 4 (angular resolution).
//! - The mesh is normalised to bounding-box diagonal 1 (centre at the origin)
//!   so that every weight parameter is model independent.
//! - Out-edges of each vertex are sorted by their tangent angle in a per-vertex
//!   frame, so the elastica graph's successors of a g-edge are one cyclic
//!   range of its head's out-edges (nothing per g'-arc is stored).

use glam::DVec3;

use crate::analysis::normals::{NormalWeighting, vertex_normals};
use crate::mesh::{RingCollector, TriMesh, VertexAdjacency, boundary_vertices};

/// The surface graph g in compact CSR form. All positions are normalised
/// (bounding-box diagonal 1); `to_world` maps back.
#[derive(Debug, Clone, Default)]
pub struct SurfaceGraph {
    /// Centre of the input's bounding box (world units).
    pub center: DVec3,
    /// World length of one normalised unit (the bbox diagonal).
    pub diagonal: f64,
    /// The normalised mesh (positions `(p − center) / diagonal`).
    pub mesh: TriMesh,
    /// Unit vertex normals of the normalised mesh (+z where undefined).
    pub normals: Vec<DVec3>,
    /// Per-vertex tangent frame `(u, v)` with `u × v = n`.
    pub frame_u: Vec<DVec3>,
    pub frame_v: Vec<DVec3>,
    /// Vertices on a boundary edge.
    pub boundary: Vec<bool>,
    /// CSR offsets: the out-edges of vertex `v` are `offsets[v]..offsets[v+1]`,
    /// sorted by `angle_out`.
    pub offsets: Vec<u32>,
    /// Tail vertex of every directed g-edge.
    pub source: Vec<u32>,
    /// Head vertex of every directed g-edge.
    pub target: Vec<u32>,
    /// The opposite directed g-edge.
    pub reverse: Vec<u32>,
    /// Approximate geodesic length (normalised units).
    pub length: Vec<f32>,
    /// Tangent angle of the edge at its tail, in the tail's frame, [0, 2π).
    pub angle_out: Vec<f32>,
    /// Tangent angle of the (arriving) edge at its head, in the head's frame.
    pub angle_in: Vec<f32>,
}

impl SurfaceGraph {
    /// Builds g for `rings` = k (clamped to 1..=8).
    pub fn new(mesh: &TriMesh, rings: u32) -> SurfaceGraph {
        let rings = rings.clamp(1, 8);
        let (center, diagonal) = match mesh.bbox() {
            Some(b) if b.diagonal() > 0.0 && b.diagonal().is_finite() => (b.center(), b.diagonal()),
            Some(b) => (b.center(), 1.0),
            None => (DVec3::ZERO, 1.0),
        };
        let mut local = mesh.clone();
        local.map_positions(|p| (p - center) / diagonal);
        let n = local.vertex_count();
        let normals: Vec<DVec3> = vertex_normals(&local, NormalWeighting::Angle)
            .into_iter()
            .map(|v| v.try_normalize().unwrap_or(DVec3::Z))
            .collect();
        let mut frame_u = Vec::with_capacity(n);
        let mut frame_v = Vec::with_capacity(n);
        for &nv in &normals {
            let (u, v) = nv.any_orthonormal_pair();
            frame_u.push(u);
            frame_v.push(v);
        }
        let boundary = boundary_vertices(&local);
        let adjacency = VertexAdjacency::new(&local);
        let mut rc = RingCollector::new(n);
        let mut ring = Vec::new();
        let mut row: Vec<(f32, u32, f32, f32)> = Vec::new();
        let mut offsets = Vec::with_capacity(n + 1);
        offsets.push(0u32);
        let mut source = Vec::new();
        let mut target = Vec::new();
        let mut length = Vec::new();
        let mut angle_out = Vec::new();
        let mut angle_in = Vec::new();
        let p = &local.positions;
        for v in 0..n {
            rc.collect(&adjacency, v, rings, &mut ring);
            row.clear();
            for &w in &ring {
                let w = w as usize;
                let c = p[w] - p[v];
                let cl = c.length();
                if cl.is_nan() || cl <= 1e-12 {
                    continue;
                }
                let tv = c - normals[v] * c.dot(normals[v]);
                let tw = c - normals[w] * c.dot(normals[w]);
                // Symmetric in (v, w): both projections must be usable.
                if tv.length() < 1e-6 * cl || tw.length() < 1e-6 * cl {
                    continue;
                }
                let theta = normals[v].angle_between(normals[w]).min(3.0);
                let arc = if theta > 1e-6 {
                    (0.5 * theta) / (0.5 * theta).sin()
                } else {
                    1.0
                };
                let a_out = angle_in_frame(tv, frame_u[v], frame_v[v]);
                let a_in = angle_in_frame(tw, frame_u[w], frame_v[w]);
                row.push((a_out, w as u32, (cl * arc) as f32, a_in));
            }
            row.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            for &(a_out, w, len, a_in) in &row {
                source.push(v as u32);
                target.push(w);
                length.push(len);
                angle_out.push(a_out);
                angle_in.push(a_in);
            }
            offsets.push(target.len() as u32);
        }
        let mut reverse = vec![u32::MAX; target.len()];
        for e in 0..target.len() {
            let (v, w) = (source[e], target[e] as usize);
            let (s, t) = (offsets[w] as usize, offsets[w + 1] as usize);
            if let Some(i) = (s..t).find(|&i| target[i] == v) {
                reverse[e] = i as u32;
            }
        }
        SurfaceGraph {
            center,
            diagonal,
            mesh: local,
            normals,
            frame_u,
            frame_v,
            boundary,
            offsets,
            source,
            target,
            reverse,
            length,
            angle_out,
            angle_in,
        }
    }

    pub fn vertex_count(&self) -> usize {
        self.offsets.len().saturating_sub(1)
    }

    /// Number of directed g-edges (= elastica-graph nodes).
    pub fn edge_count(&self) -> usize {
        self.target.len()
    }

    /// Out-edge index range of vertex `v`.
    pub fn out_edges(&self, v: usize) -> std::ops::Range<usize> {
        if v + 1 >= self.offsets.len() {
            return 0..0;
        }
        self.offsets[v] as usize..self.offsets[v + 1] as usize
    }

    /// Unit tangent (3D, normalised frame) of g-edge `e` at its tail.
    pub fn direction_out(&self, e: usize) -> DVec3 {
        let v = self.source[e] as usize;
        let a = self.angle_out[e] as f64;
        self.frame_u[v] * a.cos() + self.frame_v[v] * a.sin()
    }

    /// Unit tangent (3D) of g-edge `e` where it arrives at its head.
    pub fn direction_in(&self, e: usize) -> DVec3 {
        let w = self.target[e] as usize;
        let a = self.angle_in[e] as f64;
        self.frame_u[w] * a.cos() + self.frame_v[w] * a.sin()
    }

    /// Angle of a tangent vector `t` at vertex `v`, in [0, 2π).
    pub fn angle_at(&self, v: usize, t: DVec3) -> f32 {
        angle_in_frame(t, self.frame_u[v], self.frame_v[v])
    }

    pub fn to_world(&self, p: DVec3) -> DVec3 {
        p * self.diagonal + self.center
    }

    pub fn to_local(&self, p: DVec3) -> DVec3 {
        (p - self.center) / self.diagonal
    }

    /// Bytes held by the graph arrays (excluding the mesh copy).
    pub fn memory_bytes(&self) -> usize {
        let e = self.target.len();
        let n = self.normals.len();
        e * (4 * 6) + self.offsets.len() * 4 + n * (3 * 24 + 1)
    }
}

/// Angle of `t` in the frame `(u, v)`, in [0, 2π).
// Not `clamp`: a NaN angle maps to the top of the range here.
#[allow(clippy::manual_clamp)]
pub(crate) fn angle_in_frame(t: DVec3, u: DVec3, v: DVec3) -> f32 {
    let a = t.dot(v).atan2(t.dot(u));
    let a = if a < 0.0 {
        a + std::f64::consts::TAU
    } else {
        a
    };
    (a as f32).min(std::f32::consts::TAU - 1e-7).max(0.0)
}

/// Signed difference `a − b` wrapped to (−π, π].
#[inline]
pub(crate) fn wrap_angle(d: f32) -> f32 {
    use std::f32::consts::{PI, TAU};
    // The float remainder is slow; differences of two angles in [0, 2π)
    // need none.
    let mut d = if d.abs() < TAU { d } else { d % TAU };
    if d > PI {
        d -= TAU;
    } else if d <= -PI {
        d += TAU;
    }
    d
}
