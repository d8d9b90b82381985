//! Range checks on a parsed scenario. The first violation is reported with its key.

use super::{FixedBeacon, MovingBeacon, Scenario};

pub(super) struct Violation {
    pub key: String,
    pub value: String,
    pub allowed: String,
}

/// Rules for one number.
#[derive(Clone, Copy)]
enum Rule {
    Positive,
    NonNegative,
    Probability,
    Finite,
}

fn check(key: &str, value: f64, rule: Rule) -> Result<(), Violation> {
    let (ok, allowed) = match rule {
        Rule::Positive => (value > 0.0, "must be a finite number > 0"),
        Rule::NonNegative => (value >= 0.0, "must be a finite number >= 0"),
        Rule::Probability => ((0.0..=1.0).contains(&value), "must be a probability in [0, 1]"),
        Rule::Finite => (true, "must be a finite number"),
    };
    if ok && value.is_finite() {
        Ok(())
    } else {
        Err(Violation { key: key.to_string(), value: format!("{value:?}"), allowed: allowed.to_string() })
    }
}

fn check_count(key: &str, value: usize, min: usize, max: usize) -> Result<(), Violation> {
    if (min..=max).contains(&value) {
        Ok(())
    } else {
        Err(Violation {
            key: key.to_string(),
            value: value.to_string(),
            allowed: format!("must be a whole number from {min} to {max}"),
        })
    }
}

pub(super) fn validate(s: &Scenario) -> Result<(), Violation> {
    match s {
        Scenario::FixedBeacon(s) => validate_fixed(s),
        Scenario::MovingBeacon(s) => validate_moving(s),
    }
}

fn check_steps(duration_s: f64, dt_s: f64) -> Result<(), Violation> {
    let steps = duration_s / dt_s;
    if steps > 1e8 {
        return Err(Violation {
            key: "mission.dt_s".into(),
            value: format!("{dt_s:?}"),
            allowed: format!("gives {steps:.0} steps; at most 1e8 steps per run"),
        });
    }
    Ok(())
}

fn check_name(key: String, name: &str, taken: bool) -> Result<(), Violation> {
    let ok = !name.is_empty() && name.chars().all(|c| c.is_ascii_alphanumeric() || "+-_.".contains(c));
    if !ok {
        return Err(Violation {
            key,
            value: format!("{name:?}"),
            allowed: "must be non-empty ASCII letters, digits and + - _ .".into(),
        });
    }
    if taken {
        return Err(Violation {
            key,
            value: format!("{name:?}"),
            allowed: "must differ from the other estimators' names (set `name`)".into(),
        });
    }
    Ok(())
}

fn check_list_nonempty<T>(key: &str, v: &Option<Vec<T>>) -> Result<(), Violation> {
    match v {
        Some(v) if v.is_empty() => Err(Violation {
            key: key.into(),
            value: "[]".into(),
            allowed: "must list at least one value, or be left out".into(),
        }),
        _ => Ok(()),
    }
}

fn validate_moving(s: &MovingBeacon) -> Result<(), Violation> {
    use Rule::*;
    check_count("runs", s.runs, 1, 1_000_000)?;
    check("mission.dt_s", s.mission.dt_s, Positive)?;
    check("mission.duration_s", s.mission.duration_s, Positive)?;
    let v = &s.vehicle;
    check("vehicle.depth_m", v.depth_m, NonNegative)?;
    check("vehicle.start_north_m", v.start_north_m, Finite)?;
    check("vehicle.start_east_m", v.start_east_m, Finite)?;
    check("vehicle.heading_deg", v.heading_deg, Finite)?;
    check("vehicle.speed_m_s", v.speed_m_s, NonNegative)?;
    check("vehicle.circle_radius_m", v.circle_radius_m, Positive)?;
    check("vehicle.spiral_descent_m_s", v.spiral_descent_m_s, NonNegative)?;
    check("vehicle.leg_length_m", v.leg_length_m, Positive)?;
    check("vehicle.leg_spacing_m", v.leg_spacing_m, Positive)?;
    let n = &s.sensors;
    check("sensors.velocity_noise_m_s", n.velocity_noise_m_s, Positive)?;
    check("sensors.rate_noise_rad_s", n.rate_noise_rad_s, Positive)?;
    check("sensors.depth_noise_m", n.depth_noise_m, Positive)?;
    check("sensors.attitude_noise_deg", n.attitude_noise_deg, Positive)?;
    let a = &s.asv;
    check("asv.max_speed_m_s", a.max_speed_m_s, Positive)?;
    check("asv.max_turn_rate_deg_s", a.max_turn_rate_deg_s, Positive)?;
    check("asv.gps_noise_m", a.gps_noise_m, NonNegative)?;
    check("asv.transducer_depth_m", a.transducer_depth_m, NonNegative)?;
    check("asv.start_bearing_deg", a.start_bearing_deg, Finite)?;
    let c = &s.acoustics;
    check("acoustics.ping_period_s", c.ping_period_s, Positive)?;
    check("acoustics.sound_speed_m_s", c.sound_speed_m_s, Positive)?;
    check("acoustics.range_noise_m", c.range_noise_m, Positive)?;
    check_count("guidance.grid_radial", s.guidance.grid_radial, 1, 10_000)?;
    check_count("guidance.grid_angular", s.guidance.grid_angular, 1, 10_000)?;
    check("guidance.circle_radius_m", s.guidance.circle_radius_m, Positive)?;
    let i = &s.initial;
    check("initial.position_sigma_m", i.position_sigma_m, Positive)?;
    check("initial.depth_sigma_m", i.depth_sigma_m, Positive)?;
    check("initial.attitude_sigma_deg", i.attitude_sigma_deg, Positive)?;
    if s.estimators.is_empty() {
        return Err(Violation {
            key: "estimators".into(),
            value: "[]".into(),
            allowed: "at least one estimator is needed".into(),
        });
    }
    for (k, e) in s.estimators.iter().enumerate() {
        check_name(format!("estimators[{k}].name"), e.name(), s.estimators[..k].iter().any(|o| o.name() == e.name()))?;
    }
    check_list_nonempty("sweep.path", &s.sweep.path)?;
    check_list_nonempty("sweep.guidance", &s.sweep.guidance)?;
    check_list_nonempty("sweep.depth_m", &s.sweep.depth_m)?;
    for (j, &d) in s.sweep.depth_m.iter().flatten().enumerate() {
        check(&format!("sweep.depth_m[{j}]"), d, NonNegative)?;
    }
    check_steps(s.mission.duration_s, s.mission.dt_s)
}

