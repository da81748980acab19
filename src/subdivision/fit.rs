//! Control-mesh fitting (Kloiber 2018 §3.8, the method of Thaller,
//! Augsdörfer and Fellner 2016): one Catmull–Clark step makes the
//! quad-dominant mesh pure quad (a mesh that is already pure quad is a
//! control mesh as it is, and with [`FitSplit::NonQuads`] is fitted
//! without the step, at a quarter of the control vertices); then, repeatedly, every interior control
//! vertex moves by the offset between its limit point and the point where
//! the line through the limit point along the limit normal meets the input.
//! Stops after `max_iterations` (20) or when the largest move is below
//! `tolerance` (1e-4) × the input's largest bounding-box axis.
//!
//! Deviations, each for robustness on scans:
//! - the normal is the limit surface's normal (tangent masks of Halstead et
//!   al. 1993, see [`super::limit`]); the thesis says "normal" without more;
//! - the intersection is searched along the whole line (both directions,
//!   nearest hit), within `ray_length` × the vertex's mean incident edge
//!   length, so a vertex cannot jump across a thin part of the input;
//! - when the line misses within that bound, the offset is the normal
//!   component of the way to the closest point of the input (counted in
//!   [`FitResult::rays_missed`]); every offset is clamped to the same bound;
//! - the move that triggers the stop is still applied (it only helps);
//! - boundary vertices stay fixed, as in the thesis.
//!
//! Extension: a least-squares finish ([`FitParams::lspia_iterations`]).
//! The normal offsets put every control vertex's *limit point* on the
//! input, which interpolates it there; between those points the limit
//! surface is left where the offsets' fixed point puts it. Afterwards the
//! smooth control vertices take a few steps of progressive-iterative
//! least-squares approximation (LSPIA, Deng and Lin 2014): the limit
//! surface is sampled once subdivided (at the control vertices, edge
//! midpoints and face centres), each sample's offset to its closest point
//! of the input is found, and every control vertex moves by μ times the
//! weighted mean of its samples' offsets, plus a share of its previous
//! move (heavy-ball momentum, [`LSPIA_MOMENTUM`]). Deviation from LSPIA: the
//! weights are the samples' bilinear (hat-function) weights on the control
//! vertices rather than the limit stencils' B-spline weights, so the fixed
//! point makes the offsets average to zero over each control vertex's hat
//! (a Petrov–Galerkin condition) instead of the exact least-squares one.
//! Vertices on creases keep the curves' fit and boundary vertices stay.
//!
//! Extension: sharp features (`crease_degrees`). A smooth limit surface
//! cannot follow the input's sharp edges: on fandisk 97 % of the fitted
//! limit surface's mean distance lies within one edge of them. Edges of
//! the quad-dominant mesh that run along the input's feature curves
//! ([`crease_edges`]) become infinitely sharp creases (Hoppe et al. 1994,
//! DeRose et al. 1998; rules in [`super::catmull_clark`]), whose limit is a
//! cubic B-spline curve. A control vertex on a crease (or a corner of
//! creases) moves by the offset from its limit point to the closest point
//! of the input's feature curves instead of along the normal. Any mesh
//! fitted gets the same detection (another remesher's output too); a mesh
//! whose edges do not follow the features gets no creases.

use glam::DVec3;
use serde::{Deserialize, Serialize};

use super::catmull_clark::Vertex;
use super::subdivide_creased;
use super::{BoundaryRule, LimitError, face_normal, limit_normals, limit_positions_creased};
use crate::mesh::{EdgeTopology, PolyMesh, TriMesh};
use crate::progress::{Cancelled, Progress};
use crate::spatial::{CurveIndex, SurfaceIndex};

