//! Scenarios of kind `passive_usbl` (hoff2024): an AUV on a circle sends an acoustic
//! message every period with its INS heading, speed and depth; a surface vehicle (ASV)
//! listens with a USBL, tracks the AUV from the bearings and the reports, and moves to
//! where the next bearing tells the most. Unknown keys are errors.

use super::estimator::Host;
use super::validate::*;
use super::{EstimatorKind, EstimatorSpec, World, default_runs, default_seed};
use crate::water::Current;
use serde::{Deserialize, Serialize};

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PassiveUsbl {
    /// `passive_usbl`.
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
    pub auv: Auv,
    /// More AUVs sending messages in the same water, tracked by the same estimators;
    /// the planner serves them all (the worst one first).
    #[serde(default)]
    pub other_auvs: Vec<Auv>,
    #[serde(default)]
    pub reports: Reports,
    #[serde(default)]
    pub usbl: UsblSpec,
    #[serde(default)]
    pub asv: Asv,
    /// The water's current, felt by the dynamic vehicles (`otter`, `remus100`); the
    /// estimators are not told.
    #[serde(default)]
    pub current: Current,
    #[serde(default)]
    pub guidance: Guidance,
    #[serde(default)]
    pub initial: Initial,
    #[serde(default = "default_estimators")]
    pub estimators: Vec<EstimatorSpec>,
    #[serde(default)]
    pub sweep: Sweep,
    /// `[sea]`: the link's losses and outliers, the USBL head's errors, a sound-speed
    /// profile that bends the elevations (off by default).
    #[serde(default)]
    pub sea: super::sea::Sea,
}

fn default_estimators() -> Vec<EstimatorSpec> {
    vec![EstimatorSpec::new(EstimatorKind::Particle), EstimatorSpec::new(EstimatorKind::Bearing)]
}

/// Durations and periods.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Mission {
    pub duration_s: f64,
    /// Time between the AUV's messages (T_comms), s: one filter cycle and one step.
    pub message_period_s: f64,
    /// The surface vehicle's integration step, s.
    pub dt_s: f64,
}

impl Default for Mission {
    fn default() -> Self {
        Self { duration_s: 3600.0, message_period_s: 4.0, dt_s: 0.1 }
    }
}

/// An AUV on a circle (eq. 22), at constant depth and speed: on it exactly
/// (`kinematic`), or following it by ILOS under its autopilots (`remus100`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Auv {
    /// Name in outputs (default `auv`, then `auv2`, `auv3`, ... for `other_auvs`).
    pub name: Option<String>,
    pub centre_north_m: f64,
    pub centre_east_m: f64,
    pub circle_radius_m: f64,
    pub depth_m: f64,
    pub speed_m_s: f64,
    /// Where on the circle it starts, deg from north about the centre.
    pub start_angle_deg: f64,
    /// Turning clockwise seen from above (to starboard) or not.
    pub clockwise: bool,
    /// The truth model of the AUV.
    pub vehicle: AuvVehicle,
    /// ILOS on the circle (`remus100`): lookahead Delta (m), integral gain kappa, and
    /// the path parameter's gain mu of eq. 23 (1/(m s)).
    pub ilos_lookahead_m: f64,
    pub ilos_integral_gain: f64,
    pub path_gain: f64,
}

/// The truth model of an AUV.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum AuvVehicle {
    /// On its circle in closed form, at constant speed and depth, level.
    #[default]
    Kinematic,
    /// REMUS 100's 6-DOF dynamics (`vehicles::remus100`) under its heading, depth and
    /// speed autopilots, steered by ILOS on the circle.
    Remus100,
}

impl Default for Auv {
    fn default() -> Self {
        Self {
            name: None,
            centre_north_m: 0.0,
            centre_east_m: 0.0,
            circle_radius_m: 500.0,
            depth_m: 30.0,
            speed_m_s: 1.5,
            start_angle_deg: 0.0,
            clockwise: true,
            vehicle: AuvVehicle::Kinematic,
            ilos_lookahead_m: 10.0,
            ilos_integral_gain: 0.1,
            path_gain: 0.01,
        }
    }
}

/// The noise of the AUV's INS reports (standard deviations; Table 1, true column).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Reports {
    pub heading_noise_deg: f64,
    pub speed_noise_m_s: f64,
    pub depth_noise_m: f64,
}

impl Default for Reports {
    fn default() -> Self {
        Self {
            heading_noise_deg: 0.13f64.sqrt().to_degrees(),
            speed_noise_m_s: 0.05f64.sqrt(),
            depth_noise_m: 0.1f64.sqrt(),
        }
    }
}

