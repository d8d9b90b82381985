//! The receiver chain on simulated pings (rypkema 3.2, 4.2). CI runs small counts; the
//! `#[ignore]`d tests measure with large counts:
//! `cargo test --release -p onebeacon-sim --test dsp_chain -- --ignored --nocapture`.

use nalgebra::{Matrix3, Vector3};
use onebeacon::dsp::beamform::{angle_between, azimuth_inclination, direction, doa_crb, pyramid_8cm};
use onebeacon::dsp::matched_filter::MatchedFilter;
use onebeacon::dsp::modes::ModeBank;
use onebeacon::dsp::receiver::{Receiver, ReceiverConfig};
use onebeacon::dsp::waveform::{Lfm, rypkema_modes};
use onebeacon_sim::acoustics::channel::{Boundaries, Channel, simulate_ping};
use onebeacon_sim::seed::{Stream, gauss, rng};
use rand::RngExt;
use std::f64::consts::{PI, TAU};

struct Errors {
    range_m: Vec<f64>,
    azimuth_deg: Vec<f64>,
    direction_deg: Vec<f64>,
    /// |azimuth error| / the CRB's sigma for that direction (`doa_crb`).
    azimuth_over_crb: Vec<f64>,
}

fn percentile(v: &[f64], q: f64) -> f64 {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    s[((s.len() - 1) as f64 * q).round() as usize]
}

