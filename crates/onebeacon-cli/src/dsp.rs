//! `onebeacon dsp simulate|process`: one ping as a multichannel WAV, and the receiver
//! chain on a WAV from the simulator or the field.

use crate::output::Staging;
use crate::{BadInput, plot};
use anyhow::{Context, Result};
use nalgebra::Vector3;
use onebeacon::dsp::beamform::azimuth_inclination;
use onebeacon::dsp::matched_filter::MatchedFilter;
use onebeacon::dsp::modes::ModeBank;
use onebeacon::dsp::receiver::{Receiver, ReceiverConfig, receive_frame};
use onebeacon::dsp::waveform::rypkema_modes;
use onebeacon_sim::acoustics::channel::simulate_ping;
use onebeacon_sim::scenario::ping::{PingConfig, WaveformKind};
use onebeacon_sim::seed::{Stream, rng};
use serde_json::json;
use std::path::{Path, PathBuf};

/// `onebeacon dsp simulate [--config FILE] --out ping.wav`
pub fn simulate(config: Option<&str>, out: &Path) -> Result<()> {
    let c = PingConfig::load(config)?;
    if out.extension().and_then(|e| e.to_str()) != Some("wav") {
        return Err(BadInput(format!("--out {}: must name a .wav file", out.display())).into());
    }
    let elements = c.elements();
    let mut noise = rng(c.seed, 0, Stream::Acoustic);
    let caps =
        simulate_ping(&c.signal(), &c.source(), &c.receiver(), &c.attitude(), &elements, &c.channel(), &mut noise);
    let is_frame = c.waveform.kind == WaveformKind::GarinFrame;
    // scale to a peak of 0.5 full scale
    let peak = caps.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs())).max(f64::MIN_POSITIVE);
    let scale = 0.5 / peak;
    let rel = c.source() - c.receiver();
    let body = c.attitude().transpose() * rel.normalize();
    let (az, inc) = azimuth_inclination(&body);
    let truth = json!({
        "range_m": rel.norm(),
        "azimuth_deg": az.to_degrees(),
        "inclination_deg": inc.to_degrees(),
        "mode": if is_frame { serde_json::Value::Null } else { json!(c.waveform.mode) },
        "waveform": if is_frame { "garin_frame" } else { "chirp" },
        "radial_speed_m_s": c.geometry.radial_speed_m_s,
        "sound_speed_m_s": c.sound_speed_m_s(),
        "snr_db": if c.noise.enabled { json!(c.noise.snr_db) } else { serde_json::Value::Null },
        "fs_hz": c.capture.fs_hz,
        "samples": c.capture.samples,
        "channels": elements.len(),
        "scale": scale,
    });
    // write both files beside the target, then move them in
    let dir =
        out.parent().filter(|p| !p.as_os_str().is_empty()).map(Path::to_path_buf).unwrap_or_else(|| PathBuf::from("."));
    let wav_name = out.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_else(|| "ping.wav".into());
    let staging = Staging::beside(&dir, &wav_name)?;
    let json_name = Path::new(&wav_name).with_extension("json").to_string_lossy().into_owned();
    let spec = hound::WavSpec {
        channels: elements.len() as u16,
        sample_rate: c.capture.fs_hz.round() as u32,
        bits_per_sample: 32,
        sample_format: hound::SampleFormat::Float,
    };
    let mut w = hound::WavWriter::create(staging.file(&wav_name), spec).context("cannot write the WAV")?;
    for n in 0..c.capture.samples {
        for ch in &caps {
            w.write_sample((ch[n] * scale) as f32)?;
        }
    }
    w.finalize()?;
    staging.write(&json_name, (serde_json::to_string_pretty(&truth)? + "\n").as_bytes())?;
    let moved = staging.move_files_to(&dir)?;
    for f in moved {
        outln!("wrote {}", f.display());
    }
    Ok(())
}