/// Parameters of the control-mesh fitting. `#[serde(default)]`: a JSON
/// object with only the values to change is valid.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct FitParams {
    /// Most fitting iterations. Default 20 (Thaller et al. 2016, Kloiber §3.8).
    pub max_iterations: u32,
    /// Stop when the largest move is below this fraction of the reference's
    /// largest bounding-box axis. Default 1e-4 (Kloiber §3.8).
    pub tolerance: f64,
    /// Search the normal line this many local edge lengths (mean length of
    /// the vertex's edges in the pure-quad control mesh) each way; also the
    /// largest move per iteration. Default 2.
    pub ray_length: f64,
    /// Boundary rule for subdivision and limit points. Default
    /// [`BoundaryRule::Fixed`] (Kloiber §3.8).
    pub boundary: BoundaryRule,
    /// Subdivision levels of the limit mesh the error is measured on.
    /// Default 2 (each control quad sampled 4 × 4).
    pub error_levels: u32,
    /// Measure the limit error before fitting too (costs one more
    /// measurement). Default true.
    pub measure_before: bool,
    /// Input edges whose faces' normals differ by more than this many
    /// degrees are feature curves, and the mesh's edges along them become
    /// sharp creases (module docs); 0 turns creases off.
    pub crease_degrees: f64,
    /// Whether the mesh is split once (Catmull–Clark) before fitting.
    /// Default [`FitSplit::Auto`].
    pub split: FitSplit,
    /// Most least-squares steps after the normal offsets (module docs);
    /// they stop early once the largest move is below `tolerance`. 0
    /// turns them off (the thesis' fit). Default 10. Limit-surface mean
    /// distance after the fit, 0 → 10, on `make quality`'s meshes at the
    /// default target (1580ad2's outputs, one vertex order; Quadrille's
    /// default / Instant Meshes' quads, both fitted by `quadrille fit`):
    /// fandisk 1.96e-4 → 1.51e-4 / 8.50e-4 → 4.89e-4, rocker-arm 3.37e-4
    /// → 2.24e-4 / 3.98e-4 → 2.17e-4, spot 7.78e-4 → 4.96e-4 / 8.11e-4 →
    /// 5.05e-4, cow 1.20e-3 → 7.89e-4 / 1.20e-3 → 8.80e-4, the bunny
    /// 2.00e-4 → 1.56e-4 / 2.06e-4 → 1.55e-4, beetle 2.96e-3 → 2.59e-3 /
    /// 4.30e-3 → 2.28e-3, teapot 9.72e-4 → 8.45e-4 / 5.55e-4 → 5.10e-4,
    /// suzanne 6.05e-3 → 4.12e-3 / 6.25e-3 → 3.88e-3. The input's mean
    /// distance to the limit surface falls with it on all of them but
    /// Instant Meshes' beetle (+0.7 %); the limit surface's Hausdorff
    /// distance moves both ways (fandisk's −18 % on ours and −47 % on
    /// Instant Meshes', spot's +17 % and +16 %). The control meshes' quad
    /// corners deviate a little more from 90° (spot 13.5° → 14.7°, the
    /// bunny 4.2° → 4.7°).
    pub lspia_iterations: u32,
}

/// Whether the fitting starts with one Catmull–Clark step.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum FitSplit {
    /// The pipeline's global mode (pure quads) fits its mesh as it is; the
    /// local mode, and any mesh fitted on its own (`quadrille fit`), split
    /// first as [`FitSplit::Always`].
    #[default]
    Auto,
    /// One step first whatever the mesh (a quad mesh's control vertices
    /// quadruple): the thesis.
    Always,
    /// One step only when a face is not a quad; a pure-quad mesh is fitted
    /// as it is.
    NonQuads,
}

impl FitSplit {
    /// Whether `mesh` is split once before fitting.
    pub fn splits(self, mesh: &PolyMesh) -> bool {
        match self {
            FitSplit::Auto | FitSplit::Always => true,
            FitSplit::NonQuads => (0..mesh.face_count()).any(|f| mesh.degree(f as u32) != 4),
        }
    }
}

