//! Scenarios of kind `moving_beacon` (sousa): an underwater vehicle (ROV/AUV) with
//! 6-DOF kinematics and dead reckoning, a surface vehicle (ASV) carrying the beacon and
//! steered by a guidance law, one-way travel-time ranges propagating at the speed of
//! sound between moving ends. Unknown keys are errors.

use super::estimator::Host;
use super::validate::*;
use super::{EstimatorKind, EstimatorSpec, World, default_runs, default_seed};
use crate::vehicles::rov::BodyPath;
use serde::{Deserialize, Serialize};

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MovingBeacon {
    /// `moving_beacon`.
    pub kind: World,
    pub name: String,
    #[serde(default)]
    pub description: String,
    #[serde(default = "default_seed")]
    pub seed: u64,
    #[serde(default = "default_runs::<20>")]
    pub runs: usize,
    #[serde(default)]
    pub mission: Mission,
    #[serde(default)]
    pub vehicle: Vehicle,
    /// More underwater vehicles in the same water: the same sensors and estimators,
    /// hearing the same pings; the ASV's guidance serves `vehicle` only, and the sweep
    /// changes only `vehicle`'s path and depth.
    #[serde(default)]
    pub other_vehicles: Vec<Vehicle>,
    #[serde(default)]
    pub sensors: Sensors,
    #[serde(default)]
    pub asv: Asv,
    #[serde(default)]
    pub acoustics: Acoustics,
    /// `[sea]`: clocks (off by default).
    #[serde(default)]
    pub sea: super::sea::Sea,
    #[serde(default)]
    pub guidance: Guidance,
    #[serde(default)]
    pub initial: Initial,
    #[serde(default = "default_estimators")]
    pub estimators: Vec<EstimatorSpec>,
    #[serde(default)]
    pub sweep: Sweep,
}

fn default_estimators() -> Vec<EstimatorSpec> {
    vec![EstimatorSpec::new(EstimatorKind::RangeEkf), EstimatorSpec::new(EstimatorKind::DeadReckoning)]
}

/// Time step and duration.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Mission {
    /// Truth integration (RK4) and filter step, s.
    pub dt_s: f64,
    pub duration_s: f64,
}

impl Default for Mission {
    fn default() -> Self {
        Self { dt_s: 0.1, duration_s: 7200.0 } // sousa 4.2: two-hour missions; 10 Hz
    }
}

pub use crate::vehicles::rov::PathKind;

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Vehicle {
    /// Name in outputs (default `auv` for `vehicle`, `auv2`, `auv3`, ... for
    /// `other_vehicles`).
    pub name: Option<String>,
    pub path: PathKind,
    /// Start depth, m (positive down).
    pub depth_m: f64,
    pub start_north_m: f64,
    pub start_east_m: f64,
    pub heading_deg: f64,
    /// Surge speed on moving paths, m/s.
    pub speed_m_s: f64,
    /// Radius of the circular and spiral paths, m.
    pub circle_radius_m: f64,
    /// Descent rate of the spiral, m/s.
    pub spiral_descent_m_s: f64,
    /// Lawnmower leg length and spacing (diameter of the turns), m.
    pub leg_length_m: f64,
    pub leg_spacing_m: f64,
}

impl Vehicle {
    /// The body velocities of its path, for the truth.
    pub fn body_path(&self) -> BodyPath {
        BodyPath {
            kind: self.path,
            speed_m_s: self.speed_m_s,
            circle_radius_m: self.circle_radius_m,
            spiral_descent_m_s: self.spiral_descent_m_s,
            leg_length_m: self.leg_length_m,
            leg_spacing_m: self.leg_spacing_m,
        }
    }
}

impl Default for Vehicle {
    fn default() -> Self {
        Self {
            name: None,
            path: PathKind::Circular,
            depth_m: 5.0,
            start_north_m: 0.0,
            start_east_m: 0.0,
            heading_deg: 0.0,
            speed_m_s: 0.5,
            circle_radius_m: 25.0,
            spiral_descent_m_s: 0.005,
            leg_length_m: 100.0,
            leg_spacing_m: 20.0,
        }
    }
}

/// The underwater vehicle's sensors (standard deviations).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Sensors {
    /// Body linear velocity (u, v, w) noise, m/s (DVL-class).
    pub velocity_noise_m_s: f64,
    /// Body angular rate (p, q, r) noise, rad/s.
    pub rate_noise_rad_s: f64,
    /// Depth sensor noise, m.
    pub depth_noise_m: f64,
    /// Roll, pitch and heading noise, deg.
    pub attitude_noise_deg: f64,
}

impl Default for Sensors {
    fn default() -> Self {
        // the onboard filter's defaults (one table of them)
        let d = onebeacon::nav::SensorNoise::default();
        Self {
            velocity_noise_m_s: d.velocity_m_s,
            rate_noise_rad_s: d.rate_rad_s,
            depth_noise_m: d.depth_m,
            attitude_noise_deg: d.attitude_rad.to_degrees(),
        }
    }
}

