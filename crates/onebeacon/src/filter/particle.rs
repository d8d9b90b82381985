//! A particle filter (hoff2024 sec. 2.2), generic over its process and likelihood
//! models: particles stored one array per state component (structure of arrays),
//! log-domain weights (eq. 5 as a sum of log-likelihoods), the weighted mean and
//! covariance as the estimate, resampling (multinomial as in eq. 9, systematic,
//! stratified, residual) when the effective sample size falls below a threshold, and
//! optional roughening.
//!
//! Work is split into chunks of [`CHUNK`] particles run in parallel (rayon, with the
//! default feature `parallel`; in order without it); each chunk draws from its own random
//! stream, derived from (seed, step, chunk), and sums are reduced in chunk order, so a
//! result depends neither on the thread count nor on the feature.

pub use super::resample::{CHUNK, Resampler};
use super::resample::{chunk_ancestors, cumulative_in_place, drawn_ancestors, weight_before_chunks};
use crate::par::*;
use nalgebra::{SMatrix, SVector};
use rand::RngExt;
use rand_pcg::Pcg64;

/// The motion of the particles over a step.
pub trait ParticleProcess: Sync {
    /// Moves the particles of one chunk over `dt` seconds: `x[k][i]` is component `k` of
    /// particle `i`; `rng` is the chunk's own stream.
    fn propagate(&self, x: &mut [&mut [f64]], dt: f64, rng: &mut Pcg64);
}

/// What a measurement says of each particle.
pub trait ParticleLikelihood: Sync {
    /// Adds ln l(y | x_i), up to a constant common to all particles, to `log_w[i]` for
    /// the particles of one chunk (`x[k][i]` as in [`ParticleProcess`]).
    fn add_log_likelihood(&self, x: &[&[f64]], log_w: &mut [f64]);
}

/// Two measurements of the same time weigh the particles together.
impl<A: ParticleLikelihood, B: ParticleLikelihood> ParticleLikelihood for (A, B) {
    fn add_log_likelihood(&self, x: &[&[f64]], log_w: &mut [f64]) {
        self.0.add_log_likelihood(x, log_w);
        self.1.add_log_likelihood(x, log_w);
    }
}

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
    /// Component k of every particle.
    x: Vec<Vec<f64>>,
    /// Resampling's target buffers, kept to avoid an allocation per step.
    spare: Vec<Vec<f64>>,
    log_w: Vec<f64>,
    /// The log-likelihood of the last update, kept apart to temper it.
    increment: Vec<f64>,
    /// The tempering of the last update (1: none).
    tempering: f64,
    /// The normalised weights, computed once per change of the log-weights.
    normalised: std::cell::OnceCell<Vec<f64>>,
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

