//! The particle filter of `../shared/bench/pf_peers.py` (Stone Soup and numpy) with
//! onebeacon's `ParticleFilter`, for a side-by-side timing (`scripts/pf_peers.sh`):
//! 8 states [x, vx, y, vy, z, vz, b1, b2] (three constant-velocity axes, q = 0.05,
//! dt = 1 s, two random walks, q = 1e-4), (elevation, azimuth) of the position seen from
//! the origin with 1 deg noise, systematic resampling every cycle.
//!
//!     cargo run --release -p onebeacon --example pf_peer -- N [cycles]
//!
//! Prints the same RESULT line as the Python script: ms per cycle (median and min over
//! the cycles after 2 warm-up ones) and the final position error.

use nalgebra::SVector;
use onebeacon::filter::lanes;
use onebeacon::filter::particle::{ParticleFilter, ParticleLikelihood, ParticleProcess, ParticleSettings, Resampler};
use rand::{RngExt, SeedableRng};
use rand_distr::StandardNormal;
use rand_pcg::Pcg64;

const DT: f64 = 1.0;
const Q_CV: f64 = 0.05;
const Q_RW: f64 = 1e-4;

/// The lower Cholesky factor of one constant-velocity axis's q [[dt^3/3, dt^2/2],
/// [dt^2/2, dt]].
fn cv_factor() -> (f64, f64, f64) {
    let (a, b, c) = (Q_CV * DT.powi(3) / 3.0, Q_CV * DT * DT / 2.0, Q_CV * DT);
    let l11 = a.sqrt();
    let l21 = b / l11;
    (l11, l21, (c - l21 * l21).sqrt())
}

/// Particles handled at a time: the scratch arrays stay in the first-level cache.
const BLOCK: usize = 256;

struct Motion;

impl ParticleProcess for Motion {
    /// A constant-velocity step is the same for offsets from any origin.
    fn propagate(&self, x: &mut [&mut [f32]], origin: &[f64], dt: f64, rng: &mut Pcg64) {
        let (l11, l21, l22) = cv_factor();
        let (l11, l21, l22) = (l11 as f32, l21 as f32, l22 as f32);
        let rw = (Q_RW * dt).sqrt() as f32;
        let (dt, v0) = (dt as f32, [origin[1], origin[3], origin[5]].map(|v| (v * dt) as f32));
        let n = x[0].len();
        let mut e = [0.0; 8 * BLOCK];
        for start in (0..n).step_by(BLOCK) {
            let m = BLOCK.min(n - start);
            lanes::standard_normals(rng, &mut e[..8 * m]);
            for axis in 0..3 {
                let (e1, e2) = (&e[2 * axis * m..(2 * axis + 1) * m], &e[(2 * axis + 1) * m..(2 * axis + 2) * m]);
                let (p, v) = x[2 * axis..].split_at_mut(1);
                let (p, v) = (&mut p[0][start..start + m], &mut v[0][start..start + m]);
                for j in 0..m {
                    p[j] += (v[j] * dt + v0[axis]) + l11 * e1[j];
                    v[j] += l21 * e1[j] + l22 * e2[j];
                }
            }
            for (k, e) in [(6, &e[6 * m..7 * m]), (7, &e[7 * m..8 * m])] {
                for (b, e) in x[k][start..start + m].iter_mut().zip(e) {
                    *b += rw * e;
                }
            }
        }
    }
}

struct Bearing {
    elevation: f64,
    azimuth: f64,
    k: f64,
}

fn angles(x: f64, y: f64, z: f64) -> (f64, f64) {
    (z.atan2((x * x + y * y).sqrt()), y.atan2(x))
}

