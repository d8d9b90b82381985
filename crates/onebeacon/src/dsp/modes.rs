//! Command-mode identification (rypkema section 4.2): the capture is matched against a
//! bank of templates; the one with the largest response is this ping's mode; a mode is
//! confirmed after the same identification `confirmations` times in a row (3).

use super::Complex;
use super::matched_filter::MatchedFilter;
use std::ops::Range;

/// A bank of matched filters, one per mode.
#[derive(Debug)]
pub struct ModeBank {
    filters: Vec<MatchedFilter>,
    coherent: Option<Coherent>,
}

/// What coherent combination across elements needs: the array, the sound speed, each
/// template's centre frequency and the look directions tried.
#[derive(Debug)]
struct Coherent {
    /// `steer[t][look * M + m]` = exp(+j 2 pi fc_t tau_m(look)), tau_m = -r_m . u / c
    /// (M elements, each template's looks in one contiguous table).
    steer: Vec<Vec<Complex>>,
    elements: usize,
}

impl ModeBank {
    /// A bank of filters of one FFT length (equal template and capture lengths), so that
    /// every capture is transformed once.
    pub fn new(filters: Vec<MatchedFilter>) -> Self {
        assert!(filters.windows(2).all(|w| w[0].fft_len() == w[1].fft_len()), "filters of one FFT length");
        Self { filters, coherent: None }
    }

    /// A bank that, at its strongest candidate lags, also combines the elements
    /// coherently: the analytic outputs are phase-aligned at each template's centre
    /// frequency for look directions every 10 deg, and the best alignment is the
    /// response. Up to M times the power of one element where the incoherent sum gives
    /// about sqrt(M) in amplitude, so weak pings are told apart more often.
    pub fn with_array(
        filters: Vec<MatchedFilter>,
        centre_hz: Vec<f64>,
        elements: Vec<nalgebra::Vector3<f64>>,
        sound_speed_m_s: f64,
    ) -> Self {
        let looks = super::beamform::DirectionGrid::new(10f64.to_radians()).directions();
        let steer = centre_hz
            .iter()
            .map(|fc| {
                looks
                    .iter()
                    .flat_map(|u| {
                        elements.iter().map(move |r| {
                            Complex::from_polar(1.0, std::f64::consts::TAU * fc * (-r.dot(u) / sound_speed_m_s))
                        })
                    })
                    .collect()
            })
            .collect();
        Self { coherent: Some(Coherent { steer, elements: elements.len() }), ..Self::new(filters) }
    }

    /// The spectra of the captures, shared by every filter of the bank (and by a
    /// [`crate::dsp::receiver::Receiver`] of the same lengths).
    pub fn spectra(&self, captures: &[Vec<f64>]) -> Vec<Vec<Complex>> {
        let mut out = Vec::new();
        self.spectra_into(captures, &mut Vec::new(), &mut out);
        out
    }

    /// [`ModeBank::spectra`] into `out`, with `padded` as the work buffer (kept by the
    /// caller).
    pub fn spectra_into(&self, captures: &[Vec<f64>], padded: &mut Vec<f64>, out: &mut Vec<Vec<Complex>>) {
        let Some(f) = self.filters.first() else {
            out.clear();
            return;
        };
        out.resize_with(captures.len(), Vec::new);
        for (x, spectrum) in captures.iter().zip(out.iter_mut()) {
            f.spectrum_into(x, padded, spectrum);
        }
    }

