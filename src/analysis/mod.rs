//! Surface analysis: everything the orientation and position fields need to
//! know about the input surface (Kloiber thesis 3.1–3.3, Ebke et al. 2014
//! section 3).
//!
//! - [`normals`]: face and vertex normals;
//! - [`areas`]: barycentric cell areas (thesis Fig. 3.9);
//! - [`curvature`]: principal curvatures and directions, cubic-order fit or
//!   discrete sums (3.1.1);
//! - [`selection`]: which curvature drives the edge length (3.1.2);
//! - [`averaging`]: curvature averaging (3.1.3);
//! - [`features`]: feature vertices and orientation constraints (3.3);
//! - [`filtered_normals`]: Gaussian-filtered, scale-aware normals (Ebke 3);
//! - [`smooth_regions`]: smooth regions, significance and cyclic regions
//!   (Campen et al. 2016, 3);
//! - the sizing field itself is [`crate::sizing`] (3.2).
//!
//! Every function takes plain slices (positions, normals, an adjacency) and
//! returns per-vertex or per-face `Vec`s, so the hierarchy can recompute any
//! quantity on a coarser level (thesis 3.1.4: curvature re-estimated per
//! level). [`analyze`] runs them all on the input mesh in order.
//!
//! Loops are plain loops over vertices or faces, deterministic, single
//! threaded; the pipeline can hook progress and cancellation into them.

pub mod areas;
pub mod averaging;
pub mod curvature;
pub mod features;
pub mod filtered_normals;
pub mod normals;
pub mod selection;
pub mod smooth_regions;
pub mod thickness;

use glam::DVec3;
use serde::{Deserialize, Serialize};

use crate::mesh::{FaceAdjacency, TriMesh, VertexAdjacency};
use crate::progress::{Cancelled, Progress};
use crate::sizing::{self, SizingContext, SizingParams};

pub use areas::barycentric_cell_areas;
pub use averaging::{AveragingMethod, AveragingParams, average_curvature};
pub use curvature::{
    CurvatureEstimator, CurvatureParams, PrincipalCurvature, principal_curvatures,
};
pub use features::{FeatureParams, FeatureVertices, feature_vertices, orientation_constraints};
pub use filtered_normals::{FilteredNormalsMode, FilteredNormalsParams, Sigma, filtered_normals};
pub use normals::{NormalWeighting, face_normals, vertex_normals};
pub use selection::{CurvatureSelection, directional_curvature, select_curvature};

/// Parameters of the surface analysis. Every field has a documented default
/// (DESIGN.md's table); `#[serde(default)]` fills missing fields.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct AnalysisParams {
    /// Vertex normal weighting. Default [`NormalWeighting::Angle`].
    pub normal_weighting: NormalWeighting,
    /// Estimator and neighbourhood. Default cubic fit on the 2-ring.
    pub curvature: CurvatureParams,
    /// Default [`CurvatureSelection::MaxAbs`] (`max(|κ1|, |κ2|)`).
    pub selection: CurvatureSelection,
    /// Default simple averaging, 2 iterations, λ = 0.25, 1-ring.
    pub averaging: AveragingParams,
    /// Default on, κ3 < 0.1.
    pub features: FeatureParams,
    /// Default σ = s/2 for the global edge length s, truncated at 2σ.
    pub filtered_normals: FilteredNormalsParams,
}

/// The sizing field: one target edge length per vertex.
#[derive(Debug, Clone, PartialEq)]
pub struct SizingField {
    /// Mesh-wide quantities (global edge length s, …), for reuse on coarser levels.
    pub context: SizingContext,
    /// Target edge length per vertex, in `[min_factor, max_factor] · s`.
    pub edge_length: Vec<f64>,
    /// With [`CurvatureSelection::Directional`]: lengths along (d1, d2).
    pub directional: Option<Vec<[f64; 2]>>,
    /// The graded thin-part cap already applied to `edge_length`
    /// ([`thickness::thin_part_cap`]), kept for the coarse levels; `None`
    /// when it is off or caps nothing.
    pub thin_part_cap: Option<Vec<f64>>,
}

/// Everything [`analyze`] computes, per vertex (`vertex_*`, `curvature`,
/// `selected`, `averaged`, sizing, features) or per face (`face_*`,
/// `filtered_normals`).
#[derive(Debug, Clone)]
pub struct SurfaceAnalysis {
    pub adjacency: VertexAdjacency,
    pub face_adjacency: FaceAdjacency,
    pub face_normals: Vec<DVec3>,
    pub vertex_normals: Vec<DVec3>,
    pub cell_areas: Vec<f64>,
    pub curvature: Vec<PrincipalCurvature>,
    /// The selected curvature magnitude (thesis 3.1.2), before averaging.
    pub selected: Vec<f64>,
    /// After averaging (thesis 3.1.3); what the sizing field uses.
    pub averaged: Vec<f64>,
    pub sizing: SizingField,
    pub features: FeatureVertices,
    /// Unit filtered normal per face (the face normals when filtering is off).
    pub filtered_normals: Vec<DVec3>,
}

/// The sizing field, its directional channels and the cap applied to them.
type CappedSizing = (Vec<f64>, Option<Vec<[f64; 2]>>, Option<Vec<f64>>);

