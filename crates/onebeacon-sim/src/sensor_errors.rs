//! A vehicle's navigation sensors as they drift (`[sea.sensors]`): a heading bias that
//! wanders as a first-order Gauss-Markov process, a compass's one-cycle deviation (an
//! error that depends on the heading, as a hard-iron residual's does), a speed scale
//! factor (a DVL's or a speed log's calibration, drawn once a run) and dropouts of the
//! speed sensor (bottom lock lost), during which the vehicle keeps the last velocity it
//! measured; and a wheel or pose-graph odometry's scales and noise (`[sea.odometry]`, a
//! log's twin only).

use crate::seed::gauss;
use rand::RngExt;
use rand_pcg::Pcg64Mcg;
use serde::{Deserialize, Serialize};

/// `[sea.sensors]` (all zero: sensors with white noise only).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SensorErrors {
    /// The heading bias's stationary standard deviation, deg, and its correlation
    /// time, s.
    pub heading_bias_sigma_deg: f64,
    pub heading_bias_time_constant_s: f64,
    /// A compass's one-cycle deviation, deg: the heading reads a sin(psi + phi) off at a
    /// true heading psi, amplitude a, the phase phi drawn once a run (uniform). Bowditch,
    /// The American Practical Navigator (NGA Pub. 9), ch. 6: deviation = A + B sin(psi) + C
    /// cos(psi) + D sin(2 psi) + E cos(2 psi); this is its hard-iron part, B and C, with a =
    /// sqrt(B^2 + C^2). Unlike a bias it does not cancel on a closed track: circling at
    /// speed v it moves dead reckoning by v a / 2.
    pub heading_deviation_deg: f64,
    /// The speed scale factor's standard deviation (0.01: 1 %), drawn once a run.
    pub speed_scale_sigma: f64,
    /// The share of time the speed sensor is out, and the mean length of an outage, s.
    pub speed_dropout_prob: f64,
    pub speed_dropout_mean_s: f64,
}

impl Default for SensorErrors {
    fn default() -> Self {
        Self {
            heading_bias_sigma_deg: 0.0,
            heading_bias_time_constant_s: 600.0,
            heading_deviation_deg: 0.0,
            speed_scale_sigma: 0.0,
            speed_dropout_prob: 0.0,
            speed_dropout_mean_s: 30.0,
        }
    }
}

/// One vehicle's sensors over a run, sampled at increasing times.
#[derive(Debug, Clone)]
pub struct DriftingSensors {
    errors: SensorErrors,
    heading_bias_rad: f64,
    deviation_phase_rad: f64,
    speed_scale: f64,
    out: bool,
    held: Option<[f64; 3]>,
    last_t_s: Option<f64>,
    rng: Pcg64Mcg,
}

impl DriftingSensors {
    /// The sensors of `errors`, drawing from `rng` (a stream of their own): the bias
    /// starts from its stationary distribution, the scale and the deviation's phase are
    /// drawn once (the phase only with a deviation: without one the draws are as before it).
    pub fn new(errors: &SensorErrors, mut rng: Pcg64Mcg) -> Self {
        let heading_bias_rad = gauss(&mut rng, errors.heading_bias_sigma_deg.to_radians());
        let speed_scale = 1.0 + gauss(&mut rng, errors.speed_scale_sigma);
        let deviation_phase_rad =
            if errors.heading_deviation_deg > 0.0 { rng.random::<f64>() * std::f64::consts::TAU } else { 0.0 };
        Self {
            errors: *errors,
            heading_bias_rad,
            deviation_phase_rad,
            speed_scale,
            out: false,
            held: None,
            last_t_s: None,
            rng,
        }
    }

    /// Moves the errors on to `t_s`: the bias by its exact discretisation, b <- a b +
    /// sqrt(1 - a^2) sigma w with a = exp(-dt / tau); the outage state by a two-state
    /// chain in continuous time (rates 1 / mean out of an outage, p / ((1 - p) mean)
    /// into one), stepped exactly over dt.
    fn advance(&mut self, t_s: f64) {
        let dt = self.last_t_s.map_or(0.0, |t0| (t_s - t0).max(0.0));
        self.last_t_s = Some(t_s);
        if dt <= 0.0 {
            return;
        }
        let e = &self.errors;
        if e.heading_bias_sigma_deg > 0.0 {
            let a = (-dt / e.heading_bias_time_constant_s).exp();
            self.heading_bias_rad = a * self.heading_bias_rad
                + gauss(&mut self.rng, (1.0 - a * a).sqrt() * e.heading_bias_sigma_deg.to_radians());
        }
        if e.speed_dropout_prob > 0.0 {
            let leave = 1.0 / e.speed_dropout_mean_s;
            let enter = e.speed_dropout_prob * leave / (1.0 - e.speed_dropout_prob);
            // the probability of being out at t + dt given the state at t
            let settle = (-(enter + leave) * dt).exp();
            let stationary = e.speed_dropout_prob;
            let p_out = if self.out { stationary + (1.0 - stationary) * settle } else { stationary * (1.0 - settle) };
            self.out = self.rng.random::<f64>() < p_out;
        }
    }

