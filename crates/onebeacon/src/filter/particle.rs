//! A particle filter (hoff2024 sec. 2.2), generic over its process and likelihood
//! models: particles stored one array per state component (structure of arrays),
//! log-domain weights (eq. 5 as a sum of log-likelihoods), the weighted mean and
//! covariance as the estimate, resampling (multinomial as in eq. 9, systematic,
//! stratified, residual) when the effective sample size falls below a threshold, and
//! optional roughening.
//!
//! Particles are stored in single precision as offsets from a reference point kept in
//! double precision (the origin), which follows the cloud: when a step leaves particle 0
//! more than [`RECENTRE_AT`] from it in some component, the origin moves onto particle 0
//! (rounded to [`ORIGIN_GRID`], so that every move of the origin is exact) within the
//! step's own pass. A cloud far from the frame's origin (a UTM northing of 5e6 m, where
//! single precision is 0.5 m apart) is then held as finely as one at the origin: the
//! offsets are the same numbers wherever the cloud is. Log-weights are single precision
//! too, and the normalised weights, their sums, the estimate and its covariance double.
//! Single precision halves the bytes every pass moves and doubles the particles a vector
//! instruction holds (16 with AVX-512, 8 with AVX2: [`crate::filter::lanes`]).
//!
//! Work is split into chunks of [`CHUNK`] particles run in parallel (rayon, with the
//! default feature `parallel`; in order without it); each chunk draws from its own random
//! stream, derived from (seed, step, chunk), and sums are reduced in chunk order, so a
//! result depends neither on the thread count nor on the feature.

pub use super::resample::{CHUNK, Resampler};
use super::resample::{chunk_ancestors, cumulative_in_place, drawn_ancestors};
use crate::par::*;
use nalgebra::SVector;
use rand::RngExt;
use rand_pcg::Pcg64;

mod estimate;

/// The motion of the particles over a step.
pub trait ParticleProcess: Sync {
    /// Moves the particles of one chunk over `dt` seconds: component `k` of particle `i`
    /// is `origin[k] + x[k][i]`; `rng` is the chunk's own stream.
    fn propagate(&self, x: &mut [&mut [f32]], origin: &[f64], dt: f64, rng: &mut Pcg64);
}

/// What a measurement says of each particle.
pub trait ParticleLikelihood: Sync {
    /// Adds ln l(y | x_i), up to a constant common to all particles, to `log_w[i]` for
    /// the particles of one chunk (`origin[k] + x[k][i]` as in [`ParticleProcess`]).
    fn add_log_likelihood(&self, x: &[&[f32]], origin: &[f64], log_w: &mut [f32]);
}

/// Two measurements of the same time weigh the particles together.
impl<A: ParticleLikelihood, B: ParticleLikelihood> ParticleLikelihood for (A, B) {
    fn add_log_likelihood(&self, x: &[&[f32]], origin: &[f64], log_w: &mut [f32]) {
        self.0.add_log_likelihood(x, origin, log_w);
        self.1.add_log_likelihood(x, origin, log_w);
    }
}

/// How far particle 0 may stray from the origin in a component (in the component's
/// unit) before the origin moves onto it: offsets stay within this plus the cloud's
/// spread, where single precision is finer than 2e-6 of the unit plus 6e-8 of the spread.
pub const RECENTRE_AT: f32 = 16.0;

/// The grid the origin moves on (2^-10 of a component's unit): a multiple of it adds
/// exactly to an origin below 2^42 units.
pub const ORIGIN_GRID: f64 = 1.0 / 1024.0;

/// The filter's settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ParticleSettings {
    pub resampler: Resampler,
    /// Resample when the effective sample size falls below this fraction of the
    /// particles (1: after every update).
    pub ess_fraction: f64,
    /// Roughening after resampling (Gordon, Salmond and Smith 1993): each component
    /// jittered by K E_k N^(-1/d), E_k its spread over the particles; None: off.
    pub roughening_k: Option<f64>,
    /// The fewest effective particles an update may leave: a measurement that would
    /// leave fewer is applied tempered, its log-likelihood times the largest lambda in
    /// (0, 1] that leaves this many (its noise variance inflated by 1 / lambda), so that
    /// a likelihood far sharper than the cloud (a USBL azimuth from almost overhead)
    /// cannot collapse it onto one particle; 0: off.
    pub min_effective: f64,
}

impl Default for ParticleSettings {
    fn default() -> Self {
        Self { resampler: Resampler::Systematic, ess_fraction: 0.5, roughening_k: None, min_effective: 0.0 }
    }
}

/// N particles of a D-dimensional state.
#[derive(Debug, Clone)]
pub struct ParticleFilter<const D: usize> {
    /// Component k of every particle, as its offset from `origin[k]`.
    x: Vec<Vec<f32>>,
    /// The reference point the offsets are taken from, on [`ORIGIN_GRID`].
    origin: [f64; D],
    /// Resampling's target buffers, kept to avoid an allocation per step.
    spare: Vec<Vec<f32>>,
    log_w: Vec<f32>,
    /// The log-likelihood of the last update, kept apart to temper it.
    increment: Vec<f32>,
    /// The tempering of the last update (1: none).
    tempering: f64,
    /// The normalised weights and their effective sample size, computed once per change
    /// of the log-weights.
    normalised: std::cell::OnceCell<(Vec<f64>, f64)>,
    /// The normalised weights' buffer while they are stale, kept for the next ones.
    weight_buffer: Recycled,
    pub settings: ParticleSettings,
    seed: u64,
    /// Steps so far (predictions, updates and resamplings each take one): the random
    /// streams' second coordinate.
    step: u64,
}

