//! Levenberg-Marquardt over the factors with a sparse Cholesky factorisation
//! (nalgebra-sparse) of the normal equations, heavy-tailed kernels by iteratively
//! reweighted least squares, and the marginal covariances of the poses by selected
//! inversion of the factor at the optimum.
//!
//! The variables are ordered poses first, in time, calibration variables last: the
//! normal matrix is a band (each factor touches neighbouring nodes) with a dense border,
//! whose Cholesky factor fills in nothing outside them, so no fill-reducing ordering is
//! needed.

use super::factor::{Factor, Linear};
use nalgebra::DVector;
use nalgebra_sparse::CscMatrix;
use nalgebra_sparse::factorization::CscCholesky;
use nalgebra_sparse::pattern::SparsityPattern;
use onebeacon::nav::Robust;

/// How the solver weighs and stops.
#[derive(Debug, Clone, Copy)]
pub(crate) struct SolveOptions {
    pub kernel: Option<Robust>,
    pub max_iterations: usize,
}

/// The optimum and how it was reached.
#[derive(Debug, Clone)]
pub(crate) struct Solution {
    pub x: Vec<f64>,
    pub iterations: usize,
    pub cost0: f64,
    pub cost: f64,
    /// The normal matrix's Cholesky factor at the optimum (for the marginals).
    pub chol: CscCholesky<f64>,
}

#[derive(Debug, thiserror::Error, PartialEq)]
pub enum SolveError {
    #[error(
        "the smoothing problem is not positive definite: a variable no factor constrains (a pose with no motion to the next, a calibration variable with no prior)"
    )]
    Singular,
}

/// The normal equations' pattern: the full symmetric matrix (the symbolic factorisation
/// reads its upper half, the numeric one its lower), with each factor's slots.
struct Normal {
    pattern: SparsityPattern,
    /// Per factor, the value index of each (row, col) of its variables, row-major.
    slots: Vec<Vec<usize>>,
    diag: Vec<usize>,
}

impl Normal {
    fn new(dim: usize, factors: &[Factor]) -> Self {
        let mut cols: Vec<Vec<usize>> = (0..dim).map(|i| vec![i]).collect();
        for f in factors {
            let (v, n) = f.vars();
            for &a in &v[..n] {
                cols[a].extend_from_slice(&v[..n]);
            }
        }
        let mut offsets = Vec::with_capacity(dim + 1);
        let mut rows = Vec::new();
        offsets.push(0);
        for c in &mut cols {
            c.sort_unstable();
            c.dedup();
            rows.extend_from_slice(c);
            offsets.push(rows.len());
        }
        let find = |col: usize, row: usize| {
            offsets[col]
                + rows[offsets[col]..offsets[col + 1]]
                    .binary_search(&row)
                    .unwrap_or_else(|_| unreachable!("pattern holds every pair"))
        };
        let slots = factors
            .iter()
            .map(|f| {
                let (v, n) = f.vars();
                v[..n].iter().flat_map(|&a| v[..n].iter().map(move |&b| (a, b))).map(|(a, b)| find(b, a)).collect()
            })
            .collect();
        let diag = (0..dim).map(|i| find(i, i)).collect();
        let pattern = SparsityPattern::try_from_offsets_and_indices(dim, dim, offsets, rows)
            .unwrap_or_else(|_| unreachable!("sorted, deduplicated, in range"));
        Self { pattern, slots, diag }
    }
}

/// The factor's weight under the kernel at its whitened residual (1 for Gaussian
/// factors), and its cost rho (d^2 / 2 when Gaussian).
fn weigh(f: &Factor, r: &[f64], kernel: Option<Robust>) -> (f64, f64) {
    let d2: f64 = r.iter().map(|v| v * v).sum();
    match kernel.filter(|_| f.is_measurement()) {
        Some(k) => (1.0 / k.inflation(d2, r.len()), -k.log_density(d2)),
        None => (1.0, 0.5 * d2),
    }
}

