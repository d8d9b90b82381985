//! The physical limits every item of a stream or a log must respect before any
//! estimator sees it: the session screens an item out of them with its reason.

use super::Kind;
use super::item::Input;

/// Physical limits every item must respect before any estimator sees it. An item out
/// of them (a faulty sensor, a corrupt line) is screened out with its reason, and the
/// session goes on. (With the `serde` feature it reads from a `[limits]` table, every key
/// optional.)
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Deserialize, serde::Serialize), serde(default, deny_unknown_fields))]
pub struct Limits {
    /// Largest plausible range, m.
    pub max_range_m: f64,
    /// Largest plausible speed, m/s: speed inputs, Doppler speeds, body velocities and
    /// odometry distance per second.
    pub max_speed_m_s: f64,
    /// Largest plausible angular rate, rad/s (gyros, body rates).
    pub max_rate_rad_s: f64,
    /// Deepest plausible depth, m.
    pub max_depth_m: f64,
    /// Largest plausible jump forward in time from one item to the next, s.
    pub max_time_gap_s: f64,
    /// Most tracked beacons (`beacon_position` ids).
    pub max_beacons: usize,
    /// Most rejections kept in [`Session::rejected`] (the counts go on).
    pub max_rejections: usize,
    /// Longest stream line, bytes.
    pub max_line_bytes: usize,
}

impl Default for Limits {
    fn default() -> Self {
        Self {
            max_range_m: 20_000.0,
            max_speed_m_s: 20.0,
            max_rate_rad_s: 10.0,
            max_depth_m: 12_000.0,
            max_time_gap_s: 3600.0,
            max_beacons: 4096,
            max_rejections: 100_000,
            max_line_bytes: 1 << 16,
        }
    }
}

