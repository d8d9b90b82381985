//! One ping through the receiver chain: PHAT matched filter on every element, range
//! from the combined envelopes, then SPD-BF on the direct-path segment for the
//! direction (rypkema section 3.2). And one garin2024 communication frame: Doppler
//! speed from its tone, then range by synchronisation on the Doppler-compensated pilots
//! ([`receive_frame`]).

use super::beamform::{DirectionGrid, Lookup, SegmentTransform, Snapshot, SpdBf, azimuth_inclination};
use super::doppler::{baseband, periodogram_frequency, radial_speed};
use super::matched_filter::{MatchedFilter, RangeEstimate, estimate_range};
use super::waveform::{Lfm, PskFrame};
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
    /// Number of elements, and the last snapshot's total in-band energy.
    elements: usize,
    energy: f64,
    /// Kept from ping to ping: the envelopes, the FFT buffer, the direct-path segment's
    /// transform and snapshot, and the search grid's table positions (computed at the
    /// first search).
    envelopes: Vec<Vec<f64>>,
    work: Vec<super::Complex>,
    segment: SegmentTransform,
    snapshot: Snapshot,
    grid_lookups: std::sync::OnceLock<Lookup>,
    grid_powers: Vec<f64>,
}

impl Receiver {
    pub fn new(waveform: Lfm, elements: &[Vector3<f64>], config: ReceiverConfig) -> Self {
        let filter =
            MatchedFilter::new(&waveform.samples(config.fs_hz), waveform.band(), config.fs_hz, config.capture_len);
        let spd = SpdBf::new(elements, config.sound_speed_m_s, config.conical_resolution_rad);
        let grid = DirectionGrid::new(config.search_step_rad);
        let pulse = (waveform.duration_s * config.fs_hz).ceil() as usize;
        Self {
            config,
            waveform,
            filter,
            spd,
            grid,
            elements: elements.len(),
            energy: 0.0,
            envelopes: Vec::new(),
            work: Vec::new(),
            segment: SegmentTransform::new((pulse + pulse / 4).next_power_of_two()),
            snapshot: Snapshot { freqs_hz: Vec::new(), spectra: Vec::new() },
            grid_lookups: std::sync::OnceLock::new(),
            grid_powers: Vec::new(),
        }
    }

    /// Range and direction from one capture per element.
    pub fn process(&mut self, captures: &[Vec<f64>]) -> PingEstimate {
        let spectra: Vec<_> = captures.iter().map(|x| self.filter.spectrum(x)).collect();
        self.process_spectra(captures, &spectra)
    }

    /// [`Receiver::process`] with the captures' spectra already computed (by a
    /// [`crate::dsp::modes::ModeBank`] of the same lengths, say).
    pub fn process_spectra(&mut self, captures: &[Vec<f64>], spectra: &[Vec<super::Complex>]) -> PingEstimate {
        let range = self.distributions(captures, spectra);
        let spd = &self.spd;
        let lookups = self.grid_lookups.get_or_init(|| spd.lookups(&self.grid.directions()));
        spd.powers_at(lookups, &mut self.grid_powers);
        let powers = &self.grid_powers;
        let (direction, _) = self.grid.search_indexed(|i| powers[i], |u| spd.power(u));
        let (azimuth, inclination) = azimuth_inclination(&direction);
        PingEstimate { range, direction, azimuth, inclination }
    }

    /// The pseudo-distributions of one ping without the direction search: the range
    /// distribution (eq. 4-5, returned) and the SPD-BF tables of the direct-path segment,
    /// read afterwards at any direction with [`Receiver::beam_power`] or
    /// [`Receiver::beam_pattern`] (what the iUSBL particle filter does, at its
    /// particles only: rypkema sec. 3.3.4).
    pub fn distributions(&mut self, captures: &[Vec<f64>], spectra: &[Vec<super::Complex>]) -> RangeEstimate {
        let c = &self.config;
        self.envelopes.resize_with(spectra.len(), Vec::new);
        for (x, e) in spectra.iter().zip(self.envelopes.iter_mut()) {
            self.filter.envelope_into(x, &mut self.work, e);
        }
        let range = estimate_range(&self.envelopes, c.gate_samples, c.fs_hz, c.sound_speed_m_s);
        // the direct-path segment: the pulse from a little before the detected onset
        let pulse = (self.waveform.duration_s * c.fs_hz).ceil() as usize;
        let start = (range.lag.round() as usize).saturating_sub(pulse / 8);
        self.segment.transform(captures, start, self.waveform.band(), c.fs_hz, &mut self.snapshot);
        self.spd.compute(&self.snapshot);
        self.energy = self.snapshot.energies().iter().sum();
        range
    }

