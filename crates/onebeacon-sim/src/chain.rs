//! The receiver chain on captures from any recorder: the mode bank, then the receiver
//! of the identified mode (rypkema chirps), or the garin frame receiver; what `onebeacon
//! dsp process` and the Python `dsp.process` run.

use crate::scenario::ping::{PingConfig, WaveformKind};
use nalgebra::Vector3;
use onebeacon::dsp::matched_filter::MatchedFilter;
use onebeacon::dsp::modes::ModeBank;
use onebeacon::dsp::receiver::{Receiver, ReceiverConfig, receive_frame};
use onebeacon::dsp::waveform::rypkema_modes;
use serde_json::json;

/// A capture too short for the chain.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{len} samples per capture; at least one 20 ms pulse ({pulse} samples) is needed")]
pub struct ChainError {
    pub len: usize,
    pub pulse: usize,
}

/// Whether a matched-filter output shows a pulse, its statistic and the threshold.
fn detection(r: &onebeacon::dsp::matched_filter::RangeEstimate) -> (bool, f64, f64) {
    (r.detected(), r.peak_ratio(), onebeacon::dsp::matched_filter::detection_threshold(r.distribution.len()))
}

/// What the receiver found in one capture, and what its output files need.
pub struct Found {
    pub result: serde_json::Value,
    pub text: String,
    pub distribution: Vec<f64>,
    pub metres_per_lag: f64,
    pub offset_m: f64,
    pub range_m: f64,
    /// The mode, azimuth and inclination (chirps), for beam.png.
    pub beam: Option<(usize, f64, f64)>,
}

/// The receiver chain for captures of one length: the mode bank, then the receiver of
/// the identified mode (chirps), or [`receive_frame`] (garin frames).
pub struct Chain {
    config: PingConfig,
    elements: Vec<Vector3<f64>>,
    receiver: ReceiverConfig,
    /// Chirps: the bank and the receivers of the modes met so far.
    bank: Option<(ModeBank, Vec<Option<Receiver>>)>,
}

impl Chain {
    /// The chain for captures of `len` samples per element.
    pub fn new(config: PingConfig, len: usize) -> Result<Self, ChainError> {
        let pulse = (rypkema_modes()[0].duration_s * config.capture.fs_hz) as usize;
        if len < pulse {
            return Err(ChainError { len, pulse });
        }
        let elements = config.elements();
        let fs = config.capture.fs_hz;
        let receiver = ReceiverConfig {
            fs_hz: fs,
            capture_len: len,
            sound_speed_m_s: config.sound_speed_m_s(),
            ..ReceiverConfig::default()
        };
        let bank = (config.waveform.kind == WaveformKind::Chirp).then(|| {
            let modes = rypkema_modes();
            let filters = modes.iter().map(|m| MatchedFilter::classical(&m.samples(fs), m.band(), fs, len)).collect();
            let centres = modes.iter().map(|m| (m.f0_hz + m.f1_hz) / 2.0).collect();
            let bank = ModeBank::with_array(filters, centres, elements.clone(), config.sound_speed_m_s());
            (bank, modes.iter().map(|_| None).collect())
        });
        Ok(Self { config, elements, receiver, bank })
    }

    /// One capture: one sample vector per element, starting at the transmit epoch.
    pub fn process(&mut self, captures: &[Vec<f64>]) -> Found {
        // a recorder's DC offset carries no ping (the bands start at 9 kHz) but would
        // raise the matched filter's floor towards the detection threshold
        let centred: Vec<Vec<f64>> = captures
            .iter()
            .map(|c| {
                let mean = c.iter().sum::<f64>() / c.len().max(1) as f64;
                c.iter().map(|x| x - mean).collect()
            })
            .collect();
        let captures = &centred[..];
        let Some((bank, receivers)) = &mut self.bank else { return self.frame(captures) };
        let spectra = bank.spectra(captures);
        let mode = bank.identify(&spectra);
        let rx = receivers[mode]
            .get_or_insert_with(|| Receiver::new(rypkema_modes()[mode], &self.elements, self.receiver.clone()));
        let est = rx.process_spectra(captures, &spectra);
        let (detected, statistic, threshold) = detection(&est.range);
        let when = |v: serde_json::Value| if detected { v } else { serde_json::Value::Null };
        let result = json!({
            "detected": detected,
            "detection_statistic": statistic,
            "detection_threshold": threshold,
            "range_m": when(json!(est.range.range_m)),
            "azimuth_deg": when(json!(est.azimuth.to_degrees())),
            "inclination_deg": when(json!(est.inclination.to_degrees())),
            "mode": when(json!(mode + 1)),
            "radial_speed_m_s": serde_json::Value::Null,
            "consistent": detected && est.range.consistent,
        });
        let text = if !detected {
            format!(
                "no ping detected: statistic {statistic:.4} below the threshold {threshold:.4} (false alarms under 1 in 2000 captures)"
            )
        } else {
            format!(
                "mode {}, range {:.2} m, azimuth {:.1} deg, inclination {:.1} deg{}",
                mode + 1,
                est.range.range_m,
                est.azimuth.to_degrees(),
                est.inclination.to_degrees(),
                if est.range.consistent { "" } else { " (elements disagree: range suspect)" }
            )
        };
        Found {
            result,
            text,
            metres_per_lag: self.config.sound_speed_m_s() / self.config.capture.fs_hz,
            offset_m: 0.0,
            range_m: est.range.range_m,
            beam: Some((mode, est.azimuth, est.inclination)),
            distribution: est.range.distribution,
        }
    }

