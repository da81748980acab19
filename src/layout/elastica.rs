//! The elastica graph g′ of Campen & Kobbelt 2014, §5.3 (curved edges),
//! §5.5 (principal direction alignment) and §5.6/§5.7 (feature curves and
//! boundaries crossed orthogonally).
//!
//! A g′-node is a directed g-edge (its midpoint and direction); a g′-arc joins
//! `e0 = (u → v)` to `e1 = (v → w)` when the geodesic turning angle γ at `v`
//! is at most 30°. Its weight is `w = |e′| + α q(e′) + β κ²(e′)` with
//! `|e′| = γ m / (2 tan(γ/2)) + ||e0| − |e1||/2`, `κ² = γ²/m`,
//! `m = min(|e0|, |e1|)`, and `q(e′) = ½(q_{n0}(e0) + q_{n1}(e1)) |e′|`.
//!
//! Deviations:
//! - Arcs are implicit: g-edges at each vertex are sorted by angle, so a
//!   node's successors are one cyclic range (first index + count per node)
//!   and the arc weight is evaluated on the fly from per-node data. This keeps
//!   g′ at ~40 bytes per node instead of ~10 stored arcs per node.
//! - `q_n(e)` at the edge midpoint is the mean of `q` at both end vertices
//!   with the edge's tangent there (the principal frame lives at vertices).
//! - The anisotropy weight `(|κmin| − |κmax|)²` is capped at
//!   `max_alignment_weight` (noisy scans have huge curvature spikes).
//! - Feature curves (dihedral angle above `feature_angle`) and boundaries use
//!   `dev = |⟨t, f⊥⟩|⁻¹ − 1` (f the feature/boundary tangent, f⊥ = n × f,
//!   i.e. §5.6's d_max across the feature) with the constant weight
//!   `feature_weight`, since a flat boundary has no anisotropy to weight it.
//!   The reciprocal is clamped at 1/0.05 so the weight stays finite.
//! - `|e′|/(2 tan(γ/2))`-factor uses its Taylor series (γ ≤ 30°, error < 1e-4).

use glam::{DVec3, Vec3};
use serde::{Deserialize, Serialize};

use super::surface_graph::{SurfaceGraph, wrap_angle};
use crate::analysis::curvature::{CurvatureParams, principal_curvatures};
use crate::mesh::VertexAdjacency;

/// Parameters of the elastica graph (defaults from the paper, §5 and §8).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct ElasticaParams {
    /// k: g joins vertices within this graph distance. Default 4.
    pub rings: u32,
    /// Maximal turning angle of a g′-arc, degrees. Default 30.
    pub max_turn_degrees: f64,
    /// α: weight of principal-direction alignment. Default 1.
    pub alpha: f64,
    /// β: weight of bending energy. Default 0.25.
    pub beta: f64,
    /// Cap of the anisotropy weight `(|κmin| − |κmax|)²` (normalised units).
    /// Default 1e4.
    pub max_alignment_weight: f64,
    /// Dihedral angle (degrees) above which a mesh edge is a feature curve.
    /// Default 40.
    pub feature_angle_degrees: f64,
    /// Alignment weight on feature curves and boundaries (§5.6, §5.7).
    /// Default 100.
    pub feature_weight: f64,
}

impl Default for ElasticaParams {
    fn default() -> Self {
        ElasticaParams {
            rings: 4,
            max_turn_degrees: 30.0,
            alpha: 1.0,
            beta: 0.25,
            max_alignment_weight: 1e4,
            feature_angle_degrees: 40.0,
            feature_weight: 100.0,
        }
    }
}

/// g′ over a [`SurfaceGraph`]: per-node data for implicit arcs.
#[derive(Debug, Clone, Default)]
pub struct ElasticaGraph {
    pub g: SurfaceGraph,
    /// `q_n(e)` of every node (alignment penalty density at its midpoint).
    pub q: Vec<f32>,
    /// First successor (absolute g-edge index, within the head's out-row).
    pub succ_first: Vec<u32>,
    /// Number of successors (cyclic within the head's out-row).
    pub succ_count: Vec<u8>,
    /// Vertex positions in `f32` (normalised units): node midpoints are
    /// computed from them (12 bytes per vertex instead of per node).
    pub position: Vec<Vec3>,
    /// Per vertex: the feature/boundary tangent, zero where none.
    pub feature_tangent: Vec<DVec3>,
    pub alpha: f32,
    pub beta: f32,
    pub max_turn: f32,
}