    /// The SPD-BF power toward `u` for the last processed ping (the beam map).
    pub fn beam_power(&self, u: &Vector3<f64>) -> f64 {
        self.spd.power(u)
    }

    /// The beam pattern toward `u` for the last processed ping, in [0, 1]: the SPD power
    /// less its constant (M - 2) sum E_m (the CBF power, by the identity of
    /// [`SpdBf`]) over its largest possible value M sum E_m (Cauchy-Schwarz), 1 only
    /// where every element adds in phase.
    pub fn beam_pattern(&self, u: &Vector3<f64>) -> f64 {
        let m = self.elements as f64;
        if self.energy <= 0.0 {
            return 0.0;
        }
        ((self.spd.power(u) - (m - 2.0) * self.energy) / (m * self.energy)).clamp(0.0, 1.0)
    }

    /// The waveform this receiver is matched to.
    pub fn waveform(&self) -> &Lfm {
        &self.waveform
    }
}

/// The receiver of a vehicle commanded by a beacon's choice of chirp (rypkema sec. 4.2):
/// the mode bank identifies which template the ping is, then that mode's PHAT matched
/// filter and SPD beamformer produce the pseudo-distributions. Every capture is
/// transformed once, for the bank and the mode's receiver alike.
#[derive(Debug)]
pub struct ModeReceiver {
    bank: super::modes::ModeBank,
    receivers: Vec<Receiver>,
    /// The captures' spectra and the transform's buffer, kept from ping to ping.
    spectra: Vec<Vec<super::Complex>>,
    padded: Vec<f64>,
}

/// What a [`ModeReceiver`] made of one ping.
#[derive(Debug, Clone, PartialEq)]
pub struct ModePing {
    /// The mode identified (index into the waveforms).
    pub mode: usize,
    /// The range pseudo-distribution of that mode's matched filter.
    pub range: RangeEstimate,
}

impl ModeReceiver {
    /// A receiver for `waveforms` (one per mode) on the array `elements`.
    pub fn new(waveforms: &[Lfm], elements: &[Vector3<f64>], config: ReceiverConfig) -> Self {
        let fs = config.fs_hz;
        let filters = waveforms
            .iter()
            .map(|m| MatchedFilter::classical(&m.samples(fs), m.band(), fs, config.capture_len))
            .collect();
        let centres = waveforms.iter().map(|m| (m.f0_hz + m.f1_hz) / 2.0).collect();
        let bank = super::modes::ModeBank::with_array(filters, centres, elements.to_vec(), config.sound_speed_m_s);
        let receivers = waveforms.iter().map(|w| Receiver::new(*w, elements, config.clone())).collect();
        Self { bank, receivers, spectra: Vec::new(), padded: Vec::new() }
    }

    /// Identifies the mode with the bank's search gated to `lags` (samples from the
    /// capture start: around the navigation filter's predicted range once it has
    /// converged, the whole capture otherwise) unless the whole capture's strongest
    /// response is more than twice the gated one, then computes that mode's
    /// pseudo-distributions; if they show no pulse, the strongest mode's instead.
    pub fn process(&mut self, captures: &[Vec<f64>], lags: std::ops::Range<usize>) -> ModePing {
        self.bank.spectra_into(captures, &mut self.padded, &mut self.spectra);
        let spectra = &self.spectra;
        let all = self.bank.responses(spectra, 0..usize::MAX);
        let strongest = super::matched_filter::argmax(&all);
        let mut mode = strongest;
        if lags.start > 0 || lags.end < self.receivers[0].config.capture_len {
            // the gate is a prediction: a response outside it twice as strong as any
            // inside wins (a new beacon, a filter converged on a reflection)
            let gated = self.bank.responses(spectra, lags);
            let best = super::matched_filter::argmax(&gated);
            if gated[best] >= 0.5 * all[strongest] {
                mode = best;
            }
        }
        let mut range = self.receivers[mode].distributions(captures, spectra);
        if !range.detected() && mode != strongest {
            // the gated choice shows no pulse: the whole capture's strongest does
            mode = strongest;
            range = self.receivers[mode].distributions(captures, spectra);
        }
        ModePing { mode, range }
    }

