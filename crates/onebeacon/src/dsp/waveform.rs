//! Transmitted waveforms (rypkema section 3.2: 20 ms LFM chirps, one band per mode).

use super::Complex;
use std::f64::consts::{PI, TAU};

/// A transmitted waveform, evaluated in continuous time (zero outside the signal), so
/// that a channel can sample it at exact fractional delays and Doppler-scaled times.
pub trait Waveform {
    fn value(&self, t: f64) -> f64;
}

impl Waveform for Lfm {
    fn value(&self, t: f64) -> f64 {
        Lfm::value(self, t)
    }
}

/// Amplitude taper over the pulse.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Window {
    Rectangular,
    Hann,
    /// Cosine tapers over this fraction of the pulse (split between both ends).
    Tukey(f64),
}

impl Window {
    fn gain(&self, x: f64) -> f64 {
        match *self {
            Window::Rectangular => 1.0,
            Window::Hann => 0.5 - 0.5 * (2.0 * PI * x).cos(),
            Window::Tukey(alpha) => {
                let a = alpha.clamp(0.0, 1.0);
                if a == 0.0 {
                    return 1.0;
                }
                let edge = a / 2.0;
                if x < edge {
                    0.5 - 0.5 * (PI * x / edge).cos()
                } else if x > 1.0 - edge {
                    0.5 - 0.5 * (PI * (1.0 - x) / edge).cos()
                } else {
                    1.0
                }
            }
        }
    }
}

/// Linear frequency-modulated chirp `w(t) cos(2 pi (f0 t + k t^2 / 2))` on
/// `0 <= t < T`, `k = (f1 - f0) / T` (cosine, zero initial phase).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lfm {
    pub f0_hz: f64,
    pub f1_hz: f64,
    pub duration_s: f64,
    pub window: Window,
}

impl Lfm {
    pub fn new(f0_hz: f64, f1_hz: f64, duration_s: f64) -> Self {
        Self { f0_hz, f1_hz, duration_s, window: Window::Rectangular }
    }

    /// The waveform at continuous time `t` (zero outside the pulse): sampling it at
    /// delayed, Doppler-scaled times gives exact fractional delays.
    pub fn value(&self, t: f64) -> f64 {
        if !(0.0..self.duration_s).contains(&t) {
            return 0.0;
        }
        let k = (self.f1_hz - self.f0_hz) / self.duration_s;
        self.window.gain(t / self.duration_s) * (2.0 * PI * (self.f0_hz * t + 0.5 * k * t * t)).cos()
    }

    /// The pulse sampled at `fs` from t = 0.
    pub fn samples(&self, fs: f64) -> Vec<f64> {
        let n = (self.duration_s * fs).round() as usize;
        (0..n).map(|i| self.value(i as f64 / fs)).collect()
    }

    /// The swept band, low to high, Hz.
    /// RMS frequency F (carrier included), Hz: F^2 = int s'^2 / ((2 pi)^2 int s^2) inside
    /// the pulse (the edges of a rectangular pulse left out), from the waveform sampled
    /// at 512 points per cycle of its highest frequency, so that windows count:
    /// sqrt((f0^2 + f0 f1 + f1^2) / 3) for a rectangular chirp.
    pub fn rms_frequency_hz(&self) -> f64 {
        let dt = 1.0 / (512.0 * self.f0_hz.max(self.f1_hz));
        let n = (self.duration_s / dt).ceil() as usize;
        let s: Vec<f64> = (0..n).map(|i| self.value(i as f64 * dt)).collect();
        let energy: f64 = s.iter().map(|x| x * x).sum();
        let slope: f64 = s.windows(3).map(|w| ((w[2] - w[0]) / (2.0 * dt)).powi(2)).sum();
        (slope / energy).sqrt() / std::f64::consts::TAU
    }

    pub fn band(&self) -> (f64, f64) {
        (self.f0_hz.min(self.f1_hz), self.f0_hz.max(self.f1_hz))
    }
}

/// rypkema section 4.2: the four 20 ms command chirps, modes 1 to 4.
pub fn rypkema_modes() -> [Lfm; 4] {
    [Lfm::new(7e3, 9e3, 0.02), Lfm::new(10e3, 8e3, 0.02), Lfm::new(8e3, 6e3, 0.02), Lfm::new(9e3, 11e3, 0.02)]
}

