//! Mission statistics of fleet runs (rypkema sec. 5.2): the 2-norm navigation error's
//! 68th and 95th percentiles per AUV and estimator and pooled over the fleet (Table 3),
//! how long after each command every AUV confirmed it, the formation's spacing error
//! under offset follow, and the area the trackline survey covered. From recorded runs.

use crate::run::{RunOutput, StepRecord};
use crate::scenario::fleet::{BehaviourName, Fleet};
use crate::seed::{Stream, gauss, vehicle_rng};
use nalgebra::Vector2;
use onebeacon::nav::evaluation::{chi_square_band, quantile};
use serde::Serialize;

/// Errors of one (vehicle, estimator) or one estimator pooled over the fleet.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ErrorPercentiles {
    pub label: String,
    pub p68_m: f64,
    pub p95_m: f64,
    pub mean_m: f64,
    /// Steps counted (submerged, after launch).
    pub samples: usize,
    /// The horizontal position's NEES against the truth (never the reference), averaged
    /// over the counted steps of each run and then over the runs (NaN for an estimator
    /// without a covariance); 2 is consistent.
    pub nees_mean: f64,
    /// The 95 % band of that mean for as many runs (tracks pooled: runs x AUVs).
    pub nees_band: [f64; 2],
}

/// When one AUV confirmed one command.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Confirmation {
    pub vehicle: String,
    /// 1 to 4, as the schedule.
    pub mode: usize,
    pub commanded_s: f64,
    /// Seconds after the command (or after the launch, if later); None: never.
    pub delay_s: Option<f64>,
}

/// The spacing between every pair of AUVs against the commanded offsets, while every
/// AUV flies offset follow (from 300 s after the command).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Spacing {
    pub pairs: usize,
    pub samples: usize,
    pub mean_abs_error_m: f64,
    pub rms_error_m: f64,
    pub p95_abs_error_m: f64,
}

/// What the AUVs' true tracks covered while flying tracklines: 10 m cells visited.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Coverage {
    pub cell_m: f64,
    pub area_m2: f64,
    /// The visited cells' extent across and along the lines' heading, m.
    pub across_m: f64,
    pub along_m: f64,
}

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FleetStatistics {
    pub runs: usize,
    pub tracks: Vec<ErrorPercentiles>,
    pub fleet: Vec<ErrorPercentiles>,
    /// Run 0's confirmations.
    pub confirmations: Vec<Confirmation>,
    /// Over every run and command: the AUVs that confirmed every commanded mode, and the
    /// largest delay.
    pub all_confirmed: bool,
    pub max_delay_s: f64,
    pub spacing: Option<Spacing>,
    pub coverage: Option<Coverage>,
}

/// Errors `e` and each run's mean NEES `nees` (one per run and track) summarised.
fn percentiles(label: String, mut e: Vec<f64>, nees: &[f64]) -> ErrorPercentiles {
    e.retain(|v| v.is_finite());
    e.sort_by(f64::total_cmp);
    let mean = e.iter().sum::<f64>() / e.len().max(1) as f64;
    ErrorPercentiles {
        label,
        p68_m: quantile(&e, 0.68),
        p95_m: quantile(&e, 0.95),
        mean_m: mean,
        samples: e.len(),
        nees_mean: nees.iter().sum::<f64>() / nees.len() as f64,
        nees_band: chi_square_band(nees.len(), 2),
    }
}

/// Whether vehicle `v` is submerged and launched at record `r` (the steps the error
/// statistics count: the paper's LBL truth exists only under water).
fn counted(s: &Fleet, r: &StepRecord, v: usize) -> bool {
    r.t_s >= s.auvs[v].launch_s && r.truth[v].pos.z > 0.5
}

/// The commands of the schedule: (time, mode 1-4) of each change to a non-silent mode.
pub fn commands(s: &Fleet) -> Vec<(f64, usize)> {
    let mut out: Vec<(f64, usize)> = Vec::new();
    for e in s.schedule.iter().filter(|e| e.mode > 0) {
        if out.last().is_none_or(|&(_, m)| m != e.mode) {
            out.push((e.t_s, e.mode));
        }
    }
    out
}

