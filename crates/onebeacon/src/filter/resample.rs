//! Resampling's ancestors (hoff2024 eq. 9 and its systematic, stratified and residual
//! variants): the cumulative weights, the draws shared by the chunks, and each chunk's
//! walk through them, so that the picked ancestors are the same whatever the thread
//! count ([`super::particle`]'s chunked streams, [`CHUNK`] particles each).

use crate::par::*;
use rand::RngExt;
use rand_pcg::Pcg64;

/// Particles per chunk: the unit of parallel work and of random streams.
pub const CHUNK: usize = 8192;

crate::filter::lanes::lanes! {
    /// `to[j] = from[picked[j]] - shift`: a component's values copied from the ancestors
    /// (each index clamped to the last particle, which lets the compiler drop the bounds
    /// checks and use the level's gathers; every ancestor is below it).
    pub(super) fn gather(from: &[f32], picked: &[usize], shift: f32, to: &mut [f32]) {
        let last = from.len() - 1;
        for (v, &i) in to.iter_mut().zip(picked) {
            *v = from[i.min(last)] - shift;
        }
    }
}

/// How particles are drawn again in proportion to their weights.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum Resampler {
    /// N independent draws (hoff2024 eq. 9).
    Multinomial,
    /// One uniform offset, N evenly spaced points.
    #[default]
    Systematic,
    /// One uniform draw in each of N strata.
    Stratified,
    /// floor(N w_i) copies of each, the rest multinomially on the residual weights.
    Residual,
}

/// The sum of the `totals` before each (in order: the same whatever the thread count
/// that computed them).
pub(super) fn sums_before(totals: &[f64]) -> Vec<f64> {
    let mut acc = 0.0;
    totals
        .iter()
        .map(|t| {
            let before = acc;
            acc += t;
            before
        })
        .collect()
}

/// The weight of the chunks before each chunk of `w` (summed by chunks in parallel).
pub(super) fn weight_before_chunks(w: &[f64]) -> Vec<f64> {
    sums_before(&w.par_chunks(CHUNK).map(|c| c.iter().sum::<f64>()).collect::<Vec<f64>>())
}

/// Turns `w` into its running sum, by chunks in parallel (each chunk from the sum of
/// those before it: the same whatever the thread count).
pub(super) fn cumulative_in_place(w: &mut [f64]) -> &[f64] {
    let offsets = weight_before_chunks(w);
    w.par_chunks_mut(CHUNK).zip(offsets.par_iter()).for_each(|(c, off)| {
        let mut acc = *off;
        for v in c.iter_mut() {
            acc += *v;
            *v = acc;
        }
    });
    w
}

/// The particle whose cell of the cumulative weights `cum` holds each of `points`
/// (ascending, in [0, 1)): the first by bisection, the rest by a walk from it.
pub(super) fn walk_from(cum: &[f64], points: impl Iterator<Item = f64>) -> Vec<usize> {
    let mut points = points.peekable();
    let last = cum.len() - 1;
    let mut i = points.peek().map_or(0, |u| cum.partition_point(|c| c <= u).min(last));
    points
        .map(|u| {
            while u >= cum[i] && i < last {
                i += 1;
            }
            i
        })
        .collect()
}

/// What a resampler draws for all new particles before the chunks walk.
pub(super) enum Drawn {
    /// Nothing (systematic, stratified: each chunk walks from its own points).
    Nothing,
    /// The particle each new one copies (residual).
    Ancestors(Vec<usize>),
    /// Multinomial's sorted uniforms by exponential spacings, U_(j) = S_j / S_(n+1)
    /// with S the running sum of n + 1 standard exponentials (Devroye 1986, V.3): each
    /// chunk of new particles draws its exponentials in the lanes from a key of its own
    /// stream, in parallel;
    /// `running` holds each chunk's running sums, `before` the sum of the chunks before
    /// it, `total` S_(n+1).
    Spacings { running: Vec<f64>, before: Vec<f64>, total: f64 },
}

