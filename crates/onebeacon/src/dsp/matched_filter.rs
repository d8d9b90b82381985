//! PHAT-whitened matched filtering and range pseudo-distributions (rypkema eq. 2-5;
//! Knapp and Carter 1976 for PHAT).

use super::Complex;
use realfft::{RealFftPlanner, RealToComplex};
use rustfft::{Fft, FftPlanner};
use std::sync::Arc;

/// A matched filter for one template over captures of a fixed length.
pub struct MatchedFilter {
    capture_len: usize,
    n: usize,
    /// S*(f) on the in-band bins, and the bin range [lo, hi).
    template_conj: Vec<Complex>,
    lo: usize,
    hi: usize,
    /// PHAT whitening (keep the phase only) or the classical matched filter.
    phat: bool,
    r2c: Arc<dyn RealToComplex<f64>>,
    ifft: Arc<dyn Fft<f64>>,
    /// The band shifted to zero frequency and transformed at 1/`decimation` of the rate
    /// (the shortest length dividing n that holds twice the band): [`MatchedFilter::baseband_of`].
    decimation: usize,
    ifft_baseband: Arc<dyn Fft<f64>>,
}

impl std::fmt::Debug for MatchedFilter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("MatchedFilter").field("n", &self.n).field("band_bins", &(self.lo, self.hi)).finish()
    }
}

impl MatchedFilter {
    /// A filter for `template` sampled at `fs`, whitened and restricted to `band_hz`,
    /// for captures of `capture_len` samples. The FFT is long enough that the
    /// correlation does not wrap.
    pub fn new(template: &[f64], band_hz: (f64, f64), fs: f64, capture_len: usize) -> Self {
        Self::build(template, band_hz, fs, capture_len, true)
    }

    /// The classical (unwhitened) matched filter, scaled by the template's norm so that
    /// white noise gives every template the same output variance: the statistic to
    /// compare templates with (mode identification) at low SNR, where PHAT, which gives
    /// noise-only bins as much weight as signal bins, loses.
    pub fn classical(template: &[f64], band_hz: (f64, f64), fs: f64, capture_len: usize) -> Self {
        Self::build(template, band_hz, fs, capture_len, false)
    }

    fn build(template: &[f64], band_hz: (f64, f64), fs: f64, capture_len: usize, phat: bool) -> Self {
        let n = fast_len(capture_len + template.len());
        let mut planner = RealFftPlanner::<f64>::new();
        let r2c = planner.plan_fft_forward(n);
        let ifft = FftPlanner::<f64>::new().plan_fft_inverse(n);
        let mut padded = vec![0.0; n];
        padded[..template.len()].copy_from_slice(template);
        let mut spectrum = r2c.make_output_vec();
        r2c.process(&mut padded, &mut spectrum).expect("sizes match the plan");
        let bin = |f: f64| ((f / fs * n as f64).round().max(1.0) as usize).min(n / 2);
        let (lo, hi) = (bin(band_hz.0), bin(band_hz.1) + 1);
        let norm = spectrum[lo..hi].iter().map(|c| c.norm_sqr()).sum::<f64>().sqrt().max(f64::MIN_POSITIVE);
        let scale = if phat { 1.0 } else { 1.0 / norm };
        let template_conj = spectrum[lo..hi].iter().map(|c| c.conj() * scale).collect();
        let decimation = (1..=n).rev().find(|d| n.is_multiple_of(*d) && n / d >= 2 * (hi - lo)).unwrap_or(1);
        let ifft_baseband = FftPlanner::<f64>::new().plan_fft_inverse(n / decimation);
        Self { capture_len, n, template_conj, lo, hi, phat, r2c, ifft, decimation, ifft_baseband }
    }

    pub fn capture_len(&self) -> usize {
        self.capture_len
    }

    /// FFT length; filters of equal length can share [`MatchedFilter::spectrum`]s.
    pub fn fft_len(&self) -> usize {
        self.n
    }

    /// The zero-padded spectrum of one capture, to be shared by every filter of the
    /// same FFT length.
    pub fn spectrum(&self, x: &[f64]) -> Vec<Complex> {
        let mut spectrum = Vec::new();
        self.spectrum_into(x, &mut Vec::new(), &mut spectrum);
        spectrum
    }