fn confirmations(s: &Fleet, traj: &[StepRecord]) -> Vec<Confirmation> {
    let cmds = commands(s);
    let end = traj.last().map_or(0.0, |r| r.t_s);
    let mut out = Vec::new();
    for (i, &(t_cmd, mode)) in cmds.iter().enumerate().filter(|(_, c)| c.0 < end) {
        let until = cmds.get(i + 1).map_or(f64::INFINITY, |c| c.0);
        for (v, a) in s.auvs.iter().enumerate() {
            let from = t_cmd.max(a.launch_s);
            let t = traj
                .iter()
                .filter(|r| r.t_s >= from && r.t_s < until)
                .find(|r| r.pilots.iter().any(|p| p.vehicle == Some(v) && p.mode == Some(mode - 1)))
                .map(|r| r.t_s - from);
            out.push(Confirmation { vehicle: a.name.clone(), mode, commanded_s: t_cmd, delay_s: t });
        }
    }
    out
}

/// The spacing errors of one run: every pair, every step from 300 s after an
/// offset-follow command that every AUV has to the next command.
fn spacing_errors(s: &Fleet, traj: &[StepRecord], out: &mut Vec<f64>) -> usize {
    let cmds = commands(s);
    let n = s.auvs.len();
    let mut pairs = 0;
    for (i, &(t_cmd, mode)) in cmds.iter().enumerate() {
        let offsets: Option<Vec<nalgebra::Vector2<f64>>> = s
            .auvs
            .iter()
            .map(|a| {
                a.modes
                    .iter()
                    .find(|m| m.mode == mode && m.behaviour == BehaviourName::OffsetFollow)
                    .map(|m| nalgebra::Vector2::new(m.offset_north_m, m.offset_east_m))
            })
            .collect();
        let Some(offsets) = offsets else { continue };
        let until = cmds.get(i + 1).map_or(f64::INFINITY, |c| c.0);
        pairs = n * (n - 1) / 2;
        for r in traj.iter().filter(|r| r.t_s >= t_cmd + 300.0 && r.t_s < until) {
            for a in 0..n {
                for b in a + 1..n {
                    let d = (r.truth[a].pos - r.truth[b].pos).xy().norm();
                    out.push(d - (offsets[a] - offsets[b]).norm());
                }
            }
        }
    }
    pairs
}

/// The cells visited while every AUV's mode is a trackline, in the frame of the first
/// trackline's heading.
fn coverage(s: &Fleet, traj: &[StepRecord]) -> Option<Coverage> {
    let cmds = commands(s);
    let cell = 10.0;
    let mut cells = std::collections::BTreeSet::new();
    let mut heading = None;
    for (i, &(t_cmd, mode)) in cmds.iter().enumerate() {
        let lines: Vec<_> = s
            .auvs
            .iter()
            .filter_map(|a| a.modes.iter().find(|m| m.mode == mode && m.behaviour == BehaviourName::Trackline))
            .collect();
        if lines.len() != s.auvs.len() {
            continue;
        }
        let h = *heading.get_or_insert(lines[0].heading_deg.unwrap_or(0.0).to_radians());
        let (sn, cs) = h.sin_cos();
        let until = cmds.get(i + 1).map_or(f64::INFINITY, |c| c.0);
        for r in traj.iter().filter(|r| r.t_s >= t_cmd && r.t_s < until) {
            for (v, t) in r.truth.iter().enumerate() {
                if counted(s, r, v) {
                    let along = t.pos.x * cs + t.pos.y * sn;
                    let across = -t.pos.x * sn + t.pos.y * cs;
                    cells.insert(((along / cell).floor() as i64, (across / cell).floor() as i64));
                }
            }
        }
    }
    heading?;
    let extent = |f: fn(&(i64, i64)) -> i64| {
        let lo = cells.iter().map(f).min().unwrap_or(0);
        let hi = cells.iter().map(f).max().unwrap_or(-1);
        (hi - lo + 1) as f64 * cell
    };
    Some(Coverage {
        cell_m: cell,
        area_m2: cells.len() as f64 * cell * cell,
        along_m: extent(|c| c.0),
        across_m: extent(|c| c.1),
    })
}