fn total_cost(factors: &[Factor], active: &[bool], x: &[f64], kernel: Option<Robust>) -> f64 {
    factors
        .iter()
        .zip(active)
        .filter(|(_, on)| **on)
        .map(|(f, _)| {
            let lin_r = local_residual(f, x);
            weigh(f, &lin_r.0[..lin_r.1], kernel).1
        })
        .sum()
}

fn local_residual(f: &Factor, x: &[f64]) -> ([f64; 3], usize) {
    let (v, n) = f.vars();
    let mut local = [0.0; super::factor::MAX_VARS];
    for (l, &i) in local.iter_mut().zip(&v[..n]) {
        *l = x[i];
    }
    f.residual(&local[..n])
}

/// Minimises the sum of the factors' costs (those `active`) from `x0`.
pub(crate) fn solve(
    factors: &[Factor],
    active: &[bool],
    x0: Vec<f64>,
    opt: SolveOptions,
) -> Result<Solution, SolveError> {
    let dim = x0.len();
    let normal = Normal::new(dim, factors);
    let nnz = normal.pattern.nnz();
    let mut values = vec![0.0; nnz];
    let mut g = DVector::zeros(dim);
    let mut x = x0;
    let build = |x: &[f64], values: &mut Vec<f64>, g: &mut DVector<f64>| {
        values.iter_mut().for_each(|v| *v = 0.0);
        g.fill(0.0);
        for ((f, slots), _) in factors.iter().zip(&normal.slots).zip(active).filter(|(_, on)| **on) {
            let Linear { m, n, vars, mut r, mut j } = f.linearize(x);
            let (w, _) = weigh(f, &r[..m], opt.kernel);
            let sw = w.sqrt();
            for row in 0..m {
                r[row] *= sw;
                j[row][..n].iter_mut().for_each(|v| *v *= sw);
            }
            for a in 0..n {
                g[vars[a]] += (0..m).map(|row| j[row][a] * r[row]).sum::<f64>();
                for b in 0..n {
                    values[slots[a * n + b]] += (0..m).map(|row| j[row][a] * j[row][b]).sum::<f64>();
                }
            }
        }
    };
    let cost0 = total_cost(factors, active, &x, opt.kernel);
    let mut cost = cost0;
    let mut lambda = 1e-6;
    let mut iterations = 0;
    let symbolic_matrix = |v: Vec<f64>| {
        CscMatrix::try_from_pattern_and_values(normal.pattern.clone(), v)
            .unwrap_or_else(|_| unreachable!("one value per slot"))
    };
    build(&x, &mut values, &mut g);
    let mut chol = CscCholesky::factor(&symbolic_matrix(values.clone())).map_err(|_| SolveError::Singular)?;
    while iterations < opt.max_iterations {
        iterations += 1;
        let mut damped = values.clone();
        for &d in &normal.diag {
            damped[d] += lambda * values[d].max(1e-9);
        }
        if chol.refactor(&damped).is_err() {
            lambda *= 10.0;
            continue;
        }
        let step = chol.solve(&(-&g));
        let trial: Vec<f64> = x.iter().zip(step.iter()).map(|(a, b)| a + b).collect();
        let trial_cost = total_cost(factors, active, &trial, opt.kernel);
        if trial_cost.is_finite() && trial_cost <= cost {
            let gain = cost - trial_cost;
            x = trial;
            cost = trial_cost;
            lambda = (lambda / 10.0).max(1e-12);
            build(&x, &mut values, &mut g);
            if gain <= 1e-10 * cost.max(1.0) || step.amax() < 1e-9 {
                break;
            }
        } else {
            lambda *= 10.0;
            if lambda > 1e12 {
                break;
            }
        }
    }
    chol.refactor(&values).map_err(|_| SolveError::Singular)?;
    Ok(Solution { x, iterations, cost0, cost, chol })
}

