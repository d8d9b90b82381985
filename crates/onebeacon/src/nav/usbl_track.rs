//! Tracking an underwater vehicle from a surface station that listens to its acoustic
//! messages (hoff2024): the USBL bearing of each message (eq. 1-3, 6-7) and the INS
//! heading, speed and depth the message carries (eq. 8), on the stochastic unicycle of
//! eq. 4. The paper's particle filter ([`ParticleTracker`]) and the same models in an EKF
//! or a UKF ([`GaussianTracker`]), both behind [`Navigator`], so that they run on the
//! same measurements.

use super::Calibration;
use super::capability::ParticleBelief;
use super::{Aiding, Estimate, Gate, Kind, Measurement, Navigator, Outcome, Robust, gated_update};
use crate::filter::particle::{ParticleFilter, ParticleSettings};
use crate::filter::{AnyFilter, FilterKind, GaussianFilter, ProcessModel};
use crate::measure::hoff::{InsReport, UsblBearing};
use crate::measure::{StateComponent, Usbl, UsblAngle};
use crate::models::hoff::{DIM, DIM_MISALIGNED, HoffProcess, MisalignedProcess, idx};
use nalgebra::{SMatrix, SVector, Vector2, Vector3};
use std::cell::OnceCell;

/// A state of the tracked vehicle: [x, y, z, theta, psi, u, b_theta, b_psi] (eq. 4).
pub type TrackState = SVector<f64, DIM>;

/// The measurement noise a tracker assumes (standard deviations).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrackerNoise {
    /// sigma_USBL, rad per metre of range (eq. 3).
    pub usbl_sigma_rad_per_m: f64,
    /// The angles' noise floor besides it, rad (zero in the paper).
    pub usbl_floor_rad: f64,
    /// The station's compass error, rad (its GPS error comes with each bearing).
    pub station_heading_sigma_rad: f64,
    /// The vehicle's reported heading, speed and depth (eq. 8).
    pub heading_sigma_rad: f64,
    pub speed_sigma_m_s: f64,
    pub depth_sigma_m: f64,
    /// Eq. 6 read as printed: eq. 3's sigma as the angles' variance
    /// ([`Usbl::base_variance`]); false (the default) takes it as their standard deviation.
    pub usbl_as_printed: bool,
}

impl Default for TrackerNoise {
    /// hoff2024 Table 1, the filter's column: sigma_USBL^2 = (0.022 deg/m)^2, sigma_COG^2
    /// = 0.15 (printed with units (rad/s)^2; a heading variance, taken as rad^2),
    /// sigma_SOG^2 = 0.06 (m/s)^2, sigma_z^2 = 0.15 m^2; an exact compass.
    fn default() -> Self {
        Self {
            usbl_sigma_rad_per_m: 0.022f64.to_radians(),
            usbl_floor_rad: 0.0,
            station_heading_sigma_rad: 0.0,
            heading_sigma_rad: 0.15f64.sqrt(),
            speed_sigma_m_s: 0.06f64.sqrt(),
            depth_sigma_m: 0.15f64.sqrt(),
            usbl_as_printed: false,
        }
    }
}

/// What both trackers are made of.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrackerConfig {
    pub process: HoffProcess,
    pub noise: TrackerNoise,
    /// Bearings used or not (`Aiding::NONE`: the vehicle's reports alone).
    pub aiding: Aiding,
    /// Bearings whose NIS exceeds this are rejected (Gaussian trackers; infinite: none).
    pub nis_gate: f64,
    /// A heavy-tailed bearing update: the Gaussian trackers inflate the noise of a far
    /// bearing, the particle filter weighs it by a heavy-tailed density.
    pub robust: Option<Robust>,
    /// The USBL head's yaw misalignment as a state (the particle filter; None: the head
    /// is taken as aligned).
    pub misalignment: Option<MisalignmentPrior>,
}

/// A yaw misalignment of the USBL head that the particle tracker estimates: zero mean,
/// this standard deviation at the start, and a random walk.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MisalignmentPrior {
    pub sigma_rad: f64,
    pub walk_rad_per_sqrt_s: f64,
}

impl Default for TrackerConfig {
    fn default() -> Self {
        Self {
            process: HoffProcess::default(),
            noise: TrackerNoise::default(),
            aiding: Aiding::BEARING,
            nis_gate: f64::INFINITY,
            robust: None,
            misalignment: None,
        }
    }
}