impl Default for FitParams {
    fn default() -> Self {
        FitParams {
            max_iterations: 20,
            tolerance: 1e-4,
            ray_length: 2.0,
            boundary: BoundaryRule::Fixed,
            error_levels: 2,
            measure_before: true,
            crease_degrees: 40.0,
            split: FitSplit::Auto,
            lspia_iterations: 10,
        }
    }
}

/// The fitted control mesh and how the fitting went.
#[derive(Debug, Clone)]
pub struct FitResult {
    /// The pure-quad control mesh whose limit surface approximates the input.
    pub control: PolyMesh,
    /// Per edge of `control`: an infinitely sharp crease.
    pub sharp: Vec<bool>,
    /// The limit mesh the `after` error was measured on (`error_levels`
    /// steps, vertices on the limit surface), for display and export.
    pub limit: PolyMesh,
    /// Limit error of the unfitted control mesh (the quad-dominant mesh's
    /// own limit surface); default when `measure_before` is off.
    pub before: LimitError,
    /// Limit error after fitting.
    pub after: LimitError,
    pub summary: FitSummary,
}

impl FitResult {
    /// The vertex pairs of `control`'s sharp edges (for the OBJ crease
    /// tags of [`crate::io::write_obj_with_creases`]); `sharp` may be
    /// empty (no creases), as everywhere in [`super`].
    pub fn crease_vertex_pairs(&self) -> Vec<[u32; 2]> {
        let c = &self.control;
        (0..c.edge_count() as u32)
            .filter(|&e| self.sharp.get(e as usize).copied().unwrap_or(false))
            .map(|e| [c.origin(2 * e), c.tip(2 * e)])
            .collect()
    }
}

/// The numbers of a fitting run, for stats files and the UI.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct FitSummary {
    /// Iterations run (each moves every interior vertex once).
    pub iterations: u32,
    /// Whether the largest move fell below the tolerance.
    pub converged: bool,
    /// Largest move of each iteration (local units: reference's largest
    /// bounding-box axis = 1 for imported meshes).
    pub max_move: Vec<f64>,
    /// Least-squares steps taken after the normal offsets, and the largest
    /// move of each ([`FitParams::lspia_iterations`]).
    pub lspia_iterations: u32,
    pub lspia_max_move: Vec<f64>,
    /// Normal lines cast, and how many missed the input within the bound
    /// (closest-point fallback).
    pub rays_cast: usize,
    pub rays_missed: usize,
    /// Largest total displacement of a control vertex from its unfitted
    /// position, absolute and in units of its local edge length (the
    /// sanity bound against jumps across thin parts).
    pub max_displacement: f64,
    pub max_displacement_edges: f64,
    pub control_vertices: usize,
    pub control_faces: usize,
    /// Edges of the quad-dominant mesh made sharp creases.
    pub crease_edges: usize,
    /// Whether the mesh was split once before fitting ([`FitSplit`]).
    pub split: bool,
    pub before: LimitError,
    pub after: LimitError,
}

impl FitSummary {
    /// The largest displacement from `start` to `now`, absolute and in
    /// local edge lengths.
    fn record_displacement(&mut self, now: &[DVec3], start: &[DVec3], edge_length: &[f64]) {
        for ((&p, &s), &e) in now.iter().zip(start).zip(edge_length) {
            let d = p.distance(s);
            self.max_displacement = self.max_displacement.max(d);
            if e > 0.0 {
                self.max_displacement_edges = self.max_displacement_edges.max(d / e);
            }
        }
    }
}

/// Control vertices moved between two progress reports.
const PROGRESS_CHUNK: usize = 8192;

/// LSPIA's step μ. Deng and Lin 2014 prove convergence for μ < 2 with
/// their normalised B-spline weights (the step operator's eigenvalues then
/// lie in (0, 1]); for our hat weights that is not proven, only measured:
/// 1.5 took spot's limit-surface mean distance to 5.89e-4 in 8 steps where
/// μ = 1 needed 16 for 5.71e-4, and every move is clamped to `ray_length`
/// local edges.
const LSPIA_STEP: f64 = 1.5;

