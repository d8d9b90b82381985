//! A vehicle's computer as its configuration file describes it (`onebeacon stream
//! CONFIG`, the Python `Navigator`): the frame, the fixed beacons, where the vehicle (or
//! each vehicle a surface vehicle tracks) starts, the estimators with their shared
//! `[noise]`, the limits and the controller. The keys are those of a log description
//! (docs/logs.md) without its CSV sources: a log description is a stream configuration
//! plus where its files are, and the simulator's replay reads it into this type.

use super::builder::{TrackerStart, VehicleModel};
use super::check::{Rule, Violation, check, check_count, check_file_name};
use super::controller::ControllerSpec;
use super::estimator::{EstimatorSpec, NOISE_KEYS};
use super::estimator_check::check_estimators;
use crate::geo::Frame;
use crate::nav::capability::Capability;
use crate::nav::limits::Limits;
use crate::nav::restart::Builder;
use crate::nav::session::{Session, Start};
use crate::vehicle::unit::Unit;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};
use std::collections::{BTreeMap, BTreeSet};

/// The frame of the file's x, y, z and headings (`frame` key).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FrameKey {
    #[default]
    Ned,
    Enu,
}

impl From<FrameKey> for Frame {
    fn from(f: FrameKey) -> Self {
        match f {
            FrameKey::Ned => Frame::Ned,
            FrameKey::Enu => Frame::Enu,
        }
    }
}

/// Where a vehicle's estimators start from (`from` of `[initial]`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum InitialFrom {
    /// The first ground-truth pose.
    #[default]
    GroundTruth,
    /// `x_m`, `y_m`, `heading_deg`.
    Given,
    /// A robust multilateration of the ranges of the first `ranges_window_s` seconds
    /// (three beacons at least), heading from `heading_deg` or the window's first heading
    /// measurement: for a log whose start is unknown or doubtful (replay only).
    Ranges,
}

/// Where the start's heading comes from (`heading_from` of `[initial]`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum HeadingFrom {
    /// The ground truth's heading column.
    #[default]
    Column,
    /// The direction of the ground-truth track over its first `track_m` metres (when
    /// the heading column is missing or not to be trusted); replay only.
    Track,
}

/// Where a vehicle's estimators start (`[initial]`, or one of `[[tracked]]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Initial {
    #[serde(default)]
    pub from: InitialFrom,
    #[serde(default)]
    pub heading_from: HeadingFrom,
    #[serde(default = "default_track_m")]
    pub track_m: f64,
    /// `from = "ranges"`: how long ranges are gathered from the first one, s.
    #[serde(default = "default_ranges_window_s")]
    pub ranges_window_s: f64,
    pub x_m: Option<f64>,
    pub y_m: Option<f64>,
    pub heading_deg: Option<f64>,
    /// Initial standard deviations (`sigma_position_m`, `sigma_heading_deg`, the old
    /// names, are read too).
    #[serde(default = "default_position_sigma_m", alias = "sigma_position_m")]
    pub position_sigma_m: f64,
    #[serde(default = "default_heading_sigma_deg", alias = "sigma_heading_deg")]
    pub heading_sigma_deg: f64,
    /// When the estimators start, s (default: the first item's time).
    pub t0_s: Option<f64>,
    /// The seed of the vehicle's particle filters, any 64-bit integer (an estimator's
    /// `seed` replaces it; default 0).
    pub seed: Option<i64>,
    /// The rest of a USBL tracker's state (kinds pf and bearing: hoff2024's eight
    /// states) and its standard deviations; the rate biases start at 0 unless given.
    /// The 6-DOF filter (`model = "6dof"`) reads depth, pitch and roll, with the
    /// depth's and pitch's standard deviations (the roll's is the pitch's).
    #[serde(default)]
    pub depth_m: f64,
    #[serde(default)]
    pub pitch_deg: f64,
    #[serde(default, skip_serializing_if = "is_zero")]
    pub roll_deg: f64,
    #[serde(default)]
    pub speed_m_s: f64,
    #[serde(default)]
    pub pitch_rate_bias_deg_s: f64,
    #[serde(default)]
    pub heading_rate_bias_deg_s: f64,
    #[serde(default = "default_depth_sigma_m")]
    pub depth_sigma_m: f64,
    #[serde(default = "default_pitch_sigma_deg")]
    pub pitch_sigma_deg: f64,
    #[serde(default = "default_speed_sigma_m_s")]
    pub speed_sigma_m_s: f64,
    #[serde(default = "default_rate_bias_sigma_deg_s")]
    pub rate_bias_sigma_deg_s: f64,
    /// The unicycle's (`model = "unicycle"`) yaw rate and acceleration, with speed
    /// (`speed_m_s`), and their standard deviations (the speed's is `speed_sigma_m_s`).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub yaw_rate_deg_s: f64,
    #[serde(default, skip_serializing_if = "is_zero")]
    pub accel_m_s2: f64,
    #[serde(default = "default_yaw_rate_sigma_deg_s", skip_serializing_if = "is_default_yaw_rate_sigma")]
    pub yaw_rate_sigma_deg_s: f64,
    #[serde(default = "default_accel_sigma_m_s2", skip_serializing_if = "is_default_accel_sigma")]
    pub accel_sigma_m_s2: f64,
}