impl ElasticaGraph {
    pub fn new(g: SurfaceGraph, params: &ElasticaParams) -> ElasticaGraph {
        let n = g.vertex_count();
        let mesh = &g.mesh;
        let adjacency = VertexAdjacency::new(mesh);
        let curvature = principal_curvatures(
            &mesh.positions,
            &g.normals,
            &adjacency,
            &CurvatureParams::default(),
        );
        let feature_tangent = feature_tangents(&g, params.feature_angle_degrees);
        let max_w = params.max_alignment_weight.max(0.0);
        let q_at = |v: usize, t: DVec3| -> f64 {
            let f = feature_tangent[v];
            if f != DVec3::ZERO {
                let across = g.normals[v].cross(f).normalize_or_zero();
                let c = t.dot(across).abs().max(0.05);
                return params.feature_weight * (1.0 / c - 1.0);
            }
            let Some(pc) = curvature.get(v) else {
                return 0.0;
            };
            let weight = ((pc.k1.abs() - pc.k2.abs()).powi(2)).min(max_w);
            if weight.is_nan() || weight <= 0.0 {
                return 0.0;
            }
            let c = t.dot(pc.d1).abs().max(t.dot(pc.d2).abs()).max(0.05);
            weight * (1.0 / c - 1.0).max(0.0)
        };
        let edges = g.edge_count();
        let mut q = Vec::with_capacity(edges);
        for e in 0..edges {
            let (v, w) = (g.source[e] as usize, g.target[e] as usize);
            let qv = q_at(v, g.direction_out(e));
            let qw = q_at(w, g.direction_in(e));
            q.push((0.5 * (qv + qw)) as f32);
        }
        let position: Vec<Vec3> = mesh.positions.iter().map(|p| p.as_vec3()).collect();
        let max_turn = (params.max_turn_degrees.clamp(1.0, 90.0)).to_radians() as f32;
        let mut succ_first = vec![0u32; edges];
        let mut succ_count = vec![0u8; edges];
        for e in 0..edges {
            let w = g.target[e] as usize;
            let row = g.out_edges(w);
            if row.is_empty() {
                succ_first[e] = row.start as u32;
                continue;
            }
            let angles = &g.angle_out[row.clone()];
            let lo = (g.angle_in[e] - max_turn).rem_euclid(std::f32::consts::TAU);
            let mut i0 = angles.partition_point(|&a| a < lo);
            if i0 == angles.len() {
                i0 = 0;
            }
            let mut count = 0usize;
            while count < angles.len() && count < 255 {
                let a = angles[(i0 + count) % angles.len()];
                let off = (a - lo).rem_euclid(std::f32::consts::TAU);
                if off > 2.0 * max_turn {
                    break;
                }
                count += 1;
            }
            succ_first[e] = (row.start + i0) as u32;
            succ_count[e] = count as u8;
        }
        let _ = n;
        ElasticaGraph {
            g,
            q,
            succ_first,
            succ_count,
            position,
            feature_tangent,
            alpha: params.alpha as f32,
            beta: params.beta as f32,
            max_turn,
        }
    }

    /// Midpoint of node `e` (normalised units).
    #[inline]
    pub fn midpoint(&self, e: usize) -> Vec3 {
        let (v, w) = (self.g.source[e] as usize, self.g.target[e] as usize);
        0.5 * (self.position[v] + self.position[w])
    }

    /// Number of g′-nodes.
    pub fn node_count(&self) -> usize {
        self.q.len()
    }

    /// Calls `f(b)` for every successor node `b` of node `a`.
    #[inline]
    pub fn for_each_successor(&self, a: usize, mut f: impl FnMut(usize)) {
        let w = self.g.target[a] as usize;
        let start = self.g.offsets[w] as usize;
        let len = self.g.offsets[w + 1] as usize - start;
        if len == 0 {
            return;
        }
        let first = self.succ_first[a] as usize - start;
        for i in 0..self.succ_count[a] as usize {
            f(start + (first + i) % len);
        }
    }

