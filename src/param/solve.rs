//! Sparse symmetric positive definite solves (faer's supernodal/simplicial
//! Cholesky), shared by the cross field, the seamless map and the layout
//! tool's strip field and parametrization. [`SpdPattern`] keeps the
//! symbolic factorization (fill-reducing ordering, elimination tree,
//! supernodes) of a sparsity pattern, so that systems whose entries lie in
//! it — the cross field's two relaxation matrices — only pay for the
//! numeric factorization.

use std::sync::Arc;

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::reborrow::ReborrowMut;
use faer::sparse::linalg::cholesky::{
    LltRef, SymbolicCholesky, SymmetricOrdering, factorize_symbolic_cholesky,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use faer::{Conj, Mat, MatMut, Side, c64};

/// A matrix entry type of the solves: real (f64) or complex (c64, a
/// Hermitian matrix, e.g. a connection Laplacian on complex face values).
pub trait Scalar: faer::traits::ComplexField + Copy + Default + std::ops::AddAssign {
    fn finite(self) -> bool;
}

impl Scalar for f64 {
    fn finite(self) -> bool {
        self.is_finite()
    }
}

impl Scalar for c64 {
    fn finite(self) -> bool {
        self.re.is_finite() && self.im.is_finite()
    }
}

/// The lower triangle's sparsity pattern of a symmetric matrix with its
/// symbolic Cholesky factorization.
pub struct SpdPattern {
    n: usize,
    pattern: Option<(SymbolicSparseColMat<usize>, Arc<SymbolicCholesky<usize>>)>,
}

/// Why [`SpdPattern::factor`] gave no factor.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FactorError {
    /// An entry lies outside the pattern (a new pattern is needed).
    OutsidePattern,
    /// The matrix is not numerically positive definite.
    NotPositiveDefinite,
}

fn lower<T: Scalar>(n: usize) -> impl Fn(&&(usize, usize, T)) -> bool {
    move |&&(r, c, v)| r >= c && r < n && v.finite()
}

impl SpdPattern {
    /// The pattern of the (summed, possibly repeated) triplets' lower
    /// triangle (`row ≥ col`) and its symbolic factorization.
    pub fn new<T: Scalar>(n: usize, triplets: &[(usize, usize, T)]) -> Option<SpdPattern> {
        let keys: Vec<u64> = triplets
            .iter()
            .filter(lower(n))
            .map(|&(r, c, _)| ((c as u64) << 32) | r as u64)
            .collect();
        SpdPattern::from_keys(n, keys)
    }

    /// The pattern of the entries `(col << 32) | row` (lower triangle),
    /// AMD-ordered.
    fn from_keys(n: usize, mut keys: Vec<u64>) -> Option<SpdPattern> {
        if n == 0 {
            return Some(SpdPattern { n, pattern: None });
        }
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
        let symbolic = factorize_symbolic_cholesky(
            pattern.as_ref(),
            Side::Lower,
            SymmetricOrdering::Amd,
            Default::default(),
        )
        .ok()?;
        Some(SpdPattern {
            n,
            pattern: Some((pattern, Arc::new(symbolic))),
        })
    }

    /// Stored entries of the Cholesky factor L.
    pub fn factor_entries(&self) -> usize {
        self.pattern.as_ref().map_or(0, |(_, s)| s.len_val())
    }

    /// Numeric factorization of the matrix given by triplets (lower
    /// triangle read) whose entries lie in the pattern.
    pub fn factor<T: Scalar>(
        &self,
        triplets: &[(usize, usize, T)],
    ) -> Result<SpdFactor<T>, FactorError> {
        let mut out = SpdFactor {
            n: self.n,
            llt: None,
        };
        self.refactor(triplets, &mut out)?;
        Ok(out)
    }

