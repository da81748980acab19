//! The field optimisation: multiresolution hierarchy, orientation field,
//! position field and their singularities — Instant Meshes (Jakob et al.
//! 2015, `../shared/reference/instant-meshes-digest.md` §2–4) with the
//! curvature-adaptive changes of Kloiber 2018 (§3.1.4, §3.3, §3.4): a
//! per-vertex lattice spacing from the sizing field on every level, and
//! orientation constraints.
//!
//! The fields are computed in `f32` (memory and speed; the lattice
//! arithmetic needs no more). Everything is seeded and deterministic: the
//! Gauss–Seidel sweeps update one colour class at a time, each vertex
//! reading only other classes, so threads (native) and one thread (wasm)
//! give bit-identical results.

pub mod hierarchy;
pub mod lattice;
pub mod orientation;
pub mod position;
pub mod scale_consistency;
pub mod singularities;

use serde::{Deserialize, Serialize};

pub use hierarchy::{Hierarchy, Level, Links};
pub use orientation::{OrientationConstraints, solve_orientation};
pub use position::{ScaleMode, solve_position};
pub use singularities::{Singularity, orientation_singularities, position_singularities};

/// How the sizing field reaches the coarse levels (Kloiber §3.1.4).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum LevelSizing {
    /// Curvature and sizing estimated again on each level's own points and
    /// links (the thesis' best option).
    #[default]
    PerLevel,
    /// "Curvature summation": each coarse vertex takes the area-weighted
    /// mean of its children's edge lengths.
    Summation,
}

/// Parameters of the field stage, with the defaults of DESIGN.md.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct FieldParams {
    /// Gauss–Seidel sweeps per level for the orientation field (Instant Meshes: 6).
    pub orientation_iterations: usize,
    /// Sweeps per level for the position field (Kloiber §3.4: 10–15).
    pub position_iterations: usize,
    pub scale_mode: ScaleMode,
    pub level_sizing: LevelSizing,
    /// Let the fields live in the tangent planes of the filtered normals
    /// (Ebke et al. 2014) instead of the vertex normals.
    pub filtered_normals: bool,
    /// Split every input edge longer than `min(s/2, 2·mean edge)` at its
    /// midpoint, longest first, before the fields are built (Instant Meshes'
    /// preprocessing, digest §1.3; [`crate::mesh::refine`]). Default on:
    /// the position field is sampled at the input's vertices, and a target
    /// edge that is not well above the input's edges leaves lattice cells
    /// without samples. At a quarter of the input's vertices (rocker-arm,
    /// 2508) the defaults without it gave EV 25.5 %, corner deviation 13.6°,
    /// Hausdorff 0.027 and limit 2.18e-4, with it 5.6 %, 3.6°, 0.010 and
    /// 1.16e-4 (bunny 8708: corner 3.28 → 2.76°, Hausdorff 0.0189 → 0.0165;
    /// spot 732: EV 12.4 → 10.4 %, corner 6.72 → 5.33°; one run each). At
    /// the default target (input / 16; medians over 3 vertex orders, off →
    /// on; EV %, corner °, limit): fandisk 13.7 → 11.7, 5.71 → 4.96, 7.36e-4
    /// → 7.25e-4; rocker-arm 12.8 → 10.5, 6.61 → 6.70, 3.39e-4 → 3.29e-4;
    /// cow 26.1 → 24.3, 14.50 → 13.07, 1.19e-3 → 1.13e-3; beetle 58.9 →
    /// 52.1, 19.0 → 14.1, 3.97e-3 → 2.93e-3; but spot 26.2 → 29.4 (limit
    /// 7.95e-4 → 8.55e-4), bunny 7.3 → 8.4, 4.31 → 4.75, and suzanne's odd
    /// faces 7.1 → 12.5 %; teapot mixed.
    pub split_long_edges: bool,
    /// Make the lattice spacing consistent with the cross field before the
    /// position field ([`scale_consistency`]): the healing length, in
    /// target edges, over which the spacing may leave the sizing field's to
    /// follow the field's turning; 0 = off (the sizing field as it is).
    /// Default 5. Deviation from the thesis and Instant Meshes. Measured
    /// (docs/QUALITY.md, medians over 5 vertex orders), off → on: on the
    /// Instant-Meshes-equivalent configuration EV % rocker-arm 14.3 → 10.4,
    /// bunny 11.8 → 8.6, fandisk 15.2 → 12.1, cow 25.3 → 22.5, suzanne
    /// 60.0 → 50.0 (Instant Meshes 12.0, 8.9, 13.5, 27.2, 55.6), odd faces
    /// lower on 6 of 8 meshes; the rocker arm's position singularities
    /// 71 → 35 (tests/pipeline.rs). On the defaults EV % is lower on 6 of
    /// 8 (bunny 11.3 → 7.4, rocker-arm 16.3 → 12.9, spot 30.3 → 26.2,
    /// suzanne 60.7 → 48.3; beetle 52.8 → 56.5 and teapot 36.0 → 39.4
    /// rise) and the corner deviation on 4 (bunny 5.27 → 4.30°, spot 13.6
    /// → 12.5°; beetle 14.8 → 18.4° rises). It costs limit-surface
    /// accuracy after the fit on fandisk (0.80 → 0.85 × Instant Meshes'),
    /// the beetle (0.77 → 0.85) and the cow (1.02 → 1.10) and gains it on
    /// spot (1.12 → 0.96). Single-run rows: 20 target edges and 2.
    pub scale_consistency: f32,
    pub seed: u64,
}