impl Limits {
    /// Whether `input`, `dt_s` after the previous item, is within the limits; the
    /// reason otherwise.
    pub fn check(&self, input: &Input, dt_s: Option<f64>) -> Result<(), String> {
        // `why` names the limit: a `[limits]` key, or the fixed bound of a physical value
        let within = |what: &str, v: f64, lo: f64, hi: f64, why: &str| {
            if v.is_finite() && (lo..=hi).contains(&v) {
                Ok(())
            } else {
                Err(format!("{what} {v:?} is outside [{lo}, {hi}] ({why})"))
            }
        };
        let speed =
            |what: &str, v: f64| within(what, v, -self.max_speed_m_s, self.max_speed_m_s, "limits.max_speed_m_s");
        let rate =
            |what: &str, v: f64| within(what, v, -self.max_rate_rad_s, self.max_rate_rad_s, "limits.max_rate_rad_s");
        // unwrapped angles too (an INS counting turns: 1e6 rad is 160 000 turns, still
        // resolved to 1e-10 rad)
        let angle = |what: &str, v: f64| within(what, v, -1e6, 1e6, "an angle in radians");
        let range = |v: f64| {
            if v.is_finite() && v > 0.0 && v <= self.max_range_m {
                Ok(())
            } else {
                Err(format!("range {v:?} m is outside (0, {}] (limits.max_range_m)", self.max_range_m))
            }
        };
        let far = 1e8;
        match input.clone() {
            Input::Measurement(m) => {
                if let Some(b) = m.beacon() {
                    within("beacon_sigma_m", b.sigma_m, 0.0, 1e4, "a position error in metres")?;
                }
                // at least a second's travel, so that close items are not refused
                let most = self.max_speed_m_s * dt_s.unwrap_or(1.0).max(1.0);
                let travel = |what: &str, v: f64| within(what, v, -most, most, "limits.max_speed_m_s x the time step");
                let turn = |v: f64| {
                    within(
                        "heading_change_rad",
                        v,
                        -std::f64::consts::PI,
                        std::f64::consts::PI,
                        "a turn of at most pi per step",
                    )
                };
                match m.clone() {
                    Kind::BodyOdometry { forward_m, lateral_m, heading_change_rad } => {
                        travel("body_odometry forward_m", forward_m)?;
                        travel("body_odometry lateral_m", lateral_m)?;
                        turn(heading_change_rad)
                    }
                    Kind::Odometry { distance_m, heading_change_rad } => {
                        travel("odometry distance_m", distance_m)?;
                        turn(heading_change_rad)
                    }
                    Kind::Speed { speed_m_s } => speed("speed_m_s", speed_m_s),
                    Kind::Heading { heading_rad } => angle("heading_rad", heading_rad),
                    Kind::Depth { depth_m } => {
                        within("depth_m", depth_m, -100.0, self.max_depth_m, "limits.max_depth_m")
                    }
                    Kind::Attitude { roll_rad, pitch_rad, heading_rad } => {
                        angle("roll_rad", roll_rad)?;
                        angle("pitch_rad", pitch_rad)?;
                        angle("heading_rad", heading_rad)
                    }
                    Kind::BodyVelocity { nu } => {
                        nu[..3].iter().try_for_each(|&v| speed("body velocity", v))?;
                        nu[3..].iter().try_for_each(|&v| rate("body rate", v))
                    }
                    Kind::Inertial { heading_rad, yaw_rate_rad_s, accel_m_s2 } => {
                        angle("heading_rad", heading_rad)?;
                        rate("yaw_rate_rad_s", yaw_rate_rad_s)?;
                        within("accel_m_s2", accel_m_s2, -100.0, 100.0, "an acceleration in m/s^2")
                    }
                    Kind::Range { range_m, .. } => range(range_m),
                    Kind::Doppler { radial_speed_m_s, .. } => speed("radial_speed_m_s", radial_speed_m_s),
                    Kind::RangeDoppler { range_m, radial_speed_m_s, .. } => {
                        range(range_m)?;
                        speed("radial_speed_m_s", radial_speed_m_s)
                    }
                    Kind::Bearing { station_heading_rad, azimuth_rad, elevation_rad, .. } => {
                        angle("station_heading_rad", station_heading_rad)?;
                        angle("azimuth_rad", azimuth_rad)?;
                        within(
                            "elevation_rad",
                            elevation_rad,
                            0.0,
                            std::f64::consts::PI,
                            "an angle from the vertical in [0, pi]",
                        )
                    }
                    Kind::Report { heading_rad, speed_m_s, depth_m } => {
                        angle("heading_rad", heading_rad)?;
                        speed("speed_m_s", speed_m_s)?;
                        within("depth_m", depth_m, -100.0, self.max_depth_m, "limits.max_depth_m")
                    }
                    Kind::ArrayFix { range_m, azimuth_rad, inclination_rad, .. } => {
                        range(range_m)?;
                        angle("azimuth_rad", azimuth_rad)?;
                        within("inclination_rad", inclination_rad, 0.0, std::f64::consts::PI, "[0, pi]")
                    }
                    Kind::Capture(c) => match c.samples.iter().flatten().find(|v| !v.is_finite()) {
                        Some(v) => Err(format!("capture sample {v} is not a finite number")),
                        None => Ok(()),
                    },
                }
            }
            Input::BeaconPosition { position, .. } => {
                position.iter().try_for_each(|&v| within("beacon position", v, -far, far, "a position in metres"))
            }
            Input::Truth(p) => {
                within("ground truth x", p.north_m, -far, far, "a position in metres")?;
                within("ground truth y", p.east_m, -far, far, "a position in metres")?;
                p.heading_rad.map_or(Ok(()), |h| angle("ground truth heading", h))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nav::BeaconFix;
    use nalgebra::Vector3;

    #[test]
    fn limits_screen_the_implausible() {
        let l = Limits::default();
        let fix = BeaconFix::fixed(1, Vector3::zeros());
        let m = |k| Input::Measurement(k);
        assert!(l.check(&m(Kind::Range { beacon: fix, range_m: 150.0 }), Some(0.2)).is_ok());
        assert!(l.check(&m(Kind::Odometry { distance_m: 0.3, heading_change_rad: 0.01 }), Some(0.2)).is_ok());
        assert!(l.check(&m(Kind::Range { beacon: fix, range_m: 0.0 }), None).unwrap_err().contains("max_range_m"));
        assert!(l.check(&m(Kind::Speed { speed_m_s: 21.0 }), None).unwrap_err().contains("max_speed_m_s"));
        // 30 m in 1 s is too far at 20 m/s; in 2 s it is not
        let odo = m(Kind::Odometry { distance_m: 30.0, heading_change_rad: 0.0 });
        assert!(l.check(&odo, Some(1.0)).is_err());
        assert!(l.check(&odo, Some(2.0)).is_ok());
        let nu = [1.0, 0.0, 0.0, 0.0, 0.0, 11.0];
        assert!(l.check(&m(Kind::BodyVelocity { nu }), None).unwrap_err().contains("max_rate_rad_s"));
    }
}
