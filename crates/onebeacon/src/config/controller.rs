//! A controller as a configuration file describes it (the `[controller]` table of a
//! stream configuration; feature `serde`): hoff2024's surface vehicle (`kind =
//! "bearing"`), sousa's beacon vehicle (`kind = "fim"`) or rypkema's AUV (`kind =
//! "behaviours"`). Positions are in the file's
//! frame, angles in degrees in keys named `*_deg`; [`ControllerSpec::build`] gives the
//! controller in NED.

use super::check::Violation;
use crate::geo::Frame;
use crate::guidance::bearing::{BearingPlanner, SpreadMetric, planner_too_slow};
use crate::guidance::{FimPlanner, Metric, PolarGrid};
use crate::nav::capability::Capability;
use crate::nav::limits::Limits;
use crate::vehicle::autonomy::{Autonomy, AutonomySettings, Behaviour};
use crate::vehicle::bearing::{BearingGuidance, BearingGuidanceConfig, BearingMode};
use crate::vehicle::behaviours::Behaviours;
use crate::vehicle::fim::{FimGuidance, FimGuidanceConfig, FimMode};
use crate::vehicle::unit::{DecideOn, Helm};
use nalgebra::Vector2;
use serde::{Deserialize, Serialize};

/// The `[controller]` table.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum ControllerSpec {
    /// hoff2024's surface vehicle: it tracks AUVs by their USBL bearings and plans where
    /// to go next (sec. 3); decides on each `own_fix` line.
    Bearing(BearingSpec),
    /// sousa's beacon vehicle: at each ping it goes where the next range tells the
    /// vehicle it serves the most (sec. 3.3); decides on each `own_fix` line.
    Fim(FimSpec),
    /// rypkema's AUV: the command mode its iUSBL navigator confirmed selects a
    /// beacon-relative behaviour (sec. 4.1-4.2); decides on each `depth` line.
    Behaviours(BehavioursSpec),
}

/// Where the surface vehicle goes (`mode`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BearingModeName {
    Planner,
    Static,
    Circle,
    Offset,
}

/// How the planner scores a candidate (`metric`, eq. 10).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MetricName {
    Determinant,
    MaxEigenvalue,
}

/// `kind = "bearing"`: defaults are hoff2024's (sec. 5, the built-in scenario's).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct BearingSpec {
    pub mode: BearingModeName,
    pub metric: MetricName,
    /// The half-annulus about the belief, m, and its candidates (radii x angles).
    pub r1_m: f64,
    pub r2_m: f64,
    pub radii: usize,
    pub angles: usize,
    /// The USBL's noise the planner assumes, deg per metre of range (eq. 3).
    pub usbl_sigma_deg_per_m: f64,
    /// The surface vehicle's speed along its legs, m/s, and the message period, s.
    pub nominal_speed_m_s: f64,
    pub period_s: f64,
    pub planner_particles: usize,
    pub lead_periods: f64,
    pub circle_radius_m: f64,
    pub offset_m: f64,
    /// The point a static surface vehicle holds (the file's frame).
    pub home_x_m: f64,
    pub home_y_m: f64,
    /// The line kind after which it decides.
    pub decide_on: String,
}

impl Default for BearingSpec {
    fn default() -> Self {
        Self {
            mode: BearingModeName::Planner,
            metric: MetricName::Determinant,
            r1_m: 16.0,
            r2_m: 26.0,
            radii: 3,
            angles: 19,
            usbl_sigma_deg_per_m: 0.01,
            nominal_speed_m_s: 2.2,
            period_s: 4.0,
            planner_particles: 20_000,
            lead_periods: 2.0,
            circle_radius_m: 20.0,
            offset_m: 20.0,
            home_x_m: 0.0,
            home_y_m: 0.0,
            decide_on: "own_fix".into(),
        }
    }
}

/// Where the beacon vehicle goes (`mode` of `kind = "fim"`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FimModeName {
    /// The FIM planner with its `metric`.
    Planner,
    /// Hold `home_x_m`, `home_y_m` (baseline).
    Static,
    /// Circle the vehicle's estimate at `circle_radius_m` (baseline).
    Circle,
}