    /// [`MatchedFilter::spectrum`] into `out`, with `padded` as the work buffer (both
    /// kept by the caller from ping to ping: no allocation once they have grown).
    pub fn spectrum_into(&self, x: &[f64], padded: &mut Vec<f64>, out: &mut Vec<Complex>) {
        padded.clear();
        padded.resize(self.n, 0.0);
        let m = x.len().min(self.capture_len);
        padded[..m].copy_from_slice(&x[..m]);
        out.resize(self.n / 2 + 1, Complex::new(0.0, 0.0));
        self.r2c.process(padded, out).expect("sizes match the plan");
    }

    /// The analytic envelope |y[n]| of the PHAT-whitened correlation of `x` with the
    /// template (eq. 2-3 with the PHAT whitening of X S*), for lags 0..capture_len:
    /// lag n is the template starting at sample n.
    pub fn envelope(&self, x: &[f64]) -> Vec<f64> {
        self.envelope_of(&self.spectrum(x))
    }

    /// [`MatchedFilter::envelope`] from a capture's spectrum.
    pub fn envelope_of(&self, spectrum: &[Complex]) -> Vec<f64> {
        let mut out = Vec::new();
        self.envelope_into(spectrum, &mut Vec::new(), &mut out);
        out
    }

    /// [`MatchedFilter::envelope_of`] into `out`, with `work` as the FFT buffer (kept by
    /// the caller).
    pub fn envelope_into(&self, spectrum: &[Complex], work: &mut Vec<Complex>, out: &mut Vec<f64>) {
        self.analytic_into(spectrum, work);
        out.clear();
        out.extend(work.iter().map(|c| c.norm_sqr().sqrt()));
    }

    /// Lags per sample of [`MatchedFilter::baseband_of`].
    pub fn decimation(&self) -> usize {
        self.decimation
    }

    /// The analytic correlation at every `decimation`-th lag, from a capture's spectrum:
    /// the in-band bins shifted to zero frequency and inverse-transformed at the reduced
    /// length (the band fits in it, so nothing aliases). Sample j is lag j d with the
    /// modulus of [`MatchedFilter::analytic_of`] there, its phase turned by
    /// exp(-j 2 pi lo j / (n / d)), a factor common to every element: what mode
    /// identification needs at a tenth of the cost.
    pub fn baseband_of(&self, spectrum: &[Complex]) -> Vec<Complex> {
        assert_eq!(spectrum.len(), self.n / 2 + 1, "spectrum of another FFT length");
        let m = self.n / self.decimation;
        let mut y = vec![Complex::new(0.0, 0.0); m];
        for (i, (k, s)) in (self.lo..self.hi).zip(&self.template_conj).enumerate() {
            y[i] = self.whitened(spectrum[k] * s);
        }
        self.ifft_baseband.process(&mut y);
        y.truncate(self.capture_len.div_ceil(self.decimation));
        y.iter_mut().for_each(|c| *c /= self.n as f64);
        y
    }

    /// One bin of the cross-spectrum, twice (one-sided), whitened by PHAT (eq. 2) or not.
    fn whitened(&self, p: Complex) -> Complex {
        if !self.phat {
            return p * 2.0;
        }
        let mag = p.norm_sqr().sqrt();
        if mag > 0.0 { p * (2.0 / mag) } else { Complex::new(0.0, 0.0) }
    }

    /// The complex analytic correlation from a capture's spectrum, lags 0..capture_len
    /// (its modulus is the envelope; its phase carries the carrier, for coherent
    /// combination across elements).
    pub fn analytic_of(&self, spectrum: &[Complex]) -> Vec<Complex> {
        let mut y = Vec::new();
        self.analytic_into(spectrum, &mut y);
        y
    }

    /// [`MatchedFilter::analytic_of`] into `y`.
    pub fn analytic_into(&self, spectrum: &[Complex], y: &mut Vec<Complex>) {
        assert_eq!(spectrum.len(), self.n / 2 + 1, "spectrum of another FFT length");
        // one-sided (analytic) spectrum of the whitened cross-spectrum, in band only
        y.clear();
        y.resize(self.n, Complex::new(0.0, 0.0));
        for (k, s) in (self.lo..self.hi).zip(&self.template_conj) {
            y[k] = self.whitened(spectrum[k] * s); // eq. 2: keep the phase only (PHAT)
        }
        self.ifft.process(y);
        y.truncate(self.capture_len);
        let scale = 1.0 / self.n as f64;
        y.iter_mut().for_each(|c| *c *= scale);
    }
}

