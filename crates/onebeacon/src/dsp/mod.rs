//! Receiver signal processing: what turns sampled hydrophone signals into range, angle
//! and mode (rypkema sections 3.2, 4.2).
//!
//! - [`waveform`]: LFM chirps and rypkema's four command chirps;
//! - [`matched_filter`]: PHAT-whitened matched filter per element, the element
//!   consistency gate, their combination and the range pseudo-distribution (eq. 2-5);
//! - [`beamform`]: conventional wideband beamforming (eq. 9-11) and sensor-pair
//!   decomposition beamforming (SPD-BF), on grids or at any direction;
//! - [`doppler`]: Doppler speed from a pure tone (garin eq. 9, Kay's estimator);
//! - [`modes`]: command-mode identification against a template bank;
//! - [`receiver`]: one ping through the chain, to range and direction;
//! - [`sound_speed`]: Mackenzie (1981).

pub mod beamform;
pub mod doppler;
pub mod matched_filter;
pub mod modes;
pub mod receiver;
pub mod sound_speed;
pub mod waveform;

/// Complex numbers of the FFTs.
pub type Complex = rustfft::num_complex::Complex<f64>;