fn bad(path: &Path, what: impl std::fmt::Display) -> anyhow::Error {
    BadInput(format!("{}: {what}", path.display())).into()
}

/// Reads a WAV into one capture per channel, checking it against the configuration.
fn read_wav(path: &Path, channels: usize, fs_hz: f64) -> Result<Vec<Vec<f64>>> {
    let mut r = hound::WavReader::open(path).map_err(|e| bad(path, format!("not a readable WAV file ({e})")))?;
    let spec = r.spec();
    if spec.channels as usize != channels {
        return Err(bad(
            path,
            format!("{} channels; the array has {channels} elements (set [array] in --config)", spec.channels),
        ));
    }
    if (spec.sample_rate as f64 - fs_hz).abs() > 0.5 {
        return Err(bad(
            path,
            format!("sample rate {} Hz; expected {fs_hz} Hz (set capture.fs_hz in --config)", spec.sample_rate),
        ));
    }
    let (samples, full_scale): (Vec<f64>, f64) = match spec.sample_format {
        hound::SampleFormat::Float => (
            r.samples::<f32>()
                .map(|s| s.map(f64::from))
                .collect::<Result<_, _>>()
                .map_err(|e| bad(path, format!("truncated or corrupt ({e})")))?,
            1.0,
        ),
        hound::SampleFormat::Int => {
            let fs = (1i64 << (spec.bits_per_sample - 1)) as f64;
            (
                r.samples::<i32>()
                    .map(|s| s.map(|v| v as f64 / fs))
                    .collect::<Result<_, _>>()
                    .map_err(|e| bad(path, format!("truncated or corrupt ({e})")))?,
                1.0 - 1.0 / fs,
            )
        }
    };
    if samples.is_empty() {
        return Err(bad(path, "no samples"));
    }
    if let Some(i) = samples.iter().position(|v| !v.is_finite()) {
        return Err(bad(path, format!("sample {} of channel {} is not a number", i / channels, i % channels)));
    }
    let clipped = samples.iter().filter(|v| v.abs() >= full_scale * 0.9999).count();
    if clipped > 0 {
        return Err(bad(path, format!("{clipped} samples at full scale (clipped); record with less gain")));
    }
    let n = samples.len() / channels;
    Ok((0..channels).map(|c| (0..n).map(|i| samples[i * channels + c]).collect()).collect())
}

/// `onebeacon dsp process ping.wav [--config FILE] [--out DIR] [--json]`
pub fn process(wav: &Path, config: Option<&str>, out: Option<PathBuf>, as_json: bool) -> Result<()> {
    let c = PingConfig::load(config)?;
    let elements = c.elements();
    let fs = c.capture.fs_hz;
    let captures = read_wav(wav, elements.len(), fs)?;
    let n = captures[0].len();
    let modes = rypkema_modes();
    if n < (modes[0].duration_s * fs) as usize {
        return Err(bad(wav, format!("{n} samples per channel; at least one 20 ms pulse is needed")));
    }
    let staging = out.as_deref().map(Staging::new).transpose()?;
    if c.waveform.kind == WaveformKind::GarinFrame {
        return process_frame(&c, &captures, staging, as_json);
    }
    let filters = modes.iter().map(|m| MatchedFilter::classical(&m.samples(fs), m.band(), fs, n)).collect();
    let centres = modes.iter().map(|m| (m.f0_hz + m.f1_hz) / 2.0).collect();
    let bank = ModeBank::with_array(filters, centres, elements.clone(), c.sound_speed_m_s());
    let spectra = bank.spectra(&captures);
    let mode = bank.identify(&spectra);
    let cfg =
        ReceiverConfig { fs_hz: fs, capture_len: n, sound_speed_m_s: c.sound_speed_m_s(), ..ReceiverConfig::default() };
    let mut rx = Receiver::new(modes[mode], &elements, cfg);
    let est = rx.process_spectra(&captures, &spectra);
    let detected = est.range.detected();
    let statistic = est.range.peak_ratio();
    let threshold = onebeacon::dsp::matched_filter::detection_threshold(est.range.distribution.len());
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
    if let Some(staging) = staging {
        let c_fs = c.sound_speed_m_s() / fs;
        write_range_outputs(&staging, &est.range.distribution, c_fs, 0.0, est.range.range_m, &result)?;
        plot::beam_map(&staging.file("beam.png"), |u: &Vector3<f64>| rx.beam_power(u), est.azimuth, est.inclination)
            .context("cannot draw beam.png")?;
        for f in staging.commit()? {
            eprintln!("wrote {}", f.display());
        }
    }
    if as_json {
        outln!("{result}");
    } else if !detected {
        outln!(
            "no ping detected: statistic {statistic:.4} below the threshold {threshold:.4} (false alarms under 1 in 2000 captures)"
        );
    } else {
        outln!(
            "mode {}, range {:.2} m, azimuth {:.1} deg, inclination {:.1} deg{}",
            mode + 1,
            est.range.range_m,
            est.azimuth.to_degrees(),
            est.inclination.to_degrees(),
            if est.range.consistent { "" } else { " (elements disagree: range suspect)" }
        );
    }
    Ok(())
}