/// Square-root raised-cosine pulse of symbol period `t_sym` and roll-off `beta`, peak
/// 1 - beta + 4 beta / pi at t = 0.
pub fn srrc(t: f64, t_sym: f64, beta: f64) -> f64 {
    let x = t / t_sym;
    if x.abs() < 1e-12 {
        return 1.0 - beta + 4.0 * beta / PI;
    }
    if beta > 0.0 && (x.abs() - 1.0 / (4.0 * beta)).abs() < 1e-9 {
        let a = PI / (4.0 * beta);
        return beta / 2f64.sqrt() * ((1.0 + 2.0 / PI) * a.sin() + (1.0 - 2.0 / PI) * a.cos());
    }
    ((PI * x * (1.0 - beta)).sin() + 4.0 * beta * x * (PI * x * (1.0 + beta)).cos())
        / (PI * x * (1.0 - (4.0 * beta * x).powi(2)))
}

/// garin2024's communication frame (eq. 8): a pure tone at `f_pt_hz` over the frame plus
/// PSK symbols with SRRC pulses at `f0_hz`: `guard` null symbols, the known `pilots`
/// (BPSK), the `data` symbols, `guard` null symbols. Defaults of Table 5: f_pt 20 kHz,
/// f0 28 kHz, 6.4 kBd, bandwidth 8.96 kHz (roll-off 0.4).
#[derive(Debug, Clone, PartialEq)]
pub struct PskFrame {
    pub f_pt_hz: f64,
    pub f0_hz: f64,
    pub symbol_rate_hz: f64,
    pub rolloff: f64,
    pub guard: usize,
    pub pilots: Vec<f64>,
    pub data: Vec<Complex>,
    /// Pulses are truncated at this many symbols each side.
    pub span: usize,
}

/// A maximal-length +-1 sequence of 2^7 - 1 = 127 chips (x^7 + x^6 + 1).
pub fn m_sequence_127() -> Vec<f64> {
    let mut state = 0x7fu8;
    (0..127)
        .map(|_| {
            let bit = ((state >> 6) ^ (state >> 5)) & 1;
            state = ((state << 1) | bit) & 0x7f;
            if bit == 1 { 1.0 } else { -1.0 }
        })
        .collect()
}

impl PskFrame {
    /// Table 5's frame with 127 pilots, `data` symbols and 16 guard symbols each end.
    pub fn garin(data: Vec<Complex>) -> Self {
        Self {
            f_pt_hz: 20e3,
            f0_hz: 28e3,
            symbol_rate_hz: 6.4e3,
            rolloff: 0.4,
            guard: 16,
            pilots: m_sequence_127(),
            data,
            span: 6,
        }
    }

    pub fn symbol_period_s(&self) -> f64 {
        1.0 / self.symbol_rate_hz
    }

    /// Frame duration, s.
    pub fn duration_s(&self) -> f64 {
        (2 * self.guard + self.pilots.len() + self.data.len()) as f64 * self.symbol_period_s()
    }

    /// Occupied band of the PSK part, Hz.
    pub fn band(&self) -> (f64, f64) {
        let half = self.symbol_rate_hz * (1.0 + self.rolloff) / 2.0;
        (self.f0_hz - half, self.f0_hz + half)
    }

    /// Time of the first pilot symbol's centre, s (t0 of eq. 12 at zero range).
    pub fn first_pilot_s(&self) -> f64 {
        self.guard as f64 * self.symbol_period_s()
    }

    fn symbols_at(&self, t: f64, pilots_only: bool) -> Complex {
        let ts = self.symbol_period_s();
        let k = (t / ts).round() as i64;
        let mut sum = Complex::new(0.0, 0.0);
        for j in (k - self.span as i64)..=(k + self.span as i64) {
            let Ok(j) = usize::try_from(j) else { continue };
            let Some(idx) = j.checked_sub(self.guard) else { continue };
            let sym = if idx < self.pilots.len() {
                Complex::new(self.pilots[idx], 0.0)
            } else if !pilots_only {
                match self.data.get(idx - self.pilots.len()) {
                    Some(d) => *d,
                    None => continue,
                }
            } else {
                continue;
            };
            sum += sym * srrc(t - j as f64 * ts, ts, self.rolloff);
        }
        sum
    }

    /// The pilot section alone (passband, no tone, no data), sampled at `fs`: the
    /// template of frame synchronisation, and the frame time of its first sample.
    pub fn pilot_template(&self, fs: f64) -> (Vec<f64>, f64) {
        self.pilot_template_scaled(fs, 1.0)
    }

    /// The pilot template as received with Doppler time scale `alpha` = 1 + v / c
    /// (closing speed v): sample n is the pilot section at frame time start + alpha n /
    /// fs. A receiver at x(t) = s(alpha t - tau) then peaks at lag L with tau =
    /// alpha L / fs - start (garin eq. 10-12: compensate the Doppler, then synchronise).
    pub fn pilot_template_scaled(&self, fs: f64, alpha: f64) -> (Vec<f64>, f64) {
        let ts = self.symbol_period_s();
        let start = self.first_pilot_s() - self.span as f64 * ts;
        let len = ((self.pilots.len() + 2 * self.span) as f64 * ts * fs / alpha).ceil() as usize;
        let v = (0..len)
            .map(|n| {
                let t = start + alpha * n as f64 / fs;
                (self.symbols_at(t, true) * Complex::from_polar(1.0, TAU * self.f0_hz * t)).re
            })
            .collect();
        (v, start)
    }
}