/// Applies the thin-part cap (`sizing.thin_part_edges` > 0) to the sizing
/// field and its directional channels.
fn cap_thin_parts(
    mesh: &TriMesh,
    normals: &[DVec3],
    adjacency: &VertexAdjacency,
    mut edge_length: Vec<f64>,
    mut directional: Option<Vec<[f64; 2]>>,
    params: &SizingParams,
) -> CappedSizing {
    if !(params.thin_part_edges.is_finite() && params.thin_part_edges > 0.0) {
        return (edge_length, directional, None);
    }
    let Some(index) = crate::spatial::SurfaceIndex::new(mesh) else {
        return (edge_length, directional, None);
    };
    let diameter = thickness::shape_diameter(mesh, normals, &index);
    let cap = thickness::thin_part_cap(
        mesh,
        adjacency,
        &diameter,
        &edge_length,
        params.thin_part_edges,
        thickness::FLOOR,
        params.thin_part_gradation,
    );
    if let Some(cap) = &cap {
        for (s, &c) in edge_length.iter_mut().zip(cap) {
            *s = s.min(c);
        }
        if let Some(d) = &mut directional {
            for (pair, &c) in d.iter_mut().zip(cap) {
                pair[0] = pair[0].min(c);
                pair[1] = pair[1].min(c);
            }
        }
    }
    (edge_length, directional, cap)
}

/// Runs the whole analysis on `mesh` in pipeline order.
pub fn analyze(
    mesh: &TriMesh,
    params: &AnalysisParams,
    sizing_params: &SizingParams,
) -> SurfaceAnalysis {
    crate::progress::silently("analysis", |progress| {
        analyze_with_progress(mesh, params, sizing_params, progress)
    })
    .expect("a silent sink never cancels")
}

/// [`analyze`], reporting progress (inside the curvature estimation, the
/// longest part, and between the steps) and stopping when the sink cancels.
pub fn analyze_with_progress(
    mesh: &TriMesh,
    params: &AnalysisParams,
    sizing_params: &SizingParams,
    progress: &mut Progress<'_>,
) -> Result<SurfaceAnalysis, Cancelled> {
    progress.report(0.0, "adjacency and normals")?;
    let adjacency = VertexAdjacency::new(mesh);
    let face_adjacency = FaceAdjacency::new(mesh);
    let face_normals = face_normals(mesh);
    let vertex_normals = vertex_normals(mesh, params.normal_weighting);
    let cell_areas = barycentric_cell_areas(mesh);
    progress.report(0.05, "principal curvatures")?;
    let curvature = curvature::principal_curvatures_with_progress(
        &mesh.positions,
        &vertex_normals,
        &adjacency,
        &params.curvature,
        progress,
        0.05,
        0.7,
    )?;
    progress.report(0.7, "curvature averaging")?;
    let selected = select_curvature(&curvature, params.selection);
    let averaged = average_curvature(&selected, &adjacency, &params.averaging);
    progress.report(0.75, "sizing field")?;
    let context = SizingContext::for_mesh(mesh, &averaged, sizing_params);
    let edge_length = sizing::sizing_field(&averaged, &context, sizing_params);
    let directional = (params.selection == CurvatureSelection::Directional).then(|| {
        let pairs = directional_curvature(&curvature);
        let channel = |i: usize| {
            let values: Vec<f64> = pairs.iter().map(|p| p[i]).collect();
            let averaged = average_curvature(&values, &adjacency, &params.averaging);
            sizing::sizing_field(&averaged, &context, sizing_params)
        };
        let (along1, along2) = (channel(0), channel(1));
        along1
            .into_iter()
            .zip(along2)
            .map(|(a, b)| [a, b])
            .collect()
    });
    let (edge_length, directional, thin_part_cap) = cap_thin_parts(
        mesh,
        &vertex_normals,
        &adjacency,
        edge_length,
        directional,
        sizing_params,
    );
    progress.report(0.8, "feature vertices")?;
    let features = feature_vertices(&curvature, &adjacency, &params.features);
    progress.report(0.85, "filtered normals")?;
    let fp = &params.filtered_normals;
    let filtered = match fp.mode {
        FilteredNormalsMode::Off => face_normals.clone(),
        FilteredNormalsMode::Global => filtered_normals::filtered_normals_with_progress(
            mesh,
            &face_adjacency,
            &face_normals,
            Sigma::Uniform(fp.sigma_factor * context.global_edge_length),
            fp.truncation,
            progress,
            0.85,
            1.0,
        )?,
        FilteredNormalsMode::SizingAware => {
            let sigma =
                filtered_normals::face_sigma_from_sizing(mesh, &edge_length, fp.sigma_factor);
            filtered_normals::filtered_normals_with_progress(
                mesh,
                &face_adjacency,
                &face_normals,
                Sigma::PerFace(&sigma),
                fp.truncation,
                progress,
                0.85,
                1.0,
            )?
        }
    };
    Ok(SurfaceAnalysis {
        adjacency,
        face_adjacency,
        face_normals,
        vertex_normals,
        cell_areas,
        curvature,
        selected,
        averaged,
        sizing: SizingField {
            context,
            edge_length,
            directional,
            thin_part_cap,
        },
        features,
        filtered_normals: filtered,
    })
}
