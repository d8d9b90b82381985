//! Signal-level channel: one ping from a source to every element of an array, with
//! exact fractional delays (the waveform is evaluated in continuous time), Doppler time
//! compression, spherical spreading, image-method multipath (surface, bottom, an
//! optional vertical wall), receiver clock offset and drift, and white Gaussian noise
//! at a given per-element 2E/N0 (energy-to-noise ratio of the whole pulse).

use nalgebra::{Matrix3, Vector3};
use onebeacon::dsp::waveform::Waveform;

/// Reflecting boundaries. Depth positive down; the surface is z = 0.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Boundaries {
    pub water_depth_m: f64,
    /// Pressure reflection coefficients.
    pub surface_coef: f64,
    pub bottom_coef: f64,
    /// A vertical wall at east = `wall_east_m`, if any, and its coefficient.
    pub wall_east_m: Option<f64>,
    pub wall_coef: f64,
}

/// Channel and capture settings.
#[derive(Debug, Clone, PartialEq)]
pub struct Channel {
    pub fs_hz: f64,
    pub capture_len: usize,
    pub sound_speed_m_s: f64,
    /// Direct-path 2E/N0 per element, dB; `None` for no noise.
    pub snr_db: Option<f64>,
    pub boundaries: Option<Boundaries>,
    /// Receiver clock: reads `t (1 + drift) + offset` at true time t.
    pub clock_offset_s: f64,
    pub clock_drift_ppm: f64,
    /// Closing speed between source and receiver, m/s (Doppler scale 1 + v / c).
    pub radial_speed_m_s: f64,
}

impl Default for Channel {
    fn default() -> Self {
        Self {
            fs_hz: 37_500.0,
            capture_len: 8000,
            sound_speed_m_s: 1500.0,
            snr_db: Some(20.0),
            boundaries: None,
            clock_offset_s: 0.0,
            clock_drift_ppm: 0.0,
            radial_speed_m_s: 0.0,
        }
    }
}

/// Image sources of `source` with their reflection coefficients: the direct path, then
/// first- and second-order surface/bottom images, and the wall's images of those.
pub fn images(source: &Vector3<f64>, b: &Option<Boundaries>) -> Vec<(Vector3<f64>, f64)> {
    let mut out = vec![(*source, 1.0)];
    let Some(b) = b else { return out };
    let (x, y, z, d) = (source.x, source.y, source.z, b.water_depth_m);
    let (s, bt) = (b.surface_coef, b.bottom_coef);
    out.extend([
        (Vector3::new(x, y, -z), s),               // surface
        (Vector3::new(x, y, 2.0 * d - z), bt),     // bottom
        (Vector3::new(x, y, 2.0 * d + z), s * bt), // surface then bottom
        (Vector3::new(x, y, z - 2.0 * d), s * bt), // bottom then surface
    ]);
    if let Some(w) = b.wall_east_m {
        let mirrored: Vec<_> =
            out.iter().map(|(p, g)| (Vector3::new(p.x, 2.0 * w - p.y, p.z), g * b.wall_coef)).collect();
        out.extend(mirrored);
    }
    out
}

