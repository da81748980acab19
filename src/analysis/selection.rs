//! Curvature selection (Kloiber thesis 3.1.2): which scalar of the principal
//! curvatures drives the edge length.
//!
//! The thesis recommends the largest absolute principal curvature
//! `κ' = max(|κ1|, |κ2|)` ("no detail is lost"); mean curvature and
//! directional curvature (both |κ1| and |κ2|, giving rectangles) are options
//! it compares against. Gaussian curvature is not offered: it has units of
//! 1/length², so no edge length follows from it.
//!
//! Decision: "mean" is the magnitude `|κ1 + κ2| / 2`, since averaging and
//! sizing use magnitudes only. For directional selection the scalar field is
//! `max(|κ1|, |κ2|)` (the isotropic size, so nothing downstream gets larger
//! edges than the recommended choice) and [`directional_curvature`] gives the
//! pair along (d1, d2).

use serde::{Deserialize, Serialize};

use super::PrincipalCurvature;

/// The curvature the sizing field is computed from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CurvatureSelection {
    /// `max(|κ1|, |κ2|)` (thesis' recommendation).
    #[default]
    MaxAbs,
    /// `|κ1 + κ2| / 2`.
    Mean,
    /// |κ1| along d1 and |κ2| along d2 (rectangular quads).
    Directional,
}

/// One non-negative curvature magnitude per vertex.
pub fn select_curvature(
    curvatures: &[PrincipalCurvature],
    selection: CurvatureSelection,
) -> Vec<f64> {
    curvatures
        .iter()
        .map(|c| match selection {
            CurvatureSelection::MaxAbs | CurvatureSelection::Directional => c.max_abs(),
            CurvatureSelection::Mean => c.mean().abs(),
        })
        .collect()
}

/// `[|κ1|, |κ2|]` per vertex: the curvature along d1 and along d2.
pub fn directional_curvature(curvatures: &[PrincipalCurvature]) -> Vec<[f64; 2]> {
    curvatures
        .iter()
        .map(|c| [c.k1.abs(), c.k2.abs()])
        .collect()
}
