//! Command-mode identification (rypkema section 4.2): the capture is matched against a
//! bank of templates; the one with the largest response is this ping's mode; a mode is
//! confirmed after the same identification `confirmations` times in a row (3).

use super::Complex;
use super::matched_filter::MatchedFilter;

/// A bank of matched filters, one per mode.
#[derive(Debug)]
pub struct ModeBank {
    filters: Vec<MatchedFilter>,
}

impl ModeBank {
    /// A bank of filters of one FFT length (equal template and capture lengths), so that
    /// every capture is transformed once.
    pub fn new(filters: Vec<MatchedFilter>) -> Self {
        assert!(filters.windows(2).all(|w| w[0].fft_len() == w[1].fft_len()), "filters of one FFT length");
        Self { filters }
    }

    /// The spectra of the captures, shared by every filter of the bank (and by a
    /// [`crate::dsp::receiver::Receiver`] of the same lengths).
    pub fn spectra(&self, captures: &[Vec<f64>]) -> Vec<Vec<Complex>> {
        match self.filters.first() {
            Some(f) => captures.iter().map(|x| f.spectrum(x)).collect(),
            None => Vec::new(),
        }
    }

    /// Each mode's response: the peak over lags of the sum over elements of the squared
    /// envelopes (build the bank with [`MatchedFilter::classical`] filters for a
    /// statistic comparable across templates).
    pub fn responses(&self, spectra: &[Vec<Complex>]) -> Vec<f64> {
        self.filters
            .iter()
            .map(|f| {
                let mut sum = vec![0.0; f.capture_len()];
                for x in spectra {
                    for (s, e) in sum.iter_mut().zip(f.envelope_of(x)) {
                        *s += e * e;
                    }
                }
                sum.iter().cloned().fold(0.0, f64::max)
            })
            .collect()
    }

    /// The mode (index into the bank) with the largest response, from the spectra of
    /// the captures ([`ModeBank::spectra`]).
    pub fn identify(&self, spectra: &[Vec<Complex>]) -> usize {
        super::matched_filter::argmax(&self.responses(spectra))
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