/// Left out, `[initial]` starts from the first ground-truth pose and its heading column.
impl Default for Initial {
    fn default() -> Self {
        Self {
            from: InitialFrom::default(),
            heading_from: HeadingFrom::default(),
            track_m: default_track_m(),
            ranges_window_s: default_ranges_window_s(),
            x_m: None,
            y_m: None,
            heading_deg: None,
            position_sigma_m: default_position_sigma_m(),
            heading_sigma_deg: default_heading_sigma_deg(),
            t0_s: None,
            seed: None,
            depth_m: 0.0,
            pitch_deg: 0.0,
            roll_deg: 0.0,
            speed_m_s: 0.0,
            pitch_rate_bias_deg_s: 0.0,
            heading_rate_bias_deg_s: 0.0,
            depth_sigma_m: default_depth_sigma_m(),
            pitch_sigma_deg: default_pitch_sigma_deg(),
            speed_sigma_m_s: default_speed_sigma_m_s(),
            rate_bias_sigma_deg_s: default_rate_bias_sigma_deg_s(),
            yaw_rate_deg_s: 0.0,
            accel_m_s2: 0.0,
            yaw_rate_sigma_deg_s: default_yaw_rate_sigma_deg_s(),
            accel_sigma_m_s2: default_accel_sigma_m_s2(),
        }
    }
}

impl Initial {
    /// What a USBL tracker, the 6-DOF filter or the unicycle filter starts from besides
    /// the pose.
    pub fn tracker_start(&self) -> TrackerStart {
        TrackerStart {
            state: [
                self.depth_m,
                self.pitch_deg.to_radians(),
                self.speed_m_s,
                self.pitch_rate_bias_deg_s.to_radians(),
                self.heading_rate_bias_deg_s.to_radians(),
            ],
            sigma: [
                self.depth_sigma_m,
                self.pitch_sigma_deg.to_radians(),
                self.speed_sigma_m_s,
                self.rate_bias_sigma_deg_s.to_radians(),
            ],
            roll_rad: self.roll_deg.to_radians(),
            yaw_rate_accel: [self.yaw_rate_deg_s.to_radians(), self.accel_m_s2],
            yaw_rate_accel_sigma: [self.yaw_rate_sigma_deg_s.to_radians(), self.accel_sigma_m_s2],
            seed: self.seed,
        }
    }

    /// The initial position and heading standard deviations (m, rad).
    pub fn sigmas(&self) -> (f64, f64) {
        (self.position_sigma_m, self.heading_sigma_deg.to_radians())
    }

    /// The given pose in NED (N, E, psi) when `from = "given"`.
    pub fn given_pose(&self, frame: Frame) -> Option<(f64, f64, f64)> {
        if self.from != InitialFrom::Given {
            return None;
        }
        let p = frame.to_ned(self.x_m?, self.y_m?, 0.0);
        Some((p.x, p.y, frame.heading_to_ned(self.heading_deg?.to_radians())))
    }

