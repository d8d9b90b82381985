//! Command-mode identification (rypkema section 4.2): the capture is matched against a
//! bank of templates; the one with the largest response is this ping's mode; a mode is
//! confirmed after the same identification `confirmations` times in a row (3).

use super::matched_filter::MatchedFilter;

/// A bank of matched filters, one per mode.
#[derive(Debug)]
pub struct ModeBank {
    filters: Vec<MatchedFilter>,
}

impl ModeBank {
    pub fn new(filters: Vec<MatchedFilter>) -> Self {
        Self { filters }
    }

    /// Each mode's response: the peak over lags of the sum over elements of the squared
    /// envelopes (build the bank with [`MatchedFilter::classical`] filters for a
    /// statistic comparable across templates).
    pub fn responses(&self, captures: &[Vec<f64>]) -> Vec<f64> {
        self.filters
            .iter()
            .map(|f| {
                let mut sum = vec![0.0; f.capture_len()];
                for x in captures {
                    for (s, e) in sum.iter_mut().zip(f.envelope(x)) {
                        *s += e * e;
                    }
                }
                sum.iter().cloned().fold(0.0, f64::max)
            })
            .collect()
    }

    /// The mode (index into the bank) with the largest response.
    pub fn identify(&self, captures: &[Vec<f64>]) -> usize {
        super::matched_filter::argmax(&self.responses(captures))
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