/// The smallest length of the form 2^a 3^b 5^c that is at least `n`: fast for
/// rustfft, and up to twice shorter than the next power of two.
pub fn fast_len(n: usize) -> usize {
    let mut best = n.next_power_of_two();
    let mut p5 = 1;
    while p5 < best {
        let mut p35 = p5;
        while p35 < best {
            let mut m = p35;
            while m < n {
                m *= 2;
            }
            best = best.min(m);
            p35 *= 3;
        }
        p5 *= 5;
    }
    best
}

/// Range from the envelopes of all elements.
#[derive(Debug, Clone, PartialEq)]
pub struct RangeEstimate {
    /// Peak lag in samples, refined between samples.
    pub lag: f64,
    pub range_m: f64,
    /// Whether every element's arg-maximum lies within the gate of the others.
    pub consistent: bool,
    /// The combined output normalised to unit energy, over lags (eq. 5).
    pub distribution: Vec<f64>,
    /// Height of the combined output's peak.
    pub peak: f64,
}

impl RangeEstimate {
    /// The detection statistic: the peak of the unit-energy combined output, near 1 for
    /// a clean pulse, small for noise (its energy spread over every lag); 0 for silence.
    pub fn peak_ratio(&self) -> f64 {
        self.distribution.iter().copied().fold(0.0, f64::max)
    }

    /// Whether the statistic shows a pulse: above [`DETECTION_THRESHOLD_8000`] scaled to
    /// the capture length (noise spreads over the lags as 1 / sqrt(lags)).
    pub fn detected(&self) -> bool {
        self.peak_ratio() >= detection_threshold(self.distribution.len())
    }
}

/// The detection threshold of [`RangeEstimate::peak_ratio`] for 8000-lag captures (5
/// elements, the rypkema chirps): no noise-only capture of 2000 reached it (median
/// 0.035), every ping of 300 at 20 dB 2E/N0 per element did (0.22 or more), at 10 dB
/// about one in five (docs/reproductions/receiver.md; the example
/// `dsp_trials` of onebeacon-sim).
pub const DETECTION_THRESHOLD_8000: f64 = 0.07;

/// [`DETECTION_THRESHOLD_8000`] scaled to `lags` lags.
pub fn detection_threshold(lags: usize) -> f64 {
    DETECTION_THRESHOLD_8000 * (8000.0 / lags.max(1) as f64).sqrt()
}

/// Index of the largest value (the first one on ties).
pub fn argmax(v: &[f64]) -> usize {
    let mut best = 0;
    for (i, &x) in v.iter().enumerate() {
        if x > v[best] {
            best = i;
        }
    }
    best
}

/// Sub-sample position of the peak at `i` by a parabola through its neighbours.
pub fn parabolic_peak(v: &[f64], i: usize) -> f64 {
    if i == 0 || i + 1 >= v.len() {
        return i as f64;
    }
    let (a, b, c) = (v[i - 1], v[i], v[i + 1]);
    let den = a - 2.0 * b + c;
    if den.abs() < 1e-300 { i as f64 } else { i as f64 + 0.5 * (a - c) / den }
}