/// A buffer kept for reuse (a clone starts without one).
#[derive(Default)]
struct Recycled(std::cell::Cell<Vec<f64>>);

impl Clone for Recycled {
    fn clone(&self) -> Self {
        Self::default()
    }
}

impl std::fmt::Debug for Recycled {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Recycled")
    }
}

/// The random stream of (seed, step, chunk): a PCG with the chunk as its stream
/// selector and the seed and step mixed into its state (SplitMix64 finaliser).
fn stream(seed: u64, step: u64, chunk: u64) -> Pcg64 {
    let mut z = seed ^ step.wrapping_mul(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    Pcg64::new(u128::from(z) << 64 | u128::from(step), u128::from(chunk))
}

/// `v` on [`ORIGIN_GRID`] (exact in single precision: a power of two's multiple).
fn on_grid(v: f64) -> f64 {
    (v / ORIGIN_GRID).round() * ORIGIN_GRID
}

/// The origin's move before a step whose particle 0 is at `first` (its offsets): onto
/// it in each component it left by more than [`RECENTRE_AT`] (0 in the others).
fn recentring<const D: usize>(first: impl Fn(usize) -> Option<f32>) -> [f32; D] {
    std::array::from_fn(|k| match first(k) {
        Some(v) if v.abs() > RECENTRE_AT => on_grid(f64::from(v)) as f32,
        _ => 0.0,
    })
}

/// Takes `shift[k]` from component k of every particle of a chunk (none when all are 0).
fn shift_chunk(x: &mut [&mut [f32]], shift: &[f32]) {
    for (comp, s) in x.iter_mut().zip(shift) {
        if *s != 0.0 {
            comp.iter_mut().for_each(|v| *v -= s);
        }
    }
}

impl<const D: usize> ParticleFilter<D> {
    /// `n` particles drawn from N(mean, diag(sigma^2)), equal weights; the origin at
    /// `mean` (on [`ORIGIN_GRID`]).
    pub fn gaussian(
        n: usize,
        mean: &SVector<f64, D>,
        sigma: &SVector<f64, D>,
        settings: ParticleSettings,
        seed: u64,
    ) -> Self {
        let origin: [f64; D] = std::array::from_fn(|k| on_grid(mean[k]));
        let mut f = Self {
            x: vec![vec![0.0; n]; D],
            origin,
            spare: vec![vec![0.0; n]; D],
            log_w: vec![0.0; n],
            increment: Vec::new(),
            tempering: 1.0,
            normalised: std::cell::OnceCell::new(),
            weight_buffer: Recycled::default(),
            settings,
            seed,
            step: 0,
        };
        let (offset, sigma) = (mean - SVector::from(origin), *sigma);
        f.for_chunks(|x, _, rng| {
            for (k, comp) in x.iter_mut().enumerate() {
                for v in comp.iter_mut() {
                    *v = (offset[k] + sigma[k] * rng.sample::<f64, _>(rand_distr::StandardNormal)) as f32;
                }
            }
        });
        f
    }

    pub fn len(&self) -> usize {
        self.log_w.len()
    }

    pub fn is_empty(&self) -> bool {
        self.log_w.is_empty()
    }

    /// Component `k` of every particle.
    pub fn component(&self, k: usize) -> Vec<f64> {
        self.x[k].iter().map(|v| self.origin[k] + f64::from(*v)).collect()
    }

    /// The origin the particles are stored from.
    pub fn origin(&self) -> SVector<f64, D> {
        SVector::from(self.origin)
    }

    /// The log-weights (not normalised).
    pub fn log_weights(&self) -> &[f32] {
        &self.log_w
    }

    /// Runs `f` on every chunk in parallel with the origin and the chunk's random
    /// stream, and counts a step.
    fn for_chunks(&mut self, f: impl Fn(&mut [&mut [f32]], &[f64], &mut Pcg64) + Sync) {
        let (seed, step) = (self.seed, self.step);
        self.step += 1;
        let origin = self.origin;
        let mut views = chunk_views(&mut self.x);
        views.par_iter_mut().enumerate().for_each(|(c, view)| {
            let mut rng = stream(seed, step, c as u64);
            f(view, &origin, &mut rng);
        });
    }

    /// Moves the origin by `shift` (exactly: both on [`ORIGIN_GRID`]), before the
    /// offsets are taken it.
    fn move_origin(&mut self, shift: [f32; D]) {
        for (o, s) in self.origin.iter_mut().zip(shift) {
            *o += f64::from(s);
        }
    }

    /// Propagates every particle through `model` over `dt` seconds, the origin first
    /// moved onto particle 0 if the cloud has left it (in the same pass).
    pub fn predict(&mut self, model: &impl ParticleProcess, dt: f64) {
        let shift = recentring::<D>(|k| self.x[k].first().copied());
        self.move_origin(shift);
        self.for_chunks(|x, origin, rng| {
            shift_chunk(x, &shift);
            model.propagate(x, origin, dt, rng);
        });
    }

    /// Weighs every particle by `likelihood` (eq. 5, in logs), then resamples when the
    /// effective sample size falls below the threshold; whether it did.
    pub fn update(&mut self, likelihood: &impl ParticleLikelihood) -> bool {
        self.reweight(likelihood);
        self.resample_if_degenerate()
    }

    /// Weighs every particle by `likelihood` (eq. 5, in logs), without resampling: for
    /// several measurements of one time, resampled once after the last. Whether the
    /// weights are usable: when no particle is left with a finite weight (a measurement
    /// no particle explains, or a NaN), every weight is reset to equal and false is
    /// returned, so that one absurd measurement does not end the filter.
    pub fn reweight(&mut self, likelihood: &impl ParticleLikelihood) -> bool {
        self.invalidate_weights();
        let max = add_log_likelihood(&self.x, &self.origin, &mut self.log_w, likelihood);
        self.step += 1;
        self.tempering = 1.0;
        if !max.is_finite() {
            self.log_w.par_iter_mut().for_each(|l| *l = 0.0);
            return false;
        }
        if max.abs() > LOG_WEIGHT_RANGE {
            // the heaviest back to 0, where single precision is finest (rare: only a
            // long run of updates without resampling drifts this far)
            self.log_w.par_iter_mut().for_each(|l| *l -= max);
        }
        let floor = self.settings.min_effective.min(self.len() as f64);
        if floor > 0.0 && self.ess() < floor {
            // too sharp: take the update back (its increments once more, a rare second
            // pass) and apply it times the largest lambda that leaves `floor` effective
            // particles: bisection on log2 lambda in [-30, 0] to 1 % (the ESS falls as
            // lambda grows)
            let mut inc = std::mem::take(&mut self.increment);
            inc.clear();
            inc.resize(self.len(), 0.0);
            add_log_likelihood(&self.x, &self.origin, &mut inc, likelihood);
            self.log_w.par_iter_mut().zip(inc.par_iter()).for_each(|(w, l)| *w -= l);
            let (mut lo, mut hi) = (-30.0f64, 0.0f64);
            while hi - lo > 0.015 {
                let mid = 0.5 * (lo + hi);
                if ess_tempered(&self.log_w, &inc, mid.exp2()) >= floor { lo = mid } else { hi = mid }
            }
            let lambda = lo.exp2();
            self.log_w.par_iter_mut().zip(inc.par_iter()).for_each(|(w, l)| *w += (lambda * f64::from(*l)) as f32);
            self.increment = inc;
            self.tempering = lambda;
            self.invalidate_weights();
        }
        true
    }

    /// The factor the last update's log-likelihood was tempered by (1: applied whole;
    /// below 1 when it would have left fewer effective particles than
    /// [`ParticleSettings::min_effective`]).
    pub fn tempering(&self) -> f64 {
        self.tempering
    }

    /// Resamples when the effective sample size is below the threshold; whether it did.
    pub fn resample_if_degenerate(&mut self) -> bool {
        if self.degenerate() {
            self.resample();
            return true;
        }
        false
    }

    /// Whether the effective sample size is below the resampling threshold.
    fn degenerate(&self) -> bool {
        self.ess() < self.settings.ess_fraction * self.len() as f64
    }

    /// The normalised weights.
    pub fn weights(&self) -> Vec<f64> {
        self.normalised().to_vec()
    }

    /// The normalised weights, computed once per change of the log-weights (into the
    /// buffer of the last ones).
    fn normalised(&self) -> &[f64] {
        &self.weighed().0
    }

    /// The normalised weights and their effective sample size 1 / sum w_i^2, computed
    /// once per change of the log-weights (into the buffer of the last ones); the sums
    /// taken in chunk order.
    fn weighed(&self) -> &(Vec<f64>, f64) {
        self.normalised.get_or_init(|| {
            let max = max_log_weight(&self.log_w);
            let mut w = self.weight_buffer.0.take();
            w.resize(self.len(), 0.0);
            let partial: Vec<f64> = w
                .par_chunks_mut(CHUNK)
                .zip(self.log_w.par_chunks(CHUNK))
                .map(|(w, l)| crate::filter::lanes::exp_shifted(l, max, w))
                .collect();
            let scale = 1.0 / partial.iter().sum::<f64>();
            let squares: Vec<f64> = w
                .par_chunks_mut(CHUNK)
                .map(|c| {
                    c.iter_mut().fold(0.0, |s, v| {
                        *v *= scale;
                        s + *v * *v
                    })
                })
                .collect();
            (w, 1.0 / squares.iter().sum::<f64>())
        })
    }

    /// Marks the normalised weights stale, keeping their buffer.
    fn invalidate_weights(&mut self) {
        if let Some((w, _)) = self.normalised.take() {
            self.weight_buffer.0.set(w);
        }
    }

    /// The effective sample size, 1 / sum w_i^2.
    pub fn ess(&self) -> f64 {
        self.weighed().1
    }

    /// Draws the particles again in proportion to their weights, resets the weights,
    /// and roughens when asked. Systematic and stratified resampling run chunk by chunk
    /// in parallel: each output chunk finds its first ancestor by bisection on the
    /// cumulative weights and walks from there, and copies its particles' components.
    pub fn resample(&mut self) {
        self.resample_then(|_, _, _| {});
        self.roughen();
    }

    /// Resamples when the effective sample size is below the threshold, then propagates
    /// every particle through `model` over `dt` seconds: the same as
    /// [`ParticleFilter::resample_if_degenerate`] then [`ParticleFilter::predict`], to
    /// the bit, in one pass over the particles (each chunk copied and moved while in
    /// cache) unless roughening is on. For a filter that resamples just before it
    /// predicts, its estimate taken from the weighted particles (the lower-variance
    /// one); whether it resampled.
    pub fn predict_resampled(&mut self, model: &impl ParticleProcess, dt: f64) -> bool {
        if !self.degenerate() {
            self.predict(model, dt);
            return false;
        }
        if self.settings.roughening_k.is_some() {
            self.resample();
            self.predict(model, dt);
            return true;
        }
        let step = self.step + 1; // the prediction's step, after the resampling's
        let seed = self.seed;
        self.resample_then(|x, origin, c| model.propagate(x, origin, dt, &mut stream(seed, step, c as u64)));
        self.step += 1;
        true
    }

    /// Draws the particles again, the origin moved onto the new particle 0 if the cloud
    /// has left it (taken from them as they are copied), then applies `then` to each
    /// chunk of the new particles (with the origin and the chunk's index) while it is in
    /// cache.
    fn resample_then(&mut self, then: impl Fn(&mut [&mut [f32]], &[f64], usize) + Sync) {
        let (seed, step) = (self.seed, self.step);
        self.step += 1;
        self.normalised();
        let (mut w, _) = self.normalised.take().expect("computed above");
        let mut rng = stream(seed, step, u64::MAX);
        let resampler = self.settings.resampler;
        let drawn = drawn_ancestors(resampler, &w, &mut rng, |c| stream(seed, step, c as u64));
        let cumulative = cumulative_in_place(&mut w);
        let u0: f64 = rng.random();
        let ancestors = |c: usize, len: usize| {
            let first = c * CHUNK;
            chunk_ancestors(
                resampler,
                cumulative,
                &drawn,
                (c, first..first + len),
                u0,
                &mut stream(seed, step, c as u64),
            )
        };
        // the new particle 0: the first chunk's first ancestor
        let first = (!self.log_w.is_empty()).then(|| ancestors(0, CHUNK.min(self.log_w.len()))[0]);
        let shift = recentring::<D>(|k| first.map(|i| self.x[k][i]));
        self.move_origin(shift);
        let (from, origin) = (&self.x, self.origin);
        let mut views = chunk_views(&mut self.spare);
        views.par_iter_mut().zip(self.log_w.par_chunks_mut(CHUNK)).enumerate().for_each(|(c, (to, log_w))| {
            let picked = ancestors(c, log_w.len());
            for (k, to) in to.iter_mut().enumerate() {
                super::resample::gather(&from[k], &picked, shift[k], to);
            }
            log_w.fill(0.0);
            then(to, &origin, c);
        });
        std::mem::swap(&mut self.x, &mut self.spare);
        self.weight_buffer.0.set(w);
    }

    /// Roughening (when asked) after a resampling.
    fn roughen(&mut self) {
        if let Some(k) = self.settings.roughening_k {
            let n = self.len() as f64;
            let sigma: Vec<f64> = self
                .x
                .iter()
                .map(|c| {
                    let (lo, hi) = c.iter().fold((f32::MAX, f32::MIN), |(l, h), v| (l.min(*v), h.max(*v)));
                    k * f64::from(hi - lo).max(0.0) * n.powf(-1.0 / D as f64)
                })
                .collect();
            self.for_chunks(|x, _, rng| {
                for (comp, s) in x.iter_mut().zip(&sigma) {
                    for v in comp.iter_mut() {
                        *v += (s * rng.sample::<f64, _>(rand_distr::StandardNormal)) as f32;
                    }
                }
            });
        }
    }
}

/// Log-weights' largest magnitude before the heaviest is brought back to 0 (single
/// precision is then 6e-5 apart: a relative error of weight below 1e-4).
const LOG_WEIGHT_RANGE: f32 = 1000.0;

/// The chunks of every component: `views[c][k]` is component `k` of chunk `c`.
fn chunk_views(x: &mut [Vec<f32>]) -> Vec<Vec<&mut [f32]>> {
    let n = x.first().map_or(0, Vec::len);
    let mut views: Vec<Vec<&mut [f32]>> = (0..n.div_ceil(CHUNK)).map(|_| Vec::with_capacity(x.len())).collect();
    for comp in x.iter_mut() {
        for (c, part) in comp.chunks_mut(CHUNK).enumerate() {
            views[c].push(part);
        }
    }
    views
}

/// Adds `likelihood`'s log-likelihood of every particle of `x` (offsets from `origin`)
/// to `log_w`, chunk by chunk in parallel; the largest of the results, NaN if any is NaN.
fn add_log_likelihood(x: &[Vec<f32>], origin: &[f64], log_w: &mut [f32], likelihood: &impl ParticleLikelihood) -> f32 {
    let maxima: Vec<f32> = log_w
        .par_chunks_mut(CHUNK)
        .enumerate()
        .map(|(c, lw)| {
            let start = c * CHUNK;
            let view: Vec<&[f32]> = x.iter().map(|comp| &comp[start..start + lw.len()]).collect();
            likelihood.add_log_likelihood(&view, origin, lw);
            crate::filter::lanes::max_of(lw)
        })
        .collect();
    crate::filter::lanes::max_of(&maxima)
}

/// The effective sample size of log-weights `log_w + lambda inc`, summed by chunks in
/// order.
fn ess_tempered(log_w: &[f32], inc: &[f32], lambda: f64) -> f64 {
    let at = |i: usize| f64::from(log_w[i]) + lambda * f64::from(inc[i]);
    let max = crate::par::max_over(log_w.len(), CHUNK, at);
    let partial: Vec<(f64, f64)> = (0..log_w.len().div_ceil(CHUNK))
        .into_par_iter()
        .map(|c| {
            (c * CHUNK..((c + 1) * CHUNK).min(log_w.len())).fold((0.0, 0.0), |(s, s2), i| {
                let e = (at(i) - max).exp();
                (s + e, s2 + e * e)
            })
        })
        .collect();
    let (s, s2) = partial.iter().fold((0.0, 0.0), |(a, b), p| (a + p.0, b + p.1));
    s * s / s2
}

/// The largest log-weight (exact in any order; NaN if one is).
fn max_log_weight(log_w: &[f32]) -> f32 {
    let maxima: Vec<f32> = log_w.par_chunks(CHUNK).map(crate::filter::lanes::max_of).collect();
    crate::filter::lanes::max_of(&maxima)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_abs_diff_eq;
    use nalgebra::SMatrix;
    use nalgebra::{Matrix2, Vector2};
    use std::f64::consts::PI;

    /// predict_resampled equals resample_if_degenerate then predict, to the bit, on
    /// hoff2024's model over 3 chunks and a part, resampling or not.
    #[test]
    fn fused_resampling_and_prediction_equal_the_two_steps() {
        use crate::measure::hoff::InsReport;
        use crate::models::hoff::{DIM, HoffProcess};
        let mean = SVector::<f64, DIM>::from([100.0, 50.0, 30.0, 0.0, 0.3, 1.5, 0.0, 0.002]);
        let sigma = SVector::<f64, DIM>::from([10.0, 10.0, 2.0, 0.05, 0.2, 0.3, 0.001, 0.003]);
        let report = InsReport::example();
        for ess_fraction in [0.5, 1e-9] {
            let settings = ParticleSettings { ess_fraction, ..ParticleSettings::default() };
            let mut a = ParticleFilter::<DIM>::gaussian(3 * CHUNK + 77, &mean, &sigma, settings, 9);
            a.reweight(&report);
            let mut b = a.clone();
            let resampled = a.predict_resampled(&HoffProcess::default(), 4.0);
            assert_eq!(resampled, b.resample_if_degenerate());
            assert_eq!(resampled, ess_fraction > 0.1);
            b.predict(&HoffProcess::default(), 4.0);
            for k in 0..DIM {
                assert!(a.component(k).iter().zip(b.component(k)).all(|(u, v)| u.to_bits() == v.to_bits()), "{k}");
            }
            assert_eq!(a.log_weights(), b.log_weights());
            assert_eq!(a.step, b.step);
        }
    }

    /// Uneven weights for the resampling and subsampling tests: log w = 3 sin x_0 - x_0^2 / 2.
    struct Tilt;
    impl ParticleLikelihood for Tilt {
        fn add_log_likelihood(&self, x: &[&[f32]], origin: &[f64], log_w: &mut [f32]) {
            for (lw, v) in log_w.iter_mut().zip(x[0]) {
                let v = origin[0] + f64::from(*v);
                *lw += (3.0 * v.sin() - 0.5 * v * v) as f32;
            }
        }
    }

    /// The subsample by chunks of particles in parallel against one walk along the
    /// running sum of the weights (a brute force written out here): the same particle
    /// for every point, with m below, near and above the number of particles, over 3
    /// chunks and a part weighed unevenly.
    #[test]
    fn a_subsample_picks_the_particles_of_a_single_walk() {
        let n = 3 * CHUNK + 77;
        let mut pf =
            ParticleFilter::<2>::gaussian(n, &SVector::zeros(), &SVector::from([2.0, 1.0]), Default::default(), 6);
        pf.reweight(&Tilt);
        let w = pf.weights();
        for m in [1, 7, 1000, n - 1, n, 3 * n + 5] {
            let got = pf.subsample(m, [1, 0]);
            assert_eq!(got.len(), m);
            let (mut i, mut cum) = (0, w[0]);
            for (j, g) in got.iter().enumerate() {
                let u = (j as f64 + 0.5) / m as f64;
                while u >= cum && i + 1 < n {
                    i += 1;
                    cum += w[i];
                }
                assert_eq!(*g, [pf.component(1)[i], pf.component(0)[i]], "m {m}, point {j}");
            }
        }
    }

    /// Multinomial resampling by chunks (exponential spacings drawn chunk by chunk): over
    /// 3 chunks and a part of unevenly weighed particles, the copies of the particles of
    /// each quarter of the cloud (a binomial count, N W_A on average, variance
    /// N W_A (1 - W_A)) average within 4 standard errors over 200 resamplings, and the
    /// draws differ from one resampling to the next.
    #[test]
    fn multinomial_by_chunks_draws_in_proportion_to_weight() {
        let n = 3 * CHUNK + 77;
        let settings = ParticleSettings { resampler: Resampler::Multinomial, ..ParticleSettings::default() };
        let mut pf = ParticleFilter::<1>::gaussian(n, &SVector::zeros(), &SVector::from([1.0]), settings, 8);
        pf.reweight(&Tilt);
        let w = pf.weights();
        let index: std::collections::HashMap<u64, usize> =
            pf.component(0).iter().enumerate().map(|(i, v)| (v.to_bits(), i)).collect();
        let quarters: Vec<std::ops::Range<usize>> = (0..4).map(|q| q * n / 4..(q + 1) * n / 4).collect();
        let (reps, mut counts, mut last) = (200, [0.0; 4], Vec::new());
        for _ in 0..reps {
            let mut p = pf.clone();
            pf.step += 1; // a fresh draw each time
            p.resample();
            let after: Vec<u64> = p.component(0).iter().map(|v| v.to_bits()).collect();
            assert_ne!(after, last);
            for v in &after {
                let i = index[v];
                counts[quarters.iter().position(|q| q.contains(&i)).unwrap()] += 1.0;
            }
            last = after;
        }
        for (q, range) in quarters.iter().enumerate() {
            let wa: f64 = w[range.clone()].iter().sum();
            let (mean, expected) = (counts[q] / reps as f64, n as f64 * wa);
            let se = (n as f64 * wa * (1.0 - wa) / reps as f64).sqrt();
            assert!((mean - expected).abs() < 4.0 * se, "quarter {q}: {mean} against {expected} (se {se})");
        }
    }

    /// Systematic and stratified resampling by chunks in parallel, over several chunks:
    /// every particle of 3 chunks and a part (spread evenly over [-3, 3], each value its own)
    /// weighed by exp(-x^2) is copied floor(N w_i) or ceil(N w_i) times (systematic), or
    /// within 2 of N w_i (stratified: one draw per stratum); N particles in all.
    #[test]
    fn parallel_resampling_keeps_counts_across_chunks() {
        struct Bell;
        impl ParticleLikelihood for Bell {
            fn add_log_likelihood(&self, x: &[&[f32]], origin: &[f64], log_w: &mut [f32]) {
                for (lw, v) in log_w.iter_mut().zip(x[0]) {
                    let v = origin[0] + f64::from(*v);
                    *lw -= (v * v) as f32;
                }
            }
        }
        let n = 3 * CHUNK + 77;
        for r in [Resampler::Systematic, Resampler::Stratified] {
            let settings = ParticleSettings { resampler: r, ..ParticleSettings::default() };
            let mut pf = ParticleFilter::<1>::gaussian(n, &SVector::zeros(), &SVector::from([1.0]), settings, 4);
            pf.x[0] = (0..n).map(|i| -3.0 + 6.0 * i as f32 / n as f32).collect();
            pf.reweight(&Bell);
            let before: Vec<(u64, f64)> = pf.component(0).iter().map(|v| v.to_bits()).zip(pf.weights()).collect();
            pf.resample();
            let mut counts = std::collections::HashMap::new();
            pf.component(0).iter().for_each(|v| *counts.entry(v.to_bits()).or_insert(0usize) += 1);
            assert_eq!(counts.values().sum::<usize>(), n);
            for (bits, w) in before {
                let (c, expected) = (*counts.get(&bits).unwrap_or(&0) as f64, n as f64 * w);
                let ok = match r {
                    Resampler::Systematic => c >= expected.floor() - 1e-9 && c <= expected.ceil() + 1e-9,
                    _ => (c - expected).abs() < 2.0,
                };
                assert!(ok, "{r:?}: {c} copies of a particle of N w = {expected}");
            }
        }
    }

    /// Each resampler copies particle i N w_i times on average (2000 resamplings of 7
    /// particles, within 4 standard errors); systematic and residual copy it at least
    /// floor(N w_i) times every time, systematic at most ceil(N w_i).
    #[test]
    fn resamplers_copy_in_proportion_to_weight() {
        let w = [0.05, 0.3, 0.01, 0.24, 0.1, 0.2, 0.1];
        let n = w.len();
        for r in [Resampler::Multinomial, Resampler::Systematic, Resampler::Stratified, Resampler::Residual] {
            let mut rng = stream(1, 2, 3);
            let reps = 2000;
            let mut counts = [0.0; 7];
            for _ in 0..reps {
                let key = rng.random::<u64>();
                let drawn = drawn_ancestors(r, &w, &mut rng, |c| stream(key, 0, c as u64));
                let mut cum = w.to_vec();
                let u0 = rng.random();
                let a = chunk_ancestors(r, cumulative_in_place(&mut cum), &drawn, (0, 0..n), u0, &mut rng);
                assert_eq!(a.len(), n);
                let mut c = [0usize; 7];
                a.iter().for_each(|&i| c[i] += 1);
                for i in 0..n {
                    let expected = n as f64 * w[i];
                    if matches!(r, Resampler::Systematic | Resampler::Residual) {
                        assert!(c[i] as f64 >= expected.floor() - 1e-9, "{r:?}: {c:?}");
                    }
                    if r == Resampler::Systematic {
                        assert!(c[i] as f64 <= expected.ceil() + 1e-9, "{r:?}: {c:?}");
                    }
                    counts[i] += c[i] as f64;
                }
            }
            for i in 0..n {
                let (mean, expected) = (counts[i] / reps as f64, n as f64 * w[i]);
                // a multinomial count's variance n w (1 - w) bounds the others'
                let se = (n as f64 * w[i] * (1.0 - w[i]) / reps as f64).sqrt();
                assert!((mean - expected).abs() < 4.0 * se + 1e-9, "{r:?} particle {i}: {mean} against {expected}");
            }
        }
    }

    /// A random walk in position and velocity (x' = x + v dt, both with Gaussian process
    /// noise) measured directly in position: the particle filter's mean and covariance
    /// after 30 steps match the Kalman filter's closed form within Monte Carlo tolerance.
    #[test]
    fn matches_the_kalman_filter_on_a_linear_gaussian_problem() {
        struct Walk;
        impl ParticleProcess for Walk {
            fn propagate(&self, x: &mut [&mut [f32]], origin: &[f64], dt: f64, rng: &mut Pcg64) {
                let (p, v) = x.split_at_mut(1);
                for (p, v) in p[0].iter_mut().zip(v[0].iter_mut()) {
                    let step = (origin[1] + f64::from(*v)) * dt;
                    *p += (step + 0.3 * rng.sample::<f64, _>(rand_distr::StandardNormal)) as f32;
                    *v += (0.1 * rng.sample::<f64, _>(rand_distr::StandardNormal)) as f32;
                }
            }
        }
        struct Fix(f64);
        impl ParticleLikelihood for Fix {
            fn add_log_likelihood(&self, x: &[&[f32]], origin: &[f64], log_w: &mut [f32]) {
                for (p, lw) in x[0].iter().zip(log_w.iter_mut()) {
                    let d = origin[0] + f64::from(*p) - self.0;
                    *lw -= (d * d / (2.0 * 0.5 * 0.5)) as f32;
                }
            }
        }
        let settings = ParticleSettings {
            resampler: Resampler::Systematic,
            ess_fraction: 0.5,
            roughening_k: None,
            min_effective: 0.0,
        };
        let n = 200_000;
        let mut pf = ParticleFilter::<2>::gaussian(n, &Vector2::new(0.0, 1.0), &Vector2::new(1.0, 0.5), settings, 7);
        // the Kalman filter
        let (f, q, h, r) =
            (Matrix2::new(1.0, 1.0, 0.0, 1.0), Matrix2::new(0.09, 0.0, 0.0, 0.01), Vector2::new(1.0, 0.0), 0.25);
        let (mut m, mut p) = (Vector2::new(0.0, 1.0), Matrix2::new(1.0, 0.0, 0.0, 0.25));
        for k in 1..=30 {
            let z = 1.1 * k as f64 + 0.4 * (k as f64).sin(); // any measurements will do
            pf.predict(&Walk, 1.0);
            pf.update(&Fix(z));
            m = f * m;
            p = f * p * f.transpose() + q;
            let s = (h.transpose() * p * h)[0] + r;
            let gain = p * h / s;
            m += gain * (z - m.x);
            p -= gain * h.transpose() * p;
        }
        let (pm, pc) = pf.mean_covariance();
        let ess = pf.ess();
        for k in 0..2 {
            let se = (p[(k, k)] / ess).sqrt();
            assert!((pm[k] - m[k]).abs() < 5.0 * se, "component {k}: {} against {}", pm[k], m[k]);
            assert_abs_diff_eq!(pc[(k, k)] / p[(k, k)], 1.0, epsilon = 0.05);
        }
    }

    /// The same seed gives the same particles whatever the thread count.
    #[cfg(feature = "parallel")]
    #[test]
    fn results_do_not_depend_on_the_thread_count() {
        struct Jitter;
        impl ParticleProcess for Jitter {
            fn propagate(&self, x: &mut [&mut [f32]], _origin: &[f64], _dt: f64, rng: &mut Pcg64) {
                for c in x.iter_mut() {
                    for v in c.iter_mut() {
                        *v += rng.sample::<f32, _>(rand_distr::StandardNormal);
                    }
                }
            }
        }
        struct Near;
        impl ParticleLikelihood for Near {
            fn add_log_likelihood(&self, x: &[&[f32]], origin: &[f64], log_w: &mut [f32]) {
                for (i, lw) in log_w.iter_mut().enumerate() {
                    let (a, b) = (origin[0] + f64::from(x[0][i]), origin[1] + f64::from(x[1][i]));
                    *lw -= (a * a + b * b) as f32;
                }
            }
        }
        let run = |threads: usize, resampler: Resampler| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| {
                let settings =
                    ParticleSettings { resampler, ess_fraction: 1.0, roughening_k: Some(0.2), min_effective: 0.0 };
                let mut pf =
                    ParticleFilter::<2>::gaussian(50_000, &Vector2::zeros(), &Vector2::repeat(3.0), settings, 5);
                for _ in 0..3 {
                    pf.predict(&Jitter, 1.0);
                    pf.update(&Near);
                }
                (pf.component(0).to_vec(), pf.mean_covariance())
            })
        };
        for r in [Resampler::Residual, Resampler::Multinomial, Resampler::Systematic, Resampler::Stratified] {
            assert_eq!(run(1, r), run(3, r), "{r:?}");
        }
    }

    /// The mean and covariance against the weighted sums in double precision over the
    /// same offsets less the heaviest particle's (8 components, an angle among them, two
    /// chunks and a part): within the single-precision share, each product w y_k y_l
    /// rounded three times, then 32 additions in its lane and 4 across the lanes (39
    /// roundings of 2^-24 of the sum of |w y_k y_l|), the covariance's bound carried
    /// through E[y y'] - m m'.
    #[test]
    fn mean_and_covariance_match_double_precision_sums() {
        let n = 2 * CHUNK + 4099;
        let mean = SVector::<f64, 8>::from([0.5, 50.0, 30.0, 0.0, 3.0, 1.5, 0.0, 0.002]);
        let sigma = SVector::<f64, 8>::from([2.0, 10.0, 2.0, 0.05, 0.5, 0.3, 0.001, 0.003]);
        let mut pf = ParticleFilter::<8>::gaussian(n, &mean, &sigma, ParticleSettings::default(), 9);
        pf.update(&Tilt);
        let (m, c) = pf.mean_covariance_with_angle(Some(4));
        let w = pf.normalised();
        let heaviest = w.iter().enumerate().fold((0, f64::MIN), |b, (i, v)| if *v > b.1 { (i, *v) } else { b }).0;
        let centre: Vec<f32> = (0..8).map(|k| pf.x[k][heaviest]).collect();
        // the offsets less the heaviest particle's, in double precision
        let comps: Vec<Vec<f64>> = (0..8)
            .map(|k| {
                let centred =
                    |a: &f32| if k == 4 { crate::filter::lanes::wrap_near(a - centre[k]) } else { a - centre[k] };
                pf.x[k].iter().map(|a| f64::from(centred(a))).collect()
            })
            .collect();
        // a product's three roundings, 32 additions in its lane, 4 across the lanes
        let eps = 39.0 * 2f64.powi(-24);
        let (mut mean, mut second) = (SVector::<f64, 8>::zeros(), SMatrix::<f64, 8, 8>::zeros());
        let (mut mean_bound, mut second_bound) = (SVector::<f64, 8>::zeros(), SMatrix::<f64, 8, 8>::zeros());
        for i in 0..n {
            for k in 0..8 {
                mean[k] += w[i] * comps[k][i];
                mean_bound[k] += eps * (w[i] * comps[k][i]).abs();
                for l in 0..8 {
                    second[(k, l)] += w[i] * comps[k][i] * comps[l][i];
                    second_bound[(k, l)] += eps * (w[i] * comps[k][i] * comps[l][i]).abs();
                }
            }
        }
        let cov = second - mean * mean.transpose();
        for k in 0..8 {
            for l in 0..8 {
                let bound = second_bound[(k, l)]
                    + mean[k].abs() * mean_bound[l]
                    + mean[l].abs() * mean_bound[k]
                    + mean_bound[k] * mean_bound[l]
                    + 1e-15;
                assert!(
                    (c[(k, l)] - cov[(k, l)]).abs() <= bound,
                    "cov ({k}, {l}): {} against {}",
                    c[(k, l)],
                    cov[(k, l)]
                );
            }
        }
        for k in 0..8 {
            mean[k] += pf.origin()[k] + f64::from(centre[k]);
        }
        mean[4] = crate::geo::wrap_angle(mean[4]);
        for k in 0..8 {
            assert!((m[k] - mean[k]).abs() <= mean_bound[k] + 1e-12, "mean {k}: {} against {}", m[k], mean[k]);
        }
    }

    /// An angle component across +-pi: the mean where the particles are (pi, not 0) and
    /// the variance of their wrapped spread, against the values worked out by hand.
    #[test]
    fn angle_mean_across_the_wrap() {
        let mean = SVector::<f64, 2>::from([1.0, 0.0]);
        let mut pf = ParticleFilter::<2>::gaussian(4, &mean, &SVector::zeros(), ParticleSettings::default(), 1);
        // four angles 0.1 apart about pi: pi - 0.15, pi - 0.05, -pi + 0.05, -pi + 0.15
        let angles = [PI - 0.15, PI - 0.05, -PI + 0.05, -PI + 0.15].map(|a| a as f32);
        pf.x[1].copy_from_slice(&angles);
        let (m, c) = pf.mean_covariance_with_angle(Some(1));
        // single precision's rounding of the angles: 2.4e-7
        assert!((m[1].abs() - PI).abs() < 1e-6, "{}", m[1]);
        let var = [0.15f64, 0.05, 0.05, 0.15].iter().map(|d| d * d).sum::<f64>() / 4.0;
        assert!((c[(1, 1)] - var).abs() < 1e-6, "{}", c[(1, 1)]);
        // linear: the mean is near 0 and the spread near pi^2
        let (m, c) = pf.mean_covariance();
        assert!(m[1].abs() < 1e-6 && c[(1, 1)] > 9.0);
    }

    /// A likelihood far sharper than the cloud: N(0, 1) particles weighed by
    /// exp(-x^2 / (2 sigma^2)), sigma = 1e-4. Whole, it leaves a handful of effective
    /// particles (closed form: N sqrt(v (2 + v)) / (1 + v) with v = sigma^2, 1.4 of 1e5);
    /// with a floor of 1000 it is tempered by the lambda of the closed form, v = sigma^2 /
    /// lambda solving sqrt(v (2 + v)) / (1 + v) = 0.01 (lambda = 2.0e-4), and leaves 1000.
    /// A mild likelihood is applied whole.
    #[test]
    fn a_likelihood_sharper_than_the_cloud_is_tempered_to_the_floor() {
        struct Sharp(f64);
        impl ParticleLikelihood for Sharp {
            fn add_log_likelihood(&self, x: &[&[f32]], origin: &[f64], log_w: &mut [f32]) {
                for (l, v) in log_w.iter_mut().zip(x[0]) {
                    let v = origin[0] + f64::from(*v);
                    *l += (-v * v / (2.0 * self.0 * self.0)) as f32;
                }
            }
        }
        let n = 100_000;
        let mean = SVector::<f64, 1>::zeros();
        let sigma = SVector::<f64, 1>::from([1.0]);
        let settings = ParticleSettings { min_effective: 1000.0, ess_fraction: 0.0, ..ParticleSettings::default() };
        let mut pf = ParticleFilter::<1>::gaussian(n, &mean, &sigma, settings, 3);
        let mut whole = pf.clone();
        whole.settings.min_effective = 0.0;
        whole.reweight(&Sharp(1e-4));
        assert!(whole.ess() < 20.0, "{}", whole.ess());
        assert_eq!(whole.tempering(), 1.0);
        pf.reweight(&Sharp(1e-4));
        let ess_fraction = |v: f64| (v * (2.0 + v)).sqrt() / (1.0 + v);
        // v solving ess_fraction(v) = 0.01, by bisection
        let (mut lo, mut hi) = (0.0, 1.0);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if ess_fraction(mid) < 0.01 { lo = mid } else { hi = mid }
        }
        let lambda = 1e-8 / lo;
        assert!((pf.tempering() / lambda - 1.0).abs() < 0.1, "{} against {lambda}", pf.tempering());
        assert!((pf.ess() / 1000.0 - 1.0).abs() < 0.05, "{}", pf.ess());
        let mut mild = ParticleFilter::<1>::gaussian(n, &mean, &sigma, settings, 3);
        mild.reweight(&Sharp(2.0));
        assert_eq!(mild.tempering(), 1.0);
    }
}