impl ParticleLikelihood for Bearing {
    /// Each residual as one atan2 of the cross and dot products of the measured and the
    /// particle's directions (as hoff2024's likelihood does), in lanes.
    fn add_log_likelihood(&self, x: &[&[f32]], origin: &[f64], log_w: &mut [f32]) {
        let (sa, ca) = self.azimuth.sin_cos();
        let (se, ce) = self.elevation.sin_cos();
        let (sa, ca, se, ce, k) = (sa as f32, ca as f32, se as f32, ce as f32, self.k as f32);
        let o = [origin[0], origin[2], origin[4]].map(|v| v as f32);
        let n = log_w.len();
        let (mut cross_a, mut dot_a, mut cross_e, mut dot_e) = ([0.0; BLOCK], [0.0; BLOCK], [0.0; BLOCK], [0.0; BLOCK]);
        let (mut da, mut de) = ([0.0; BLOCK], [0.0; BLOCK]);
        for start in (0..n).step_by(BLOCK) {
            let m = BLOCK.min(n - start);
            let (px, py, pz) = (&x[0][start..start + m], &x[2][start..start + m], &x[4][start..start + m]);
            for j in 0..m {
                let (px, py, pz) = (o[0] + px[j], o[1] + py[j], o[2] + pz[j]);
                let h = (px * px + py * py).sqrt();
                cross_a[j] = sa * px - ca * py;
                dot_a[j] = ca * px + sa * py;
                cross_e[j] = se * h - ce * pz;
                dot_e[j] = ce * h + se * pz;
            }
            lanes::atan2(&cross_a[..m], &dot_a[..m], &mut da[..m]);
            lanes::atan2(&cross_e[..m], &dot_e[..m], &mut de[..m]);
            for (j, lw) in log_w[start..start + m].iter_mut().enumerate() {
                *lw -= k * (da[j] * da[j] + de[j] * de[j]);
            }
        }
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let n = args.get(1).and_then(|a| a.parse::<f64>().ok()).unwrap_or(5e5) as usize;
    let cycles = args.get(2).and_then(|a| a.parse().ok()).unwrap_or(12usize);
    let sig = 1f64.to_radians();
    let truth0 = SVector::<f64, 8>::from([100.0, 1.0, 50.0, 0.5, -40.0, 0.0, 0.0, 0.0]);
    let spread = SVector::<f64, 8>::from([10.0, 0.5, 10.0, 0.5, 5.0, 0.1, 0.01, 0.01]);
    let settings = ParticleSettings {
        resampler: Resampler::Systematic,
        ess_fraction: 1.0 + 1e-9,
        roughening_k: None,
        min_effective: 0.0,
    };
    let mut pf = ParticleFilter::<8>::gaussian(n, &truth0, &spread, settings, 1);
    // the truth and its measurements, drawn from the same model
    let mut rng = Pcg64::seed_from_u64(7);
    let (l11, l21, l22) = cv_factor();
    let mut t = truth0;
    let mut times = Vec::new();
    for _ in 0..cycles + 2 {
        for axis in 0..3 {
            let (e1, e2): (f64, f64) = (rng.sample(StandardNormal), rng.sample(StandardNormal));
            t[2 * axis] += t[2 * axis + 1] * DT + l11 * e1;
            t[2 * axis + 1] += l21 * e1 + l22 * e2;
        }
        let (el, az) = angles(t[0], t[2], t[4]);
        let z = Bearing {
            elevation: el + sig * rng.sample::<f64, _>(StandardNormal),
            azimuth: az + sig * rng.sample::<f64, _>(StandardNormal),
            k: 0.5 / (sig * sig),
        };
        let start = std::time::Instant::now();
        // resampled (every cycle: ess_fraction above 1) in the prediction's pass
        pf.predict_resampled(&Motion, DT);
        pf.reweight(&z);
        times.push(start.elapsed().as_secs_f64() * 1e3);
    }
    let (mean, _) = pf.mean_covariance();
    let err = ((mean[0] - t[0]).powi(2) + (mean[2] - t[2]).powi(2) + (mean[4] - t[4]).powi(2)).sqrt();
    let mut measured = times[2..].to_vec();
    measured.sort_by(f64::total_cmp);
    println!(
        "RESULT pf onebeacon N={n} median_ms={:.1} min_ms={:.1} cycles={} final_pos_err_m={err:.2}",
        measured[measured.len() / 2],
        measured[0],
        measured.len()
    );
}
