//! Levenberg-Marquardt over the factors with a sparse Cholesky factorisation
//! (nalgebra-sparse) of the normal equations, heavy-tailed kernels by iteratively
//! reweighted least squares, and the marginal covariances of the poses by selected
//! inversion of the factor at the optimum.
//!
//! The nodes (poses, or a track's positions and velocities) come first, in time: their
//! normal matrix A is a band (each factor touches
//! neighbouring nodes) whose Cholesky factor fills in nothing outside it, so no
//! fill-reducing ordering is needed. The few calibration variables, which every range
//! or motion factor touches, are a dense border [A B; B^T C] taken out by their Schur
//! complement S = C - B^T A^-1 B (a sparse factorisation of the whole would be
//! quadratic in the poses in nalgebra-sparse's symbolic analysis).

use super::factor::{Factor, Linear, Node};
use nalgebra::{DMatrix, DVector};
use nalgebra_sparse::CscMatrix;
use nalgebra_sparse::factorization::{CscCholesky, CscSymbolicCholesky};
use nalgebra_sparse::pattern::SparsityPattern;
use onebeacon::nav::Robust;

/// The solver stops when a step lowers the cost by less than this fraction (GTSAM's
/// relative error tolerance, as `../shared/bench/gtsam_smooth.py` sets it).
const RELATIVE_TOLERANCE: f64 = 1e-6;

/// Levenberg-Marquardt as GTSAM's `LevenbergMarquardtOptimizer` runs it by default: the
/// damping lambda I (identity, not the normal matrix's diagonal) starts at 1e-5, is divided
/// by 10 after a step that lowers the cost and multiplied by 10 after one that does not
/// (`lambdaInitial`, `lambdaFactor`, `diagonalDamping = false`). On plaza1 and plaza2, all
/// beacons and each alone, it takes the iterations GTSAM's takes (scripts/smooth_vs_gtsam.py).
const LAMBDA_INITIAL: f64 = 1e-5;
const LAMBDA_FACTOR: f64 = 10.0;
/// Damping this large and still no step lowers the cost: a minimum.
const LAMBDA_SETTLED: f64 = 1e12;

/// How the solver weighs, bounds and stops.
#[derive(Debug, Clone, Copy)]
pub(crate) struct SolveOptions<'a> {
    pub kernel: Option<Robust>,
    pub max_iterations: usize,
    /// Variables kept within (index, low, high): each step is projected on them.
    pub bounds: &'a [(usize, f64, f64)],
    /// What the nodes hold.
    pub node: Node,
}

/// The optimum, how it was reached, and the marginal covariances there.
#[derive(Debug, Clone)]
pub(crate) struct Solution {
    pub x: Vec<f64>,
    pub iterations: usize,
    /// Whether the cost settled (a step lowered it by less than the tolerance, or no
    /// step could lower it) before the iteration cap.
    pub converged: bool,
    pub cost0: f64,
    pub cost: f64,
    /// The covariance of each node's variables.
    pub nodes: Vec<DMatrix<f64>>,
    /// Covariance of the calibration variables.
    pub calibration: DMatrix<f64>,
}

#[derive(Debug, thiserror::Error, PartialEq)]
pub enum SolveError {
    #[error(
        "the smoothing problem is not positive definite: a variable no factor constrains (a pose with no motion to the next, a calibration variable with no prior)"
    )]
    Singular,
}

/// The node block's pattern: every factor touches at most two consecutive nodes, so
/// with a motion (or constant-velocity) factor between each two it is block tridiagonal
/// (blocks of a node's size), kept as the full symmetric matrix (the symbolic
/// factorisation reads its upper half, the numeric one its lower).
struct Pattern {
    pattern: SparsityPattern,
    nodes: usize,
    size: usize,
}

impl Pattern {
    fn new(poses: usize, size: usize) -> Self {
        let nodes = poses / size;
        let mut offsets = Vec::with_capacity(poses + 1);
        let mut rows = Vec::with_capacity(3 * size * poses);
        offsets.push(0);
        for c in 0..poses {
            let k = c / size;
            rows.extend(size * k.saturating_sub(1)..size * (k + 2).min(nodes));
            offsets.push(rows.len());
        }
        let pattern = SparsityPattern::try_from_offsets_and_indices(poses, poses, offsets, rows)
            .unwrap_or_else(|_| unreachable!("sorted, in range"));
        Self { pattern, nodes, size }
    }

    /// The value index of (row, col), both variables of neighbouring (or the same) nodes.
    fn slot(&self, row: usize, col: usize) -> usize {
        let first = self.size * (col / self.size).saturating_sub(1);
        debug_assert!(row >= first && row < self.size * (col / self.size + 2).min(self.nodes));
        self.pattern.major_offsets()[col] + row - first
    }
}

