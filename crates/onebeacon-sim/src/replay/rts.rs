//! The cheap smoother: a Rauch-Tung-Striebel pass over each Gaussian filter of a log
//! ([`onebeacon::filter::rts`]), scored at the ground-truth rows as the filters are.

use super::{Log, LogError, replay_session, session_and_start};
use onebeacon::nav::Estimate;
use onebeacon::nav::evaluation::{ErrorStats, horizontal_error};
use std::collections::BTreeSet;

/// One estimator's Rauch-Tung-Striebel pass.
#[derive(Debug, Clone)]
pub struct RtsRun {
    /// The estimator's name.
    pub name: String,
    /// The smoothed estimates, each holding from its time on (NED).
    pub estimates: Vec<Estimate>,
    /// Its errors at the ground-truth rows.
    pub stats: ErrorStats,
}

impl RtsRun {
    /// The smoothed estimate at `t_s` (the last one from before it; the first before
    /// the first).
    pub fn at(&self, t_s: f64) -> &Estimate {
        let k = self.estimates.partition_point(|e| e.t_s <= t_s);
        &self.estimates[k.saturating_sub(1)]
    }

    /// The horizontal error at `t_s` against a reference (north, east) with its own
    /// error `sigma_m` per axis, m, and its NEES (NaN for no truth).
    pub fn error(&self, t_s: f64, north_m: f64, east_m: f64, sigma_m: f64) -> (f64, Option<f64>) {
        horizontal_error(self.at(t_s), north_m, east_m, sigma_m)
    }
}

/// The log's filters run with their history kept, and a Rauch-Tung-Striebel pass over
/// each one that keeps one (the Gaussian planar family with beacon aiding; the others
/// are left out), scored
/// against the ground truth (no rows: empty statistics).
pub fn rts(log: &Log, beacons: Option<BTreeSet<u32>>) -> Result<Vec<RtsRun>, LogError> {
    let (session, start) = session_and_start(log, beacons)?;
    let mut truth = Vec::new();
    let r = replay_session(log, session.with_history(), start, |rec| {
        if let Some(p) = rec.truth.first().filter(|p| !p.pos.x.is_nan()) {
            truth.push((rec.t_s, p.pos.x, p.pos.y, p.sigma_m));
        }
        Ok::<_, LogError>(())
    })?;
    let mut session = r.session;
    let runs = (0..session.names.len()).filter_map(|i| {
        let estimates = session.smoothed(i)?;
        (!estimates.is_empty()).then(|| {
            let mut run = RtsRun { name: session.names[i].clone(), estimates, stats: ErrorStats::default() };
            for &(t, north, east, sigma) in &truth {
                let (error_m, nees) = run.error(t, north, east, sigma);
                run.stats.push(error_m, nees);
            }
            run
        })
    });
    Ok(runs.collect())
}
