//! `onebeacon dsp simulate|process`: one ping as a multichannel WAV, and the receiver
//! chain on a WAV from the simulator or the field.

use crate::output::Staging;
use crate::{BadInput, plot};
use anyhow::{Context, Result};
use nalgebra::Vector3;
use onebeacon::dsp::beamform::azimuth_inclination;
use onebeacon_sim::acoustics::channel::simulate_ping;
use onebeacon_sim::acoustics::wav::Recording;
use onebeacon_sim::chain::{Chain, Found};
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
    let json_name = Path::new(&wav_name).with_extension("json").to_string_lossy().into_owned();
    let staging = Staging::beside(&dir, &[&wav_name, &json_name])?;
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
    let moved = staging.move_files_to()?;
    for f in moved {
        outln!("wrote {}", f.display());
    }
    Ok(())
}

fn bad(path: &Path, what: impl std::fmt::Display) -> anyhow::Error {
    BadInput(format!("{}: {what}", path.display())).into()
}

/// `onebeacon dsp process ping.wav [--config FILE] [--out DIR] [--json]`: one capture,
/// or a recording longer than `capture.samples` cut into captures of that length (the
/// last one padded with zeros), each processed on its own.
pub fn process(wav: &Path, config: Option<&str>, out: Option<PathBuf>, as_json: bool) -> Result<()> {
    let c = PingConfig::load(config)?;
    let channels = c.elements().len();
    let fs = c.capture.fs_hz;
    let open = || Recording::open(wav, channels, fs).map_err(|e| bad(wav, e));
    let frames = open()?.check().map_err(|e| bad(wav, e))?;
    let len = if frames <= c.capture.samples { frames } else { c.capture.samples };
    let mut chain = Chain::new(c, len).map_err(|e| bad(wav, e))?;
    let mut inputs = vec![wav.to_path_buf()];
    inputs.extend(config.map(PathBuf::from));
    let staging = out.as_deref().map(|d| Staging::new(d, &inputs)).transpose()?;
    let mut recording = open()?;
    if frames == len {
        let found = chain.process(&recording.next_capture(len).map_err(|e| bad(wav, e))?);
        if let Some(staging) = staging {
            write_range_outputs(&staging, &found)?;
            if let Some((mode, az, inc)) = found.beam {
                let power = |u: &Vector3<f64>| chain.beam_power(mode, u);
                plot::beam_map(&staging.file("beam.png"), power, az, inc).context("cannot draw beam.png")?;
            }
            for f in staging.commit()? {
                eprintln!("wrote {}", f.display());
            }
        }
        if as_json {
            outln!("{}", found.result);
        } else {
            outln!("{}", found.text);
        }
        return Ok(());
    }
    // a recording: one line per capture, and captures.csv
    let count = frames.div_ceil(len);
    let mut table = match &staging {
        Some(s) => Some(csv::Writer::from_path(s.file("captures.csv")).context("cannot write captures.csv")?),
        None => None,
    };
    let columns = [
        "capture",
        "t_s",
        "detected",
        "range_m",
        "azimuth_deg",
        "inclination_deg",
        "mode",
        "radial_speed_m_s",
        "consistent",
    ];
    if let Some(t) = &mut table {
        t.write_record(columns)?;
    }
    // the lines show the progress on a terminal; a progress report when they go to a
    // file or a pipe
    let progress = if std::io::IsTerminal::is_terminal(&std::io::stdout()) {
        crate::progress::Progress::Hidden
    } else {
        crate::progress::Progress::new(count as u64, "captures", "dsp process".into())
    };
    for k in 0..count {
        let mut captures = recording.next_capture(len).map_err(|e| bad(wav, e))?;
        for ch in &mut captures {
            ch.resize(len, 0.0);
        }
        let found = chain.process(&captures);
        let t_s = (k * len) as f64 / fs;
        let mut result = found.result;
        result["capture"] = json!(k);
        result["t_s"] = json!(t_s);
        if let Some(t) = &mut table {
            let cell = |key: &str| match &result[key] {
                serde_json::Value::Null => String::new(),
                v => v.to_string(),
            };
            let detected = result.get("detected").map_or("true".to_string(), |d| d.to_string());
            let row: Vec<String> =
                columns.iter().map(|&key| if key == "detected" { detected.clone() } else { cell(key) }).collect();
            t.write_record(&row)?;
        }
        if as_json {
            outln!("{result}");
        } else {
            outln!("capture {k} at {t_s:.3} s: {}", found.text);
        }
        progress.inc(1);
    }
    progress.finish();
    if let (Some(staging), Some(t)) = (staging, table) {
        t.into_inner().map_err(|e| anyhow::anyhow!("cannot write captures.csv: {}", e.error()))?;
        for f in staging.commit()? {
            eprintln!("wrote {}", f.display());
        }
    }
    Ok(())
}

/// The range pseudo-distribution as CSV and PNG (range = lag x metres per lag - offset)
/// and the estimates as JSON.
fn write_range_outputs(staging: &Staging, found: &Found) -> Result<()> {
    let (distribution, metres_per_lag, offset_m) = (&found.distribution, found.metres_per_lag, found.offset_m);
    let mut csv = String::from("range_m,pseudo_probability\n");
    for (i, p) in distribution.iter().enumerate() {
        csv.push_str(&format!("{:.4},{p:.6e}\n", i as f64 * metres_per_lag - offset_m));
    }
    staging.write("range.csv", csv.as_bytes())?;
    staging.write("estimate.json", (serde_json::to_string_pretty(&found.result)? + "\n").as_bytes())?;
    plot::range_distribution(&staging.file("range.png"), distribution, metres_per_lag, offset_m, found.range_m)
        .context("cannot draw range.png")
}
