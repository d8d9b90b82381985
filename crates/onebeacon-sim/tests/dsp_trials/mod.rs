//! Trials of the receiver chain on simulated pings (rypkema 3.2, 4.2; garin2024 eqs. 9,
//! 12): tests/dsp_chain.rs checks them at small counts, examples/dsp_trials.rs measures
//! them at the counts behind docs/reproductions/receiver.md's tables.
#![allow(dead_code)] // each includer uses a part

use nalgebra::{Matrix3, Vector3};
use onebeacon::dsp::beamform::{angle_between, azimuth_inclination, direction, doa_crb, pyramid_8cm};
use onebeacon::dsp::matched_filter::MatchedFilter;
use onebeacon::dsp::modes::ModeBank;
use onebeacon::dsp::receiver::{Receiver, ReceiverConfig, receive_frame};
use onebeacon::dsp::waveform::{Lfm, rypkema_modes};
use onebeacon_sim::acoustics::channel::{Channel, simulate_ping};
use onebeacon_sim::scenario::ping::PingConfig;
use onebeacon_sim::seed::{Stream, gauss, rng};
use rand::RngExt;
use std::f64::consts::{PI, TAU};

pub struct Errors {
    pub range_m: Vec<f64>,
    pub azimuth_deg: Vec<f64>,
    pub direction_deg: Vec<f64>,
    /// |azimuth error| / the CRB's sigma for that direction (`doa_crb`).
    pub azimuth_over_crb: Vec<f64>,
}

/// The `q` quantile of `v` (nearest rank).
pub fn percentile(v: &[f64], q: f64) -> f64 {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    s[((s.len() - 1) as f64 * q).round() as usize]
}

