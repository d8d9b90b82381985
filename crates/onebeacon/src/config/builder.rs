//! From an estimator spec to its navigator on a log or a stream (replay, `stream`, the
//! Python `Navigator`): a USBL tracker, the iUSBL navigator, sousa's 6-DOF filter,
//! garin2024's unicycle filter or the planar family. Every world of the simulator builds
//! its vehicles' navigators here too (a fleet's iUSBL receiver on the channel model
//! aside).

use super::estimator::{EstimatorKind, EstimatorSpec, Host};
use crate::models::hoff::{DIM, idx};
use crate::models::kinematic6dof::{Cov as Cov6, State as Eta};
use crate::models::unicycle::{Cov as UnicycleCov, State as UnicycleState};
use crate::nav::capability::Capability;
use crate::nav::restart::Builder;
use crate::nav::single_beacon::{self, Guards};
use crate::nav::{GaussianTracker, IusblNavigator, ParticleTracker, SensorNoise, TrackerNoise, range_6dof};
use nalgebra::SVector;
use serde::{Deserialize, Serialize};

/// The motion model of a stream's (or a log's) estimators (`model`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum VehicleModel {
    /// A planar vehicle on odometry (speed and heading, or increments): the planar
    /// family, or a USBL tracker or the iUSBL navigator by kind.
    #[default]
    #[serde(rename = "planar")]
    Planar,
    /// sousa's 6-DOF kinematic vehicle on body velocities, depth and attitude (sec. 3.2):
    /// the estimators are those of a moving_beacon world.
    #[serde(rename = "6dof")]
    Kinematic6Dof,
    /// garin2024's planar unicycle (sec. III: position, heading, speed, yaw rate and
    /// acceleration) on speed and inertial lines: the estimators are those of a
    /// fixed_beacon world.
    #[serde(rename = "unicycle")]
    Unicycle,
}

impl VehicleModel {
    /// The host whose estimator vocabulary applies.
    pub fn host(self) -> Host {
        match self {
            VehicleModel::Planar => Host::Log,
            VehicleModel::Kinematic6Dof => Host::MovingBeacon,
            VehicleModel::Unicycle => Host::FixedBeacon,
        }
    }

    /// Its `model` key's value.
    pub fn label(self) -> &'static str {
        match self {
            VehicleModel::Planar => "planar",
            VehicleModel::Kinematic6Dof => "6dof",
            VehicleModel::Unicycle => "unicycle",
        }
    }

    pub fn is_planar(&self) -> bool {
        *self == VehicleModel::Planar
    }
}

/// What a log's or a stream's estimators start from besides their pose: for a USBL
/// tracker (hoff2024's state order) depth, pitch, speed and the two rate biases (m, rad,
/// m/s, rad/s) and the standard deviations of depth, pitch, speed and biases; for the
/// 6-DOF filter depth, pitch and `roll_rad` with the depth's and pitch's standard
/// deviations (the roll's is the pitch's); for the unicycle the speed (the tracker's),
/// `yaw_rate_accel` (rad/s, m/s^2) and the standard deviations of the three; and the
/// seed of the vehicle's particle filters.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct TrackerStart {
    pub state: [f64; 5],
    pub sigma: [f64; 4],
    pub roll_rad: f64,
    pub yaw_rate_accel: [f64; 2],
    pub yaw_rate_accel_sigma: [f64; 2],
    pub seed: Option<i64>,
}

impl EstimatorSpec {
    /// Whether the navigator [`EstimatorSpec::builder`] makes for `model` gives
    /// `capability`: the iUSBL navigator its beacon-relative position, the 6-DOF filter
    /// its body velocity.
    pub fn provides(&self, capability: Capability, model: VehicleModel) -> bool {
        match capability {
            Capability::BeaconRelative => model.is_planar() && self.kind.iusbl(),
            Capability::BodyVelocity => model == VehicleModel::Kinematic6Dof,
        }
    }

