//! A position from ranges alone: robust multilateration, for starting a filter whose
//! initial position is unknown or doubtful (a log's `[initial] from = "ranges"`).

use nalgebra::{Matrix2, Vector2, Vector3};

/// A horizontal position fix from ranges.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fix {
    /// North, east, m.
    pub position: Vector2<f64>,
    /// Its covariance, m^2: the robust residual scale squared times (J' W J)^-1.
    pub covariance: Matrix2<f64>,
    /// The robust scale of the residuals, m (1.4826 x their median absolute value).
    pub residual_sigma_m: f64,
    /// Ranges whose residual is beyond 3 robust sigmas (outliers the fit set aside).
    pub outliers: usize,
}

/// Huber's threshold, in robust sigmas of the residuals.
const HUBER_K: f64 = 1.345;

/// The horizontal position (at depth `depth_m`) that best explains `ranges` (beacon
/// id, position NED, range m; a moving vehicle's ranges can each give the beacon's
/// position shifted by the vehicle's displacement): iteratively reweighted Gauss-Newton
/// with Huber weights on the residuals, scaled by their median absolute deviation, from
/// five starts about the beacons (their centroid and four points half their spread
/// away), on all ranges and, with four beacons or more, on all but one beacon's (a burst
/// of false ranges to one beacon can pull every start of the whole set), each fit then
/// judged on all ranges; the one with the smallest median residual is kept (least
/// median of squares: it holds while most ranges are true) and solved again on the
/// ranges within 3 robust sigmas of it. None with fewer than
/// three distinct beacons, or beacons in a line (the position and its mirror image
/// through the line explain the ranges alike).
pub fn multilaterate(ranges: &[(u32, Vector3<f64>, f64)], depth_m: f64) -> Option<Fix> {
    let mut ids: Vec<u32> = ranges.iter().map(|r| r.0).collect();
    ids.sort_unstable();
    ids.dedup();
    let mut distinct: Vec<Vector2<f64>> = Vec::new();
    for (_, b, _) in ranges {
        if !distinct.iter().any(|d| (d - b.xy()).norm() < 1e-6) {
            distinct.push(b.xy());
        }
    }
    if ids.len() < 3 || distinct.len() < 3 {
        return None;
    }
    let centroid = distinct.iter().sum::<Vector2<f64>>() / distinct.len() as f64;
    // beacons in a line: every position has a mirror image through it
    let scatter: Matrix2<f64> = distinct.iter().map(|d| (d - centroid) * (d - centroid).transpose()).sum();
    let e = scatter.symmetric_eigenvalues();
    if e.min() <= 1e-6 * e.max() {
        return None;
    }
    let spread = distinct.iter().map(|d| (d - centroid).norm()).fold(0.0, f64::max).max(1.0);
    let h = spread / 2.0;
    let starts =
        [Vector2::zeros(), Vector2::new(h, 0.0), Vector2::new(-h, 0.0), Vector2::new(0.0, h), Vector2::new(0.0, -h)];
    let all: Vec<(Vector3<f64>, f64)> = ranges.iter().map(|(_, b, r)| (*b, *r)).collect();
    let but = |id: u32| -> Vec<(Vector3<f64>, f64)> {
        ranges.iter().filter(|r| r.0 != id).map(|(_, b, r)| (*b, *r)).collect()
    };
    let mut subsets = vec![all.clone()];
    if ids.len() >= 4 {
        subsets.extend(ids.iter().map(|&id| but(id)));
    }
    subsets
        .iter()
        .flat_map(|subset| starts.iter().filter_map(move |s| solve(subset, depth_m, centroid + s)))
        // every range judged at each subset's fix: refining on all of them would let a
        // burst's pull (Huber's bounded, but growing with the scale) win back
        .filter_map(|p| evaluate(&all, depth_m, p))
        .min_by(|a, b| a.0.residual_sigma_m.total_cmp(&b.0.residual_sigma_m).then(a.1.total_cmp(&b.1)))
        .map(|(best, cost)| {
            // solved again on the ranges within 3 robust sigmas of the fit kept: all of
            // them when none is an outlier, the set without a burst otherwise
            let res = residuals(&all, depth_m, best.position);
            let inliers: Vec<_> = all
                .iter()
                .zip(&res)
                .filter(|(_, (e, _))| e.abs() <= 3.0 * best.residual_sigma_m)
                .map(|(r, _)| *r)
                .collect();
            solve(&inliers, depth_m, best.position)
                .and_then(|p| evaluate(&all, depth_m, p))
                .filter(|(_, c)| c.is_finite())
                .unwrap_or((best, cost))
                .0
        })
}

