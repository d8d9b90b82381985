//! What the acoustic link does to a message besides its Gaussian noise: it is lost,
//! alone or in bursts (a two-state Gilbert-Elliott chain), or its range is wrong: a
//! multipath arrival (a reflected path detected instead of the direct one, so the range
//! reads long by an exponential excess) or a false detection (noise or another
//! source's ping taken for the beacon's, a range anywhere up to a maximum).

use rand::RngExt;
use rand_distr::{Distribution, Exp};
use rand_pcg::Pcg64Mcg;
use serde::{Deserialize, Serialize};

/// The link's errors (`[sea.link]`, all zero: every message heard on its direct path).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LinkErrors {
    /// The share of messages lost, in the long run.
    pub loss_prob: f64,
    /// The mean length of a run of lost messages; `1 / (1 - loss_prob)` (the default,
    /// and the least) loses each message independently.
    pub loss_burst_mean: Option<f64>,
    /// The probability that a heard range is a multipath arrival, and its mean excess, m.
    pub multipath_prob: f64,
    pub multipath_excess_m: f64,
    /// The probability that a heard range is a false detection, uniform on
    /// [0, `false_max_range_m`].
    pub false_prob: f64,
    pub false_max_range_m: f64,
}

impl LinkErrors {
    /// The loss chain's probabilities of entering and of staying in the lost state.
    /// With stationary loss share p and mean burst L: staying is 1 - 1 / L and entering
    /// p / (L (1 - p)), so that the lost state's stationary share, enter / (enter + 1 /
    /// L), is p; L = 1 / (1 - p) makes both p (independent losses).
    fn loss_chain(&self) -> (f64, f64) {
        let p = self.loss_prob;
        if p <= 0.0 {
            return (0.0, 0.0);
        }
        let burst = self.loss_burst_mean.unwrap_or(1.0 / (1.0 - p));
        (p / (burst * (1.0 - p)), 1.0 - 1.0 / burst)
    }

    /// Whether the link changes anything.
    pub fn any(&self) -> bool {
        self.loss_prob > 0.0 || self.multipath_prob > 0.0 || self.false_prob > 0.0
    }
}

/// One receiver's link over one run.
#[derive(Debug, Clone)]
pub struct Link {
    errors: LinkErrors,
    enter: f64,
    stay: f64,
    lost: bool,
    rng: Pcg64Mcg,
}

impl Link {
    /// A link drawing from `rng` (a stream of its own, so that a clean link changes no
    /// other draw).
    pub fn new(errors: &LinkErrors, rng: Pcg64Mcg) -> Self {
        let (enter, stay) = errors.loss_chain();
        Self { errors: *errors, enter, stay, lost: false, rng }
    }

    /// How the next message arrives. Every message draws the same numbers, so that
    /// one's fate does not shift the next's.
    pub fn arrive(&mut self) -> Arrival {
        let e = &self.errors;
        if !e.any() {
            return Arrival::Direct;
        }
        let (u_loss, u_kind, u_false): (f64, f64, f64) = (self.rng.random(), self.rng.random(), self.rng.random());
        let excess = if e.multipath_excess_m > 0.0 {
            Exp::new(1.0 / e.multipath_excess_m).map_or(0.0, |d| d.sample(&mut self.rng))
        } else {
            0.0
        };
        self.lost = u_loss < if self.lost { self.stay } else { self.enter };
        if self.lost {
            Arrival::Lost
        } else if u_kind < e.false_prob {
            Arrival::False { u: u_false }
        } else if u_kind < e.false_prob + e.multipath_prob {
            Arrival::Multipath { excess_m: excess }
        } else {
            Arrival::Direct
        }
    }

    /// The range a message carrying `range_m` arrives with, or None when it is lost.
    pub fn hear(&mut self, range_m: f64) -> Option<f64> {
        match self.arrive() {
            Arrival::Lost => None,
            Arrival::Direct => Some(range_m),
            Arrival::Multipath { excess_m } => Some(range_m + excess_m),
            Arrival::False { u } => Some(u * self.errors.false_max_range_m),
        }
    }
}

/// How a message arrives.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Arrival {
    Lost,
    /// On its direct path.
    Direct,
    /// On a reflected path, this much longer.
    Multipath {
        excess_m: f64,
    },
    /// A false detection; `u` is uniform on [0, 1) (its place in the false range's or
    /// angle's span).
    False {
        u: f64,
    },
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    fn link(errors: LinkErrors) -> Link {
        Link::new(&errors, Pcg64Mcg::seed_from_u64(3))
    }

    /// Over 2e5 messages: the loss share, the mean burst, the outliers' shares and the
    /// multipath excess against the values asked (binomial and exponential standard
    /// errors, 5 of them).
    #[test]
    fn losses_and_outliers_come_as_asked() {
        let n = 200_000;
        for burst in [None, Some(4.0)] {
            let e = LinkErrors {
                loss_prob: 0.2,
                loss_burst_mean: burst,
                multipath_prob: 0.1,
                multipath_excess_m: 8.0,
                false_prob: 0.05,
                false_max_range_m: 500.0,
            };
            let mut l = link(e);
            let heard: Vec<Option<f64>> = (0..n).map(|_| l.hear(100.0)).collect();
            let lost = heard.iter().filter(|h| h.is_none()).count() as f64;
            // the share of a Markov chain's state: its standard error grows with the
            // burst length (variance factor (1 + rho) / (1 - rho), rho = stay - enter)
            let (enter, stay) = e.loss_chain();
            let rho = stay - enter;
            let se = (0.2 * 0.8 / n as f64 * (1.0 + rho) / (1.0 - rho)).sqrt();
            assert!((lost / n as f64 - 0.2).abs() < 5.0 * se, "{burst:?}: lost {}", lost / n as f64);
            let bursts = heard.windows(2).filter(|w| w[0].is_some() && w[1].is_none()).count() as f64;
            let mean_burst = lost / bursts;
            let expected = burst.unwrap_or(1.0 / 0.8);
            assert!((mean_burst - expected).abs() < 0.05 * expected, "{burst:?}: bursts of {mean_burst}");
            let got: Vec<f64> = heard.iter().flatten().copied().collect();
            let m = got.len() as f64;
            let share = |k: usize, p: f64| (k as f64 / m - p).abs() < 5.0 * (p * (1.0 - p) / m).sqrt();
            assert!(share(got.iter().filter(|r| **r == 100.0).count(), 0.85), "direct share");
            // a false range falls below the true 100 m with probability 100 / 500
            assert!(share(got.iter().filter(|r| **r < 100.0).count(), 0.05 * 0.2), "false share below 100 m");
        }
        let mut l = link(LinkErrors { multipath_prob: 1.0, multipath_excess_m: 8.0, ..LinkErrors::default() });
        let excess: f64 = (0..n).map(|_| l.hear(100.0).unwrap() - 100.0).sum::<f64>() / n as f64;
        assert!((excess - 8.0).abs() < 5.0 * 8.0 / (n as f64).sqrt(), "mean excess {excess}");
    }

    #[test]
    fn a_clean_link_draws_nothing() {
        let mut l = link(LinkErrors::default());
        assert_eq!(l.hear(42.0), Some(42.0));
        let mut fresh = Pcg64Mcg::seed_from_u64(3);
        assert_eq!(l.rng.random::<u64>(), fresh.random::<u64>());
    }
}