/// The draw of the resamplers that draw for all new particles at once, for normalised
/// weights `w`: the main stream `rng` draws what is not by chunk, `chunk_rng(c)` is
/// chunk c's stream.
pub(super) fn drawn_ancestors(
    resampler: Resampler,
    w: &[f64],
    rng: &mut Pcg64,
    chunk_rng: impl Fn(usize) -> Pcg64 + Sync,
) -> Drawn {
    let n = w.len();
    match resampler {
        Resampler::Systematic | Resampler::Stratified => Drawn::Nothing,
        Resampler::Multinomial => {
            let mut running = vec![0.0; n];
            let totals: Vec<f64> = running
                .par_chunks_mut(CHUNK)
                .enumerate()
                .map(|(c, e)| {
                    crate::filter::lanes::exponentials(chunk_rng(c).random::<u64>(), e);
                    let mut acc = 0.0;
                    for v in e.iter_mut() {
                        acc += *v;
                        *v = acc;
                    }
                    acc
                })
                .collect();
            let before = sums_before(&totals);
            let total = totals.iter().sum::<f64>() - (1.0 - rng.random::<f64>()).ln();
            Drawn::Spacings { running, before, total }
        }
        Resampler::Residual => {
            let mut out = Vec::with_capacity(n);
            let mut residual: Vec<f64> = Vec::with_capacity(n);
            for (i, wi) in w.iter().enumerate() {
                let copies = (n as f64 * wi).floor() as usize;
                out.extend(std::iter::repeat_n(i, copies));
                residual.push(n as f64 * wi - copies as f64);
            }
            let rest = n - out.len();
            if rest > 0 {
                let total: f64 = residual.iter().sum();
                residual.iter_mut().for_each(|r| *r /= total);
                out.extend(multinomial(&residual, rest, rng));
            }
            Drawn::Ancestors(out)
        }
    }
}

/// The index of the particle each new particle of `range` (chunk `c` of the new ones)
/// copies: its share of the drawn ancestors (residual), or a walk along the cumulative
/// weights `cum` from the range's first point: (j + u0) / N for systematic, (j + U_j) / N
/// for stratified with U_j drawn from `rng`, the chunk's spacings for multinomial.
pub(super) fn chunk_ancestors(
    resampler: Resampler,
    cum: &[f64],
    drawn: &Drawn,
    (c, range): (usize, std::ops::Range<usize>),
    u0: f64,
    rng: &mut Pcg64,
) -> Vec<usize> {
    let n = cum.len() as f64;
    match (drawn, resampler) {
        (Drawn::Ancestors(a), _) => a[range].to_vec(),
        (Drawn::Spacings { running, before, total }, _) => {
            walk_from(cum, running[range].iter().map(|s| (before[c] + s) / total))
        }
        (Drawn::Nothing, Resampler::Stratified) => walk_from(cum, range.map(|j| (j as f64 + rng.random::<f64>()) / n)),
        (Drawn::Nothing, _) => systematic(cum, range, u0),
    }
}

/// Systematic resampling's ancestors of new particles `range`, for the points
/// (j + u0) / N, without a walk's unpredictable branches: the points below C_i number
/// k_i = ceil(N C_i - u0), so particle i is the ancestor of new particles k_(i-1) to
/// k_i - 1 and new particle j's is the number of i with k_i <= j. The first of the range
/// by bisection; then each later particle i is written where its new particles start
/// (k_(i-1)), in order (one copied no times is overwritten by the next, which starts at
/// the same place), and a running maximum fills the places between.
fn systematic(cum: &[f64], range: std::ops::Range<usize>, u0: f64) -> Vec<usize> {
    let (n, last) = (cum.len() as f64, cum.len().saturating_sub(1));
    // ceil(t) for t > -1 by truncation (libm's ceil is a call at the baseline level)
    let k = |c: f64| {
        let t = n * c - u0;
        let i = t as i64;
        (i + i64::from((i as f64) < t)) as usize
    };
    let ancestor = |j: usize| cum.partition_point(|c| k(*c) <= j).min(last);
    let (lo, len) = (range.start, range.len());
    let Some(end) = len.checked_sub(1) else { return Vec::new() };
    let (first, final_) = (ancestor(lo), ancestor(lo + end));
    let mut out = vec![0; len];
    out[0] = first;
    let starts: Vec<usize> = cum[first..final_].iter().map(|c| k(*c) - lo).collect();
    for (i, s) in (first + 1..).zip(starts) {
        out[s] = i;
    }
    let mut max = first;
    for a in out.iter_mut() {
        max = max.max(*a);
        *a = max;
    }
    out
}

/// `m` independent draws of an index with probabilities `w`: sorted uniforms (from
/// exponential spacings) walked along the cumulative weights.
pub(super) fn multinomial(w: &[f64], m: usize, rng: &mut Pcg64) -> Vec<usize> {
    let e: Vec<f64> = (0..=m).map(|_| -(1.0 - rng.random::<f64>()).ln()).collect();
    let total: f64 = e.iter().sum();
    let mut acc = 0.0;
    walk(
        w,
        e[..m].iter().map(|v| {
            acc += v;
            acc / total
        }),
    )
}

/// The particle whose cumulative-weight cell holds each of `points` (ascending, in
/// [0, 1)), walked once along the normalised weights `w`.
pub(super) fn walk(w: &[f64], points: impl Iterator<Item = f64>) -> Vec<usize> {
    let mut out = Vec::with_capacity(points.size_hint().0);
    let (mut i, mut cum) = (0, w[0]);
    for u in points {
        while u >= cum && i + 1 < w.len() {
            i += 1;
            cum += w[i];
        }
        out.push(i);
    }
    out
}
