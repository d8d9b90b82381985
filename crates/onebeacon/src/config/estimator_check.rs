//! The checks of `[[estimators]]` tables: each key applies to the host it is given in
//! and is in range; the first violation is reported with its key.

use super::check::{Rule, Violation, check, check_count, check_names, check_ukf};
use super::estimator::{EstimatorKind, EstimatorSpec, Host};
use crate::nav::Aiding;

impl EstimatorSpec {
    /// The numeric tuning keys that are set, with their rule and their hosts.
    fn tuning_keys(&self) -> Vec<(&'static str, f64, Rule, &'static [Host])> {
        use Host::*;
        use Rule::*;
        const RANGING: &[Host] = &[FixedBeacon, MovingBeacon, Log];
        const FIXED_LOG: &[Host] = &[FixedBeacon, Log];
        const USBL: &[Host] = &[PassiveUsbl, Log];
        const CALIBRATING: &[Host] = &[FixedBeacon, MovingBeacon, Log];
        const CLOCKED: &[Host] = &[FixedBeacon, MovingBeacon];
        const CARRIED: &[Host] = &[FixedBeacon, MovingBeacon, Log];
        const GATED: &[Host] = &[FixedBeacon, MovingBeacon, PassiveUsbl, Log];
        let flag = |b: Option<bool>| b.map(|b| f64::from(u8::from(b)));
        let mut keys = vec![
            ("range_sigma_m", self.noise.range_sigma_m, Positive, RANGING),
            ("doppler_sigma_m_s", self.noise.doppler_sigma_m_s, Positive, FIXED_LOG),
            ("heading_sigma_deg", self.noise.heading_sigma_deg, Positive, &[FixedBeacon, PassiveUsbl, Log]),
            ("usbl_sigma_deg_per_m", self.usbl.usbl_sigma_deg_per_m, Positive, USBL),
            ("usbl_floor_deg", self.usbl.usbl_floor_deg, NonNegative, USBL),
            ("usbl_as_printed", flag(self.usbl.usbl_as_printed), Finite, USBL),
            ("usbl_misalignment_sigma_deg", self.usbl.usbl_misalignment_sigma_deg, Positive, USBL),
            (
                "usbl_misalignment_walk_deg_per_sqrt_s",
                self.usbl.usbl_misalignment_walk_deg_per_sqrt_s,
                NonNegative,
                USBL,
            ),
            ("compass_sigma_deg", self.usbl.compass_sigma_deg, NonNegative, USBL),
            ("depth_sigma_m", self.noise.depth_sigma_m, Positive, &[MovingBeacon, PassiveUsbl, Log]),
            ("velocity_sigma_m_s", self.six_dof.velocity_sigma_m_s, Positive, &[MovingBeacon]),
            ("rate_sigma_rad_s", self.six_dof.rate_sigma_rad_s, Positive, &[MovingBeacon]),
            ("attitude_sigma_deg", self.six_dof.attitude_sigma_deg, Positive, &[MovingBeacon]),
            ("seed", self.seed.map(|s| s as f64), Finite, &[Log]),
            ("process_noise_scale", self.usbl.process_noise_scale, Positive, USBL),
            ("particles", self.particle.particles.map(|n| n as f64), Positive, USBL),
            ("ess_fraction", self.particle.ess_fraction, Positive, USBL),
            ("roughening_k", self.particle.roughening_k, Positive, USBL),
            ("min_effective_particles", self.particle.min_effective_particles, NonNegative, USBL),
            ("yaw_rate_sigma_rad_s", self.unicycle.yaw_rate_sigma_rad_s, Positive, &[FixedBeacon]),
            ("accel_sigma_m_s2", self.unicycle.accel_sigma_m_s2, Positive, &[FixedBeacon]),
            ("distance_sigma_frac", self.planar.distance_sigma_frac, NonNegative, &[Log]),
            ("heading_change_sigma_frac", self.planar.heading_change_sigma_frac, NonNegative, &[Log]),
            ("heading_walk_deg_per_sqrt_m", self.planar.heading_walk_deg_per_sqrt_m, NonNegative, &[Log]),
            ("speed_sigma_m_s", self.noise.speed_sigma_m_s, NonNegative, &[PassiveUsbl, Log]),
            ("bias_walk_m_per_sqrt_s", self.calibration.bias_walk_m_per_sqrt_s, NonNegative, CALIBRATING),
            ("position_walk_m_per_sqrt_s", self.planar.position_walk_m_per_sqrt_s, NonNegative, &[Log]),
            ("track_accel_sigma_m_s2", self.planar.track_accel_sigma_m_s2, Positive, &[Log]),
            ("nis_gate", self.gating.nis_gate, Threshold, GATED),
            ("huber_k", self.gating.huber_k, Positive, GATED),
            ("student_t_dof", self.gating.student_t_dof, Positive, GATED),
            ("mirror_recovery", flag(self.unicycle.mirror_recovery), Finite, &[FixedBeacon]),
            ("min_speed_m_s", self.unicycle.min_speed_m_s, Positive, &[FixedBeacon]),
            ("estimate_bias", flag(self.calibration.estimate_bias), Finite, CALIBRATING),
            ("estimate_bias_drift", flag(self.calibration.estimate_bias_drift), Finite, CLOCKED),
            ("bias_drift_sigma_m_s", self.calibration.bias_drift_sigma_m_s, Positive, CLOCKED),
            ("estimate_beacon_offsets", flag(self.calibration.estimate_beacon_offsets), Finite, &[Log]),
            ("bias_m", self.calibration.bias_m, Finite, CALIBRATING),
            ("bias_sigma_m", self.calibration.bias_sigma_m, Positive, CALIBRATING),
            ("estimate_range_scale", flag(self.calibration.estimate_range_scale), Finite, CALIBRATING),
            ("range_scale_sigma", self.calibration.range_scale_sigma, Positive, CALIBRATING),
            ("estimate_distance_scale", flag(self.calibration.estimate_distance_scale), Finite, &[Log]),
            ("distance_scale_sigma", self.calibration.distance_scale_sigma, Positive, &[Log]),
            ("estimate_turn_scale", flag(self.calibration.estimate_turn_scale), Finite, &[Log]),
            ("turn_scale_sigma", self.calibration.turn_scale_sigma, Positive, &[Log]),
            ("estimate_current", flag(self.calibration.estimate_current), Finite, CARRIED),
            ("current_sigma_m_s", self.calibration.current_sigma_m_s, Positive, CARRIED),
            ("current_walk_m_s_per_sqrt_s", self.calibration.current_walk_m_s_per_sqrt_s, NonNegative, CARRIED),
            ("speed_coast_time_s", self.planar.speed_coast_time_s, Positive, &[Log]),
            ("estimate_heading_offset", flag(self.calibration.estimate_heading_offset), Finite, &[Log]),
            ("heading_offset_sigma_deg", self.calibration.heading_offset_sigma_deg, Positive, &[Log]),
            ("heading_offset_time_s", self.calibration.heading_offset_time_s, Positive, &[Log]),
        ];
        for q in self.unicycle.q_diag.iter().flatten() {
            keys.push(("q_diag", Some(*q), NonNegative, &[FixedBeacon]));
        }
        for q in self.usbl.process_sigma.iter().flatten() {
            keys.push(("process_sigma", Some(*q), NonNegative, USBL));
        }
        keys.into_iter().filter_map(|(k, v, s, h)| v.map(|v| (k, v, s, h))).collect()
    }
}