/// How the FIM planner scores a candidate (`metric` of `kind = "fim"`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FimMetricName {
    /// det FIM of the previous and the next range (eq. 3.15).
    ApproachA,
    /// det FIM now plus det FIM at the vehicle's predicted position (eq. 3.16-3.19).
    ApproachB,
}

/// `kind = "fim"`: defaults are the built-in sousa scenario's (scenarios/sousa.toml,
/// which gives each its source or says it has none).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FimSpec {
    pub mode: FimModeName,
    pub metric: FimMetricName,
    /// The polar search grid over the reaching set: rings, directions and the
    /// refinements about the best cell.
    pub grid_radial: usize,
    pub grid_angular: usize,
    pub grid_refinements: usize,
    /// The vehicle's range noise the planner assumes, m (its FIM's variance).
    pub range_sigma_m: f64,
    /// The beacon transducer's depth, m.
    pub beacon_depth_m: f64,
    /// The ping period, s, and the beacon vehicle's top speed, m/s: the reaching set's
    /// radius is their product.
    pub period_s: f64,
    pub max_speed_m_s: f64,
    pub circle_radius_m: f64,
    /// The point a static beacon vehicle holds (the file's frame).
    pub home_x_m: f64,
    pub home_y_m: f64,
    /// The line kind after which it decides.
    pub decide_on: String,
}

impl Default for FimSpec {
    fn default() -> Self {
        Self {
            mode: FimModeName::Planner,
            metric: FimMetricName::ApproachA,
            // no source: the simulator's search grid since it was built
            grid_radial: 100,
            grid_angular: 72,
            grid_refinements: 12,
            // unstated in the thesis: a modem's OWTT noise
            range_sigma_m: 1.0,
            // eq. 3.7: the beacon at the surface
            beacon_depth_m: 0.0,
            // unstated in the thesis
            period_s: 10.0,
            // sec. 4.2.1: the ASV's top speed
            max_speed_m_s: 2.0,
            // no source: the circling baseline's radius
            circle_radius_m: 30.0,
            home_x_m: 0.0,
            home_y_m: 0.0,
            decide_on: "own_fix".into(),
        }
    }
}

/// `kind = "behaviours"`: the AUV's transit speed and depth and its behaviour per
/// command mode.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct BehavioursSpec {
    pub speed_m_s: f64,
    pub depth_m: f64,
    /// `[[controller.modes]]`: one behaviour per command mode.
    pub modes: Vec<ModeBehaviour>,
    pub decide_on: String,
}

impl Default for BehavioursSpec {
    fn default() -> Self {
        let d = AutonomySettings::default();
        Self { speed_m_s: d.speed_m_s, depth_m: d.depth_m, modes: Vec::new(), decide_on: "depth".into() }
    }
}

/// The most message periods a planner may lead its belief by: beyond a few, the
/// straight-line prediction from the estimated velocity means nothing (hoff2024 sec. 5
/// leads by 2). No source: a guard against a slip (1e9 sent commands 4e9 s ahead).
pub const MAX_LEAD_PERIODS: f64 = 100.0;

/// The command modes a bank holds (rypkema: 4).
pub const MODES: usize = 4;

/// A behaviour's name (`behaviour`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BehaviourName {
    Loiter,
    Trackline,
    OffsetFollow,
    Return,
    Abort,
}

/// One mode's behaviour and its parameters (offsets from the beacon, NED).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModeBehaviour {
    /// 1 to 4.
    pub mode: usize,
    pub behaviour: BehaviourName,
    #[serde(default)]
    pub offset_north_m: f64,
    #[serde(default)]
    pub offset_east_m: f64,
    /// Loiter.
    pub radius_m: Option<f64>,
    #[serde(default)]
    pub clockwise: bool,
    /// Trackline and return: the line's heading, deg from north; its length, m.
    pub heading_deg: Option<f64>,
    pub length_m: Option<f64>,
    /// Trackline and offset follow: the buffer, m.
    pub buffer_m: Option<f64>,
    /// Offset follow: the depth ceiling, m.
    pub ceiling_m: Option<f64>,
}

