//! Scale-aware filtered normals (Ebke, Campen, Bommes, Kobbelt 2014,
//! section 3, "Smooth Normals").
//!
//! The face normal field is convolved with a Gaussian over the surface,
//! `N̂(f) = Σ_{f' ∈ B_{2σ}(f)} N(f') G_σ(dist(c(f), c(f'))) A_{f'}`, and
//! renormalised. With σ = s/2 for the target edge length s, features closer
//! than s merge into one maximum, so detail, noise and small handles below
//! the target size do not make singularities in the fields. With a sizing
//! field, σ varies per face: σ(f) = S(f)/2.
//!
//! Decisions and deviations:
//! - Geodesic distance is approximated by Dijkstra over the dual graph:
//!   face barycentres, joined across shared edges by straight segments. This
//!   slightly overestimates distance (zig-zag paths), i.e. the kernel is a
//!   little narrower than nominal; the paper leaves the distance computation
//!   open.
//! - `A_{f'}` is the whole area of f' when its barycentre is within the
//!   truncation radius, and 0 otherwise (the paper clips faces to the ball).
//! - The normalisation constant 1/(2πσ²) is omitted: it cancels on
//!   renormalisation.
//! - σ ≤ 0 or non-finite gives the face normal itself (the σ → 0 limit). A
//!   neighbourhood whose normals cancel keeps the face normal.
//! - S(f), when derived from a per-vertex sizing field, is the mean of the
//!   face's three vertex edge lengths.

use std::cmp::Ordering;
use std::collections::BinaryHeap;

use glam::DVec3;
use serde::{Deserialize, Serialize};

use crate::mesh::{FaceAdjacency, TriMesh};

/// Whether and how normals are filtered.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FilteredNormalsMode {
    /// Filtered normals are the face normals.
    Off,
    /// σ = factor × global edge length everywhere (Ebke: σ = s/2).
    #[default]
    Global,
    /// σ(f) = factor × S(f) from the sizing field (Ebke's sizing-field variant).
    SizingAware,
}

/// Parameters of the normal filter.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct FilteredNormalsParams {
    /// Default [`FilteredNormalsMode::Global`].
    pub mode: FilteredNormalsMode,
    /// σ as a fraction of the edge length. Default 0.5 (Ebke: σ = s/2).
    pub sigma_factor: f64,
    /// Kernel truncation radius in units of σ. Default 2 (Ebke: r = 2σ).
    pub truncation: f64,
}

impl Default for FilteredNormalsParams {
    fn default() -> Self {
        FilteredNormalsParams {
            mode: FilteredNormalsMode::Global,
            sigma_factor: 0.5,
            truncation: 2.0,
        }
    }
}

/// The kernel width per face.
#[derive(Debug, Clone, Copy)]
pub enum Sigma<'a> {
    /// The same σ for every face.
    Uniform(f64),
    /// σ(f), one per face.
    PerFace(&'a [f64]),
}

/// σ(f) = `factor` × the mean of the face's vertex edge lengths.
pub fn face_sigma_from_sizing(mesh: &TriMesh, vertex_edge_length: &[f64], factor: f64) -> Vec<f64> {
    mesh.triangles
        .iter()
        .map(|t| {
            let sum: f64 = t
                .iter()
                .map(|&v| vertex_edge_length.get(v as usize).copied().unwrap_or(0.0))
                .sum();
            factor * sum / 3.0
        })
        .collect()
}

#[derive(PartialEq)]
struct Entry(f64, u32);

impl Eq for Entry {}

