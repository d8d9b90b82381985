//! The inverted-USBL navigator of rypkema sec. 3.3: a vehicle without a DVL estimates
//! where one beacon is relative to itself from the pings its own 5-element array
//! hears, with the factored particle filter of [`crate::filter::factored`], and
//! identifies the command mode the beacon sends (sec. 4.2).
//!
//! Fed [`Kind::Speed`] (propeller model, eq. 1), [`Kind::Attitude`] or [`Kind::Heading`]
//! (AHRS), [`Kind::Depth`] (pressure) and, once a second, either a [`Kind::Capture`] (the
//! hydrophone data: the receiver chain runs here, the signal in the loop) or a
//! [`Kind::ArrayFix`] (a ping already reduced to range, direction and mode, for large
//! campaigns). The estimate is the vehicle's position relative to the beacon (eq. 17-18)
//! offset by the beacon's position as the ping reports it (its GPS; the beacon-centred
//! frame when unknown).

use super::Calibration;
use super::capability::{BeaconRelative, FactoredBelief, ParticleBelief};
use super::{Estimate, Kind, Measurement, Navigator, Outcome};
use crate::dsp::beamform::direction;
use crate::dsp::modes::ModeConfirmation;
use crate::dsp::receiver::{ModeReceiver, Receiver};
use crate::filter::factored::{FactoredFilter, FactoredSets, FactoredSettings, Motion, PingLikelihood};
use crate::models::kinematic6dof::rotation;
use nalgebra::{Matrix2, Matrix3, Vector2, Vector3};
use std::collections::VecDeque;

/// The navigator's settings (rypkema sec. 3.3; defaults from the paper where it gives
/// them, otherwise said so).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IusblConfig {
    pub filter: FactoredSettings,
    /// Factored update (the paper) or joint (every particle weighed by both).
    pub factored: bool,
    /// Speed-over-ground noise of the propeller model, m/s (ours: 0.1).
    pub sigma_speed_m_s: f64,
    /// Heading noise of the prediction, rad (the SandShark's AHRS: 3 deg).
    pub sigma_heading_rad: f64,
    /// Standard deviation of the AHRS heading's slow error, rad, that no ping can show:
    /// every direction is turned into NED with it, so it turns the whole cloud about the
    /// vehicle and the cloud cannot average it away. It is added to the reported
    /// covariance as a consider term (sigma^2 (J r)(J r)^T, r the relative position);
    /// the particles are not moved. Rypkema sec. 2.1: "one standard deviation of
    /// heading error for these vehicles is approximately 3 deg" (3 deg).
    pub heading_bias_sigma_rad: f64,
    /// Largest expected speed of the beacon, m/s: its process noise per second (ours: 0.5).
    pub beacon_speed_m_s: f64,
    /// The beacon's depth, m (rypkema: towed at about 1 m).
    pub beacon_depth_m: f64,
    /// Shallower than this the vehicle is at the surface: the filter starts again at the
    /// next ping heard below it (sec. 3.3.2). m.
    pub surface_depth_m: f64,
    /// Identical identifications in a row that confirm a mode (3).
    pub confirmations: usize,
    /// Once the filter's horizontal standard deviation is below `gate_sigma_m`, the mode
    /// search is gated to the predicted range +- `gate_halfwidth_m` (ours: 15 m, 30 m).
    pub gate_sigma_m: f64,
    pub gate_halfwidth_m: f64,
    /// Floor added to both pseudo-distributions (scaled to a peak of 1), so that one
    /// ping whose peak is a reflection cannot zero every particle (ours: 0.02).
    pub floor: f64,
    /// The beam pattern (CBF-normalised SPD power, in [0, 1]) raised to this power as
    /// the direction weight: an 8 cm array's main lobe is tens of degrees wide where the
    /// direction is known to a few degrees (ours: 40, chosen, not tuned; the factored
    /// filter's errors on rypkema-m1 hardly move between 10 and 100, see README).
    pub beam_exponent: f64,
    /// Noise of a [`Kind::ArrayFix`]'s range and direction as the filter weighs them
    /// (Gaussian in range, von Mises-Fisher in direction): m, rad (ours: 0.7 m, 7 deg,
    /// the 68 % errors of the paper's receivers).
    pub fix_sigma_range_m: f64,
    pub fix_sigma_angle_rad: f64,
    /// Sample rate and sound speed of the receiver: lags to ranges (eq. 5).
    pub fs_hz: f64,
    pub sound_speed_m_s: f64,
}