/// The surface vehicle carrying the beacon.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Asv {
    pub max_speed_m_s: f64,
    pub max_turn_rate_deg_s: f64,
    /// GPS position noise (each horizontal axis), m (sousa eq. 4.3).
    pub gps_noise_m: f64,
    /// Transducer depth, m.
    pub transducer_depth_m: f64,
    /// Direction from the vehicle to the ASV at the start, deg; the distance is the
    /// best standoff for the vehicle's depth (sousa Fig. 4.7).
    pub start_bearing_deg: f64,
    /// The truth model of the ASV.
    pub vehicle: super::passive_usbl::AsvVehicle,
}

impl Default for Asv {
    fn default() -> Self {
        Self {
            max_speed_m_s: 2.0,
            max_turn_rate_deg_s: 30.0,
            gps_noise_m: 1.0,
            transducer_depth_m: 0.0,
            start_bearing_deg: 0.0,
            vehicle: super::passive_usbl::AsvVehicle::Kinematic,
        }
    }
}

/// One-way travel-time ranging.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Acoustics {
    /// Time between pings, s.
    pub ping_period_s: f64,
    pub sound_speed_m_s: f64,
    /// Range noise (travel-time error times sound speed), m.
    pub range_noise_m: f64,
}

impl Default for Acoustics {
    fn default() -> Self {
        Self { ping_period_s: 10.0, sound_speed_m_s: 1500.0, range_noise_m: 1.0 }
    }
}

/// How the ASV chooses where to be at the next ping.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum GuidanceKind {
    /// Maximise det FIM of the previous and next range (sousa approach A, eq. 3.15).
    #[serde(rename = "A")]
    ApproachA,
    /// Maximise det FIM(now) + det FIM(predicted next) (sousa approach B, eq. 3.19).
    #[serde(rename = "B")]
    ApproachB,
    /// Stay at the start point (baseline).
    #[serde(rename = "static")]
    Static,
    /// Circle the vehicle's estimate at a fixed radius (baseline).
    #[serde(rename = "circle")]
    Circle,
}

impl GuidanceKind {
    pub fn label(self) -> &'static str {
        match self {
            GuidanceKind::ApproachA => "A",
            GuidanceKind::ApproachB => "B",
            GuidanceKind::Static => "static",
            GuidanceKind::Circle => "circle",
        }
    }
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Guidance {
    pub kind: GuidanceKind,
    /// Polar search grid over the reaching set: rings and directions.
    pub grid_radial: usize,
    pub grid_angular: usize,
    /// Radius of the circling baseline, m.
    pub circle_radius_m: f64,
}

impl Default for Guidance {
    fn default() -> Self {
        // the onboard controller's defaults (one table of them)
        let d = onebeacon::config::controller::FimSpec::default();
        Self {
            kind: GuidanceKind::ApproachA,
            grid_radial: d.grid_radial,
            grid_angular: d.grid_angular,
            circle_radius_m: d.circle_radius_m,
        }
    }
}

/// Initial uncertainty of the vehicle's filter (standard deviations; the estimate
/// starts at the truth plus one draw of these).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Initial {
    pub position_sigma_m: f64,
    pub depth_sigma_m: f64,
    pub attitude_sigma_deg: f64,
}

impl Default for Initial {
    fn default() -> Self {
        Self { position_sigma_m: 1.0, depth_sigma_m: 0.1, attitude_sigma_deg: 1.0 }
    }
}

/// Values swept by `mc`: the cells are every combination.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Sweep {
    pub path: Option<Vec<PathKind>>,
    pub depth_m: Option<Vec<f64>>,
    pub guidance: Option<Vec<GuidanceKind>>,
}

/// One sweep cell of a moving-beacon scenario.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MovingBeaconCell {
    pub path: PathKind,
    pub depth_m: f64,
    pub guidance: GuidanceKind,
}

impl MovingBeacon {
    pub fn base_cell(&self) -> MovingBeaconCell {
        MovingBeaconCell { path: self.vehicle.path, depth_m: self.vehicle.depth_m, guidance: self.guidance.kind }
    }

    /// Every combination of the swept values, path outermost, guidance innermost.
    pub fn cells(&self) -> Vec<MovingBeaconCell> {
        let b = self.base_cell();
        let paths = self.sweep.path.clone().unwrap_or_else(|| vec![b.path]);
        let depths = self.sweep.depth_m.clone().unwrap_or_else(|| vec![b.depth_m]);
        let guidances = self.sweep.guidance.clone().unwrap_or_else(|| vec![b.guidance]);
        let mut cells = Vec::new();
        for &path in &paths {
            for &depth_m in &depths {
                for &guidance in &guidances {
                    cells.push(MovingBeaconCell { path, depth_m, guidance });
                }
            }
        }
        cells
    }

