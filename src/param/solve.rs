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

/// Sparse forward substitution with a supernodal Cholesky factor
/// (A = Pᵀ L Lᵀ P): for a sparse b, w = L⁻¹ P b is non-zero only on the
/// supernodes of the elimination tree's paths from b's rows to the root,
/// and only those are visited (Gilbert & Peierls' reach, by supernodes).
/// Two such vectors give bᵀ A⁻¹ c = wᵀ v, a Schur complement's entries,
/// for the cost of the paths instead of two whole triangular solves per
/// column.
pub struct ForwardSubstitution<'a> {
    symbolic: &'a faer::sparse::linalg::cholesky::supernodal::SymbolicSupernodalCholesky<usize>,
    values: &'a [f64],
    /// Per original row, its row in the factor (P's inverse).
    inv: Option<&'a [usize]>,
    /// Per (permuted) row, its supernode.
    supernode_of: Vec<usize>,
    /// Per supernode, its parent (`usize::MAX` at a root).
    parent: Vec<usize>,
    x: Vec<f64>,
    reached: Vec<bool>,
}

impl SpdFactor<f64> {
    /// The factor's sparse forward substitution; None when the factor is
    /// simplicial (small or very sparse systems) or empty.
    pub fn forward_substitution(&self) -> Option<ForwardSubstitution<'_>> {
        let (symbolic, values) = self.llt.as_ref()?;
        let faer::sparse::linalg::cholesky::SymbolicCholeskyRaw::Supernodal(sn) = symbolic.raw()
        else {
            return None;
        };
        let count = sn.n_supernodes();
        let (begin, end) = (sn.supernode_begin(), sn.supernode_end());
        let mut supernode_of = vec![0; self.n];
        for s in 0..count {
            supernode_of[begin[s]..end[s]].fill(s);
        }
        let (ptr, rows) = (sn.col_ptr_for_row_idx(), sn.row_idx());
        let parent = (0..count)
            .map(|s| {
                // The first row below the supernode lies in its parent.
                rows[ptr[s]..ptr[s + 1]]
                    .iter()
                    .min()
                    .map_or(usize::MAX, |&r| supernode_of[r])
            })
            .collect();
        Some(ForwardSubstitution {
            symbolic: sn,
            values,
            inv: symbolic.perm().map(|p| p.arrays().1),
            supernode_of,
            parent,
            x: vec![0.0; self.n],
            reached: vec![false; count],
        })
    }
}

impl ForwardSubstitution<'_> {
    /// w = L⁻¹ P b for b given by (row, value) entries (rows of the
    /// original matrix, summed when repeated): its non-zero entries as
    /// (factor row, value), rows ascending.
    pub fn solve(&mut self, b: &[(usize, f64)]) -> Vec<(usize, f64)> {
        let sn = self.symbolic;
        let mut list = Vec::new();
        for &(r, v) in b {
            let i = self.inv.map_or(r, |inv| inv[r]);
            self.x[i] += v;
            let mut s = self.supernode_of[i];
            while s != usize::MAX && !self.reached[s] {
                self.reached[s] = true;
                list.push(s);
                s = self.parent[s];
            }
        }
        // Children come before their parents in the supernodes' order.
        list.sort_unstable();
        let (begin, end) = (sn.supernode_begin(), sn.supernode_end());
        let (ptr, rows, val_ptr) = (sn.col_ptr_for_row_idx(), sn.row_idx(), sn.col_ptr_for_val());
        for &s in &list {
            let (start, size) = (begin[s], end[s] - begin[s]);
            let pattern = &rows[ptr[s]..ptr[s + 1]];
            let height = size + pattern.len();
            // Column-major, `height` rows: the lower-triangular diagonal
            // block over the rows below.
            let l = &self.values[val_ptr[s]..val_ptr[s + 1]];
            for j in 0..size {
                let col = &l[j * height..(j + 1) * height];
                let xj = self.x[start + j] / col[j];
                self.x[start + j] = xj;
                if xj == 0.0 {
                    continue;
                }
                for i in j + 1..size {
                    self.x[start + i] -= col[i] * xj;
                }
                for (k, &r) in pattern.iter().enumerate() {
                    self.x[r] -= col[size + k] * xj;
                }
            }
        }
        // Every row touched lies in a reached supernode (the rows below a
        // supernode are its ancestors').
        let mut out = Vec::new();
        for &s in &list {
            self.reached[s] = false;
            for i in begin[s]..end[s] {
                if self.x[i] != 0.0 {
                    out.push((i, self.x[i]));
                }
                self.x[i] = 0.0;
            }
        }
        out
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

#[cfg(test)]
mod tests {
    use super::*;

    fn sparse_dot(a: &[(usize, f64)], b: &[(usize, f64)]) -> f64 {
        let (mut i, mut j, mut sum) = (0, 0, 0.0);
        while i < a.len() && j < b.len() {
            match a[i].0.cmp(&b[j].0) {
                std::cmp::Ordering::Less => i += 1,
                std::cmp::Ordering::Greater => j += 1,
                std::cmp::Ordering::Equal => {
                    sum += a[i].1 * b[j].1;
                    i += 1;
                    j += 1;
                }
            }
        }
        sum
    }

    /// ⟨L⁻¹Pb, L⁻¹Pc⟩ = bᵀA⁻¹c against full solves, on a grid Laplacian
    /// (with a random positive diagonal and edge weights) large enough for
    /// a supernodal factor; a one-entry b reaches only part of the rows.
    #[test]
    fn sparse_forward_substitution_gives_the_inverse_form() {
        let m = 150;
        let n = m * m;
        let mut seed = 12345u64;
        let mut next = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut t = Vec::new();
        for i in 0..m {
            for j in 0..m {
                let a = i * m + j;
                t.push((a, a, 0.01 + next()));
                for b in [(i + 1 < m).then(|| a + m), (j + 1 < m).then(|| a + 1)]
                    .into_iter()
                    .flatten()
                {
                    let w = 0.5 + next();
                    t.extend([(a, a, w), (b, b, w), (b, a, -w)]);
                }
            }
        }
        let factor = SpdFactor::new(n, &t).expect("SPD");
        let mut forward = factor
            .forward_substitution()
            .expect("a supernodal factor at this size");
        let mut bs: Vec<Vec<(usize, f64)>> = vec![
            vec![(0, 1.0)],
            vec![(n / 2 + 7, -2.0), (n / 2 + 8, 1.0)],
            vec![(3 * m + 5, 1.0), (n - 1, 0.5), (3 * m + 5, 0.25)],
            vec![(17, 1.0), (2 * m, -1.0)],
        ];
        bs.push((0..n).map(|i| (i, next() - 0.5)).collect());
        let ws: Vec<Vec<(usize, f64)>> = bs.iter().map(|b| forward.solve(b)).collect();
        assert!(
            ws[0].len() < n / 4,
            "{} of {n} rows reached from one entry",
            ws[0].len()
        );
        let dense: Vec<Vec<f64>> = bs
            .iter()
            .map(|b| {
                let mut d = vec![0.0; n];
                for &(i, v) in b {
                    d[i] += v;
                }
                d
            })
            .collect();
        let solved = factor.solve(&dense).expect("solved");
        for i in 0..bs.len() {
            for j in 0..bs.len() {
                let want: f64 = dense[i].iter().zip(&solved[j]).map(|(a, b)| a * b).sum();
                let got = sparse_dot(&ws[i], &ws[j]);
                assert!(
                    (got - want).abs() <= 1e-10 * want.abs().max(1e-3),
                    "b{i}ᵀA⁻¹b{j}: {got} vs {want}"
                );
            }
        }
    }
}