impl<const D: usize> ParticleFilter<D> {
    /// `n` particles drawn from N(mean, diag(sigma^2)), equal weights.
    pub fn gaussian(
        n: usize,
        mean: &SVector<f64, D>,
        sigma: &SVector<f64, D>,
        settings: ParticleSettings,
        seed: u64,
    ) -> Self {
        let mut f = Self {
            x: vec![vec![0.0; n]; D],
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
        let (mean, sigma) = (*mean, *sigma);
        f.for_chunks(|x, rng| {
            for (k, comp) in x.iter_mut().enumerate() {
                for v in comp.iter_mut() {
                    *v = mean[k] + sigma[k] * rng.sample::<f64, _>(rand_distr::StandardNormal);
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
    pub fn component(&self, k: usize) -> &[f64] {
        &self.x[k]
    }

    /// The log-weights (not normalised).
    pub fn log_weights(&self) -> &[f64] {
        &self.log_w
    }

    /// Runs `f` on every chunk in parallel with the chunk's random stream, and counts a
    /// step.
    fn for_chunks(&mut self, f: impl Fn(&mut [&mut [f64]], &mut Pcg64) + Sync) {
        let (seed, step) = (self.seed, self.step);
        self.step += 1;
        let mut views = chunk_views(&mut self.x);
        views.par_iter_mut().enumerate().for_each(|(c, view)| {
            let mut rng = stream(seed, step, c as u64);
            f(view, &mut rng);
        });
    }

    /// Propagates every particle through `model` over `dt` seconds.
    pub fn predict(&mut self, model: &impl ParticleProcess, dt: f64) {
        self.for_chunks(|x, rng| model.propagate(x, dt, rng));
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
        let max = add_log_likelihood(&self.x, &mut self.log_w, likelihood);
        self.step += 1;
        self.tempering = 1.0;
        if !max.is_finite() {
            self.log_w.par_iter_mut().for_each(|l| *l = 0.0);
            return false;
        }
        let floor = self.settings.min_effective.min(self.len() as f64);
        if floor > 0.0 && ess_of(self.normalised()) < floor {
            // too sharp: take the update back (its increments once more, a rare second
            // pass) and apply it times the largest lambda that leaves `floor` effective
            // particles: bisection on log2 lambda in [-30, 0] to 1 % (the ESS falls as
            // lambda grows)
            let mut inc = std::mem::take(&mut self.increment);
            inc.clear();
            inc.resize(self.len(), 0.0);
            add_log_likelihood(&self.x, &mut inc, likelihood);
            self.log_w.par_iter_mut().zip(inc.par_iter()).for_each(|(w, l)| *w -= l);
            let (mut lo, mut hi) = (-30.0f64, 0.0f64);
            while hi - lo > 0.015 {
                let mid = 0.5 * (lo + hi);
                if ess_tempered(&self.log_w, &inc, mid.exp2()) >= floor { lo = mid } else { hi = mid }
            }
            let lambda = lo.exp2();
            self.log_w.par_iter_mut().zip(inc.par_iter()).for_each(|(w, l)| *w += lambda * l);
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
        ess_of(self.normalised()) < self.settings.ess_fraction * self.len() as f64
    }

    /// `m` particles drawn systematically in proportion to their weights (offset one
    /// half: no random draw), for a planner that scores a belief on a subsample; each
    /// stands for 1 / m of the weight. Components `k` of each. By chunks of particles
    /// in parallel: each takes the points within its share of the cumulative weight
    /// (from the sums of the chunks before it) and walks them along its particles.
    pub fn subsample<const K: usize>(&self, m: usize, k: [usize; K]) -> Vec<[f64; K]> {
        let w = self.normalised();
        let offsets = weight_before_chunks(w);
        let point = |j: usize| (j as f64 + 0.5) / m as f64;
        // the first point at or past cumulative weight `c` (the last chunk takes the rest)
        let first_at = |c: f64| {
            let mut j = ((c * m as f64 - 0.5).ceil().max(0.0) as usize).min(m);
            while j > 0 && point(j - 1) >= c {
                j -= 1;
            }
            while j < m && point(j) < c {
                j += 1;
            }
            j
        };
        let (chunks, n, x) = (offsets.len(), self.len(), &self.x);
        let picked: Vec<Vec<[f64; K]>> = (0..chunks)
            .into_par_iter()
            .map(|c| {
                let (lo, hi) = (first_at(offsets[c]), if c + 1 == chunks { m } else { first_at(offsets[c + 1]) });
                let (first, w) = (c * CHUNK, &w[c * CHUNK..((c + 1) * CHUNK).min(n)]);
                let (mut i, mut cum) = (0, offsets[c] + w[0]);
                (lo..hi)
                    .map(|j| {
                        while point(j) >= cum && i + 1 < w.len() {
                            i += 1;
                            cum += w[i];
                        }
                        k.map(|comp| x[comp][first + i])
                    })
                    .collect()
            })
            .collect();
        picked.concat()
    }

    /// The normalised weights.
    pub fn weights(&self) -> Vec<f64> {
        self.normalised().to_vec()
    }

    /// The normalised weights, computed once per change of the log-weights (into the
    /// buffer of the last ones).
    fn normalised(&self) -> &[f64] {
        self.normalised.get_or_init(|| {
            // the maximum is exact in any order; the sum is taken in chunk order
            let log_w = &self.log_w;
            let max = crate::par::max_over(log_w.len(), CHUNK, |i| log_w[i]);
            let mut w = self.weight_buffer.0.take();
            w.resize(self.len(), 0.0);
            let partial: Vec<f64> = w
                .par_chunks_mut(CHUNK)
                .zip(self.log_w.par_chunks(CHUNK))
                .map(|(w, l)| crate::filter::lanes::exp_shifted(l, max, w))
                .collect();
            let scale = 1.0 / partial.iter().sum::<f64>();
            w.par_iter_mut().for_each(|v| *v *= scale);
            w
        })
    }

    /// Marks the normalised weights stale, keeping their buffer.
    fn invalidate_weights(&mut self) {
        if let Some(w) = self.normalised.take() {
            self.weight_buffer.0.set(w);
        }
    }

    /// The effective sample size, 1 / sum w_i^2.
    pub fn ess(&self) -> f64 {
        ess_of(self.normalised())
    }

    /// The weighted mean and covariance of the particles, in one pass.
    pub fn mean_covariance(&self) -> (SVector<f64, D>, SMatrix<f64, D, D>) {
        self.mean_covariance_with_angle(None)
    }

    /// [`ParticleFilter::mean_covariance`] with component `angle` (when given) an angle
    /// in (-pi, pi]: taken as its difference from the heaviest particle's, wrapped, so
    /// that a cloud across +-pi has its mean and spread where they are (for a spread
    /// well below pi). The mean angle is wrapped.
    pub fn mean_covariance_with_angle(&self, angle: Option<usize>) -> (SVector<f64, D>, SMatrix<f64, D, D>) {
        let w = self.normalised();
        let x = &self.x;
        let reference = angle.map_or(0.0, |k| {
            let heaviest = w.iter().enumerate().fold((0, f64::MIN), |b, (i, v)| if *v > b.1 { (i, *v) } else { b });
            x[k][heaviest.0]
        });
        // per chunk: sum w x_k (w x_k times a component of ones) and sum w x_k x_l
        // (k <= l), each a four-way dot product over the chunk (in the lanes, the pairs in
        // groups of four), reduced in chunk order
        let mut pairs: Vec<(usize, usize)> =
            (0..D).map(|k| (k, D)).chain((0..D).flat_map(|k| (k..D).map(move |l| (k, l)))).collect();
        let used = pairs.len();
        pairs.resize(used.next_multiple_of(4), (0, 0));
        let ones = vec![1.0; CHUNK.min(w.len())];
        let partial: Vec<(SVector<f64, D>, SMatrix<f64, D, D>)> = (0..w.len().div_ceil(CHUNK))
            .into_par_iter()
            .map(|c| {
                let (start, end) = (c * CHUNK, ((c + 1) * CHUNK).min(w.len()));
                let w = &w[start..end];
                let wrapped: Vec<f64> = angle.map_or_else(Vec::new, |k| {
                    x[k][start..end].iter().map(|a| crate::geo::wrap_near(a - reference)).collect()
                });
                let comp = |k: usize| if Some(k) == angle { &wrapped[..] } else { &x[k][start..end] };
                let comps: Vec<&[f64]> = (0..D).map(comp).chain([&ones[..w.len()]]).collect();
                let whole = w.len() / 4 * 4;
                let mut products = vec![[0.0; 4]; pairs.len()];
                crate::filter::lanes::add_products(&w[..whole], &comps, &pairs, &mut products);
                // the tail of fewer than four particles apart, as a four-way dot product
                // sums it, then the four accumulators pairwise
                let (mut s, mut ss) = (SVector::<f64, D>::zeros(), SMatrix::<f64, D, D>::zeros());
                for (&(k, l), a) in pairs[..used].iter().zip(&products) {
                    let tail: f64 = (whole..w.len()).map(|i| w[i] * comps[k][i] * comps[l][i]).sum();
                    let total = (a[0] + a[1]) + (a[2] + a[3]) + tail;
                    if l == D {
                        s[k] = total;
                    } else {
                        (ss[(k, l)], ss[(l, k)]) = (total, total);
                    }
                }
                (s, ss)
            })
            .collect();
        let (mut mean, mut second) = (SVector::zeros(), SMatrix::zeros());
        for (s, ss) in partial {
            mean += s;
            second += ss;
        }
        let cov = second - mean * mean.transpose();
        if let Some(k) = angle {
            mean[k] = crate::geo::wrap_near(mean[k] + reference);
        }
        (mean, cov)
    }

    /// Draws the particles again in proportion to their weights, resets the weights,
    /// and roughens when asked. Systematic and stratified resampling run chunk by chunk
    /// in parallel: each output chunk finds its first ancestor by bisection on the
    /// cumulative weights and walks from there, and copies its particles' components.
    pub fn resample(&mut self) {
        self.resample_then(|_, _| {});
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
        self.resample_then(|x, c| model.propagate(x, dt, &mut stream(seed, step, c as u64)));
        self.step += 1;
        true
    }

    /// Draws the particles again, then applies `then` to each chunk of the new particles
    /// (with the chunk's index) while it is in cache.
    fn resample_then(&mut self, then: impl Fn(&mut [&mut [f64]], usize) + Sync) {
        let (seed, step) = (self.seed, self.step);
        self.step += 1;
        self.normalised();
        let mut w = self.normalised.take().expect("computed above");
        let mut rng = stream(seed, step, u64::MAX);
        let resampler = self.settings.resampler;
        let drawn = drawn_ancestors(resampler, &w, &mut rng, |c| stream(seed, step, c as u64));
        let cumulative = cumulative_in_place(&mut w);
        let u0: f64 = rng.random();
        let from = &self.x;
        let mut views = chunk_views(&mut self.spare);
        views.par_iter_mut().zip(self.log_w.par_chunks_mut(CHUNK)).enumerate().for_each(|(c, (to, log_w))| {
            let first = c * CHUNK;
            let len = log_w.len();
            let mut rng = stream(seed, step, c as u64);
            let picked = chunk_ancestors(resampler, cumulative, &drawn, (c, first..first + len), u0, &mut rng);
            for (k, to) in to.iter_mut().enumerate() {
                for (v, &i) in to.iter_mut().zip(&picked) {
                    *v = from[k][i];
                }
            }
            log_w.fill(0.0);
            then(to, c);
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
                    let (lo, hi) = c.iter().fold((f64::MAX, f64::MIN), |(l, h), v| (l.min(*v), h.max(*v)));
                    k * (hi - lo).max(0.0) * n.powf(-1.0 / D as f64)
                })
                .collect();
            self.for_chunks(|x, rng| {
                for (comp, s) in x.iter_mut().zip(&sigma) {
                    for v in comp.iter_mut() {
                        *v += s * rng.sample::<f64, _>(rand_distr::StandardNormal);
                    }
                }
            });
        }
    }
}

/// The chunks of every component: `views[c][k]` is component `k` of chunk `c`.
fn chunk_views(x: &mut [Vec<f64>]) -> Vec<Vec<&mut [f64]>> {
    let n = x.first().map_or(0, Vec::len);
    let mut views: Vec<Vec<&mut [f64]>> = (0..n.div_ceil(CHUNK)).map(|_| Vec::with_capacity(x.len())).collect();
    for comp in x.iter_mut() {
        for (c, part) in comp.chunks_mut(CHUNK).enumerate() {
            views[c].push(part);
        }
    }
    views
}

/// Adds `likelihood`'s log-likelihood of every particle of `x` to `log_w`, chunk by
/// chunk in parallel; the largest of the results, NaN if any is NaN.
fn add_log_likelihood(x: &[Vec<f64>], log_w: &mut [f64], likelihood: &impl ParticleLikelihood) -> f64 {
    let maxima: Vec<f64> = log_w
        .par_chunks_mut(CHUNK)
        .enumerate()
        .map(|(c, lw)| {
            let start = c * CHUNK;
            let view: Vec<&[f64]> = x.iter().map(|comp| &comp[start..start + lw.len()]).collect();
            likelihood.add_log_likelihood(&view, lw);
            let (max, nan) = lw.iter().fold((f64::NEG_INFINITY, false), |(m, nan), v| (m.max(*v), nan | v.is_nan()));
            if nan { f64::NAN } else { max }
        })
        .collect();
    maxima.into_iter().fold(f64::NEG_INFINITY, |a, b| if a.is_nan() || b.is_nan() { f64::NAN } else { a.max(b) })
}

/// The effective sample size of log-weights `log_w + lambda inc`, summed by chunks in
/// order.
fn ess_tempered(log_w: &[f64], inc: &[f64], lambda: f64) -> f64 {
    let at = |i: usize| log_w[i] + lambda * inc[i];
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

/// The effective sample size of normalised weights, 1 / sum w_i^2.
fn ess_of(w: &[f64]) -> f64 {
    let partial: Vec<f64> = w.par_chunks(CHUNK).map(|c| c.iter().map(|v| v * v).sum::<f64>()).collect();
    1.0 / partial.iter().sum::<f64>()
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_abs_diff_eq;
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
        let report = InsReport {
            heading_rad: 0.3,
            speed_m_s: 1.5,
            depth_m: 30.0,
            sigma_heading_rad: 0.1,
            sigma_speed_m_s: 0.2,
            sigma_depth_m: 0.4,
        };
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
        fn add_log_likelihood(&self, x: &[&[f64]], log_w: &mut [f64]) {
            for (lw, v) in log_w.iter_mut().zip(x[0]) {
                *lw += 3.0 * v.sin() - 0.5 * v * v;
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
    /// every particle of 3 chunks and a part (drawn from N(0, 1), each value its own)
    /// weighed by exp(-x^2) is copied floor(N w_i) or ceil(N w_i) times (systematic), or
    /// within 2 of N w_i (stratified: one draw per stratum); N particles in all.
    #[test]
    fn parallel_resampling_keeps_counts_across_chunks() {
        struct Bell;
        impl ParticleLikelihood for Bell {
            fn add_log_likelihood(&self, x: &[&[f64]], log_w: &mut [f64]) {
                for (lw, v) in log_w.iter_mut().zip(x[0]) {
                    *lw -= v * v;
                }
            }
        }
        let n = 3 * CHUNK + 77;
        for r in [Resampler::Systematic, Resampler::Stratified] {
            let settings = ParticleSettings { resampler: r, ..ParticleSettings::default() };
            let mut pf = ParticleFilter::<1>::gaussian(n, &SVector::zeros(), &SVector::from([1.0]), settings, 4);
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
            fn propagate(&self, x: &mut [&mut [f64]], dt: f64, rng: &mut Pcg64) {
                let (p, v) = x.split_at_mut(1);
                for (p, v) in p[0].iter_mut().zip(v[0].iter_mut()) {
                    *p += *v * dt + 0.3 * rng.sample::<f64, _>(rand_distr::StandardNormal);
                    *v += 0.1 * rng.sample::<f64, _>(rand_distr::StandardNormal);
                }
            }
        }
        struct Fix(f64);
        impl ParticleLikelihood for Fix {
            fn add_log_likelihood(&self, x: &[&[f64]], log_w: &mut [f64]) {
                for (p, lw) in x[0].iter().zip(log_w.iter_mut()) {
                    *lw -= (p - self.0) * (p - self.0) / (2.0 * 0.5 * 0.5);
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
            fn propagate(&self, x: &mut [&mut [f64]], _dt: f64, rng: &mut Pcg64) {
                for c in x.iter_mut() {
                    for v in c.iter_mut() {
                        *v += rng.sample::<f64, _>(rand_distr::StandardNormal);
                    }
                }
            }
        }
        struct Near;
        impl ParticleLikelihood for Near {
            fn add_log_likelihood(&self, x: &[&[f64]], log_w: &mut [f64]) {
                for (i, lw) in log_w.iter_mut().enumerate() {
                    *lw -= x[0][i] * x[0][i] + x[1][i] * x[1][i];
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

    /// sum a_i b_i with four accumulators, the tail apart: the reference order.
    fn dot(a: &[f64], b: &[f64]) -> f64 {
        let mut acc = [0.0; 4];
        let (a4, b4) = (a.chunks_exact(4), b.chunks_exact(4));
        let tail: f64 = a4.remainder().iter().zip(b4.remainder()).map(|(a, b)| a * b).sum();
        for (a, b) in a4.zip(b4) {
            for j in 0..4 {
                acc[j] += a[j] * b[j];
            }
        }
        (acc[0] + acc[1]) + (acc[2] + acc[3]) + tail
    }

    /// The mean and covariance equal, to the bit, the chunk-by-chunk four-way dot
    /// products written out pair by pair (8 components, an angle among them, a chunk and
    /// a part with a tail of 3).
    #[test]
    fn mean_and_covariance_are_the_dot_products_of_each_chunk() {
        let n = 2 * CHUNK + 4099;
        let mean = SVector::<f64, 8>::from([0.5, 50.0, 30.0, 0.0, 3.0, 1.5, 0.0, 0.002]);
        let sigma = SVector::<f64, 8>::from([2.0, 10.0, 2.0, 0.05, 0.5, 0.3, 0.001, 0.003]);
        let mut pf = ParticleFilter::<8>::gaussian(n, &mean, &sigma, ParticleSettings::default(), 9);
        pf.update(&Tilt);
        let (m, c) = pf.mean_covariance_with_angle(Some(4));
        let w = pf.normalised();
        let reference =
            pf.x[4][w.iter().enumerate().fold((0, f64::MIN), |b, (i, v)| if *v > b.1 { (i, *v) } else { b }).0];
        let (mut mean, mut second) = (SVector::<f64, 8>::zeros(), SMatrix::<f64, 8, 8>::zeros());
        for start in (0..n).step_by(CHUNK) {
            let end = (start + CHUNK).min(n);
            let w = &w[start..end];
            let comps: Vec<Vec<f64>> = (0..8)
                .map(|k| {
                    let x = &pf.x[k][start..end];
                    if k == 4 { x.iter().map(|a| crate::geo::wrap_near(a - reference)).collect() } else { x.to_vec() }
                })
                .collect();
            for k in 0..8 {
                mean[k] += dot(w, &comps[k]);
                let wx: Vec<f64> = w.iter().zip(&comps[k]).map(|(w, x)| w * x).collect();
                for l in k..8 {
                    second[(k, l)] += dot(&wx, &comps[l]);
                    second[(l, k)] = second[(k, l)];
                }
            }
        }
        let cov = second - mean * mean.transpose();
        mean[4] = crate::geo::wrap_near(mean[4] + reference);
        assert!(m.iter().zip(mean.iter()).all(|(a, b)| a.to_bits() == b.to_bits()), "{m} {mean}");
        assert!(c.iter().zip(cov.iter()).all(|(a, b)| a.to_bits() == b.to_bits()), "{c} {cov}");
    }

    /// An angle component across +-pi: the mean where the particles are (pi, not 0) and
    /// the variance of their wrapped spread, against the values worked out by hand.
    #[test]
    fn angle_mean_across_the_wrap() {
        let mean = SVector::<f64, 2>::from([1.0, 0.0]);
        let mut pf = ParticleFilter::<2>::gaussian(4, &mean, &SVector::zeros(), ParticleSettings::default(), 1);
        // four angles 0.1 apart about pi: pi - 0.15, pi - 0.05, -pi + 0.05, -pi + 0.15
        let angles = [PI - 0.15, PI - 0.05, -PI + 0.05, -PI + 0.15];
        pf.x[1].copy_from_slice(&angles);
        let (m, c) = pf.mean_covariance_with_angle(Some(1));
        assert!((m[1].abs() - PI).abs() < 1e-12, "{}", m[1]);
        let var = [0.15f64, 0.05, 0.05, 0.15].iter().map(|d| d * d).sum::<f64>() / 4.0;
        assert!((c[(1, 1)] - var).abs() < 1e-12, "{}", c[(1, 1)]);
        // linear: the mean is near 0 and the spread near pi^2
        let (m, c) = pf.mean_covariance();
        assert!(m[1].abs() < 1e-12 && c[(1, 1)] > 9.0);
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
            fn add_log_likelihood(&self, x: &[&[f64]], log_w: &mut [f64]) {
                for (l, v) in log_w.iter_mut().zip(x[0]) {
                    *l += -v * v / (2.0 * self.0 * self.0);
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
