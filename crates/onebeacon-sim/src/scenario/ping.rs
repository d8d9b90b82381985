//! Configuration of one simulated or recorded ping (`onebeacon dsp simulate|process
//! --config FILE`): waveform, capture, array, geometry, water, noise and clock. Every
//! key is optional; the defaults are rypkema's receiver (5-element pyramid with 8 cm
//! edges, 8000 samples at 37.5 kS/s, mode-1 chirp) 120 m from the beacon.

use super::load::{ScenarioError, deserialize, invalid, tables_where_tables_belong};
use super::validate::{Rule, Violation, check, check_count, check_fields};
use crate::acoustics::channel::{Boundaries, Channel};
use nalgebra::{Matrix3, Rotation3, Vector3};
use onebeacon::dsp::Complex;
use onebeacon::dsp::beamform::{pyramid_8cm, tetrahedron};
use onebeacon::dsp::sound_speed::mackenzie;
use onebeacon::dsp::waveform::{Lfm, PskFrame, rypkema_modes};
use rand::RngExt;
use serde::{Deserialize, Serialize};

#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PingConfig {
    pub seed: u64,
    pub waveform: Waveform,
    pub capture: Capture,
    pub array: Array,
    pub geometry: Geometry,
    pub water: Water,
    pub noise: Noise,
    pub clock: Clock,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum WaveformKind {
    /// One of rypkema's command chirps.
    Chirp,
    /// garin2024's communication frame: tone at 20 kHz plus PSK at 28 kHz (Table 5).
    GarinFrame,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Waveform {
    /// `chirp` or `garin_frame`.
    pub kind: WaveformKind,
    /// rypkema's command mode, 1-4: 7->9, 10->8, 8->6, 9->11 kHz, 20 ms (chirps).
    pub mode: usize,
    /// Data symbols of a garin frame (QPSK, drawn from `seed`): 1740 make Table 5's
    /// 300 ms frame with 127 pilots and 2 x 16 guard symbols.
    pub data_symbols: usize,
}
impl Default for Waveform {
    fn default() -> Self {
        Self { kind: WaveformKind::Chirp, mode: 1, data_symbols: 1740 }
    }
}

/// The waveform of a ping configuration.
#[derive(Debug, Clone, PartialEq)]
pub enum Signal {
    Chirp(Lfm),
    Frame(PskFrame),
}

impl onebeacon::dsp::waveform::Waveform for Signal {
    fn value(&self, t: f64) -> f64 {
        match self {
            Signal::Chirp(c) => c.value(t),
            Signal::Frame(f) => onebeacon::dsp::waveform::Waveform::value(f, t),
        }
    }
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Capture {
    pub fs_hz: f64,
    /// Samples per element from the PPS.
    pub samples: usize,
}
impl Default for Capture {
    fn default() -> Self {
        Self { fs_hz: 37_500.0, samples: 8000 }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ArrayKind {
    Pyramid,
    Tetrahedron,
    Custom,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Array {
    /// `pyramid` (rypkema, 8 cm edges), `tetrahedron` (of `edge_m`) or `custom`.
    pub kind: ArrayKind,
    pub edge_m: f64,
    /// Element positions (x forward, y starboard, z down), m, for `custom`.
    pub elements_m: Vec<[f64; 3]>,
}
impl Default for Array {
    fn default() -> Self {
        Self { kind: ArrayKind::Pyramid, edge_m: 0.08, elements_m: Vec::new() }
    }
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Geometry {
    pub source_north_m: f64,
    pub source_east_m: f64,
    pub source_depth_m: f64,
    pub receiver_north_m: f64,
    pub receiver_east_m: f64,
    pub receiver_depth_m: f64,
    pub receiver_roll_deg: f64,
    pub receiver_pitch_deg: f64,
    pub receiver_heading_deg: f64,
    /// Closing speed, m/s (Doppler).
    pub radial_speed_m_s: f64,
}
impl Default for Geometry {
    fn default() -> Self {
        Self {
            source_north_m: 100.0,
            source_east_m: 60.0,
            source_depth_m: 1.0,
            receiver_north_m: 0.0,
            receiver_east_m: 0.0,
            receiver_depth_m: 30.0,
            receiver_roll_deg: 0.0,
            receiver_pitch_deg: 0.0,
            receiver_heading_deg: 0.0,
            radial_speed_m_s: 0.0,
        }
    }
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Water {
    /// Sound speed, m/s; absent: Mackenzie (1981) from temperature and salinity at the
    /// mean depth of source and receiver.
    pub sound_speed_m_s: Option<f64>,
    pub temperature_c: f64,
    pub salinity_ppt: f64,
    /// Water depth for surface and bottom reflections; absent: free field.
    pub depth_m: Option<f64>,
    pub surface_coef: f64,
    pub bottom_coef: f64,
    /// A vertical wall at this east coordinate (the river's stone wall), if any.
    pub wall_east_m: Option<f64>,
    pub wall_coef: f64,
}
impl Default for Water {
    fn default() -> Self {
        Self {
            sound_speed_m_s: None,
            temperature_c: 10.0,
            salinity_ppt: 35.0,
            depth_m: None,
            surface_coef: -1.0,
            bottom_coef: 0.5,
            wall_east_m: None,
            wall_coef: 0.8,
        }
    }
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Noise {
    /// Direct-path 2E/N0 per element, dB.
    pub snr_db: f64,
    /// Set false for a noise-free ping.
    pub enabled: bool,
}
impl Default for Noise {
    fn default() -> Self {
        Self { snr_db: 20.0, enabled: true }
    }
}

#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Clock {
    pub offset_s: f64,
    pub drift_ppm: f64,
}

impl PingConfig {
    /// Reads `path`, or the defaults.
    pub fn load(path: Option<&str>) -> Result<Self, ScenarioError> {
        let Some(path) = path else { return Ok(Self::default()) };
        Self::parse(&onebeacon::config::toml_file::read(std::path::Path::new(path))?, path)
    }

    pub fn parse(text: &str, source_name: &str) -> Result<Self, ScenarioError> {
        let c: Self = deserialize(text, source_name)?;
        let (input, canonical): (toml::Table, toml::Table) = (
            deserialize(text, source_name)?,
            toml::from_str(&toml::to_string(&c).expect("a ping configuration is TOML")).expect("and parses back"),
        );
        tables_where_tables_belong(&input, &canonical, "").map_err(|v| invalid(source_name, v))?;
        c.validate().map_err(|v| invalid(source_name, v))?;
        Ok(c)
    }

    fn validate(&self) -> Result<(), Violation> {
        check_count("waveform.mode", self.waveform.mode, 1, 4)?;
        check_count("waveform.data_symbols", self.waveform.data_symbols, 0, 1_000_000)?;
        check_fields!("capture", self.capture, { fs_hz: Positive });
        if self.waveform.kind == WaveformKind::GarinFrame && self.capture.fs_hz < 65_000.0 {
            return Err(Violation {
                key: "capture.fs_hz".into(),
                value: format!("{:?}", self.capture.fs_hz),
                allowed: "a garin frame reaches 32.5 kHz: needs a rate over 65 kHz (Table 5: 96153)".into(),
            });
        }
        check_count("capture.samples", self.capture.samples, 1, 10_000_000)?;
        check_fields!("array", self.array, { edge_m: Positive });
        if self.array.kind == ArrayKind::Custom {
            check_count("array.elements_m (count)", self.array.elements_m.len(), 2, 64)?;
            for (i, e) in self.array.elements_m.iter().enumerate() {
                for (j, v) in e.iter().enumerate() {
                    check(&format!("array.elements_m[{i}][{j}]"), *v, Rule::Finite)?;
                }
            }
            check_array_geometry(&self.array.elements_m)?;
        }
        check_fields!("geometry", self.geometry, {
            source_north_m: Finite,
            source_east_m: Finite,
            source_depth_m: NonNegative,
            receiver_north_m: Finite,
            receiver_east_m: Finite,
            receiver_depth_m: NonNegative,
            receiver_roll_deg: Finite,
            receiver_pitch_deg: Finite,
            receiver_heading_deg: Finite,
            radial_speed_m_s: Finite,
        });
        if let Some(c) = self.water.sound_speed_m_s {
            check("water.sound_speed_m_s", c, Rule::Positive)?;
        }
        check_fields!("water", self.water, { temperature_c: Finite, salinity_ppt: NonNegative, surface_coef: Finite, bottom_coef: Finite, wall_coef: Finite });
        if let Some(d) = self.water.depth_m {
            check("water.depth_m", d, Rule::Positive)?;
        }
        if let Some(w) = self.water.wall_east_m {
            check("water.wall_east_m", w, Rule::Finite)?;
        }
        check_fields!("noise", self.noise, { snr_db: Finite });
        check_fields!("clock", self.clock, { offset_s: Finite, drift_ppm: Finite });
        // physically meaningful values, so that a ping can neither panic nor come out
        // as NaN or as a silent capture
        let within = |key: &str, v: f64, lo: f64, hi: f64, what: &str| {
            if (lo..=hi).contains(&v) {
                Ok(())
            } else {
                Err(Violation {
                    key: key.into(),
                    value: format!("{v:?}"),
                    allowed: format!("must be in [{lo}, {hi}] ({what})"),
                })
            }
        };
        if self.waveform.kind != WaveformKind::GarinFrame {
            let top = self.chirp().f0_hz.max(self.chirp().f1_hz);
            within("capture.fs_hz", self.capture.fs_hz, 2.0 * top, 1e7, "over twice the chirp's highest frequency")?;
        }
        within("capture.fs_hz", self.capture.fs_hz, 1.0, 1e7, "a sampling rate, Hz")?;
        within("noise.snr_db", self.noise.snr_db, -60.0, 200.0, "2E/N0 per element, dB")?;
        within("geometry.radial_speed_m_s", self.geometry.radial_speed_m_s, -50.0, 50.0, "m/s")?;
        within("clock.drift_ppm", self.clock.drift_ppm, -1e4, 1e4, "ppm")?;
        let w = &self.water;
        for (key, v) in [
            ("water.surface_coef", w.surface_coef),
            ("water.bottom_coef", w.bottom_coef),
            ("water.wall_coef", w.wall_coef),
        ] {
            within(key, v, -1.0, 1.0, "a reflection coefficient")?;
        }
        within("water.temperature_c", w.temperature_c, -2.0, 40.0, "sea water, deg C")?;
        within("water.salinity_ppt", w.salinity_ppt, 0.0, 45.0, "sea water, ppt")?;
        if let Some(c) = w.sound_speed_m_s {
            within("water.sound_speed_m_s", c, 1300.0, 1700.0, "sound in water, m/s")?;
        }
        // the direct path must arrive inside the capture window
        let arrival_s = (self.source() - self.receiver()).norm() / self.sound_speed_m_s() + self.clock.offset_s;
        let window_s = self.capture.samples as f64 / self.capture.fs_hz;
        if !(0.0..window_s).contains(&arrival_s) {
            return Err(Violation {
                key: "geometry".into(),
                value: format!("the ping arrives at {arrival_s:.4} s"),
                allowed: format!(
                    "must arrive within the capture window, [0, {window_s:.4}) s (capture.samples / capture.fs_hz): move the source closer or capture longer"
                ),
            });
        }
        Ok(())
    }

    /// The configured chirp (the command mode's), used by chirp pings.
    pub fn chirp(&self) -> Lfm {
        rypkema_modes()[self.waveform.mode - 1]
    }

    /// The garin frame with its data symbols drawn from `seed`.
    pub fn frame(&self) -> PskFrame {
        let mut g = crate::seed::rng(self.seed, 0, crate::seed::Stream::Initial);
        let data = (0..self.waveform.data_symbols)
            .map(|_| {
                let (a, b): (bool, bool) = (g.random(), g.random());
                Complex::new(if a { 1.0 } else { -1.0 }, if b { 1.0 } else { -1.0 }) / 2f64.sqrt()
            })
            .collect();
        PskFrame::garin(data)
    }

    pub fn signal(&self) -> Signal {
        match self.waveform.kind {
            WaveformKind::Chirp => Signal::Chirp(self.chirp()),
            WaveformKind::GarinFrame => Signal::Frame(self.frame()),
        }
    }

    /// Element positions in the array (body) frame, m.
    pub fn elements(&self) -> Vec<Vector3<f64>> {
        match self.array.kind {
            ArrayKind::Pyramid => pyramid_8cm().iter().map(|e| e * (self.array.edge_m / 0.08)).collect(),
            ArrayKind::Tetrahedron => tetrahedron(self.array.edge_m),
            ArrayKind::Custom => self.array.elements_m.iter().map(|e| Vector3::new(e[0], e[1], e[2])).collect(),
        }
    }

    pub fn source(&self) -> Vector3<f64> {
        let g = &self.geometry;
        Vector3::new(g.source_north_m, g.source_east_m, g.source_depth_m)
    }

    pub fn receiver(&self) -> Vector3<f64> {
        let g = &self.geometry;
        Vector3::new(g.receiver_north_m, g.receiver_east_m, g.receiver_depth_m)
    }

    /// Body-to-NED rotation of the receiving array.
    pub fn attitude(&self) -> Matrix3<f64> {
        let g = &self.geometry;
        Rotation3::from_euler_angles(
            g.receiver_roll_deg.to_radians(),
            g.receiver_pitch_deg.to_radians(),
            g.receiver_heading_deg.to_radians(),
        )
        .into_inner()
    }

    pub fn sound_speed_m_s(&self) -> f64 {
        let w = &self.water;
        w.sound_speed_m_s.unwrap_or_else(|| {
            mackenzie(
                w.temperature_c,
                w.salinity_ppt,
                (self.geometry.source_depth_m + self.geometry.receiver_depth_m) / 2.0,
            )
        })
    }

    pub fn channel(&self) -> Channel {
        let w = &self.water;
        Channel {
            fs_hz: self.capture.fs_hz,
            capture_len: self.capture.samples,
            sound_speed_m_s: self.sound_speed_m_s(),
            snr_db: self.noise.enabled.then_some(self.noise.snr_db),
            boundaries: w.depth_m.map(|d| Boundaries {
                water_depth_m: d,
                surface_coef: w.surface_coef,
                bottom_coef: w.bottom_coef,
                wall_east_m: w.wall_east_m,
                wall_coef: w.wall_coef,
            }),
            clock_offset_s: self.clock.offset_s,
            clock_drift_ppm: self.clock.drift_ppm,
            radial_speed_m_s: self.geometry.radial_speed_m_s,
        }
    }
}

/// Elements that can tell a direction: no two at one point (closer than 1 mm).
fn check_array_geometry(elements: &[[f64; 3]]) -> Result<(), Violation> {
    const CLOSE_M: f64 = 1e-3;
    let p: Vec<Vector3<f64>> = elements.iter().map(|e| Vector3::from(*e)).collect();
    for i in 0..p.len() {
        if let Some(j) = (0..i).find(|&j| (p[i] - p[j]).norm() < CLOSE_M) {
            return Err(Violation {
                key: format!("array.elements_m[{i}]"),
                value: format!("{:?}", elements[i]),
                allowed: format!(
                    "must be at least 1 mm from element {j}: elements at one point cannot tell a direction"
                ),
            });
        }
    }
    // a line array measures one cone angle about its line, not azimuth and inclination
    let far = (1..p.len()).max_by(|&a, &b| (p[a] - p[0]).norm().total_cmp(&(p[b] - p[0]).norm())).unwrap_or(0);
    let line = (p[far] - p[0]).normalize();
    if p.iter().all(|q| (q - p[0]).cross(&line).norm() < CLOSE_M) {
        return Err(Violation {
            key: "array.elements_m".into(),
            value: format!("{elements:?}"),
            allowed: "must not lie on one line (within 1 mm): a line array measures one cone angle about its line, \
                      not azimuth and inclination; place an element at least 1 mm off the line"
                .into(),
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_and_errors() {
        let c = PingConfig::parse("", "ping.toml").unwrap();
        assert_eq!(c.elements().len(), 5);
        assert!((c.sound_speed_m_s() - 1490.0).abs() < 5.0);
        let e = PingConfig::parse("[waveform]\nmode = 5\n", "ping.toml").unwrap_err().to_string();
        assert!(e.contains("waveform.mode") && e.contains("1 to 4"), "{e}");
        let e = PingConfig::parse("[array]\nkind = \"ring\"\n", "ping.toml").unwrap_err().to_string();
        assert!(e.contains("array.kind") && e.contains("pyramid"), "{e}");
        let e = PingConfig::parse("[waveform]\nkind = \"garin_frame\"\n", "ping.toml").unwrap_err().to_string();
        assert!(e.contains("capture.fs_hz") && e.contains("65 kHz"), "{e}");
        let e = PingConfig::parse("[water]\ndepth_m = -5\n", "ping.toml").unwrap_err().to_string();
        assert!(e.contains("water.depth_m"), "{e}");
        // configs that would panic, give NaN samples or a silent capture
        for (text, key) in [
            ("[capture]\nfs_hz = 1e-3\n", "capture.fs_hz"),
            ("[capture]\nfs_hz = 15000\n", "capture.fs_hz"), // under twice mode 1's 9 kHz
            ("[noise]\nsnr_db = -1000\n", "noise.snr_db"),
            ("[water]\nbottom_coef = -3\n", "water.bottom_coef"),
            ("[geometry]\nsource_north_m = 5000\n", "must arrive within the capture window"),
            ("[clock]\noffset_s = -1\n", "must arrive within the capture window"),
            ("[array]\nkind = \"custom\"\nelements_m = [[0.1, 0, 0], [0.1, 0, 0], [0.1, 0, 0]]\n", "elements_m[1]"),
            ("[array]\nkind = \"custom\"\nelements_m = [[0, 0, 0], [0.05, 0, 0], [0.0501, 0, 0.0002]]\n", "element 1"),
            // colinear: cfb7f93 reported a direction 48 deg off as consistent
            (
                "[array]\nkind = \"custom\"\nelements_m = [[0, 0, 0], [0.05, 0, 0], [0.1, 0, 0.0005], [0.15, 0, 0]]\n",
                "one cone angle",
            ),
        ] {
            let e = PingConfig::parse(text, "ping.toml").unwrap_err().to_string();
            assert!(e.contains(key), "{text}: {e}");
        }
        // an element 2 mm off the line through the others: an array of two dimensions
        let plane = "[array]\nkind = \"custom\"\nelements_m = [[0, 0, 0], [0.05, 0, 0.002], [0.1, 0, 0]]\n";
        assert!(PingConfig::parse(plane, "ping.toml").is_ok());
    }
}