impl Default for IusblConfig {
    fn default() -> Self {
        Self {
            filter: FactoredSettings::default(),
            factored: true,
            sigma_speed_m_s: 0.1,
            sigma_heading_rad: 3f64.to_radians(),
            heading_bias_sigma_rad: 3f64.to_radians(),
            beacon_speed_m_s: 0.5,
            beacon_depth_m: 1.0,
            surface_depth_m: 0.5,
            confirmations: 3,
            gate_sigma_m: 15.0,
            gate_halfwidth_m: 30.0,
            floor: 0.02,
            beam_exponent: 40.0,
            fix_sigma_range_m: 0.7,
            fix_sigma_angle_rad: 7f64.to_radians(),
            fs_hz: 37_500.0,
            sound_speed_m_s: 1481.0,
        }
    }
}

/// The paper's attitude angles (roll gamma, pitch beta, yaw alpha of eq. 15: ENU
/// vehicle-carried frame, body x forward, y port, z up, yaw from east toward north) of
/// our NED roll, pitch and heading: gamma = roll, beta = -pitch, alpha = pi/2 - heading.
pub fn paper_angles(roll: f64, pitch: f64, heading: f64) -> (f64, f64, f64) {
    (roll, -pitch, std::f64::consts::FRAC_PI_2 - heading)
}

/// The paper's azimuth (from body x toward port) and inclination (from body up) of a
/// direction given in our body frame (forward, starboard, down) by azimuth from x toward
/// starboard and inclination from down: phi = -azimuth, theta = pi - inclination.
pub fn paper_direction(azimuth: f64, inclination: f64) -> (f64, f64) {
    (-azimuth, std::f64::consts::PI - inclination)
}

/// A ping reduced by the vehicle's receiver chain: the range distribution of the
/// identified mode's matched filter (scaled to a peak of 1) and its beam pattern.
struct SignalLikelihood<'a> {
    distribution: &'a [f64],
    peak: f64,
    metres_per_lag: f64,
    receiver: &'a Receiver,
    exponent: f64,
    floor: f64,
}

impl PingLikelihood for SignalLikelihood<'_> {
    fn range_weight(&self, r: f64) -> f64 {
        let lag = (r / self.metres_per_lag).round();
        let v = if lag >= 0.0 { self.distribution.get(lag as usize).copied().unwrap_or(0.0) } else { 0.0 };
        self.floor + (1.0 - self.floor) * (v / self.peak).clamp(0.0, 1.0)
    }

    fn direction_weight(&self, u: &Vector3<f64>) -> f64 {
        self.floor + (1.0 - self.floor) * self.receiver.beam_pattern(u).powf(self.exponent)
    }
}

/// A ping given as range and direction: Gaussian in range, von Mises-Fisher in
/// direction, with the floor.
struct FixLikelihood {
    range_m: f64,
    sigma_range_m: f64,
    toward: Vector3<f64>,
    kappa: f64,
    floor: f64,
}

impl PingLikelihood for FixLikelihood {
    fn range_weight(&self, r: f64) -> f64 {
        self.floor + (1.0 - self.floor) * (-0.5 * ((r - self.range_m) / self.sigma_range_m).powi(2)).exp()
    }

    fn direction_weight(&self, u: &Vector3<f64>) -> f64 {
        self.floor + (1.0 - self.floor) * (self.kappa * (u.dot(&self.toward) - 1.0)).exp()
    }
}

/// The factored update or the joint one.
fn update(filter: &mut FactoredFilter, factored: bool, like: &impl PingLikelihood, att: &Matrix3<f64>) {
    if factored {
        filter.update_factored(like, att);
    } else {
        filter.update_joint(like, att);
    }
}