impl Waveform for PskFrame {
    /// eq. 8: Re[exp(j 2 pi f_pt t) + sum x[k] g(t - kT) exp(j 2 pi f0 t)] over the frame.
    fn value(&self, t: f64) -> f64 {
        if !(0.0..self.duration_s()).contains(&t) {
            return 0.0;
        }
        (TAU * self.f_pt_hz * t).cos() + (self.symbols_at(t, false) * Complex::from_polar(1.0, TAU * self.f0_hz * t)).re
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_abs_diff_eq;

    #[test]
    fn chirp_sweeps_its_band() {
        let c = Lfm::new(7e3, 9e3, 0.02);
        assert_eq!(c.samples(37_500.0).len(), 750); // 20 ms at 37.5 kS/s
        // instantaneous frequency from the phase: f0 + k t
        let inst = |t: f64| 7e3 + (2e3 / 0.02) * t;
        for t in [0.001, 0.009, 0.017] {
            // count zero crossings over 2 ms from t (resolution 250 Hz)
            let fs = 1e6;
            let n = 2000;
            let mut crossings = 0;
            for i in 0..n {
                let (a, b) = (c.value(t + i as f64 / fs), c.value(t + (i + 1) as f64 / fs));
                if a.signum() != b.signum() {
                    crossings += 1;
                }
            }
            let f = crossings as f64 / 2.0 / (n as f64 / fs);
            assert!((f - inst(t + n as f64 / fs / 2.0)).abs() < 300.0, "{f}");
        }
        assert_eq!(c.value(-1e-6), 0.0);
        assert_eq!(c.value(0.02), 0.0);
        assert_abs_diff_eq!(c.value(0.0), 1.0);
        assert_eq!(rypkema_modes()[1].band(), (8e3, 10e3));
    }

    #[test]
    fn rms_frequency_of_a_rectangular_chirp() {
        let f = Lfm::new(7e3, 9e3, 0.02).rms_frequency_hz();
        assert!((f - ((49e6 + 63e6 + 81e6) / 3.0f64).sqrt()).abs() < 1.0, "{f}"); // 8020.8 Hz
    }

    #[test]
    fn srrc_and_frame() {
        // the raised cosine (SRRC convolved with itself) has zeros at the other symbols:
        // check numerically that sum g(t) g(t - kT) dt is ~0 for k != 0
        let (ts, beta) = (1.0, 0.4);
        let dt = 1e-3;
        let corr = |k: f64| {
            (-8000..8000).map(|i| srrc(i as f64 * dt, ts, beta) * srrc(i as f64 * dt - k, ts, beta)).sum::<f64>() * dt
        };
        let c0 = corr(0.0);
        for k in [1.0, 2.0, 3.0] {
            assert!((corr(k) / c0).abs() < 0.01, "k {k}: {}", corr(k) / c0);
        }
        // the limits at 0 and at T / (4 beta) are continuous
        assert!((srrc(1e-7, ts, beta) - srrc(0.0, ts, beta)).abs() < 1e-5);
        let edge = 1.0 / (4.0 * beta);
        assert!((srrc(edge + 1e-7, ts, beta) - srrc(edge, ts, beta)).abs() < 1e-5);
        // the m-sequence is balanced and its cyclic autocorrelation is two-valued
        let m = m_sequence_127();
        assert_eq!(m.iter().sum::<f64>().abs(), 1.0);
        for lag in 1..127 {
            let r: f64 = (0..127).map(|i| m[i] * m[(i + lag) % 127]).sum();
            assert_eq!(r, -1.0);
        }
        let f = PskFrame::garin(vec![Complex::new(1.0, 0.0); 1740]);
        assert!((f.duration_s() - 0.297).abs() < 1e-3);
        assert!((f.band().1 - f.band().0 - 8960.0).abs() < 1e-6);
        assert_eq!(f.value(-0.1), 0.0);
    }

    #[test]
    fn windows_taper_the_ends() {
        let c = Lfm { window: Window::Hann, ..Lfm::new(7e3, 9e3, 0.02) };
        assert_abs_diff_eq!(c.value(0.0), 0.0);
        let t = Lfm { window: Window::Tukey(0.2), ..Lfm::new(7e3, 9e3, 0.02) };
        assert_abs_diff_eq!(t.window.gain(0.5), 1.0);
        assert_abs_diff_eq!(t.window.gain(0.05), 0.5, epsilon = 1e-12);
    }
}