/// Residuals r_i - |p - b_i| at `p`, and the rows of their Jacobian d|p - b_i| / dp.
fn residuals(ranges: &[(Vector3<f64>, f64)], depth_m: f64, p: Vector2<f64>) -> Vec<(f64, Vector2<f64>)> {
    ranges
        .iter()
        .map(|(b, r)| {
            let d = Vector3::new(p.x, p.y, depth_m) - b;
            let dist = d.norm().max(1e-9);
            (r - dist, d.xy() / dist)
        })
        .collect()
}

/// The robust scale of residuals: 1.4826 times their median absolute value (floored at
/// 1 cm).
fn robust_sigma(res: &[(f64, Vector2<f64>)]) -> f64 {
    let mut a: Vec<f64> = res.iter().map(|(e, _)| e.abs()).collect();
    a.sort_by(f64::total_cmp);
    (1.4826 * a[a.len() / 2]).max(0.01)
}

fn huber_weight(e: f64, sigma: f64) -> f64 {
    let u = (e / sigma).abs();
    if u <= HUBER_K { 1.0 } else { HUBER_K / u }
}

/// IRLS from `p`: the position it converges to.
fn solve(ranges: &[(Vector3<f64>, f64)], depth_m: f64, mut p: Vector2<f64>) -> Option<Vector2<f64>> {
    for _ in 0..50 {
        let res = residuals(ranges, depth_m, p);
        let sigma = robust_sigma(&res);
        let (mut jtj, mut jte) = (Matrix2::zeros(), Vector2::zeros());
        for (e, j) in &res {
            let w = huber_weight(*e, sigma);
            jtj += w * j * j.transpose();
            jte += w * j * *e;
        }
        let step = jtj.try_inverse()? * jte;
        p += step;
        if step.norm() < 1e-6 {
            break;
        }
    }
    Some(p)
}

