//! Lost messages from the gaps in what was heard: where a beacon's ranges come on a
//! schedule (nine in ten gaps within 5 % of a whole number of its median gap), a gap of
//! m periods is m - 1 messages lost, and the heard / lost sequence gives the counts of
//! the two-state chain of `acoustics::link` (entering and staying in the lost state),
//! whose maximum-likelihood probabilities are the shares of those transitions. The loss
//! share and the mean burst follow (as `LinkErrors::loss_chain` inverts them), their
//! intervals by the delta method on two binomial proportions.

use super::ranges::Value;

/// The chain's transition counts: heard -> heard, heard -> lost, lost -> lost,
/// lost -> heard.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Transitions {
    pub hh: u64,
    pub hl: u64,
    pub ll: u64,
    pub lh: u64,
}

impl std::ops::AddAssign for Transitions {
    fn add_assign(&mut self, o: Self) {
        (self.hh, self.hl, self.ll, self.lh) = (self.hh + o.hh, self.hl + o.hl, self.ll + o.ll, self.lh + o.lh);
    }
}

/// The loss share and mean burst of a chain's counts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LossFit {
    pub period_s: Option<f64>,
    pub counts: Transitions,
    pub loss_prob: Value,
    pub loss_burst_mean: Value,
}

/// The schedule's period of `times` (sorted), or None when they come on none.
pub(crate) fn period(times: &[f64]) -> Option<f64> {
    let mut gaps: Vec<f64> = times.windows(2).map(|w| w[1] - w[0]).filter(|g| *g > 0.0).collect();
    if gaps.len() < 10 {
        return None;
    }
    gaps.sort_by(f64::total_cmp);
    let p = gaps[gaps.len() / 2];
    let on = gaps.iter().filter(|g| ((*g / p) - (*g / p).round()).abs() < 0.05).count();
    (on * 10 >= gaps.len() * 9).then_some(p)
}

/// The transitions of `times` (sorted) heard on a schedule of `period_s`.
pub(crate) fn transitions(times: &[f64], period_s: f64) -> Transitions {
    let mut c = Transitions::default();
    for w in times.windows(2) {
        let m = ((w[1] - w[0]) / period_s).round().max(1.0) as u64;
        if m == 1 {
            c.hh += 1;
        } else {
            c.hl += 1;
            c.ll += m - 2;
            c.lh += 1;
        }
    }
    c
}

/// The loss share and burst of counts `c` (None: nothing lost, or nothing heard).
pub(crate) fn fit(c: Transitions, period_s: Option<f64>) -> Option<LossFit> {
    let (nh, nl) = ((c.hh + c.hl) as f64, (c.ll + c.lh) as f64);
    if nh == 0.0 || nl == 0.0 {
        return None;
    }
    let (enter, stay) = (c.hl as f64 / nh, c.ll as f64 / nl);
    let (var_e, var_s) = (enter * (1.0 - enter) / nh, stay * (1.0 - stay) / nl);
    // p = enter / (enter + 1 - stay): its stationary share; L = 1 / (1 - stay)
    let q = enter + 1.0 - stay;
    let p = enter / q;
    let (dp_de, dp_ds) = ((1.0 - stay) / (q * q), enter / (q * q));
    let sd_p = (dp_de * dp_de * var_e + dp_ds * dp_ds * var_s).sqrt();
    let burst = 1.0 / (1.0 - stay);
    let sd_b = burst * burst * var_s.sqrt();
    // within what each may be: a share in [0, 1], a mean run of at least 1
    let value = |v: f64, sd: f64, (least, most): (f64, f64)| Value {
        value: v,
        interval: (sd > 0.0).then(|| [(v - 1.96 * sd).max(least), (v + 1.96 * sd).min(most)]),
    };
    Some(LossFit {
        period_s,
        counts: c,
        loss_prob: value(p, sd_p, (0.0, 1.0)),
        loss_burst_mean: value(burst, sd_b, (1.0, f64::INFINITY)),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::acoustics::link::{Link, LinkErrors};
    use rand::SeedableRng;

    /// The simulator's own chain (`acoustics::link`), 20 000 messages a second apart
    /// with a jitter of 10 ms: the schedule is found, and the fitted share and burst
    /// lie within 4 of their standard deviations of the truth (a bound that fails once
    /// in 15 000 draws).
    #[test]
    fn the_simulators_loss_chain_is_fitted_back() {
        let errors = LinkErrors { loss_prob: 0.2, loss_burst_mean: Some(3.0), ..LinkErrors::default() };
        let mut link = Link::new(&errors, rand_pcg::Pcg64Mcg::seed_from_u64(7));
        let times: Vec<f64> = (0..20_000)
            .filter(|_| link.hear(1.0).is_some())
            .map(|i| i as f64 + 0.01 * ((i * 37 % 11) as f64 / 10.0 - 0.5))
            .collect();
        let p = period(&times).expect("a schedule");
        assert!((p - 1.0).abs() < 0.011, "{p}");
        let f = fit(transitions(&times, p), Some(p)).unwrap();
        let within = |v: Value, truth: f64| {
            let [lo, hi] = v.interval.unwrap();
            (v.value - truth).abs() < 4.0 * (hi - lo) / (2.0 * 1.96)
        };
        assert!(within(f.loss_prob, 0.2), "{:?}", f.loss_prob);
        assert!(within(f.loss_burst_mean, 3.0), "{:?}", f.loss_burst_mean);
        // a log without a schedule
        let irregular: Vec<f64> = (0..100).map(|i| (i as f64).powf(1.3)).collect();
        assert_eq!(period(&irregular), None);
    }
}
