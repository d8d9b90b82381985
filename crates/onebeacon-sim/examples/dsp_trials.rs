//! The receiver chain's trials at the counts behind docs/reproductions/receiver.md's
//! tables, as JSON on stdout (scripts/reproduce formats them):
//! `cargo run --release -p onebeacon-sim --example dsp_trials [-- --quick]`.
//! `--quick` runs each trial at a tenth of its count or less (what CI checks).

#[path = "../tests/dsp_trials/mod.rs"]
mod dsp_trials;

use dsp_trials::*;
use onebeacon::dsp::matched_filter::detection_threshold;
use onebeacon_sim::acoustics::channel::{Boundaries, Channel};
use serde_json::{Value, json};

const SNRS_CHIRP_DB: [f64; 6] = [-10.0, -5.0, 0.0, 5.0, 10.0, 20.0];
const SNRS_FRAME_DB: [f64; 4] = [10.0, 20.0, 30.0, 40.0];

/// The quantiles every statistic row gives, and how many of `v` reach `threshold`.
fn quantiles(v: &[f64], threshold: f64) -> Value {
    json!({"n": v.len(), "p01": percentile(v, 0.01), "p05": percentile(v, 0.05), "median": percentile(v, 0.5),
           "p99": percentile(v, 0.99), "p999": percentile(v, 0.999), "max": percentile(v, 1.0),
           "reaching_threshold": v.iter().filter(|&&s| s >= threshold).count()})
}

fn errors(e: &Errors) -> Value {
    json!({"pings": e.range_m.len(), "range_m_68": percentile(&e.range_m, 0.68),
           "azimuth_deg_68": percentile(&e.azimuth_deg, 0.68),
           "azimuth_over_crb_68": percentile(&e.azimuth_over_crb, 0.68),
           "direction_deg_68": percentile(&e.direction_deg, 0.68)})
}

fn main() {
    let quick = match std::env::args().nth(1).as_deref() {
        None => false,
        Some("--quick") => true,
        Some(other) => {
            eprintln!("dsp_trials: unknown argument {other:?}; the only one is --quick");
            std::process::exit(2);
        }
    };
    let n = |full: usize, small: usize| if quick { small } else { full };
    let step = |what: &str| eprintln!("dsp_trials: {what} ...");

    step("chirp pings, free field and surface + bottom");
    let shallow =
        Boundaries { water_depth_m: 5.0, surface_coef: -1.0, bottom_coef: 0.5, wall_east_m: None, wall_coef: 0.0 };
    let pings = json!([
        {"channel": "free field", "errors": errors(&chirp_errors(n(1000, 40), &Channel::default(), false, 2))},
        {"channel": "surface + bottom in 5 m of water",
         "errors": errors(&chirp_errors(n(1000, 40), &Channel { boundaries: Some(shallow), ..Channel::default() }, true, 3))},
    ]);

    step("mode identification");
    let modes: Vec<Value> = [0.0, 5.0, 10.0]
        .iter()
        .map(|&snr| {
            let pings = n(1000, 40);
            let share: Vec<f64> =
                [None, Some(15.0), Some(5.0)].iter().map(|&g| mode_accuracy(pings, snr, 6, g)).collect();
            json!({"snr_db": snr, "pings": pings, "whole": share[0], "gate_15": share[1], "gate_5": share[2]})
        })
        .collect();

    step("garin2024's tone and frame synchronisation");
    let (ml, pulse_pair, bound) = tone_doppler(n(2000, 50), 9);
    let sync = frame_sync_errors(n(500, 20), 5);
    let garin = json!({"tone_frames": n(2000, 50), "ml_rmse_m_s": ml, "eq9_rmse_m_s": pulse_pair, "bound_m_s": bound,
                       "sync_frames": sync.len(), "sync_rms_m": rms(&sync), "sync_68_m": percentile(&sync, 0.68)});

    step("the chirp's detection statistic");
    let (chirp, chirp_lags) = chirp_detection_statistics(n(2000, 50), &SNRS_CHIRP_DB, n(300, 20), 9);
    let chirp_rows: Vec<Value> = std::iter::once(None)
        .chain(SNRS_CHIRP_DB.iter().map(Some))
        .zip(&chirp)
        .map(|(snr, s)| json!({"snr_db": snr, "statistic": quantiles(s, detection_threshold(chirp_lags))}))
        .collect();

    step("the frame's detection statistic");
    let (frames, lags) = frame_detection_statistics(n(1000, 20), &SNRS_FRAME_DB, n(100, 10), 9);
    let frame_rows: Vec<Value> = std::iter::once(None)
        .chain(SNRS_FRAME_DB.iter().map(Some))
        .zip(&frames)
        .map(|(snr, s)| {
            json!({"snr_db": snr, "synchronised": s.synchronised,
                   "statistic": quantiles(&s.statistic, detection_threshold(lags)),
                   "peak_over_mean": quantiles(&s.peak_over_mean, f64::INFINITY)})
        })
        .collect();

    let out = json!({
        "pings": pings, "modes": modes, "garin": garin,
        "chirp_detection": {"lags": chirp_lags, "threshold": detection_threshold(chirp_lags), "rows": chirp_rows},
        "frame_detection": {"lags": lags, "threshold": detection_threshold(lags), "rows": frame_rows},
    });
    println!("{out:#}");
}
