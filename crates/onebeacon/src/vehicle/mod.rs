//! The vehicle's own computer: what a vehicle decides from what its navigators believe.
//!
//! A [`Controller`] turns the beliefs of navigators (its own vehicle's, or the vehicles
//! it serves) and what the vehicle knows of itself ([`Situation`]: its clock, and at the
//! surface its GPS and compass) into a [`Command`] for its autopilots. The papers'
//! decision logic lives here, so that the same code runs in the simulator, on a log and
//! on a vehicle:
//!
//! - [`bearing::BearingGuidance`]: hoff2024's surface vehicle: which AUV to serve, the
//!   half-annulus planner (eq. 10-12) and its straight legs (eq. 13-16), or a baseline;
//! - [`fim::FimGuidance`]: sousa's beacon vehicle: the waypoint of largest Fisher
//!   information in its reaching set at each ping (eq. 3.15-3.19), or a baseline;
//! - [`behaviours::Behaviours`] on [`autonomy`]: rypkema's AUV: the command mode its navigator confirmed
//!   selects a beacon-relative behaviour (sec. 4.1-4.2) whose setpoint it follows.
//!
//! The simulator's engine runs every step as: each controller decides, the world moves
//! its truth under the commands and says what was heard, the navigators process it.

pub mod autonomy;
pub mod bearing;
pub mod behaviours;
pub mod fim;
pub mod unit;

use crate::guidance::FimPlanner;
use crate::nav::Navigator;
use crate::nav::capability::Capability;
use nalgebra::{Vector2, Vector3};

/// What a vehicle knows of itself when it decides.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Situation {
    /// Its clock, s.
    pub t_s: f64,
    /// Its own fix, when it has one (a surface vehicle's GPS and compass; an AUV
    /// navigates on its navigators instead).
    pub fix: Option<OwnFix>,
}

/// A vehicle's own position, heading and speed, as its sensors give them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OwnFix {
    /// Horizontal NED position, m.
    pub position_m: Vector2<f64>,
    /// Heading, rad, and speed through the water, m/s.
    pub heading_rad: f64,
    pub speed_m_s: f64,
}

/// What a controller asks of its vehicle's autopilots.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Command {
    /// Follow the straight path from `from` to `to` over the next period, timed along it
    /// (hoff2024 eq. 24-26).
    Path { from: Vector2<f64>, to: Vector2<f64> },
    /// Be at `waypoint` at time `arrive_s` (sousa sec. 3.3).
    Waypoint { waypoint: Vector2<f64>, arrive_s: f64 },
    /// Hold a heading, speed and depth: a behaviour's setpoint, with the command mode
    /// that selected it and what the behaviour is doing.
    Setpoint { setpoint: Setpoint, mode: Option<usize>, phase: Phase },
}

/// What the autonomy asks of the vehicle's autopilots.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Setpoint {
    pub heading_rad: f64,
    /// Speed over ground, m/s; 0: propeller off.
    pub speed_m_s: f64,
    pub depth_m: f64,
}

/// What the vehicle is doing, for records and pictures.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    /// No mode confirmed yet: holding heading at depth.
    Waiting,
    /// Driving (to a point, along a line, around a circle).
    Driving,
    /// Propeller off at an offset-follow point.
    Drifting,
    /// Propeller off for good: a return's end or an abort.
    Surfacing,
}

/// A guidance decision with what it was taken on, for records and pictures.
#[derive(Debug, Clone, PartialEq)]
pub enum GuidanceSnapshot {
    /// A beacon vehicle's FIM guidance at one ping (sousa).
    Fim(FimSnapshot),
    /// A surface vehicle's bearing planner at one decision (hoff2024).
    Bearing(BearingSnapshot),
}

/// What a surface vehicle's bearing planner knew and chose at one decision
/// (hoff2024 Fig. 3): the candidates on the half-annulus with their scores.
#[derive(Debug, Clone, PartialEq)]
pub struct BearingSnapshot {
    pub t_s: f64,
    /// The AUV the decision served.
    pub vehicle: usize,
    /// The ASV's position, the belief's mean shifted by the lead (NED).
    pub asv: Vector2<f64>,
    pub belief_mean: Vector3<f64>,
    pub candidates: Vec<(Vector2<f64>, f64)>,
    pub waypoint: Vector2<f64>,
}

