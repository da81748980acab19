//! Curvature averaging (Kloiber thesis 3.1.3).
//!
//! For `iterations` rounds, every vertex v takes
//! `curv_new(v) = λ·curv_old(v) + (1 − λ)/W · Σ_x w_x(v)·curv_old(x)` over the
//! vertices x of its n-ring, `W = Σ_x w_x(v)`, with the weights
//! - simple: `w = 1`;
//! - similarity-based (Eq. 3.4): `w = 1 / ((k·|c(v) − c(x)|)² + 0.01)`, k = 2;
//! - expand high curvature (Eq. 3.5): `w = C` if `c(x) < B`, else
//!   `1 − (1 − (c(x) − B)/(1 − B))²·(1 − C)`, B = 0.005, C = 0.3.
//!
//! Decisions where the thesis is vague:
//! - Values are made absolute first (the thesis' Fig. 3.4 argument), so the
//!   output is non-negative.
//! - The normalised curvature `c ∈ [0, 1]` of Eq. 3.4 and 3.5 is the value
//!   divided by the largest value of the field, recomputed at the start of
//!   every iteration (the thesis normalises by the largest curvature; B was
//!   chosen for that normalisation).
//! - In Eq. 3.5 the weight of neighbour x depends on x's own curvature (high
//!   curvature neighbours pull harder, which is what "expands" them).
//! - The neighbourhood excludes v itself; v enters only through λ. A vertex
//!   without neighbours, or whose weights sum to zero, keeps its value.
//! - Updates are Jacobi-style (all vertices read the previous iteration), so
//!   the result does not depend on vertex order.

use serde::{Deserialize, Serialize};

use crate::mesh::{Csr, RingCollector, VertexAdjacency};

/// The averaging weights.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AveragingMethod {
    /// No averaging; values are only made absolute.
    None,
    /// All neighbours weigh 1.
    #[default]
    Simple,
    /// Eq. 3.4: neighbours of similar curvature weigh more.
    SimilarityBased,
    /// Eq. 3.5: high-curvature neighbours weigh more.
    ExpandHighCurvature,
}

/// Parameters of the curvature averaging. Defaults follow the thesis'
/// recommendation (chapter 4: simple average, 1–3 iterations, self-weight
/// 0–0.5, 1- or 2-ring).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct AveragingParams {
    /// Default [`AveragingMethod::Simple`].
    pub method: AveragingMethod,
    /// Number of rounds. Default 2.
    pub iterations: u32,
    /// Damping (self-weight) λ ∈ [0, 1] (clamped). Default 0.25.
    pub damping: f64,
    /// Neighbourhood size in rings, 1–5 (clamped). Default 1.
    pub rings: u32,
    /// k of Eq. 3.4. Default 2.
    pub similarity_k: f64,
    /// Breakpoint B of Eq. 3.5, in normalised curvature. Default 0.005.
    pub expand_breakpoint: f64,
    /// Constant weight C of Eq. 3.5 below the breakpoint. Default 0.3.
    pub expand_constant: f64,
}

impl Default for AveragingParams {
    fn default() -> Self {
        AveragingParams {
            method: AveragingMethod::Simple,
            iterations: 2,
            damping: 0.25,
            rings: 1,
            similarity_k: 2.0,
            expand_breakpoint: 0.005,
            expand_constant: 0.3,
        }
    }
}

/// The n-ring of every vertex (excluding the vertex), as rows.
pub fn ring_neighbourhoods(adjacency: &VertexAdjacency, rings: u32) -> Csr {
    let count = adjacency.vertex_count();
    if rings <= 1 {
        return adjacency.csr().clone();
    }
    let mut collector = RingCollector::new(count);
    let mut ring = Vec::new();
    let mut offsets = Vec::with_capacity(count + 1);
    let mut items = Vec::new();
    offsets.push(0u32);
    for v in 0..count {
        collector.collect(adjacency, v, rings, &mut ring);
        ring.sort_unstable();
        items.extend_from_slice(&ring);
        offsets.push(items.len() as u32);
    }
    Csr { offsets, items }
}

/// Eq. 3.5: the weight of a neighbour with normalised curvature `c`.
pub fn expand_high_curvature_weight(c: f64, breakpoint: f64, constant: f64) -> f64 {
    if c < breakpoint || breakpoint >= 1.0 {
        constant
    } else {
        let t = 1.0 - (c - breakpoint) / (1.0 - breakpoint);
        1.0 - t * t * (1.0 - constant)
    }
}

/// Eq. 3.4: the weight between normalised curvatures `cv` and `cx`.
pub fn similarity_weight(cv: f64, cx: f64, k: f64) -> f64 {
    let d = k * (cv - cx).abs();
    1.0 / (d * d + 0.01)
}

/// Averages the absolute values of a per-vertex field (one value per vertex
/// of `adjacency`; extra values are returned unchanged in absolute value).
pub fn average_curvature(
    values: &[f64],
    adjacency: &VertexAdjacency,
    params: &AveragingParams,
) -> Vec<f64> {
    let mut current: Vec<f64> = values
        .iter()
        .map(|v| if v.is_finite() { v.abs() } else { 0.0 })
        .collect();
    if params.method == AveragingMethod::None || params.iterations == 0 {
        return current;
    }
    let neighbourhoods = ring_neighbourhoods(adjacency, params.rings.clamp(1, 5));
    let lambda = if params.damping.is_finite() {
        params.damping.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let k = params.similarity_k;
    let (breakpoint, constant) = (params.expand_breakpoint, params.expand_constant.max(0.0));
    let count = current.len().min(neighbourhoods.rows());
    let mut next = current.clone();
    for _ in 0..params.iterations {
        let largest = current.iter().copied().fold(0.0, f64::max);
        let normalised = |x: f64| if largest > 0.0 { x / largest } else { 0.0 };
        for v in 0..count {
            let around = neighbourhoods.row(v);
            let cv = normalised(current[v]);
            let mut total_weight = 0.0;
            let mut sum = 0.0;
            for &x in around {
                let value = current[x as usize];
                let w = match params.method {
                    AveragingMethod::None | AveragingMethod::Simple => 1.0,
                    AveragingMethod::SimilarityBased => similarity_weight(cv, normalised(value), k),
                    AveragingMethod::ExpandHighCurvature => {
                        expand_high_curvature_weight(normalised(value), breakpoint, constant)
                    }
                };
                total_weight += w;
                sum += w * value;
            }
            next[v] = if total_weight > 0.0 && total_weight.is_finite() {
                let averaged = lambda * current[v] + (1.0 - lambda) * sum / total_weight;
                if averaged.is_finite() {
                    averaged
                } else {
                    current[v]
                }
            } else {
                current[v]
            };
        }
        std::mem::swap(&mut current, &mut next);
    }
    current
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn expand_weight_is_continuous_and_bounded() {
        let (b, c) = (0.005, 0.3);
        assert_eq!(expand_high_curvature_weight(0.0, b, c), c);
        assert!((expand_high_curvature_weight(b, b, c) - c).abs() < 1e-12);
        assert!((expand_high_curvature_weight(1.0, b, c) - 1.0).abs() < 1e-12);
        let mut last = 0.0;
        for i in 0..=100 {
            let w = expand_high_curvature_weight(i as f64 / 100.0, b, c);
            assert!(w >= last && w <= 1.0);
            last = w;
        }
    }

    #[test]
    fn similarity_weight_peaks_at_100() {
        assert!((similarity_weight(0.3, 0.3, 2.0) - 100.0).abs() < 1e-9);
        assert!(similarity_weight(0.0, 1.0, 2.0) < 0.25);
    }
}