/// The USBL on the ASV (Table 1, true column).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct UsblSpec {
    /// sigma_USBL: the standard deviation of each angle per metre of range, deg/m (eq. 3).
    pub noise_deg_per_m: f64,
    pub transducer_depth_m: f64,
}

impl Default for UsblSpec {
    fn default() -> Self {
        Self { noise_deg_per_m: 0.01, transducer_depth_m: 0.0 }
    }
}

/// The surface vehicle: kinematic, with speed and turn-rate limits, following
/// straight legs with the time assignment of eq. 24-26.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Asv {
    pub max_speed_m_s: f64,
    pub max_turn_rate_deg_s: f64,
    /// u_nom: the speed legs are planned at (eq. 15), below the top speed.
    pub nominal_speed_m_s: f64,
    /// c_u: the along-track gain of the speed law (eq. 26), 1/s.
    pub along_track_gain: f64,
    /// Line-of-sight lookahead distance along the leg, m, and the gain kappa of an ILOS
    /// integral across legs (0: plain LOS).
    pub lookahead_m: f64,
    pub ilos_integral_gain: f64,
    /// GPS error per horizontal axis and compass error of the ASV (the paper: exact).
    pub gps_noise_m: f64,
    pub compass_noise_deg: f64,
    /// Where it starts: this far from the first AUV, in this direction (deg from north).
    pub start_distance_m: f64,
    pub start_bearing_deg: f64,
    /// The truth model of the ASV.
    pub vehicle: AsvVehicle,
}

/// The truth model of the ASV.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum AsvVehicle {
    /// A unicycle with speed and turn-rate limits, steered and sped exactly as asked.
    #[default]
    Kinematic,
    /// The Otter's 6-DOF dynamics under its heading and speed autopilots
    /// (`vehicles::otter`), the guidance's heading and speed as their commands.
    Otter,
}

impl Default for Asv {
    fn default() -> Self {
        Self {
            max_speed_m_s: 3.09,
            max_turn_rate_deg_s: 20.0,
            nominal_speed_m_s: 2.2,
            along_track_gain: 0.2,
            lookahead_m: 5.0,
            ilos_integral_gain: 0.0,
            gps_noise_m: 0.0,
            compass_noise_deg: 0.0,
            start_distance_m: 20.0,
            start_bearing_deg: 180.0,
            vehicle: AsvVehicle::Kinematic,
        }
    }
}

/// How the ASV chooses where to go.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum GuidanceKind {
    /// The half-annulus point of largest det C (eq. 10-12, generalised variance).
    #[serde(rename = "det")]
    Determinant,
    /// The half-annulus point of largest eigenvalue of C (eq. 10-12).
    #[serde(rename = "max-eig")]
    MaxEigenvalue,
    /// Stay at the start (baseline).
    #[serde(rename = "static")]
    Static,
    /// Circle the belief at `circle_radius_m` (baseline).
    #[serde(rename = "circle")]
    Circle,
    /// Hold `offset_m` behind the belief, along its course (baseline).
    #[serde(rename = "offset")]
    Offset,
}

impl GuidanceKind {
    pub fn label(self) -> &'static str {
        match self {
            GuidanceKind::Determinant => "det",
            GuidanceKind::MaxEigenvalue => "max-eig",
            GuidanceKind::Static => "static",
            GuidanceKind::Circle => "circle",
            GuidanceKind::Offset => "offset",
        }
    }
}

pub use onebeacon::config::controller::MAX_LEAD_PERIODS;

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Guidance {
    pub kind: GuidanceKind,
    /// The half-annulus r1..r2 around the belief (m), sampled at `radii` radii and
    /// `angles` rotations.
    pub r1_m: f64,
    pub r2_m: f64,
    pub radii: usize,
    pub angles: usize,
    /// Particles the planner scores a candidate on (a subsample of the filter's).
    pub planner_particles: usize,
    /// The message periods the ASV is assumed to take to the next point: the belief is
    /// shifted by the AUV's estimated velocity over them (sec. 3).
    pub lead_periods: f64,
    pub circle_radius_m: f64,
    pub offset_m: f64,
}

