//! After the dive: fixed-interval smoothing of a log as sparse nonlinear least squares
//! over every pose ([`graph`]: motion, heading, range, Doppler and USBL factors;
//! calibration variables: range scale, turn and distance scale, range offsets, a clock
//! drift), solved by Levenberg-Marquardt over a sparse Cholesky factorisation with
//! Huber, Student-t or Cauchy kernels ([`solve`]), with the marginal covariance of
//! every pose. The noise is the filters' ([`PlanarNoise`]): the smoother reads what an
//! estimator of the log reads.

mod factor;
mod graph;
mod options;
mod solve;
#[cfg(test)]
mod tests;

pub use options::{CALIBRATION_NAMES, KERNEL_NAMES, config};
pub use solve::SolveError;

use factor::Node;
use nalgebra::{Matrix2, Vector2};
use onebeacon::filter::consistency::nees;
use onebeacon::log::{Log, LogError};
use onebeacon::nav::evaluation::ErrorStats;
use onebeacon::nav::{PlanarConfig, PlanarNoise, Robust};
use std::collections::{BTreeMap, BTreeSet};

/// Range offsets as variables: none, one shared by every beacon (a clock offset), or
/// one per beacon.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Offsets {
    None,
    Shared,
    PerBeacon,
}

/// Which calibration variables the smoother estimates.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Calibrate {
    pub range_scale: bool,
    pub turn_scale: bool,
    pub distance_scale: bool,
    pub offsets: Offsets,
    /// A range error growing linearly in time (a one-way travel time's clock drift
    /// times the sound speed), m/s.
    pub clock_drift: bool,
}

impl Calibrate {
    pub const NONE: Calibrate = Calibrate {
        range_scale: false,
        turn_scale: false,
        distance_scale: false,
        offsets: Offsets::None,
        clock_drift: false,
    };
    pub const ALL: Calibrate = Calibrate {
        range_scale: true,
        turn_scale: true,
        distance_scale: true,
        offsets: Offsets::PerBeacon,
        clock_drift: true,
    };
}

/// The calibration variables' priors (means 1 for scales, `offset_m` for offsets, 0
/// for the drift).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Priors {
    pub range_scale_sigma: f64,
    pub turn_scale_sigma: f64,
    pub distance_scale_sigma: f64,
    pub offset_m: f64,
    pub offset_sigma_m: f64,
    pub drift_sigma_m_per_s: f64,
}

/// What the smoother weighs and estimates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SmoothConfig {
    pub noise: PlanarNoise,
    pub calibrate: Calibrate,
    pub priors: Priors,
    /// The heavy-tailed kernel of the acoustic measurements and heading fixes.
    pub kernel: Option<Robust>,
    /// After the solve, measurements whose squared whitened residual exceeds this are
    /// dropped and the problem solved again (chi-square: 10.83 is 99.9 % at 1 dof).
    pub nis_gate: Option<f64>,
    /// USBL azimuth and elevation standard deviation, rad.
    pub usbl_sigma_rad: f64,
    pub max_iterations: usize,
    /// A craft tracked with a constant-velocity model, as the tracker of this key does
    /// (`track_accel_sigma_m_s2`: the square root of the white acceleration's spectral
    /// density, m/s^1.5): nodes hold position and velocity at the acoustic measurements'
    /// times; motion rows and heading fixes are not read. None: the log's motion rows.
    pub track_accel_sigma_m_s2: Option<f64>,
}

impl Default for SmoothConfig {
    /// The filters' default noise, the range scale and the turn scale as variables (what
    /// plaza's logs carry: ranges 7 % long, turns over-reported by up to 5 %; offsets
    /// and a drift are left to `--calibrate`, as with one beacon they trade against the
    /// scale), a Huber kernel (k = 1.345).
    fn default() -> Self {
        let calibrate = Calibrate { range_scale: true, turn_scale: true, ..Calibrate::NONE };
        Self { kernel: Some(Robust::Huber { k: 1.345 }), ..Self::from_planar(&PlanarConfig::default(), calibrate) }
    }
}

impl SmoothConfig {
    /// The smoother an estimator of the log describes: its noise, kernel, gate,
    /// calibration priors and constant-velocity model, with the variables `calibrate`.
    pub fn from_planar(c: &PlanarConfig, calibrate: Calibrate) -> Self {
        Self {
            noise: c.noise,
            calibrate,
            priors: Priors {
                range_scale_sigma: c.range_scale_sigma,
                turn_scale_sigma: c.turn_scale_sigma,
                distance_scale_sigma: c.distance_scale_sigma,
                offset_m: c.bias_m,
                offset_sigma_m: c.bias_sigma_m,
                drift_sigma_m_per_s: DRIFT_SIGMA_M_PER_S,
            },
            kernel: c.robust,
            nis_gate: c.nis_gate,
            usbl_sigma_rad: 1f64.to_radians(),
            // the cap ../shared/bench/gtsam_smooth.py gives GTSAM (setMaxIterations); plaza1
            // beacon 1 alone, scale 1 and no kernel, needs 127 (GTSAM 98)
            max_iterations: 200,
            track_accel_sigma_m_s2: c.track_accel_sigma_m_s2,
        }
    }
}