/// One attitude sample of the rolling buffer.
#[derive(Debug, Clone, Copy)]
struct Attitude {
    t_s: f64,
    roll: f64,
    pitch: f64,
    heading: f64,
}

/// How long the attitude buffer reaches back, s (the paper: the past second).
const ATTITUDE_WINDOW_S: f64 = 1.5;

/// The iUSBL navigator (rypkema sec. 3.3 and 4.2).
pub struct IusblNavigator {
    pub config: IusblConfig,
    filter: FactoredFilter,
    receiver: Option<ModeReceiver>,
    confirmation: ModeConfirmation,
    attitude: VecDeque<Attitude>,
    /// Latest speed, depth; dead-reckoned displacement and its time since the last ping.
    speed_m_s: f64,
    depth_m: Option<f64>,
    t_s: f64,
    t_dr_s: Option<f64>,
    displacement_m: Vector2<f64>,
    depth_at_ping_m: Option<f64>,
    t_ping_s: Option<f64>,
    /// The beacon of the last ping (id, position).
    beacon: Option<(u32, Vector3<f64>)>,
    /// Whether the vehicle surfaced since the last initialisation.
    surfaced: bool,
    pings: u64,
    /// Pings in a row with no pulse detected (the mode gate is off after 3).
    missed: u32,
}

impl IusblNavigator {
    /// A navigator whose filter draws from `seed`, with the receiver chain `receiver`
    /// for [`Kind::Capture`]s (None: it takes [`Kind::ArrayFix`]es only).
    pub fn new(config: IusblConfig, receiver: Option<ModeReceiver>, seed: u64) -> Self {
        Self {
            filter: FactoredFilter::new(config.filter, seed),
            receiver,
            confirmation: ModeConfirmation::new(config.confirmations),
            attitude: VecDeque::new(),
            speed_m_s: 0.0,
            depth_m: None,
            t_s: 0.0,
            t_dr_s: None,
            displacement_m: Vector2::zeros(),
            depth_at_ping_m: None,
            t_ping_s: None,
            beacon: None,
            surfaced: false,
            pings: 0,
            missed: 0,
            config,
        }
    }

    /// The particle set.
    pub fn filter(&self) -> &FactoredFilter {
        &self.filter
    }

    /// Integrates the dead-reckoned displacement up to `t` with the speed and heading
    /// held since the last sample.
    fn dead_reckon(&mut self, t: f64) {
        if let (Some(t0), Some(a)) = (self.t_dr_s, self.attitude.back()) {
            let dt = (t - t0).max(0.0);
            self.displacement_m += Vector2::new(a.heading.cos(), a.heading.sin()) * (self.speed_m_s * dt);
        }
        self.t_dr_s = Some(t);
    }

    /// The attitude nearest to time `t` in the buffer (the latest if empty of it).
    fn attitude_at(&self, t: f64) -> Matrix3<f64> {
        let a = self.attitude.iter().min_by(|a, b| (a.t_s - t).abs().total_cmp(&(b.t_s - t).abs()));
        a.map_or_else(Matrix3::identity, |a| rotation(a.roll, a.pitch, a.heading))
    }

    /// Starts the filter again (surfacing, a new beacon).
    fn reinitialise(&mut self) {
        self.filter.initialise();
        self.surfaced = false;
    }

    /// Prediction to the ping at `t` (eq. 21) over the interval since the last one.
    fn predict_to(&mut self, t: f64) {
        self.dead_reckon(t);
        let dt = self.t_ping_s.map_or(0.0, |t0| (t - t0).max(0.0));
        let depth_change = match (self.depth_m, self.depth_at_ping_m) {
            (Some(d), Some(d0)) => d - d0,
            _ => 0.0,
        };
        let c = &self.config;
        self.filter.predict(&Motion {
            displacement_m: self.displacement_m,
            depth_change_m: depth_change,
            sigma_distance_m: c.sigma_speed_m_s * dt,
            sigma_heading_rad: c.sigma_heading_rad,
            sigma_beacon_m: c.beacon_speed_m_s * dt,
        });
        self.displacement_m = Vector2::zeros();
        self.depth_at_ping_m = self.depth_m;
        self.t_ping_s = Some(t);
    }

