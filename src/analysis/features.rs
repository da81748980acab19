//! Feature vertices (Kloiber thesis 3.3): vertices on sharp ridges and creases
//! whose principal directions constrain the orientation field.
//!
//! A vertex is a *feature candidate* when it is strongly anisotropic,
//! `κ3 = min(|κ1|, |κ2|) / max(|κ1|, |κ2|) < 0.1` (Rugis & Klette 2006), and
//! strongly curved, `max(|κ1|, |κ2|) > median`. A *true feature vertex* is a
//! candidate whose `max(|κ1|, |κ2|)` exceeds that of each of its 1-ring
//! neighbours and which has at least one candidate neighbour (stray
//! candidates from noise are dropped).
//!
//! Decisions where the thesis is vague:
//! - "The median curvature of all principal curvatures for all vertices" is
//!   taken literally: the median of the 2·N values |κ1|, |κ2|.
//! - The thesis feeds κ3 from "(smoothed)" curvatures; we use the principal
//!   curvatures of the n-ring fit directly (the fit already smooths over its
//!   neighbourhood; averaging works on a scalar and has no directions).
//! - A true feature vertex must itself be a candidate.
//! - "Exceeds each neighbour" is strict; exact ties (symmetric meshes) go to
//!   the lower vertex index, so a plateau yields one vertex, deterministically.
//! - The orientation constraint is the direction of the smaller |κ| (along
//!   the ridge); for a 4-symmetric cross field the other principal direction
//!   is the same constraint.

use glam::DVec3;
use serde::{Deserialize, Serialize};

use super::PrincipalCurvature;
use crate::mesh::VertexAdjacency;

/// Parameters of the feature-vertex classification.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct FeatureParams {
    /// Classify feature vertices at all. Default true.
    pub enabled: bool,
    /// Candidates need `κ3` below this. Default 0.1.
    pub anisotropy_threshold: f64,
}

impl Default for FeatureParams {
    fn default() -> Self {
        FeatureParams {
            enabled: true,
            anisotropy_threshold: 0.1,
        }
    }
}

/// Per-vertex classification.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FeatureVertices {
    /// Anisotropic, strongly curved vertices.
    pub candidate: Vec<bool>,
    /// Candidates that are local maxima of `max|κ|` with a candidate neighbour.
    pub feature: Vec<bool>,
}

impl FeatureVertices {
    /// Indices of the true feature vertices.
    pub fn indices(&self) -> Vec<u32> {
        (0..self.feature.len() as u32)
            .filter(|&v| self.feature[v as usize])
            .collect()
    }
}

/// The median of the absolute principal curvatures (both of every vertex).
pub fn median_abs_curvature(curvatures: &[PrincipalCurvature]) -> f64 {
    let mut all: Vec<f64> = curvatures
        .iter()
        .flat_map(|c| [c.k1.abs(), c.k2.abs()])
        .filter(|k| k.is_finite())
        .collect();
    if all.is_empty() {
        return 0.0;
    }
    let mid = all.len() / 2;
    let (_, &mut upper, _) = all.select_nth_unstable_by(mid, f64::total_cmp);
    if all.len() % 2 == 1 {
        upper
    } else {
        let lower = all[..mid].iter().copied().fold(f64::NEG_INFINITY, f64::max);
        0.5 * (lower + upper)
    }
}

/// Classifies candidates and true feature vertices.
pub fn feature_vertices(
    curvatures: &[PrincipalCurvature],
    adjacency: &VertexAdjacency,
    params: &FeatureParams,
) -> FeatureVertices {
    let n = curvatures.len();
    if !params.enabled {
        return FeatureVertices {
            candidate: vec![false; n],
            feature: vec![false; n],
        };
    }
    let median = median_abs_curvature(curvatures);
    let candidate: Vec<bool> = curvatures
        .iter()
        .map(|c| c.anisotropy() < params.anisotropy_threshold && c.max_abs() > median)
        .collect();
    let count = n.min(adjacency.vertex_count());
    let mut feature = vec![false; n];
    for v in 0..count {
        if !candidate[v] {
            continue;
        }
        let kv = curvatures[v].max_abs();
        let mut has_candidate_neighbour = false;
        let mut is_maximum = true;
        for &x in adjacency.neighbors(v) {
            let x = x as usize;
            if x >= n {
                continue;
            }
            has_candidate_neighbour |= candidate[x];
            let kx = curvatures[x].max_abs();
            if kx > kv || (kx == kv && x < v) {
                is_maximum = false;
                break;
            }
        }
        feature[v] = is_maximum && has_candidate_neighbour;
    }
    FeatureVertices { candidate, feature }
}

/// `(vertex, unit tangent direction)` for every true feature vertex: the
/// principal direction of the smaller |κ|, i.e. along the feature line.
pub fn orientation_constraints(
    features: &FeatureVertices,
    curvatures: &[PrincipalCurvature],
) -> Vec<(u32, DVec3)> {
    features
        .indices()
        .into_iter()
        .filter_map(|v| {
            curvatures
                .get(v as usize)
                .map(|c| (v, c.min_abs_direction()))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pc(k1: f64, k2: f64) -> PrincipalCurvature {
        PrincipalCurvature {
            k1,
            k2,
            d1: DVec3::X,
            d2: DVec3::Y,
        }
    }

    #[test]
    fn median_of_both_curvatures() {
        let c = [pc(1.0, 0.0), pc(3.0, -2.0)];
        assert_eq!(median_abs_curvature(&c), 1.5);
        assert_eq!(
            median_abs_curvature(&[pc(1.0, 0.0), pc(3.0, 2.0), pc(5.0, 4.0)]),
            2.5
        );
        assert_eq!(median_abs_curvature(&[]), 0.0);
    }

    #[test]
    fn ridge_maximum_with_candidate_neighbour_is_a_feature() {
        // A path 0-1-2-3-4 with a ridge peaking at 2; vertex 4 is an isolated
        // anisotropic spike next to no candidate.
        let adj = VertexAdjacency::from_edges(6, &[[0, 1], [1, 2], [2, 3], [3, 4], [4, 5]]);
        let c = [
            pc(0.0, 0.0),
            pc(5.0, 0.1),
            pc(9.0, 0.2),
            pc(1.0, 1.0),
            pc(8.0, 0.0),
            pc(0.0, 0.0),
        ];
        let f = feature_vertices(&c, &adj, &FeatureParams::default());
        assert_eq!(f.candidate, vec![false, true, true, false, true, false]);
        assert_eq!(f.indices(), vec![2]);
        let constraints = orientation_constraints(&f, &c);
        assert_eq!(constraints, vec![(2, DVec3::Y)]);
    }
}