/// The range the scale variables (range, turn and distance scale) are kept within: a
/// factor of two either way is no calibration but a misplaced beacon or a units slip.
/// No source: a guard, far outside the few per cent real logs show (plaza: 1.07).
pub const SCALE_BOUNDS: (f64, f64) = (0.5, 2.0);

/// The prior on a range drift: 1 mm/s, a clock drift of 0.7 us/s at 1500 m/s.
pub const DRIFT_SIGMA_M_PER_S: f64 = 1e-3;

#[derive(Debug, thiserror::Error)]
pub enum SmoothError {
    #[error(transparent)]
    Log(#[from] LogError),
    #[error(transparent)]
    Solve(#[from] SolveError),
    #[error(
        "no motion to smooth: the log has no odometry, body_odometry, speed or body_velocity rows after its start; for a craft tracked from outside, give a constant-velocity model (--track-accel SIGMA, or --like an estimator with track_accel_sigma_m_s2)"
    )]
    NoMotion,
}

/// A smoothed log: a pose and its marginal covariance per node, the calibration
/// variables, and how the solve went.
#[derive(Debug, Clone)]
pub struct Smoothed {
    pub t_s: Vec<f64>,
    /// North, east (m), heading (rad, continuous along the trajectory).
    pub poses: Vec<[f64; 3]>,
    /// Dead reckoning from the same start (the solver's initial values; a track's: the
    /// constant-velocity tracker run forward).
    pub dead_reckoning: Vec<[f64; 3]>,
    /// Marginal covariance of (north, east, heading) per pose.
    pub covariances: Vec<[[f64; 3]; 3]>,
    /// Calibration variables: name, value, standard deviation.
    pub calibration: Vec<(String, f64, f64)>,
    pub iterations: usize,
    /// Whether every solve settled before its iteration cap.
    pub converged: bool,
    pub cost0: f64,
    pub cost: f64,
    /// What went wrong without failing: a solve stopped at its cap, a calibration
    /// variable at its bound.
    pub warnings: Vec<String>,
    /// Measurements used per kind, dropped by the gate, and items without a factor.
    pub used: BTreeMap<&'static str, usize>,
    pub gated: usize,
    pub ignored: BTreeMap<&'static str, usize>,
    /// Ground-truth rows: (t, north, east, the reference's own sigma per axis).
    pub truth: Vec<(f64, f64, f64, f64)>,
    /// Seconds to read the log and build the graph, and to solve it (with the marginals).
    pub build_s: f64,
    pub solve_s: f64,
}

/// Smooths `log` (its beacons `beacons`, all when `None`).
pub fn smooth(log: &Log, beacons: Option<&BTreeSet<u32>>, cfg: &SmoothConfig) -> Result<Smoothed, SmoothError> {
    let started = std::time::Instant::now();
    let g = graph::build(log, beacons, cfg)?;
    let build_s = started.elapsed().as_secs_f64();
    let bounds: Vec<(usize, f64, f64)> = g
        .calibration
        .iter()
        .filter(|(name, _)| name.ends_with("scale"))
        .map(|(_, i)| (*i, SCALE_BOUNDS.0, SCALE_BOUNDS.1))
        .collect();
    let options =
        solve::SolveOptions { kernel: cfg.kernel, max_iterations: cfg.max_iterations, bounds: &bounds, node: g.node };
    let mut active = vec![true; g.factors.len()];
    let size = g.node.size();
    let poses = size * g.t_s.len();
    let mut sol = solve::solve(&g.factors, &active, g.x0.clone(), poses, options)?;
    let mut gated = 0;
    if let Some(gate) = cfg.nis_gate {
        for (f, on) in g.factors.iter().zip(&mut active) {
            let (r, m) = f.whitened(&sol.x);
            if f.is_measurement() && r[..m].iter().map(|r| r * r).sum::<f64>() > gate {
                *on = false;
                gated += 1;
            }
        }
        if gated > 0 {
            let (iterations, converged) = (sol.iterations, sol.converged);
            sol = solve::solve(&g.factors, &active, sol.x, poses, options)?;
            sol.iterations += iterations;
            sol.converged &= converged;
        }
    }
    let n = g.t_s.len();
    let pose = |x: &[f64], k: usize| match g.node {
        Node::Pose => [x[3 * k], x[3 * k + 1], x[3 * k + 2]],
        // a track's heading is its course (the start's heading while at rest)
        Node::Track => {
            let v = [x[4 * k + 2], x[4 * k + 3]];
            [x[4 * k], x[4 * k + 1], if v[0].hypot(v[1]) > 0.0 { v[1].atan2(v[0]) } else { g.start_heading_rad }]
        }
    };
    let mut warnings = Vec::new();
    if !sol.converged {
        warnings.push(format!(
            "the smoother stopped at its cap of {} iterations before its cost settled (cost {:.1} -> {:.1}): the \
             smoothed track is not an optimum",
            cfg.max_iterations, sol.cost0, sol.cost
        ));
    }
    for (name, i) in &g.calibration {
        let v = sol.x[*i];
        if bounds.iter().any(|&(b, lo, hi)| b == *i && (v <= lo || v >= hi)) {
            warnings.push(format!(
                "the smoother's {name} ended at its bound {v} (scales are kept within {} to {}): the measurements do \
                 not fit the log's geometry; check the beacons' positions and their units",
                SCALE_BOUNDS.0, SCALE_BOUNDS.1
            ));
        }
    }
    Ok(Smoothed {
        poses: (0..n).map(|k| pose(&sol.x, k)).collect(),
        dead_reckoning: (0..n).map(|k| pose(&g.x0, k)).collect(),
        calibration: g
            .calibration
            .iter()
            .map(|(name, i)| (name.clone(), sol.x[*i], sol.calibration[(i - poses, i - poses)].sqrt()))
            .collect(),
        covariances: sol
            .nodes
            .iter()
            .zip(0..)
            .map(|(c, k)| pose_covariance(c, &sol.x[size * k..size * (k + 1)]))
            .collect(),
        iterations: sol.iterations,
        converged: sol.converged,
        cost0: sol.cost0,
        cost: sol.cost,
        warnings,
        used: g.used,
        gated,
        ignored: g.ignored,
        truth: g.truth,
        t_s: g.t_s,
        build_s,
        solve_s: started.elapsed().as_secs_f64() - build_s,
    })
}

