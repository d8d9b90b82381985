//! One ping through the receiver chain: PHAT matched filter on every element, range
//! from the combined envelopes, then SPD-BF on the direct-path segment for the
//! direction (rypkema section 3.2).

use super::beamform::{DirectionGrid, Snapshot, SpdBf, azimuth_inclination};
use super::matched_filter::{MatchedFilter, RangeEstimate, estimate_range};
use super::waveform::Lfm;
use nalgebra::Vector3;

/// Receiver settings.
#[derive(Debug, Clone, PartialEq)]
pub struct ReceiverConfig {
    pub fs_hz: f64,
    pub capture_len: usize,
    pub sound_speed_m_s: f64,
    /// Element arg-maxima must agree within this many samples (rypkema: 15).
    pub gate_samples: usize,
    /// SPD-BF conical grid resolution, rad (rypkema: 0.25 deg).
    pub conical_resolution_rad: f64,
    /// Azimuth/inclination search grid before refinement, rad.
    pub search_step_rad: f64,
}

impl Default for ReceiverConfig {
    fn default() -> Self {
        Self {
            fs_hz: 37_500.0,
            capture_len: 8000,
            sound_speed_m_s: 1500.0,
            gate_samples: 15,
            conical_resolution_rad: 0.25f64.to_radians(),
            search_step_rad: 2f64.to_radians(),
        }
    }
}

/// What one ping gives.
#[derive(Debug, Clone, PartialEq)]
pub struct PingEstimate {
    pub range: RangeEstimate,
    /// Unit vector toward the source in the array frame, and its angles (rad).
    pub direction: Vector3<f64>,
    pub azimuth: f64,
    pub inclination: f64,
}

/// Matched filter and SPD beamformer for one waveform and one array.
#[derive(Debug)]
pub struct Receiver {
    pub config: ReceiverConfig,
    waveform: Lfm,
    filter: MatchedFilter,
    spd: SpdBf,
    grid: DirectionGrid,
}

impl Receiver {
    pub fn new(waveform: Lfm, elements: &[Vector3<f64>], config: ReceiverConfig) -> Self {
        let filter =
            MatchedFilter::new(&waveform.samples(config.fs_hz), waveform.band(), config.fs_hz, config.capture_len);
        let spd = SpdBf::new(elements, config.sound_speed_m_s, config.conical_resolution_rad);
        let grid = DirectionGrid::new(config.search_step_rad);
        Self { config, waveform, filter, spd, grid }
    }

    /// Range and direction from one capture per element.
    pub fn process(&mut self, captures: &[Vec<f64>]) -> PingEstimate {
        let spectra: Vec<_> = captures.iter().map(|x| self.filter.spectrum(x)).collect();
        self.process_spectra(captures, &spectra)
    }

    /// [`Receiver::process`] with the captures' spectra already computed (by a
    /// [`crate::dsp::modes::ModeBank`] of the same lengths, say).
    pub fn process_spectra(&mut self, captures: &[Vec<f64>], spectra: &[Vec<super::Complex>]) -> PingEstimate {
        let c = &self.config;
        let envelopes: Vec<Vec<f64>> = spectra.iter().map(|x| self.filter.envelope_of(x)).collect();
        let range = estimate_range(&envelopes, c.gate_samples, c.fs_hz, c.sound_speed_m_s);
        // the direct-path segment: the pulse from a little before the detected onset
        let pulse = (self.waveform.duration_s * c.fs_hz).ceil() as usize;
        let len = (pulse + pulse / 4).next_power_of_two();
        let start = (range.lag.round() as usize).saturating_sub(pulse / 8);
        let snap = Snapshot::from_segment(captures, start, len, self.waveform.band(), c.fs_hz);
        self.spd.compute(&snap);
        let spd = &self.spd;
        let (direction, _) = self.grid.search(|u| spd.power(u));
        let (azimuth, inclination) = azimuth_inclination(&direction);
        PingEstimate { range, direction, azimuth, inclination }
    }

    /// The SPD-BF power toward `u` for the last processed ping (the beam map).
    pub fn beam_power(&self, u: &Vector3<f64>) -> f64 {
        self.spd.power(u)
    }
}
