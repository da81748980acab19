//! Sparse symmetric positive definite solves (faer's supernodal/simplicial
//! Cholesky), shared by the cross field, the seamless map and the layout
//! tool's strip field and parametrization.

use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::Llt;
use faer::sparse::{SparseColMat, Triplet};
use faer::{Mat, Side};

/// A factorized SPD matrix, for several solves with one factorization.
pub struct SpdFactor {
    n: usize,
    llt: Option<Llt<usize, f64>>,
}

impl SpdFactor {
    /// Factorizes the matrix given by (summed, possibly repeated) triplets;
    /// only the lower triangle (`row ≥ col`) is read. None if it is not
    /// numerically positive definite.
    pub fn new(n: usize, triplets: &[(usize, usize, f64)]) -> Option<SpdFactor> {
        if n == 0 {
            return Some(SpdFactor { n, llt: None });
        }
        let entries: Vec<Triplet<usize, usize, f64>> = triplets
            .iter()
            .filter(|&&(r, c, v)| r >= c && r < n && v.is_finite())
            .map(|&(r, c, v)| Triplet::new(r, c, v))
            .collect();
        let a = SparseColMat::<usize, f64>::try_new_from_triplets(n, n, &entries).ok()?;
        let llt = a.sp_cholesky(Side::Lower).ok()?;
        Some(SpdFactor { n, llt: Some(llt) })
    }

    /// Solves for several right-hand sides; None if the result is not finite.
    pub fn solve(&self, rhs: &[Vec<f64>]) -> Option<Vec<Vec<f64>>> {
        let Some(llt) = &self.llt else {
            return Some(rhs.to_vec());
        };
        let mut b = Mat::<f64>::zeros(self.n, rhs.len());
        for (j, col) in rhs.iter().enumerate() {
            for (i, &v) in col.iter().enumerate().take(self.n) {
                b[(i, j)] = v;
            }
        }
        llt.solve_in_place(b.as_mut());
        let out: Vec<Vec<f64>> = (0..rhs.len())
            .map(|j| (0..self.n).map(|i| b[(i, j)]).collect())
            .collect();
        out.iter().flatten().all(|v| v.is_finite()).then_some(out)
    }
}

/// Solves the symmetric positive definite system given by (summed)
/// triplets, for several right-hand sides; None if the factorization fails.
pub fn solve_spd(
    n: usize,
    triplets: &[(usize, usize, f64)],
    rhs: &[Vec<f64>],
) -> Option<Vec<Vec<f64>>> {
    SpdFactor::new(n, triplets)?.solve(rhs)
}

/// Accumulates the normal equations `AᵀA x = Aᵀb` of weighted
/// least-squares rows.
#[derive(Debug, Clone, Default)]
pub struct NormalEquations {
    pub triplets: Vec<(usize, usize, f64)>,
    pub rhs: Vec<f64>,
}

impl NormalEquations {
    pub fn new(n: usize) -> NormalEquations {
        NormalEquations {
            triplets: Vec::new(),
            rhs: vec![0.0; n],
        }
    }

    /// Adds the row `w · (Σ c_i x_i − b)`.
    pub fn row(&mut self, w: f64, entries: &[(usize, f64)], b: f64) {
        let w2 = w * w;
        for &(i, ci) in entries {
            self.rhs[i] += w2 * ci * b;
            for &(j, cj) in entries {
                self.triplets.push((i, j, w2 * ci * cj));
            }
        }
    }
}
