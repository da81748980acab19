//! Exact linear equality constraints by elimination (the way CoMISo, the
//! solver of Bommes et al. 2009, handles MIQ's seam, boundary and integer
//! constraints): each constraint `Σ c_i x_i = b` eliminates one variable,
//! kept fully reduced as an affine expression of the free variables, so
//! the remaining least-squares system is sparse SPD.

/// An affine expression `Σ c_j y_j + constant` of free variables.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Expr {
    pub terms: Vec<(usize, f64)>,
    pub constant: f64,
}

/// Coefficients below this are dropped (the constraints have small
/// integer coefficients, so exact cancellations are exact).
const TINY: f64 = 1e-12;

/// Variables `0..n`, some eliminated.
#[derive(Debug, Clone)]
pub struct Eliminator {
    expr: Vec<Option<Expr>>,
    /// Per free variable: eliminated variables whose expression uses it
    /// (may hold stale entries).
    users: Vec<Vec<usize>>,
    /// Variables below this index are preferred as pivots.
    preferred: usize,
}

/// The outcome of adding a constraint.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Added {
    Eliminated(usize),
    /// Implied by the earlier ones (residual within tolerance).
    Redundant,
    /// Contradicts the earlier ones by this residual.
    Conflict(f64),
}

impl Eliminator {
    pub fn new(n: usize, preferred: usize) -> Eliminator {
        Eliminator {
            expr: vec![None; n],
            users: vec![Vec::new(); n],
            preferred,
        }
    }

    pub fn len(&self) -> usize {
        self.expr.len()
    }

    pub fn is_empty(&self) -> bool {
        self.expr.is_empty()
    }

    pub fn is_free(&self, i: usize) -> bool {
        self.expr[i].is_none()
    }

    /// `Σ c_i x_i + constant` in free variables only.
    pub fn reduce(&self, terms: &[(usize, f64)], constant: f64) -> Expr {
        let mut out: Vec<(usize, f64)> = Vec::with_capacity(terms.len() * 2);
        let mut k = constant;
        for &(i, c) in terms {
            match &self.expr[i] {
                None => out.push((i, c)),
                Some(e) => {
                    k += c * e.constant;
                    out.extend(e.terms.iter().map(|&(j, d)| (j, c * d)));
                }
            }
        }
        Expr {
            terms: merge(out),
            constant: k,
        }
    }

    /// Adds `Σ c_i x_i = b`. The pivot is the first surviving term with a
    /// unit coefficient below the preferred index, else with a unit
    /// coefficient anywhere, else the first surviving term (below the
    /// preferred index first). Unit pivots keep integer expressions
    /// integer: at a quarter cone the seam constraints read
    /// (I − R) w = t, and solving them for w (coefficients ½) would make
    /// the translations half-integers once the cone is rounded, where
    /// solving for t keeps t integer for an integer w.
    pub fn add(&mut self, terms: &[(usize, f64)], b: f64, tolerance: f64) -> Added {
        let e = self.reduce(terms, -b);
        let pick = |e: &Expr| {
            let order: Vec<usize> = terms.iter().map(|t| t.0).collect();
            let first = |pred: &dyn Fn(usize, f64) -> bool| {
                order
                    .iter()
                    .copied()
                    .chain(e.terms.iter().map(|t| t.0))
                    .find(|&i| e.terms.iter().any(|t| t.0 == i && pred(i, t.1.abs())))
            };
            let unit = |c: f64| (c - 1.0).abs() < 1e-9;
            first(&|i, c| i < self.preferred && unit(c))
                .or_else(|| first(&|_, c| unit(c)))
                .or_else(|| first(&|i, c| i < self.preferred && c > 0.5))
                .or_else(|| first(&|_, c| c > 0.5))
        };
        let Some(p) = pick(&e).or_else(|| e.terms.first().map(|t| t.0)) else {
            return if e.constant.abs() <= tolerance {
                Added::Redundant
            } else {
                Added::Conflict(e.constant)
            };
        };
        let cp = e.terms.iter().find(|t| t.0 == p).map_or(1.0, |t| t.1);
        // x_p = −(Σ_{j≠p} c_j x_j + k) / c_p.
        let solved = Expr {
            terms: e
                .terms
                .iter()
                .filter(|t| t.0 != p)
                .map(|&(j, c)| (j, -c / cp))
                .collect(),
            constant: -e.constant / cp,
        };
        let mut users = std::mem::take(&mut self.users[p]);
        users.sort_unstable();
        users.dedup();
        for u in users {
            let Some(old) = self.expr[u].take() else {
                continue;
            };
            if !old.terms.iter().any(|t| t.0 == p) {
                // A stale entry: the expression no longer uses p.
                self.expr[u] = Some(old);
                continue;
            }
            let updated = self.substitute(&old, p, &solved);
            for &(j, _) in &updated.terms {
                if !old.terms.iter().any(|t| t.0 == j) {
                    self.users[j].push(u);
                }
            }
            self.expr[u] = Some(updated);
        }
        for &(j, _) in &solved.terms {
            self.users[j].push(p);
        }
        self.expr[p] = Some(solved);
        Added::Eliminated(p)
    }

