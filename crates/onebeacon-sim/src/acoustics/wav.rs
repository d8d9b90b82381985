//! Multichannel WAV recordings (one channel per array element) read a capture at a
//! time: nothing but one capture is held, however long the recording.

use std::io::Read;
use std::path::Path;

/// Why a WAV cannot be used: one line, without the file's name.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct WavError(pub String);

/// A WAV being read capture by capture: frames of one sample per channel, scaled to
/// full scale 1.
pub struct Recording<R: Read> {
    reader: hound::WavReader<R>,
    channels: usize,
    /// Integer samples are divided by this; None for float samples.
    int_scale: Option<f64>,
    /// Frames read so far.
    read: usize,
}

impl Recording<std::io::BufReader<std::io::Take<std::fs::File>>> {
    /// Opens the WAV at `path` ([`Recording::new`]): a regular file, read to its length.
    pub fn open(path: &Path, channels: usize, fs_hz: f64) -> Result<Self, WavError> {
        let file = onebeacon::io::file::open_bounded(path).map_err(WavError)?;
        Self::new(std::io::BufReader::new(file), channels, fs_hz)
    }
}

impl<R: Read> Recording<R> {
    /// Reads the header and checks it against the array (`channels`) and the sampling
    /// rate.
    pub fn new(reader: R, channels: usize, fs_hz: f64) -> Result<Self, WavError> {
        let reader = hound::WavReader::new(reader).map_err(|e| WavError(format!("not a readable WAV file ({e})")))?;
        let spec = reader.spec();
        if spec.channels as usize != channels {
            return Err(WavError(format!(
                "{} channels; the array has {channels} elements (set [array] in --config)",
                spec.channels
            )));
        }
        if (spec.sample_rate as f64 - fs_hz).abs() > 0.5 {
            return Err(WavError(format!(
                "sample rate {} Hz; expected {fs_hz} Hz (set capture.fs_hz in --config)",
                spec.sample_rate
            )));
        }
        let int_scale = (spec.sample_format == hound::SampleFormat::Int)
            .then(|| (1i64 << (spec.bits_per_sample.clamp(1, 32) - 1)) as f64);
        Ok(Self { reader, channels, int_scale, read: 0 })
    }

    /// Frames read so far.
    pub fn frames_read(&self) -> usize {
        self.read
    }

    /// Full scale: a sample this large was clipped.
    fn full_scale(&self) -> f64 {
        self.int_scale.map_or(1.0, |fs| 1.0 - 1.0 / fs)
    }

    /// The next `len` frames, one vector per channel (fewer at the end of the file;
    /// empty after it). A truncated file or a sample that is not a number is an error.
    pub fn next_capture(&mut self, len: usize) -> Result<Vec<Vec<f64>>, WavError> {
        let mut out = vec![Vec::with_capacity(len); self.channels];
        let samples: Box<dyn Iterator<Item = hound::Result<f64>>> = match self.int_scale {
            None => Box::new(self.reader.samples::<f32>().map(|s| s.map(f64::from))),
            Some(fs) => Box::new(self.reader.samples::<i32>().map(move |s| s.map(|v| v as f64 / fs))),
        };
        for (i, v) in samples.take(len * self.channels).enumerate() {
            let v = v.map_err(|e| WavError(format!("truncated or corrupt ({e})")))?;
            let (frame, channel) = (self.read + i / self.channels, i % self.channels);
            if !v.is_finite() {
                return Err(WavError(format!("sample {frame} of channel {channel} is not a number")));
            }
            out[channel].push(v);
        }
        self.read += out[self.channels - 1].len();
        Ok(out)
    }

    /// Reads the rest of the recording, a capture at a time, so that a bad sample is
    /// found before any result is given: the frames per channel it holds. No sample, a
    /// sample that is not a number, a truncated file and clipping are errors.
    pub fn check(mut self) -> Result<usize, WavError> {
        let full_scale = self.full_scale();
        let mut clipped = 0;
        loop {
            let capture = self.next_capture(1 << 16)?;
            if capture[0].is_empty() {
                break;
            }
            clipped += capture.iter().flatten().filter(|v| v.abs() >= full_scale * 0.9999).count();
        }
        if self.read == 0 {
            return Err(WavError("no samples".into()));
        }
        if clipped > 0 {
            return Err(WavError(format!("{clipped} samples at full scale (clipped); record with less gain")));
        }
        Ok(self.read)
    }
}