/// The entries of the inverse of L L^T on the pattern of L (Takahashi, Fagan and Chen's
/// recurrence): Z_ij = delta_ij / L_jj^2 - (1 / L_jj) sum_(k > j) L_kj Z_ik, from the last
/// column to the first. Returned as values aligned with L's pattern.
pub(crate) fn selected_inverse(l: &CscMatrix<f64>) -> Vec<f64> {
    let (offsets, rows, lv) = (l.col_offsets(), l.row_indices(), l.values());
    let mut z = vec![0.0; lv.len()];
    let at = |z: &[f64], r: usize, c: usize| {
        let (r, c) = if r >= c { (r, c) } else { (c, r) };
        let s = offsets[c];
        z[s + rows[s..offsets[c + 1]].binary_search(&r).unwrap_or_else(|_| unreachable!("pattern of L is closed"))]
    };
    for j in (0..l.ncols()).rev() {
        let (s, e) = (offsets[j], offsets[j + 1]);
        let ljj = lv[s];
        // below-diagonal entries from the bottom up, then the diagonal
        for p in (s + 1..e).rev() {
            let i = rows[p];
            let sum: f64 = (s + 1..e).map(|q| lv[q] * at(&z, i, rows[q])).sum();
            z[p] = -sum / ljj;
        }
        let sum: f64 = (s + 1..e).map(|q| lv[q] * z[q]).sum();
        z[s] = 1.0 / (ljj * ljj) - sum / ljj;
    }
    z
}

/// The 3 x 3 blocks (row-major) of the inverse at the given first indices.
pub(crate) fn marginal_blocks(
    l: &CscMatrix<f64>,
    z: &[f64],
    firsts: impl Iterator<Item = usize>,
) -> Vec<[[f64; 3]; 3]> {
    let (offsets, rows) = (l.col_offsets(), l.row_indices());
    let at = |r: usize, c: usize| {
        let (r, c) = if r >= c { (r, c) } else { (c, r) };
        let s = offsets[c];
        rows[s..offsets[c + 1]].binary_search(&r).map_or(0.0, |p| z[s + p])
    };
    firsts.map(|f| std::array::from_fn(|a| std::array::from_fn(|b| at(f + a, f + b)))).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::DMatrix;
    use nalgebra_sparse::CooMatrix;

    /// The selected inverse against the dense inverse, on a banded matrix with a dense
    /// border (the smoother's shape).
    #[test]
    fn selected_inverse_matches_the_dense_inverse() {
        let n = 12;
        let mut dense = DMatrix::<f64>::zeros(n, n);
        for i in 0..n {
            dense[(i, i)] = 4.0 + i as f64 * 0.1;
            if i + 1 < n - 2 {
                dense[(i, i + 1)] = -1.0;
                dense[(i + 1, i)] = -1.0;
            }
            if i < n - 2 {
                for b in n - 2..n {
                    dense[(i, b)] = 0.3;
                    dense[(b, i)] = 0.3;
                }
            }
        }
        let mut coo = CooMatrix::new(n, n);
        for i in 0..n {
            for j in 0..n {
                if dense[(i, j)] != 0.0 {
                    coo.push(i, j, dense[(i, j)]);
                }
            }
        }
        let chol = CscCholesky::factor(&CscMatrix::from(&coo)).unwrap();
        let z = selected_inverse(chol.l());
        let inv = dense.try_inverse().unwrap();
        let l = chol.l();
        for c in 0..n {
            let span = l.col_offsets()[c]..l.col_offsets()[c + 1];
            for (&r, zv) in l.row_indices()[span.clone()].iter().zip(&z[span]) {
                assert!((zv - inv[(r, c)]).abs() < 1e-12, "({r}, {c}): {zv} vs {}", inv[(r, c)]);
            }
        }
        let blocks = marginal_blocks(l, &z, [0, 4].into_iter());
        assert!((blocks[1][2][1] - inv[(6, 5)]).abs() < 1e-12);
    }
}