    fn substitute(&self, e: &Expr, p: usize, by: &Expr) -> Expr {
        let c = e.terms.iter().find(|t| t.0 == p).map_or(0.0, |t| t.1);
        let mut terms: Vec<(usize, f64)> = e.terms.iter().copied().filter(|t| t.0 != p).collect();
        terms.extend(by.terms.iter().map(|&(j, d)| (j, c * d)));
        Expr {
            terms: merge(terms),
            constant: e.constant + c * by.constant,
        }
    }

    /// The value of every variable given the free ones' values.
    pub fn expand(&self, free: &[f64]) -> Vec<f64> {
        (0..self.expr.len())
            .map(|i| match &self.expr[i] {
                None => free[i],
                Some(e) => e.constant + e.terms.iter().map(|&(j, c)| c * free[j]).sum::<f64>(),
            })
            .collect()
    }
}

fn merge(mut terms: Vec<(usize, f64)>) -> Vec<(usize, f64)> {
    terms.sort_unstable_by_key(|t| t.0);
    let mut out: Vec<(usize, f64)> = Vec::with_capacity(terms.len());
    for (i, c) in terms {
        match out.last_mut() {
            Some(last) if last.0 == i => last.1 += c,
            _ => out.push((i, c)),
        }
    }
    out.retain(|t| t.1.abs() > TINY);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chain_of_equalities_reduces_to_one_free_variable() {
        let mut el = Eliminator::new(4, 4);
        assert_eq!(
            el.add(&[(1, 1.0), (0, -1.0)], 0.0, 1e-9),
            Added::Eliminated(1)
        );
        assert_eq!(
            el.add(&[(2, 1.0), (1, -1.0)], 1.0, 1e-9),
            Added::Eliminated(2)
        );
        assert_eq!(el.add(&[(0, 1.0)], 3.0, 1e-9), Added::Eliminated(0));
        assert_eq!(el.add(&[(2, 1.0)], 4.0, 1e-9), Added::Redundant);
        assert!(matches!(el.add(&[(2, 1.0)], 5.0, 1e-9), Added::Conflict(_)));
        let x = el.expand(&[0.0, 0.0, 0.0, 7.0]);
        assert_eq!(x, vec![3.0, 3.0, 4.0, 7.0]);
    }

    /// A quarter cone at w = (w0, w1) with seam translation t = (t0, t1):
    /// (I − R) w = t with R the quarter rotation, i.e. w0 + w1 = t0 and
    /// w1 − w0 = t1. With the wedge variables preferred, the unit pivot
    /// keeps t an integer expression of w: for an integer cone position
    /// the translations come out integer (solving for w would give
    /// w = ((t0 − t1)/2, (t0 + t1)/2)).
    #[test]
    fn quarter_cone_keeps_the_translations_integer() {
        let (w0, w1, t0, t1) = (0, 1, 2, 3);
        let mut el = Eliminator::new(4, 2);
        el.add(&[(w0, 1.0), (w1, 1.0), (t0, -1.0)], 0.0, 1e-9);
        el.add(&[(w1, 1.0), (w0, -1.0), (t1, -1.0)], 0.0, 1e-9);
        el.add(&[(w0, 1.0)], 3.0, 1e-9);
        el.add(&[(w1, 1.0)], -2.0, 1e-9);
        let x = el.expand(&[0.0; 4]);
        assert_eq!(x, vec![3.0, -2.0, 1.0, -5.0]);
        for q in [t0, t1] {
            assert!(el.reduce(&[(q, 1.0)], 0.0).terms.is_empty());
        }
    }
}