    /// The estimator on a vehicle whose estimators start as `start` says, built by the
    /// session (or the simulator's track) at its start and again from its last sound
    /// pose: a USBL tracker (pf, bearing: hoff2024's eight states), the iUSBL navigator
    /// (which starts from its first fix), or the planar family; with `model` 6dof, sousa's
    /// filter, with `model` unicycle garin2024's. The one place navigators are built from
    /// specs, for logs, streams and every world of the simulator; the noise a spec does not
    /// give is [`TrackerNoise::default`] and [`SensorNoise::default`] (a world writes its
    /// own into the specs).
    pub fn builder(&self, start: TrackerStart, model: VehicleModel) -> Builder {
        match model {
            VehicleModel::Kinematic6Dof => return self.range_6dof_builder(start),
            VehicleModel::Unicycle => return self.unicycle_builder(start),
            VehicleModel::Planar => {}
        }
        // the seed's 64 bits (TOML integers are signed)
        let seed = self.seed.or(start.seed).unwrap_or(0) as u64;
        if self.kind.tracks_bearings() {
            let [depth, pitch, speed, pitch_bias, heading_bias] = start.state;
            let [s_depth, s_pitch, s_speed, s_bias] = start.sigma;
            // the pose and its sigmas are the builder's arguments
            let x0 = SVector::<f64, DIM>::from([0.0, 0.0, depth, pitch, 0.0, speed, pitch_bias, heading_bias]);
            let sigma0 = SVector::<f64, DIM>::from([0.0, 0.0, s_depth, s_pitch, 0.0, s_speed, s_bias, s_bias]);
            return self.tracker_builder(x0, sigma0, seed);
        }
        if self.kind.iusbl() {
            let config = self.iusbl.clone().unwrap_or_default().config(self.kind == EstimatorKind::Iusbl);
            return Box::new(move |_, _, _, _| Box::new(IusblNavigator::new(config, None, seed)));
        }
        crate::nav::planar::builder(self.planar_config(), self.filter_kind())
    }

    /// sousa's 6-DOF filter (range-ekf, dead-reckoning, with the calibration states asked
    /// for), starting from `start` (depth, roll, pitch), its pose (north, east, heading)
    /// and their sigmas the builder's arguments.
    fn range_6dof_builder(&self, start: TrackerStart) -> Builder {
        let noise = self.sensor_noise(SensorNoise::default());
        let (aiding, filter) = (self.aiding(Host::MovingBeacon), self.filter_kind());
        let (calibration, gate) = (self.range_calibration(), self.gate());
        let [depth, pitch, ..] = start.state;
        let [s_depth, s_attitude, ..] = start.sigma;
        Box::new(move |t0, (north, east, heading), s_position, s_heading| {
            let eta = Eta::from([north, east, depth, start.roll_rad, pitch, heading]);
            let sigma = Eta::from([s_position, s_position, s_depth, s_attitude, s_attitude, s_heading]);
            let p0 = Cov6::from_diagonal(&sigma.component_mul(&sigma));
            range_6dof::boxed(noise, aiding, filter, t0, (eta, p0), calibration, gate)
        })
    }

    /// garin2024's single-beacon filter (its kind's acoustic measurements, eq. 25's
    /// tuning where a key is absent, the calibration states asked for, its guards),
    /// starting from `start` (speed, yaw rate, acceleration and their sigmas), its pose
    /// and their sigmas the builder's arguments.
    fn unicycle_builder(&self, start: TrackerStart) -> Builder {
        let (aiding, tuning, filter) = (self.aiding(Host::FixedBeacon), self.ekf_tuning(), self.filter_kind());
        let (gate, robust) = self.gate();
        let guards = Guards {
            min_speed_m_s: self.unicycle.min_speed_m_s,
            mirror: self.unicycle.mirror_recovery.unwrap_or(true),
            gate,
            robust,
        };
        let calibration = self.range_calibration();
        let ([_, _, speed, ..], [_, _, s_speed, _]) = (start.state, start.sigma);
        let ([yaw_rate, accel], [s_yaw_rate, s_accel]) = (start.yaw_rate_accel, start.yaw_rate_accel_sigma);
        Box::new(move |t0, (north, east, heading), s_position, s_heading| {
            let z = UnicycleState::from([north, east, heading, speed, yaw_rate, accel]);
            let sigma = UnicycleState::from([s_position, s_position, s_heading, s_speed, s_yaw_rate, s_accel]);
            let p0 = UnicycleCov::from_diagonal(&sigma.component_mul(&sigma));
            single_beacon::boxed(aiding, tuning, filter, t0, (z, p0), calibration, guards)
        })
    }

