//! One 5-element, 8000-sample ping: PHAT matched filter against 4 templates (mode
//! identification) plus range and SPD-BF on a 0.25 deg conical grid with a 2 deg
//! direction search and refinement (target: under 5 ms on one core).

use criterion::{Criterion, criterion_group, criterion_main};
use onebeacon::dsp::beamform::{direction, pyramid_8cm};
use onebeacon::dsp::matched_filter::MatchedFilter;
use onebeacon::dsp::modes::ModeBank;
use onebeacon::dsp::receiver::{Receiver, ReceiverConfig};
use onebeacon::dsp::waveform::rypkema_modes;
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let fs = 37_500.0;
    let modes = rypkema_modes();
    let el = pyramid_8cm();
    let u = direction(1.0, 2.0);
    // a noise-free plane wave 120 m away; the work does not depend on the content
    let captures: Vec<Vec<f64>> = el
        .iter()
        .map(|r| {
            let tau = 120.0 / 1500.0 - r.dot(&u) / 1500.0;
            (0..8000).map(|n| modes[0].value(n as f64 / fs - tau) + 1e-3 * ((n * 7919) % 13) as f64).collect()
        })
        .collect();
    let bank =
        ModeBank::new(modes.iter().map(|m| MatchedFilter::classical(&m.samples(fs), m.band(), fs, 8000)).collect());
    let mut rx = Receiver::new(modes[0], &el, ReceiverConfig::default());
    c.bench_function("ping: 4-template mode id + PHAT range + SPD-BF 0.25 deg", |b| {
        b.iter(|| {
            let spectra = bank.spectra(black_box(&captures));
            let mode = bank.identify(&spectra);
            black_box((mode, rx.process_spectra(black_box(&captures), &spectra)))
        })
    });
    c.bench_function("ping: PHAT range + SPD-BF 0.25 deg only", |b| {
        b.iter(|| black_box(rx.process(black_box(&captures))))
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