    /// The keys of one `[initial]` table (or one of `[[tracked]]`, `section` naming it).
    pub fn check(&self, section: &str) -> Result<(), Violation> {
        if self.from == InitialFrom::Given && (self.x_m.is_none() || self.y_m.is_none() || self.heading_deg.is_none()) {
            return Err(Violation {
                key: format!("{section}.from"),
                value: "\"given\"".into(),
                allowed: format!("needs {section}.x_m, {section}.y_m and {section}.heading_deg"),
            });
        }
        for (key, v) in [("x_m", self.x_m), ("y_m", self.y_m), ("heading_deg", self.heading_deg), ("t0_s", self.t0_s)] {
            if let Some(v) = v {
                check(&format!("{section}.{key}"), v, Rule::Finite)?;
            }
        }
        for (key, v, rule) in [
            ("position_sigma_m", self.position_sigma_m, Rule::Positive),
            ("heading_sigma_deg", self.heading_sigma_deg, Rule::Positive),
            ("track_m", self.track_m, Rule::Positive),
            ("ranges_window_s", self.ranges_window_s, Rule::Positive),
            ("depth_m", self.depth_m, Rule::Finite),
            ("pitch_deg", self.pitch_deg, Rule::Finite),
            ("roll_deg", self.roll_deg, Rule::Finite),
            ("speed_m_s", self.speed_m_s, Rule::Finite),
            ("pitch_rate_bias_deg_s", self.pitch_rate_bias_deg_s, Rule::Finite),
            ("heading_rate_bias_deg_s", self.heading_rate_bias_deg_s, Rule::Finite),
            ("depth_sigma_m", self.depth_sigma_m, Rule::Positive),
            ("pitch_sigma_deg", self.pitch_sigma_deg, Rule::Positive),
            ("speed_sigma_m_s", self.speed_sigma_m_s, Rule::Positive),
            ("rate_bias_sigma_deg_s", self.rate_bias_sigma_deg_s, Rule::Positive),
            ("yaw_rate_deg_s", self.yaw_rate_deg_s, Rule::Finite),
            ("accel_m_s2", self.accel_m_s2, Rule::Finite),
            ("yaw_rate_sigma_deg_s", self.yaw_rate_sigma_deg_s, Rule::Positive),
            ("accel_sigma_m_s2", self.accel_sigma_m_s2, Rule::Positive),
        ] {
            check(&format!("{section}.{key}"), v, rule)?;
        }
        Ok(())
    }
}

fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

fn default_track_m() -> f64 {
    2.0
}
fn default_ranges_window_s() -> f64 {
    30.0
}
fn default_position_sigma_m() -> f64 {
    1.0
}
fn default_heading_sigma_deg() -> f64 {
    5.0
}
// a tracker's, as hoff2024's built-in scenario
fn default_depth_sigma_m() -> f64 {
    1.0
}
fn default_pitch_sigma_deg() -> f64 {
    2.0
}
fn default_speed_sigma_m_s() -> f64 {
    0.3
}
fn default_rate_bias_sigma_deg_s() -> f64 {
    0.05
}
// the unicycle's, as the fixed_beacon world's defaults (0.01 rad/s, 0.01 m/s^2; no
// source beyond that world's own choice)
fn default_yaw_rate_sigma_deg_s() -> f64 {
    0.01f64.to_degrees()
}
fn default_accel_sigma_m_s2() -> f64 {
    0.01
}
fn is_default_yaw_rate_sigma(v: &f64) -> bool {
    *v == default_yaw_rate_sigma_deg_s()
}
fn is_default_accel_sigma(v: &f64) -> bool {
    *v == default_accel_sigma_m_s2()
}

/// Where one vehicle's estimators start: when and from which pose (the session's
/// [`Start`]), the rest of a tracker's start, and the initial position and heading
/// standard deviations (m, rad).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VehicleStart {
    pub start: Start,
    pub tracker: TrackerStart,
    pub sigmas: (f64, f64),
}

/// One fixed beacon (`[[beacon]]`), in the file's frame, m.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Beacon {
    pub id: u32,
    pub x_m: f64,
    pub y_m: f64,
    #[serde(default)]
    pub z_m: f64,
}