impl Default for FieldParams {
    fn default() -> Self {
        FieldParams {
            orientation_iterations: 6,
            position_iterations: 15,
            scale_mode: ScaleMode::PerVertex,
            level_sizing: LevelSizing::PerLevel,
            filtered_normals: false,
            split_long_edges: true,
            scale_consistency: 5.0,
            seed: 0,
        }
    }
}

/// Area-weighted means of a per-vertex quantity on every level ("curvature
/// summation"), level 0 first.
pub fn restrict_by_area(hierarchy: &Hierarchy, values: &[f32]) -> Vec<Vec<f32>> {
    let mut out = vec![values.to_vec()];
    for l in 1..hierarchy.levels.len() {
        let (coarse, fine) = (&hierarchy.levels[l], &hierarchy.levels[l - 1]);
        let prev = &out[l - 1];
        let next = (0..coarse.len())
            .map(|c| {
                let (mut sum, mut weight) = (0.0f32, 0.0f32);
                for child in coarse.children(c) {
                    let a = fine.areas[child].max(1e-30);
                    sum += a * prev[child];
                    weight += a;
                }
                sum / weight
            })
            .collect();
        out.push(next);
    }
    out
}

/// The smallest value of each coarse vertex's children on every level,
/// level 0 first (for bounds such as the thin-part cap, where a mean would
/// let a coarse vertex exceed the bound of part of its region).
pub fn restrict_by_min(hierarchy: &Hierarchy, values: &[f32]) -> Vec<Vec<f32>> {
    let mut out = vec![values.to_vec()];
    for l in 1..hierarchy.levels.len() {
        let prev = &out[l - 1];
        let next = (0..hierarchy.levels[l].len())
            .map(|c| {
                hierarchy.levels[l]
                    .children(c)
                    .map(|child| prev[child])
                    .fold(f32::INFINITY, f32::min)
            })
            .collect();
        out.push(next);
    }
    out
}

/// Level-0 links: one per triangle edge, weight 1.
pub fn mesh_links(vertex_count: usize, triangles: &[[u32; 3]]) -> Links {
    Links::from_edges(
        vertex_count,
        triangles
            .iter()
            .flat_map(|t| [[t[0], t[1]], [t[1], t[2]], [t[2], t[0]]]),
    )
}