/// The fix at `p` judged by `ranges`, and its robust cost (sum of Huber's rho of the
/// scaled residuals, in metres); None where the ranges do not determine a position.
fn evaluate(ranges: &[(Vector3<f64>, f64)], depth_m: f64, p: Vector2<f64>) -> Option<(Fix, f64)> {
    let res = residuals(ranges, depth_m, p);
    let sigma = robust_sigma(&res);
    let mut jtj = Matrix2::zeros();
    let mut cost = 0.0;
    for (e, j) in &res {
        let w = huber_weight(*e, sigma);
        jtj += w * j * j.transpose();
        let u = (e / sigma).abs();
        cost += if u <= HUBER_K { 0.5 * u * u } else { HUBER_K * u - 0.5 * HUBER_K * HUBER_K };
    }
    // a near-singular normal matrix: the beacons in a line, the position undetermined
    let (eigen_min, eigen_max) = {
        let e = jtj.symmetric_eigenvalues();
        (e.min(), e.max())
    };
    if eigen_min <= 1e-6 * eigen_max {
        return None;
    }
    let covariance = jtj.try_inverse()? * sigma * sigma;
    let outliers = res.iter().filter(|(e, _)| e.abs() > 3.0 * sigma).count();
    // the cost in metres, comparable between starts: sigma x the scaled cost
    Some((Fix { position: p, covariance, residual_sigma_m: sigma, outliers }, cost * sigma))
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_abs_diff_eq;
    use rand::SeedableRng;
    use rand_distr::{Distribution, Normal};

    /// Three beacons, 60 ranges with 0.3 m Gaussian noise and four gross outliers
    /// (-200 m to +300 m): the fix lands within 0.2 m of the truth, the outliers are set
    /// aside, and the residual scale is near the noise; exact ranges give the truth to
    /// 1e-6 m; beacons in a line give none.
    #[test]
    fn robust_fix_ignores_gross_outliers() {
        let truth = Vector2::new(12.0, -7.0);
        let beacons = [Vector3::new(50.0, 0.0, 0.0), Vector3::new(-20.0, 40.0, 0.0), Vector3::new(-25.0, -45.0, 5.0)];
        let dist = |b: &Vector3<f64>| (Vector3::new(truth.x, truth.y, 0.0) - b).norm();
        let exact: Vec<_> = beacons.iter().zip(0..).map(|(b, id)| (id, *b, dist(b))).collect();
        let fix = multilaterate(&exact, 0.0).unwrap();
        assert_abs_diff_eq!(fix.position, truth, epsilon = 1e-6);

        let noise = Normal::new(0.0, 0.3).unwrap();
        let mut rng = rand_pcg::Pcg64::seed_from_u64(3);
        let mut ranges: Vec<_> =
            (0..60).map(|k| (k as u32 % 3, beacons[k % 3], dist(&beacons[k % 3]) + noise.sample(&mut rng))).collect();
        for (k, e) in [-200.0, -40.0, 120.0, 300.0].into_iter().enumerate() {
            ranges[k * 7].2 += e;
        }
        let fix = multilaterate(&ranges, 0.0).unwrap();
        assert!((fix.position - truth).norm() < 0.2, "{:?}", fix.position);
        assert_eq!(fix.outliers, 4);
        assert!((0.2..0.45).contains(&fix.residual_sigma_m), "{}", fix.residual_sigma_m);
        let line = [Vector3::new(0.0, 0.0, 0.0), Vector3::new(10.0, 0.0, 0.0), Vector3::new(20.0, 0.0, 0.0)];
        assert!(multilaterate(&line.map(|b| (0, b, 15.0)), 0.0).is_none());
        assert!(multilaterate(&exact[..2], 0.0).is_none());
    }

    /// Four long-baseline beacons 400-600 m off, 16 ranges with 0.8 m of noise, all four
    /// of beacon 0's 200 m short (a burst): every start of the whole set ends between
    /// the false and the true ranges, tens of metres off; the fits without one beacon
    /// find the truth, within 1 m, and beacon 0's ranges are the outliers.
    #[test]
    fn a_burst_of_false_ranges_to_one_beacon_does_not_move_the_fix() {
        let truth = Vector2::new(80.0, 45.0);
        let beacons = [(300.0, 400.0), (420.0, -350.0), (-380.0, -300.0), (-350.0, 450.0)];
        let beacons = beacons.map(|(n, e)| Vector3::new(n, e, 0.0));
        let dist = |b: &Vector3<f64>| (Vector3::new(truth.x, truth.y, 0.0) - b).norm();
        let noise = Normal::new(0.0, 0.8).unwrap();
        let mut rng = rand_pcg::Pcg64::seed_from_u64(5);
        let ranges: Vec<_> = (0..16)
            .map(|k| {
                let false_m = if k % 4 == 0 { -200.0 } else { 0.0 };
                (k as u32 % 4, beacons[k % 4], dist(&beacons[k % 4]) + noise.sample(&mut rng) + false_m)
            })
            .collect();
        let fix = multilaterate(&ranges, 0.0).unwrap();
        assert!((fix.position - truth).norm() < 1.0, "{:?}", fix.position);
        assert_eq!(fix.outliers, 4);
    }
}
