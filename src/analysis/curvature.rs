//! Principal curvatures and directions per vertex (Kloiber thesis 3.1.1).
//!
//! **Cubic-order fit** (default; Goldfeather & Interrante 2004, as the thesis
//! uses it): in a local frame at vertex p — normal n as the height axis, any
//! tangent pair (u, v) — the n-ring neighbours q are fitted by
//! `z = A/2 x² + B xy + C/2 y² + D x³ + E x²y + F xy² + G y³`. Each neighbour
//! gives three equations: its height, and the two slopes `z_x = −a/c`,
//! `z_y = −b/c` from its vertex normal (a, b, c) in the frame. The 7 unknowns
//! are solved in the least-squares sense by a QR decomposition; the Weingarten
//! matrix is `[[A, B], [B, C]]`, its eigenvalues are the principal curvatures
//! and its eigenvectors the principal directions.
//!
//! **Discrete sums** (fast option; C. Dong & Wang 2005 as the thesis describes
//! it, Eq. 3.3): the normal curvature towards each neighbour is estimated from
//! the normal difference, `κ_n = (n_q − n)·(q − p) / |q − p|²`, and
//! `κ_n = a cos²Φ + b cosΦ sinΦ + c sin²Φ` is fitted over the neighbours, Φ
//! measured from the tangent towards the neighbour of largest |κ_n|.
//!
//! Decisions where the sources are vague, and deviations:
//! - Sign: κ > 0 where the surface bends away from its normal (a sphere with
//!   outward normals has κ = +1/r). Only |κ| matters downstream.
//! - `k1 ≥ k2` (signed order); `d1`, `d2` are unit, tangent, and
//!   `d2 = n × d1`.
//! - Coordinates are divided by the mean neighbour distance before the fit, so
//!   the solve is equally well conditioned at every scale and the result
//!   scales exactly as 1/scale.
//! - A neighbour whose normal is more than ~84° from n (`c < 0.1`; folds,
//!   flipped normals) contributes its height equation only — its slopes would
//!   be unbounded.
//! - Degradation: the cubic fit needs 7 independent equations; when the
//!   neighbourhood is too small or degenerate (R of the QR has a relative
//!   pivot below 1e-8) the quadratic fit (A, B, C only) is used, solved by an
//!   SVD that drops directions without data; with no usable neighbour the
//!   curvature is zero. Nothing returns NaN.
//! - The functions take positions, normals and a [`VertexAdjacency`] rather
//!   than triangles, so coarser hierarchy levels (vertex graphs) can re-estimate
//!   curvature the same way (thesis 3.1.4).

use glam::DVec3;
use nalgebra::{DMatrix, DVector, Matrix2, SymmetricEigen};
use serde::{Deserialize, Serialize};

use crate::mesh::{RingCollector, VertexAdjacency};

/// Principal curvatures and directions at one vertex.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PrincipalCurvature {
    /// Maximal principal curvature (signed, 1/length).
    pub k1: f64,
    /// Minimal principal curvature, `k2 ≤ k1`.
    pub k2: f64,
    /// Unit principal direction of `k1`.
    pub d1: DVec3,
    /// Unit principal direction of `k2`, `n × d1`.
    pub d2: DVec3,
}

impl PrincipalCurvature {
    /// Zero curvature with directions tangent to `normal`.
    pub fn flat(normal: DVec3) -> PrincipalCurvature {
        let n = normal.try_normalize().unwrap_or(DVec3::Z);
        let (d1, d2) = n.any_orthonormal_pair();
        PrincipalCurvature {
            k1: 0.0,
            k2: 0.0,
            d1,
            d2,
        }
    }

    /// `max(|κ1|, |κ2|)`.
    pub fn max_abs(&self) -> f64 {
        self.k1.abs().max(self.k2.abs())
    }

    /// `min(|κ1|, |κ2|)`.
    pub fn min_abs(&self) -> f64 {
        self.k1.abs().min(self.k2.abs())
    }

    /// Mean curvature `(κ1 + κ2) / 2`.
    pub fn mean(&self) -> f64 {
        0.5 * (self.k1 + self.k2)
    }

    pub fn gaussian(&self) -> f64 {
        self.k1 * self.k2
    }

    /// The scale-invariant anisotropy `κ3 = min|κ| / max|κ|` (Rugis & Klette
    /// 2006, thesis 3.3); 1 (isotropic) where both curvatures are zero.
    pub fn anisotropy(&self) -> f64 {
        let max = self.max_abs();
        if max > 0.0 { self.min_abs() / max } else { 1.0 }
    }