impl Default for Guidance {
    fn default() -> Self {
        // the onboard controller's defaults (one table of them)
        let d = onebeacon::config::controller::BearingSpec::default();
        Self {
            kind: GuidanceKind::Determinant,
            r1_m: d.r1_m,
            r2_m: d.r2_m,
            radii: d.radii,
            angles: d.angles,
            planner_particles: d.planner_particles,
            lead_periods: d.lead_periods,
            circle_radius_m: d.circle_radius_m,
            offset_m: d.offset_m,
        }
    }
}

/// The trackers' initial uncertainty (standard deviations; each starts at the truth
/// plus one draw of these).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Initial {
    pub position_sigma_m: f64,
    pub depth_sigma_m: f64,
    pub pitch_sigma_deg: f64,
    pub heading_sigma_deg: f64,
    pub speed_sigma_m_s: f64,
    /// The pitch and heading rate biases, deg/s.
    pub rate_bias_sigma_deg_s: f64,
}

impl Default for Initial {
    fn default() -> Self {
        Self {
            position_sigma_m: 5.0,
            depth_sigma_m: 1.0,
            pitch_sigma_deg: 2.0,
            heading_sigma_deg: 10.0,
            speed_sigma_m_s: 0.3,
            rate_bias_sigma_deg_s: 0.05,
        }
    }
}

/// Values swept by `mc`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Sweep {
    pub guidance: Option<Vec<GuidanceKind>>,
}

/// One sweep cell.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PassiveUsblCell {
    pub guidance: GuidanceKind,
}

impl PassiveUsbl {
    pub fn base_cell(&self) -> PassiveUsblCell {
        PassiveUsblCell { guidance: self.guidance.kind }
    }

    pub fn cells(&self) -> Vec<PassiveUsblCell> {
        let kinds = self.sweep.guidance.clone().unwrap_or_else(|| vec![self.guidance.kind]);
        kinds.into_iter().map(|guidance| PassiveUsblCell { guidance }).collect()
    }

    /// Steps (message periods) after the start.
    pub fn steps(&self) -> usize {
        (self.mission.duration_s / self.mission.message_period_s).round() as usize
    }

    /// The noise of the world's measurements, which the trackers assume unless told
    /// otherwise (a matched filter).
    pub fn tracker_noise(&self) -> onebeacon::nav::TrackerNoise {
        onebeacon::nav::TrackerNoise {
            usbl_sigma_rad_per_m: self.usbl.noise_deg_per_m.to_radians(),
            usbl_floor_rad: 0.0,
            station_heading_sigma_rad: self.asv.compass_noise_deg.to_radians(),
            heading_sigma_rad: self.reports.heading_noise_deg.to_radians(),
            speed_sigma_m_s: self.reports.speed_noise_m_s,
            depth_sigma_m: self.reports.depth_noise_m,
            usbl_as_printed: false,
        }
    }

    /// The AUVs, each with its name set.
    pub fn auvs(&self) -> Vec<Auv> {
        std::iter::once(self.auv.clone())
            .chain(self.other_auvs.iter().cloned())
            .enumerate()
            .map(|(i, mut a)| {
                a.name = Some(a.name.unwrap_or_else(|| if i == 0 { "auv".into() } else { format!("auv{}", i + 1) }));
                a
            })
            .collect()
    }
}

// ---- validation: the range checks of this world's keys

/// One AUV's table of a passive_usbl scenario (`prefix`: its key).
fn check_auv(prefix: &str, a: &Auv) -> Result<(), Violation> {
    use Rule::*;
    let fields = [
        ("centre_north_m", a.centre_north_m, Finite),
        ("centre_east_m", a.centre_east_m, Finite),
        ("circle_radius_m", a.circle_radius_m, Positive),
        ("depth_m", a.depth_m, NonNegative),
        ("speed_m_s", a.speed_m_s, NonNegative),
        ("start_angle_deg", a.start_angle_deg, Finite),
        ("ilos_lookahead_m", a.ilos_lookahead_m, Positive),
        ("ilos_integral_gain", a.ilos_integral_gain, NonNegative),
        ("path_gain", a.path_gain, NonNegative),
    ];
    check_table(prefix, &fields, a.name.as_ref())?;
    // REMUS 100 tops out at 2.48 m/s (1525 rpm) and needs way on for its fins
    if a.vehicle == AuvVehicle::Remus100 && !(0.5..=2.4).contains(&a.speed_m_s) {
        return Err(Violation {
            key: format!("{prefix}.speed_m_s"),
            value: format!("{:?}", a.speed_m_s),
            allowed: "must be from 0.5 to 2.4 m/s for a remus100 (its top speed is 2.48 m/s)".into(),
        });
    }
    Ok(())
}