    /// The heading the sensor reads at `t_s` for a true `heading_rad` (before its white
    /// noise).
    pub fn heading(&mut self, t_s: f64, heading_rad: f64) -> f64 {
        self.advance(t_s);
        let deviation = self.errors.heading_deviation_deg.to_radians() * (heading_rad + self.deviation_phase_rad).sin();
        heading_rad + self.heading_bias_rad + deviation
    }

    /// The speed the sensor reads at `t_s` for a measured `speed_m_s` (the true speed
    /// with its white noise): scaled, or the last one read while the sensor is out.
    pub fn speed(&mut self, t_s: f64, speed_m_s: f64) -> f64 {
        self.velocity(t_s, [speed_m_s, 0.0, 0.0])[0]
    }

    /// The same for a velocity sensor's three linear components (a DVL's u, v, w): one
    /// scale on all, all held while it is out.
    pub fn velocity(&mut self, t_s: f64, v: [f64; 3]) -> [f64; 3] {
        self.advance(t_s);
        if self.out
            && let Some(held) = self.held
        {
            return held;
        }
        let read = v.map(|c| self.speed_scale * c);
        self.held = Some(read);
        read
    }
}

/// `[sea.odometry]`: a row of odometry reads (1 + scale) times the true distance and
/// turn, plus white noise whose variance grows with the distance (distance) and the time
/// (turn) the row spans: a heading random walk.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct OdometryErrors {
    pub distance_scale: f64,
    pub turn_scale: f64,
    pub distance_sigma_m_per_sqrt_m: f64,
    pub turn_sigma_deg_per_sqrt_s: f64,
}

impl OdometryErrors {
    /// A row's distance and turn from the true ones over `dt_s`.
    pub(crate) fn read(&self, distance_m: f64, turn_rad: f64, dt_s: f64, rng: &mut Pcg64Mcg) -> (f64, f64) {
        let d =
            (1.0 + self.distance_scale) * distance_m + gauss(rng, self.distance_sigma_m_per_sqrt_m * distance_m.sqrt());
        let sigma_turn = self.turn_sigma_deg_per_sqrt_s.to_radians() * dt_s.max(0.0).sqrt();
        (d.max(0.0), (1.0 + self.turn_scale) * turn_rad + gauss(rng, sigma_turn))
    }