/// Each LSPIA move adds this share of the vertex's previous move (Polyak's
/// heavy ball), for the slow modes of the step operator. At 10 steps, 0 →
/// 0.7 lowered the limit surface's mean distance on every shared mesh, for
/// our meshes and Instant Meshes' (spot 5.75e-4 → 4.96e-4, rocker-arm
/// 2.56e-4 → 2.24e-4, the bunny 1.66e-4 → 1.56e-4, Instant Meshes' fandisk
/// 6.05e-4 → 4.89e-4); 0.5 and 0.85 did less on spot and the bunny.
const LSPIA_MOMENTUM: f64 = 0.7;

/// Fits a Catmull–Clark control mesh to `reference`, starting from
/// `quad_dominant` (any polygon mesh in the reference's coordinates).
/// Reports progress under the current stage name; returns [`Cancelled`]
/// when the sink asks to stop.
pub fn fit_control_mesh(
    quad_dominant: &PolyMesh,
    reference: &TriMesh,
    params: &FitParams,
    progress: &mut Progress,
) -> Result<FitResult, Cancelled> {
    let rule = params.boundary;
    let split = params.split.splits(quad_dominant);
    progress.report(0.0, "the pure quad control mesh")?;
    let features = feature_curves(reference, params.crease_degrees);
    let (mut control, sharp, crease_count) =
        start_mesh(quad_dominant, rule, features.as_ref(), split);
    let start = control.positions.clone();
    let scale = reference
        .bbox()
        .map(|b| b.largest_axis())
        .filter(|s| s.is_finite() && *s > 0.0)
        .unwrap_or(1.0);
    let Some(index) = SurfaceIndex::new(reference) else {
        // Nothing to fit to: the control mesh is the subdivided input.
        let limit = super::limit_mesh_creased(&control, &sharp, params.error_levels, rule);
        return Ok(FitResult {
            summary: FitSummary {
                control_vertices: control.vertex_count(),
                control_faces: control.face_count(),
                split,
                ..FitSummary::default()
            },
            control,
            sharp,
            limit,
            before: LimitError::default(),
            after: LimitError::default(),
        });
    };

    let before = if params.measure_before {
        progress.report(0.02, "measuring the unfitted limit surface")?;
        LimitError::measure_with_progress(
            &control,
            &sharp,
            reference,
            &index,
            params.error_levels,
            rule,
            progress,
            0.02,
            0.05,
        )?
        .0
    } else {
        LimitError::default()
    };

    let edge_length = mean_edge_lengths(&control);
    let movable: Vec<u32> = (0..control.vertex_count() as u32)
        .filter(|&v| !control.is_boundary_vertex(v))
        .collect();
    // Control vertices on creases follow the feature curves.
    let on_crease: Vec<bool> = movable
        .iter()
        .map(|&v| {
            matches!(
                Vertex::of(&control, v, &sharp),
                Vertex::Crease(..) | Vertex::Corner
            )
        })
        .collect();
    let mut summary = FitSummary {
        control_vertices: control.vertex_count(),
        control_faces: control.face_count(),
        crease_edges: crease_count,
        split,
        ..FitSummary::default()
    };
    let max_iterations = params.max_iterations;
    let mut offsets: Vec<(DVec3, bool)> = Vec::new();
    let mut chunk_offsets: Vec<(DVec3, bool)> = Vec::new();
    for it in 0..max_iterations {
        let at = |done: f32| 0.05 + 0.65 * (it as f32 + done) / max_iterations.max(1) as f32;
        let message = format!("fitting iteration {}", it + 1);
        progress.report(at(0.0), &message)?;
        let limit = limit_positions_creased(&control, rule, &sharp);
        let normals = limit_normals(&control);
        // In chunks, so progress (and cancelling) gets a word in on big
        // meshes in a single-threaded worker.
        offsets.clear();
        for (c, chunk) in movable.chunks(PROGRESS_CHUNK).enumerate() {
            if c > 0 {
                progress.report(
                    at((c * PROGRESS_CHUNK) as f32 / movable.len() as f32),
                    &message,
                )?;
            }
            let first = c * PROGRESS_CHUNK;
            let crease_chunk = &on_crease[first..first + chunk.len()];
            let work: Vec<(u32, bool)> = chunk
                .iter()
                .copied()
                .zip(crease_chunk.iter().copied())
                .collect();
            crate::parallel::map_into(&work, &mut chunk_offsets, |&(v, crease)| {
                let (l, n) = (limit[v as usize], normals[v as usize]);
                let bound = params.ray_length * edge_length[v as usize];
                match (&features, crease) {
                    (Some(curves), true) => {
                        let (c, _, _) = curves.closest(l);
                        ((c - l).clamp_length_max(bound), false)
                    }
                    _ => offset_to_surface(&index, l, n, bound),
                }
            });
            offsets.extend_from_slice(&chunk_offsets);
        }
        let mut largest = 0.0f64;
        for (&v, &(offset, missed)) in movable.iter().zip(&offsets) {
            control.positions[v as usize] += offset;
            largest = largest.max(offset.length());
            summary.rays_missed += missed as usize;
        }
        summary.rays_cast += movable.len();
        summary.max_move.push(largest);
        summary.iterations = it + 1;
        if largest < params.tolerance * scale {
            summary.converged = true;
            break;
        }
    }
    if params.lspia_iterations > 0 {
        let at = LspiaAt {
            sharp: &sharp,
            movable: &movable,
            on_crease: &on_crease,
            edge_length: &edge_length,
            scale,
        };
        lspia(&mut control, &at, &index, params, &mut summary, progress)?;
    }

    summary.record_displacement(&control.positions, &start, &edge_length);
    progress.report(0.92, "measuring the fitted limit surface")?;
    let (after, limit) = LimitError::measure_with_progress(
        &control,
        &sharp,
        reference,
        &index,
        params.error_levels,
        rule,
        progress,
        0.92,
        1.0,
    )?;
    summary.before = before.clone();
    summary.after = after.clone();
    progress.report(1.0, "control mesh fitted")?;
    Ok(FitResult {
        control,
        sharp,
        limit,
        before,
        after,
        summary,
    })
}