    /// Whatever a ping needs before its update: a new beacon or a surfacing starts the
    /// filter again; then the prediction to `t`.
    fn begin_ping(&mut self, t: f64, beacon: &super::BeaconFix) {
        let position = beacon.position_ned_m;
        if self.beacon.is_some_and(|(id, _)| id != beacon.id) || self.surfaced {
            self.reinitialise();
        }
        self.beacon = Some((beacon.id, position));
        self.predict_to(t);
        self.pings += 1;
    }

    /// The search window of the mode bank, in lags: around the predicted range once
    /// converged, the whole capture before.
    fn mode_lags(&self) -> std::ops::Range<usize> {
        let (mean, cov) = self.filter.mean_covariance();
        let sigma = cov.trace().max(0.0).sqrt();
        if sigma > self.config.gate_sigma_m || self.pings < 5 || self.missed >= 3 {
            return 0..usize::MAX;
        }
        let dz = self.config.beacon_depth_m - self.depth_m.unwrap_or(0.0);
        let r = (mean.norm_squared() + dz * dz).sqrt();
        let per_lag = self.config.sound_speed_m_s / self.config.fs_hz;
        let lo = ((r - self.config.gate_halfwidth_m) / per_lag).max(0.0) as usize;
        let hi = ((r + self.config.gate_halfwidth_m) / per_lag).ceil() as usize;
        lo..hi
    }

    fn process_capture(&mut self, t: f64, c: &super::event::Capture) -> Outcome {
        let lags = self.mode_lags();
        let Some(rx) = self.receiver.as_mut() else { return Outcome::Skipped };
        let ping = rx.process(&c.samples, lags);
        if !ping.range.detected() {
            self.missed = self.missed.saturating_add(1);
            return Outcome::Rejected(super::Innovation::NONE); // no pulse heard: nothing to weigh
        }
        self.missed = 0;
        self.confirmation.push(ping.mode);
        let t_tx = c.beacon.t_tx_s.unwrap_or(t);
        self.begin_ping(t, &c.beacon);
        let per_lag = self.config.sound_speed_m_s / self.config.fs_hz;
        let att = self.attitude_at(t_tx + ping.range.lag / self.config.fs_hz);
        let peak = ping.range.distribution.iter().copied().fold(0.0, f64::max).max(f64::MIN_POSITIVE);
        let rx = self.receiver.as_ref().expect("checked above");
        let like = SignalLikelihood {
            distribution: &ping.range.distribution,
            peak,
            metres_per_lag: per_lag,
            receiver: rx.receiver(ping.mode),
            exponent: self.config.beam_exponent,
            floor: self.config.floor,
        };
        update(&mut self.filter, self.config.factored, &like, &att);
        Outcome::Accepted(super::Innovation::NONE)
    }

    fn process_fix(&mut self, t: f64, beacon: &super::BeaconFix, r: f64, az: f64, incl: f64, mode: usize) -> Outcome {
        self.confirmation.push(mode);
        let t_tx = beacon.t_tx_s.unwrap_or(t - r / self.config.sound_speed_m_s);
        self.begin_ping(t, beacon);
        let att = self.attitude_at(t_tx + r / self.config.sound_speed_m_s);
        let c = &self.config;
        let like = FixLikelihood {
            range_m: r,
            sigma_range_m: c.fix_sigma_range_m,
            toward: direction(az, incl),
            kappa: 1.0 / c.fix_sigma_angle_rad.powi(2),
            floor: c.floor,
        };
        update(&mut self.filter, c.factored, &like, &att);
        Outcome::Accepted(super::Innovation::NONE)
    }

    /// The beacon's position as its last ping reported it (the beacon-centred frame's
    /// origin when unknown).
    fn origin(&self) -> Vector3<f64> {
        self.beacon.map(|(_, p)| p).filter(|p| p.iter().all(|v| v.is_finite())).unwrap_or_default()
    }

