//! The limit surface's distance to the input (Kloiber 2018 §3.9's
//! violet/green colouring and §5's Hausdorff distance between limit surface
//! and reference mesh).
//!
//! The limit surface is sampled by [`limit_mesh`]: `levels` subdivision
//! steps with every vertex pushed to its limit position, so every sample
//! lies exactly on the limit surface. Distances are measured from those
//! samples to the reference (signed, positive on the side the reference's
//! normals point to) and, for the symmetric Hausdorff distance, from the
//! reference's vertices to the triangulated limit mesh.
//!
//! Deviation: Kloiber colours the control vertices by their distance along
//! their own normal; here every sample of the limit surface carries its
//! signed distance to the reference, which is what a viewer colouring the
//! limit mesh needs (the sign agrees for consistently oriented meshes).
//! [`LimitError`] is meant to be embedded by `metrics` as-is.

use serde::{Deserialize, Serialize};

use super::{BoundaryRule, limit_mesh_with_progress};
use crate::mesh::{PolyMesh, TriMesh};
use crate::progress::{Cancelled, Progress};
use crate::spatial::{DistanceStats, PiecewiseDistance, SurfaceIndex};

/// Distances between a control mesh's limit surface and the reference.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct LimitError {
    /// Signed distance to the reference of each vertex of the limit mesh
    /// the error was measured on (`limit_mesh(control, levels, rule)`,
    /// same vertex order), positive outside. Not serialised (it is per
    /// vertex; the viewer receives it as a typed array).
    #[serde(skip)]
    pub per_vertex_signed: Vec<f64>,
    /// Limit surface → reference: max, mean, RMS over the samples.
    pub stats: DistanceStats,
    /// Reference vertices → limit surface (triangulated limit mesh).
    pub reference_to_limit: DistanceStats,
    /// Symmetric Hausdorff distance: the larger of the two maxima.
    pub hausdorff: f64,
    /// Subdivision levels of the sampling limit mesh.
    pub levels: u32,
}

impl LimitError {
    /// Measures the limit surface of `control`, sampled at `levels`, against
    /// `reference` (with its prebuilt `index`). Returns the limit mesh too,
    /// whose vertices `per_vertex_signed` belongs to.
    pub fn measure(
        control: &PolyMesh,
        reference: &TriMesh,
        index: &SurfaceIndex,
        levels: u32,
        rule: BoundaryRule,
    ) -> (LimitError, PolyMesh) {
        crate::progress::silently("limit error", |progress| {
            Self::measure_with_progress(
                control,
                &[],
                reference,
                index,
                levels,
                rule,
                progress,
                0.0,
                1.0,
            )
        })
        .expect("a silent sink never cancels")
    }

    /// [`LimitError::measure`] of a control mesh with sharp edges
    /// (`sharp[e]` for edge `e`, empty for none), reporting the fraction done mapped to
    /// `[from, to]` between chunks of distance queries; stops when the
    /// sink cancels.
    #[allow(clippy::too_many_arguments)]
    pub fn measure_with_progress(
        control: &PolyMesh,
        sharp: &[bool],
        reference: &TriMesh,
        index: &SurfaceIndex,
        levels: u32,
        rule: BoundaryRule,
        progress: &mut Progress<'_>,
        from: f32,
        to: f32,
    ) -> Result<(LimitError, PolyMesh), Cancelled> {
        let mut at = |done: f32, message: &str| progress.report(from + (to - from) * done, message);
        let limit = limit_mesh_with_progress(control, sharp, levels, rule, &mut |done| {
            at(0.1 * done, "limit error: subdividing to the limit surface")
        })?;
        let mut per_vertex_signed = Vec::with_capacity(limit.positions.len());
        let mut chunk_out = Vec::new();
        let n = limit.positions.len().max(1);
        for (c, chunk) in limit.positions.chunks(CHUNK).enumerate() {
            at(
                0.1 + 0.5 * (c * CHUNK) as f32 / n as f32,
                "limit error: distances of the limit surface",
            )?;
            crate::parallel::map_into(chunk, &mut chunk_out, |&p| index.signed_distance(p));
            per_vertex_signed.extend_from_slice(&chunk_out);
        }
        let stats = DistanceStats::of(per_vertex_signed.iter().copied());
        let triangles = limit.to_face_list().triangulate(&limit.positions);
        let limit_tris = TriMesh {
            positions: limit.positions.clone(),
            triangles,
        };
        let limit_index = PiecewiseDistance::build(&limit_tris, PIECE, &mut |done| {
            at(0.6 + 0.1 * done, "limit error: indexing the limit surface")
        })?;
        let reference_to_limit = if limit_tris.triangles.is_empty() {
            DistanceStats::default()
        } else {
            let mut d = Vec::with_capacity(reference.positions.len());
            let n = reference.positions.len().max(1);
            for (c, chunk) in reference.positions.chunks(CHUNK).enumerate() {
                at(
                    0.7 + 0.3 * (c * CHUNK) as f32 / n as f32,
                    "limit error: distances to the limit surface",
                )?;
                crate::parallel::map_into(chunk, &mut chunk_out, |&p| limit_index.distance(p));
                d.extend_from_slice(&chunk_out);
            }
            DistanceStats::of(d)
        };
        let error = LimitError {
            per_vertex_signed,
            hausdorff: stats.max.max(reference_to_limit.max),
            stats,
            reference_to_limit,
            levels,
        };
        Ok((error, limit))
    }
}

/// Distance queries between two progress reports.
const CHUNK: usize = 4096;

/// Triangles per BVH piece of the limit mesh (one build between progress
/// reports, ~40 ms natively).
const PIECE: usize = 65_536;