/// The normal equations at one point: the pose block A (values on the pattern), the
/// border B (poses x calibration) and C, the gradient g = J^T r.
#[derive(Clone)]
struct Normal {
    a: Vec<f64>,
    b: DMatrix<f64>,
    c: DMatrix<f64>,
    g: DVector<f64>,
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
            let (r, m) = f.whitened(x);
            weigh(f, &r[..m], kernel).1
        })
        .sum()
}

/// The problem: factors, which are active, the pose block's pattern.
struct Problem<'a> {
    factors: &'a [Factor],
    active: &'a [bool],
    pattern: Pattern,
    poses: usize,
    dim: usize,
    kernel: Option<Robust>,
}

impl Problem<'_> {
    /// The reweighted normal equations at `x`.
    fn normal(&self, x: &[f64]) -> Normal {
        let (p, k) = (self.poses, self.dim - self.poses);
        let mut ne = Normal {
            a: vec![0.0; self.pattern.pattern.nnz()],
            b: DMatrix::zeros(p, k),
            c: DMatrix::zeros(k, k),
            g: DVector::zeros(self.dim),
        };
        for (f, _) in self.factors.iter().zip(self.active).filter(|(_, on)| **on) {
            let Linear { m, n, vars, mut r, mut j } = f.linearize(x);
            let sw = weigh(f, &r[..m], self.kernel).0.sqrt();
            for row in 0..m {
                r[row] *= sw;
                j[row][..n].iter_mut().for_each(|v| *v *= sw);
            }
            for a in 0..n {
                ne.g[vars[a]] += (0..m).map(|row| j[row][a] * r[row]).sum::<f64>();
                for b in 0..n {
                    let h: f64 = (0..m).map(|row| j[row][a] * j[row][b]).sum();
                    match (vars[a] < p, vars[b] < p) {
                        (true, true) => ne.a[self.pattern.slot(vars[a], vars[b])] += h,
                        (true, false) => ne.b[(vars[a], vars[b] - p)] += h,
                        (false, true) => {}
                        (false, false) => ne.c[(vars[a] - p, vars[b] - p)] += h,
                    }
                }
            }
        }
        ne
    }

    /// Factors A + lambda I (a fresh factor the first time).
    fn factor(&self, chol: &mut Option<CscCholesky<f64>>, ne: &Normal, lambda: f64) -> bool {
        let mut a = ne.a.clone();
        for i in 0..self.poses {
            a[self.pattern.slot(i, i)] += lambda;
        }
        match chol {
            Some(c) => c.refactor(&a).is_ok(),
            None => {
                match CscCholesky::factor_numerical(CscSymbolicCholesky::factor(self.pattern.pattern.clone()), &a) {
                    Ok(c) => {
                        *chol = Some(c);
                        true
                    }
                    Err(_) => false,
                }
            }
        }
    }

    /// The Schur complement's pieces at a factored A: W = A^-1 B and the factored
    /// S = C + lambda I - B^T W.
    fn schur(
        &self,
        chol: &CscCholesky<f64>,
        ne: &Normal,
        lambda: f64,
    ) -> Option<(DMatrix<f64>, nalgebra::Cholesky<f64, nalgebra::Dyn>)> {
        let w = if ne.b.ncols() > 0 { chol.solve(&ne.b) } else { DMatrix::zeros(self.poses, 0) };
        let mut s = &ne.c - ne.b.transpose() * &w;
        for i in 0..s.nrows() {
            s[(i, i)] += lambda;
        }
        s.cholesky().map(|s| (w, s))
    }

    /// The LM step: [A B; B^T C] (damped) d = -g by the Schur complement.
    fn step(&self, ne: &Normal, lambda: f64, chol: &mut Option<CscCholesky<f64>>) -> Option<DVector<f64>> {
        if !self.factor(chol, ne, lambda) {
            return None;
        }
        let chol = chol.as_ref()?;
        let (w, s) = self.schur(chol, ne, lambda)?;
        let p = self.poses;
        let y = chol.solve(&ne.g.rows(0, p));
        let rhs = ne.b.transpose() * &y - ne.g.rows(p, self.dim - p);
        let dc = s.solve(&rhs);
        let da = -(&y + &w * &dc);
        let mut d = DVector::zeros(self.dim);
        d.rows_mut(0, p).copy_from(&da.column(0));
        d.rows_mut(p, self.dim - p).copy_from(&dc.column(0));
        Some(d)
    }
}

