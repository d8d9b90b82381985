//! Doppler speed from a pure tone (garin2024 section 3.4, eq. 9; Kay 1989, "A fast and
//! accurate single frequency estimator"): the tone is taken to complex baseband, low-passed and
//! decimated to a few hundred hertz, and its frequency estimated by garin's single-lag
//! phase difference (eq. 9) or by Kay's weighted phase-difference estimator, which
//! reaches the Cramer-Rao bound above about 10 dB per sample.

use super::Complex;
use std::f64::consts::{PI, TAU};

/// Mixes the real signal `x` (sampled at `fs`) by exp(-j 2 pi `fc` t) and averages
/// blocks of `d` samples: a boxcar low-pass and decimation by `d` (first null at fs/d,
/// so the image at 2 fc is far down). Returns samples at fs / d.
pub fn baseband(x: &[f64], fc: f64, fs: f64, d: usize) -> Vec<Complex> {
    let d = d.max(1);
    let w = Complex::from_polar(1.0, -TAU * fc / fs);
    let mut osc = Complex::new(1.0, 0.0);
    let mut out = Vec::with_capacity(x.len() / d);
    let mut acc = Complex::new(0.0, 0.0);
    for (i, v) in x.iter().enumerate() {
        acc += osc * *v;
        osc *= w;
        if i % 1024 == 1023 {
            osc /= osc.norm(); // keep the oscillator on the unit circle
        }
        if (i + 1) % d == 0 {
            out.push(acc / d as f64);
            acc = Complex::new(0.0, 0.0);
        }
    }
    out
}

/// garin eq. 9 as a frequency estimator over the whole record: the phase of the lag-1
/// autocorrelation, f = fs / (2 pi) arg(sum z[k] z*[k-1]).
pub fn pulse_pair_frequency(z: &[Complex], fs: f64) -> f64 {
    let r: Complex = z.windows(2).map(|w| w[1] * w[0].conj()).sum();
    r.arg() * fs / TAU
}

/// Kay's weighted phase-difference estimator (Kay 1989): f = fs / (2 pi) sum over k of
/// w_k arg(z[k+1] z*[k]), w_k = 1.5 N / (N^2 - 1) [1 - ((k - (N/2 - 1)) / (N/2))^2].
pub fn kay_frequency(z: &[Complex], fs: f64) -> f64 {
    let n = z.len() as f64;
    if z.len() < 2 {
        return 0.0;
    }
    let half = n / 2.0;
    let sum: f64 = z
        .windows(2)
        .enumerate()
        .map(|(k, w)| {
            let weight = 1.5 * n / (n * n - 1.0) * (1.0 - ((k as f64 - (half - 1.0)) / half).powi(2));
            weight * (w[1] * w[0].conj()).arg()
        })
        .sum();
    sum * fs / TAU
}

/// Maximum-likelihood frequency of one complex tone: the periodogram peak within
/// +-`max_abs_hz` (8x zero-padded FFT), refined by golden-section search on the exact
/// DTFT. Reaches the bound down to low per-sample SNR as long as the total SNR is
/// above threshold, where the phase-difference estimators (eq. 9, Kay) need about
/// 10 dB per sample.
pub fn periodogram_frequency(z: &[Complex], fs: f64, max_abs_hz: f64) -> f64 {
    if z.is_empty() {
        return 0.0;
    }
    let power = |f: f64| {
        let w = Complex::from_polar(1.0, -TAU * f / fs);
        let mut e = Complex::new(1.0, 0.0);
        let mut s = Complex::new(0.0, 0.0);
        for v in z {
            s += v * e;
            e *= w;
        }
        s.norm_sqr()
    };
    let n = (8 * z.len()).next_power_of_two();
    let mut buf = vec![Complex::new(0.0, 0.0); n];
    buf[..z.len()].copy_from_slice(z);
    rustfft::FftPlanner::<f64>::new().plan_fft_forward(n).process(&mut buf);
    let df = fs / n as f64;
    let mut best = (0.0, f64::MIN);
    for (k, v) in buf.iter().enumerate() {
        let f = if k <= n / 2 { k as f64 * df } else { (k as f64 - n as f64) * df };
        if f.abs() <= max_abs_hz && v.norm_sqr() > best.1 {
            best = (f, v.norm_sqr());
        }
    }
    // golden section on [f - df, f + df]
    crate::optim::golden_section_max(power, best.0 - df, best.0 + df, 40).0
}

/// Cramer-Rao bound (standard deviation, Hz) on the frequency of a complex tone in
/// white noise: var >= 6 / ((2 pi)^2 eta N (N^2 - 1) Ts^2), with per-sample SNR `eta`,
/// `n` samples `ts` apart.
pub fn frequency_crlb_hz(eta: f64, n: usize, ts: f64) -> f64 {
    let n = n as f64;
    (6.0 / ((2.0 * PI).powi(2) * eta * n * (n * n - 1.0) * ts * ts)).sqrt()
}

/// Radial speed (positive closing) from the Doppler shift `f_d` of a tone at `f_tone`:
/// f_d = v f_tone / c (garin 3.4).
pub fn radial_speed(f_d: f64, f_tone: f64, c: f64) -> f64 {
    f_d * c / f_tone
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_distr::StandardNormal;

    /// A Monte Carlo reference (ours, numpy): T_d = 50 ms, N = 50, 10 dB per sample: CRLB 0.35 Hz,
    /// Kay 0.36 Hz RMSE (within 15 % of the bound here).
    #[test]
    fn kay_reaches_the_bound_at_10_db() {
        let (n, fs) = (50usize, 1000.0);
        let eta = 10.0;
        let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(3);
        let bound = frequency_crlb_hz(eta, n, 1.0 / fs);
        assert!((bound - 0.35).abs() < 0.01, "{bound}");
        let trials = 2000;
        let (mut se_kay, mut se_pp) = (0.0, 0.0);
        for _ in 0..trials {
            let f = 40.0 * (rng.random::<f64>() - 0.5);
            let phi = TAU * rng.random::<f64>();
            let sigma = (0.5f64 / eta).sqrt(); // complex noise of total power 1 / eta
            let z: Vec<Complex> = (0..n)
                .map(|k| {
                    Complex::from_polar(1.0, TAU * f * k as f64 / fs + phi)
                        + Complex::new(
                            sigma * rng.sample::<f64, _>(StandardNormal),
                            sigma * rng.sample::<f64, _>(StandardNormal),
                        )
                })
                .collect();
            se_kay += (kay_frequency(&z, fs) - f).powi(2);
            se_pp += (pulse_pair_frequency(&z, fs) - f).powi(2);
        }
        let (kay, pp) = ((se_kay / trials as f64).sqrt(), (se_pp / trials as f64).sqrt());
        assert!(kay < 1.15 * bound, "Kay {kay} vs bound {bound}");
        assert!(pp >= kay * 0.9, "pulse-pair {pp}");
    }

    #[test]
    fn baseband_finds_a_shifted_tone() {
        let fs = 96_153.0;
        let f = 20_000.0 + 26.66; // 2 m/s closing at c = 1500
        let x: Vec<f64> = (0..(0.3 * fs) as usize).map(|i| (TAU * f * i as f64 / fs).cos()).collect();
        let z = baseband(&x, 20_000.0, fs, 240);
        let fz = fs / 240.0;
        let est = kay_frequency(&z, fz);
        assert!((est - 26.66).abs() < 0.01, "{est}");
        assert!((radial_speed(est, 20_000.0, 1500.0) - 2.0).abs() < 1e-3);
    }
}
