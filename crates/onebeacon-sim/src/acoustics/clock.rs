//! Clocks that are not perfect: each beacon's and each vehicle's clock reads the true time
//! plus an offset left by the last synchronisation, a rate error (drift, constant in a
//! run) and a random walk. A one-way travel time is read between two clocks, the
//! transmitter's at transmission and the receiver's at reception, so their difference
//! is a range error: 1 ppm of drift apart is 3.6 ms, 5.4 m at 1500 m/s, after an hour.

use crate::seed::gauss;
use rand_pcg::Pcg64Mcg;
use serde::{Deserialize, Serialize};

/// The errors each clock draws (`[sea.clocks]`, all zero: perfect clocks).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ClockErrors {
    /// Standard deviation of a clock's offset at the start (after synchronisation), s.
    pub offset_sigma_s: f64,
    /// Standard deviation of a clock's rate error, ppm (1e-6 s per s), constant in a run.
    pub drift_sigma_ppm: f64,
    /// A clock's random walk, s per sqrt(s) (the phase noise left after the drift).
    pub walk_s_per_sqrt_s: f64,
}

/// One clock of one run.
#[derive(Debug, Clone)]
pub struct Clock {
    offset_s: f64,
    drift: f64,
    walk_sigma: f64,
    walk_s: f64,
    last_t_s: f64,
    rng: Pcg64Mcg,
}

impl Clock {
    /// A clock drawing its offset and drift, then its walk, from `rng` (a stream of its
    /// own, so that perfect clocks change no other draw).
    pub fn new(errors: &ClockErrors, mut rng: Pcg64Mcg) -> Self {
        let offset_s = gauss(&mut rng, errors.offset_sigma_s);
        let drift = gauss(&mut rng, errors.drift_sigma_ppm * 1e-6);
        Self { offset_s, drift, walk_sigma: errors.walk_s_per_sqrt_s, walk_s: 0.0, last_t_s: 0.0, rng }
    }

    /// What the clock reads minus the true time `t_s`, s. The walk steps forward to each
    /// later time asked; an earlier time reads the walk where it is.
    pub fn error_s(&mut self, t_s: f64) -> f64 {
        if t_s > self.last_t_s {
            if self.walk_sigma > 0.0 {
                self.walk_s += gauss(&mut self.rng, self.walk_sigma * (t_s - self.last_t_s).sqrt());
            }
            self.last_t_s = t_s;
        }
        self.offset_s + self.drift * t_s + self.walk_s
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    fn clock(errors: ClockErrors, seed: u64) -> Clock {
        Clock::new(&errors, Pcg64Mcg::seed_from_u64(seed))
    }

    /// Perfect clocks read the truth exactly; a drifting one's error is a straight line
    /// through its offset.
    #[test]
    fn perfect_and_drifting_clocks() {
        let mut perfect = clock(ClockErrors::default(), 1);
        assert!([0.0, 10.0, 3600.0].iter().all(|&t| perfect.error_s(t) == 0.0));
        let mut c = clock(ClockErrors { offset_sigma_s: 1e-3, drift_sigma_ppm: 1.0, walk_s_per_sqrt_s: 0.0 }, 2);
        let (e0, e1, e2) = (c.error_s(0.0), c.error_s(1800.0), c.error_s(3600.0));
        assert!(e0 != 0.0 && e2 != e0);
        assert!((e2 - e0 - 2.0 * (e1 - e0)).abs() < 1e-15, "{e0} {e1} {e2}");
    }

    /// The spread of drift and walk over 4000 clocks against the closed forms: the
    /// variance at t is (drift t)^2 + walk^2 t; the sample variance's relative standard
    /// error is sqrt(2 / 4000) = 2.2 %, the tolerance five of them.
    #[test]
    fn the_spread_of_many_clocks() {
        let n = 4000;
        let spread = |errors: ClockErrors, t: f64| {
            let e: Vec<f64> = (0..n).map(|k| clock(errors, 100 + k).error_s(t)).collect();
            e.iter().map(|x| x * x).sum::<f64>() / n as f64
        };
        let drift = ClockErrors { drift_sigma_ppm: 2.0, ..Default::default() };
        let expected = (2e-6 * 3600.0f64).powi(2);
        assert!((spread(drift, 3600.0) / expected - 1.0).abs() < 0.11, "drift");
        let walk = ClockErrors { walk_s_per_sqrt_s: 1e-5, ..Default::default() };
        let mut clocks: Vec<Clock> = (0..n).map(|k| clock(walk, 9000 + k)).collect();
        // stepping through 100 times gives the same spread as one step
        let mut last = vec![0.0; n as usize];
        for t in 1..=100 {
            for (c, e) in clocks.iter_mut().zip(&mut last) {
                *e = c.error_s(f64::from(t) * 36.0);
            }
        }
        let var = last.iter().map(|x| x * x).sum::<f64>() / n as f64;
        assert!((var / (1e-10 * 3600.0) - 1.0).abs() < 0.11, "walk {var}");
    }
}