impl ModeBehaviour {
    /// The behaviour (its required keys checked by [`ControllerSpec::check`]).
    pub fn behaviour(&self) -> Behaviour {
        let at = Vector2::new(self.offset_north_m, self.offset_east_m);
        let heading = self.heading_deg.unwrap_or(0.0).to_radians();
        let length = self.length_m.unwrap_or(0.0);
        match self.behaviour {
            BehaviourName::Loiter => {
                Behaviour::Loiter { centre_m: at, radius_m: self.radius_m.unwrap_or(0.0), clockwise: self.clockwise }
            }
            BehaviourName::Trackline => Behaviour::Trackline {
                centre_m: at,
                heading_rad: heading,
                length_m: length,
                buffer_m: self.buffer_m.unwrap_or(0.0),
            },
            BehaviourName::OffsetFollow => Behaviour::OffsetFollow {
                offset_m: at,
                buffer_m: self.buffer_m.unwrap_or(0.0),
                ceiling_m: self.ceiling_m.unwrap_or(0.0),
            },
            BehaviourName::Return => Behaviour::Return { end_m: at, heading_rad: heading, length_m: length },
            BehaviourName::Abort => Behaviour::Abort,
        }
    }

    /// The keys `behaviour` needs.
    pub fn required(&self) -> &'static [&'static str] {
        match self.behaviour {
            BehaviourName::Loiter => &["radius_m"],
            BehaviourName::Trackline => &["heading_deg", "length_m", "buffer_m"],
            BehaviourName::OffsetFollow => &["buffer_m", "ceiling_m"],
            BehaviourName::Return => &["heading_deg", "length_m"],
            BehaviourName::Abort => &[],
        }
    }

    /// The value of a numeric key (None when absent or not a key).
    pub fn value(&self, key: &str) -> Option<f64> {
        match key {
            "radius_m" => self.radius_m,
            "heading_deg" => self.heading_deg,
            "length_m" => self.length_m,
            "buffer_m" => self.buffer_m,
            "ceiling_m" => self.ceiling_m,
            _ => None,
        }
    }
}

/// The behaviours of a bank of [`MODES`] modes (None: the mode keeps the current one).
pub fn mode_bank(modes: &[ModeBehaviour]) -> Vec<Option<Behaviour>> {
    let mut bank = vec![None; MODES];
    for m in modes {
        bank[m.mode - 1] = Some(m.behaviour());
    }
    bank
}

impl ControllerSpec {
    /// What it reads of its first estimator's navigator beyond the estimate (checked
    /// when a configuration is read: [`super::builder::VehicleModel`] and the kind must
    /// give it).
    pub fn needs(&self) -> Option<Capability> {
        match self {
            ControllerSpec::Behaviours(_) => Some(Capability::BeaconRelative),
            ControllerSpec::Fim(f) if f.mode == FimModeName::Planner && f.metric == FimMetricName::ApproachB => {
                Some(Capability::BodyVelocity)
            }
            _ => None,
        }
    }

    /// The line kind after which the controller decides.
    pub fn decide_on(&self) -> &str {
        match self {
            ControllerSpec::Bearing(b) => &b.decide_on,
            ControllerSpec::Fim(f) => &f.decide_on,
            ControllerSpec::Behaviours(b) => &b.decide_on,
        }
    }