/// A stream configuration file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StreamConfig {
    pub name: String,
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub description: String,
    #[serde(default)]
    pub frame: FrameKey,
    /// The estimators' vehicle model: `"planar"` (default), sousa's `"6dof"`, whose
    /// estimators take a moving_beacon world's keys, or garin2024's `"unicycle"`, whose
    /// estimators take a fixed_beacon world's.
    #[serde(default, skip_serializing_if = "VehicleModel::is_planar")]
    pub model: VehicleModel,
    /// Fixed beacons (`[[beacon]]`), in the file's frame.
    #[serde(default, rename = "beacon", skip_serializing_if = "Vec::is_empty")]
    pub beacons: Vec<Beacon>,
    #[serde(default)]
    pub initial: Initial,
    /// `[[tracked]]`: the vehicles a surface vehicle tracks, one `[initial]` table each
    /// (a line's `vehicle` is its index); without it, one vehicle from `[initial]`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub tracked: Vec<Initial>,
    /// `[[estimators]]` as in scenarios (`[[estimator]]`, the old name, is read too).
    #[serde(alias = "estimator")]
    pub estimators: Vec<EstimatorSpec>,
    /// Noise keys every estimator takes unless it gives its own (`[noise]`): one place
    /// for what the sensors are, the estimators differing in what they estimate. Its
    /// keys are [`NOISE_KEYS`]; [`StreamConfig::checked`] hands them to the estimators.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub noise: BTreeMap<String, f64>,
    /// What an item must respect before any estimator sees it.
    #[serde(default)]
    pub limits: Limits,
    /// The vehicle's controller: a surface vehicle's planner or an AUV's behaviours,
    /// deciding on its estimators' beliefs.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub controller: Option<ControllerSpec>,
}

impl StreamConfig {
    /// Checks every key, then gives each estimator the `[noise]` keys it does not set:
    /// the configuration a [`StreamConfig::unit`] is built from.
    pub fn checked(mut self) -> Result<Self, Violation> {
        self.check()?;
        for e in &mut self.estimators {
            for (key, v) in &self.noise {
                e.key_mut(key).expect("checked: a noise key").get_or_insert(*v);
            }
        }
        Ok(self)
    }

    /// Every key in range, the first violation with its key.
    pub fn check(&self) -> Result<(), Violation> {
        check_file_name("name", &self.name)?;
        for (i, b) in self.beacons.iter().enumerate() {
            for (key, v) in [("x_m", b.x_m), ("y_m", b.y_m), ("z_m", b.z_m)] {
                check(&format!("beacon[{i}].{key}"), v, Rule::Finite)?;
            }
            if self.beacons[..i].iter().any(|o| o.id == b.id) {
                return Err(Violation {
                    key: format!("beacon[{i}].id"),
                    value: b.id.to_string(),
                    allowed: "must differ from the other beacons' ids".into(),
                });
            }
        }
        for (key, v) in &self.noise {
            let Some((_, positive)) = NOISE_KEYS.iter().find(|(k, _)| k == key) else {
                let keys: Vec<&str> = NOISE_KEYS.iter().map(|k| k.0).collect();
                return Err(Violation {
                    key: format!("noise.{key}"),
                    value: format!("{v:?}"),
                    allowed: format!("is not a noise key (keys: {})", keys.join(", ")),
                });
            };
            check(&format!("noise.{key}"), *v, if *positive { Rule::Positive } else { Rule::NonNegative })?;
        }
        check_estimators(&self.estimators, self.model.host())?;
        self.initial.check("initial")?;
        for (v, init) in self.tracked.iter().enumerate() {
            init.check(&format!("tracked[{v}]"))?;
        }
        let l = &self.limits;
        for (key, v) in [
            ("max_range_m", l.max_range_m),
            ("max_speed_m_s", l.max_speed_m_s),
            ("max_rate_rad_s", l.max_rate_rad_s),
            ("max_depth_m", l.max_depth_m),
            ("max_time_gap_s", l.max_time_gap_s),
        ] {
            check(&format!("limits.{key}"), v, Rule::Positive)?;
        }
        check_count("limits.max_beacons", l.max_beacons, 1, 1 << 20)?;
        check_count("limits.max_rejections", l.max_rejections, 0, 100_000_000)?;
        check_count("limits.max_line_bytes", l.max_line_bytes, 64, 1 << 26)?;
        // the controller's setpoints within the limits, checked first
        let Some(c) = &self.controller else { return Ok(()) };
        c.check(&crate::io::kinds(), l)?;
        // what it reads of its first estimator
        if let Some(need) = c.needs() {
            let first = self.estimators.first();
            if !first.is_some_and(|e| e.provides(need, self.model)) {
                let hint = match need {
                    Capability::BeaconRelative => "kind \"iusbl\" or \"iusbl-joint\" first among [[estimators]]",
                    Capability::BodyVelocity => "model = \"6dof\"",
                };
                return Err(Violation {
                    key: "estimators[0].kind".into(),
                    value: first.map_or("(none)".into(), |e| format!("{:?}", e.kind.label())),
                    allowed: format!("the [controller] reads {} of its first estimator: {hint}", need.label()),
                });
            }
        }
        Ok(())
    }