/// The captures of one ping transmitted at t = 0 (the PPS both ends share) by a source
/// at `source` (NED) and received by an array centred at `receiver` with body-to-NED
/// rotation `attitude` and element positions `elements` (body frame).
pub fn simulate_ping<W: Waveform + ?Sized, R: rand::Rng>(
    waveform: &W,
    source: &Vector3<f64>,
    receiver: &Vector3<f64>,
    attitude: &Matrix3<f64>,
    elements: &[Vector3<f64>],
    ch: &Channel,
    rng: &mut R,
) -> Vec<Vec<f64>> {
    let c = ch.sound_speed_m_s;
    let alpha = 1.0 + ch.radial_speed_m_s / c;
    let paths = images(source, &ch.boundaries);
    let drift = 1.0 + ch.clock_drift_ppm * 1e-6;
    let mut direct_energy = 0.0;
    let mut captures: Vec<Vec<f64>> = elements
        .iter()
        .map(|r| {
            let p = receiver + attitude * r;
            let arrivals: Vec<(f64, f64)> = paths
                .iter()
                .map(|(q, g)| {
                    let d = (p - q).norm().max(1e-3);
                    (d / c, g / d) // delay, amplitude (spherical spreading)
                })
                .collect();
            let samples: Vec<(f64, f64)> = (0..ch.capture_len)
                .map(|n| {
                    let t = (n as f64 / ch.fs_hz - ch.clock_offset_s) / drift; // true time of sample n
                    let direct = arrivals[0].1 * waveform.value(alpha * t - arrivals[0].0);
                    let all =
                        direct + arrivals[1..].iter().map(|(tau, a)| a * waveform.value(alpha * t - tau)).sum::<f64>();
                    (direct, all)
                })
                .collect();
            direct_energy += samples.iter().map(|(d, _)| d * d).sum::<f64>();
            samples.into_iter().map(|(_, x)| x).collect()
        })
        .collect();
    if let Some(snr_db) = ch.snr_db {
        // 2E/N0 = sum of x^2 / sigma^2 for white noise of variance sigma^2
        let e = direct_energy / elements.len().max(1) as f64;
        let sigma = (e / 10f64.powf(snr_db / 10.0)).sqrt();
        for x in captures.iter_mut().flatten() {
            *x += crate::seed::gauss(rng, sigma);
        }
    }
    captures
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use onebeacon::dsp::waveform::Lfm;

    #[test]
    fn image_sources_mirror_the_boundaries() {
        let b = Boundaries {
            water_depth_m: 5.0,
            surface_coef: -1.0,
            bottom_coef: 0.5,
            wall_east_m: Some(10.0),
            wall_coef: 0.8,
        };
        let im = images(&Vector3::new(1.0, 2.0, 1.5), &Some(b));
        assert_eq!(im.len(), 10);
        assert_eq!(im[1], (Vector3::new(1.0, 2.0, -1.5), -1.0));
        assert_eq!(im[2], (Vector3::new(1.0, 2.0, 8.5), 0.5));
        assert_eq!(im[5], (Vector3::new(1.0, 18.0, 1.5), 0.8));
    }

    #[test]
    fn noise_has_the_requested_snr() {
        let ch = Channel { snr_db: Some(20.0), ..Channel::default() };
        let chirp = Lfm::new(7e3, 9e3, 0.02);
        let el = onebeacon::dsp::beamform::pyramid_8cm();
        let mut rng = crate::seed::rng(1, 0, crate::seed::Stream::Acoustic);
        let src = Vector3::new(100.0, 0.0, 1.0);
        let rx = Vector3::new(0.0, 0.0, 3.0);
        let noisy = simulate_ping(&chirp, &src, &rx, &Matrix3::identity(), &el, &ch, &mut rng);
        let clean = simulate_ping(
            &chirp,
            &src,
            &rx,
            &Matrix3::identity(),
            &el,
            &Channel { snr_db: None, ..ch.clone() },
            &mut rng,
        );
        let (mut e, mut n) = (0.0, 0.0);
        for (a, b) in noisy.iter().flatten().zip(clean.iter().flatten()) {
            e += b * b;
            n += (a - b) * (a - b);
        }
        let per_sample_noise = n / (8000.0 * 5.0);
        let snr = 10.0 * ((e / 5.0) / per_sample_noise).log10();
        assert!((snr - 20.0).abs() < 0.2, "{snr}");
        // spherical spreading: amplitude 1 / distance
        let peak = clean[0].iter().cloned().fold(0.0, f64::max);
        assert_relative_eq!(peak, 1.0 / (src - rx).norm(), max_relative = 0.02);
    }
}
