//! The onboard controllers of a scenario's vehicles, built from its configuration: the
//! surface vehicle's bearing planner (passive USBL), the beacon vehicle's FIM guidance
//! (moving beacon), each fleet AUV's behaviours. The worlds move the vehicles under
//! their commands; what the vehicles decide is the onboard crate's
//! ([`onebeacon::vehicle`]).

use crate::engine::Helm;
use crate::scenario::fleet::{Fleet, MODES};
use crate::scenario::moving_beacon::GuidanceKind as FimKind;
use crate::scenario::passive_usbl::GuidanceKind as BearingKind;
use crate::scenario::{MovingBeacon, MovingBeaconCell, PassiveUsbl, PassiveUsblCell};
use nalgebra::Vector2;
use onebeacon::guidance::bearing::{BearingPlanner, SpreadMetric};
use onebeacon::guidance::{FimPlanner, Metric, PolarGrid, best_standoff};
use onebeacon::vehicle::autonomy::{Autonomy, AutonomySettings};
use onebeacon::vehicle::bearing::{BearingGuidance, BearingGuidanceConfig, BearingMode};
use onebeacon::vehicle::behaviours::Behaviours;
use onebeacon::vehicle::fim::{FimGuidance, FimGuidanceConfig, FimMode};

/// The ASV of a passive-USBL world, starting at `home`: it serves every AUV.
pub(crate) fn passive_usbl(s: &PassiveUsbl, cell: &PassiveUsblCell, home: Vector2<f64>) -> Vec<Helm> {
    let g = &s.guidance;
    // the baselines keep the determinant for their (unused) planner
    let (mode, metric) = match cell.guidance {
        BearingKind::Determinant => (BearingMode::Planner, SpreadMetric::Determinant),
        BearingKind::MaxEigenvalue => (BearingMode::Planner, SpreadMetric::MaxEigenvalue),
        BearingKind::Static => (BearingMode::Static, SpreadMetric::Determinant),
        BearingKind::Circle => (BearingMode::Circle, SpreadMetric::Determinant),
        BearingKind::Offset => (BearingMode::Offset, SpreadMetric::Determinant),
    };
    let planner = BearingPlanner {
        metric,
        r1_m: g.r1_m,
        r2_m: g.r2_m,
        radii: g.radii,
        angles: g.angles,
        // the planner knows the USBL as the first estimator assumes it
        sigma_usbl_rad_per_m: s.estimators[0].tracker_config(s.tracker_noise()).noise.usbl_sigma_rad_per_m,
    };
    let config = BearingGuidanceConfig {
        mode,
        planner,
        nominal_speed_m_s: s.asv.nominal_speed_m_s,
        period_s: s.mission.message_period_s,
        planner_particles: g.planner_particles,
        lead_periods: g.lead_periods,
        circle_radius_m: g.circle_radius_m,
        offset_m: g.offset_m,
        home_m: home,
    };
    vec![Helm { controller: Box::new(BearingGuidance::new(config)), serves: (0..s.auvs().len()).collect() }]
}

/// The ASV's start in a moving-beacon world: the best standoff for the vehicle's start
/// depth and the ASV's reach (sousa Fig. 4.7), in the direction `asv.start_bearing_deg`
/// from the vehicle.
pub(crate) fn initial_asv_position(s: &MovingBeacon, cell: &MovingBeaconCell) -> Vector2<f64> {
    let reach = s.asv.max_speed_m_s * s.acoustics.ping_period_s;
    let grid = PolarGrid { radial: 20, angular: 36, refinements: 10 };
    let d = best_standoff((cell.depth_m - s.asv.transducer_depth_m).max(0.0), reach, grid).distance_m;
    let b = s.asv.start_bearing_deg.to_radians();
    Vector2::new(s.vehicle.start_north_m, s.vehicle.start_east_m) + Vector2::new(b.cos(), b.sin()) * d
}

/// The beacon-carrying ASV of a moving-beacon world, starting at `home`: it serves the
/// first vehicle.
pub(crate) fn moving_beacon(s: &MovingBeacon, cell: &MovingBeaconCell, home: Vector2<f64>) -> Vec<Helm> {
    let g = &s.guidance;
    let mode = match cell.guidance {
        FimKind::ApproachA | FimKind::ApproachB => FimMode::Planner,
        FimKind::Static => FimMode::Static,
        FimKind::Circle => FimMode::Circle,
    };
    let planner = FimPlanner {
        metric: if cell.guidance == FimKind::ApproachB { Metric::ApproachB } else { Metric::ApproachA },
        grid: PolarGrid { radial: g.grid_radial, angular: g.grid_angular, refinements: 12 },
        range_var_m2: s.acoustics.range_noise_m.powi(2),
        beacon_depth_m: s.asv.transducer_depth_m,
    };
    let config = FimGuidanceConfig {
        mode,
        planner,
        period_s: s.acoustics.ping_period_s,
        max_speed_m_s: s.asv.max_speed_m_s,
        circle_radius_m: g.circle_radius_m,
        home_m: home,
    };
    vec![Helm { controller: Box::new(FimGuidance::new(config)), serves: vec![0] }]
}

/// Each fleet AUV's behaviours by command mode, on its own first estimator.
pub(crate) fn fleet(s: &Fleet) -> Vec<Helm> {
    s.auvs
        .iter()
        .enumerate()
        .map(|(v, a)| {
            let settings = AutonomySettings { speed_m_s: a.speed_m_s, depth_m: a.depth_m, ..Default::default() };
            let mut modes = vec![None; MODES];
            for m in &a.modes {
                modes[m.mode - 1] = Some(m.behaviour());
            }
            Helm { controller: Box::new(Behaviours::new(Autonomy::new(settings, modes))), serves: vec![v] }
        })
        .collect()
}
