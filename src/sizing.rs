//! Sizing field: curvature → target edge length per vertex (Kloiber thesis
//! 3.2).
//!
//! The global edge length s is Instant Meshes' scale: `s = √(area / V)` for a
//! target vertex count V (default: input vertices / 16), or given directly.
//! Per vertex, with κ the selected (averaged) curvature magnitude, one of
//! - **uniform** (default, Instant Meshes; see [`EdgeLengthMethod`] for the
//!   measured reason): `x = s`;
//! - **osculating-circle error**: the chord length x whose sagitta
//!   on the osculating circle of radius r = 1/κ is the allowed error ε,
//!   `x(ε) = √(2ε/κ − ε²)`, with ε a fraction (default 0.025) of the largest
//!   bounding-box axis;
//! - **osculating radius**: `x = factor · r`, factor default 0.8;
//! - **transfer function**: `x = T(c) · s` for the normalised curvature
//!   `c = 100 · κ / κ_max ∈ [0, 100]`, T piecewise linear through user
//!   control points (the thesis' editor);
//!
//! and then every length is clamped to `[0.7 s, 5 s]`.
//!
//! Decisions where the thesis is vague:
//! - When ε ≥ r (a curvature so high that the whole osculating circle lies
//!   within the error), x(ε) is taken as r (its value at ε = r); the formula
//!   would shrink again and turn imaginary beyond 2r. The clamp makes this
//!   moot in practice.
//! - κ = 0 gives an infinite length, clamped to the upper bound.
//! - The clamps apply to all three methods, the transfer function included,
//!   so the position field never sees lengths its clusters cannot support.
//! - Transfer-function control points are sanitised rather than rejected:
//!   sorted by x (stable, so equal x make a step), x clamped to [0, 100],
//!   y clamped to ≥ 0; the ends extend as constants. No points means T = 1
//!   (uniform, i.e. Instant Meshes).
//! - κ_max for the normalisation is the largest finite value of the field
//!   being converted, unless the caller passes one (coarser hierarchy levels
//!   should pass the finest level's, so the same curvature maps to the same
//!   length on every level). The same holds for the global edge length and
//!   the bounding-box axis: [`SizingContext`] carries all three.

use serde::{Deserialize, Serialize};

use crate::mesh::TriMesh;

/// How curvature becomes an edge length.
///
/// The default is [`EdgeLengthMethod::Uniform`]: measured by `make quality`
/// (docs/QUALITY.md, im-equivalent vs "+adaptive sizing (per-vertex
/// scale)" at the default target), the thesis' osculating-error sizing made
/// the meshes less regular and no closer to the input — EV 16.6 → 40.7 %,
/// non-quads 6.4 → 20.7 % on fandisk, EV 11.2 → 34.9 % on the bunny, mean
/// distance 0.86e-3 → 0.98e-3 (fandisk), 1.02e-3 → 1.03e-3 (bunny). The
/// adaptive methods stay available as parameters.
///
/// In the global mode a graded sizing is realised by the cross field's
/// cones (`param::cross_field`'s sizing transport, with ln S diffused to
/// the target scale), and is not better there either: single runs at 4×
/// the default target, uniform → osculating error, EV % fandisk 1.7 → 4.1,
/// spot 5.9 → 7.1, rocker-arm 1.0 → 5.6; corner deviation 3.65° → 7.66°,
/// 5.10° → 7.21°, 2.87° → 7.60°; limit-surface mean distance after the fit
/// 6.8e-4 → 7.5e-4, 6.3e-4 → 7.3e-4, 3.7e-4 → 3.3e-4 (the bunny 2.04e-4 with
/// it, Instant Meshes' 2.06e-4). Without the transport the map sheared into
/// the sizing instead: corner deviation 19.9° (fandisk), 21.2° (rocker-arm).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum EdgeLengthMethod {
    /// `x(ε) = √(2ε/κ − ε²)`.
    OsculatingError,
    /// `x = factor / κ`.
    OsculatingRadius,
    /// `x = T(100 κ / κ_max) · s`.
    TransferFunction,
    /// `x = s` everywhere (Instant Meshes' uniform scale). Default.
    #[default]
    Uniform,
}