/// A garin frame through [`receive_frame`]: range, Doppler speed, direction.
fn process_frame(c: &PingConfig, captures: &[Vec<f64>], staging: Option<Staging>, as_json: bool) -> Result<()> {
    let elements = c.elements();
    let config = ReceiverConfig {
        fs_hz: c.capture.fs_hz,
        capture_len: captures[0].len(),
        sound_speed_m_s: c.sound_speed_m_s(),
        ..ReceiverConfig::default()
    };
    let est = receive_frame(&c.frame(), &elements, &config, captures);
    let (range_m, v) = (est.range_m, est.radial_speed_m_s);
    let (az, inc) = est.direction.unwrap_or((f64::NAN, f64::NAN));
    let num = |x: f64| if x.is_finite() { json!(x) } else { serde_json::Value::Null };
    let result = json!({
        "range_m": range_m,
        "azimuth_deg": num(az.to_degrees()),
        "inclination_deg": num(inc.to_degrees()),
        "mode": serde_json::Value::Null,
        "radial_speed_m_s": v,
        "consistent": est.sync.consistent,
    });
    if let Some(staging) = staging {
        // lags in metres, scaled by the Doppler compensation, less the pilots' offset
        write_range_outputs(&staging, &est.sync.distribution, est.metres_per_lag, est.offset_m, range_m, &result)?;
        for f in staging.commit()? {
            eprintln!("wrote {}", f.display());
        }
    }
    if as_json {
        outln!("{result}");
    } else {
        outln!(
            "garin frame: range {range_m:.2} m, Doppler speed {v:.3} m/s (closing positive){}",
            if elements.len() > 1 {
                format!(", azimuth {:.1} deg, inclination {:.1} deg", az.to_degrees(), inc.to_degrees())
            } else {
                String::new()
            }
        );
    }
    Ok(())
}

/// The range pseudo-distribution as CSV and PNG (range = lag x `metres_per_sample` -
/// `offset_m`) and the estimates as JSON.
fn write_range_outputs(
    staging: &Staging,
    distribution: &[f64],
    metres_per_sample: f64,
    offset_m: f64,
    estimate_m: f64,
    result: &serde_json::Value,
) -> Result<()> {
    let mut csv = String::from("range_m,pseudo_probability\n");
    for (i, p) in distribution.iter().enumerate() {
        csv.push_str(&format!("{:.4},{p:.6e}\n", i as f64 * metres_per_sample - offset_m));
    }
    staging.write("range.csv", csv.as_bytes())?;
    staging.write("estimate.json", (serde_json::to_string_pretty(result)? + "\n").as_bytes())?;
    plot::range_distribution(&staging.file("range.png"), distribution, metres_per_sample, offset_m, estimate_m)
        .context("cannot draw range.png")
}