    /// The vehicle's horizontal position relative to the beacon (eq. 17-18), and its
    /// covariance: the filter's, moved on by the displacement dead-reckoned since the
    /// last ping (the particles move at pings only), with the heading error's consider
    /// term ([`IusblConfig::heading_bias_sigma_rad`]): a small turn d of every
    /// direction moves the relative position r by d J r.
    fn relative(&self) -> (Vector2<f64>, Matrix2<f64>) {
        let (mean, cov) = self.filter.mean_covariance();
        let rel = self.displacement_m - mean;
        let turned = Vector2::new(-rel.y, rel.x) * self.config.heading_bias_sigma_rad;
        (rel, cov + turned * turned.transpose())
    }
}

impl Navigator for IusblNavigator {
    fn process(&mut self, m: &Measurement) -> Outcome {
        let t = m.t_s.max(self.t_s);
        self.t_s = t;
        match &m.kind {
            Kind::Speed { speed_m_s } if speed_m_s.is_finite() => {
                self.dead_reckon(t);
                self.speed_m_s = speed_m_s.clamp(0.0, 10.0);
                Outcome::Applied
            }
            Kind::Attitude { roll_rad, pitch_rad, heading_rad }
                if roll_rad.is_finite() && pitch_rad.is_finite() && heading_rad.is_finite() =>
            {
                self.dead_reckon(t);
                self.attitude.push_back(Attitude { t_s: t, roll: *roll_rad, pitch: *pitch_rad, heading: *heading_rad });
                while self.attitude.front().is_some_and(|a| a.t_s < t - ATTITUDE_WINDOW_S) {
                    self.attitude.pop_front();
                }
                Outcome::Applied
            }
            Kind::Heading { heading_rad } if heading_rad.is_finite() => {
                let (roll, pitch) = self.attitude.back().map_or((0.0, 0.0), |a| (a.roll, a.pitch));
                let attitude = Kind::Attitude { roll_rad: roll, pitch_rad: pitch, heading_rad: *heading_rad };
                self.process(&Measurement::new(t, attitude))
            }
            Kind::Depth { depth_m } if depth_m.is_finite() => {
                self.depth_m = Some(*depth_m);
                if *depth_m < self.config.surface_depth_m {
                    self.surfaced = true;
                }
                Outcome::Applied
            }
            Kind::Capture(c) => {
                if self.depth_m.is_some_and(|d| d < self.config.surface_depth_m) {
                    return Outcome::Skipped; // at the surface: no acoustics
                }
                self.process_capture(t, c)
            }
            Kind::ArrayFix { beacon, range_m, azimuth_rad, inclination_rad, mode } => {
                if self.depth_m.is_some_and(|d| d < self.config.surface_depth_m)
                    || ![*range_m, *azimuth_rad, *inclination_rad].iter().all(|v| v.is_finite())
                {
                    return Outcome::Skipped;
                }
                self.process_fix(t, beacon, *range_m, *azimuth_rad, *inclination_rad, *mode)
            }
            _ => Outcome::Skipped,
        }
    }

    fn estimate(&self) -> Estimate {
        let (rel, cov) = self.relative();
        let origin = self.origin();
        let heading = self.attitude.back().map_or(0.0, |a| a.heading);
        let (roll, pitch) = self.attitude.back().map_or((0.0, 0.0), |a| (a.roll, a.pitch));
        Estimate {
            t_s: self.t_s,
            position_ned_m: Vector3::new(origin.x + rel.x, origin.y + rel.y, self.depth_m.unwrap_or(0.0)),
            horizontal_cov_m2: cov,
            heading_state_rad: heading,
            heading_var_rad2: self.config.sigma_heading_rad.powi(2),
            roll_pitch_rad: [roll, pitch],
            speed_m_s: Some(self.speed_m_s),
            calibration: Calibration::default(),
        }
    }

    fn particles(&self) -> Option<&dyn ParticleBelief> {
        Some(self)
    }