    /// Direction of the larger |κ| (across a ridge).
    pub fn max_abs_direction(&self) -> DVec3 {
        if self.k1.abs() >= self.k2.abs() {
            self.d1
        } else {
            self.d2
        }
    }

    /// Direction of the smaller |κ| (along a ridge or a cylinder's axis).
    pub fn min_abs_direction(&self) -> DVec3 {
        if self.k1.abs() >= self.k2.abs() {
            self.d2
        } else {
            self.d1
        }
    }
}

/// The curvature estimator.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CurvatureEstimator {
    /// Cubic-order surface fit with normals (Goldfeather & Interrante 2004).
    #[default]
    CubicFit,
    /// Least-squares fit of normal curvatures from normal differences
    /// (C. Dong & Wang 2005). Faster, less precise directions.
    DiscreteSums,
}

/// Parameters of the curvature estimation.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct CurvatureParams {
    /// Default: [`CurvatureEstimator::CubicFit`].
    pub estimator: CurvatureEstimator,
    /// Size of the neighbourhood in rings, 1–5 (clamped). Default 2
    /// (thesis 3.1.1: "empirically, a 2-ring neighbourhood is a reasonable
    /// choice").
    pub rings: u32,
}

impl Default for CurvatureParams {
    fn default() -> Self {
        CurvatureParams {
            estimator: CurvatureEstimator::CubicFit,
            rings: 2,
        }
    }
}

/// Principal curvatures of every vertex.
///
/// `positions` and unit `normals` are per vertex (same length as the
/// adjacency's vertex count; missing normals count as +z). Units: 1/length of
/// `positions`.
pub fn principal_curvatures(
    positions: &[DVec3],
    normals: &[DVec3],
    adjacency: &VertexAdjacency,
    params: &CurvatureParams,
) -> Vec<PrincipalCurvature> {
    crate::progress::silently("curvature", |progress| {
        principal_curvatures_with_progress(
            positions, normals, adjacency, params, progress, 0.0, 1.0,
        )
    })
    .unwrap_or_default()
}

/// [`principal_curvatures`], reporting the fraction done mapped to
/// `[from, to]` every 1024 vertices; stops when the sink cancels.
pub fn principal_curvatures_with_progress(
    positions: &[DVec3],
    normals: &[DVec3],
    adjacency: &VertexAdjacency,
    params: &CurvatureParams,
    progress: &mut crate::progress::Progress<'_>,
    from: f32,
    to: f32,
) -> Result<Vec<PrincipalCurvature>, crate::progress::Cancelled> {
    let count = positions.len().min(adjacency.vertex_count());
    let rings = params.rings.clamp(1, 5);
    let mut collector = RingCollector::new(count);
    let mut ring = Vec::new();
    let mut fit = Fit::default();
    let normal_of = |i: usize| normals.get(i).copied().unwrap_or(DVec3::Z);
    let mut out = Vec::with_capacity(positions.len());
    for v in 0..positions.len() {
        if v % 1024 == 0 && v > 0 {
            let done = v as f32 / positions.len() as f32;
            progress.report(from + (to - from) * done, "principal curvatures")?;
        }
        let normal = normal_of(v);
        if v >= count {
            out.push(PrincipalCurvature::flat(normal));
            continue;
        }
        collector.collect(adjacency, v, rings, &mut ring);
        let estimate = match params.estimator {
            CurvatureEstimator::CubicFit => fit.cubic(positions, &normal_of, v, normal, &ring),
            CurvatureEstimator::DiscreteSums => {
                discrete_sums(positions, &normal_of, v, normal, &ring)
            }
        };
        out.push(estimate.unwrap_or_else(|| PrincipalCurvature::flat(normal)));
    }
    Ok(out)
}

/// Reused buffers for the per-vertex fits.
#[derive(Default)]
struct Fit {
    /// Neighbours in the scaled local frame: (x, y, height, slopes if usable).
    local: Vec<LocalSample>,
    rows: Vec<f64>,
    rhs: Vec<f64>,
}

type LocalSample = (f64, f64, f64, Option<(f64, f64)>);

/// Smallest accepted relative pivot / singular value of a fit.
const RANK_TOLERANCE: f64 = 1e-8;
/// Neighbour normals closer than this to the tangent plane give no slopes.
const MIN_NORMAL_COSINE: f64 = 0.1;