/// `n` pings from random directions (elevation within +-45 deg, where azimuth is well
/// defined) at 30-290 m, through `channel`, processed by the receiver.
fn run(n: usize, channel: &Channel, multipath: bool, seed: u64) -> Errors {
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
            // 5 m of water: beacon at 1 m, receiver at 2.5 m, horizontal ranges
            let az = TAU * geo.random::<f64>();
            let rx = Vector3::new(0.0, 0.0, 2.5);
            (rx, rx + Vector3::new(range * az.cos(), range * az.sin(), -1.5))
        } else {
            let u = direction(TAU * geo.random::<f64>(), PI / 4.0 + PI / 2.0 * geo.random::<f64>());
            let rx = Vector3::new(0.0, 0.0, 300.0);
            (rx, rx + u * range)
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

fn report(label: &str, e: &Errors) {
    eprintln!(
        "{label}: {} pings; 68 % range error {:.3} m, 68 % azimuth error {:.2} deg (68 % of error / CRB sigma: {:.2}, \
         0.99 at the bound), 68 % direction error {:.2} deg",
        e.range_m.len(),
        percentile(&e.range_m, 0.68),
        percentile(&e.azimuth_deg, 0.68),
        percentile(&e.azimuth_over_crb, 0.68),
        percentile(&e.direction_deg, 0.68)
    );
}

/// 20 dB per element, no multipath: 68 % of range errors under 0.2 m (the CRLB for five
/// elements is about 1.8 cm); azimuth errors within 1.5x the array's CRB per ping (2.1
/// deg level, growing as 1 / cos(elevation); `doa_crb`). The 2 deg is below the
/// bound at every elevation: no unbiased estimator reaches it at 20 dB.
#[test]
fn twenty_db_free_field_range_and_azimuth() {
    let e = run(30, &Channel::default(), false, 1);
    report("20 dB free field", &e);
    assert!(percentile(&e.range_m, 0.68) < 0.2);
    assert!(percentile(&e.azimuth_over_crb, 0.68) < 1.5);
}

#[test]
#[ignore]
fn measure_free_field_and_multipath() {
    report("20 dB free field", &run(1000, &Channel::default(), false, 2));
    let b = Boundaries { water_depth_m: 5.0, surface_coef: -1.0, bottom_coef: 0.5, wall_east_m: None, wall_coef: 0.0 };
    report(
        "20 dB, surface + bottom in 5 m",
        &run(1000, &Channel { boundaries: Some(b), ..Channel::default() }, true, 3),
    );
}

/// The share of `n` pings at `snr_db` whose mode the bank identifies. With `gate_m`, the
/// search is gated to +-`gate_m` around a predicted range that is off by a Gaussian error
/// of sigma `gate_m / 3` (a navigation filter's prediction).
fn mode_accuracy(n: usize, snr_db: f64, seed: u64, gate_m: Option<f64>) -> f64 {
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

/// Over 1000 pings at 10 dB the bank (classical matched filters, coherent combination
/// across elements at the strongest lags) is right on 98.1 % searching the whole
/// capture (incoherent only: 96.7 %), and on 99.8 % with the search gated to +-15 m
/// around a prediction (99.3 % over 7 x 300 pings of other seeds); CI checks smaller
/// counts against 95 % and 97.5 %.
#[test]
fn modes_are_identified_at_10_db() {
    let acc = mode_accuracy(60, 10.0, 5, None);
    let gated = mode_accuracy(150, 10.0, 1, Some(15.0));
    eprintln!("mode identification at 10 dB: {:.1} %, gated {:.1} %", 100.0 * acc, 100.0 * gated);
    assert!(acc >= 0.95);
    assert!(gated >= 0.975);
}

#[test]
#[ignore]
fn measure_mode_identification() {
    for snr in [0.0, 5.0, 10.0] {
        for gate in [None, Some(15.0), Some(5.0)] {
            eprintln!(
                "mode identification at {snr} dB over 1000 pings, gate {gate:?} m: {:.2} %",
                100.0 * mode_accuracy(1000, snr, 6, gate)
            );
        }
    }
}

/// garin2024's pure tone (f_pt = 20 kHz, fs = 96.153 kHz, Table 5) over a 300 ms frame
/// at 2E/N0 = 20 dB, |v_r| <= 3 m/s: Doppler speed RMSE of the periodogram (ML)
/// estimator on the baseband decimated to 400 Hz and of eq. 9 (single lag) on the
/// oversampled baseband (4 kHz), with the bound. Returns (ML, eq. 9, bound), m/s.
fn tone_doppler(trials: usize, seed: u64) -> (f64, f64, f64) {
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

#[test]
fn tone_doppler_speed_at_20_db() {
    let (kay, pp, bound) = tone_doppler(60, 8);
    eprintln!("Doppler speed RMSE at 20 dB: ML {kay:.4} m/s, eq. 9 {pp:.4} m/s, bound {bound:.4} m/s");
    assert!(kay < 0.05, "{kay}");
    assert!(kay < 1.5 * bound, "ML {kay} vs bound {bound}");
}

#[test]
#[ignore]
fn measure_tone_doppler() {
    let (kay, pp, bound) = tone_doppler(2000, 9);
    eprintln!(
        "Doppler speed RMSE at 20 dB over 2000 frames: ML {kay:.4} m/s ({:.2} x bound), eq. 9 {pp:.4} m/s ({:.2} x bound), bound {bound:.4} m/s",
        kay / bound,
        pp / bound
    );
}

/// garin2024 eq. 12: range from frame synchronisation on the pilot sequence, one
/// hydrophone, 30-300 m, 2E/N0 = 20 dB for the pilot sequence (the part the
/// synchronisation uses; the whole frame carries about 14 dB more). Returns the range
/// errors, m.
fn frame_sync_errors(n: usize, seed: u64) -> Vec<f64> {
    use onebeacon::dsp::Complex;
    use onebeacon::dsp::matched_filter::{argmax, parabolic_peak};
    use onebeacon::dsp::waveform::PskFrame;
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
    use onebeacon::dsp::waveform::Waveform;
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

#[test]
fn frame_sync_range_at_20_db() {
    let e = frame_sync_errors(20, 4);
    let rms = (e.iter().map(|v| v * v).sum::<f64>() / e.len() as f64).sqrt();
    eprintln!("frame-sync range RMS error at 20 dB: {rms:.4} m over {} frames", e.len());
    assert!(rms < 0.1, "{rms}");
}

#[test]
#[ignore]
fn measure_frame_sync() {
    let e = frame_sync_errors(500, 5);
    let rms = (e.iter().map(|v| v * v).sum::<f64>() / e.len() as f64).sqrt();
    eprintln!("frame-sync range RMS error at 20 dB over 500 frames: {rms:.4} m, 68 % {:.4} m", percentile(&e, 0.68));
}

/// garin2024's frame through `receive_frame`, at the radial speeds of an AUV (closing
/// and opening, 0.5-2 m/s): the Doppler speed within 0.05 m/s and the synchronised range
/// within 0.1 m of the geometry, and the direction within 5 deg of the truth.
#[test]
fn garin_frame_gives_range_doppler_speed_and_direction() {
    use onebeacon::dsp::receiver::receive_frame;
    use onebeacon_sim::scenario::ping::PingConfig;
    for v in [-2.0, 0.5, 1.5] {
        let text = format!(
            "[waveform]\nkind = \"garin_frame\"\n[capture]\nfs_hz = 96153\nsamples = 52000\n\
             [geometry]\nradial_speed_m_s = {v}\n[noise]\nsnr_db = 30\n"
        );
        let c = PingConfig::parse(&text, "frame.toml").unwrap();
        let elements = c.elements();
        let mut noise = rng(3, 0, Stream::Acoustic);
        let caps =
            simulate_ping(&c.signal(), &c.source(), &c.receiver(), &c.attitude(), &elements, &c.channel(), &mut noise);
        let config = ReceiverConfig {
            fs_hz: c.capture.fs_hz,
            capture_len: caps[0].len(),
            sound_speed_m_s: c.sound_speed_m_s(),
            ..ReceiverConfig::default()
        };
        let est = receive_frame(&c.frame(), &elements, &config, &caps);
        let rel = c.source() - c.receiver();
        assert!((est.radial_speed_m_s - v).abs() < 0.05, "v {v}: {}", est.radial_speed_m_s);
        assert!((est.range_m - rel.norm()).abs() < 0.1, "v {v}: range {} vs {}", est.range_m, rel.norm());
        let (az, inc) = est.direction.expect("a five-element array");
        let truth = c.attitude().transpose() * rel.normalize();
        assert!(angle_between(&direction(az, inc), &truth).to_degrees() < 5.0, "v {v}: direction");
    }
}

/// The detection statistic (the peak of the combined, unit-energy matched-filter
/// output) on noise-only captures and on pings at falling SNR.
#[test]
#[ignore]
fn measure_detection_statistic() {
    let chirp = Lfm::new(7e3, 9e3, 0.02);
    let el = pyramid_8cm();
    let mut rx = Receiver::new(chirp, &el, ReceiverConfig::default());
    let cfg = ReceiverConfig::default();
    let mut noise = rng(9, 0, Stream::Acoustic);
    let mut stats = Vec::new();
    for _ in 0..2000 {
        let caps: Vec<Vec<f64>> =
            (0..el.len()).map(|_| (0..cfg.capture_len).map(|_| gauss(&mut noise, 1.0)).collect()).collect();
        stats.push(rx.process(&caps).range.peak_ratio());
    }
    eprintln!(
        "noise only: median {:.4}, 99 % {:.4}, 99.9 % {:.4}, max {:.4}",
        percentile(&stats, 0.5),
        percentile(&stats, 0.99),
        percentile(&stats, 0.999),
        percentile(&stats, 1.0)
    );
    let mut geo = rng(9, 0, Stream::Initial);
    for snr in [-10.0, -5.0, 0.0, 5.0, 10.0, 20.0] {
        let channel = Channel { snr_db: Some(snr), ..Channel::default() };
        let mut s = Vec::new();
        for _ in 0..300 {
            let range = 30.0 + 260.0 * geo.random::<f64>();
            let u = direction(TAU * geo.random::<f64>(), PI / 4.0 + PI / 2.0 * geo.random::<f64>());
            let receiver = Vector3::new(0.0, 0.0, 300.0);
            let caps = simulate_ping(
                &chirp,
                &(receiver + u * range),
                &receiver,
                &Matrix3::identity(),
                &el,
                &channel,
                &mut noise,
            );
            s.push(rx.process(&caps).range.peak_ratio());
        }
        eprintln!(
            "{snr} dB: 1 % {:.4}, 5 % {:.4}, median {:.4}",
            percentile(&s, 0.01),
            percentile(&s, 0.05),
            percentile(&s, 0.5)
        );
    }
}

/// The detection statistic of garin2024's frame synchronisation (the peak of the
/// combined, unit-energy output of the pilots' matched filter) on noise-only captures
/// and on frames at falling SNR (2E/N0 of the whole frame: the pilots hold 7 % of it),
/// against the threshold the chirps use; and peak over mean, an alternative.
#[test]
#[ignore]
fn measure_frame_detection_statistic() {
    use onebeacon::dsp::matched_filter::detection_threshold;
    use onebeacon::dsp::receiver::receive_frame;
    use onebeacon_sim::scenario::ping::PingConfig;
    let config_text = |snr: f64, v: f64| {
        format!(
            "[waveform]\nkind = \"garin_frame\"\n[capture]\nfs_hz = 96153\nsamples = 52000\n\
             [geometry]\nradial_speed_m_s = {v}\n[noise]\nsnr_db = {snr}\n"
        )
    };
    let c = PingConfig::parse(&config_text(20.0, 0.0), "frame.toml").unwrap();
    let elements = c.elements();
    let config = ReceiverConfig {
        fs_hz: c.capture.fs_hz,
        capture_len: c.capture.samples,
        sound_speed_m_s: c.sound_speed_m_s(),
        ..ReceiverConfig::default()
    };
    let mut noise = rng(9, 0, Stream::Acoustic);
    let mut stats = Vec::new();
    let mut psr = Vec::new();
    let mut lags = 0;
    for _ in 0..100 {
        let caps: Vec<Vec<f64>> =
            (0..elements.len()).map(|_| (0..c.capture.samples).map(|_| gauss(&mut noise, 1.0)).collect()).collect();
        let sync = receive_frame(&c.frame(), &elements, &config, &caps).sync;
        lags = sync.distribution.len();
        stats.push(sync.peak_ratio());
        psr.push(peak_to_mean(&sync.distribution));
    }
    eprintln!(
        "noise only ({lags} lags, threshold {:.4}): median {:.4}, 99 % {:.4}, 99.9 % {:.4}, max {:.4}",
        detection_threshold(lags),
        percentile(&stats, 0.5),
        percentile(&stats, 0.99),
        percentile(&stats, 0.999),
        percentile(&stats, 1.0)
    );
    eprintln!(
        "noise only, peak / mean: median {:.2}, 99 % {:.2}, 99.9 % {:.2}, max {:.2}",
        percentile(&psr, 0.5),
        percentile(&psr, 0.99),
        percentile(&psr, 0.999),
        percentile(&psr, 1.0)
    );
    let mut geo = rng(9, 0, Stream::Initial);
    for snr in [10.0, 20.0, 30.0, 40.0] {
        let (mut s, mut p, mut synced) = (Vec::new(), Vec::new(), 0);
        for _ in 0..100 {
            let v = -2.0 + 4.0 * geo.random::<f64>();
            let c = PingConfig::parse(&config_text(snr, v), "frame.toml").unwrap();
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
            synced += usize::from((est.range_m - (c.source() - c.receiver()).norm()).abs() < 1.0);
            let sync = est.sync;
            s.push(sync.peak_ratio());
            p.push(peak_to_mean(&sync.distribution));
        }
        eprintln!(
            "{snr} dB: {synced} of 100 synchronised within 1 m; 1 % {:.4}, 5 % {:.4}, median {:.4}; peak / mean: 1 % {:.2}, 5 % {:.2}, median {:.2}",
            percentile(&s, 0.01),
            percentile(&s, 0.05),
            percentile(&s, 0.5),
            percentile(&p, 0.01),
            percentile(&p, 0.05),
            percentile(&p, 0.5)
        );
    }
}

fn peak_to_mean(d: &[f64]) -> f64 {
    let mean = d.iter().sum::<f64>() / d.len() as f64;
    d.iter().copied().fold(0.0, f64::max) / mean
}