/// Minimises the sum of the factors' costs (those `active`) from `x0`, whose first
/// `poses` variables are the poses.
pub(crate) fn solve(
    factors: &[Factor],
    active: &[bool],
    x0: Vec<f64>,
    poses: usize,
    opt: SolveOptions,
) -> Result<Solution, SolveError> {
    let size = opt.node.size();
    let problem =
        Problem { factors, active, pattern: Pattern::new(poses, size), poses, dim: x0.len(), kernel: opt.kernel };
    let mut x = x0;
    let cost0 = total_cost(factors, active, &x, opt.kernel);
    let mut cost = cost0;
    let mut lambda = LAMBDA_INITIAL;
    // steps that lowered the cost (GTSAM's iterations; a rejected trial is not one)
    let mut iterations = 0;
    let mut chol = None;
    let mut ne = problem.normal(&x);
    let mut converged = false;
    while iterations < opt.max_iterations {
        if lambda >= LAMBDA_SETTLED {
            converged = true;
            break;
        }
        let Some(step) = problem.step(&ne, lambda, &mut chol) else {
            lambda *= LAMBDA_FACTOR;
            continue;
        };
        let mut trial = match opt.node {
            Node::Pose => retract(&x, &step, poses),
            Node::Track => x.iter().zip(step.iter()).map(|(a, b)| a + b).collect(),
        };
        for &(i, lo, hi) in opt.bounds {
            trial[i] = trial[i].clamp(lo, hi);
        }
        let trial_cost = total_cost(factors, active, &trial, opt.kernel);
        if !(trial_cost.is_finite() && trial_cost <= cost) {
            lambda *= LAMBDA_FACTOR;
            continue;
        }
        iterations += 1;
        let gain = cost - trial_cost;
        (x, cost) = (trial, trial_cost);
        lambda /= LAMBDA_FACTOR;
        ne = problem.normal(&x);
        if gain <= RELATIVE_TOLERANCE * cost || step.amax() < 1e-9 {
            converged = true;
            break;
        }
    }
    // the marginals at the optimum: Cov(nodes) = A^-1 + W S^-1 W^T, Cov(calibration) = S^-1
    if !problem.factor(&mut chol, &ne, 0.0) {
        return Err(SolveError::Singular);
    }
    let chol = chol.ok_or(SolveError::Singular)?;
    let (w, s) = problem.schur(&chol, &ne, 0.0).ok_or(SolveError::Singular)?;
    let s_inv = s.inverse();
    let l = chol.l();
    let z = selected_inverse(l);
    let mut blocks = marginal_blocks(l, &z, (0..poses / size).map(|k| size * k), size);
    if s_inv.nrows() > 0 {
        for (k, block) in blocks.iter_mut().enumerate() {
            let wk = w.rows(size * k, size);
            *block += wk * &s_inv * wk.transpose();
        }
    }
    Ok(Solution { x, iterations, converged, cost0, cost, nodes: blocks, calibration: s_inv })
}

/// The state `x` moved by the step `h` (solved in the global coordinates in which the
/// factors are linearised): each pose (north, east, heading) along the SE(2) exponential
/// of its increment read in its own body frame, x_k Exp(R(psi_k)^T dp, dpsi), so that a
/// pose that turns moves along an arc rather than its tangent; the calibration variables
/// by h. To first order this is x + h, the step the normal equations model; it is the
/// retraction of GTSAM's Pose2 (Expmap: t = V(dpsi) v, V = [[sin w / w, -(1 - cos w) / w],
/// [(1 - cos w) / w, sin w / w]]), and it takes plaza2's range-scale smoothing from 14
/// iterations to GTSAM's 6 (scripts/smooth_vs_gtsam.py).
pub(crate) fn retract(x: &[f64], h: &DVector<f64>, poses: usize) -> Vec<f64> {
    let mut out: Vec<f64> = x.iter().zip(h.iter()).map(|(a, b)| a + b).collect();
    for k in 0..poses / 3 {
        let (psi, w) = (x[3 * k + 2], h[3 * k + 2]);
        let (c, s) = (psi.cos(), psi.sin());
        // the increment in the body frame: R(psi)^T dp
        let (bx, by) = (c * h[3 * k] + s * h[3 * k + 1], -s * h[3 * k] + c * h[3 * k + 1]);
        let (a, b) = if w.abs() < 1e-9 { (1.0, 0.5 * w) } else { (w.sin() / w, (1.0 - w.cos()) / w) };
        let (vx, vy) = (a * bx - b * by, b * bx + a * by);
        out[3 * k] = x[3 * k] + c * vx - s * vy;
        out[3 * k + 1] = x[3 * k + 1] + s * vx + c * vy;
    }
    out
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

/// The `size` x `size` blocks of the inverse at the given first indices.
pub(crate) fn marginal_blocks(
    l: &CscMatrix<f64>,
    z: &[f64],
    firsts: impl Iterator<Item = usize>,
    size: usize,
) -> Vec<DMatrix<f64>> {
    let (offsets, rows) = (l.col_offsets(), l.row_indices());
    let at = |r: usize, c: usize| {
        let (r, c) = if r >= c { (r, c) } else { (c, r) };
        let s = offsets[c];
        rows[s..offsets[c + 1]].binary_search(&r).map_or(0.0, |p| z[s + p])
    };
    firsts.map(|f| DMatrix::from_fn(size, size, |a, b| at(f + a, f + b))).collect()
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
        let blocks = marginal_blocks(l, &z, [0, 4].into_iter(), 3);
        assert!((blocks[1][(2, 1)] - inv[(6, 5)]).abs() < 1e-12);
    }
}