impl Fit {
    fn cubic(
        &mut self,
        positions: &[DVec3],
        normal_of: &impl Fn(usize) -> DVec3,
        v: usize,
        normal: DVec3,
        ring: &[u32],
    ) -> Option<PrincipalCurvature> {
        let n = normal.try_normalize()?;
        let (u, w) = n.any_orthonormal_pair();
        let p = positions[v];

        // Local coordinates, scaled by the mean neighbour distance.
        let mut scale = 0.0;
        let mut used = 0usize;
        for &q in ring {
            let d = positions[q as usize] - p;
            let l = d.length();
            if l > 0.0 && l.is_finite() {
                scale += l;
                used += 1;
            }
        }
        if used == 0 {
            return None;
        }
        let h = scale / used as f64;
        if !(h > 0.0 && h.is_finite()) {
            return None;
        }
        self.local.clear();
        for &q in ring {
            let d = (positions[q as usize] - p) / h;
            if d.length_squared() < 1e-20 {
                continue;
            }
            let nq = normal_of(q as usize);
            let c = nq.dot(n);
            let slopes = (c > MIN_NORMAL_COSINE).then(|| (-nq.dot(u) / c, -nq.dot(w) / c));
            self.local.push((d.dot(u), d.dot(w), d.dot(n), slopes));
        }

        let coefficients = self.solve_cubic().or_else(|| self.solve_quadratic())?;
        let (a, b, c) = (
            coefficients[0] / h,
            coefficients[1] / h,
            coefficients[2] / h,
        );
        // The fit's second fundamental form w.r.t. +n is [[A, B], [B, C]];
        // our sign convention (convex positive) negates it.
        principal_from_form(-a, -b, -c, n, u, w)
    }

    /// The full cubic fit; `None` when the system has fewer than 7
    /// independent equations.
    fn solve_cubic(&mut self) -> Option<[f64; 3]> {
        self.rows.clear();
        self.rhs.clear();
        for &(x, y, z, slopes) in &self.local {
            self.rows.extend_from_slice(&[
                0.5 * x * x,
                x * y,
                0.5 * y * y,
                x * x * x,
                x * x * y,
                x * y * y,
                y * y * y,
            ]);
            self.rhs.push(z);
            if let Some((zx, zy)) = slopes {
                self.rows
                    .extend_from_slice(&[x, y, 0.0, 3.0 * x * x, 2.0 * x * y, y * y, 0.0]);
                self.rhs.push(zx);
                self.rows
                    .extend_from_slice(&[0.0, x, y, 0.0, x * x, 2.0 * x * y, 3.0 * y * y]);
                self.rhs.push(zy);
            }
        }
        let m = self.rhs.len();
        if m < 7 {
            return None;
        }
        let a = DMatrix::from_row_slice(m, 7, &self.rows);
        let mut b = DVector::from_column_slice(&self.rhs);
        let qr = a.qr();
        let r = qr.r();
        let largest = (0..7).map(|i| r[(i, i)].abs()).fold(0.0, f64::max);
        if largest.is_nan()
            || largest <= 0.0
            || (0..7).any(|i| r[(i, i)].abs() < RANK_TOLERANCE * largest)
        {
            return None;
        }
        qr.q_tr_mul(&mut b);
        let x = r.solve_upper_triangular(&b.rows(0, 7).into_owned())?;
        let coefficients = [x[0], x[1], x[2]];
        coefficients
            .iter()
            .all(|c| c.is_finite())
            .then_some(coefficients)
    }

    /// The quadratic fit (A, B, C) by SVD, dropping unobserved directions.
    fn solve_quadratic(&mut self) -> Option<[f64; 3]> {
        self.rows.clear();
        self.rhs.clear();
        for &(x, y, z, slopes) in &self.local {
            self.rows
                .extend_from_slice(&[0.5 * x * x, x * y, 0.5 * y * y]);
            self.rhs.push(z);
            if let Some((zx, zy)) = slopes {
                self.rows.extend_from_slice(&[x, y, 0.0]);
                self.rhs.push(zx);
                self.rows.extend_from_slice(&[0.0, x, y]);
                self.rhs.push(zy);
            }
        }
        least_squares_svd(&self.rows, &self.rhs, 3).map(|x| [x[0], x[1], x[2]])
    }
}

/// Minimum-norm least-squares solution of `rows · x = rhs` (`rows` row-major
/// with `columns` columns), singular values below the relative tolerance
/// dropped.
fn least_squares_svd(rows: &[f64], rhs: &[f64], columns: usize) -> Option<Vec<f64>> {
    let m = rhs.len();
    if m == 0 {
        return None;
    }
    let a = DMatrix::from_row_slice(m, columns, rows);
    let b = DVector::from_column_slice(rhs);
    let svd = a.svd(true, true);
    let largest = svd.singular_values.max();
    if !(largest > 0.0 && largest.is_finite()) {
        return None;
    }
    let x = svd.solve(&b, RANK_TOLERANCE * largest).ok()?;
    x.iter()
        .all(|c| c.is_finite())
        .then(|| x.iter().copied().collect())
}

