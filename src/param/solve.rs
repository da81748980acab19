//! Sparse symmetric positive definite solves (faer's supernodal/simplicial
//! Cholesky), shared by the cross field, the seamless map and the layout
//! tool's strip field and parametrization. [`SpdPattern`] keeps the
//! symbolic factorization (fill-reducing ordering, elimination tree,
//! supernodes) of a sparsity pattern, so that systems whose entries lie in
//! it — the integer rounding's re-solves, the cross field's two relaxation
//! matrices — only pay for the numeric factorization.

use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Llt, SymbolicLlt};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use faer::{Mat, Side};

/// The lower triangle's sparsity pattern of a symmetric matrix with its
/// symbolic Cholesky factorization.
pub struct SpdPattern {
    n: usize,
    pattern: Option<(SymbolicSparseColMat<usize>, SymbolicLlt<usize>)>,
}

/// Why [`SpdPattern::factor`] gave no factor.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FactorError {
    /// An entry lies outside the pattern (a new pattern is needed).
    OutsidePattern,
    /// The matrix is not numerically positive definite.
    NotPositiveDefinite,
}

fn lower(n: usize) -> impl Fn(&&(usize, usize, f64)) -> bool {
    move |&&(r, c, v)| r >= c && r < n && v.is_finite()
}

impl SpdPattern {
    /// The pattern of the (summed, possibly repeated) triplets' lower
    /// triangle (`row ≥ col`) and its symbolic factorization.
    pub fn new(n: usize, triplets: &[(usize, usize, f64)]) -> Option<SpdPattern> {
        if n == 0 {
            return Some(SpdPattern { n, pattern: None });
        }
        let mut keys: Vec<u64> = triplets
            .iter()
            .filter(lower(n))
            .map(|&(r, c, _)| ((c as u64) << 32) | r as u64)
            .collect();
        keys.sort_unstable();
        keys.dedup();
        let mut col_ptr = vec![0usize; n + 1];
        for &k in &keys {
            col_ptr[(k >> 32) as usize + 1] += 1;
        }
        for c in 0..n {
            col_ptr[c + 1] += col_ptr[c];
        }
        let row_idx: Vec<usize> = keys.iter().map(|&k| (k & 0xffff_ffff) as usize).collect();
        let pattern = SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx);
        let symbolic = SymbolicLlt::try_new(pattern.as_ref(), Side::Lower).ok()?;
        Some(SpdPattern {
            n,
            pattern: Some((pattern, symbolic)),
        })
    }

    /// Numeric factorization of the matrix given by triplets (lower
    /// triangle read) whose entries lie in the pattern.
    pub fn factor(&self, triplets: &[(usize, usize, f64)]) -> Result<SpdFactor, FactorError> {
        let n = self.n;
        let Some((pattern, symbolic)) = &self.pattern else {
            return Ok(SpdFactor { n, llt: None });
        };
        let (col_ptr, row_idx) = (pattern.col_ptr(), pattern.row_idx());
        let mut values = vec![0.0; row_idx.len()];
        for &(r, c, v) in triplets.iter().filter(lower(n)) {
            let (a, b) = (col_ptr[c], col_ptr[c + 1]);
            let k = row_idx[a..b]
                .binary_search(&r)
                .map_err(|_| FactorError::OutsidePattern)?;
            values[a + k] += v;
        }
        let a = SparseColMatRef::new(pattern.as_ref(), &values);
        let llt = Llt::try_new_with_symbolic(symbolic.clone(), a, Side::Lower)
            .map_err(|_| FactorError::NotPositiveDefinite)?;
        Ok(SpdFactor { n, llt: Some(llt) })
    }
}

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
        SpdPattern::new(n, triplets)?.factor(triplets).ok()
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
/// least-squares rows; `triplets` holds the lower triangle (`row ≥ col`),
/// all that [`SpdFactor`] reads.
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
            for &(j, cj) in entries.iter().filter(|e| e.0 <= i) {
                self.triplets.push((i, j, w2 * ci * cj));
            }
        }
    }
}