    /// Checks the keys; `kinds` are the line kinds a stream may carry, `limits` the
    /// vehicle's (every setpoint within them: speeds within max_speed_m_s, depths within
    /// max_depth_m, distances and positions within max_range_m).
    pub fn check(&self, kinds: &[&str], limits: &Limits) -> Result<(), Violation> {
        let bad = |key: &str, value: String, allowed: &str| {
            Err(Violation { key: format!("controller.{key}"), value, allowed: allowed.into() })
        };
        if !kinds.contains(&self.decide_on()) {
            return bad("decide_on", format!("{:?}", self.decide_on()), &format!("one of {}", kinds.join(", ")));
        }
        let positive = |key: &str, v: f64| {
            if v.is_finite() && v > 0.0 { Ok(()) } else { bad(key, format!("{v:?}"), "must be a number > 0") }
        };
        // a setpoint within the vehicle's limits (`limit` names the [limits] key)
        let within = |key: &str, v: f64, most: f64, limit: &str| {
            if v.abs() <= most {
                Ok(())
            } else {
                bad(key, format!("{v:?}"), &format!("must be within {most} (limits.{limit}, the vehicle's)"))
            }
        };
        match self {
            ControllerSpec::Bearing(b) => {
                positive("r1_m", b.r1_m)?;
                if !(b.r2_m.is_finite() && b.r2_m >= b.r1_m) {
                    return bad("r2_m", format!("{:?}", b.r2_m), "must be a number >= r1_m");
                }
                for (key, v) in [
                    ("usbl_sigma_deg_per_m", b.usbl_sigma_deg_per_m),
                    ("nominal_speed_m_s", b.nominal_speed_m_s),
                    ("period_s", b.period_s),
                    ("circle_radius_m", b.circle_radius_m),
                    ("offset_m", b.offset_m),
                ] {
                    positive(key, v)?;
                }
                if !(b.lead_periods.is_finite() && (0.0..=MAX_LEAD_PERIODS).contains(&b.lead_periods)) {
                    let allowed = format!("must be a number from 0 to {MAX_LEAD_PERIODS}");
                    return bad("lead_periods", format!("{:?}", b.lead_periods), &allowed);
                }
                for (key, n) in [("radii", b.radii), ("angles", b.angles), ("planner_particles", b.planner_particles)] {
                    if !(1..=10_000_000).contains(&n) {
                        return bad(key, n.to_string(), "must be a count in 1..=10000000");
                    }
                }
                if let Some(why) = planner_too_slow(b.radii, b.angles, b.planner_particles, b.period_s) {
                    return bad("radii", b.radii.to_string(), &why);
                }
                within("nominal_speed_m_s", b.nominal_speed_m_s, limits.max_speed_m_s, "max_speed_m_s")?;
                for (key, v) in [
                    ("r2_m", b.r2_m),
                    ("circle_radius_m", b.circle_radius_m),
                    ("offset_m", b.offset_m),
                    ("home_x_m", b.home_x_m),
                    ("home_y_m", b.home_y_m),
                ] {
                    within(key, v, limits.max_range_m, "max_range_m")?;
                }
            }
            ControllerSpec::Fim(f) => {
                for (key, v) in [
                    ("range_sigma_m", f.range_sigma_m),
                    ("period_s", f.period_s),
                    ("max_speed_m_s", f.max_speed_m_s),
                    ("circle_radius_m", f.circle_radius_m),
                ] {
                    positive(key, v)?;
                }
                // the planner scores radial x angular cells, refinements times over
                for (key, n, most) in [
                    ("grid_radial", f.grid_radial, 10_000),
                    ("grid_angular", f.grid_angular, 10_000),
                    ("grid_refinements", f.grid_refinements, 100),
                ] {
                    if !(1..=most).contains(&n) {
                        return bad(key, n.to_string(), &format!("must be a count in 1..={most}"));
                    }
                }
                if f.grid_radial * f.grid_angular * f.grid_refinements > 10_000_000 {
                    let allowed =
                        "grid_radial x grid_angular x grid_refinements must be at most 1e7 (a decision's work)";
                    return bad("grid_radial", f.grid_radial.to_string(), allowed);
                }
                within("max_speed_m_s", f.max_speed_m_s, limits.max_speed_m_s, "max_speed_m_s")?;
                within("beacon_depth_m", f.beacon_depth_m, limits.max_depth_m, "max_depth_m")?;
                for (key, v) in
                    [("circle_radius_m", f.circle_radius_m), ("home_x_m", f.home_x_m), ("home_y_m", f.home_y_m)]
                {
                    within(key, v, limits.max_range_m, "max_range_m")?;
                }
            }
            ControllerSpec::Behaviours(b) => {
                positive("speed_m_s", b.speed_m_s)?;
                within("speed_m_s", b.speed_m_s, limits.max_speed_m_s, "max_speed_m_s")?;
                if !(b.depth_m.is_finite() && b.depth_m >= 0.0) {
                    return bad("depth_m", format!("{:?}", b.depth_m), "must be a depth >= 0");
                }
                within("depth_m", b.depth_m, limits.max_depth_m, "max_depth_m")?;
                for (i, m) in b.modes.iter().enumerate() {
                    if !(1..=MODES).contains(&m.mode) {
                        return bad(&format!("modes[{i}].mode"), m.mode.to_string(), "must be 1 to 4");
                    }
                    if b.modes[..i].iter().any(|o| o.mode == m.mode) {
                        return bad(&format!("modes[{i}].mode"), m.mode.to_string(), "is given twice");
                    }
                    for k in m.required() {
                        let v = m.value(k);
                        let ok = v.is_some_and(|v| v.is_finite() && (*k == "heading_deg" || v > 0.0));
                        if !ok {
                            let value = v.map_or("(absent)".into(), |v| format!("{v:?}"));
                            return bad(&format!("modes[{i}].{k}"), value, "the behaviour needs it, a number > 0");
                        }
                    }
                    for (k, v) in [("offset_north_m", m.offset_north_m), ("offset_east_m", m.offset_east_m)]
                        .into_iter()
                        .chain(["radius_m", "length_m", "buffer_m"].map(|k| (k, m.value(k).unwrap_or(0.0))))
                    {
                        within(&format!("modes[{i}].{k}"), v, limits.max_range_m, "max_range_m")?;
                    }
                    within(
                        &format!("modes[{i}].ceiling_m"),
                        m.ceiling_m.unwrap_or(0.0),
                        limits.max_depth_m,
                        "max_depth_m",
                    )?;
                }
            }
        }
        Ok(())
    }