    /// [`SpdPattern::factor`] into `out`, reusing its storage when it
    /// holds a factor of this pattern's size.
    pub fn refactor<T: Scalar>(
        &self,
        triplets: &[(usize, usize, T)],
        out: &mut SpdFactor<T>,
    ) -> Result<(), FactorError> {
        let n = self.n;
        let Some((pattern, symbolic)) = &self.pattern else {
            *out = SpdFactor { n, llt: None };
            return Ok(());
        };
        let (col_ptr, row_idx) = (pattern.col_ptr(), pattern.row_idx());
        let mut values = vec![T::default(); row_idx.len()];
        for &(r, c, v) in triplets.iter().filter(lower(n)) {
            let (a, b) = (col_ptr[c], col_ptr[c + 1]);
            let k = row_idx[a..b]
                .binary_search(&r)
                .map_err(|_| FactorError::OutsidePattern)?;
            values[a + k] += v;
        }
        let a = SparseColMatRef::new(pattern.as_ref(), &values);
        let mut l = match out.llt.take() {
            Some((_, mut l)) if out.n == n => {
                l.clear();
                l
            }
            _ => Vec::new(),
        };
        l.resize(symbolic.len_val(), T::default());
        let par = faer::get_global_parallelism();
        let mut buffer =
            MemBuffer::new(symbolic.factorize_numeric_llt_scratch::<T>(par, Default::default()));
        symbolic
            .factorize_numeric_llt::<T>(
                &mut l,
                a,
                Side::Lower,
                Default::default(),
                par,
                MemStack::new(&mut buffer),
                Default::default(),
            )
            .map_err(|_| FactorError::NotPositiveDefinite)?;
        *out = SpdFactor {
            n,
            llt: Some((symbolic.clone(), l)),
        };
        Ok(())
    }
}

/// A factorized SPD (Hermitian positive definite for c64) matrix, for
/// several solves with one factorization.
pub struct SpdFactor<T = f64> {
    n: usize,
    llt: Option<(Arc<SymbolicCholesky<usize>>, Vec<T>)>,
}

impl<T: Scalar> SpdFactor<T> {
    /// No factor yet, of an n × n system (storage for [`SpdPattern::refactor`]).
    pub fn empty(n: usize) -> SpdFactor<T> {
        SpdFactor { n, llt: None }
    }

    /// Factorizes the matrix given by (summed, possibly repeated) triplets;
    /// only the lower triangle (`row ≥ col`) is read. None if it is not
    /// numerically positive definite.
    pub fn new(n: usize, triplets: &[(usize, usize, T)]) -> Option<SpdFactor<T>> {
        SpdPattern::new(n, triplets)?.factor(triplets).ok()
    }

    /// Solves for several right-hand sides (one triangular pass for all of
    /// them); None if the result is not finite.
    pub fn solve(&self, rhs: &[Vec<T>]) -> Option<Vec<Vec<T>>> {
        let Some((symbolic, values)) = &self.llt else {
            return Some(rhs.to_vec());
        };
        let mut b = Mat::<T>::zeros(self.n, rhs.len());
        for (j, col) in rhs.iter().enumerate() {
            for (i, &v) in col.iter().enumerate().take(self.n) {
                b[(i, j)] = v;
            }
        }
        let par = faer::get_global_parallelism();
        let mut buffer = MemBuffer::new(symbolic.solve_in_place_scratch::<T>(rhs.len(), par));
        LltRef::new(symbolic, values).solve_in_place_with_conj(
            Conj::No,
            b.as_mut(),
            par,
            MemStack::new(&mut buffer),
        );
        let out: Vec<Vec<T>> = (0..rhs.len())
            .map(|j| (0..self.n).map(|i| b[(i, j)]).collect())
            .collect();
        out.iter().flatten().all(|v| v.finite()).then_some(out)
    }
}

impl<T: Scalar> SpdFactor<T> {
    /// Solves in place for the columns of `rhs` (n rows); false if the
    /// result is not finite.
    pub fn solve_in_place(&self, mut rhs: MatMut<'_, T>) -> bool {
        if let Some((symbolic, values)) = &self.llt {
            let par = faer::get_global_parallelism();
            let mut buffer = MemBuffer::new(symbolic.solve_in_place_scratch::<T>(rhs.ncols(), par));
            LltRef::new(symbolic, values).solve_in_place_with_conj(
                Conj::No,
                rhs.rb_mut(),
                par,
                MemStack::new(&mut buffer),
            );
        }
        (0..rhs.ncols()).all(|j| (0..rhs.nrows()).all(|i| rhs[(i, j)].finite()))
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