fn validate_fixed(s: &FixedBeacon) -> Result<(), Violation> {
    use Rule::*;
    check_count("runs", s.runs, 1, 1_000_000)?;

    let m = &s.mission;
    check("mission.dt_s", m.dt_s, Positive)?;
    check("mission.speed_m_s", m.speed_m_s, Positive)?;
    if let Some(d) = m.duration_s {
        check("mission.duration_s", d, Positive)?;
    }

    let p = &s.path;
    check("path.start_north_m", p.start_north_m, Finite)?;
    check("path.start_east_m", p.start_east_m, Finite)?;
    check("path.leg_heading_deg", p.leg_heading_deg, Finite)?;
    check("path.leg_length_m", p.leg_length_m, Positive)?;
    check("path.leg_spacing_m", p.leg_spacing_m, Positive)?;
    check_count("path.legs", p.legs, 1, 10_000)?;

    check("beacon.north_m", s.beacon.north_m, Finite)?;
    check("beacon.east_m", s.beacon.east_m, Finite)?;

    check("comms.t_com_s", s.comms.t_com_s, Positive)?;
    check("comms.frame_loss_prob", s.comms.frame_loss_prob, Probability)?;

    let n = &s.sensors;
    check("sensors.range_noise_m", n.range_noise_m, NonNegative)?;
    check("sensors.doppler_noise_m_s", n.doppler_noise_m_s, NonNegative)?;
    check("sensors.heading_noise_deg", n.heading_noise_deg, NonNegative)?;
    check("sensors.heading_bias_deg", n.heading_bias_deg, NonNegative)?;
    check("sensors.heading_bias_drift_deg_per_h", n.heading_bias_drift_deg_per_h, NonNegative)?;
    check("sensors.gyro_noise_rad_s", n.gyro_noise_rad_s, NonNegative)?;
    check("sensors.accel_noise_m_s2", n.accel_noise_m_s2, NonNegative)?;

    let i = &s.initial;
    check("initial.position_sigma_m", i.position_sigma_m, Positive)?;
    check("initial.heading_sigma_deg", i.heading_sigma_deg, Positive)?;
    check("initial.speed_sigma_m_s", i.speed_sigma_m_s, Positive)?;
    check("initial.yaw_rate_sigma_rad_s", i.yaw_rate_sigma_rad_s, Positive)?;
    check("initial.accel_sigma_m_s2", i.accel_sigma_m_s2, Positive)?;

    if s.estimators.is_empty() {
        return Err(Violation {
            key: "estimators".into(),
            value: "[]".into(),
            allowed: "at least one estimator is needed".into(),
        });
    }
    for (k, e) in s.estimators.iter().enumerate() {
        let key = |f: &str| format!("estimators[{k}].{f}");
        for (j, &q) in e.q_diag.iter().enumerate() {
            check(&format!("estimators[{k}].q_diag[{j}]"), q, NonNegative)?;
        }
        check(&key("r_range_m2"), e.r_range_m2, Positive)?;
        check(&key("r_doppler_m2_s2"), e.r_doppler_m2_s2, Positive)?;
        check(&key("r_heading_rad2"), e.r_heading_rad2, Positive)?;
        check(&key("r_yaw_rate_rad2_s2"), e.r_yaw_rate_rad2_s2, Positive)?;
        check(&key("r_accel_m2_s4"), e.r_accel_m2_s4, Positive)?;
        let name = e.name();
        let name_ok = !name.is_empty() && name.chars().all(|c| c.is_ascii_alphanumeric() || "+-_.".contains(c));
        if !name_ok {
            return Err(Violation {
                key: key("name"),
                value: format!("{name:?}"),
                allowed: "must be non-empty ASCII letters, digits and + - _ .".into(),
            });
        }
        if s.estimators[..k].iter().any(|o| o.name() == name) {
            return Err(Violation {
                key: key("name"),
                value: format!("{name:?}"),
                allowed: "must differ from the other estimators' names (set `name`)".into(),
            });
        }
    }

    if let Some(v) = &s.sweep.t_com_s {
        if v.is_empty() {
            return Err(Violation {
                key: "sweep.t_com_s".into(),
                value: "[]".into(),
                allowed: "must list at least one value, or be left out".into(),
            });
        }
        for (j, &t) in v.iter().enumerate() {
            check(&format!("sweep.t_com_s[{j}]"), t, Positive)?;
        }
    }

    // the run must be of a workable size
    let steps = s.duration_s() / m.dt_s;
    if steps > 1e8 {
        return Err(Violation {
            key: "mission.dt_s".into(),
            value: format!("{:?}", m.dt_s),
            allowed: format!("gives {steps:.0} steps; at most 1e8 steps per run"),
        });
    }
    Ok(())
}