/// The `[[estimators]]` tables of `host`: names, the UKF's parameters, every tuning
/// key that is set (it must apply to the host and be in range), and the acoustic
/// measurements (the host must give them).
pub fn check_estimators(specs: &[EstimatorSpec], host: Host) -> Result<(), Violation> {
    check_names("estimators", &specs.iter().map(|e| e.name()).collect::<Vec<_>>())?;
    for (k, e) in specs.iter().enumerate() {
        // the planar state has 4 to 8 components; 7 bounds kappa for the common case
        let states = match host {
            Host::Log => 7,
            Host::PassiveUsbl => 8,
            Host::FixedBeacon | Host::MovingBeacon => 6 + e.range_calibration().states(),
        };
        let key = |f: &str| format!("estimators[{k}].{f}");
        check_ukf(&format!("estimators[{k}]"), states, (e.ukf_alpha, e.ukf_beta, e.ukf_kappa))?;
        for (name, v, rule, hosts) in e.tuning_keys() {
            if !hosts.contains(&host) {
                let flag = name.starts_with("estimate_") || matches!(name, "mirror_recovery" | "usbl_as_printed");
                let value = if flag { (v != 0.0).to_string() } else { format!("{v:?}") };
                let applies: Vec<&str> = hosts.iter().map(|h| h.label()).collect();
                return Err(Violation {
                    key: key(name),
                    value,
                    allowed: format!("does not apply to a {} (it applies to: {})", host.label(), applies.join(", ")),
                });
            }
            check(&key(name), v, rule)?;
        }
        if e.calibration.estimate_beacon_offsets == Some(true)
            && (e.calibration.estimate_bias == Some(true) || e.planar.track_accel_sigma_m_s2.is_some())
        {
            return Err(Violation {
                key: key("estimate_beacon_offsets"),
                value: "true".into(),
                allowed: "replaces the shared offset of estimate_bias (give one of the two), and does not apply to the tracker (track_accel_sigma_m_s2)".into(),
            });
        }
        // a log's motion states are the planar navigator's
        let motion = [
            ("estimate_heading_offset", e.calibration.estimate_heading_offset == Some(true)),
            ("speed_coast_time_s", e.planar.speed_coast_time_s.is_some()),
            ("estimate_current", host == Host::Log && e.calibration.estimate_current == Some(true)),
        ];
        if let Some((name, _)) = motion.iter().find(|(_, on)| *on)
            && (e.kind.tracks_bearings() || e.kind.iusbl() || e.planar.track_accel_sigma_m_s2.is_some())
        {
            return Err(Violation {
                key: key(name),
                value: "(set)".into(),
                allowed: "applies to a log's planar navigators (kinds range+doppler, rosb, range-ekf, dead-reckoning), not to a USBL tracker, the iUSBL navigator or the constant-velocity tracker (track_accel_sigma_m_s2)".into(),
            });
        }
        if e.iusbl.is_some() && !e.kind.iusbl() {
            return Err(Violation {
                key: key("iusbl"),
                value: "(set)".into(),
                allowed: format!("applies to kinds iusbl and iusbl-joint only, not to {:?}", e.kind.label()),
            });
        }
        for (name, v, positive) in e.iusbl.iter().flat_map(|k| k.numbers()) {
            check(&key(&format!("iusbl.{name}")), v, if positive { Rule::Positive } else { Rule::NonNegative })?;
        }
        let particle = e.kind == EstimatorKind::Particle;
        let tracker = e.kind.tracks_bearings();
        if e.kind.iusbl() && host != Host::Log {
            return Err(Violation {
                key: key("kind"),
                value: format!("{:?}", e.kind.label()),
                allowed: format!("navigates on a beacon's array fixes: a fleet world or a log, not a {}", host.label()),
            });
        }
        // a log may carry USBL bearings (a surface vehicle's stream)
        if tracker && !matches!(host, Host::PassiveUsbl | Host::Log)
            || host == Host::PassiveUsbl && matches!(e.kind, EstimatorKind::RangeDoppler | EstimatorKind::Rosb)
        {
            let allowed = if tracker {
                format!("tracks a vehicle by USBL bearings: a passive_usbl world or a log, not a {}", host.label())
            } else {
                "uses ranges; a passive_usbl world gives USBL bearings and the vehicle's reports (kinds pf, bearing, range-ekf, dead-reckoning)".to_string()
            };
            return Err(Violation { key: key("kind"), value: format!("{:?}", e.kind.label()), allowed });
        }
        let pf_only = [
            ("particles", e.particle.particles.is_some()),
            ("resampler", e.particle.resampler.is_some()),
            ("ess_fraction", e.particle.ess_fraction.is_some()),
            ("roughening_k", e.particle.roughening_k.is_some()),
            ("min_effective_particles", e.particle.min_effective_particles.is_some()),
            ("usbl_misalignment_sigma_deg", e.usbl.usbl_misalignment_sigma_deg.is_some()),
            ("usbl_misalignment_walk_deg_per_sqrt_s", e.usbl.usbl_misalignment_walk_deg_per_sqrt_s.is_some()),
        ];
        if let Some((name, _)) = pf_only.iter().find(|(_, set)| *set).filter(|_| !particle) {
            return Err(Violation {
                key: key(name),
                value: "(set)".into(),
                allowed: format!("applies to a particle filter (kind = \"pf\") only, not to kind {:?}", e.kind.label()),
            });
        }
        if e.usbl.usbl_misalignment_walk_deg_per_sqrt_s.is_some() && e.usbl.usbl_misalignment_sigma_deg.is_none() {
            return Err(Violation {
                key: key("usbl_misalignment_walk_deg_per_sqrt_s"),
                value: "(set)".into(),
                allowed: "walks the misalignment state that usbl_misalignment_sigma_deg turns on (give it too)".into(),
            });
        }
        if particle {
            check_count(&key("particles"), e.particle.particles.unwrap_or(1), 1, 50_000_000)?;
            if let Some(f) = e.particle.ess_fraction {
                check(&key("ess_fraction"), f, Rule::Probability)?;
            }
        }
        let has = if host == Host::Log && tracker { Aiding::BEARING } else { host.acoustic() };
        let asked = e.aiding(host);
        if (asked.doppler && !has.doppler) || (asked.range && !has.range) || (asked.bearing && !has.bearing) {
            let (k, value) = match &e.measurements {
                Some(m) => (key("measurements"), format!("{m:?}").to_lowercase()),
                None => (key("kind"), format!("{:?}", e.kind.label())),
            };
            let gives = match host {
                Host::MovingBeacon => "ranges only",
                Host::PassiveUsbl => "USBL bearings only",
                Host::FixedBeacon | Host::Log => "ranges and Doppler speeds only",
            };
            let uses = if asked.doppler && !has.doppler {
                "Doppler speeds"
            } else if asked.range && !has.range {
                "ranges"
            } else {
                "USBL bearings"
            };
            return Err(Violation { key: k, value, allowed: format!("uses {uses}; a {} gives {gives}", host.label()) });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nav::SensorNoise;

    fn spec(text: &str) -> EstimatorSpec {
        toml::from_str(text).unwrap()
    }

    fn error(text: &str, host: Host) -> String {
        match check_estimators(&[spec(text)], host) {
            Ok(()) => String::new(),
            Err(v) => format!("{} = {}: {}", v.key, v.value, v.allowed),
        }
    }

    /// The short names and what they stand for in each host (written out by hand).
    #[test]
    fn short_names_expand_per_host() {
        use EstimatorKind::*;
        let (rd, r, none) = (Aiding::RANGE_DOPPLER, Aiding::RANGE, Aiding::NONE);
        for (kind, fixed, moving, log) in
            [(RangeDoppler, rd, rd, rd), (Rosb, r, r, r), (RangeEkf, rd, r, rd), (DeadReckoning, none, none, none)]
        {
            let e = EstimatorSpec::new(kind);
            assert_eq!(
                [e.aiding(Host::FixedBeacon), e.aiding(Host::MovingBeacon), e.aiding(Host::Log)],
                [fixed, moving, log]
            );
        }
        // old spellings and the full form
        assert_eq!(spec("kind = \"range_ekf\"").kind, RangeEkf);
        assert_eq!(spec("kind = \"dead_reckoning\"").kind, DeadReckoning);
        let doppler_only = spec("kind = \"range-ekf\"\nmeasurements = [\"doppler\"]");
        assert_eq!(doppler_only.aiding(Host::Log), Aiding { range: false, doppler: true, bearing: false });
    }

    /// One table means the same in every host where its keys apply, and is refused by
    /// name where they do not.
    #[test]
    fn one_table_every_host() {
        let shared = "kind = \"rosb\"\nname = \"r\"\nrange_sigma_m = 2.0\nfilter = \"ukf\"\nukf_alpha = 0.5";
        for host in [Host::FixedBeacon, Host::MovingBeacon, Host::Log] {
            assert_eq!(error(shared, host), "", "{host:?}");
        }
        let e = spec(shared);
        assert_eq!(e.ekf_tuning().r_range_m2, 4.0);
        assert_eq!(e.planar_config().noise.range_sigma_m, 2.0);
        let sensors =
            SensorNoise { velocity_m_s: 0.1, rate_rad_s: 0.01, depth_m: 0.1, attitude_rad: 0.02, range_m: 1.0 };
        assert_eq!(e.sensor_noise(sensors).range_m, 2.0);
        assert_eq!(e.sensor_noise(sensors).velocity_m_s, 0.1);

        assert_eq!(
            error("kind = \"pf\"\nrange_sigma_m = 3.0", Host::PassiveUsbl),
            "estimators[0].range_sigma_m = 3.0: does not apply to a passive_usbl world (it applies to: fixed_beacon world, moving_beacon world or 6-DOF stream, log or planar stream)"
        );
        assert_eq!(
            error("kind = \"range+doppler\"", Host::MovingBeacon),
            "estimators[0].kind = \"range+doppler\": uses Doppler speeds; a moving_beacon world or 6-DOF stream gives ranges only"
        );
        assert!(error("kind = \"rosb\"\nq_diag = [1, 1, 1, 1, -1, 1]", Host::FixedBeacon).contains(">= 0"));
        assert_eq!(
            error("kind = \"rosb\"\nestimate_bias_drift = true", Host::Log),
            "estimators[0].estimate_bias_drift = true: does not apply to a log or planar stream (it applies to: fixed_beacon world, moving_beacon world or 6-DOF stream)"
        );
        assert_eq!(
            error("kind = \"range-ekf\"\nestimate_bias_drift = true\nrobust = \"huber\"", Host::MovingBeacon),
            ""
        );
        assert!(error("kind = \"rosb\"\nrange_sigma_m = 0.0", Host::Log).contains("> 0"));
        // the misalignment state: a particle filter's, its walk only with it
        assert_eq!(error("kind = \"pf\"\nusbl_misalignment_sigma_deg = 2.0", Host::PassiveUsbl), "");
        assert_eq!(
            error("kind = \"bearing\"\nusbl_misalignment_sigma_deg = 2.0", Host::PassiveUsbl),
            "estimators[0].usbl_misalignment_sigma_deg = (set): applies to a particle filter (kind = \"pf\") only, not to kind \"bearing\""
        );
        assert!(
            error("kind = \"pf\"\nusbl_misalignment_walk_deg_per_sqrt_s = 0.1", Host::PassiveUsbl)
                .contains("usbl_misalignment_sigma_deg turns on")
        );
        assert!(error("kind = \"pf\"\nusbl_misalignment_sigma_deg = -1.0", Host::PassiveUsbl).contains("> 0"));
    }

    /// The drift implies the offset; the states follow the pose in the order offset,
    /// drift, scale, current; the priors are the keys' or the documented defaults.
    #[test]
    fn calibration_keys_make_calibration_states() {
        use crate::nav::OffsetPrior;
        let drift = spec("kind = \"range-ekf\"\nestimate_bias_drift = true\nbias_sigma_m = 2.0");
        let o = OffsetPrior { initial_m: 0.0, sigma_m: 2.0, walk_m_per_sqrt_s: 0.005, drift_sigma_m_s: Some(4.5e-3) };
        assert_eq!(drift.range_calibration().offset, Some(o));
        assert_eq!(drift.range_calibration().states(), 2);
        let all =
            spec("kind = \"range-ekf\"\nestimate_bias = true\nestimate_range_scale = true\nrange_scale_sigma = 0.02");
        assert_eq!(all.range_calibration().scale_sigma, Some(0.02));
        assert_eq!(all.range_calibration().states(), 2);
        assert_eq!(spec("kind = \"range-ekf\"").range_calibration().states(), 0);
        // the current: two states behind the rest, the documented defaults where a key
        // is absent
        use crate::nav::CurrentPrior;
        let water = spec("kind = \"range+doppler\"\nestimate_bias_drift = true\nestimate_current = true");
        let defaults = CurrentPrior { sigma_m_s: 0.1, walk_m_s_per_sqrt_s: 1e-3 };
        assert_eq!(water.range_calibration().current, Some(defaults));
        assert_eq!(water.range_calibration().states(), 4);
        let own = spec(
            "kind = \"range-ekf\"\nestimate_current = true\ncurrent_sigma_m_s = 0.3\ncurrent_walk_m_s_per_sqrt_s = 0",
        );
        assert_eq!(own.range_calibration().current, Some(CurrentPrior { sigma_m_s: 0.3, walk_m_s_per_sqrt_s: 0.0 }));
        // a log's planar navigators take the current, and the heading offset (its
        // extended layout); a tracker does not
        let log = spec(
            "kind = \"range+doppler\"\nestimate_current = true\nestimate_heading_offset = true\nheading_offset_time_s = 600",
        );
        assert_eq!(error("kind = \"range+doppler\"\nestimate_current = true", Host::Log), "");
        let p = log.planar_config();
        assert_eq!(p.current, Some(defaults));
        assert_eq!(
            p.heading_offset,
            Some(crate::nav::HeadingOffsetPrior { sigma_rad: 3f64.to_radians(), time_s: 600.0 })
        );
        assert!(p.extended() && !spec("kind = \"range+doppler\"").planar_config().extended());
        assert_eq!(
            error("kind = \"bearing\"\nestimate_heading_offset = true", Host::Log),
            "estimators[0].estimate_heading_offset = (set): applies to a log's planar navigators (kinds range+doppler, rosb, range-ekf, dead-reckoning), not to a USBL tracker, the iUSBL navigator or the constant-velocity tracker (track_accel_sigma_m_s2)"
        );
        assert!(
            error("kind = \"range-ekf\"\nspeed_coast_time_s = 4\ntrack_accel_sigma_m_s2 = 0.1", Host::Log)
                .contains("planar")
        );
        assert!(
            error("kind = \"range-ekf\"\nestimate_heading_offset = true", Host::FixedBeacon).contains("does not apply")
        );
        assert!(
            error("kind = \"rosb\"\nestimate_current = true\ncurrent_sigma_m_s = 0", Host::FixedBeacon).contains("> 0")
        );
    }

    /// Left out, garin2024's noise keys are eq. 25's variances exactly (no square root
    /// and square in between).
    #[test]
    fn fixed_beacon_defaults_are_eq_25() {
        let t = EstimatorSpec::new(EstimatorKind::RangeDoppler).ekf_tuning();
        assert_eq!((t.r_heading_rad2, t.r_yaw_rate_rad2_s2, t.r_accel_m2_s4), (1.0, 0.005, 0.005));
        assert_eq!((t.r_range_m2, t.r_doppler_m2_s2), (12.0, 0.2));
        assert_eq!(t.q_diag, [0.25f64.powi(8); 6]);
    }
}