pub(super) fn validate_passive(s: &PassiveUsbl) -> Result<(), Violation> {
    check_file_name("name", &s.name)?;
    check_count("runs", s.runs, 1, 1_000_000)?;
    s.sea.check(s.kind)?;
    check_fields!("mission", s.mission, {
        duration_s: Positive,
        message_period_s: Positive,
        dt_s: Positive,
    });
    if s.mission.dt_s > s.mission.message_period_s {
        return Err(Violation {
            key: "mission.dt_s".into(),
            value: format!("{:?}", s.mission.dt_s),
            allowed: format!("must be at most mission.message_period_s ({})", s.mission.message_period_s),
        });
    }
    check_steps(s.mission.duration_s, s.mission.dt_s, "mission.duration_s")?;
    check_auv("auv", &s.auv)?;
    check_count("other_auvs (count)", s.other_auvs.len(), 0, 31)?;
    for (k, a) in s.other_auvs.iter().enumerate() {
        check_auv(&format!("other_auvs[{k}]"), a)?;
    }
    let names: Vec<String> = s.auvs().into_iter().filter_map(|a| a.name).collect();
    check_vehicle_names(
        &names,
        "other_auvs",
        "must differ from the other AUVs' names (`auv` for `auv`, `auvN` for the N-th)",
    )?;
    // the trackers assume these unless told otherwise: a zero would be a likelihood
    // of zero width
    check_fields!("reports", s.reports, {
        heading_noise_deg: Positive,
        speed_noise_m_s: Positive,
        depth_noise_m: Positive,
    });
    check_fields!("usbl", s.usbl, {
        noise_deg_per_m: Positive,
        transducer_depth_m: NonNegative,
    });
    check_fields!("asv", s.asv, {
        max_speed_m_s: Positive,
        max_turn_rate_deg_s: Positive,
        nominal_speed_m_s: Positive,
        along_track_gain: NonNegative,
        lookahead_m: Positive,
        ilos_integral_gain: NonNegative,
        gps_noise_m: NonNegative,
        compass_noise_deg: NonNegative,
        start_distance_m: NonNegative,
        start_bearing_deg: Finite,
    });
    super::sea::check_current("current", &s.current)?;
    let dynamic = s.asv.vehicle == AsvVehicle::Otter || s.auvs().iter().any(|a| a.vehicle == AuvVehicle::Remus100);
    if s.current.flows() && !dynamic {
        return Err(Violation {
            key: "current.speed_m_s".into(),
            value: format!("{:?}", s.current.speed_m_s),
            allowed: "must be 0 unless a vehicle feels it (asv.vehicle = \"otter\" or an AUV's vehicle = \"remus100\"; kinematic vehicles move as commanded)".into(),
        });
    }
    let g = &s.guidance;
    check_fields!("guidance", g, {
        r1_m: Positive,
        r2_m: Positive,
        lead_periods: NonNegative,
        circle_radius_m: Positive,
        offset_m: NonNegative,
    });
    if g.r2_m < g.r1_m {
        return Err(Violation {
            key: "guidance.r2_m".into(),
            value: format!("{:?}", g.r2_m),
            allowed: format!("must be at least guidance.r1_m ({})", g.r1_m),
        });
    }
    check_count("guidance.radii", g.radii, 1, 1000)?;
    check_count("guidance.angles", g.angles, 1, 10_000)?;
    check_count("guidance.planner_particles", g.planner_particles, 1, 10_000_000)?;
    let period = s.mission.message_period_s;
    if let Some(why) = onebeacon::guidance::bearing::planner_too_slow(g.radii, g.angles, g.planner_particles, period) {
        return Err(Violation { key: "guidance.radii".into(), value: g.radii.to_string(), allowed: why });
    }
    if g.lead_periods > MAX_LEAD_PERIODS {
        let allowed = format!("must be at most {MAX_LEAD_PERIODS} (the belief's straight-line prediction)");
        return Err(Violation { key: "guidance.lead_periods".into(), value: format!("{:?}", g.lead_periods), allowed });
    }
    check_fields!("initial", s.initial, {
        position_sigma_m: Positive,
        depth_sigma_m: Positive,
        pitch_sigma_deg: Positive,
        heading_sigma_deg: Positive,
        speed_sigma_m_s: Positive,
        rate_bias_sigma_deg_s: Positive,
    });
    check_estimators(&s.estimators, Host::PassiveUsbl)?;
    check_list_nonempty("sweep.guidance", &s.sweep.guidance)
}