impl TrackerNoise {
    /// The USBL of a bearing measured from `station` (its GPS position and error) at
    /// compass heading `station_heading_rad`, with this noise.
    pub fn usbl(&self, station: &super::BeaconFix, station_heading_rad: f64) -> Usbl {
        Usbl {
            position_ned_m: station.position_ned_m,
            heading_rad: station_heading_rad,
            sigma_rad_per_m: self.usbl_sigma_rad_per_m,
            position_sigma_m: station.sigma_m,
            heading_sigma_rad: self.station_heading_sigma_rad,
            floor_rad: self.usbl_floor_rad,
            as_printed: self.usbl_as_printed,
        }
    }
}

/// The estimate of a tracked state with mean `x`, covariance `p` (its heading entries
/// as given: `heading` and its variance).
fn estimate_of(t_s: f64, x: &TrackState, p: &SMatrix<f64, DIM, DIM>, heading: (f64, f64)) -> Estimate {
    Estimate {
        t_s,
        position_ned_m: Vector3::new(x[idx::X], x[idx::Y], x[idx::Z]),
        horizontal_cov_m2: p.fixed_view::<2, 2>(0, 0).into_owned(),
        heading_state_rad: heading.0,
        heading_var_rad2: heading.1,
        roll_pitch_rad: [0.0, x[idx::THETA]],
        speed_m_s: Some(x[idx::U]),
        calibration: Calibration::default(),
    }
}

/// hoff2024's particle filter: particles propagated through eq. 4 with truncated
/// noise, weighed by each report (eq. 8) and bearing (eq. 6-7), resampled once per
/// message time when the effective sample size is low (before the next prediction, so
/// that a report and a bearing of the same message weigh the particles together).
#[derive(Debug, Clone)]
pub struct ParticleTracker {
    cloud: Cloud,
    config: TrackerConfig,
    t_s: f64,
    /// The estimate, computed once per change of the particles.
    cache: OnceCell<Estimate>,
}

/// The particles: the vehicle's eight states, or nine with the head's misalignment.
#[derive(Debug, Clone)]
enum Cloud {
    Aligned(ParticleFilter<DIM>),
    Misaligned(ParticleFilter<DIM_MISALIGNED>, MisalignedProcess),
}

/// `$body` with `$pf` the cloud's filter, whichever its dimension.
macro_rules! with_pf {
    ($cloud:expr, $pf:ident => $body:expr) => {
        match $cloud {
            Cloud::Aligned($pf) => $body,
            Cloud::Misaligned($pf, _) => $body,
        }
    };
}

impl ParticleTracker {
    /// `n` particles drawn from N(`mean`, diag(`sigma`^2)) at `t0_s` (truncated
    /// components clamped into their bounds), and the misalignment's prior if the
    /// config estimates it.
    pub fn new(
        config: TrackerConfig,
        settings: ParticleSettings,
        n: usize,
        t0_s: f64,
        mean: &TrackState,
        sigma: &TrackState,
        seed: u64,
    ) -> Self {
        let mut mean = *mean;
        mean[idx::Z] = mean[idx::Z].max(config.process.z_min_m);
        mean[idx::U] = mean[idx::U].max(0.0);
        let n = n.max(1);
        let cloud = match config.misalignment {
            None => Cloud::Aligned(ParticleFilter::gaussian(n, &mean, sigma, settings, seed)),
            Some(prior) => {
                let mean = mean.push(0.0);
                let sigma = sigma.push(prior.sigma_rad);
                let process =
                    MisalignedProcess { process: config.process, walk_rad_per_sqrt_s: prior.walk_rad_per_sqrt_s };
                Cloud::Misaligned(ParticleFilter::gaussian(n, &mean, &sigma, settings, seed), process)
            }
        };
        Self { cloud, config, t_s: t0_s, cache: OnceCell::new() }
    }

    fn advance_to(&mut self, t_s: f64) {
        let dt = t_s - self.t_s;
        if dt > 0.0 {
            match &mut self.cloud {
                Cloud::Aligned(pf) => pf.predict_resampled(&self.config.process, dt),
                Cloud::Misaligned(pf, process) => pf.predict_resampled(process, dt),
            };
            self.t_s = t_s;
        }
    }
}