pub fn rms(v: &[f64]) -> f64 {
    (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt()
}

/// A receiver 300 m deep and a source from a random direction within +-45 deg of
/// elevation at `range` m (free field).
fn free_field(geo: &mut rand_pcg::Pcg64Mcg, range: f64) -> (Vector3<f64>, Vector3<f64>) {
    let u = direction(TAU * geo.random::<f64>(), PI / 4.0 + PI / 2.0 * geo.random::<f64>());
    let receiver = Vector3::new(0.0, 0.0, 300.0);
    (receiver, receiver + u * range)
}

/// One capture of `samples` samples of unit white noise per element.
fn noise_capture(elements: usize, samples: usize, noise: &mut rand_pcg::Pcg64Mcg) -> Vec<Vec<f64>> {
    (0..elements).map(|_| (0..samples).map(|_| gauss(noise, 1.0)).collect()).collect()
}

/// `n` pings from random directions (elevation within +-45 deg, where azimuth is well
/// defined) at 30-290 m, through `channel`, processed by the receiver. `multipath`: 5 m
/// of water, beacon at 1 m, receiver at 2.5 m, horizontal ranges.
pub fn chirp_errors(n: usize, channel: &Channel, multipath: bool, seed: u64) -> Errors {
    let chirp = Lfm::new(7e3, 9e3, 0.02);
    let el = pyramid_8cm();
    let mut rx = Receiver::new(chirp, &el, ReceiverConfig::default());
    let mut geo = rng(seed, 0, Stream::Initial);
    let mut noise = rng(seed, 0, Stream::Acoustic);
    let mut e = Errors { range_m: vec![], azimuth_deg: vec![], direction_deg: vec![], azimuth_over_crb: vec![] };
    let two_e_over_n0 = 10f64.powf(channel.snr_db.unwrap_or(f64::INFINITY) / 10.0);
    for _ in 0..n {
        let range = 30.0 + 260.0 * geo.random::<f64>();
        let (receiver, source) = if multipath {
            let az = TAU * geo.random::<f64>();
            let rx = Vector3::new(0.0, 0.0, 2.5);
            (rx, rx + Vector3::new(range * az.cos(), range * az.sin(), -1.5))
        } else {
            free_field(&mut geo, range)
        };
        let caps = simulate_ping(&chirp, &source, &receiver, &Matrix3::identity(), &el, channel, &mut noise);
        let est = rx.process(&caps);
        let truth = (source - receiver).normalize();
        let (az_true, incl_true) = azimuth_inclination(&truth);
        let crb = doa_crb(&el, az_true, incl_true, chirp.rms_frequency_hz(), two_e_over_n0, channel.sound_speed_m_s)
            .expect("elevations within +-45 deg");
        let daz = (est.azimuth - az_true + PI).rem_euclid(TAU) - PI;
        e.range_m.push((est.range.range_m - (source - receiver).norm()).abs());
        e.azimuth_deg.push(daz.abs().to_degrees());
        e.direction_deg.push(angle_between(&est.direction, &truth).to_degrees());
        e.azimuth_over_crb.push(daz.abs() / crb[(0, 0)].sqrt());
    }
    e
}

/// The share of `n` pings at `snr_db` whose mode the bank identifies. With `gate_m`, the
/// search is gated to +-`gate_m` around a predicted range that is off by a Gaussian error
/// of sigma `gate_m / 3` (a navigation filter's prediction).
pub fn mode_accuracy(n: usize, snr_db: f64, seed: u64, gate_m: Option<f64>) -> f64 {
    let fs = 37_500.0;
    let c = 1500.0;
    let modes = rypkema_modes();
    let el = pyramid_8cm();
    let filters = modes.iter().map(|m| MatchedFilter::classical(&m.samples(fs), m.band(), fs, 8000)).collect();
    let centres = modes.iter().map(|m| (m.f0_hz + m.f1_hz) / 2.0).collect();
    let bank = ModeBank::with_array(filters, centres, el.clone(), c);
    let ch = Channel { snr_db: Some(snr_db), ..Channel::default() };
    let mut g = rng(seed, 0, Stream::Initial);
    let mut noise = rng(seed, 0, Stream::Acoustic);
    let mut right = 0;
    for _ in 0..n {
        let mode = (g.random::<f64>() * 4.0) as usize % 4;
        let range = 30.0 + 260.0 * g.random::<f64>();
        let receiver = Vector3::new(0.0, 0.0, 3.0);
        let src = Vector3::new(range, 0.0, 1.0);
        let caps = simulate_ping(&modes[mode], &src, &receiver, &Matrix3::identity(), &el, &ch, &mut noise);
        let spectra = bank.spectra(&caps);
        let found = match gate_m {
            None => bank.identify(&spectra),
            Some(w) => {
                let predicted = (src - receiver).norm() + gauss(&mut g, w / 3.0);
                let lag = |r: f64| (r.max(0.0) / c * fs).round() as usize;
                bank.identify_within(&spectra, lag(predicted - w)..lag(predicted + w))
            }
        };
        right += usize::from(found == mode);
    }
    right as f64 / n as f64
}

/// garin2024's pure tone (f_pt = 20 kHz, fs = 96.153 kHz, Table 5) over a 300 ms frame
/// at 2E/N0 = 20 dB, |v_r| <= 3 m/s: Doppler speed RMSE of the periodogram (ML)
/// estimator on the baseband decimated to 400 Hz and of eq. 9 (single lag) on the
/// oversampled baseband (4 kHz), with the bound. Returns (ML, eq. 9, bound), m/s.
pub fn tone_doppler(trials: usize, seed: u64) -> (f64, f64, f64) {
    use onebeacon::dsp::doppler::{
        baseband, frequency_crlb_hz, periodogram_frequency, pulse_pair_frequency, radial_speed,
    };
    let (fs, f_pt, c, t_d) = (96_153.0, 20_000.0, 1500.0, 0.3);
    let n = (t_d * fs) as usize;
    let snr = 100.0; // 2E/N0 = 20 dB
    let eta = snr / n as f64; // per sample, real tone of unit amplitude: power 1/2
    let sigma = (0.5 / eta).sqrt();
    let mut g = rng(seed, 0, Stream::Acoustic);
    let (mut se_kay, mut se_pp) = (0.0, 0.0);
    for _ in 0..trials {
        let v = 6.0 * g.random::<f64>() - 3.0;
        let alpha = 1.0 + v / c;
        let phi = TAU * g.random::<f64>();
        let x: Vec<f64> = (0..n)
            .map(|i| {
                (TAU * f_pt * alpha * i as f64 / fs + phi).cos()
                    + sigma * g.sample::<f64, _>(rand_distr::StandardNormal)
            })
            .collect();
        let (d_kay, d_pp) = (240, 24);
        let kay = radial_speed(periodogram_frequency(&baseband(&x, f_pt, fs, d_kay), fs / d_kay as f64, 60.0), f_pt, c);
        let pp = radial_speed(pulse_pair_frequency(&baseband(&x, f_pt, fs, d_pp), fs / d_pp as f64), f_pt, c);
        se_kay += (kay - v).powi(2);
        se_pp += (pp - v).powi(2);
    }
    // the bound on the decimated complex baseband: eta_d N_d = (2E/N0) / 2
    let d = 240usize;
    let n_d = n / d;
    let eta_d = snr / 2.0 / n_d as f64;
    let bound = radial_speed(frequency_crlb_hz(eta_d, n_d, d as f64 / fs), f_pt, c);
    ((se_kay / trials as f64).sqrt(), (se_pp / trials as f64).sqrt(), bound)
}

/// garin2024 eq. 12: range from frame synchronisation on the pilot sequence, one
/// hydrophone, 30-300 m, 2E/N0 = 20 dB for the pilot sequence (the part the
/// synchronisation uses; the whole frame carries about 14 dB more). Returns the range
/// errors, m.
pub fn frame_sync_errors(n: usize, seed: u64) -> Vec<f64> {
    use onebeacon::dsp::Complex;
    use onebeacon::dsp::matched_filter::{argmax, parabolic_peak};
    use onebeacon::dsp::waveform::{PskFrame, Waveform};
    let (fs, c) = (96_153.0, 1500.0);
    let capture = (0.55 * fs) as usize;
    let mut g = rng(seed, 0, Stream::Initial);
    let mut noise = rng(seed, 0, Stream::Acoustic);
    let qpsk = |g: &mut rand_pcg::Pcg64Mcg| {
        let (a, b): (bool, bool) = (g.random(), g.random());
        Complex::new(if a { 1.0 } else { -1.0 }, if b { 1.0 } else { -1.0 }) / 2f64.sqrt()
    };
    let frame = PskFrame::garin((0..1740).map(|_| qpsk(&mut g)).collect());
    let (template, t_start) = frame.pilot_template(fs);
    let mf = MatchedFilter::classical(&template, frame.band(), fs, capture);
    let frame_energy: f64 = (0..(frame.duration_s() * fs) as usize).map(|i| frame.value(i as f64 / fs).powi(2)).sum();
    let pilot_energy: f64 = template.iter().map(|v| v * v).sum();
    let snr_db = 20.0 + 10.0 * (frame_energy / pilot_energy).log10();
    let ch =
        Channel { fs_hz: fs, capture_len: capture, sound_speed_m_s: c, snr_db: Some(snr_db), ..Channel::default() };
    let one = [Vector3::zeros()];
    (0..n)
        .map(|_| {
            let range = 30.0 + 270.0 * g.random::<f64>();
            let src = Vector3::new(range, 0.0, 2.0);
            let rx = Vector3::new(0.0, 0.0, 2.0);
            let caps = simulate_ping(&frame, &src, &rx, &Matrix3::identity(), &one, &ch, &mut noise);
            let env = mf.envelope(&caps[0]);
            let lag = parabolic_peak(&env, argmax(&env));
            let estimate = c * (lag / fs - t_start); // eq. 12, with t0 = lag / fs + span T
            (estimate - range).abs()
        })
        .collect()
}

/// The detection statistic (the peak of the combined, unit-energy matched-filter output,
/// `RangeEstimate::peak_ratio`) of the rypkema chirp on the 5-element array: over `n`
/// noise-only captures, then over `n_per_snr` pings at each of `snrs_db` (2E/N0 per
/// element; random directions at 30-290 m). Returns the statistics of each set and the
/// number of lags they were taken over.
pub fn chirp_detection_statistics(n: usize, snrs_db: &[f64], n_per_snr: usize, seed: u64) -> (Vec<Vec<f64>>, usize) {
    let chirp = Lfm::new(7e3, 9e3, 0.02);
    let el = pyramid_8cm();
    let cfg = ReceiverConfig::default();
    let mut rx = Receiver::new(chirp, &el, cfg.clone());
    let mut noise = rng(seed, 0, Stream::Acoustic);
    let mut lags = 0;
    let noise_only = (0..n)
        .map(|_| {
            let range = rx.process(&noise_capture(el.len(), cfg.capture_len, &mut noise)).range;
            lags = range.distribution.len();
            range.peak_ratio()
        })
        .collect();
    let mut geo = rng(seed, 0, Stream::Initial);
    let mut sets = vec![noise_only];
    for &snr in snrs_db {
        let channel = Channel { snr_db: Some(snr), ..Channel::default() };
        let set = (0..n_per_snr)
            .map(|_| {
                let range = 30.0 + 260.0 * geo.random::<f64>();
                let (receiver, source) = free_field(&mut geo, range);
                let caps = simulate_ping(&chirp, &source, &receiver, &Matrix3::identity(), &el, &channel, &mut noise);
                rx.process(&caps).range.peak_ratio()
            })
            .collect();
        sets.push(set);
    }
    (sets, lags)
}

/// A ping config of garin2024's frame at `snr_db` (2E/N0 of the whole frame, per
/// element) and radial speed `v` m/s, in a 52000-sample capture.
pub fn garin_frame_config(snr_db: f64, v: f64) -> PingConfig {
    let text = format!(
        "[waveform]\nkind = \"garin_frame\"\n[capture]\nfs_hz = 96153\nsamples = 52000\n\
         [geometry]\nradial_speed_m_s = {v}\n[noise]\nsnr_db = {snr_db}\n"
    );
    PingConfig::parse(&text, "frame.toml").expect("a valid ping config")
}

/// The receiver configuration for captures of `c`.
pub fn frame_receiver(c: &PingConfig) -> ReceiverConfig {
    ReceiverConfig {
        fs_hz: c.capture.fs_hz,
        capture_len: c.capture.samples,
        sound_speed_m_s: c.sound_speed_m_s(),
        ..ReceiverConfig::default()
    }
}

/// One set of garin frames through `receive_frame`: the detection statistic of the
/// pilots' synchronisation, its peak over the mean of its distribution, and how many
/// frames were synchronised within 1 m (none for noise only).
pub struct FrameSet {
    pub statistic: Vec<f64>,
    pub peak_over_mean: Vec<f64>,
    pub synchronised: usize,
}

/// [`FrameSet`]s over `n` noise-only captures, then over `n_per_snr` frames at each of
/// `snrs_db`, radial speeds uniform in +-2 m/s. Also returns the number of lags.
pub fn frame_detection_statistics(n: usize, snrs_db: &[f64], n_per_snr: usize, seed: u64) -> (Vec<FrameSet>, usize) {
    let c = garin_frame_config(20.0, 0.0);
    let elements = c.elements();
    let config = frame_receiver(&c);
    let mut noise = rng(seed, 0, Stream::Acoustic);
    let peak_to_mean = |d: &[f64]| d.iter().copied().fold(0.0, f64::max) * d.len() as f64 / d.iter().sum::<f64>();
    let mut lags = 0;
    let frame = c.frame();
    let mut noise_only = FrameSet { statistic: vec![], peak_over_mean: vec![], synchronised: 0 };
    for _ in 0..n {
        let caps = noise_capture(elements.len(), c.capture.samples, &mut noise);
        let sync = receive_frame(&frame, &elements, &config, &caps).sync;
        lags = sync.distribution.len();
        noise_only.statistic.push(sync.peak_ratio());
        noise_only.peak_over_mean.push(peak_to_mean(&sync.distribution));
    }
    let mut geo = rng(seed, 0, Stream::Initial);
    let mut sets = vec![noise_only];
    for &snr in snrs_db {
        let mut set = FrameSet { statistic: vec![], peak_over_mean: vec![], synchronised: 0 };
        for _ in 0..n_per_snr {
            let c = garin_frame_config(snr, -2.0 + 4.0 * geo.random::<f64>());
            let caps = simulate_ping(
                &c.signal(),
                &c.source(),
                &c.receiver(),
                &c.attitude(),
                &elements,
                &c.channel(),
                &mut noise,
            );
            let est = receive_frame(&c.frame(), &elements, &config, &caps);
            set.synchronised += usize::from((est.range_m - (c.source() - c.receiver()).norm()).abs() < 1.0);
            set.statistic.push(est.sync.peak_ratio());
            set.peak_over_mean.push(peak_to_mean(&est.sync.distribution));
        }
        sets.push(set);
    }
    (sets, lags)
}