/// The statistics of recorded runs of `s` (tracks in the order of
/// [`crate::Scenario::tracks`]: each AUV's estimators in order), run i of base seed
/// `seed` at index i. With `[reference] sigma_m`, the errors are against a reference fix
/// per step and AUV (the truth plus its own error, from a seeded stream of its own).
pub fn statistics(s: &Fleet, seed: u64, runs: &[RunOutput]) -> FleetStatistics {
    let estimators: Vec<&str> = s.estimators.iter().map(|e| e.label()).collect();
    let ne = estimators.len();
    let mut per_track: Vec<Vec<f64>> = vec![Vec::new(); s.auvs.len() * ne];
    // each run's mean NEES per track over its counted steps
    let mut nees: Vec<Vec<f64>> = vec![Vec::with_capacity(runs.len()); s.auvs.len() * ne];
    let sigma = s.reference.sigma_m;
    for (run, out) in runs.iter().enumerate() {
        let mut rngs: Vec<_> = (0..s.auvs.len()).map(|v| vehicle_rng(seed, run as u64, v, Stream::Reference)).collect();
        let mut fixes: Vec<Vector2<f64>> = Vec::with_capacity(s.auvs.len());
        let mut run_nees = vec![(0.0, 0usize); per_track.len()]; // (sum, steps)
        for r in &out.trajectory {
            // every AUV's fix of this step, drawn whether it counts or not
            fixes.clear();
            if sigma > 0.0 {
                let drawn = rngs.iter_mut().zip(&r.truth);
                fixes.extend(drawn.map(|(rng, t)| t.pos.xy() + Vector2::new(gauss(rng, sigma), gauss(rng, sigma))));
            }
            for (i, e) in r.estimates.iter().enumerate() {
                if counted(s, r, e.vehicle) {
                    let error = fixes.get(e.vehicle).map_or(e.error_m, |f| (e.pos.xy() - f).norm());
                    per_track[i].push(error);
                    run_nees[i] = (run_nees[i].0 + e.nees, run_nees[i].1 + 1);
                }
            }
        }
        for (all, (sum, n)) in nees.iter_mut().zip(run_nees) {
            all.push(sum / n as f64);
        }
    }
    let tracks = per_track
        .iter()
        .enumerate()
        .map(|(i, e)| percentiles(format!("{}/{}", s.auvs[i / ne].name, estimators[i % ne]), e.clone(), &nees[i]))
        .collect();
    let fleet = (0..ne)
        .map(|j| {
            let all = per_track.iter().skip(j).step_by(ne).flatten().copied().collect();
            let all_nees: Vec<f64> = nees.iter().skip(j).step_by(ne).flatten().copied().collect();
            percentiles(format!("fleet/{}", estimators[j]), all, &all_nees)
        })
        .collect();
    let mut all_confirmed = true;
    let mut max_delay: f64 = 0.0;
    for out in runs {
        for c in confirmations(s, &out.trajectory) {
            match c.delay_s {
                Some(d) => max_delay = max_delay.max(d),
                None => all_confirmed = false,
            }
        }
    }
    let mut spacing = Vec::new();
    let mut pairs = 0;
    for out in runs {
        pairs = spacing_errors(s, &out.trajectory, &mut spacing);
    }
    let spacing = (!spacing.is_empty()).then(|| {
        let mut abs: Vec<f64> = spacing.iter().map(|v| v.abs()).collect();
        abs.sort_by(f64::total_cmp);
        Spacing {
            pairs,
            samples: abs.len(),
            mean_abs_error_m: abs.iter().sum::<f64>() / abs.len() as f64,
            rms_error_m: (spacing.iter().map(|v| v * v).sum::<f64>() / spacing.len() as f64).sqrt(),
            p95_abs_error_m: quantile(&abs, 0.95),
        }
    });
    FleetStatistics {
        runs: runs.len(),
        tracks,
        fleet,
        confirmations: runs.first().map(|o| confirmations(s, &o.trajectory)).unwrap_or_default(),
        all_confirmed,
        max_delay_s: max_delay,
        spacing,
        coverage: runs.first().and_then(|o| coverage(s, &o.trajectory)),
    }
}