    /// A USBL tracker (kinds pf and bearing: hoff2024's eight states) starting from `x0`
    /// with standard deviations `sigma0`, their pose (north, east, heading) and its
    /// sigmas the builder's arguments; `seed` seeds a particle filter.
    fn tracker_builder(&self, x0: SVector<f64, DIM>, sigma0: SVector<f64, DIM>, seed: u64) -> Builder {
        let (config, filter) = (self.tracker_config(TrackerNoise::default()), self.filter_kind());
        let particle = (self.kind == EstimatorKind::Particle).then(|| self.particle_settings());
        Box::new(move |t0, (north, east, heading), sigma_position, sigma_heading| {
            let (mut x, mut sigma) = (x0, sigma0);
            (x[idx::X], x[idx::Y], x[idx::PSI]) = (north, east, heading);
            (sigma[idx::X], sigma[idx::Y], sigma[idx::PSI]) = (sigma_position, sigma_position, sigma_heading);
            match particle {
                Some((n, settings)) => Box::new(ParticleTracker::new(config, settings, n, t0, &x, &sigma, seed)),
                None => Box::new(GaussianTracker::new(config, filter, t0, &x, &sigma)),
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each kind's navigator hands out the capabilities its type has and no other (the
    /// table is read from the navigators' docs: particles for the two particle filters,
    /// factored sets for the factored one only, held-out weighing for the Gaussian range
    /// family, smoothing for it with beacon aiding, offsets only when asked for), and
    /// the controller capabilities agree with what [`EstimatorSpec::provides`] says at
    /// configuration.
    #[test]
    fn each_navigator_hands_out_the_capabilities_of_its_kind() {
        use EstimatorKind::*;
        let start =
            TrackerStart { state: [10.0, 0.0, 1.5, 0.0, 0.0], sigma: [1.0, 0.1, 0.2, 0.01], ..Default::default() };
        // kind, model, offsets, then particles, factored, weighing, smoothing, offsets
        let table = [
            (RangeDoppler, VehicleModel::Planar, false, [false, false, true, true, false]),
            (Rosb, VehicleModel::Planar, true, [false, false, true, true, true]),
            (DeadReckoning, VehicleModel::Planar, false, [false, false, true, false, false]),
            (Particle, VehicleModel::Planar, false, [true, false, false, false, false]),
            (Bearing, VehicleModel::Planar, false, [false, false, false, false, false]),
            (Iusbl, VehicleModel::Planar, false, [true, true, false, false, false]),
            (IusblJoint, VehicleModel::Planar, false, [true, false, false, false, false]),
            (RangeEkf, VehicleModel::Kinematic6Dof, false, [false, false, false, false, false]),
        ];
        for (kind, model, offsets, want) in table {
            let mut spec = EstimatorSpec::new(kind);
            spec.calibration.estimate_beacon_offsets = Some(offsets);
            let mut nav = spec.builder(start, model)(0.0, (0.0, 0.0, 0.0), 1.0, 0.1);
            let got = [
                nav.particles().is_some(),
                nav.factored().is_some(),
                nav.weighing().is_some(),
                nav.smoothing().is_some(),
                nav.beacon_offsets().is_some(),
            ];
            assert_eq!(got, want, "{} ({model:?})", kind.label());
            for (capability, has) in [
                (Capability::BeaconRelative, nav.beacon_relative().is_some()),
                (Capability::BodyVelocity, nav.body_velocity().is_some()),
            ] {
                assert_eq!(spec.provides(capability, model), has, "{} ({model:?}): {capability:?}", kind.label());
            }
        }
    }
}
