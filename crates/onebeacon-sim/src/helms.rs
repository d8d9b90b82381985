//! The onboard controllers of a scenario's vehicles, built from its configuration: the
//! surface vehicle's bearing planner (passive USBL), the beacon vehicle's FIM guidance
//! (moving beacon), each fleet AUV's behaviours. The worlds move the vehicles under
//! their commands; what the vehicles decide is the onboard crate's
//! ([`onebeacon::vehicle`]).

use crate::engine::Helm;
use crate::scenario::fleet::Fleet;
use crate::scenario::moving_beacon::GuidanceKind as FimKind;
use crate::scenario::passive_usbl::GuidanceKind as BearingKind;
use crate::scenario::{MovingBeacon, MovingBeaconCell, PassiveUsbl, PassiveUsblCell};
use nalgebra::Vector2;
use onebeacon::config::controller::{
    BearingModeName, BearingSpec, BehavioursSpec, ControllerSpec, FimMetricName, FimModeName, FimSpec, MetricName,
};
use onebeacon::geo::Frame;
use onebeacon::guidance::{PolarGrid, best_standoff};

/// The controller of a passive-USBL world's ASV, starting at `home`, as a stream
/// configuration gives it (the planner knows the USBL as the first estimator assumes it).
pub(crate) fn passive_usbl_spec(s: &PassiveUsbl, cell: &PassiveUsblCell, home: Vector2<f64>) -> ControllerSpec {
    let g = &s.guidance;
    // the baselines keep the determinant for their (unused) planner
    let (mode, metric) = match cell.guidance {
        BearingKind::Determinant => (BearingModeName::Planner, MetricName::Determinant),
        BearingKind::MaxEigenvalue => (BearingModeName::Planner, MetricName::MaxEigenvalue),
        BearingKind::Static => (BearingModeName::Static, MetricName::Determinant),
        BearingKind::Circle => (BearingModeName::Circle, MetricName::Determinant),
        BearingKind::Offset => (BearingModeName::Offset, MetricName::Determinant),
    };
    ControllerSpec::Bearing(BearingSpec {
        mode,
        metric,
        r1_m: g.r1_m,
        r2_m: g.r2_m,
        radii: g.radii,
        angles: g.angles,
        usbl_sigma_deg_per_m: s.estimators[0].usbl_sigma_deg_per_m.unwrap_or(s.usbl.noise_deg_per_m),
        nominal_speed_m_s: s.asv.nominal_speed_m_s,
        period_s: s.mission.message_period_s,
        planner_particles: g.planner_particles,
        lead_periods: g.lead_periods,
        circle_radius_m: g.circle_radius_m,
        offset_m: g.offset_m,
        home_x_m: home.x,
        home_y_m: home.y,
        decide_on: "own_fix".into(),
    })
}

/// The ASV of a passive-USBL world, starting at `home`: it serves every AUV.
pub(crate) fn passive_usbl(s: &PassiveUsbl, cell: &PassiveUsblCell, home: Vector2<f64>) -> Vec<Helm> {
    let controller = passive_usbl_spec(s, cell, home).build(Frame::Ned).controller;
    vec![Helm { controller, serves: (0..s.auvs().len()).collect() }]
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

/// The controller of a moving-beacon world's ASV, starting at `home`, as a stream
/// configuration gives it.
pub(crate) fn moving_beacon_spec(s: &MovingBeacon, cell: &MovingBeaconCell, home: Vector2<f64>) -> ControllerSpec {
    let g = &s.guidance;
    let mode = match cell.guidance {
        FimKind::ApproachA | FimKind::ApproachB => FimModeName::Planner,
        FimKind::Static => FimModeName::Static,
        FimKind::Circle => FimModeName::Circle,
    };
    ControllerSpec::Fim(FimSpec {
        mode,
        metric: if cell.guidance == FimKind::ApproachB { FimMetricName::ApproachB } else { FimMetricName::ApproachA },
        grid_radial: g.grid_radial,
        grid_angular: g.grid_angular,
        range_sigma_m: s.acoustics.range_noise_m,
        beacon_depth_m: s.asv.transducer_depth_m,
        period_s: s.acoustics.ping_period_s,
        max_speed_m_s: s.asv.max_speed_m_s,
        circle_radius_m: g.circle_radius_m,
        home_x_m: home.x,
        home_y_m: home.y,
        ..FimSpec::default()
    })
}

/// The beacon-carrying ASV of a moving-beacon world, starting at `home`: it serves the
/// first vehicle.
pub(crate) fn moving_beacon(s: &MovingBeacon, cell: &MovingBeaconCell, home: Vector2<f64>) -> Vec<Helm> {
    let controller = moving_beacon_spec(s, cell, home).build(Frame::Ned).controller;
    vec![Helm { controller, serves: vec![0] }]
}

/// The controller of fleet AUV `v`, as a stream configuration gives it: its behaviours
/// by command mode, deciding after each depth reading (the last of a step's sensors).
pub(crate) fn fleet_spec(s: &Fleet, v: usize) -> ControllerSpec {
    let a = &s.auvs[v];
    ControllerSpec::Behaviours(BehavioursSpec {
        speed_m_s: a.speed_m_s,
        depth_m: a.depth_m,
        modes: a.modes.clone(),
        decide_on: "depth".into(),
    })
}

/// Each fleet AUV's behaviours by command mode, on its own first estimator.
pub(crate) fn fleet(s: &Fleet) -> Vec<Helm> {
    (0..s.auvs.len())
        .map(|v| Helm { controller: fleet_spec(s, v).build(Frame::Ned).controller, serves: vec![v] })
        .collect()
}
