//! The smoother's configuration as users name it (`onebeacon smooth`'s flags, the
//! Python `smooth`'s keywords): an estimator of the log to weigh as, calibration
//! variables and a kernel by name.

use super::{Calibrate, Offsets, SmoothConfig};
use onebeacon::log::Log;
use onebeacon::nav::Robust;

/// The calibration variables' names.
pub const CALIBRATION_NAMES: &str =
    "none, all, range_scale, turn_scale, distance_scale, offsets, shared_offset, clock_drift";
/// The kernels' names.
pub const KERNEL_NAMES: &str = "none, huber, cauchy, student_t";

/// The defaults, or what the log's estimator `like` reads (its noise, kernel, gate,
/// calibration, a constant-velocity model), with the variables `calibrate`, the kernel
/// `kernel` and a constant-velocity model of white acceleration `track_accel` (m/s^1.5)
/// over them; the error names what is wrong and what is allowed.
pub fn config(
    log: &Log,
    like: Option<&str>,
    calibrate: Option<&[String]>,
    kernel: Option<&str>,
    track_accel: Option<f64>,
) -> Result<SmoothConfig, String> {
    // without --like, the default smoother with the log's `[noise]`
    let mut cfg = SmoothConfig { noise: log.description.default_noise(), ..SmoothConfig::default() };
    if let Some(name) = like {
        let estimators = &log.description.estimators;
        let e = estimators.iter().find(|e| e.name() == name).ok_or_else(|| {
            let names: Vec<String> = estimators.iter().map(|e| e.name()).collect();
            format!("like {name}: not an estimator of the log (estimators: {})", names.join(", "))
        })?;
        let p = e.planar_config();
        if p.extended() || p.speed_coast_time_s.is_some() {
            return Err(format!(
                "like {name}: the smoother has no heading offset, current or coasting speed (estimate_heading_offset, estimate_current, speed_coast_time_s); smooth like an estimator without them"
            ));
        }
        let offsets = match (p.estimate_beacon_offsets, p.estimate_bias) {
            (true, _) => Offsets::PerBeacon,
            (false, true) => Offsets::Shared,
            (false, false) => Offsets::None,
        };
        let c = Calibrate {
            range_scale: p.estimate_range_scale,
            turn_scale: p.estimate_turn_scale,
            distance_scale: p.estimate_distance_scale,
            offsets,
            clock_drift: false,
        };
        cfg = SmoothConfig::from_planar(&p, c);
    }
    if let Some(a) = track_accel {
        if !(a.is_finite() && a > 0.0) {
            return Err(format!("track-accel {a}: the white acceleration must be a positive number of m/s^1.5"));
        }
        cfg.track_accel_sigma_m_s2 = Some(a);
    }
    if let Some(names) = calibrate {
        cfg.calibrate = calibration(names)?;
    }
    if let Some(k) = kernel {
        cfg.kernel = kernel_named(k)?;
    }
    Ok(cfg)
}

fn calibration(names: &[String]) -> Result<Calibrate, String> {
    let mut c = Calibrate::NONE;
    for n in names {
        match n.as_str() {
            "none" => c = Calibrate::NONE,
            "all" => c = Calibrate::ALL,
            "range_scale" => c.range_scale = true,
            "turn_scale" => c.turn_scale = true,
            "distance_scale" => c.distance_scale = true,
            "offsets" => c.offsets = Offsets::PerBeacon,
            "shared_offset" => c.offsets = Offsets::Shared,
            "clock_drift" => c.clock_drift = true,
            other => {
                return Err(format!("calibrate {other}: not a calibration variable (allowed: {CALIBRATION_NAMES})"));
            }
        }
    }
    Ok(c)
}

fn kernel_named(name: &str) -> Result<Option<Robust>, String> {
    Ok(match name {
        "none" => None,
        "huber" => Some(Robust::Huber { k: 1.345 }),
        "cauchy" => Some(Robust::Cauchy { k: 2.3849 }),
        "student_t" => Some(Robust::StudentT { dof: 4.0 }),
        other => return Err(format!("kernel {other}: not a kernel (allowed: {KERNEL_NAMES})")),
    })
}