impl Navigator for ParticleTracker {
    fn process(&mut self, m: &Measurement) -> Outcome {
        let ok = match m.kind {
            Kind::Report { heading_rad, speed_m_s, depth_m } => {
                self.advance_to(m.t_s);
                let n = &self.config.noise;
                let report = InsReport {
                    heading_rad,
                    speed_m_s,
                    depth_m,
                    sigma_heading_rad: n.heading_sigma_rad,
                    sigma_speed_m_s: n.speed_sigma_m_s,
                    sigma_depth_m: n.depth_sigma_m,
                };
                with_pf!(&mut self.cloud, pf => pf.reweight(&report))
            }
            Kind::Bearing { station, station_heading_rad, azimuth_rad, elevation_rad }
                if self.config.aiding.bearing =>
            {
                self.advance_to(m.t_s);
                let usbl = self.config.noise.usbl(&station, station_heading_rad);
                let bearing = UsblBearing { usbl, azimuth_rad, elevation_rad, robust: self.config.robust };
                with_pf!(&mut self.cloud, pf => pf.reweight(&bearing))
            }
            _ => return Outcome::Skipped,
        };
        self.cache = OnceCell::new();
        // a particle filter has no innovation covariance: no NIS
        if ok { Outcome::Accepted(super::Innovation::NONE) } else { Outcome::Rejected(super::Innovation::NONE) }
    }

    fn predict_to(&mut self, t_s: f64) {
        if t_s > self.t_s {
            self.advance_to(t_s);
            self.cache = OnceCell::new();
        }
    }

    fn estimate(&self) -> Estimate {
        *self.cache.get_or_init(|| {
            with_pf!(&self.cloud, pf => {
                let (x, p) = pf.mean_covariance_with_angle(Some(idx::PSI));
                let (v, c) = (x.fixed_rows::<DIM>(0).into_owned(), p.fixed_view::<DIM, DIM>(0, 0).into_owned());
                let mut e = estimate_of(self.t_s, &v, &c, (v[idx::PSI], c[(idx::PSI, idx::PSI)]));
                e.calibration.usbl_misalignment_rad = x.as_slice().get(idx::MISALIGNMENT).copied();
                e
            })
        })
    }

    fn particles(&self) -> Option<&dyn ParticleBelief> {
        Some(self)
    }
}

impl ParticleBelief for ParticleTracker {
    fn position_sample(&self, m: usize) -> Vec<Vector3<f64>> {
        let picked = with_pf!(&self.cloud, pf => pf.subsample(m.min(pf.len()), [idx::X, idx::Y, idx::Z]));
        picked.into_iter().map(Vector3::from).collect()
    }
}

/// The same models in an EKF or a UKF: eq. 4's mean step and noise (without the
/// truncation), the report as three direct observations, the bearing as the two
/// angles of [`Usbl`].
#[derive(Debug, Clone)]
pub struct GaussianTracker {
    filter: AnyFilter<DIM>,
    config: TrackerConfig,
    gate: Gate,
    t_s: f64,
}

impl GaussianTracker {
    pub fn new(config: TrackerConfig, kind: FilterKind, t0_s: f64, mean: &TrackState, sigma: &TrackState) -> Self {
        let p0 = SMatrix::from_diagonal(&sigma.component_mul(sigma));
        Self { filter: AnyFilter::new(kind, *mean, p0), gate: Gate::new(config.nis_gate), config, t_s: t0_s }
    }

    fn advance_to(&mut self, t_s: f64) {
        let dt = t_s - self.t_s;
        if dt > 0.0 {
            let q = self.config.process.noise_covariance(self.filter.mean(), dt);
            self.filter.predict(&self.config.process, dt, &q);
            self.t_s = t_s;
        }
    }
}

impl Navigator for GaussianTracker {
    fn process(&mut self, m: &Measurement) -> Outcome {
        match m.kind {
            Kind::Report { heading_rad, speed_m_s, depth_m } => {
                self.advance_to(m.t_s);
                let n = &self.config.noise;
                let models = [
                    StateComponent::angle(idx::PSI, n.heading_sigma_rad.powi(2)),
                    StateComponent::value(idx::U, n.speed_sigma_m_s.powi(2)),
                    StateComponent::value(idx::Z, n.depth_sigma_m.powi(2)),
                ]; // eq. 8
                let z = Vector3::new(heading_rad, speed_m_s, depth_m);
                gated_update(&mut self.filter, &models, z, f64::INFINITY, None)
            }
            Kind::Bearing { station, station_heading_rad, azimuth_rad, elevation_rad }
                if self.config.aiding.bearing =>
            {
                self.advance_to(m.t_s);
                let usbl = self.config.noise.usbl(&station, station_heading_rad);
                let models = [usbl.model(UsblAngle::Azimuth), usbl.model(UsblAngle::Elevation)]; // eq. 1-3
                let z = Vector2::new(azimuth_rad, elevation_rad);
                self.gate.update(&mut self.filter, &models, z, self.config.robust)
            }
            _ => Outcome::Skipped,
        }
    }