/// What the beacon vehicle's FIM guidance knew and chose at one ping, so that its
/// metric can be mapped over the reaching set (sousa Fig. 3.5, 3.7).
#[derive(Debug, Clone, PartialEq)]
pub struct FimSnapshot {
    pub t_s: f64,
    /// The planner whose metric is mapped (approach A for the baselines).
    pub planner: FimPlanner,
    /// The beacon's position estimate at this ping, the centre of its reaching set.
    pub previous: Vector2<f64>,
    pub reach_m: f64,
    /// The vehicle's estimate now and predicted at the next ping.
    pub target: Vector3<f64>,
    pub target_next: Vector3<f64>,
    /// The waypoint the guidance chose.
    pub waypoint: Vector2<f64>,
}

/// A decision: the command, and the guidance snapshot when a planner was consulted.
#[derive(Debug, Clone, PartialEq)]
pub struct Decided {
    pub command: Command,
    pub snapshot: Option<GuidanceSnapshot>,
}

impl From<Command> for Decided {
    fn from(command: Command) -> Self {
        Self { command, snapshot: None }
    }
}

/// Why a controller could not decide.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DecideError {
    /// A surface vehicle's guidance needs its own fix (GPS and compass).
    #[error("no own position fix: a surface vehicle's guidance needs its GPS and compass")]
    NoFix,
    /// The controller reads the beliefs of `needed` vehicles and was given `given`.
    #[error("the controller reads {needed} vehicles' beliefs, {given} given")]
    Beliefs { needed: usize, given: usize },
    /// The navigators it reads have not started (no initial state yet).
    #[error("the navigators have not started yet")]
    NotStarted,
    /// The navigator it reads cannot tell what it needs (a configuration check refuses
    /// such a pair before it runs).
    #[error("the controller needs {}, which its navigator does not give", .0.label())]
    Lacks(Capability),
}

/// What turns beliefs into a command.
pub trait Controller: Send {
    /// Decides from the vehicle's own `situation` and `beliefs`: the first navigator of
    /// each vehicle the controller serves (a surface vehicle's trackers of the AUVs; an
    /// AUV's own navigator), as they stand now.
    fn decide(&mut self, situation: &Situation, beliefs: &[&dyn Navigator]) -> Result<Decided, DecideError>;
}

/// `situation`'s fix, or [`DecideError::NoFix`].
pub(crate) fn own_fix(situation: &Situation) -> Result<&OwnFix, DecideError> {
    situation.fix.as_ref().ok_or(DecideError::NoFix)
}

/// At least `needed` beliefs, or [`DecideError::Beliefs`].
pub(crate) fn need(beliefs: &[&dyn Navigator], needed: usize) -> Result<(), DecideError> {
    if beliefs.len() < needed { Err(DecideError::Beliefs { needed, given: beliefs.len() }) } else { Ok(()) }
}

#[cfg(test)]
mod tests {
    use super::autonomy::{Autonomy, AutonomySettings, Behaviour};
    use super::bearing::{BearingGuidance, BearingGuidanceConfig, BearingMode};
    use super::behaviours::Behaviours;
    use super::fim::{FimGuidance, FimGuidanceConfig, FimMode};
    use super::*;
    use crate::guidance::bearing::{BearingPlanner, SpreadMetric};
    use crate::guidance::{Metric, PolarGrid};
    use crate::nav::{Estimate, Measurement, Outcome};
    use approx::assert_abs_diff_eq;
    use nalgebra::Matrix2;

    /// A belief that stands still: an estimate at `at` heading `heading`, a command mode
    /// and a beacon-relative position.
    struct Fixed {
        at: Vector3<f64>,
        heading: f64,
        sigma_m: f64,
        mode: Option<usize>,
        relative: Option<Vector3<f64>>,
        body_velocity: Option<Vector3<f64>>,
    }

    impl Fixed {
        fn at(north: f64, east: f64) -> Self {
            Self {
                at: Vector3::new(north, east, 20.0),
                heading: 0.0,
                sigma_m: 1.0,
                mode: None,
                relative: None,
                body_velocity: None,
            }
        }
    }

    impl Navigator for Fixed {
        fn process(&mut self, _: &Measurement) -> Outcome {
            Outcome::Skipped
        }
        fn estimate(&self) -> Estimate {
            Estimate {
                t_s: 0.0,
                position_ned_m: self.at,
                horizontal_cov_m2: Matrix2::identity() * self.sigma_m.powi(2),
                heading_state_rad: self.heading,
                heading_var_rad2: 0.01,
                roll_pitch_rad: [0.0; 2],
                speed_m_s: Some(1.5),
                calibration: crate::nav::Calibration::default(),
            }
        }
        fn beacon_relative(&self) -> Option<&dyn crate::nav::capability::BeaconRelative> {
            self.relative.map(|_| self as &dyn crate::nav::capability::BeaconRelative)
        }
        fn body_velocity(&self) -> Option<&dyn crate::nav::capability::BodyVelocity> {
            self.body_velocity.map(|_| self as &dyn crate::nav::capability::BodyVelocity)
        }
    }

