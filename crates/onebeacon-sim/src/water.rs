//! The water's current (`[current]` of a passive_usbl world, `[sea.current]` of the
//! fixed_beacon and fleet worlds): a mean speed and direction, each wandering about its
//! mean as a first-order Gauss-Markov process. It carries the vehicles over ground while
//! their speed sensors (a propeller's RPM, an accelerometer) measure through the water;
//! the filters are not told.

use crate::seed::gauss;
use nalgebra::Vector3;
use rand_pcg::Pcg64Mcg;
use serde::{Deserialize, Serialize};

/// A current constant in the water column, or slowly varying: its speed and direction
/// each a first-order Gauss-Markov process about their means.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Current {
    pub speed_m_s: f64,
    /// The direction it flows toward, deg from north.
    pub toward_deg: f64,
    /// Stationary standard deviations of the speed and the direction about their means,
    /// and their correlation time.
    pub speed_sigma_m_s: f64,
    pub direction_sigma_deg: f64,
    pub time_constant_s: f64,
}

impl Default for Current {
    fn default() -> Self {
        Self {
            speed_m_s: 0.0,
            toward_deg: 0.0,
            speed_sigma_m_s: 0.0,
            direction_sigma_deg: 0.0,
            time_constant_s: 1800.0,
        }
    }
}

impl Current {
    /// Whether there is any.
    pub fn flows(&self) -> bool {
        self.speed_m_s > 0.0 || self.speed_sigma_m_s > 0.0
    }
}

/// The current of one run: its speed and direction, each drifting as a first-order
/// Gauss-Markov process about its mean.
pub struct Water {
    spec: Current,
    speed_dev: f64,
    direction_dev: f64,
    rng: Pcg64Mcg,
}

impl Water {
    pub fn new(spec: Current, mut rng: Pcg64Mcg) -> Self {
        let speed_dev = gauss(&mut rng, spec.speed_sigma_m_s);
        let direction_dev = gauss(&mut rng, spec.direction_sigma_deg.to_radians());
        Self { spec, speed_dev, direction_dev, rng }
    }

    pub fn ned(&self) -> Vector3<f64> {
        let dir = self.spec.toward_deg.to_radians() + self.direction_dev;
        let speed = (self.spec.speed_m_s + self.speed_dev).max(0.0);
        Vector3::new(dir.cos(), dir.sin(), 0.0) * speed
    }

    /// The current now, then drifted over the step of `dt` s that it acts on.
    pub fn step(&mut self, dt: f64) -> Vector3<f64> {
        let now = self.ned();
        self.drift(dt);
        now
    }

    /// Drifts over `dt` s (exact discretisation of the first-order process).
    pub fn drift(&mut self, dt: f64) {
        let a = (-dt / self.spec.time_constant_s).exp();
        let b = (1.0 - a * a).sqrt();
        self.speed_dev = a * self.speed_dev + gauss(&mut self.rng, b * self.spec.speed_sigma_m_s);
        self.direction_dev =
            a * self.direction_dev + gauss(&mut self.rng, b * self.spec.direction_sigma_deg.to_radians());
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The current's slow variation: the speed's deviation from its mean, sampled every
    /// 4 s over 4e5 s, has the stationary standard deviation asked for (within 5 %) and
    /// the first-order process's autocorrelation exp(-lag / T) at one correlation time
    /// (within 0.05).
    #[test]
    fn the_current_varies_as_a_gauss_markov_process() {
        let spec = Current {
            speed_m_s: 0.3,
            speed_sigma_m_s: 0.1,
            direction_sigma_deg: 10.0,
            time_constant_s: 400.0,
            ..Default::default()
        };
        let mut w = Water::new(spec, crate::seed::rng(1, 0, crate::seed::Stream::Current));
        let x: Vec<f64> = (0..100_000)
            .map(|_| {
                w.drift(4.0);
                w.speed_dev
            })
            .collect();
        let var = x.iter().map(|v| v * v).sum::<f64>() / x.len() as f64;
        let lag = 100; // 400 s
        let cov = x.windows(lag + 1).map(|p| p[0] * p[lag]).sum::<f64>() / (x.len() - lag) as f64;
        assert!((var.sqrt() / 0.1 - 1.0).abs() < 0.05, "{}", var.sqrt());
        assert!((cov / var - (-1.0f64).exp()).abs() < 0.05, "{}", cov / var);
    }
}