/// Combines per-element envelopes (eq. 4: the sum over element pairs of the products
/// of envelopes), checks that the elements agree within `gate` samples (rypkema: 15),
/// normalises to unit energy (eq. 5) and converts the refined peak lag to a range with
/// sound speed `c` at `fs`.
pub fn estimate_range(envelopes: &[Vec<f64>], gate: usize, fs: f64, c: f64) -> RangeEstimate {
    let len = envelopes.iter().map(Vec::len).min().unwrap_or(0);
    let peaks: Vec<usize> = envelopes.iter().map(|e| argmax(&e[..len])).collect();
    let consistent = match (peaks.iter().min(), peaks.iter().max()) {
        (Some(lo), Some(hi)) => hi - lo <= gate,
        _ => false,
    };
    // eq. 4: the sum over pairs i < j of e_i e_j is ((sum e)^2 - sum e^2) / 2
    let mut sum = vec![0.0; len];
    let mut combined = vec![0.0; len];
    for e in envelopes {
        for ((s, q), v) in sum.iter_mut().zip(combined.iter_mut()).zip(&e[..len]) {
            *s += v;
            *q += v * v;
        }
    }
    if envelopes.len() == 1 {
        combined.copy_from_slice(&envelopes[0][..len]);
    } else {
        for (q, s) in combined.iter_mut().zip(&sum) {
            *q = 0.5 * (s * s - *q);
        }
    }
    let energy = combined.iter().map(|v| v * v).sum::<f64>().sqrt();
    let peak_index = argmax(&combined);
    let lag = parabolic_peak(&combined, peak_index);
    let peak = combined.get(peak_index).copied().unwrap_or(0.0);
    if energy > 0.0 {
        combined.iter_mut().for_each(|v| *v /= energy);
    }
    RangeEstimate { lag, range_m: c * lag / fs, consistent, distribution: combined, peak }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dsp::waveform::Lfm;
    use approx::assert_abs_diff_eq;

    /// A chirp delayed by a fractional number of samples (evaluated in continuous
    /// time) is found at that delay to a small fraction of a sample, on every element.
    #[test]
    fn finds_fractional_delays() {
        let fs = 37_500.0;
        let chirp = Lfm::new(7e3, 9e3, 0.02);
        let mf = MatchedFilter::new(&chirp.samples(fs), chirp.band(), fs, 8000);
        for delay in [1234.0, 2000.37, 5123.81, 7000.5] {
            let x: Vec<f64> = (0..8000).map(|n| chirp.value((n as f64 - delay) / fs)).collect();
            let env = mf.envelope(&x);
            let est = estimate_range(&[env.clone(), env.clone(), env], 15, fs, 1500.0);
            assert!(est.consistent);
            assert!((est.lag - delay).abs() < 0.1, "delay {delay}: found {}", est.lag);
            assert_abs_diff_eq!(est.range_m, 1500.0 * delay / fs, epsilon = 0.1 * 1500.0 / fs);
            let energy: f64 = est.distribution.iter().map(|v| v * v).sum();
            assert_abs_diff_eq!(energy, 1.0, epsilon = 1e-9);
        }
    }

    /// The decimated baseband correlation has the full-rate envelope at every d-th lag.
    #[test]
    fn baseband_matches_the_full_rate_envelope() {
        let fs = 37_500.0;
        let chirp = Lfm::new(10e3, 8e3, 0.02);
        for mf in [
            MatchedFilter::new(&chirp.samples(fs), chirp.band(), fs, 8000),
            MatchedFilter::classical(&chirp.samples(fs), chirp.band(), fs, 8000),
        ] {
            let x: Vec<f64> = (0..8000)
                .map(|n| chirp.value((n as f64 - 3210.4) / fs) + 0.3 * ((n * 7919 % 13) as f64 - 6.0))
                .collect();
            let spectrum = mf.spectrum(&x);
            let (full, base, d) = (mf.analytic_of(&spectrum), mf.baseband_of(&spectrum), mf.decimation());
            assert!(d > 4, "{d}");
            for (j, b) in base.iter().enumerate() {
                assert_abs_diff_eq!(b.norm(), full[j * d].norm(), epsilon = 1e-9 * (1.0 + full[j * d].norm()));
            }
        }
    }

    #[test]
    fn gate_flags_disagreeing_elements() {
        let mut a = vec![0.0; 100];
        let mut b = vec![0.0; 100];
        a[20] = 1.0;
        b[40] = 1.0;
        assert!(!estimate_range(&[a.clone(), b], 15, 1.0, 1.0).consistent);
        let mut c = vec![0.0; 100];
        c[30] = 1.0;
        assert!(estimate_range(&[a, c], 15, 1.0, 1.0).consistent);
    }

    #[test]
    fn fast_lengths() {
        assert_eq!(fast_len(8750), 9000); // 2^3 3^2 5^3
        assert_eq!(fast_len(1024), 1024);
        assert_eq!(fast_len(1025), 1080); // 2^3 3^3 5
        for n in 1..2000 {
            let m = fast_len(n);
            assert!(m >= n);
            let mut r = m;
            for p in [2, 3, 5] {
                while r.is_multiple_of(p) {
                    r /= p;
                }
            }
            assert_eq!(r, 1, "{m}");
        }
    }

    #[test]
    fn parabola_recovers_the_vertex() {
        let v: Vec<f64> = (0..10).map(|i| -(i as f64 - 4.3).powi(2)).collect();
        assert_abs_diff_eq!(parabolic_peak(&v, argmax(&v)), 4.3, epsilon = 1e-12);
    }
}