    /// Whether `a → b` is a g′-arc.
    pub fn is_arc(&self, a: usize, b: usize) -> bool {
        self.g.target[a] == self.g.source[b]
            && self.g.target[b] != self.g.source[a]
            && self.turn(a, b).abs() <= self.max_turn + 1e-6
    }

    /// Signed geodesic turning angle γ from `a` to `b` at their common vertex.
    #[inline]
    pub fn turn(&self, a: usize, b: usize) -> f32 {
        wrap_angle(self.g.angle_out[b] - self.g.angle_in[a])
    }

    /// The weight `w(e′)` of the arc `a → b` (§5.3, equation 2).
    #[inline]
    pub fn arc_weight(&self, a: usize, b: usize) -> f32 {
        let gamma = self.turn(a, b).abs();
        self.weight(
            gamma,
            self.g.length[a],
            self.g.length[b],
            self.q[a],
            self.q[b],
        )
    }

    /// `w(e′)` from the turning angle γ, the lengths and the `q_n` of both
    /// nodes.
    #[inline(always)]
    fn weight(&self, gamma: f32, la: f32, lb: f32, qa: f32, qb: f32) -> f32 {
        let m = la.min(lb).max(1e-9);
        let g2 = gamma * gamma;
        // γ / (2 tan(γ/2)) = 1 − γ²/12 − γ⁴/720 − …
        let shrink = 1.0 - g2 / 12.0 - g2 * g2 / 720.0;
        let len = m * shrink + 0.5 * (la - lb).abs();
        let q = 0.5 * (qa + qb) * len;
        len + self.alpha * q + self.beta * g2 / m
    }

    /// Calls `f(b, w(a → b))` for every successor node `b` of node `a`
    /// (the same values as [`Self::arc_weight`], with `a`'s data loaded once).
    #[inline(always)]
    pub fn for_each_arc(&self, a: usize, mut f: impl FnMut(usize, f32)) {
        let g = &self.g;
        let w = g.target[a] as usize;
        let start = g.offsets[w] as usize;
        let len = g.offsets[w + 1] as usize - start;
        if len == 0 {
            return;
        }
        let (angle_in, la, qa) = (g.angle_in[a], g.length[a], self.q[a]);
        let mut i = self.succ_first[a] as usize - start;
        for _ in 0..self.succ_count[a] {
            let b = start + i;
            let gamma = wrap_angle(g.angle_out[b] - angle_in).abs();
            f(b, self.weight(gamma, la, g.length[b], qa, self.q[b]));
            i += 1;
            if i == len {
                i = 0;
            }
        }
    }

    /// Bytes held by g and g′ (excluding the mesh copy).
    pub fn memory_bytes(&self) -> usize {
        self.g.memory_bytes()
            + self.q.len() * (4 + 4 + 1)
            + self.position.len() * 12
            + self.feature_tangent.len() * 24
    }
}

/// Per vertex the tangent of the feature curve or boundary through it (zero
/// where there is none, or at corners where more than two meet).
fn feature_tangents(g: &SurfaceGraph, feature_angle_degrees: f64) -> Vec<DVec3> {
    let mesh = &g.mesh;
    let n = mesh.vertex_count();
    let face_normals: Vec<DVec3> = (0..mesh.face_count())
        .map(|f| mesh.face_normal_unnormalized(f))
        .collect();
    let mut sum = vec![DVec3::ZERO; n];
    let mut count = vec![0u8; n];
    for e in
        crate::mesh::EdgeTopology::sharp_edges(mesh, &face_normals, feature_angle_degrees, true)
    {
        let (a, b) = (e.a as usize, e.b as usize);
        let d = (mesh.positions[b] - mesh.positions[a]).normalize_or_zero();
        for v in [a, b] {
            let s = if sum[v].dot(d) < 0.0 { -d } else { d };
            sum[v] += s;
            count[v] = count[v].saturating_add(1);
        }
    }
    (0..n)
        .map(|v| {
            if count[v] == 0 || count[v] > 2 {
                return DVec3::ZERO;
            }
            let nv = g.normals[v];
            (sum[v] - nv * sum[v].dot(nv)).normalize_or_zero()
        })
        .collect()
}