    impl crate::nav::capability::BeaconRelative for Fixed {
        fn beacon_relative_ned_m(&self) -> Vector3<f64> {
            self.relative.unwrap_or_default()
        }
        fn command_mode(&self) -> Option<usize> {
            self.mode
        }
    }

    impl crate::nav::capability::BodyVelocity for Fixed {
        fn body_velocity_m_s(&self) -> Vector3<f64> {
            self.body_velocity.unwrap_or_default()
        }
    }

    fn surface(north: f64, east: f64) -> Situation {
        let fix = OwnFix { position_m: Vector2::new(north, east), heading_rad: 0.0, speed_m_s: 1.0 };
        Situation { t_s: 10.0, fix: Some(fix) }
    }

    fn bearing(mode: BearingMode) -> BearingGuidance {
        BearingGuidance::new(BearingGuidanceConfig {
            mode,
            planner: BearingPlanner {
                metric: SpreadMetric::Determinant,
                r1_m: 16.0,
                r2_m: 26.0,
                radii: 3,
                angles: 7,
                sigma_usbl_rad_per_m: 0.022f64.to_radians(),
            },
            nominal_speed_m_s: 2.0,
            period_s: 4.0,
            planner_particles: 400,
            lead_periods: 2.0,
            circle_radius_m: 20.0,
            offset_m: 20.0,
            home_m: Vector2::new(-5.0, 3.0),
        })
    }

    fn path(d: &Decided) -> (Vector2<f64>, Vector2<f64>) {
        let Command::Path { from, to } = d.command else { panic!("{:?}", d.command) };
        (from, to)
    }

    /// The baselines' geometry: static heads home; trailing 20 m behind an AUV heading
    /// north at (100, 0) from (0, 0) is one period's reach (8 m) toward (80, 0); circling
    /// at 20 m from 20 m east of the AUV steps 8 / 20 rad around it (capped at pi / 2).
    #[test]
    fn the_surface_vehicles_baselines() {
        let auv = Fixed::at(100.0, 0.0);
        let d = bearing(BearingMode::Static).decide(&surface(0.0, 0.0), &[&auv]).unwrap();
        assert_eq!(path(&d), (Vector2::zeros(), Vector2::new(-5.0, 3.0)));
        let d = bearing(BearingMode::Offset).decide(&surface(0.0, 0.0), &[&auv]).unwrap();
        assert_abs_diff_eq!(path(&d).1, Vector2::new(8.0, 0.0), epsilon = 1e-12);
        let d = bearing(BearingMode::Circle).decide(&surface(100.0, 20.0), &[&auv]).unwrap();
        let a = std::f64::consts::FRAC_PI_2 + 8.0 / 20.0;
        let circle = Vector2::new(100.0 + 20.0 * a.cos(), 20.0 * a.sin());
        let step = circle - Vector2::new(100.0, 20.0);
        assert_abs_diff_eq!(
            path(&d).1,
            Vector2::new(100.0, 20.0) + step.normalize() * 8.0_f64.min(step.norm()),
            epsilon = 1e-9
        );
        assert!(d.snapshot.is_none());
    }

    /// The planner serves the least certain AUV, plans a waypoint on its half-annulus
    /// (16-26 m from the lead-shifted belief), and keeps that leg until eq. 16 says it is
    /// done: a second decision from the leg's start takes no new plan.
    #[test]
    fn the_planner_serves_the_least_certain_auv_and_keeps_its_leg() {
        let sure = Fixed::at(50.0, 0.0);
        let unsure = Fixed { sigma_m: 5.0, ..Fixed::at(0.0, 60.0) };
        let mut g = bearing(BearingMode::Planner);
        let d = g.decide(&surface(0.0, 0.0), &[&sure, &unsure]).unwrap();
        let Some(GuidanceSnapshot::Bearing(b)) = &d.snapshot else { panic!("a plan") };
        assert_eq!(b.vehicle, 1);
        let r = (b.waypoint - b.belief_mean.xy()).norm();
        assert!((16.0 - 1e-9..=26.0 + 1e-9).contains(&r), "{r}");
        let (from, to) = path(&d);
        assert_abs_diff_eq!(from, Vector2::zeros(), epsilon = 1e-12);
        assert_abs_diff_eq!((to - from).norm(), 8.0_f64.min(b.waypoint.norm()), epsilon = 1e-9);
        let again = g.decide(&surface(0.0, 0.0), &[&sure, &unsure]).unwrap();
        assert!(again.snapshot.is_none());
    }