    fn predict_to(&mut self, t_s: f64) {
        self.advance_to(t_s);
    }

    fn estimate(&self) -> Estimate {
        let (x, p) = (self.filter.mean(), self.filter.covariance());
        estimate_of(self.t_s, x, p, (x[idx::PSI], p[(idx::PSI, idx::PSI)]))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measure::ScalarModel;
    use crate::nav::BeaconFix;
    use rand::SeedableRng;
    use std::f64::consts::FRAC_PI_2;

    /// The k-th bearing (every 4 s) of `truth` from a station stepping 0.5 rad round a
    /// 20 m ring about (40, -20) m, heading 1 rad off its angle, sigma_USBL as given; the
    /// head turned by `misaligned` reads the azimuth that much less.
    fn ring_bearing(
        k: u32,
        truth: &TrackState,
        sigma_rad_per_m: f64,
        misaligned: f64,
        rng: &mut rand_pcg::Pcg64Mcg,
    ) -> (f64, Kind) {
        let a = 0.5 * f64::from(k);
        let station = Vector3::new(40.0 + 20.0 * a.cos(), -20.0 + 20.0 * a.sin(), 0.0);
        let usbl = Usbl::exact(station, a + 1.0, sigma_rad_per_m);
        let az = usbl.model(UsblAngle::Azimuth).sample(truth, rng) - misaligned;
        let el = usbl.model(UsblAngle::Elevation).sample(truth, rng);
        let bearing = Kind::Bearing {
            station: BeaconFix::fixed(0, station),
            station_heading_rad: a + 1.0,
            azimuth_rad: crate::geo::wrap_angle(az),
            elevation_rad: el,
        };
        (4.0 * f64::from(k), bearing)
    }

    /// A vehicle at rest 30 m down, heard from stations on a ring around it: the
    /// particle filter and the EKF both find it from a start 8 m off, within a few
    /// standard deviations of what they report, and agree with each other.
    #[test]
    fn both_trackers_find_a_vehicle_from_bearings() {
        let truth = TrackState::from([40.0, -20.0, 30.0, 0.0, 0.7, 0.0, 0.0, 0.0]);
        let start = TrackState::from([46.0, -15.0, 29.0, 0.0, 0.7, 0.1, 0.0, 0.0]);
        let sigma = TrackState::from([8.0, 8.0, 2.0, 0.02, 0.3, 0.3, 0.001, 0.001]);
        let config = TrackerConfig::default();
        let mut pf = ParticleTracker::new(config, ParticleSettings::default(), 20_000, 0.0, &start, &sigma, 5);
        let mut ekf = GaussianTracker::new(config, FilterKind::Ekf, 0.0, &start, &sigma);
        let true_usbl = 0.01f64.to_radians();
        let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(9);
        for k in 1..=40 {
            let (t, bearing) = ring_bearing(k, &truth, true_usbl, 0.0, &mut rng);
            let p = truth.fixed_rows::<3>(0).into_owned();
            let report = Kind::Report {
                heading_rad: 0.7 + crate::filter::gauss(&mut rng, 0.3),
                speed_m_s: crate::filter::gauss(&mut rng, 0.2f64).abs(),
                depth_m: p.z + crate::filter::gauss(&mut rng, 0.3),
            };
            for nav in [&mut pf as &mut dyn Navigator, &mut ekf] {
                nav.process(&Measurement::new(t, report.clone()));
                assert!(matches!(nav.process(&Measurement::new(t, bearing.clone())), Outcome::Accepted(..)));
            }
        }
        for e in [pf.estimate(), ekf.estimate()] {
            let err = (e.position_ned_m - truth.fixed_rows::<3>(0)).xy();
            let nees = err.transpose() * e.horizontal_cov_m2.try_inverse().unwrap() * err;
            assert!(err.norm() < 1.5, "{err:?}");
            assert!(nees[0] < 13.8, "NEES {}", nees[0]); // chi^2(2) at 0.999
        }
        let (a, b) = (pf.estimate().position_ned_m, ekf.estimate().position_ned_m);
        assert!((a - b).norm() < 1.0, "{a:?} against {b:?}");
        assert_eq!(pf.particles().map(|p| p.position_sample(100).len()), Some(100));
        assert!(ekf.particles().is_none());
    }

    /// A head turned by 3 deg reads every azimuth 3 deg less: heard from stations on a
    /// ring around a vehicle at rest (36 m slant range, sigma_USBL 0.01 deg/m: 0.36 deg a
    /// bearing), a particle tracker with the misalignment as a state (5 deg prior, a walk
    /// of 0.05 deg/sqrt(s)) finds it within 0.25 deg, about 4 standard deviations of the
    /// mean of 40 bearings (0.36 / sqrt(40) = 0.057 deg), and the vehicle within 0.5 m
    /// (each bearing's cross error is 0.23 m); the aligned tracker reports none. (With a
    /// walk of 0.005 deg/sqrt(s) the 2e4 particles' values collapse early and land 1 deg
    /// off.)
    #[test]
    fn particle_tracker_estimates_a_yaw_misalignment() {
        let truth = TrackState::from([40.0, -20.0, 30.0, 0.0, 0.7, 0.0, 0.0, 0.0]);
        let start = TrackState::from([46.0, -15.0, 29.0, 0.0, 0.7, 0.1, 0.0, 0.0]);
        let sigma = TrackState::from([8.0, 8.0, 2.0, 0.02, 0.3, 0.3, 0.001, 0.001]);
        let misaligned = 3f64.to_radians();
        let prior = MisalignmentPrior { sigma_rad: 5f64.to_radians(), walk_rad_per_sqrt_s: 0.05f64.to_radians() };
        // a vehicle known to hold still (a loose speed would let it circle with the
        // stations and mimic the misalignment)
        let still = TrackerConfig {
            process: HoffProcess { sigma: [0.02, 0.02, 0.02, 1e-4, 1e-4, 1e-3, 1e-6, 1e-6], ..HoffProcess::default() },
            noise: TrackerNoise { speed_sigma_m_s: 0.01, ..TrackerNoise::default() },
            ..TrackerConfig::default()
        };
        let config = TrackerConfig { misalignment: Some(prior), ..still };
        let settings = ParticleSettings::default();
        let mut pf = ParticleTracker::new(config, settings, 20_000, 0.0, &start, &sigma, 5);
        let mut aligned = ParticleTracker::new(still, settings, 20_000, 0.0, &start, &sigma, 5);
        let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(4);
        for k in 1..=40 {
            let (t, bearing) = ring_bearing(k, &truth, 0.01f64.to_radians(), misaligned, &mut rng);
            let report = Kind::Report { heading_rad: 0.7, speed_m_s: 0.0, depth_m: 30.0 };
            for nav in [&mut pf, &mut aligned] {
                nav.process(&Measurement::new(t, report.clone()));
                nav.process(&Measurement::new(t, bearing.clone()));
            }
        }
        let e = pf.estimate();
        let found = e.calibration.usbl_misalignment_rad.expect("a misalignment state");
        let err = (e.position_ned_m - truth.fixed_rows::<3>(0)).xy().norm();
        assert!((found - misaligned).abs() < 0.25f64.to_radians(), "{} deg", found.to_degrees());
        assert!(err < 0.5, "{err} m");
        assert_eq!(aligned.estimate().calibration.usbl_misalignment_rad, None, "no state: absent, not zero");
    }

    /// With no message for 12 s, both trackers move their estimate on along the believed
    /// course: a vehicle believed at 1.5 m/s heading east (0.2 m/s spread) is 18 m east
    /// of where it was, within 3 standard deviations of the particles' mean (0.2 x 12 /
    /// sqrt(2e4)) for the particle filter, to 1e-9 for the EKF's mean step; its time
    /// moves on too, and a time already reached changes nothing.
    #[test]
    fn trackers_predict_to_a_step_no_message_reached() {
        let start = TrackState::from([0.0, 0.0, 30.0, 0.0, FRAC_PI_2, 1.5, 0.0, 0.0]);
        let sigma = TrackState::from([0.1, 0.1, 0.1, 1e-4, 1e-4, 0.2, 1e-6, 1e-6]);
        let config = TrackerConfig::default();
        let mut pf = ParticleTracker::new(config, ParticleSettings::default(), 20_000, 0.0, &start, &sigma, 5);
        let mut ekf = GaussianTracker::new(config, FilterKind::Ekf, 0.0, &start, &sigma);
        for (nav, tol) in
            [(&mut pf as &mut dyn Navigator, 3.0 * 0.2 * 12.0 / 20_000f64.sqrt() + 0.05), (&mut ekf, 1e-9)]
        {
            nav.predict_to(12.0);
            let e = nav.estimate();
            assert!(
                (e.position_ned_m.y - 18.0).abs() < tol && e.position_ned_m.x.abs() < tol,
                "{:?}",
                e.position_ned_m
            );
            assert_eq!(e.t_s, 12.0);
            nav.predict_to(12.0);
            assert_eq!(nav.estimate().position_ned_m, e.position_ned_m);
        }
    }
}