    fn beacon_relative(&self) -> Option<&dyn BeaconRelative> {
        Some(self)
    }

    /// The sets of the factored filter (rypkema sec. 4.2); none for the joint one.
    fn factored(&self) -> Option<&dyn FactoredBelief> {
        self.config.factored.then_some(self as &dyn FactoredBelief)
    }
}

impl ParticleBelief for IusblNavigator {
    /// Every k-th particle (equally weighted after each resampling), k = n / m.
    fn position_sample(&self, m: usize) -> Vec<Vector3<f64>> {
        let origin = self.origin();
        let step = (self.filter.particles().len() / m.max(1)).max(1);
        let d = self.displacement_m;
        self.filter
            .particles()
            .iter()
            .step_by(step)
            .map(|p| Vector3::new(origin.x + d.x - p.x, origin.y + d.y - p.y, self.depth_m.unwrap_or(0.0)))
            .collect()
    }
}

impl FactoredBelief for IusblNavigator {
    fn factored_sets(&self) -> &FactoredSets {
        self.filter.sets()
    }
}

impl BeaconRelative for IusblNavigator {
    fn beacon_relative_ned_m(&self) -> Vector3<f64> {
        let (rel, _) = self.relative();
        Vector3::new(rel.x, rel.y, self.depth_m.unwrap_or(0.0))
    }

    fn command_mode(&self) -> Option<usize> {
        self.confirmation.confirmed()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use nalgebra::Rotation3;

    /// Eq. 15 (ENU, body forward-port-up, yaw from east) with the converted angles is
    /// our NED rotation seen through the two frame changes: R_enu = T R_ned F, T swapping
    /// north and east and flipping down, F flipping starboard and down. And a direction
    /// given by our azimuth and inclination is the paper's (eq. 16) at the converted
    /// angles.
    #[test]
    fn enu_and_ned_frames_and_yaw_conventions() {
        let t = Matrix3::new(0.0, 1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, -1.0);
        let f = Matrix3::from_diagonal(&Vector3::new(1.0, -1.0, -1.0));
        let rz = |a: f64| Rotation3::from_axis_angle(&Vector3::z_axis(), a).into_inner();
        let ry = |a: f64| Rotation3::from_axis_angle(&Vector3::y_axis(), a).into_inner();
        let rx = |a: f64| Rotation3::from_axis_angle(&Vector3::x_axis(), a).into_inner();
        for (roll, pitch, heading) in [(0.0, 0.0, 0.0), (0.1, -0.2, 0.7), (-0.3, 0.25, 3.0), (0.05, 0.4, -2.2)] {
            let (g, b, a) = paper_angles(roll, pitch, heading);
            let paper = rz(a) * ry(b) * rx(g); // eq. 15
            assert_relative_eq!(paper, t * rotation(roll, pitch, heading) * f, epsilon = 1e-12);
            for (az, incl) in [(0.3, 1.2), (2.5, 2.0), (-1.0, 0.4)] {
                let (phi, theta) = paper_direction(az, incl);
                let u_paper = Vector3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos()); // eq. 16
                assert_relative_eq!(f * direction(az, incl), u_paper, epsilon = 1e-12);
            }
        }
        // heading 0 (north) is the paper's yaw 90 deg; heading 90 deg (east) is yaw 0
        assert_relative_eq!(paper_angles(0.0, 0.0, 0.0).2, 90f64.to_radians());
        assert_relative_eq!(paper_angles(0.0, 0.0, 90f64.to_radians()).2, 0.0);
    }