    /// A surface vehicle's guidance without its own fix, or without the beliefs it
    /// reads, is an error (not a panic); so is a controller whose navigator lacks what
    /// it reads (behaviours without a beacon-relative position, approach B without a
    /// body velocity), where these fell back on zeros before.
    #[test]
    fn missing_inputs_are_errors() {
        let auv = Fixed::at(1.0, 1.0);
        let blind = Situation { t_s: 0.0, fix: None };
        assert_eq!(bearing(BearingMode::Planner).decide(&blind, &[&auv]).unwrap_err(), DecideError::NoFix);
        assert_eq!(
            bearing(BearingMode::Planner).decide(&surface(0.0, 0.0), &[]).unwrap_err(),
            DecideError::Beliefs { needed: 1, given: 0 }
        );
        let mut behaviours = Behaviours::new(Autonomy::new(AutonomySettings::default(), vec![None]));
        let lacks = DecideError::Lacks(Capability::BeaconRelative);
        assert_eq!(behaviours.decide(&blind, &[&auv]).unwrap_err(), lacks);
        let lacks = DecideError::Lacks(Capability::BodyVelocity);
        assert_eq!(fim(FimMode::Planner).decide(&surface(0.0, 0.0), &[&auv]).unwrap_err(), lacks);
        // approach A's baselines predict no motion without it
        assert!(fim(FimMode::Static).decide(&surface(0.0, 0.0), &[&auv]).is_ok());
    }

    fn fim(mode: FimMode) -> FimGuidance {
        FimGuidance::new(FimGuidanceConfig {
            mode,
            planner: crate::guidance::FimPlanner {
                metric: Metric::ApproachB,
                grid: PolarGrid { radial: 8, angular: 16, refinements: 6 },
                range_var_m2: 1.0,
                beacon_depth_m: 0.5,
            },
            period_s: 10.0,
            max_speed_m_s: 2.0,
            circle_radius_m: 25.0,
            home_m: Vector2::new(7.0, 7.0),
        })
    }

    /// The FIM guidance reaches within its set (20 m a ping), arrives by the next ping,
    /// predicts the vehicle on its last body velocity (1 m/s north for 10 s), and its
    /// baselines map approach A's metric.
    #[test]
    fn the_beacon_vehicles_waypoint() {
        let auv = Fixed { body_velocity: Some(Vector3::new(1.0, 0.0, 0.0)), ..Fixed::at(30.0, 0.0) };
        let d = fim(FimMode::Planner).decide(&surface(0.0, 0.0), &[&auv]).unwrap();
        let Command::Waypoint { waypoint, arrive_s } = d.command else { panic!() };
        assert!(waypoint.norm() <= 20.0 + 1e-9 && arrive_s == 20.0, "{waypoint} {arrive_s}");
        let Some(GuidanceSnapshot::Fim(f)) = d.snapshot else { panic!() };
        assert_abs_diff_eq!(f.target_next - f.target, Vector3::new(10.0, 0.0, 0.0), epsilon = 1e-12);
        assert_eq!(f.planner.metric, Metric::ApproachB);
        let d = fim(FimMode::Static).decide(&surface(0.0, 0.0), &[&auv]).unwrap();
        let Some(GuidanceSnapshot::Fim(f)) = d.snapshot else { panic!() };
        assert_eq!((f.waypoint, f.planner.metric), (Vector2::new(7.0, 7.0), Metric::ApproachA));
    }

    /// The AUV holds heading at depth until a mode is confirmed, then follows the mode's
    /// behaviour: an abort stops the propeller.
    #[test]
    fn the_auvs_behaviour_follows_the_confirmed_mode() {
        let autonomy = Autonomy::new(AutonomySettings::default(), vec![None, Some(Behaviour::Abort)]);
        let mut b = Behaviours::new(autonomy);
        let mut auv = Fixed { heading: 0.3, relative: Some(Vector3::new(10.0, 0.0, 2.0)), ..Fixed::at(0.0, 0.0) };
        let now = Situation { t_s: 1.0, fix: None };
        let Command::Setpoint { setpoint, mode, phase } = b.decide(&now, &[&auv]).unwrap().command else { panic!() };
        assert_eq!((mode, phase), (None, Phase::Waiting));
        assert_abs_diff_eq!(setpoint.heading_rad, 0.3, epsilon = 1e-12);
        auv.mode = Some(1);
        let Command::Setpoint { setpoint, mode, phase } = b.decide(&now, &[&auv]).unwrap().command else { panic!() };
        assert_eq!((mode, phase, setpoint.speed_m_s), (Some(1), Phase::Surfacing, 0.0));
    }
}