impl PartialOrd for Entry {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Entry {
    // Reversed: BinaryHeap pops the nearest face first; ties by index.
    fn cmp(&self, other: &Self) -> Ordering {
        other
            .0
            .total_cmp(&self.0)
            .then_with(|| other.1.cmp(&self.1))
    }
}

/// Filtered unit normal of every face (`face_normals` unit, one per face;
/// the result is unit, or zero for a zero-area face with no usable
/// neighbourhood).
pub fn filtered_normals(
    mesh: &TriMesh,
    adjacency: &FaceAdjacency,
    face_normals: &[DVec3],
    sigma: Sigma<'_>,
    truncation: f64,
) -> Vec<DVec3> {
    crate::progress::silently("filtered normals", |progress| {
        filtered_normals_with_progress(
            mesh,
            adjacency,
            face_normals,
            sigma,
            truncation,
            progress,
            0.0,
            1.0,
        )
    })
    .unwrap_or_default()
}

/// [`filtered_normals`], reporting the fraction done mapped to
/// `[from, to]` every 2048 faces; stops when the sink cancels.
#[allow(clippy::too_many_arguments)]
pub fn filtered_normals_with_progress(
    mesh: &TriMesh,
    adjacency: &FaceAdjacency,
    face_normals: &[DVec3],
    sigma: Sigma<'_>,
    truncation: f64,
    progress: &mut crate::progress::Progress<'_>,
    from: f32,
    to: f32,
) -> Result<Vec<DVec3>, crate::progress::Cancelled> {
    let faces = mesh.face_count().min(face_normals.len());
    let centroids: Vec<DVec3> = (0..faces)
        .map(|f| {
            let [a, b, c] = mesh.corners(f);
            (a + b + c) / 3.0
        })
        .collect();
    let areas: Vec<f64> = (0..faces).map(|f| mesh.face_area(f)).collect();
    // Dual-edge lengths, aligned with the adjacency rows (NaN marks a
    // neighbour index out of range, which is skipped).
    let csr = adjacency.csr();
    let rows = csr.rows().min(faces);
    let mut lengths = vec![f64::NAN; csr.items.len()];
    for f in 0..rows {
        let (start, end) = (csr.offsets[f] as usize, csr.offsets[f + 1] as usize);
        for (length, &k) in lengths[start..end].iter_mut().zip(&csr.items[start..end]) {
            if (k as usize) < faces {
                *length = centroids[f].distance(centroids[k as usize]);
            }
        }
    }
    let truncation = if truncation.is_finite() && truncation > 0.0 {
        truncation
    } else {
        2.0
    };
    let mut distance = vec![f64::INFINITY; faces];
    let mut stamp = vec![u32::MAX; faces];
    let mut heap = BinaryHeap::new();
    let mut out = Vec::with_capacity(faces);
    for f in 0..faces {
        if f % 2048 == 0 && f > 0 {
            let done = f as f32 / faces as f32;
            progress.report(from + (to - from) * done, "filtered normals")?;
        }
        let s = match sigma {
            Sigma::Uniform(s) => s,
            Sigma::PerFace(per_face) => per_face.get(f).copied().unwrap_or(0.0),
        };
        if !(s > 0.0 && s.is_finite()) {
            out.push(face_normals[f]);
            continue;
        }
        let radius = truncation * s;
        let inv_two_sigma_sq = 1.0 / (2.0 * s * s);
        let g = f as u32;
        heap.clear();
        stamp[f] = g;
        distance[f] = 0.0;
        heap.push(Entry(0.0, g));
        let mut sum = DVec3::ZERO;
        while let Some(Entry(d, h)) = heap.pop() {
            let h = h as usize;
            if d > distance[h] {
                continue;
            }
            sum += face_normals[h] * ((-d * d * inv_two_sigma_sq).exp() * areas[h]);
            if h >= rows {
                continue;
            }
            let (start, end) = (csr.offsets[h] as usize, csr.offsets[h + 1] as usize);
            for (&k, &length) in csr.items[start..end].iter().zip(&lengths[start..end]) {
                let k = k as usize;
                let nd = d + length;
                // NaN (out-of-range neighbour) fails the comparison.
                if nd <= radius && (stamp[k] != g || nd < distance[k]) {
                    stamp[k] = g;
                    distance[k] = nd;
                    heap.push(Entry(nd, k as u32));
                }
            }
        }
        out.push(sum.try_normalize().unwrap_or(face_normals[f]));
    }
    Ok(out)
}