    /// The controller, in NED from a file in `frame`, with the line kind it decides on.
    pub fn build(&self, frame: Frame) -> Helm {
        let decide_on = DecideOn(self.decide_on().to_string());
        let controller: Box<dyn crate::vehicle::Controller> = match self {
            ControllerSpec::Bearing(b) => {
                let home = frame.to_ned(b.home_x_m, b.home_y_m, 0.0);
                Box::new(BearingGuidance::new(BearingGuidanceConfig {
                    mode: match b.mode {
                        BearingModeName::Planner => BearingMode::Planner,
                        BearingModeName::Static => BearingMode::Static,
                        BearingModeName::Circle => BearingMode::Circle,
                        BearingModeName::Offset => BearingMode::Offset,
                    },
                    planner: BearingPlanner {
                        metric: match b.metric {
                            MetricName::Determinant => SpreadMetric::Determinant,
                            MetricName::MaxEigenvalue => SpreadMetric::MaxEigenvalue,
                        },
                        r1_m: b.r1_m,
                        r2_m: b.r2_m,
                        radii: b.radii,
                        angles: b.angles,
                        sigma_usbl_rad_per_m: b.usbl_sigma_deg_per_m.to_radians(),
                    },
                    nominal_speed_m_s: b.nominal_speed_m_s,
                    period_s: b.period_s,
                    planner_particles: b.planner_particles,
                    lead_periods: b.lead_periods,
                    circle_radius_m: b.circle_radius_m,
                    offset_m: b.offset_m,
                    home_m: home.xy(),
                }))
            }
            ControllerSpec::Fim(f) => {
                let home = frame.to_ned(f.home_x_m, f.home_y_m, 0.0);
                Box::new(FimGuidance::new(FimGuidanceConfig {
                    mode: match f.mode {
                        FimModeName::Planner => FimMode::Planner,
                        FimModeName::Static => FimMode::Static,
                        FimModeName::Circle => FimMode::Circle,
                    },
                    planner: FimPlanner {
                        metric: match f.metric {
                            FimMetricName::ApproachA => Metric::ApproachA,
                            FimMetricName::ApproachB => Metric::ApproachB,
                        },
                        grid: PolarGrid {
                            radial: f.grid_radial,
                            angular: f.grid_angular,
                            refinements: f.grid_refinements,
                        },
                        range_var_m2: f.range_sigma_m.powi(2),
                        beacon_depth_m: f.beacon_depth_m,
                    },
                    period_s: f.period_s,
                    max_speed_m_s: f.max_speed_m_s,
                    circle_radius_m: f.circle_radius_m,
                    home_m: home.xy(),
                }))
            }
            ControllerSpec::Behaviours(b) => {
                let settings = AutonomySettings { speed_m_s: b.speed_m_s, depth_m: b.depth_m, ..Default::default() };
                Box::new(Behaviours::new(Autonomy::new(settings, mode_bank(&b.modes))))
            }
        };
        Helm { controller, decide_on }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn checked(toml: &str) -> Result<(), Violation> {
        let spec: ControllerSpec = toml::from_str(toml).unwrap();
        spec.check(&["own_fix", "depth"], &Limits::default())
    }

    /// What cfb7f93 took and sent out: a planner 5000 times over its period's work (11 s
    /// a decision against 4 s), a lead of 1e9 periods, a home 1e308 m away, an AUV
    /// commanded 1e9 m deep at 1e308 m/s. Each is refused by its key; hoff2024's and
    /// rypkema's settings are taken.
    #[test]
    fn the_controllers_work_and_setpoints_are_bounded() {
        assert!(checked("kind = \"bearing\"").is_ok());
        let refused = |toml: &str, key: &str, words: &str| {
            let v = checked(toml).unwrap_err();
            assert_eq!(v.key, format!("controller.{key}"), "{toml}: {v}");
            assert!(v.allowed.contains(words), "{toml}: {v}");
        };
        refused("kind = \"bearing\"\nradii = 1000\nangles = 1000", "radii", "at most 4.000e8 fit a period of 4 s");
        assert!(checked("kind = \"bearing\"\nradii = 10\nangles = 100\nperiod_s = 1.0").is_ok());
        refused("kind = \"bearing\"\nlead_periods = 1e9", "lead_periods", "from 0 to 100");
        refused("kind = \"bearing\"\nhome_x_m = 1e308", "home_x_m", "limits.max_range_m");
        refused("kind = \"bearing\"\nnominal_speed_m_s = 1e308", "nominal_speed_m_s", "limits.max_speed_m_s");
        let asv = "kind = \"fim\"\n";
        assert!(checked(asv).is_ok());
        refused(&format!("{asv}grid_radial = 10000\ngrid_angular = 10000"), "grid_radial", "at most 1e7");
        refused(&format!("{asv}grid_refinements = 0"), "grid_refinements", "1..=100");
        refused(&format!("{asv}max_speed_m_s = 1e308"), "max_speed_m_s", "limits.max_speed_m_s");
        refused(&format!("{asv}home_y_m = 1e308"), "home_y_m", "limits.max_range_m");
        refused(&format!("{asv}range_sigma_m = 0"), "range_sigma_m", "> 0");
        let auv = "kind = \"behaviours\"\n";
        assert!(checked(auv).is_ok());
        refused(&format!("{auv}depth_m = 1e9"), "depth_m", "limits.max_depth_m");
        refused(&format!("{auv}speed_m_s = 1e308"), "speed_m_s", "limits.max_speed_m_s");
        let mode = "[[modes]]\nmode = 1\nbehaviour = \"loiter\"\nradius_m = 1e12";
        refused(&format!("{auv}{mode}"), "modes[0].radius_m", "limits.max_range_m");
    }
}