    /// Each mode's response: the peak over the lags in `lags` of the sum over elements of
    /// the squared envelopes (build the bank with [`MatchedFilter::classical`] filters for
    /// a statistic comparable across templates). Lags beyond the capture are ignored.
    /// Computed on the decimated baseband correlation ([`MatchedFilter::baseband_of`]:
    /// the envelope at every d-th lag).
    pub fn responses(&self, spectra: &[Vec<Complex>], lags: Range<usize>) -> Vec<f64> {
        self.filters
            .iter()
            .enumerate()
            .map(|(t, f)| {
                let d = f.decimation();
                let outputs: Vec<Vec<Complex>> = spectra.iter().map(|x| f.baseband_of(x)).collect();
                let len = outputs.first().map_or(0, Vec::len);
                let lags = (lags.start / d).min(len)..lags.end.div_ceil(d).min(len);
                let mut sum = vec![0.0; len];
                for y in &outputs {
                    for (s, v) in sum.iter_mut().zip(y) {
                        *s += v.norm_sqr();
                    }
                }
                match &self.coherent {
                    None => sum[lags].iter().cloned().fold(0.0, f64::max),
                    Some(c) => c.best_alignment(&outputs, &sum, lags, &c.steer[t]),
                }
            })
            .collect()
    }

    /// The mode (index into the bank) with the largest response anywhere in the
    /// capture, from the spectra of the captures ([`ModeBank::spectra`]).
    pub fn identify(&self, spectra: &[Vec<Complex>]) -> usize {
        self.identify_within(spectra, 0..usize::MAX)
    }

    /// [`ModeBank::identify`] with the search gated to the lags `lags` (samples from the
    /// capture start), e.g. around the arrival the navigation filter predicts: fewer
    /// noise-only lags can outgrow the true peak (gating the search around the prediction buys dBs).
    pub fn identify_within(&self, spectra: &[Vec<Complex>], lags: Range<usize>) -> usize {
        super::matched_filter::argmax(&self.responses(spectra, lags))
    }
}

impl Coherent {
    /// The largest coherent power over the look directions at the 8 strongest local
    /// maxima of the incoherent sum within `lags`.
    fn best_alignment(&self, outputs: &[Vec<Complex>], sum: &[f64], lags: Range<usize>, steer: &[Complex]) -> f64 {
        let inner = lags.start.max(1)..lags.end.min(sum.len().saturating_sub(1));
        let mut peaks: Vec<usize> = inner.filter(|&n| sum[n] >= sum[n - 1] && sum[n] > sum[n + 1]).collect();
        peaks.sort_by(|a, b| sum[*b].total_cmp(&sum[*a]));
        peaks.truncate(8);
        let mut best = 0.0f64;
        let mut y = vec![Complex::new(0.0, 0.0); self.elements];
        for &n in &peaks {
            for (v, o) in y.iter_mut().zip(outputs) {
                *v = o[n];
            }
            for w in steer.chunks_exact(self.elements) {
                let s: Complex = y.iter().zip(w).map(|(y, w)| y * w).sum();
                best = best.max(s.norm_sqr());
            }
        }
        best
    }
}

/// Confirms a mode after `confirmations` identical identifications in a row.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ModeConfirmation {
    pub confirmations: usize,
    last: Option<usize>,
    run: usize,
    confirmed: Option<usize>,
}

impl ModeConfirmation {
    pub fn new(confirmations: usize) -> Self {
        Self { confirmations, last: None, run: 0, confirmed: None }
    }

    /// Adds one ping's identification; returns the confirmed mode, if any.
    pub fn push(&mut self, mode: usize) -> Option<usize> {
        self.run = if self.last == Some(mode) { self.run + 1 } else { 1 };
        self.last = Some(mode);
        if self.run >= self.confirmations {
            self.confirmed = Some(mode);
        }
        self.confirmed
    }

    /// The mode confirmed last, if any.
    pub fn confirmed(&self) -> Option<usize> {
        self.confirmed
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn three_in_a_row_switch_the_mode() {
        let mut c = ModeConfirmation::new(3);
        assert_eq!(c.push(1), None);
        assert_eq!(c.push(1), None);
        assert_eq!(c.push(1), Some(1));
        assert_eq!(c.push(2), Some(1)); // one different ping does not switch
        assert_eq!(c.push(2), Some(1));
        assert_eq!(c.push(3), Some(1));
        assert_eq!(c.push(2), Some(1));
        assert_eq!(c.push(2), Some(1));
        assert_eq!(c.push(2), Some(2));
    }
}