    pub(crate) fn check(&self) -> Result<(), String> {
        for (key, v, lo, hi) in [
            ("distance_scale", self.distance_scale, -0.5, 0.5),
            ("turn_scale", self.turn_scale, -0.5, 0.5),
            ("distance_sigma_m_per_sqrt_m", self.distance_sigma_m_per_sqrt_m, 0.0, 10.0),
            ("turn_sigma_deg_per_sqrt_s", self.turn_sigma_deg_per_sqrt_s, 0.0, 90.0),
        ] {
            if !(lo..=hi).contains(&v) {
                return Err(format!("sea.odometry.{key} = {v:?}: allowed from {lo} to {hi}"));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    /// Over 2e5 samples 10 s apart: the bias's standard deviation and its correlation
    /// at one time constant (exp(-1)) within 5 %; the share of time out and the mean
    /// outage within 5 % (the chain's samples are correlated: 2e5 samples hold some
    /// 2e4 outages); the scale's spread over 4000 runs within 5 %.
    #[test]
    fn drifts_and_outages_have_their_statistics() {
        let errors = SensorErrors {
            heading_bias_sigma_deg: 2.0,
            heading_bias_time_constant_s: 600.0,
            speed_scale_sigma: 0.01,
            speed_dropout_prob: 0.2,
            speed_dropout_mean_s: 30.0,
            ..SensorErrors::default()
        };
        let mut s = DriftingSensors::new(&errors, Pcg64Mcg::seed_from_u64(9));
        let n = 200_000;
        let (mut bias, mut out) = (Vec::with_capacity(n), Vec::with_capacity(n));
        for k in 0..n {
            let t = 10.0 * k as f64;
            bias.push(s.heading(t, 0.0).to_degrees());
            out.push(s.out);
        }
        let var = bias.iter().map(|b| b * b).sum::<f64>() / n as f64;
        let lag = 60;
        let cov = bias.windows(lag + 1).map(|w| w[0] * w[lag]).sum::<f64>() / (n - lag) as f64;
        assert!((var.sqrt() / 2.0 - 1.0).abs() < 0.05, "bias sigma {}", var.sqrt());
        assert!((cov / var - (-1.0f64).exp()).abs() < 0.05, "correlation {}", cov / var);
        let share = out.iter().filter(|o| **o).count() as f64 / n as f64;
        assert!((share / 0.2 - 1.0).abs() < 0.05, "out {share}");
        let outages = out.windows(2).filter(|w| !w[0] && w[1]).count() as f64;
        let mean_s = share * n as f64 * 10.0 / outages;
        // sampled every 10 s, an outage is seen as a run of samples out; the chain stays
        // out from one sample to the next with p + (1 - p) exp(-(enter + leave) 10 s),
        // leave = 1 / 30 s and enter + leave = leave / (1 - p): a mean run of 36.7 s
        let stay = 0.2 + 0.8 * (-10.0 / (30.0 * 0.8f64)).exp();
        let seen = 10.0 / (1.0 - stay);
        assert!((mean_s / seen - 1.0).abs() < 0.05, "outage {mean_s} s against {seen}");
        let scales: Vec<f64> = (0..4000)
            .map(|k| DriftingSensors::new(&errors, Pcg64Mcg::seed_from_u64(k)).speed(0.0, 1.0) - 1.0)
            .collect();
        let sd = (scales.iter().map(|x| x * x).sum::<f64>() / 4000.0).sqrt();
        assert!((sd / 0.01 - 1.0).abs() < 0.05, "scale sigma {sd}");
    }

    /// Out, the sensor holds the last speed it read; back, it reads again.
    #[test]
    fn an_outage_holds_the_last_speed() {
        let errors = SensorErrors { speed_dropout_prob: 0.5, speed_dropout_mean_s: 20.0, ..SensorErrors::default() };
        let mut s = DriftingSensors::new(&errors, Pcg64Mcg::seed_from_u64(1));
        let mut last = None;
        let mut held = 0;
        for k in 0..2000 {
            let truth = 1.0 + 0.001 * k as f64;
            let read = s.speed(k as f64, truth);
            if s.out && last.is_some() {
                assert_eq!(Some(read), last);
                held += 1;
            } else {
                assert_eq!(read, truth);
            }
            last = Some(read);
        }
        assert!(held > 500, "{held} held");
    }

    /// A one-cycle deviation D sin(psi + phi): dead reckoning on the heading it reads, a
    /// vehicle circling at v = 1 m/s drifts by v D / 2 per unit time (to first order in D;
    /// the second-order term, D^2 / 8 of v, is 1e-4 m/s at 3 deg), toward a direction set by
    /// the phase; a constant bias of the same size drifts by nothing over whole laps. Over
    /// 10 laps of 100 s each, at 3 deg: within 1 % of v D / 2.
    #[test]
    fn a_deviation_drifts_a_circling_dead_reckoning_by_half_its_amplitude() {
        let drift = |errors: SensorErrors, seed: u64| {
            let mut s = DriftingSensors::new(&errors, Pcg64Mcg::seed_from_u64(seed));
            let (dt, lap_s, laps) = (0.01, 100.0, 10);
            let n = (laps as f64 * lap_s / dt) as usize;
            let (mut north, mut east) = (0.0, 0.0);
            for k in 0..n {
                let t = k as f64 * dt;
                let psi = std::f64::consts::TAU * (t + 0.5 * dt) / lap_s;
                let read = s.heading(t, psi);
                north += (read.cos() - psi.cos()) * dt;
                east += (read.sin() - psi.sin()) * dt;
            }
            f64::hypot(north, east) / (n as f64 * dt)
        };
        let d = 3.0f64;
        for seed in 0..4 {
            let rate = drift(SensorErrors { heading_deviation_deg: d, ..SensorErrors::default() }, seed);
            let expected = d.to_radians() / 2.0;
            assert!((rate / expected - 1.0).abs() < 0.01, "seed {seed}: {rate} m/s against {expected}");
        }
        let biased =
            SensorErrors { heading_bias_sigma_deg: d, heading_bias_time_constant_s: 1e7, ..SensorErrors::default() };
        assert!(drift(biased, 1) < 1e-3, "a constant bias drifts by {}", drift(biased, 1));
    }
}