/// Principal curvatures of the symmetric form `[[a, b], [b, c]]` expressed in
/// the tangent basis (u, w) of normal n.
fn principal_from_form(
    a: f64,
    b: f64,
    c: f64,
    n: DVec3,
    u: DVec3,
    w: DVec3,
) -> Option<PrincipalCurvature> {
    if !(a.is_finite() && b.is_finite() && c.is_finite()) {
        return None;
    }
    let eigen = SymmetricEigen::new(Matrix2::new(a, b, b, c));
    let (i, j) = if eigen.eigenvalues[0] >= eigen.eigenvalues[1] {
        (0, 1)
    } else {
        (1, 0)
    };
    let e = eigen.eigenvectors.column(i);
    let d1 = (e[0] * u + e[1] * w).try_normalize()?;
    let d2 = n.cross(d1).try_normalize()?;
    let result = PrincipalCurvature {
        k1: eigen.eigenvalues[i],
        k2: eigen.eigenvalues[j],
        d1,
        d2,
    };
    (result.k1.is_finite() && result.k2.is_finite()).then_some(result)
}

/// Dong & Wang's normal-curvature fit at vertex `v`.
fn discrete_sums(
    positions: &[DVec3],
    normal_of: &impl Fn(usize) -> DVec3,
    v: usize,
    normal: DVec3,
    ring: &[u32],
) -> Option<PrincipalCurvature> {
    let n = normal.try_normalize()?;
    let p = positions[v];
    // (unit tangent towards the neighbour, normal curvature towards it)
    let mut samples: Vec<(DVec3, f64)> = Vec::with_capacity(ring.len());
    for &q in ring {
        let d = positions[q as usize] - p;
        let l2 = d.length_squared();
        let Some(t) = (d - d.dot(n) * n).try_normalize() else {
            continue;
        };
        let kn = (normal_of(q as usize) - n).dot(d) / l2;
        if l2 > 0.0 && kn.is_finite() {
            samples.push((t, kn));
        }
    }
    let reference = samples
        .iter()
        .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
        .map(|s| s.0)?;
    let other = n.cross(reference);
    let mut rows = Vec::with_capacity(samples.len() * 3);
    let mut rhs = Vec::with_capacity(samples.len());
    for &(t, kn) in &samples {
        let (cos, sin) = (t.dot(reference), t.dot(other));
        rows.extend_from_slice(&[cos * cos, cos * sin, sin * sin]);
        rhs.push(kn);
    }
    let x = least_squares_svd(&rows, &rhs, 3)?;
    principal_from_form(x[0], 0.5 * x[1], x[2], n, reference, other)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::normals::{NormalWeighting, vertex_normals};
    use crate::mesh::{TriMesh, generate};

    fn estimate(mesh: &TriMesh, params: &CurvatureParams) -> Vec<PrincipalCurvature> {
        let normals = vertex_normals(mesh, NormalWeighting::Angle);
        principal_curvatures(
            &mesh.positions,
            &normals,
            &VertexAdjacency::new(mesh),
            params,
        )
    }

    #[test]
    fn tiny_meshes_give_finite_curvature() {
        let tri = TriMesh::new(vec![DVec3::ZERO, DVec3::X, DVec3::Y], vec![[0, 1, 2]]).unwrap();
        for estimator in [
            CurvatureEstimator::CubicFit,
            CurvatureEstimator::DiscreteSums,
        ] {
            for rings in [1, 2, 5] {
                let params = CurvatureParams { estimator, rings };
                for m in [&tri, &generate::tetrahedron()] {
                    for c in estimate(m, &params) {
                        assert!(c.k1.is_finite() && c.k2.is_finite());
                        assert!(c.d1.is_finite() && c.d2.is_finite());
                        assert!((c.d1.length() - 1.0).abs() < 1e-9);
                        assert!(c.k1 >= c.k2);
                    }
                }
            }
        }
        // A flat triangle has no curvature.
        for c in estimate(&tri, &CurvatureParams::default()) {
            assert!(c.max_abs() < 1e-12);
        }
    }

    #[test]
    fn discrete_sums_on_a_sphere() {
        let m = generate::icosphere(2.0, 4);
        let params = CurvatureParams {
            estimator: CurvatureEstimator::DiscreteSums,
            rings: 1,
        };
        for c in estimate(&m, &params) {
            assert!(
                (c.k1 - 0.5).abs() < 0.02 && (c.k2 - 0.5).abs() < 0.02,
                "{c:?}"
            );
        }
    }
}