/// What [`lspia`] needs of the control mesh: its sharp edges, the
/// interior control vertices and which of them are on creases (it moves
/// the others), the mean edge lengths, and the reference's largest axis
/// (for the tolerance).
#[derive(Clone, Copy)]
struct LspiaAt<'a> {
    sharp: &'a [bool],
    movable: &'a [u32],
    on_crease: &'a [bool],
    edge_length: &'a [f64],
    scale: f64,
}

/// The least-squares finish (module docs): up to
/// `params.lspia_iterations` steps moving the interior control vertices
/// off creases, each by at most `ray_length` local edges, reporting
/// progress from 70 % to 90 %.
fn lspia(
    control: &mut PolyMesh,
    at_mesh: &LspiaAt,
    index: &SurfaceIndex,
    params: &FitParams,
    summary: &mut FitSummary,
    progress: &mut Progress,
) -> Result<(), Cancelled> {
    let LspiaAt {
        sharp,
        movable,
        on_crease,
        edge_length,
        scale,
    } = *at_mesh;
    let smooth = movable.iter().zip(on_crease).filter(|&(_, &c)| !c);
    let smooth: Vec<u32> = smooth.map(|(&v, _)| v).collect();
    let rule = params.boundary;
    let weights = hat_weights(control);
    let steps = params.lspia_iterations;
    let mut offsets: Vec<DVec3> = Vec::new();
    let mut chunk_offsets: Vec<DVec3> = Vec::new();
    let mut previous = vec![DVec3::ZERO; control.vertex_count()];
    for it in 0..steps {
        let message = format!("least-squares step {}", it + 1);
        let at = |done: f32| 0.7 + 0.2 * (it as f32 + done) / steps as f32;
        progress.report(at(0.0), &message)?;
        let samples = super::limit_mesh_creased(control, sharp, 1, rule).positions;
        debug_assert_eq!(samples.len(), weights.len());
        offsets.clear();
        for (c, chunk) in samples.chunks(4 * PROGRESS_CHUNK).enumerate() {
            if c > 0 {
                let done = (c * 4 * PROGRESS_CHUNK) as f32 / samples.len() as f32;
                progress.report(at(done), &message)?;
            }
            crate::parallel::map_into(chunk, &mut chunk_offsets, |&p| index.closest(p).point - p);
            offsets.extend_from_slice(&chunk_offsets);
        }
        let largest = lspia_move(
            &mut control.positions,
            &weights,
            &offsets,
            &smooth,
            &|v| params.ray_length * edge_length[v],
            &mut previous,
        );
        summary.lspia_iterations = it + 1;
        summary.lspia_max_move.push(largest);
        if largest < params.tolerance * scale {
            break;
        }
    }
    Ok(())
}