    pub fn steps(&self) -> usize {
        (self.mission.duration_s / self.mission.dt_s).round() as usize
    }

    /// The underwater vehicles of `cell`: `vehicle` on the cell's path and depth, then
    /// `other_vehicles`, each with its name set.
    pub fn vehicles(&self, cell: &MovingBeaconCell) -> Vec<Vehicle> {
        let first = Vehicle { path: cell.path, depth_m: cell.depth_m, ..self.vehicle.clone() };
        std::iter::once(first)
            .chain(self.other_vehicles.iter().cloned())
            .enumerate()
            .map(|(i, mut v)| {
                v.name = Some(v.name.unwrap_or_else(|| if i == 0 { "auv".into() } else { format!("auv{}", i + 1) }));
                v
            })
            .collect()
    }

    /// The vehicle's sensor noise, which the world draws from and the filters and the
    /// bound read (a matched filter).
    pub fn sensor_noise(&self) -> onebeacon::nav::SensorNoise {
        let n = &self.sensors;
        onebeacon::nav::SensorNoise {
            velocity_m_s: n.velocity_noise_m_s,
            rate_rad_s: n.rate_noise_rad_s,
            depth_m: n.depth_noise_m,
            attitude_rad: n.attitude_noise_deg.to_radians(),
            range_m: self.acoustics.range_noise_m,
        }
    }
}

// ---- validation: the range checks of this world's keys

/// One underwater vehicle's table (`prefix`: its key).
fn check_vehicle(prefix: &str, v: &Vehicle) -> Result<(), Violation> {
    use Rule::*;
    let fields = [
        ("depth_m", v.depth_m, NonNegative),
        ("start_north_m", v.start_north_m, Finite),
        ("start_east_m", v.start_east_m, Finite),
        ("heading_deg", v.heading_deg, Finite),
        ("speed_m_s", v.speed_m_s, NonNegative),
        ("circle_radius_m", v.circle_radius_m, Positive),
        ("spiral_descent_m_s", v.spiral_descent_m_s, NonNegative),
        ("leg_length_m", v.leg_length_m, Positive),
        ("leg_spacing_m", v.leg_spacing_m, Positive),
    ];
    check_table(prefix, &fields, v.name.as_ref())
}

pub(super) fn validate_moving(s: &MovingBeacon) -> Result<(), Violation> {
    use Rule::*;
    check_file_name("name", &s.name)?;
    check_count("runs", s.runs, 1, 1_000_000)?;
    s.sea.check(s.kind)?;
    check_fields!("mission", s.mission, {
        dt_s: Positive,
        duration_s: Positive,
    });
    check_vehicle("vehicle", &s.vehicle)?;
    check_count("other_vehicles (count)", s.other_vehicles.len(), 0, 31)?;
    for (k, v) in s.other_vehicles.iter().enumerate() {
        check_vehicle(&format!("other_vehicles[{k}]"), v)?;
    }
    let vehicles = s.vehicles(&s.base_cell());
    let names: Vec<String> = vehicles.into_iter().filter_map(|v| v.name).collect();
    check_vehicle_names(
        &names,
        "other_vehicles",
        "must differ from the other vehicles' names (`auv` for `vehicle`, `auvN` for the N-th)",
    )?;
    let n = &s.sensors;
    check_fields!("sensors", n, {
        velocity_noise_m_s: Positive,
        rate_noise_rad_s: Positive,
        depth_noise_m: Positive,
        attitude_noise_deg: Positive,
    });
    let a = &s.asv;
    check_fields!("asv", a, {
        max_speed_m_s: Positive,
        max_turn_rate_deg_s: Positive,
        gps_noise_m: NonNegative,
        transducer_depth_m: NonNegative,
        start_bearing_deg: Finite,
    });
    let c = &s.acoustics;
    check_fields!("acoustics", c, {
        ping_period_s: Positive,
        sound_speed_m_s: Positive,
        range_noise_m: Positive,
    });
    check_count("guidance.grid_radial", s.guidance.grid_radial, 1, 10_000)?;
    check_count("guidance.grid_angular", s.guidance.grid_angular, 1, 10_000)?;
    check_fields!("guidance", s.guidance, {
        circle_radius_m: Positive,
    });
    let i = &s.initial;
    check_fields!("initial", i, {
        position_sigma_m: Positive,
        depth_sigma_m: Positive,
        attitude_sigma_deg: Positive,
    });
    check_estimators(&s.estimators, Host::MovingBeacon)?;
    check_list_nonempty("sweep.path", &s.sweep.path)?;
    check_list_nonempty("sweep.guidance", &s.sweep.guidance)?;
    check_list_nonempty("sweep.depth_m", &s.sweep.depth_m)?;
    for (j, &d) in s.sweep.depth_m.iter().flatten().enumerate() {
        check(&format!("sweep.depth_m[{j}]"), d, NonNegative)?;
    }
    check_steps(s.mission.duration_s, s.mission.dt_s, "mission.duration_s")
}
