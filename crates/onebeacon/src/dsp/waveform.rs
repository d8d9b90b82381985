//! Transmitted waveforms (../shared/acoustics.md, "Waveforms and reception").

use std::f64::consts::PI;

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
    pub fn band(&self) -> (f64, f64) {
        (self.f0_hz.min(self.f1_hz), self.f0_hz.max(self.f1_hz))
    }
}

/// rypkema section 4.2: the four 20 ms command chirps, modes 1 to 4.
pub fn rypkema_modes() -> [Lfm; 4] {
    [Lfm::new(7e3, 9e3, 0.02), Lfm::new(10e3, 8e3, 0.02), Lfm::new(8e3, 6e3, 0.02), Lfm::new(9e3, 11e3, 0.02)]
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_abs_diff_eq;

    #[test]
    fn chirp_sweeps_its_band() {
        let c = Lfm::new(7e3, 9e3, 0.02);
        assert_eq!(c.samples(37_500.0).len(), 750); // acoustics.md
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
    fn windows_taper_the_ends() {
        let c = Lfm { window: Window::Hann, ..Lfm::new(7e3, 9e3, 0.02) };
        assert_abs_diff_eq!(c.value(0.0), 0.0);
        let t = Lfm { window: Window::Tukey(0.2), ..Lfm::new(7e3, 9e3, 0.02) };
        assert_abs_diff_eq!(t.window.gain(0.5), 1.0);
        assert_abs_diff_eq!(t.window.gain(0.05), 0.5, epsilon = 1e-12);
    }
}