    /// The receiver of mode `mode` (its beam pattern is the last ping's when that ping
    /// was of this mode).
    pub fn receiver(&self, mode: usize) -> &Receiver {
        &self.receivers[mode]
    }

    pub fn modes(&self) -> usize {
        self.receivers.len()
    }
}

/// What one communication frame gives.
#[derive(Debug, Clone, PartialEq)]
pub struct FrameEstimate {
    /// Range from frame synchronisation (eq. 12), m.
    pub range_m: f64,
    /// Radial speed from the tone's Doppler shift, positive closing (eq. 9, 15), m/s.
    pub radial_speed_m_s: f64,
    /// The synchronisation on the pilots: lag, element agreement, lag distribution.
    pub sync: RangeEstimate,
    /// Range of lag `i` of `sync.distribution`: `i * metres_per_lag - offset_m`.
    pub metres_per_lag: f64,
    pub offset_m: f64,
    /// Azimuth and inclination by SPD-BF on the pilot section (rad; `None` with a single
    /// element).
    pub direction: Option<(f64, f64)>,
}

/// A garin2024 frame received on `elements` (one capture each, from the transmit epoch):
/// the Doppler speed from the tone over the whole capture (baseband, decimation to about
/// 400 Hz, periodogram maximum within 80 Hz; eq. 9's single lag is only a baseline), then
/// synchronisation on the pilots time-scaled by that Doppler (eq. 10-12), then SPD-BF on
/// the pilot section. `config` gives the sample rate, sound speed, element gate and
/// beamforming grids (its `capture_len` is not used: the captures' length is).
pub fn receive_frame(
    frame: &PskFrame,
    elements: &[Vector3<f64>],
    config: &ReceiverConfig,
    captures: &[Vec<f64>],
) -> FrameEstimate {
    let (fs, sound) = (config.fs_hz, config.sound_speed_m_s);
    let n = captures[0].len();
    // Doppler speed from the tone (no synchronisation needed)
    let d = (fs / 400.0).round() as usize;
    let z = baseband(&captures[0], frame.f_pt_hz, fs, d);
    let f_d = periodogram_frequency(&z, fs / d as f64, 80.0);
    let v = radial_speed(f_d, frame.f_pt_hz, sound);
    // then synchronise on the Doppler-compensated pilots (eq. 10-12)
    let alpha = 1.0 + v / sound;
    let (template, t_start) = frame.pilot_template_scaled(fs, alpha);
    let mf = MatchedFilter::classical(&template, frame.band(), fs, n);
    let envelopes: Vec<Vec<f64>> = captures.iter().map(|x| mf.envelope(x)).collect();
    let sync = estimate_range(&envelopes, config.gate_samples, fs, sound);
    let range_m = sound * (alpha * sync.lag / fs - t_start); // eq. 12
    let direction = (elements.len() > 1).then(|| {
        let snap = Snapshot::from_segment(captures, sync.lag.round() as usize, template.len(), frame.band(), fs);
        let mut spd = SpdBf::new(elements, sound, config.conical_resolution_rad);
        spd.compute(&snap);
        let (u, _) = DirectionGrid::new(config.search_step_rad).search(|u| spd.power(u));
        azimuth_inclination(&u)
    });
    FrameEstimate {
        range_m,
        radial_speed_m_s: v,
        sync,
        metres_per_lag: alpha * sound / fs,
        offset_m: sound * t_start,
        direction,
    }
}