/// One LSPIA move (Deng and Lin 2014, with the momentum of the module
/// docs): each vertex of `movable` moves by [`LSPIA_STEP`] × the weighted
/// mean of the `offsets` of the samples that weigh on it (`weights`, one
/// list per sample) plus [`LSPIA_MOMENTUM`] × its `previous` move, clamped
/// to `bound(v)`. Returns the largest move.
pub(crate) fn lspia_move(
    positions: &mut [DVec3],
    weights: &[Vec<(u32, f64)>],
    offsets: &[DVec3],
    movable: &[u32],
    bound: &dyn Fn(usize) -> f64,
    previous: &mut [DVec3],
) -> f64 {
    let n = positions.len();
    let (mut sum, mut weight) = (vec![DVec3::ZERO; n], vec![0.0; n]);
    for (w, offset) in weights.iter().zip(offsets) {
        for &(v, x) in w {
            sum[v as usize] += x * *offset;
            weight[v as usize] += x;
        }
    }
    let mut largest = 0.0f64;
    for &v in movable {
        let v = v as usize;
        if weight[v] > 0.0 {
            let step = (LSPIA_STEP * sum[v] / weight[v] + LSPIA_MOMENTUM * previous[v])
                .clamp_length_max(bound(v));
            previous[v] = step;
            positions[v] += step;
            largest = largest.max(step.length());
        }
    }
    largest
}

/// Per vertex of `control` subdivided once (numbered as
/// [`subdivide_creased`] numbers them: control vertices, edge points, face
/// points), its bilinear weights on the control vertices: 1 on itself, ½
/// on each end of its edge, 1/n on each corner of its n-gon.
pub(crate) fn hat_weights(control: &PolyMesh) -> Vec<Vec<(u32, f64)>> {
    let mut weights: Vec<Vec<(u32, f64)>> = (0..control.vertex_count() as u32)
        .map(|v| vec![(v, 1.0)])
        .collect();
    for e in 0..control.edge_count() as u32 {
        let (a, b) = (control.origin(2 * e), control.tip(2 * e));
        weights.push(vec![(a, 0.5), (b, 0.5)]);
    }
    for f in 0..control.face_count() as u32 {
        let corners: Vec<u32> = control.face_vertices(f).collect();
        let x = 1.0 / corners.len() as f64;
        weights.push(corners.into_iter().map(|v| (v, x)).collect());
    }
    weights
}

/// The control mesh the fitting starts from, its sharp edges and how many
/// edges of `mesh` became creases: `mesh` with its edges along `curves`
/// sharp, split once (Catmull–Clark) when `split`, else as it is.
fn start_mesh(
    mesh: &PolyMesh,
    rule: BoundaryRule,
    curves: Option<&CurveIndex>,
    split: bool,
) -> (PolyMesh, Vec<bool>, usize) {
    let creases = curves.map_or_else(Vec::new, |curves| crease_edges(mesh, curves));
    let count = creases.iter().filter(|&&c| c).count();
    let (control, sharp) = if split {
        subdivide_creased(mesh, rule, &creases)
    } else {
        (mesh.clone(), creases)
    };
    (control, sharp, count)
}

