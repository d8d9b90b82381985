//! What a USBL head on a surface vehicle measures besides eq. 3's noise: it is mounted
//! with a misalignment against the vehicle's axes, the waves roll and pitch the vehicle,
//! and an attitude sensor with its own error and latency levels the measured direction
//! again; hull and propellers occlude sectors of the head, where nothing is heard; and
//! each angle has a noise floor besides the range-proportional term (the floor itself
//! lives in [`onebeacon::measure::Usbl`], which the trackers read).

use crate::seed::gauss;
use nalgebra::{Rotation3, Vector3};
use onebeacon::geo::wrap_angle;
use rand::RngExt;
use rand_pcg::Pcg64Mcg;
use serde::{Deserialize, Serialize};
use std::f64::consts::{PI, TAU};

/// `[sea.usbl]`: all zero, a head aligned on a flat sea, heard all round.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct UsblErrors {
    /// The head's mounting misalignment against the vehicle's axes, deg: roll, pitch and
    /// yaw, rotated in that order (R = Rz(yaw) Ry(pitch) Rx(roll)). A residual after
    /// calibration, unknown to the filters.
    pub misalignment_deg: [f64; 3],
    /// The carrier's roll and pitch in the waves (standard deviations, deg), each a
    /// narrow-band sea about `wave_period_s` (s).
    pub wave_roll_deg: f64,
    pub wave_pitch_deg: f64,
    pub wave_period_s: f64,
    /// The attitude sensor that levels the measured direction: its roll and pitch error
    /// (standard deviation, deg, white) and its latency (s: it reports the attitude of
    /// that long ago).
    pub attitude_noise_deg: f64,
    pub attitude_latency_s: f64,
    /// A noise floor on each angle (standard deviation, deg), besides
    /// `usbl.noise_deg_per_m`'s range-proportional term.
    pub angle_floor_deg: f64,
    /// Sectors of the head's azimuth where nothing is heard, `[from, to]` in deg from the
    /// bow, clockwise from `from` to `to` (`[[150, 210]]`: astern, the propellers).
    pub occluded_deg: Vec<[f64; 2]>,
}

impl Default for UsblErrors {
    fn default() -> Self {
        Self {
            misalignment_deg: [0.0; 3],
            wave_roll_deg: 0.0,
            wave_pitch_deg: 0.0,
            wave_period_s: 6.0,
            attitude_noise_deg: 0.0,
            attitude_latency_s: 0.0,
            angle_floor_deg: 0.0,
            occluded_deg: Vec::new(),
        }
    }
}

impl UsblErrors {
    /// Whether the head differs from an aligned one on a flat sea heard all round (the
    /// floor aside, which only widens the noise).
    pub fn bends(&self) -> bool {
        self.misalignment_deg.iter().any(|a| *a != 0.0)
            || self.wave_roll_deg > 0.0
            || self.wave_pitch_deg > 0.0
            || self.attitude_noise_deg > 0.0
            || !self.occluded_deg.is_empty()
    }
}

/// Sinusoids a narrow-band sea is summed from: enough for a Gaussian-looking motion,
/// few enough to cost nothing.
const WAVE_COMPONENTS: usize = 8;

/// One angle of wave motion: equal sinusoids at frequencies spread evenly over 0.7-1.4
/// of the peak's, each with a random phase (a run's sea), summing to the asked standard
/// deviation (each amplitude sigma sqrt(2 / K)).
#[derive(Debug, Clone)]
struct Swell {
    amplitude: f64,
    omega: [f64; WAVE_COMPONENTS],
    phase: [f64; WAVE_COMPONENTS],
}

impl Swell {
    fn new(sigma_rad: f64, period_s: f64, rng: &mut Pcg64Mcg) -> Self {
        let peak = TAU / period_s;
        let omega = std::array::from_fn(|i| peak * (0.7 + 0.7 * i as f64 / (WAVE_COMPONENTS - 1) as f64));
        let phase = std::array::from_fn(|_| TAU * rng.random::<f64>());
        Self { amplitude: sigma_rad * (2.0 / WAVE_COMPONENTS as f64).sqrt(), omega, phase }
    }

    fn at(&self, t_s: f64) -> f64 {
        if self.amplitude == 0.0 {
            return 0.0;
        }
        self.omega.iter().zip(&self.phase).map(|(w, p)| (w * t_s + p).sin()).sum::<f64>() * self.amplitude
    }
}