    /// A silent capture, one of NaNs and an absurd fix leave the filter as it was
    /// (no pulse: nothing to weigh; not finite: skipped).
    #[test]
    fn bad_pings_leave_the_filter_alone() {
        let rx = ModeReceiver::new(
            &crate::dsp::waveform::rypkema_modes(),
            &crate::dsp::beamform::pyramid_8cm(),
            crate::dsp::receiver::ReceiverConfig::default(),
        );
        let mut nav = IusblNavigator::new(IusblConfig::default(), Some(rx), 2);
        nav.process(&Measurement::new(0.0, Kind::Depth { depth_m: 2.5 }));
        let before = nav.filter().particles().to_vec();
        let beacon = super::super::BeaconFix::fixed(0, Vector3::new(10.0, 0.0, 1.0));
        for value in [0.0, f64::NAN] {
            let capture = super::super::Capture { beacon, samples: vec![vec![value; 8000]; 5] };
            let out = nav.process(&Measurement::new(1.0, Kind::Capture(std::sync::Arc::new(capture))));
            assert!(matches!(out, Outcome::Rejected(..)), "{out:?}");
        }
        let fix = Kind::ArrayFix { beacon, range_m: f64::NAN, azimuth_rad: 0.0, inclination_rad: 1.0, mode: 0 };
        assert_eq!(nav.process(&Measurement::new(2.0, fix)), Outcome::Skipped);
        assert_eq!(nav.filter().particles(), &before[..]);
        assert!(nav.estimate().position_ned_m.iter().all(|v| v.is_finite()));
    }

    /// Fixes from a beacon 40 m north-east of a vehicle driving east: the relative
    /// estimate converges to the truth and the modes are confirmed after three.
    #[test]
    fn fixes_converge_and_confirm_the_mode() {
        let mut nav = IusblNavigator::new(IusblConfig::default(), None, 3);
        let beacon = Vector3::new(30.0, 30.0, 1.0);
        let mut rng = rand_pcg::Pcg64::new(5, 7);
        let mut modes = Vec::new();
        for k in 0..120 {
            let t = k as f64;
            let vehicle = Vector3::new(0.0, t * 1.0, 2.5);
            let heading = std::f64::consts::FRAC_PI_2;
            let _ = nav.process(&Measurement::new(t, Kind::Depth { depth_m: 2.5 }));
            let _ = nav.process(&Measurement::new(t, Kind::Speed { speed_m_s: 1.0 }));
            let _ = nav
                .process(&Measurement::new(t, Kind::Attitude { roll_rad: 0.0, pitch_rad: 0.0, heading_rad: heading }));
            let d = rotation(0.0, 0.0, heading).transpose() * (beacon - vehicle);
            let (az, incl) = crate::dsp::beamform::azimuth_inclination(&d);
            let noise = |s: f64, rng: &mut rand_pcg::Pcg64| crate::filter::gauss(rng, s);
            let fix = Kind::ArrayFix {
                beacon: super::super::BeaconFix::fixed(0, beacon),
                range_m: d.norm() + noise(0.3, &mut rng),
                azimuth_rad: az + noise(0.03, &mut rng),
                inclination_rad: incl + noise(0.03, &mut rng),
                mode: if k < 60 { 0 } else { 2 },
            };
            let _ = nav.process(&Measurement::new(t + 0.02, fix));
            modes.push(nav.command_mode());
            if k > 40 && k % 10 == 0 {
                let e = nav.estimate();
                assert!((e.position_ned_m.xy() - vehicle.xy()).norm() < 3.0, "{k}: {} vs {vehicle}", e.position_ned_m);
            }
        }
        // between pings the estimate moves on by dead reckoning: 1 m/s east for 1 s
        let before = nav.estimate().position_ned_m;
        for i in 1..=10 {
            let t = 119.02 + 0.1 * i as f64;
            nav.process(&Measurement::new(t, Kind::Speed { speed_m_s: 1.0 }));
            let east = Kind::Attitude { roll_rad: 0.0, pitch_rad: 0.0, heading_rad: std::f64::consts::FRAC_PI_2 };
            nav.process(&Measurement::new(t, east));
        }
        let moved = nav.estimate().position_ned_m - before;
        assert!((moved.y - 1.0).abs() < 1e-9 && moved.x.abs() < 1e-9, "{moved}");
        assert_eq!(modes[1], None);
        assert_eq!(modes[2], Some(0));
        assert_eq!(modes[61], Some(0));
        assert_eq!(modes[62], Some(2));
    }
}