    /// The beamformer power towards unit vector `u` of the receiver of `mode`, once
    /// that mode was met (0 otherwise).
    pub fn beam_power(&self, mode: usize, u: &Vector3<f64>) -> f64 {
        let rx = self.bank.as_ref().and_then(|(_, receivers)| receivers[mode].as_ref());
        rx.map_or(0.0, |rx| rx.beam_power(u))
    }

    /// A garin frame through [`receive_frame`]: range, Doppler speed, direction, when
    /// the pilots' synchronisation passes the same detection test as a chirp.
    fn frame(&self, captures: &[Vec<f64>]) -> Found {
        let est = receive_frame(&self.config.frame(), &self.elements, &self.receiver, captures);
        let (detected, statistic, threshold) = detection(&est.sync);
        let (range_m, v) = (est.range_m, est.radial_speed_m_s);
        let (az, inc) = est.direction.unwrap_or((f64::NAN, f64::NAN));
        let num = |x: f64| if detected && x.is_finite() { json!(x) } else { serde_json::Value::Null };
        let result = json!({
            "detected": detected,
            "detection_statistic": statistic,
            "detection_threshold": threshold,
            "range_m": num(range_m),
            "azimuth_deg": num(az.to_degrees()),
            "inclination_deg": num(inc.to_degrees()),
            "mode": serde_json::Value::Null,
            "radial_speed_m_s": num(v),
            "consistent": detected && est.sync.consistent,
        });
        let direction = if self.elements.len() > 1 {
            format!(", azimuth {:.1} deg, inclination {:.1} deg", az.to_degrees(), inc.to_degrees())
        } else {
            String::new()
        };
        let text = if detected {
            format!("garin frame: range {range_m:.2} m, Doppler speed {v:.3} m/s (closing positive){direction}")
        } else {
            format!(
                "no frame detected: statistic {statistic:.4} below the threshold {threshold:.4} (false alarms under 1 in 1000 captures)"
            )
        };
        Found {
            result,
            text,
            // lags in metres, scaled by the Doppler compensation, less the pilots' offset
            distribution: est.sync.distribution,
            metres_per_lag: est.metres_per_lag,
            offset_m: est.offset_m,
            range_m,
            beam: None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_distr::{Distribution, Normal};

    /// A recorder's DC offset changes nothing: the same noise with and without 0.3 of
    /// offset gives the same detection statistic (the offset alone once scored 0.0668
    /// against the threshold of 0.07).
    #[test]
    fn a_dc_offset_changes_nothing() {
        let c = PingConfig::default();
        let (n, elements) = (c.capture.samples, c.elements().len());
        let mut rng = rand_pcg::Pcg64::seed_from_u64(3);
        let noise = Normal::new(0.0, 1e-3).unwrap();
        let plain: Vec<Vec<f64>> = (0..elements).map(|_| (0..n).map(|_| noise.sample(&mut rng)).collect()).collect();
        let offset: Vec<Vec<f64>> = plain.iter().map(|ch| ch.iter().map(|x| x + 0.3).collect()).collect();
        let statistic = |captures: &[Vec<f64>]| {
            let found = Chain::new(c.clone(), n).unwrap().process(captures);
            (found.result["detection_statistic"].as_f64().unwrap(), found.result["detected"].as_bool().unwrap())
        };
        let ((a, _), (b, detected)) = (statistic(&plain), statistic(&offset));
        assert!((a - b).abs() < 1e-9, "{a} against {b}");
        assert!(!detected, "noise with an offset is no ping: {b}");
    }
}