/// The reference's feature curves: its interior edges whose faces' normals
/// differ by more than `degrees` ([`EdgeTopology::sharp_edges`]). `None`
/// when `degrees` is 0 or there are none.
pub(crate) fn feature_curves(reference: &TriMesh, degrees: f64) -> Option<CurveIndex> {
    if degrees.is_nan() || degrees <= 0.0 {
        return None;
    }
    let normals: Vec<DVec3> = (0..reference.face_count())
        .map(|f| reference.face_normal_unnormalized(f))
        .collect();
    let segments: Vec<[u32; 2]> = EdgeTopology::sharp_edges(reference, &normals, degrees, false)
        .iter()
        .map(|e| [e.a, e.b])
        .collect();
    CurveIndex::new(&reference.positions, &segments)
}

/// Which edges of `mesh` run along the feature curves: interior edges
/// whose two faces meet at a crease (normals more than 30° apart) and
/// whose points at 0, ¼, ½, ¾ and 1 of the way lie within a tenth of the
/// edge's length of the curves, the inner three on segments within 30° of
/// the edge's direction. So scan noise (short, scattered sharp input
/// edges) and edges that cross a feature make no creases.
pub fn crease_edges(mesh: &PolyMesh, curves: &CurveIndex) -> Vec<bool> {
    let cos_30 = 30f64.to_radians().cos();
    (0..mesh.edge_count() as u32)
        .map(|e| {
            let h = 2 * e;
            if mesh.is_boundary_halfedge(h) || mesh.is_boundary_halfedge(h ^ 1) {
                return false;
            }
            let (n1, n2) = (
                face_normal(mesh, mesh.face(h)).normalize_or_zero(),
                face_normal(mesh, mesh.face(h ^ 1)).normalize_or_zero(),
            );
            if n1 == DVec3::ZERO || n2 == DVec3::ZERO || n1.dot(n2) > cos_30 {
                return false;
            }
            let (a, b) = (
                mesh.positions[mesh.origin(h) as usize],
                mesh.positions[mesh.tip(h) as usize],
            );
            let length = a.distance(b);
            if length.is_nan() || length <= 0.0 {
                return false;
            }
            let direction = (b - a) / length;
            [0.0, 0.25, 0.5, 0.75, 1.0].iter().all(|&t| {
                let (_, distance, segment) = curves.closest(a.lerp(b, t));
                let along = t == 0.0
                    || t == 1.0
                    || curves.direction(segment).dot(direction).abs() >= cos_30;
                distance <= 0.1 * length && along
            })
        })
        .collect()
}

/// The move of one control vertex: from its limit point `l` along the unit
/// normal `n` to the nearest crossing of the input within `bound`, or the
/// normal component of the way to the closest point (second value `true`).
/// Never longer than `bound`.
fn offset_to_surface(index: &SurfaceIndex, l: DVec3, n: DVec3, bound: f64) -> (DVec3, bool) {
    if n == DVec3::ZERO || bound.is_nan() || bound <= 0.0 {
        return (DVec3::ZERO, true);
    }
    let (offset, missed) = match index.line(l, n, bound) {
        Some(hit) => (hit.point - l, false),
        None => {
            let c = index.closest(l).point;
            ((c - l).dot(n) * n, true)
        }
    };
    (offset.clamp_length_max(bound), missed)
}

/// Mean length of each vertex's edges.
pub(crate) fn mean_edge_lengths(mesh: &PolyMesh) -> Vec<f64> {
    (0..mesh.vertex_count() as u32)
        .map(|v| {
            let p = mesh.positions[v as usize];
            let (mut sum, mut n) = (0.0, 0usize);
            for h in mesh.outgoing(v) {
                sum += p.distance(mesh.positions[mesh.tip(h) as usize]);
                n += 1;
            }
            if n == 0 { 0.0 } else { sum / n as f64 }
        })
        .collect()
}