/// A USBL head over one run: its mounting, its carrier's waves, its attitude sensor.
#[derive(Debug, Clone)]
pub struct UsblHead {
    mounting: Rotation3<f64>,
    roll: Swell,
    pitch: Swell,
    attitude_sigma_rad: f64,
    latency_s: f64,
    /// Occluded sectors as (start, width), rad from the bow clockwise.
    occluded: Vec<(f64, f64)>,
    rng: Pcg64Mcg,
}

impl UsblHead {
    /// The head of `errors`, its sea and its attitude errors drawn from `rng` (a stream
    /// of its own).
    pub fn new(errors: &UsblErrors, mut rng: Pcg64Mcg) -> Self {
        let [r, p, y] = errors.misalignment_deg.map(f64::to_radians);
        let roll = Swell::new(errors.wave_roll_deg.to_radians(), errors.wave_period_s, &mut rng);
        let pitch = Swell::new(errors.wave_pitch_deg.to_radians(), errors.wave_period_s, &mut rng);
        let occluded = errors
            .occluded_deg
            .iter()
            .map(|[from, to]| (from.to_radians().rem_euclid(TAU), (to - from).to_radians().rem_euclid(TAU)))
            .collect();
        Self {
            mounting: Rotation3::from_euler_angles(r, p, y),
            roll,
            pitch,
            attitude_sigma_rad: errors.attitude_noise_deg.to_radians(),
            latency_s: errors.attitude_latency_s,
            occluded,
            rng,
        }
    }

    /// The azimuth (from the carrier's heading) and elevation (eq. 1-2) the head reports,
    /// before its angle noise, for a signal arriving along `toward_source` (NED, from the
    /// head toward where it comes from) at `t_s` on a carrier heading `heading_rad`; None
    /// when the head is occluded that way.
    pub fn measure(&mut self, toward_source: &Vector3<f64>, heading_rad: f64, t_s: f64) -> Option<(f64, f64)> {
        let body = Rotation3::from_euler_angles(self.roll.at(t_s), self.pitch.at(t_s), heading_rad);
        let in_head = (body * self.mounting).inverse() * toward_source;
        let bow = in_head.y.atan2(in_head.x).rem_euclid(TAU);
        if self.occluded.iter().any(|&(start, width)| (bow - start).rem_euclid(TAU) <= width) {
            return None;
        }
        // levelled with the attitude sensor's roll and pitch (the head taken as aligned)
        let t = t_s - self.latency_s;
        let roll = self.roll.at(t) + gauss(&mut self.rng, self.attitude_sigma_rad);
        let pitch = self.pitch.at(t) + gauss(&mut self.rng, self.attitude_sigma_rad);
        let level = Rotation3::from_euler_angles(roll, pitch, 0.0) * in_head;
        Some((wrap_angle(level.y.atan2(level.x)), level.xy().norm().atan2(level.z)))
    }