/// Parameters of the sizing field.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct SizingParams {
    /// Target vertex count for the global edge length; `None` (default) is
    /// input vertices / 16 (Instant Meshes, thesis 3.2).
    pub target_vertex_count: Option<usize>,
    /// Explicit global edge length in mesh units; overrides the vertex count.
    /// Default `None`.
    pub edge_length: Option<f64>,
    /// Default [`EdgeLengthMethod::Uniform`] (see there for the figures).
    pub method: EdgeLengthMethod,
    /// Allowed error ε as a fraction of the largest bounding-box axis.
    /// Default 0.025 (thesis: 0.02–0.03).
    pub epsilon: f64,
    /// Factor of the osculating radius for [`EdgeLengthMethod::OsculatingRadius`].
    /// Default 0.8 (thesis Fig. 3.18).
    pub radius_factor: f64,
    /// Control points `[c, T(c)]`, c ∈ [0, 100] the normalised curvature, T a
    /// multiple of the global edge length. Default approximates the
    /// osculating-error curve: `[0, 5], [2, 2], [10, 1], [100, 0.7]`.
    pub transfer_function: Vec<[f64; 2]>,
    /// Lower clamp, × global edge length. Default 0.7.
    pub min_factor: f64,
    /// Upper clamp, × global edge length. Default 5.
    pub max_factor: f64,
    /// Thin parts: edges around the cross-section of a part whose shape
    /// diameter d is small, i.e. the length is capped at `π d / thin_part_edges`
    /// ([`crate::analysis::thickness`]); 0 turns the cap off. Applied after
    /// the clamps (it may go below `min_factor`), before the calibration.
    ///
    /// Off by default (0): it lowers the Hausdorff distance where thin parts
    /// were lost, but the graded size field costs regularity everywhere it
    /// applies. Medians over 5 vertex orders at the default target, default
    /// → default with 5 edges (`scripts/quality.py`, rows "default + thin
    /// parts"): Hausdorff teapot 0.187 → 0.077, spot 0.104 → 0.061, cow
    /// 0.168 → 0.144, but beetle 0.093 → 0.138 and fandisk 0.025 → 0.038;
    /// EV % teapot 44.5 → 52.9, cow 28.0 → 49.5, spot 31.2 → 44.0; corner
    /// deviation cow 15.7 → 23.9°, spot 14.8 → 17.8°.
    ///
    /// In the global mode (the map's S(f) follows the capped field) it
    /// also stays off: it brings the cow's legs and spot's horns back but
    /// costs the quads' shape beyond Instant Meshes'. Medians over 5
    /// vertex orders at the default target (`scripts/quality.py`, rows
    /// global → global + thin parts (5 edges) / (8 edges); Instant Meshes
    /// in brackets): Hausdorff cow 0.195 → 0.191 / 0.109 (0.115), spot
    /// 0.125 → 0.095 / 0.090 (0.110); but corner deviation cow 7.5° →
    /// 13.9° / 17.2° (11.6°), spot 9.4° → 11.5° / 11.5° (9.8°), EV cow
    /// 10.4 → 23.9 / 29.3 % (27.2 %), spot 17.6 → 20.1 / 22.1 % (29.4 %).
    /// (At the default target the cow's legs are about 1.1 target edges
    /// round; the cap's floor, [`crate::analysis::thickness::FLOOR`],
    /// allows about 3 round them.)
    pub thin_part_edges: f64,
    /// Growth of the thin-part cap per unit of surface distance away from
    /// the thin part (a Lipschitz bound on the cap). Default 0.5.
    pub thin_part_gradation: f64,
}

impl Default for SizingParams {
    fn default() -> Self {
        SizingParams {
            target_vertex_count: None,
            edge_length: None,
            method: EdgeLengthMethod::Uniform,
            epsilon: 0.025,
            radius_factor: 0.8,
            transfer_function: vec![[0.0, 5.0], [2.0, 2.0], [10.0, 1.0], [100.0, 0.7]],
            min_factor: 0.7,
            max_factor: 5.0,
            thin_part_edges: 0.0,
            thin_part_gradation: 0.5,
        }
    }
}

/// Instant Meshes' global edge length: `√(area / target vertices)`, or the
/// explicit length. Always finite and positive (falls back to 1 for a mesh
/// without area).
pub fn global_edge_length(area: f64, input_vertex_count: usize, params: &SizingParams) -> f64 {
    if let Some(s) = params.edge_length.filter(|s| s.is_finite() && *s > 0.0) {
        return s;
    }
    let target = params
        .target_vertex_count
        .unwrap_or(input_vertex_count / 16)
        .max(1);
    let s = (area / target as f64).sqrt();
    if s.is_finite() && s > 0.0 { s } else { 1.0 }
}

/// The mesh-wide quantities the per-vertex conversion needs; computed once on
/// the input and reused on every hierarchy level.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SizingContext {
    /// s, in mesh units.
    pub global_edge_length: f64,
    /// Largest bounding-box axis (ε is a fraction of it).
    pub reference_length: f64,
    /// κ_max for the transfer function's normalisation.
    pub max_curvature: f64,
}

impl SizingContext {
    /// From the input mesh and its selected curvature magnitudes.
    pub fn for_mesh(mesh: &TriMesh, curvature: &[f64], params: &SizingParams) -> SizingContext {
        let referenced = {
            let mut used = vec![false; mesh.vertex_count()];
            for t in &mesh.triangles {
                for &v in t {
                    used[v as usize] = true;
                }
            }
            used.iter().filter(|&&u| u).count()
        };
        SizingContext {
            global_edge_length: global_edge_length(mesh.total_area(), referenced, params),
            reference_length: mesh.bbox().map_or(1.0, |b| b.largest_axis()),
            max_curvature: max_finite(curvature),
        }
    }
}

fn max_finite(values: &[f64]) -> f64 {
    values
        .iter()
        .filter(|v| v.is_finite())
        .fold(0.0, |m, &v| m.max(v.abs()))
}