    /// A session of the estimators on a vehicle that starts as `initial` says, starting
    /// at `start`, restricted to `beacons` when given (replay and stream).
    pub fn session(&self, initial: &Initial, start: Start, beacons: Option<BTreeSet<u32>>) -> Session {
        let from = initial.tracker_start();
        let builders = self.estimators.iter().map(|e| e.builder(from, self.model)).collect();
        self.session_of(builders, start, initial.sigmas(), beacons)
    }

    /// A session of the estimators, each built by its builder in `builders`.
    fn session_of(
        &self,
        builders: Vec<Builder>,
        start: Start,
        sigmas: (f64, f64),
        beacons: Option<BTreeSet<u32>>,
    ) -> Session {
        let estimators = self.estimators.iter().map(EstimatorSpec::name).zip(builders).collect();
        let mut session = Session::new(self.frame.into(), estimators, start, sigmas, beacons).with_limits(self.limits);
        for (stats, e) in session.stats.iter_mut().zip(&self.estimators) {
            let (gate, kernel) = if self.model.is_planar() { e.log_gate() } else { e.gate() };
            *stats = stats.weighed_as(Some(gate), kernel);
        }
        session
    }

    /// Where each vehicle the computer estimates starts (its own from `[initial]`, or
    /// each of `[[tracked]]`): at its given pose, or at the first ground-truth line. A
    /// heading from the track starts where the track is `track_m` long (a stream cannot
    /// look ahead); a start from ranges, which needs a window of the log, is refused by
    /// its key.
    pub fn starts(&self) -> Result<Vec<VehicleStart>, Violation> {
        let frame = Frame::from(self.frame);
        let vehicles: Vec<(String, &Initial)> = if self.tracked.is_empty() {
            vec![("initial".into(), &self.initial)]
        } else {
            self.tracked.iter().enumerate().map(|(v, i)| (format!("tracked[{v}]"), i)).collect()
        };
        let mut starts = Vec::new();
        for (section, init) in vehicles {
            let start = match init.given_pose(frame) {
                Some(pose) => Start::At { t0_s: init.t0_s, pose },
                None if init.from == InitialFrom::Ranges => {
                    return Err(Violation {
                        key: format!("{section}.from"),
                        value: "\"ranges\"".into(),
                        allowed: "needs a window of the log; a stream starts from the first ground_truth line or a given pose".into(),
                    });
                }
                // a stream cannot look ahead: it starts where the track is track_m long
                None if init.heading_from == HeadingFrom::Track => Start::Track { track_m: init.track_m, from: None },
                None => Start::FirstTruth,
            };
            starts.push(VehicleStart { start, tracker: init.tracker_start(), sigmas: init.sigmas() });
        }
        Ok(starts)
    }

    /// The vehicle's computer: one session per vehicle it estimates, each started as
    /// [`StreamConfig::starts`] says, and the `[controller]` when there is one; no
    /// rejection log (a stream reports each line as it comes).
    pub fn unit(&self) -> Result<Unit, Violation> {
        Ok(self.unit_of(&self.starts()?, &EstimatorSpec::builder))
    }

    /// The vehicle's computer with its vehicles starting at `starts` (one session each)
    /// and each estimator built by `build` (its spec's [`EstimatorSpec::builder`], or
    /// the simulator's where a world's signal needs another): [`StreamConfig::unit`]'s,
    /// and the simulator's, which knows its starts to the last bit.
    pub fn unit_of(
        &self,
        starts: &[VehicleStart],
        build: &dyn Fn(&EstimatorSpec, TrackerStart, VehicleModel) -> Builder,
    ) -> Unit {
        let sessions = starts
            .iter()
            .map(|v| {
                let builders = self.estimators.iter().map(|e| build(e, v.tracker, self.model)).collect();
                let session = self.session_of(builders, v.start, v.sigmas, None);
                let limits = Limits { max_rejections: 0, ..*session.limits() };
                session.with_limits(limits)
            })
            .collect();
        let frame = Frame::from(self.frame);
        let fixed = self.beacons.iter().map(|b| (b.id, Vector3::new(b.x_m, b.y_m, b.z_m))).collect();
        let helm = self.controller.as_ref().map(|c| c.build(frame));
        Unit::new(sessions, fixed, frame, helm)
    }
}