    /// A false detection's angles: azimuth uniform all round from `u` (uniform on [0,
    /// 1)), elevation uniform below the horizon.
    pub fn false_angles(&mut self, u: f64) -> (f64, f64) {
        (TAU * u - PI, 0.5 * PI * self.rng.random::<f64>())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    fn head(errors: UsblErrors) -> UsblHead {
        UsblHead::new(&errors, Pcg64Mcg::seed_from_u64(5))
    }

    fn toward(az: f64, el: f64) -> Vector3<f64> {
        Vector3::new(el.sin() * az.cos(), el.sin() * az.sin(), el.cos())
    }

    /// An aligned head on a flat sea reports eq. 1-2's angles; a yaw misalignment turns
    /// the azimuth by minus itself and leaves the elevation; a roll misalignment of a
    /// head on a vehicle heading east tilts a signal from straight south (its starboard
    /// beam) by itself: elevation 90 deg from the vertical seen 5 deg lower or higher
    /// (the mounting turned with the vehicle, not about north).
    #[test]
    fn misalignment_turns_the_angles_by_itself() {
        let (az, el, psi) = (0.7, 1.1, -2.5);
        let (a, e) = head(UsblErrors::default()).measure(&toward(az + psi, el), psi, 3.0).unwrap();
        assert!((a - az).abs() < 1e-12 && (e - el).abs() < 1e-12);
        let yawed = UsblErrors { misalignment_deg: [0.0, 0.0, 2.0], ..UsblErrors::default() };
        let (a, e) = head(yawed).measure(&toward(az + psi, el), psi, 3.0).unwrap();
        assert!((a - (az - 2f64.to_radians())).abs() < 1e-12 && (e - el).abs() < 1e-12);
        let rolled = UsblErrors { misalignment_deg: [5.0, 0.0, 0.0], ..UsblErrors::default() };
        let (a, e) = head(rolled).measure(&toward(PI, PI / 2.0), PI / 2.0, 3.0).unwrap();
        assert!((a - PI / 2.0).abs() < 1e-12 && ((e - PI / 2.0).abs() - 5f64.to_radians()).abs() < 1e-12);
    }

    /// Waves levelled by an exact sensor change nothing (1e-12); their roll and pitch
    /// have the asked standard deviation over 2e4 s (within 10 %: 8 components'
    /// random phases); a sensor 0.5 s late leaves an error of about the roll rate's
    /// sigma omega times 0.5 s, a sensor with noise its noise.
    #[test]
    fn waves_are_levelled_by_the_attitude_sensor() {
        let sea = UsblErrors { wave_roll_deg: 5.0, wave_pitch_deg: 2.0, ..UsblErrors::default() };
        let mut h = head(sea.clone());
        let (az, el, psi) = (0.3, 0.9, 1.0);
        for k in 0..100 {
            let (a, e) = h.measure(&toward(az + psi, el), psi, 0.37 * k as f64).unwrap();
            assert!((a - az).abs() < 1e-12 && (e - el).abs() < 1e-12, "{k}");
        }
        let n = 20_000;
        let rms = |s: &Swell| ((0..n).map(|k| s.at(k as f64 * 1.01).powi(2)).sum::<f64>() / n as f64).sqrt();
        assert!((rms(&h.roll).to_degrees() / 5.0 - 1.0).abs() < 0.1, "roll {}", rms(&h.roll).to_degrees());
        assert!((rms(&h.pitch).to_degrees() / 2.0 - 1.0).abs() < 0.1, "pitch {}", rms(&h.pitch).to_degrees());
        // straight east of a head heading north: the elevation reads the roll error
        let east = toward(PI / 2.0, PI / 2.0);
        let spread = |errors: UsblErrors| {
            let mut h = head(errors);
            let e: Vec<f64> = (0..n).map(|k| h.measure(&east, 0.0, k as f64 * 1.01).unwrap().1 - PI / 2.0).collect();
            (e.iter().map(|v| v * v).sum::<f64>() / n as f64).sqrt().to_degrees()
        };
        let late = spread(UsblErrors { attitude_latency_s: 0.5, wave_pitch_deg: 0.0, ..sea.clone() });
        // the rate's mean square over the band: sigma^2 times the mean of omega^2
        let omega2 = (0..WAVE_COMPONENTS)
            .map(|i| (TAU / 6.0 * (0.7 + 0.7 * i as f64 / (WAVE_COMPONENTS - 1) as f64)).powi(2))
            .sum::<f64>()
            / WAVE_COMPONENTS as f64;
        let expected = 5.0 * omega2.sqrt() * 0.5;
        assert!((late / expected - 1.0).abs() < 0.15, "late {late} against {expected}");
        let noisy = spread(UsblErrors { attitude_noise_deg: 0.2, ..sea });
        assert!((noisy / 0.2 - 1.0).abs() < 0.05, "noisy {noisy}");
    }

    /// A sector from 150 to 210 deg hides what is astern, relative to the bow whatever
    /// the heading; one across north (350 to 10) hides the bow.
    #[test]
    fn occluded_sectors_hide_the_signal() {
        let stern = UsblErrors { occluded_deg: vec![[150.0, 210.0], [350.0, 10.0]], ..UsblErrors::default() };
        let mut h = head(stern);
        for psi in [0.0, 2.0, -3.0] {
            for (rel_deg, heard) in
                [(180.0, false), (155.0, false), (145.0, true), (90.0, true), (5.0, false), (-5.0, false), (15.0, true)]
            {
                let rel = f64::to_radians(rel_deg);
                assert_eq!(h.measure(&toward(psi + rel, 1.0), psi, 0.0).is_some(), heard, "{psi} {rel_deg}");
            }
        }
    }
}