/// A node's covariance as (north, east, heading): a pose's as it is; a track's course
/// atan2(vE, vN) linearised, its variance pi^2 (no information) at rest.
fn pose_covariance(c: &nalgebra::DMatrix<f64>, node: &[f64]) -> [[f64; 3]; 3] {
    if c.nrows() == 3 {
        return std::array::from_fn(|a| std::array::from_fn(|b| c[(a, b)]));
    }
    let (vn, ve) = (node[2], node[3]);
    let s2 = vn * vn + ve * ve;
    // d course / d (n, e, vN, vE)
    let j = [0.0, 0.0, -ve / s2, vn / s2];
    let mut out: [[f64; 3]; 3] =
        std::array::from_fn(|a| std::array::from_fn(|b| if a < 2 && b < 2 { c[(a, b)] } else { 0.0 }));
    for a in 0..2 {
        out[a][2] = (0..4).map(|i| c[(a, i)] * j[i]).sum();
        out[2][a] = out[a][2];
    }
    out[2][2] = (0..4).map(|i| (0..4).map(|l| j[i] * c[(i, l)] * j[l]).sum::<f64>()).sum();
    if !(s2 > 0.0 && out[2][2].is_finite()) {
        out[0][2] = 0.0;
        out[1][2] = 0.0;
        out[2][0] = 0.0;
        out[2][1] = 0.0;
        out[2][2] = std::f64::consts::PI.powi(2);
    }
    out
}

impl Smoothed {
    /// The pose at time `t` (linear between nodes, heading included) and the
    /// horizontal covariance of the nearer node.
    pub fn at(&self, t: f64) -> ([f64; 3], Matrix2<f64>) {
        let (p, k) = self.interpolate(&self.poses, t);
        let c = &self.covariances[k];
        (p, Matrix2::new(c[0][0], c[0][1], c[1][0], c[1][1]))
    }

    /// A track of this smoother's nodes (the poses, dead reckoning) at time `t`, and
    /// the node nearer to it.
    fn interpolate(&self, track: &[[f64; 3]], t: f64) -> ([f64; 3], usize) {
        let at = graph::between(&self.t_s, t);
        let (p, q) = (track[at.k], track[if at.next { at.k + 1 } else { at.k }]);
        let a = at.alpha;
        (std::array::from_fn(|i| (1.0 - a) * p[i] + a * q[i]), if a > 0.5 { at.k + 1 } else { at.k })
    }

    /// The horizontal error at time `t` against a true (north, east), m, and its NEES.
    pub fn error(&self, t: f64, north_m: f64, east_m: f64, sigma_m: f64) -> (f64, Option<f64>) {
        let (p, cov) = self.at(t);
        let d = Vector2::new(p[0] - north_m, p[1] - east_m);
        (d.norm(), nees(&d, &(cov + nalgebra::Matrix2::identity() * sigma_m * sigma_m)))
    }

    /// The smoothed trajectory's errors and NEES against the ground truth, and dead
    /// reckoning's errors.
    pub fn score(&self) -> (ErrorStats, ErrorStats) {
        let (mut s, mut dr) = (ErrorStats::default(), ErrorStats::default());
        for &(t, n, e, sigma) in &self.truth {
            let (error_m, nees) = self.error(t, n, e, sigma);
            s.push(error_m, nees);
            let (q, _) = self.interpolate(&self.dead_reckoning, t);
            dr.push((q[0] - n).hypot(q[1] - e), None);
        }
        (s, dr)
    }
}
