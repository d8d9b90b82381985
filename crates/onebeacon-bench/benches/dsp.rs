//! One 5-element, 8000-sample ping: PHAT matched filter against 4 templates (mode
//! identification) plus range and SPD-BF on a 0.25 deg conical grid with a 2 deg
//! direction search and refinement (target: under 5 ms on one core).

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::Vector3;
use onebeacon::dsp::beamform::{Cbf, DirectionGrid, Snapshot, SpdBf, direction, pyramid_8cm};
use onebeacon::dsp::matched_filter::MatchedFilter;
use onebeacon::dsp::modes::ModeBank;
use onebeacon::dsp::receiver::ModeReceiver;
use onebeacon::dsp::receiver::{Receiver, ReceiverConfig};
use onebeacon::dsp::waveform::rypkema_modes;
use onebeacon::nav::{BeaconFix, Capture, IusblConfig, IusblNavigator, Kind, Measurement, Navigator};
use std::hint::black_box;
use std::sync::Arc;

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
    let filters = modes.iter().map(|m| MatchedFilter::classical(&m.samples(fs), m.band(), fs, 8000)).collect();
    let centres = modes.iter().map(|m| (m.f0_hz + m.f1_hz) / 2.0).collect();
    let bank = ModeBank::with_array(filters, centres, el.clone(), 1500.0);
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

    // one second of one AUV with the signal in the loop (rypkema: about 500 ms on a
    // Raspberry Pi 3): 10 speed and attitude samples, the ping's receiver chain (mode
    // bank, PHAT range, SPD-BF tables) and the factored update of 500 particles
    let mut nav =
        IusblNavigator::new(IusblConfig::default(), Some(ModeReceiver::new(&modes, &el, ReceiverConfig::default())), 1);
    let capture =
        Arc::new(Capture { beacon: BeaconFix::fixed(0, Vector3::new(100.0, 60.0, 1.0)), samples: captures.clone() });
    let mut t = 0.0;
    c.bench_function("iusbl: one second of one AUV (receiver chain + 500-particle factored update)", |b| {
        b.iter(|| {
            for _ in 0..10 {
                t += 0.1;
                nav.process(&Measurement::new(t, Kind::Speed { speed_m_s: 1.0 }));
                nav.process(&Measurement::new(t, Kind::Attitude { roll_rad: 0.0, pitch_rad: 0.0, heading_rad: 0.3 }));
            }
            black_box(nav.process(&Measurement::new(t, Kind::Capture(capture.clone()))))
        })
    });
    let fix = Kind::ArrayFix {
        beacon: BeaconFix::fixed(0, Vector3::new(100.0, 60.0, 1.0)),
        range_m: 117.0,
        azimuth_rad: 0.4,
        inclination_rad: 1.6,
        mode: 0,
    };
    c.bench_function("iusbl: the 500-particle factored update alone (a fix's likelihoods)", |b| {
        b.iter(|| {
            t += 1.0;
            black_box(nav.process(&Measurement::new(t, fix.clone())))
        })
    });

    // CBF against SPD-BF over the same 1 deg azimuth x inclination grid (65 160 looks)
    let snap = Snapshot::from_segment(&captures, 3100, 1024, modes[0].band(), fs);
    let grid = DirectionGrid::new(1f64.to_radians());
    let cbf = Cbf { elements: el.clone(), sound_speed_m_s: 1500.0 };
    let mut spd = SpdBf::new(&el, 1500.0, 0.25f64.to_radians());
    let mut group = c.benchmark_group("1 deg direction grid");
    group.sample_size(10);
    group.bench_function("CBF (steering computed on the fly)", |b| {
        b.iter(|| black_box(grid.search(|u| cbf.power(&snap, u))))
    });
    group.bench_function("SPD-BF (pair tables at 0.25 deg + lookups)", |b| {
        b.iter(|| {
            spd.compute(black_box(&snap));
            black_box(grid.search(|u| spd.power(u)))
        })
    });
    group.finish();
    let (n_cos, pairs) = spd.size();
    eprintln!(
        "memory: SPD tables {pairs} x {n_cos} x 8 B = {} kB; a stored CBF steering table: {} looks x {} elements x {} bins x 16 B = {:.0} MB",
        pairs * n_cos * 8 / 1000,
        grid.len(),
        el.len(),
        snap.freqs_hz.len(),
        (grid.len() * el.len() * snap.freqs_hz.len() * 16) as f64 / 1e6
    );
}

criterion_group!(benches, bench);
criterion_main!(benches);