/// A piecewise-linear transfer function over normalised curvature [0, 100].
#[derive(Debug, Clone, PartialEq)]
pub struct TransferFunction {
    points: Vec<(f64, f64)>,
}

impl TransferFunction {
    /// From control points `[x, y]` (sanitised; see the module doc).
    pub fn new(points: &[[f64; 2]]) -> TransferFunction {
        let mut points: Vec<(f64, f64)> = points
            .iter()
            .filter(|p| p[0].is_finite() && p[1].is_finite())
            .map(|p| (p[0].clamp(0.0, 100.0), p[1].max(0.0)))
            .collect();
        points.sort_by(|a, b| a.0.total_cmp(&b.0));
        TransferFunction { points }
    }

    /// T(c) for c ∈ [0, 100] (clamped). At a step (two points with equal x)
    /// the later point's y holds from x on, as in the thesis' definition.
    pub fn evaluate(&self, c: f64) -> f64 {
        let Some(&first) = self.points.first() else {
            return 1.0;
        };
        let c = if c.is_finite() {
            c.clamp(0.0, 100.0)
        } else {
            0.0
        };
        // The last i with x_i ≤ c.
        let i = self.points.partition_point(|p| p.0 <= c);
        if i == 0 {
            return first.1;
        }
        let (x0, y0) = self.points[i - 1];
        match self.points.get(i) {
            None => y0,
            Some(&(x1, y1)) => {
                if x1 > x0 {
                    y0 + (y1 - y0) / (x1 - x0) * (c - x0)
                } else {
                    y0
                }
            }
        }
    }
}

/// x(ε) on the osculating circle of curvature `kappa` (see the module doc).
pub fn osculating_error_length(kappa: f64, epsilon: f64) -> f64 {
    let kappa = kappa.abs();
    if kappa == 0.0 {
        return f64::INFINITY;
    }
    let r = 1.0 / kappa;
    if epsilon >= r {
        return r;
    }
    (2.0 * epsilon * r - epsilon * epsilon).max(0.0).sqrt()
}

/// Target edge length per vertex from curvature magnitudes (1/length).
pub fn sizing_field(curvature: &[f64], context: &SizingContext, params: &SizingParams) -> Vec<f64> {
    let s = context.global_edge_length;
    let (lo, hi) = {
        let lo = if params.min_factor.is_finite() {
            params.min_factor.max(0.0)
        } else {
            0.7
        };
        let hi = if params.max_factor.is_finite() {
            params.max_factor
        } else {
            5.0
        };
        (lo * s, hi.max(lo) * s)
    };
    let epsilon = params.epsilon.abs() * context.reference_length;
    let transfer = TransferFunction::new(&params.transfer_function);
    curvature
        .iter()
        .map(|&k| {
            let k = if k.is_finite() { k.abs() } else { 0.0 };
            let x = match params.method {
                EdgeLengthMethod::OsculatingError => osculating_error_length(k, epsilon),
                EdgeLengthMethod::OsculatingRadius => params.radius_factor.abs() / k,
                EdgeLengthMethod::TransferFunction => {
                    let c = if context.max_curvature > 0.0 {
                        100.0 * k / context.max_curvature
                    } else {
                        0.0
                    };
                    transfer.evaluate(c) * s
                }
                EdgeLengthMethod::Uniform => s,
            };
            if x.is_nan() { hi } else { x.clamp(lo, hi) }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn transfer_function_matches_control_points_and_steps() {
        let points = [
            [0.0, 3.0],
            [20.0, 1.0],
            [50.0, 1.0],
            [50.0, 2.0],
            [100.0, 4.0],
        ];
        let t = TransferFunction::new(&points);
        for p in [[0.0, 3.0], [20.0, 1.0], [50.0, 2.0], [100.0, 4.0]] {
            assert!((t.evaluate(p[0]) - p[1]).abs() < 1e-12, "{p:?}");
        }
        assert!((t.evaluate(10.0) - 2.0).abs() < 1e-12);
        assert!((t.evaluate(75.0) - 3.0).abs() < 1e-12);
        assert!((t.evaluate(49.999) - 1.0).abs() < 1e-9);
        assert_eq!(TransferFunction::new(&[]).evaluate(30.0), 1.0);
    }

    #[test]
    fn osculating_error_inverts_the_sagitta() {
        let (k, eps) = (2.0, 0.01);
        let x = osculating_error_length(k, eps);
        let r = 1.0 / k;
        let sagitta = r - (r * r - x * x).sqrt();
        assert!((sagitta - eps).abs() < 1e-12);
        assert_eq!(osculating_error_length(100.0, 0.5), 0.01);
        assert!(osculating_error_length(0.0, 0.1).is_infinite());
    }

    #[test]
    fn global_length_from_vertex_count() {
        let p = SizingParams::default();
        assert!((global_edge_length(16.0, 1600, &p) - 0.4).abs() < 1e-12);
        let explicit = SizingParams {
            edge_length: Some(0.3),
            ..p.clone()
        };
        assert_eq!(global_edge_length(16.0, 1600, &explicit), 0.3);
        assert_eq!(global_edge_length(0.0, 0, &p), 1.0);
    }
}
