//! The ping of `../shared/bench/dsp_numpy.py` (and of `benches/dsp.rs`) timed the way
//! the Python script times it, for a side-by-side comparison (`scripts/dsp_peers.sh`):
//! the 5-element pyramid, 8000 samples at 37.5 kS/s, the mode-0 chirp from direction
//! (az = 1 rad, incl = 2 rad) at 120 m plus the bench's deterministic 'noise'.
//!
//!     cargo run --release -p onebeacon --example dsp_peer -- [reps]
//!
//! `ping_full`: 4-template mode identification (with the coherent alignment), PHAT
//! range, SPD-BF tables at 0.25 deg, the 2 deg direction search and its refinement;
//! `ping_range`: PHAT range and SPD-BF only. Prints RESULT lines like the script's:
//! ms per ping, median and min over `reps` after one warm-up. With `STAGES=1` it also
//! prints each stage's median (spectra, mode identification, pseudo-distributions,
//! PHAT envelopes, eq. 4, SPD-BF tables, everything but the mode search).

use onebeacon::dsp::beamform::{direction, pyramid_8cm};
use onebeacon::dsp::matched_filter::MatchedFilter;
use onebeacon::dsp::modes::ModeBank;
use onebeacon::dsp::receiver::{Receiver, ReceiverConfig};
use onebeacon::dsp::waveform::rypkema_modes;
use std::hint::black_box;
use std::time::Instant;

fn time(reps: usize, mut f: impl FnMut()) -> (f64, f64) {
    f();
    let mut t: Vec<f64> = (0..reps)
        .map(|_| {
            let a = Instant::now();
            f();
            a.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    t.sort_by(f64::total_cmp);
    (t[t.len() / 2], t[0])
}

fn main() {
    let reps: usize = std::env::args().nth(1).and_then(|a| a.parse().ok()).unwrap_or(30);
    let fs = 37_500.0;
    let modes = rypkema_modes();
    let el = pyramid_8cm();
    let u = direction(1.0, 2.0);
    let captures: Vec<Vec<f64>> = el
        .iter()
        .map(|r| {
            let tau = 120.0 / 1500.0 - r.dot(&u) / 1500.0;
            (0..8000).map(|n| modes[0].value(n as f64 / fs - tau) + 1e-3 * ((n * 7919) % 13) as f64).collect()
        })
        .collect();
    let filters = modes.iter().map(|m| MatchedFilter::classical(&m.samples(fs), m.band(), fs, 8000)).collect();
    let centres = modes.iter().map(|m| (m.f0_hz + m.f1_hz) / 2.0).collect();
    let bank = ModeBank::with_array(filters, centres, el.clone(), 1500.0);
    let mut rx = Receiver::new(modes[0], &el, ReceiverConfig::default());
    let (mut padded, mut spectra) = (Vec::new(), Vec::new());
    let (median, min) = time(reps, || {
        bank.spectra_into(black_box(&captures), &mut padded, &mut spectra);
        let mode = bank.identify(&spectra);
        black_box((mode, rx.process_spectra(&captures, &spectra)));
    });
    println!("RESULT dsp rust ping_full median_ms={median:.3} min_ms={min:.3} reps={reps}");
    let (median, min) = time(reps, || {
        black_box(rx.process(black_box(&captures)));
    });
    println!("RESULT dsp rust ping_range median_ms={median:.3} min_ms={min:.3} reps={reps}");
    if std::env::var("STAGES").is_ok() {
        let (m, _) = time(reps, || {
            bank.spectra_into(&captures, &mut padded, &mut spectra);
        });
        println!("spectra {m:.3}");
        let (m, _) = time(reps, || {
            black_box(bank.identify(&spectra));
        });
        println!("identify {m:.3}");
        let (m, _) = time(reps, || {
            black_box(rx.distributions(&captures, &spectra));
        });
        println!("distributions {m:.3}");
        let f = MatchedFilter::new(&modes[0].samples(fs), modes[0].band(), fs, 8000);
        let mut w = Vec::new();
        let mut e = Vec::new();
        let (m, _) = time(reps, || {
            for x in &spectra {
                f.envelope_into(x, &mut w, &mut e);
            }
        });
        println!("5 phat envelopes {m:.3}");
        let envs: Vec<Vec<f64>> = spectra.iter().map(|x| f.envelope_of(x)).collect();
        let (m, _) = time(reps, || {
            black_box(onebeacon::dsp::matched_filter::estimate_range(&envs, 15, fs, 1500.0));
        });
        println!("estimate_range {m:.3}");
        let snap = onebeacon::dsp::beamform::Snapshot::from_segment(&captures, 3100, 1024, modes[0].band(), fs);
        let mut spd = onebeacon::dsp::beamform::SpdBf::new(&el, 1500.0, 0.25f64.to_radians());
        let (m, _) = time(reps, || {
            spd.compute(&snap);
        });
        println!("spd compute {m:.3}");
        let (m, _) = time(reps, || {
            black_box(rx.process_spectra(&captures, &spectra));
        });
        println!("process_spectra {m:.3}");
    }
}
